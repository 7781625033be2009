//! The parameter tables: one per scene, the single source of parameter names,
//! units, defaults and allowed ranges for the CLI, scene files, the C ABI and
//! the FMU.

use crate::error::{Error, Result};

/// Allowed interval of a parameter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Range {
    /// Lower bound.
    pub min: f64,
    /// Whether `min` itself is allowed.
    pub min_inclusive: bool,
    /// Upper bound.
    pub max: f64,
    /// Whether `max` itself is allowed.
    pub max_inclusive: bool,
    /// Whether the value must be a whole number.
    pub integer: bool,
}

impl Range {
    /// `(min, max]`
    pub const fn open_closed(min: f64, max: f64) -> Self {
        Range {
            min,
            min_inclusive: false,
            max,
            max_inclusive: true,
            integer: false,
        }
    }
    /// `[min, max]`
    pub const fn closed(min: f64, max: f64) -> Self {
        Range {
            min,
            min_inclusive: true,
            max,
            max_inclusive: true,
            integer: false,
        }
    }
    /// Whole numbers in `[min, max]`.
    pub const fn integer(min: f64, max: f64) -> Self {
        Range {
            min,
            min_inclusive: true,
            max,
            max_inclusive: true,
            integer: true,
        }
    }

    /// Whether `v` is finite and inside the interval.
    pub fn contains(&self, v: f64) -> bool {
        v.is_finite()
            && (if self.min_inclusive {
                v >= self.min
            } else {
                v > self.min
            })
            && (if self.max_inclusive {
                v <= self.max
            } else {
                v < self.max
            })
            && (!self.integer || v.fract() == 0.0)
    }
}

impl std::fmt::Display for Range {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.integer {
            write!(f, "integers ")?;
        }
        write!(
            f,
            "{}{}, {}{}",
            if self.min_inclusive { '[' } else { '(' },
            self.min,
            self.max,
            if self.max_inclusive { ']' } else { ')' }
        )
    }
}

/// One named level of a parameter with levels (a scheme): its name, what it
/// is, and the values it gives other parameters of the table. A level's
/// value is its index in [`ParamSpec::levels`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Level {
    /// The name in scene files, on the command line, in the C ABI and FMUs.
    pub name: &'static str,
    /// One-line meaning.
    pub description: &'static str,
    /// The parameters it sets and their values; a parameter set by hand
    /// keeps its own value whatever the level ([`crate::Scene::set`]).
    pub sets: &'static [(&'static str, f64)],
}

/// One row of a parameter table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParamSpec {
    /// Name used by the CLI, scene files, the C ABI and the FMU.
    pub name: &'static str,
    /// SI unit ("1" for dimensionless).
    pub unit: &'static str,
    /// Default value.
    pub default: f64,
    /// Allowed values.
    pub range: Range,
    /// One-line meaning.
    pub description: &'static str,
    /// Named levels, for a parameter whose values are choices by name (the
    /// `scheme`); empty for a number.
    pub levels: &'static [Level],
}

impl ParamSpec {
    /// The level of value `value`, for a parameter with levels.
    pub fn level(&self, value: f64) -> Option<&'static Level> {
        if self.levels.is_empty() || !self.range.contains(value) {
            return None;
        }
        self.levels.get(value as usize)
    }

    /// The value of `text`: a level's name, for a parameter with levels, or
    /// a number; an error naming the parameter otherwise.
    pub fn parse(&self, text: &str) -> Result<f64> {
        let t = text.trim();
        if let Some(k) = self.levels.iter().position(|l| l.name == t) {
            return Ok(k as f64);
        }
        if !self.levels.is_empty() && t.parse::<f64>().is_err() {
            return Err(Error::UnknownModel {
                key: self.name.to_string(),
                name: t.to_string(),
                allowed: self.level_names(),
            });
        }
        t.parse().map_err(|_| Error::ParseValue {
            name: self.name.to_string(),
            text: text.to_string(),
        })
    }

    /// The names of the levels, comma-separated.
    pub fn level_names(&self) -> String {
        self.levels
            .iter()
            .map(|l| l.name)
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// Checks `value` against the range, with an error naming the parameter.
    pub fn check(&self, value: f64) -> Result<()> {
        if self.range.contains(value) {
            Ok(())
        } else {
            Err(Error::OutOfRange {
                name: self.name.to_string(),
                value,
                range: self.range.to_string(),
            })
        }
    }
}

/// One row of a parameter table.
pub const fn spec(
    name: &'static str,
    unit: &'static str,
    default: f64,
    range: Range,
    description: &'static str,
) -> ParamSpec {
    ParamSpec {
        name,
        unit,
        default,
        range,
        description,
        levels: &[],
    }
}

/// The row of a parameter with named levels: its value is the index of a
/// level (integers `[0, levels - 1]`), `default` the default level's.
pub const fn levels_spec(
    name: &'static str,
    default: usize,
    levels: &'static [Level],
    description: &'static str,
) -> ParamSpec {
    ParamSpec {
        name,
        unit: "1",
        default: default as f64,
        range: Range::integer(0.0, (levels.len() - 1) as f64),
        description,
        levels,
    }
}

/// The tables `parts` one after the other, at compile time; `N` is their
/// total length (a wrong `N` stops the build).
pub const fn concat<const N: usize>(parts: &[&[ParamSpec]]) -> [ParamSpec; N] {
    let mut out = [ParamSpec {
        name: "",
        unit: "",
        default: 0.0,
        range: Range::closed(0.0, 0.0),
        description: "",
        levels: &[],
    }; N];
    let (mut k, mut p) = (0, 0);
    while p < parts.len() {
        let mut i = 0;
        while i < parts[p].len() {
            out[k] = parts[p][i];
            k += 1;
            i += 1;
        }
        p += 1;
    }
    assert!(k == N, "the parts do not add up to N rows");
    out
}

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
        pub const $jl: &[$crate::scene::params::ParamSpec] = &$crate::material::choice::compose::<
            { table_len($crate::material::choice::MaterialChoice::JOHNSON_COOK_LINEAR) },
        >($before, $crate::material::choice::MaterialChoice::JOHNSON_COOK_LINEAR, $after);
        $(#[$bl_meta])*
        pub const $bl: &[$crate::scene::params::ParamSpec] = &$crate::material::choice::compose::<
            { table_len($crate::material::choice::MaterialChoice::BILINEAR_LINEAR) },
        >($before, $crate::material::choice::MaterialChoice::BILINEAR_LINEAR, $after);
        $(#[$jm_meta])*
        pub const $jm: &[$crate::scene::params::ParamSpec] = &$crate::material::choice::compose::<
            { table_len($crate::material::choice::MaterialChoice::JOHNSON_COOK_MIE_GRUNEISEN) },
        >($before, $crate::material::choice::MaterialChoice::JOHNSON_COOK_MIE_GRUNEISEN, $after);
        $(#[$bm_meta])*
        pub const $bm: &[$crate::scene::params::ParamSpec] = &$crate::material::choice::compose::<
            { table_len($crate::material::choice::MaterialChoice::BILINEAR_MIE_GRUNEISEN) },
        >($before, $crate::material::choice::MaterialChoice::BILINEAR_MIE_GRUNEISEN, $after);

        /// The parameter table of a choice.
        fn $pick(
            choice: $crate::material::choice::MaterialChoice,
        ) -> &'static [$crate::scene::params::ParamSpec] {
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
