//! The parameter tables: one per scene, the single source of parameter names,
//! units, defaults and allowed ranges for the CLI, scene files, the C ABI and
//! the FMU. Their rows are the types of [`crate::params`], re-exported here.

pub use crate::params::{Level, ParamSpec, Range, concat, levels_spec, spec};

/// Declares a parameter struct whose rows live in a table declared
/// elsewhere (for example a scene table composed with a material block):
/// `Default` takes each field's default from `$table`, and `get` and `set`
/// reach the fields by name.
macro_rules! param_struct {
    (
        $(#[$meta:meta])*
        $name:ident, $table:expr, { $( $field:ident ),* $(,)? }
    ) => {
        $(#[$meta])*
        #[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
        #[serde(deny_unknown_fields, default)]
        pub struct $name {
            $( #[doc = concat!("`", stringify!($field), "`, as the parameter table describes it.")]
            pub $field: f64, )*
        }

        impl Default for $name {
            /// The defaults of the table.
            fn default() -> Self {
                let d = |name: &str| {
                    $table
                        .iter()
                        .find(|s| s.name == name)
                        .expect("every field is a row of the table")
                        .default
                };
                Self { $( $field: d(stringify!($field)), )* }
            }
        }

        impl $name {
            /// Value of the parameter called `name`, if it exists.
            pub fn get(&self, name: &str) -> Option<f64> {
                match name {
                    $( stringify!($field) => Some(self.$field), )*
                    _ => None,
                }
            }

            /// Sets the parameter called `name`; whether it exists.
            pub fn set(&mut self, name: &str, value: f64) -> bool {
                match name {
                    $( stringify!($field) => { self.$field = value; true } )*
                    _ => false,
                }
            }
        }
    };
}
pub(crate) use param_struct;

/// Declares the parameter table of a scene for each material choice (its
/// rows `before`, the block of the choice's models, its rows `after`;
/// [`crate::material::choice::compose`]) as the four named constants, and
/// `fn $pick(choice) -> &'static [ParamSpec]` that picks one.
macro_rules! choice_tables {
    (
        $before:expr, $after:expr, $pick:ident;
        $(#[$jl_meta:meta])* $jl:ident,
        $(#[$bl_meta:meta])* $bl:ident,
        $(#[$jm_meta:meta])* $jm:ident,
        $(#[$bm_meta:meta])* $bm:ident $(,)?
    ) => {
        /// The length of the table of a choice.
        const fn table_len(choice: $crate::material::choice::MaterialChoice) -> usize {
            $before.len() + $crate::material::choice::block_len(choice) + $after.len()
        }
        $(#[$jl_meta])*
        pub const $jl: &[$crate::params::ParamSpec] = &$crate::material::choice::compose::<
            { table_len($crate::material::choice::MaterialChoice::JOHNSON_COOK_LINEAR) },
        >($before, $crate::material::choice::MaterialChoice::JOHNSON_COOK_LINEAR, $after);
        $(#[$bl_meta])*
        pub const $bl: &[$crate::params::ParamSpec] = &$crate::material::choice::compose::<
            { table_len($crate::material::choice::MaterialChoice::BILINEAR_LINEAR) },
        >($before, $crate::material::choice::MaterialChoice::BILINEAR_LINEAR, $after);
        $(#[$jm_meta])*
        pub const $jm: &[$crate::params::ParamSpec] = &$crate::material::choice::compose::<
            { table_len($crate::material::choice::MaterialChoice::JOHNSON_COOK_MIE_GRUNEISEN) },
        >($before, $crate::material::choice::MaterialChoice::JOHNSON_COOK_MIE_GRUNEISEN, $after);
        $(#[$bm_meta])*
        pub const $bm: &[$crate::params::ParamSpec] = &$crate::material::choice::compose::<
            { table_len($crate::material::choice::MaterialChoice::BILINEAR_MIE_GRUNEISEN) },
        >($before, $crate::material::choice::MaterialChoice::BILINEAR_MIE_GRUNEISEN, $after);

        /// The parameter table of a choice.
        fn $pick(
            choice: $crate::material::choice::MaterialChoice,
        ) -> &'static [$crate::params::ParamSpec] {
            use $crate::material::choice::{EosKind::*, StrengthKind::*};
            match (choice.strength, choice.eos) {
                (JohnsonCook, Linear) => $jl,
                (Bilinear, Linear) => $bl,
                (JohnsonCook, MieGruneisen) => $jm,
                (Bilinear, MieGruneisen) => $bm,
            }
        }
    };
}
pub(crate) use choice_tables;
