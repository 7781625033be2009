//! The `taylor` scene: a rod striking a rigid smooth anvil (House et al.
//! test 7 on 4340 steel by default), with the chosen strength model and
//! equation of state (Johnson-Cook and the linear EOS by default),
//! adiabatic heating, a rigid smooth anvil and a traction-free mantle and
//! top.
//!
//! Its parameter table is the rod's geometry and speed, the material block
//! of the chosen models ([`crate::material::choice`]), then the numerical
//! parameters. Each choice has an FMU of its own: `TaylorImpact`
//! (Johnson-Cook, linear: the table and variables of before the choice
//! existed), `TaylorImpactBilinear`, `TaylorImpactMieGruneisen` and
//! `TaylorImpactBilinearMieGruneisen`.

use super::params::{Level, ParamSpec, Range, choice_tables, levels_spec};
use super::row::{FmuIdentity, MaterialSlot, SceneRow};
use super::table1::Table1Row;
use super::{Scene, SceneKind};
use crate::budget::MemoryPerNode;
use crate::material::choice::{MaterialChoice, Prefix};
use crate::observe::TAYLOR_OBSERVABLES;
use crate::solver::axisymmetric::TaylorSolver;

/// The parameters of a Taylor run, the solver's setup (defined with it);
/// their defaults are this table's.
pub use crate::solver::axisymmetric::TaylorParams;

/// The registry row of the `taylor` scene.
pub static ROW: SceneRow = SceneRow {
    name: "taylor",
    title: "Taylor impact, House et al. test 7 (4340 steel, 181 m/s)",
    params: TAYLOR_PARAMS,
    material: Some(MaterialSlot {
        default: MaterialChoice::JOHNSON_COOK_LINEAR,
        params: params_of,
        fmus: &[
            (
                MaterialChoice::BILINEAR_LINEAR,
                FmuIdentity {
                    model_identifier: "TaylorImpactBilinear",
                    model_name: "TaylorImpactBilinear",
                    description: "Taylor rod impact on a rigid anvil: axisymmetric Modified SPH (MSPH, Batra & Zhang 2008) \
                                  with bilinear J2 plasticity and the linear equation of state",
                },
            ),
            (
                MaterialChoice::JOHNSON_COOK_MIE_GRUNEISEN,
                FmuIdentity {
                    model_identifier: "TaylorImpactMieGruneisen",
                    model_name: "TaylorImpactMieGruneisen",
                    description: "Taylor rod impact on a rigid anvil: axisymmetric Modified SPH (MSPH, Batra & Zhang 2008) \
                                  with Johnson-Cook thermo-viscoplasticity and the Mie-Gruneisen equation of state",
                },
            ),
            (
                MaterialChoice::BILINEAR_MIE_GRUNEISEN,
                FmuIdentity {
                    model_identifier: "TaylorImpactBilinearMieGruneisen",
                    model_name: "TaylorImpactBilinearMieGruneisen",
                    description: "Taylor rod impact on a rigid anvil: axisymmetric Modified SPH (MSPH, Batra & Zhang 2008) \
                                  with bilinear J2 plasticity and the Mie-Gruneisen equation of state",
                },
            ),
        ],
    }),
    observables: TAYLOR_OBSERVABLES,
    fields: crate::solver::axisymmetric::TAYLOR_FIELDS,
    reference: || Table1Row::all()[6].reference(),
    variants: table1_variants,
    check: |s| {
        material_choice(s).check_consistency(Prefix::None, |n| s.get(n))?;
        TaylorParams::of(s).check_consistency()
    },
    nodes: |s| TaylorParams::of(s).nodes(),
    // Measured 2.0 kB a node at 60 across (BENCHMARKS.md, "Memory per
    // node"); the neighbour lists grow as the rod spreads.
    memory: |_| MemoryPerNode { bytes: 4000.0 },
    build: |s: &Scene| {
        let material = material_choice(s).material(Prefix::None, |n| s.get(n))?;
        Ok(Box::new(TaylorSolver::with_material(
            TaylorParams::of(s),
            material,
        )?))
    },
    fmu: Some(FmuIdentity {
        model_identifier: "TaylorImpact",
        model_name: "TaylorImpact",
        description: "Taylor rod impact on a rigid anvil: axisymmetric Modified SPH (MSPH, Batra & Zhang 2008) \
                      with Johnson-Cook thermo-viscoplasticity; defaults are House et al. (1995) test 7 on 4340 steel",
    }),
};

/// The material models of a `taylor` scene.
fn material_choice(s: &Scene) -> MaterialChoice {
    s.kind()
        .material()
        .expect("the taylor scene has a material choice")
}

/// The rod's speed and geometry: the rows before the material block.
pub(super) const BEFORE: &[ParamSpec] = &[
    spec(
        "impact_speed",
        "m/s",
        181.0,
        Range::closed(0.01, 2000.0),
        "speed of the rod toward the anvil",
    ),
    spec(
        "initial_length",
        "m",
        0.03797,
        Range::closed(1.0e-4, 10.0),
        "rod length L0",
    ),
    spec(
        "initial_diameter",
        "m",
        0.007595,
        Range::closed(1.0e-4, 10.0),
        "rod diameter D0",
    ),
];

/// The numerical parameters and the end time: the rows after the material
/// block.
const AFTER: &[ParamSpec] = &[
    spec(
        "particles_radial",
        "1",
        20.0,
        Range::integer(3.0, 200.0),
        "particles across the radius, axis and mantle included; axial spacing matches",
    ),
    spec(
        "smoothing_ratio",
        "1",
        2.0,
        Range::closed(0.5, 4.0),
        "smoothing length h divided by the particle spacing (scheme)",
    ),
    spec(
        "smoothing_coefficient",
        "1",
        0.2,
        Range::closed(0.0, 0.5),
        "alpha_cs of the conservative smoothing (3.23) (scheme)",
    ),
    spec(
        "smoothing_order",
        "1",
        2.0,
        Range::integer(1.0, 2.0),
        "velocity and density smoothing: 1 = the paper's (3.23), 2 = its bi-Laplacian (large strain) (scheme)",
    ),
    spec(
        "shifting",
        "1",
        0.1,
        Range::closed(0.0, 1.0),
        "particle shifting beta: pairs closer than half the spacing push apart by up to beta times the spacing per step; 0 = Lagrangian, as the paper (scheme)",
    ),
    END_TIME,
    levels_spec(
        "scheme",
        0,
        SCHEMES,
        "numerical scheme by name, which sets the knobs marked (scheme); a knob set by hand overrides it: \
         0 = large_strain (the validated default), 1 = paper (Batra & Zhang's MSPH exactly)",
    ),
];

/// The schemes of the axisymmetric MSPH solver, by name (the `scheme` row;
/// [`crate::solver::axisymmetric::scheme::MsphScheme`] decodes the knobs they set). The
/// first is the default.
pub const SCHEMES: &[Level] = &[
    Level {
        name: "large_strain",
        description: "the validated default: h = 2 spacings, the order-2 (bi-Laplacian) smoothing of velocity \
                      and density, particle shifting beta = 0.1 (VALIDATION.md, \"Right by default\")",
        sets: &[
            ("smoothing_ratio", 2.0),
            ("smoothing_coefficient", 0.2),
            ("smoothing_order", 2.0),
            ("shifting", 0.1),
        ],
    },
    Level {
        name: "paper",
        description: "Batra & Zhang (2008) exactly: h = 1.5 spacings, the conservative smoothing (3.23), \
                      Lagrangian particles",
        sets: &[
            ("smoothing_ratio", 1.5),
            ("smoothing_coefficient", 0.2),
            ("smoothing_order", 1.0),
            ("shifting", 0.0),
        ],
    },
];

/// The end time of a rod scene.
pub(super) const END_TIME: ParamSpec = spec(
    "end_time",
    "s",
    400.0e-6,
    Range::closed(1.0e-9, 1.0),
    "latest simulated time; the run normally ends earlier, when the rod is at rest",
);

pub(super) use super::params::spec;

choice_tables! {
    BEFORE, AFTER, params_of;
    /// The parameter table of the `taylor` scene with Johnson-Cook and the
    /// linear EOS (the default): speed and geometry, the material block, the
    /// numerical parameters. Defaults are House et al. test 7 with the 4340
    /// steel constants of Batra & Zhang (2008).
    TAYLOR_PARAMS,
    /// The table with bilinear strength and the linear EOS.
    TAYLOR_BILINEAR_PARAMS,
    /// The table with Johnson-Cook and Mie-Grüneisen.
    TAYLOR_MIE_GRUNEISEN_PARAMS,
    /// The table with bilinear strength and Mie-Grüneisen.
    TAYLOR_BILINEAR_MIE_GRUNEISEN_PARAMS,
}

impl Default for TaylorParams {
    /// The defaults of the table.
    fn default() -> Self {
        TaylorParams::from_fn(|name| {
            TAYLOR_PARAMS
                .iter()
                .find(|s| s.name == name)
                .expect("every field is a row of the table")
                .default
        })
    }
}

impl TaylorParams {
    /// The parameters of a `taylor` scene, any material choice: every
    /// row of its table that is a field here, the others at their defaults.
    pub fn of(scene: &Scene) -> TaylorParams {
        let mut p = TaylorParams::default();
        for (spec, v) in scene.param_specs().iter().zip(scene.values()) {
            p.set(spec.name, *v);
        }
        p
    }

    /// Particles along the axis: the length over the radial spacing, plus
    /// one.
    pub(crate) fn axial_particles(&self) -> f64 {
        let spacing = 0.5 * self.initial_diameter / (self.particles_radial - 1.0);
        (self.initial_length / spacing).round() + 1.0
    }

    /// Particles of the axisymmetric lattice (across times along).
    pub(crate) fn nodes(&self) -> f64 {
        self.particles_radial * self.axial_particles()
    }

    /// Checks the geometric constraint that single ranges cannot express
    /// (the material's are [`MaterialChoice::check_consistency`]).
    pub fn check_consistency(&self) -> crate::Result<()> {
        use crate::Error::Inconsistent;
        let n = self.particles_radial;
        let axial = self.axial_particles();
        if !(2.0..=100_000.0).contains(&axial) {
            return Err(Inconsistent(format!(
                "initial_length / spacing gives {axial} particles along the axis; allowed [2, 100000] \
                 (initial_length = {} m, initial_diameter = {} m, particles_radial = {n})",
                self.initial_length, self.initial_diameter
            )));
        }
        Ok(())
    }
}

/// The Taylor scenes of Table 1 (written here, with the row they are
/// variants of, so that `table1.rs` holds only the table).
impl Table1Row {
    /// The Taylor scene of this configuration (other parameters default).
    pub fn scene(&self) -> Scene {
        let mut s = Scene::default_of(SceneKind::default_of_row(&ROW));
        for (name, v) in [
            ("impact_speed", self.v),
            ("initial_length", self.l0),
            ("initial_diameter", self.d0),
        ] {
            s.set(name, v).expect("Table 1 values lie in the ranges");
        }
        s.title = format!(
            "House et al. (1995) test {}: L0 = {} mm, D0 = {} mm, V = {} m/s",
            self.test,
            self.l0 * 1e3,
            self.d0 * 1e3,
            self.v
        );
        s.reference = self.reference();
        s
    }
}

/// The twelve configurations as named variants of the `taylor` scene,
/// `table1-1` ... `table1-12`.
pub fn table1_variants() -> Vec<(String, Scene)> {
    Table1Row::all()
        .iter()
        .enumerate()
        .map(|(k, row)| (format!("table1-{}", k + 1), row.scene()))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every field of [`TaylorParams`] is a row of the default table, and
    /// the default table lists exactly the fields, in the order of the
    /// table before the material choice existed (the `TaylorImpact` FMU's
    /// value references).
    #[test]
    fn default_table_is_the_fields_in_order() {
        let names: Vec<&str> = TAYLOR_PARAMS.iter().map(|s| s.name).collect();
        let p = TaylorParams::default();
        assert!(names.iter().all(|n| p.get(n).is_some() || *n == "scheme"));
        assert_eq!(
            names.join(" "),
            "impact_speed initial_length initial_diameter density shear_modulus bulk_modulus \
             specific_heat taylor_quinney jc_a jc_b jc_n jc_c jc_m melt_temperature \
             room_temperature initial_temperature ref_strain_rate particles_radial \
             smoothing_ratio smoothing_coefficient smoothing_order shifting end_time scheme"
        );
        for c in MaterialChoice::ALL {
            let t = params_of(c);
            assert_eq!(t.len(), table_len(c));
            assert_eq!(t[..3], *BEFORE);
            assert_eq!(t[t.len() - AFTER.len()..], *AFTER);
        }
    }
}
