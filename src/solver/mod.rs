//! Solvers. Each scene composes exactly the physics it needs: the
//! axisymmetric Taylor solver ([`axisymmetric`]) and the radial Noh solver
//! ([`radial`]) share the kernel, the neighbour search, the MSPH basis and the
//! helpers here (pair weights, conservative smoothing, central-difference
//! bookkeeping), but nothing else runs per step.

pub mod axisymmetric;
pub mod mlpg3d;
pub mod radial;
pub mod shared;
pub mod uniaxial;

/// Courant number of eq. (3.22).
pub const COURANT: f64 = 0.2;

/// Declares the setup struct of a solver: its parameters as public `f64`
/// fields, each with its description, saved with the solver's state
/// (serde: unknown fields refused, missing ones at `Default`, which the
/// scene that holds the parameter table implements from it), `get` by
/// name, and `from_fn`, which takes each field from a function of its name;
/// `with set` adds a public `set` by name.
macro_rules! setup_struct {
    (
        $(#[$meta:meta])*
        $name:ident {
            $( $field:ident: $doc:literal, )*
        }
    ) => {
        $(#[$meta])*
        #[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
        #[serde(deny_unknown_fields, default)]
        pub struct $name {
            $( #[doc = $doc] pub $field: f64, )*
        }

        impl $name {
            /// Value of the parameter called `name`, if it exists.
            pub fn get(&self, name: &str) -> Option<f64> {
                match name {
                    $( stringify!($field) => Some(self.$field), )*
                    _ => None,
                }
            }

            /// The parameters whose values `value` gives by name, taken
            /// field by field in declaration order.
            pub(crate) fn from_fn(mut value: impl FnMut(&str) -> f64) -> Self {
                Self { $( $field: value(stringify!($field)), )* }
            }
        }
    };
    (
        $(#[$meta:meta])*
        $name:ident, with set {
            $( $field:ident: $doc:literal, )*
        }
    ) => {
        $crate::solver::setup_struct! {
            $(#[$meta])*
            $name {
                $( $field: $doc, )*
            }
        }

        impl $name {
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
pub(crate) use setup_struct;

/// Splits a CSR-aligned buffer into one mutable slice per particle so that
/// rows can be filled in parallel.
pub(crate) fn rows_mut<'a, T>(mut buf: &'a mut [T], offsets: &[usize]) -> Vec<&'a mut [T]> {
    let mut rows = Vec::with_capacity(offsets.len().saturating_sub(1));
    for w in offsets.windows(2) {
        let (head, tail) = std::mem::take(&mut buf).split_at_mut(w[1] - w[0]);
        rows.push(head);
        buf = tail;
    }
    rows
}

/// The first degenerate moment matrix, in particle order, as the named error.
pub(crate) fn first_degenerate(
    status: Vec<std::result::Result<(), crate::approx::msph::Degenerate>>,
    time: f64,
) -> crate::Result<()> {
    match status.into_iter().find_map(|s| s.err()) {
        Some(e) => Err(crate::Error::SingularMomentMatrix {
            method: crate::error::MomentMethod::Msph,
            particle: e.particle,
            time,
            condition: e.condition,
        }),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_mut_splits_by_offsets() {
        let mut buf = [0, 1, 2, 3, 4, 5];
        let rows = rows_mut(&mut buf, &[0, 2, 2, 6]);
        assert_eq!(rows.len(), 3);
        assert_eq!(&*rows[0], &[0, 1]);
        assert!(rows[1].is_empty());
        assert_eq!(&*rows[2], &[2, 3, 4, 5]);
    }
}
