//! The `taylor3d` scene: House et al. test 7 in 3-D by the MLPG mixed
//! method (seed 004, [`crate::solver::mlpg3d`]): a rod of 4340 steel on the ring
//! lattice striking a rigid smooth anvil, with the `taylor` scene's
//! parameter and observable names, the same choice of material models
//! ([`crate::material::choice`]; no FMU of its own for the other choices
//! yet), `particles_radial` nodes across the
//! radius (axis and mantle included: `particles_radial − 1` rings, the
//! spacing of a `taylor` run with the same value), and the MLPG solver's
//! damping ratio.

use super::Scene;
use super::params::{Level, ParamSpec, Range, choice_tables, levels_spec, param_struct};
use super::row::{MaterialSlot, SceneRow};
use super::taylor::{BEFORE, END_TIME, TaylorParams, spec};
use crate::approx::lattice::Cylinder;
use crate::budget::MemoryPerNode;
use crate::material::Material;
use crate::material::choice::{MaterialChoice, Prefix};
use crate::observe::TAYLOR3D_OBSERVABLES;
use crate::solver::mlpg3d::scheme::MlpgScheme;
use crate::solver::mlpg3d::{DAMPING, Mlpg3d, REBUILD_STRAIN, RodSetup, SMOOTHING};

/// The registry row of the `taylor3d` scene.
pub static ROW: SceneRow = SceneRow {
    name: "taylor3d",
    title: "Taylor impact in 3-D by MLPG, House et al. test 7 (4340 steel, 181 m/s)",
    params: TAYLOR3D_PARAMS,
    material: Some(MaterialSlot {
        default: MaterialChoice::JOHNSON_COOK_LINEAR,
        params: params_of,
        fmus: &[],
    }),
    observables: TAYLOR3D_OBSERVABLES,
    fields: crate::solver::mlpg3d::MLPG_FIELDS,
    reference: || super::table1::Table1Row::all()[6].reference(),
    variants,
    check: |s| {
        material_choice(s).check_consistency(Prefix::None, |n| s.get(n))?;
        Taylor3dParams::of(s).check_consistency()
    },
    nodes: |s| {
        let p = Taylor3dParams::of(s);
        let radius = 0.5 * p.initial_diameter;
        let spacing = radius / (p.particles_radial - 1.0);
        let lattice = RingLattice::of(s);
        lattice.nodes(radius, p.initial_length, spacing)
    },
    memory: mlpg_memory,
    build: |s: &Scene| {
        let material = material_choice(s).material(Prefix::None, |n| s.get(n))?;
        Ok(Box::new(Taylor3dParams::of(s).build_with(material)?))
    },
    fmu: Some(super::row::FmuIdentity {
        model_identifier: "Taylor3dImpact",
        model_name: "Taylor3dImpact",
        description: "Taylor rod impact on a rigid anvil in 3-D: the MLPG mixed method (Han, Liu, Rajendran & Atluri) \
                      with Johnson-Cook thermo-viscoplasticity; defaults are House et al. (1995) test 7 on 4340 steel",
    }),
};

/// The peak bytes a node of the 3-D MLPG solver (`taylor3d`,
/// `penetration`) with the nodal forms (`weak_form` 1 and 2, both scenes'
/// defaults). The heap's most live at once over whole runs, counted by the
/// allocator (2026-11-29), is 4.51-6.10 kB a node: `taylor3d` 5.12 at 4
/// across, 5.05 at 6, 4.89 at 10; `penetration` 4.51 at 3, 4.73 at 4, 4.81
/// at 6 (the whole body), and as a quarter 6.10 at 3 and 5.67 at 8. This
/// is 1.23-1.66 times those peaks (`tests/mlpg_alloc.rs` holds it between
/// the peak and twice it); with the base it covers the peak resident
/// memory of every run measured; and it admits a million-node `taylor3d` (34
/// across) at the default budget of 8 GiB (docs/notes/2026-11-29-memory-bounds.md).
/// It was 20 kB (`taylor3d`) and 40 kB (`penetration`) before.
pub(crate) const NODAL_FORM_MEMORY: MemoryPerNode = MemoryPerNode { bytes: 7_500.0 };

/// The same with the seed's local weak form over test spheres
/// (`weak_form` 0, as in the scheme `paper`), whose heap is about twice
/// the nodal forms': 7.73 kB a node at 3 across, 8.16 at 4, 8.82 at 6 and
/// 9.63 at 10 with the scheme `paper` (it grows with the resolution, the
/// peak in the first build), 10.30-11.33 kB at 3-10 across with
/// `weak_form = 0` on the default scheme's other knobs, 8.41 kB for
/// `penetration` at 3 across with `paper` (docs/notes/2026-11-29-memory-bounds.md).
/// One figure for both forms could not be within twice both peaks.
pub(crate) const SPHERE_FORM_MEMORY: MemoryPerNode = MemoryPerNode { bytes: 14_000.0 };

/// The peak memory per node of a run of the 3-D MLPG solver, by its forces.
pub(crate) fn mlpg_memory(s: &Scene) -> MemoryPerNode {
    match s.get("weak_form") {
        Ok(w) if w < 0.5 => SPHERE_FORM_MEMORY,
        _ => NODAL_FORM_MEMORY,
    }
}

/// The ring lattice of a 3-D scene's bodies, as far as its node count
/// depends on it: whole or quarter (`symmetry`), aligned or staggered
/// (`lattice`).
#[derive(Debug, Clone, Copy)]
pub(crate) struct RingLattice {
    /// The quarter `x >= 0`, `y >= 0` (the quarter model).
    pub quarter: bool,
    /// The odd layers turned by half a node's angle.
    pub staggered: bool,
}

impl RingLattice {
    /// The lattice of a 3-D scene (one with `symmetry` and `lattice`).
    pub fn of(s: &Scene) -> Self {
        let v = |name: &str| s.get(name).expect("a 3-D scene's parameter");
        RingLattice {
            quarter: v("symmetry") >= 0.5,
            staggered: v("lattice") >= 0.5,
        }
    }

    /// Nodes of the ring lattice of a cylinder ([`crate::approx::lattice`])
    /// of `radius` and `length` at the radial `spacing`, one layer a
    /// spacing: `1 + 3 k (k + 1)` a layer for `k` rings; in the quarter,
    /// the axis and, of ring `j`'s `6 j` nodes, those at angles in
    /// [0, π/2] (the planes' nodes kept): `floor(1.5 j) + 1`, or
    /// `floor(1.5 j - 0.5) + 1` on a staggered lattice's odd layers.
    pub fn nodes(self, radius: f64, length: f64, spacing: f64) -> f64 {
        let k = (radius / spacing).round() as usize;
        let layers = (length / spacing).round().max(1.0) + 1.0;
        if !self.quarter {
            let k = k as f64;
            return (1.0 + 3.0 * k * (k + 1.0)) * layers;
        }
        let layer = |turn: f64| {
            1.0 + (1..=k)
                .map(|j| (1.5 * j as f64 - turn).floor() + 1.0)
                .sum::<f64>()
        };
        let (even, odd) = ((layers / 2.0).ceil(), (layers / 2.0).floor());
        let turned = if self.staggered { 0.5 } else { 0.0 };
        even * layer(0.0) + odd * layer(turned)
    }
}

/// The material models of a `taylor3d` scene.
fn material_choice(s: &Scene) -> MaterialChoice {
    s.kind()
        .material()
        .expect("the taylor3d scene has a material choice")
}

/// The `smoothing_order` row of the 3-D scenes (`taylor3d`, `penetration`).
pub(crate) const SMOOTHING_ORDER_SPEC: ParamSpec = spec(
    "smoothing_order",
    "1",
    2.0,
    Range::integer(1.0, 2.0),
    "MLPG velocity smoothing with H = I - Phi (Phi: the MLS approximation at the nodes): 1 = v <- v - alpha H v, 2 = v <- v - alpha M^-1 H^T M H v, its symmetric square, which spares smooth fields (README, 3-D MLPG)",
);

/// The `symmetry` row of the 3-D scenes of a normal impact: 0 the whole
/// body, 1 the quarter model (`src/approx/mirror.rs`).
pub(crate) const SYMMETRY: ParamSpec = spec(
    "symmetry",
    "1",
    0.0,
    Range::integer(0.0, 1.0),
    "0 = the whole body; 1 = the quarter x >= 0, y >= 0 with the symmetry planes x = 0 and y = 0 by mirror images of the nodes \
     near them (a quarter of the nodes; energies are reported for the whole body; the forces of weak_form = 0 or 1)",
);

/// The `weak_form` row of the 3-D scenes: 0 the seed's local weak form
/// over test spheres (eq. 10), 1 the nodal Galerkin form
/// (`src/approx/nodal.rs`), 2 the nodal form with gradients that conform to
/// the nodal quadrature at the surfaces (`src/approx/conform.rs`).
pub(crate) const WEAK_FORM: ParamSpec = spec(
    "weak_form",
    "1",
    2.0,
    Range::integer(0.0, 2.0),
    "forces of the MLPG solver: 0 = the seed's local weak form over test spheres (eq. 10), 1 = nodal Galerkin form, \
     the adjoint of the collocated gradients, which conserves momentum and energy, 2 = the nodal form with gradients \
     corrected so that a uniform stress leaves the nodes off the surfaces in equilibrium (whole body only; README, 3-D MLPG) (scheme)",
);

/// The `conform_preconditioner` row of the 3-D scenes: the preconditioner
/// of the conforming correction's conjugate gradients (`weak_form = 2`).
pub(crate) const CONFORM_PRECONDITIONER: ParamSpec = spec(
    "conform_preconditioner",
    "1",
    1.0,
    Range::integer(0.0, 1.0),
    "preconditioner of the conjugate gradients of the conforming correction (weak_form = 2): 0 = Jacobi's (the \
     iterations grow as the spacing shrinks), 1 = Jacobi's plus levels of groups of nodes whose linear functions take \
     the smooth modes, whose iterations do not (README, 3-D MLPG); the two answers differ within the correction's \
     tolerance",
);

/// The `lattice` row of the 3-D scenes: 0 the ring lattice with every
/// layer's nodes on the same radial lines, 1 the staggered lattice (odd
/// layers turned by half a node's angle, `NodeLattice::cylinder_with`).
pub(crate) const LATTICE: ParamSpec = spec(
    "lattice",
    "1",
    1.0,
    Range::integer(0.0, 1.0),
    "node lattice of the rod: 0 = rings with the nodes of every layer on the same radial lines, 1 = staggered, the odd \
     layers turned by half a node's angle so that layers pressed together interleave (README, 3-D MLPG) (scheme)",
);

/// The numerical parameters and the end time: the rows after the material
/// block.
const AFTER: &[ParamSpec] = &[
    spec(
        "particles_radial",
        "1",
        6.0,
        Range::integer(3.0, 60.0),
        "nodes across the radius, axis and mantle included (rings + 1); axial spacing matches",
    ),
    spec(
        "damping",
        "1",
        DAMPING,
        Range::closed(0.0, 0.5),
        "damping ratio at the highest frequency of the stiffness-proportional damping (README, 3-D MLPG)",
    ),
    spec(
        "smoothing_coefficient",
        "1",
        SMOOTHING,
        Range::closed(0.0, 0.5),
        "alpha of the MLPG velocity smoothing toward the MLS approximation at each node (README, 3-D MLPG) (scheme)",
    ),
    SMOOTHING_ORDER_SPEC,
    spec(
        "rebuild_strain",
        "1",
        REBUILD_STRAIN,
        Range::closed(1.0e-4, 0.2),
        "relative motion of neighbours past which the MLPG shapes, test spheres and traction operator are rebuilt",
    ),
    SHIFTING,
    WEAK_FORM,
    CONFORM_PRECONDITIONER,
    SYMMETRY,
    LATTICE,
    END_TIME,
    levels_spec(
        "scheme",
        0,
        SCHEMES,
        "numerical scheme by name, which sets the knobs marked (scheme); a knob set by hand overrides it: \
         0 = large_strain (the validated default), 1 = paper (the seed's MLPG mixed method exactly)",
    ),
];

/// The `shifting` row of the 3-D scenes.
pub(crate) const SHIFTING: ParamSpec = spec(
    "shifting",
    "1",
    0.1,
    Range::closed(0.0, 1.0),
    "node shifting beta: pairs closer than half the spacing push apart by up to beta times the spacing per step; \
     0 = Lagrangian, as the seed (scheme)",
);

/// The seed's MLPG mixed method exactly: the local weak form over test
/// spheres, the order-1 velocity smoothing, Lagrangian nodes on the aligned
/// ring lattice.
pub(crate) const PAPER_3D: Level = Level {
    name: "paper",
    description: "the seed's MLPG mixed method exactly: the local weak form over test spheres (eq. 10), the \
                  order-1 velocity smoothing, Lagrangian nodes on the aligned ring lattice",
    sets: &[
        ("smoothing_coefficient", SMOOTHING),
        ("smoothing_order", 1.0),
        ("shifting", 0.0),
        ("weak_form", 0.0),
        ("lattice", 0.0),
    ],
};

/// The schemes of the 3-D MLPG solver on a rod, by name (the `scheme` row;
/// [`MlpgScheme`] decodes the knobs they set). The first is the default.
pub const SCHEMES: &[Level] = &[
    Level {
        name: "large_strain",
        description: "the validated default: the nodal form with conforming gradients, the order-2 smoothing, \
                      node shifting beta = 0.1, the staggered lattice (whole body only; VALIDATION.md, \
                      \"Right by default\")",
        sets: &[
            ("smoothing_coefficient", SMOOTHING),
            ("smoothing_order", 2.0),
            ("shifting", 0.1),
            ("weak_form", 2.0),
            ("lattice", 1.0),
        ],
    },
    PAPER_3D,
];

choice_tables! {
    BEFORE, AFTER, params_of;
    /// Parameters of the 3-D Taylor impact scene with Johnson-Cook and the
    /// linear EOS (the default; SI units): the `taylor` scene's names and
    /// defaults for the rod and its material, the resolution, and the MLPG
    /// damping, smoothing, rebuild strain and node shifting.
    TAYLOR3D_PARAMS,
    /// The table with bilinear strength and the linear EOS.
    TAYLOR3D_BILINEAR_PARAMS,
    /// The table with Johnson-Cook and Mie-Grüneisen.
    TAYLOR3D_MIE_GRUNEISEN_PARAMS,
    /// The table with bilinear strength and Mie-Grüneisen.
    TAYLOR3D_BILINEAR_MIE_GRUNEISEN_PARAMS,
}

/// The built-in variant `taylor3d-aisi310`: the seed's own 3-D Taylor case
/// (004, section 5.1), the `aisi310_bilinear` preset at 300 m/s. The seed
/// prints the rod as "length 12.7 cm, radius 76.2 cm", which cannot be a
/// Taylor rod; **assumed** here: L0 = 12.7 mm and D0 = 7.62 mm (the
/// misprint read as a length in mm and a diameter in mm). A rigid-plastic
/// estimate stops that rod in about 35 µs; the seed shows its profile at
/// 50 µs, which is the end time.
pub fn variants() -> Vec<(String, Scene)> {
    let mut s = Scene::builtin("taylor3d").expect("taylor3d is a built-in scene");
    s.choose_material(None, None, Some("aisi310_bilinear"))
        .expect("the aisi310_bilinear preset fits the taylor3d scene");
    for (name, v) in [
        ("impact_speed", 300.0),
        ("initial_length", 0.0127),
        ("initial_diameter", 0.00762),
        ("end_time", 50.0e-6),
    ] {
        s.set(name, v).expect("a parameter of taylor3d, in range");
    }
    s.title = "The seed's 3-D Taylor impact (AISI 310, bilinear, 300 m/s): L0 = 12.7 mm, \
               D0 = 7.62 mm (assumed; the seed misprints them), to 50 us"
        .to_string();
    s.reference = Default::default();
    vec![("taylor3d-aisi310".to_string(), s)]
}

param_struct! {
    /// The parameters of a 3-D Taylor run (SI units): those of
    /// `TAYLOR3D_PARAMS`. A run of another material choice takes its
    /// geometry and numerical parameters from here and its material from
    /// the scene's material block; the other material fields then keep
    /// their defaults and are not used.
    Taylor3dParams, TAYLOR3D_PARAMS, {
        impact_speed, initial_length, initial_diameter, density, shear_modulus,
        bulk_modulus, specific_heat, taylor_quinney, jc_a, jc_b, jc_n, jc_c, jc_m,
        melt_temperature, room_temperature, initial_temperature, ref_strain_rate,
        particles_radial, damping, smoothing_coefficient, smoothing_order, rebuild_strain,
        shifting, weak_form, conform_preconditioner, symmetry, lattice, end_time,
    }
}

impl Taylor3dParams {
    /// The parameters of a `taylor3d` scene, any material choice: every
    /// row of its table that is a field here, the others at their defaults.
    pub fn of(scene: &Scene) -> Taylor3dParams {
        let mut p = Taylor3dParams::default();
        for (spec, v) in scene.param_specs().iter().zip(scene.values()) {
            p.set(spec.name, *v);
        }
        p
    }

    /// The `taylor` parameters of the same names (its own defaults for the
    /// rest).
    pub fn taylor(&self) -> TaylorParams {
        let mut p = TaylorParams::default();
        for s in super::taylor::TAYLOR_PARAMS {
            if let Some(v) = self.get(s.name) {
                p.set(s.name, v);
            }
        }
        p
    }

    /// The geometric check of the `taylor` scene (nodes along the axis at
    /// the matched spacing; the material's are
    /// [`MaterialChoice::check_consistency`]).
    pub fn check_consistency(&self) -> crate::Result<()> {
        self.setup()?;
        self.taylor().check_consistency()
    }

    /// The material of the default choice (Johnson-Cook, linear EOS) from
    /// these fields.
    pub fn material(&self) -> Material {
        MaterialChoice::JOHNSON_COOK_LINEAR
            .material(Prefix::None, |name| {
                self.get(name)
                    .ok_or_else(|| crate::Error::Inconsistent(format!("no parameter {name}")))
            })
            .expect("Taylor3dParams has every parameter of Johnson-Cook and the linear EOS")
    }

    /// The numerical scheme, decoded and checked against the symmetry.
    pub fn scheme(&self) -> crate::Result<MlpgScheme> {
        let get = |name: &str| {
            self.get(name)
                .ok_or_else(|| crate::Error::Inconsistent(format!("no parameter {name}")))
        };
        MlpgScheme::decode(get)
    }

    /// The rod and the numerical choices.
    pub(crate) fn setup(&self) -> crate::Result<RodSetup> {
        let mut s = RodSetup::new(
            Cylinder {
                radius: 0.5 * self.initial_diameter,
                length: self.initial_length,
            },
            self.particles_radial as usize - 1,
            self.impact_speed,
            self.end_time,
        );
        s.damping = self.damping;
        s.rebuild_strain = self.rebuild_strain;
        s.quarter = self.symmetry >= 0.5;
        s.scheme = self.scheme()?;
        Ok(s)
    }

    /// The run at the instant of impact, of the default material choice.
    /// Its type is not part of the public API (the tests reach it through
    /// `internals`).
    #[doc(hidden)]
    pub fn build(&self) -> crate::Result<Mlpg3d> {
        self.build_with(self.material())
    }

    /// The run at the instant of impact, of `material` (whose reference
    /// density sets the node masses; not part of the public API, as
    /// [`Taylor3dParams::build`]).
    #[doc(hidden)]
    pub fn build_with(&self, material: Material) -> crate::Result<Mlpg3d> {
        Mlpg3d::new(self.setup()?, material)
    }
}

/// The `taylor` scene of a `taylor3d` scene: the same rod, speed, material
/// choice and constants and end time, for the axisymmetric MSPH solver at
/// `particles_radial` across the radius (its own numerical defaults: the
/// two solvers' other numerical parameters differ in meaning).
pub fn axisymmetric_twin(s: &Scene, particles_radial: f64) -> crate::Result<Scene> {
    let choice = match s.kind().material() {
        Some(c) if s.kind().name() == ROW.name => c,
        _ => {
            return Err(crate::Error::Inconsistent(format!(
                "scene `{}` is not a taylor3d scene",
                s.kind().name()
            )));
        }
    };
    let mut twin = Scene::builtin("taylor")?;
    twin.set_material(choice)?;
    let material = choice.param_specs(Prefix::None);
    for spec in s.param_specs() {
        let shared = BEFORE.iter().any(|b| b.name == spec.name)
            || material.iter().any(|m| m.name == spec.name)
            || spec.name == "end_time";
        if shared {
            twin.set(spec.name, s.get(spec.name)?)?;
        }
    }
    twin.set("particles_radial", particles_radial)?;
    twin.title = format!("{} (axisymmetric MSPH twin)", s.title);
    twin.reference = s.reference.clone();
    Ok(twin)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::budget::{DEFAULT_MEMORY_BUDGET, check_memory_with};

    /// The node count the memory budget estimates is the count a run
    /// builds, for the whole body and the quarter on the aligned and the
    /// staggered lattice, of both 3-D scenes.
    #[test]
    fn the_estimated_nodes_are_the_built_nodes() {
        for (name, across) in [("taylor3d", 4.0), ("taylor3d", 7.0), ("penetration", 3.0)] {
            for (symmetry, lattice) in [(0.0, 0.0), (0.0, 1.0), (1.0, 0.0), (1.0, 1.0)] {
                let mut s = Scene::builtin(name).unwrap();
                s.set("particles_radial", across).unwrap();
                s.set("symmetry", symmetry).unwrap();
                s.set("lattice", lattice).unwrap();
                // The quarter model takes the nodal form.
                s.set("weak_form", 1.0).unwrap();
                let run = crate::Simulation::new(s.clone()).unwrap();
                assert_eq!(
                    s.estimated_nodes(),
                    run.particles() as f64,
                    "{name} at {across} across, symmetry {symmetry}, lattice {lattice}"
                );
            }
        }
    }

    /// A million-node `taylor3d` (34 across: 1 114 477 nodes) is admitted at
    /// the default budget (8 GiB) with the default scheme, and refused
    /// with the seed's test spheres (the scheme `paper`), whose heap per
    /// node is about twice the nodal forms'.
    #[test]
    fn a_million_node_taylor3d_is_admitted_at_the_default_budget() {
        let mut s = Scene::builtin("taylor3d").unwrap();
        s.set("particles_radial", 34.0).unwrap();
        assert_eq!(s.estimated_nodes(), 1_114_477.0);
        check_memory_with(s.estimated_nodes(), mlpg_memory(&s), DEFAULT_MEMORY_BUDGET).unwrap();
        s.set_str("scheme", "paper").unwrap();
        let e = check_memory_with(s.estimated_nodes(), mlpg_memory(&s), DEFAULT_MEMORY_BUDGET)
            .unwrap_err();
        assert_eq!(e.name(), "MemoryBudget");
    }
}
