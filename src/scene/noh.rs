//! The `noh` scene: the cylindrical Noh problem, eqs. (4.1)-(4.4): an ideal gas
//! streaming toward the axis at unit speed. One-dimensional in R; no strength,
//! no heating beyond compression and smoothing, no anvil.

use super::Scene;
use super::params::{ParamSpec, Range, spec};
use super::row::{SceneRow, no_variants};
use crate::budget::MemoryPerNode;
use crate::observe::NOH_OBSERVABLES;
use crate::solver::radial::NohSolver;

/// The parameters of a Noh run, the solver's setup (defined with it), and
/// the window of its pre-shock observable; the parameters' defaults are
/// this table's.
pub use crate::solver::radial::{NohParams, PRE_SHOCK_WINDOW};
use std::collections::BTreeMap;

/// The registry row of the `noh` scene.
pub static ROW: SceneRow = SceneRow {
    name: "noh",
    title: "Cylindrical Noh problem (gamma = 5/3)",
    params: NOH_PARAMS,
    material: None,
    observables: NOH_OBSERVABLES,
    fields: crate::solver::radial::NOH_FIELDS,
    reference: || {
        BTreeMap::from([
            ("shock_radius".to_string(), 0.2),
            ("post_shock_density".to_string(), 16.0),
        ])
    },
    variants: no_variants,
    check: |s| NohParams::from_values(s.values()).check_consistency(),
    nodes: |s| NohParams::from_values(s.values()).particles_radial,
    // Measured 0.67 kB a particle at 20 000 (BENCHMARKS.md, "Memory per
    // node").
    memory: |_| MemoryPerNode { bytes: 1000.0 },
    build: |s: &Scene| {
        Ok(Box::new(NohSolver::new(NohParams::from_values(
            s.values(),
        ))?))
    },
    fmu: None,
};

/// The parameter table of this scene, in the order of [`NohParams`]'s
/// fields.
pub const NOH_PARAMS: &[ParamSpec] = &[
    spec(
        "particles_radial",
        "1",
        800.0,
        Range::integer(10.0, 100_000.0),
        "particles along the radius, the one on the axis included",
    ),
    spec(
        "outer_radius",
        "1",
        1.5,
        Range::open_closed(0.0, 100.0),
        "initial radius of the gas column; 1.5 keeps gas out to r = 0.9 at t = 0.6",
    ),
    spec(
        "gamma",
        "1",
        5.0 / 3.0,
        Range::open_closed(1.0, 10.0),
        "ratio of specific heats of the ideal gas",
    ),
    spec(
        "smoothing_ratio",
        "1",
        1.5,
        Range::closed(0.5, 4.0),
        "smoothing length h divided by the particle spacing",
    ),
    spec(
        "smoothing_coefficient",
        "1",
        0.3,
        Range::closed(0.0, 0.5),
        "alpha_cs of the conservative smoothing (3.23)",
    ),
    spec(
        "viscosity_quadratic",
        "1",
        1.0,
        Range::closed(0.0, 10.0),
        "c_q of the radial von Neumann-Richtmyer artificial viscosity",
    ),
    spec(
        "viscosity_linear",
        "1",
        0.5,
        Range::closed(0.0, 10.0),
        "c_l of the radial artificial viscosity",
    ),
    spec(
        "end_time",
        "1",
        0.6,
        Range::closed(1.0e-3, 100.0),
        "simulated time at which the run ends",
    ),
];

/// The row of the table called `name`.
fn row(name: &str) -> usize {
    NOH_PARAMS
        .iter()
        .position(|s| s.name == name)
        .expect("every field is a row of the table")
}

impl Default for NohParams {
    fn default() -> Self {
        NohParams::from_fn(|name| NOH_PARAMS[row(name)].default)
    }
}

impl NohParams {
    /// The parameters from one value per row of the table, in its
    /// order (as [`crate::Scene::values`] holds them).
    pub fn from_values(values: &[f64]) -> Self {
        debug_assert_eq!(
            values.len(),
            NOH_PARAMS.len(),
            "one value per row of the table"
        );
        NohParams::from_fn(|name| values[row(name)])
    }

    /// Cross-parameter checks: the gas streams inward at unit speed, so the
    /// column must start at least `0.9 + end_time` wide for the windows of
    /// the observables (`pre_shock_density_l1` over 0.25 <= r <= 0.9,
    /// `post_shock_density` over 0.1 <= r <= 0.18) to hold gas to the end.
    pub fn check_consistency(&self) -> crate::Result<()> {
        let need = PRE_SHOCK_WINDOW.1 + self.end_time;
        if self.outer_radius < need {
            return Err(crate::Error::Inconsistent(format!(
                "outer_radius = {} must be at least 0.9 + end_time = {need} so that gas \
                 fills the observation windows (0.1 <= r <= 0.9) until the end",
                self.outer_radius
            )));
        }
        // The pre-shock gas keeps its initial spacing, so a window at least
        // one spacing wide always holds a particle to measure.
        let spacing = self.outer_radius / (self.particles_radial - 1.0);
        let width = PRE_SHOCK_WINDOW.1 - PRE_SHOCK_WINDOW.0;
        if spacing > width {
            return Err(crate::Error::Inconsistent(format!(
                "outer_radius = {} over particles_radial = {} gives a spacing of {spacing}, \
                 wider than the pre-shock window ({width}); use at least {} particles",
                self.outer_radius,
                self.particles_radial,
                (self.outer_radius / width).ceil() + 1.0
            )));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The table lists exactly the fields of [`NohParams`], in their order:
    /// each row's value lands in the field of its name.
    #[test]
    fn the_table_is_the_fields_in_order() {
        let values: Vec<f64> = (0..NOH_PARAMS.len()).map(|k| k as f64 + 0.5).collect();
        let p = NohParams::from_values(&values);
        let d = NohParams::default();
        for (k, s) in NOH_PARAMS.iter().enumerate() {
            assert_eq!(p.get(s.name), Some(values[k]), "{}", s.name);
            assert_eq!(d.get(s.name), Some(s.default), "{}", s.name);
        }
        let json = serde_json::to_value(p).unwrap();
        assert_eq!(json.as_object().unwrap().len(), NOH_PARAMS.len());
    }
}
