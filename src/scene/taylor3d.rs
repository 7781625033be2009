//! The `taylor3d` scene: House et al. test 7 in 3-D by the MLPG mixed
//! method (seed 004, [`crate::mlpg`]): a rod of 4340 steel on the ring
//! lattice striking a rigid smooth anvil, with the `taylor` scene's
//! parameter and observable names (its material from the same
//! [`TaylorSolver::material_of`]), `particles_radial` nodes across the
//! radius (axis and mantle included: `particles_radial − 1` rings, the
//! spacing of a `taylor` run with the same value), and the MLPG solver's
//! damping ratio.

use super::Scene;
use super::params::{Range, param_table};
use super::registry::{SceneRow, no_variants, restore};
use super::taylor::{TAYLOR_PARAMS, TaylorParams};
use crate::mlpg::solver::{DAMPING, Mlpg3d, REBUILD_STRAIN, RodSetup, SMOOTHING};
use crate::mlpg::{Cylinder, lattice::NodeLattice};
use crate::observe::TAYLOR3D_OBSERVABLES;
use crate::solver::axisymmetric::TaylorSolver;

/// The registry row of the `taylor3d` scene.
pub static ROW: SceneRow = SceneRow {
    name: "taylor3d",
    title: "Taylor impact in 3-D by MLPG, House et al. test 7 (4340 steel, 181 m/s)",
    params: TAYLOR3D_PARAMS,
    material: None,
    observables: TAYLOR3D_OBSERVABLES,
    reference: || super::table1::Table1Row::all()[6].reference(),
    variants: no_variants,
    check: |s| Taylor3dParams::from_values(s.values()).check_consistency(),
    build: |s: &Scene| Ok(Box::new(Taylor3dParams::from_values(s.values()).build()?)),
    restore: restore::<Mlpg3d>,
    fmu: Some(super::registry::FmuIdentity {
        model_identifier: "Taylor3dImpact",
        model_name: "Taylor3dImpact",
        description: "Taylor rod impact on a rigid anvil in 3-D: the MLPG mixed method (Han, Liu, Rajendran & Atluri) \
                      with Johnson-Cook thermo-viscoplasticity; defaults are House et al. (1995) test 7 on 4340 steel",
    }),
};

param_table! {
    /// Parameters of the 3-D Taylor impact scene (SI units): the `taylor`
    /// scene's names and defaults for the rod and its material, the
    /// resolution, and the MLPG damping.
    Taylor3dParams, TAYLOR3D_PARAMS {
        impact_speed: "m/s" = 181.0, Range::closed(0.01, 2000.0),
            "speed of the rod toward the anvil";
        initial_length: "m" = 0.03797, Range::closed(1.0e-4, 10.0),
            "rod length L0";
        initial_diameter: "m" = 0.007595, Range::closed(1.0e-4, 10.0),
            "rod diameter D0";
        density: "kg/m3" = 7830.0, Range::closed(100.0, 1.0e5),
            "reference mass density";
        shear_modulus: "Pa" = 82.9e9, Range::closed(1.0e6, 1.0e14),
            "shear modulus mu";
        bulk_modulus: "Pa" = 169.1e9, Range::closed(1.0e6, 1.0e15),
            "bulk modulus K of the linear EOS P = K(rho/rho0 - 1)";
        specific_heat: "J/(kg.K)" = 460.0, Range::closed(1.0, 1.0e5),
            "specific heat C";
        taylor_quinney: "1" = 1.0, Range::closed(0.0, 1.0),
            "Taylor-Quinney coefficient: the fraction of plastic work that becomes heat";
        jc_a: "Pa" = 792.0e6, Range::closed(0.0, 1.0e11),
            "Johnson-Cook a (initial yield stress)";
        jc_b: "Pa" = 510.0e6, Range::closed(0.0, 1.0e11),
            "Johnson-Cook b (hardening modulus)";
        jc_n: "1" = 0.26, Range::open_closed(0.0, 5.0),
            "Johnson-Cook n (hardening exponent)";
        jc_c: "1" = 0.014, Range::closed(0.0, 1.0),
            "Johnson-Cook c (strain-rate sensitivity)";
        jc_m: "1" = 1.03, Range::open_closed(0.0, 10.0),
            "Johnson-Cook m (thermal softening exponent)";
        melt_temperature: "K" = 1293.0, Range::closed(1.0, 1.0e5),
            "melting temperature T_M";
        room_temperature: "K" = 293.0, Range::closed(1.0, 1.0e5),
            "room temperature T_room";
        initial_temperature: "K" = 293.0, Range::closed(1.0, 1.0e5),
            "rod temperature at impact";
        ref_strain_rate: "1/s" = 1.0, Range::closed(1.0e-6, 1.0e12),
            "reference strain rate of Johnson-Cook";
        particles_radial: "1" = 6.0, Range::integer(3.0, 60.0),
            "nodes across the radius, axis and mantle included (rings + 1); axial spacing matches";
        damping: "1" = DAMPING, Range::closed(0.0, 0.5),
            "damping ratio at the highest frequency of the stiffness-proportional damping (README, 3-D MLPG)";
        smoothing_coefficient: "1" = SMOOTHING, Range::closed(0.0, 0.5),
            "alpha of the MLPG velocity smoothing toward the MLS approximation at each node (README, 3-D MLPG)";
        rebuild_strain: "1" = REBUILD_STRAIN, Range::closed(1.0e-4, 0.2),
            "relative motion of neighbours past which the MLPG shapes, test spheres and traction operator are rebuilt";
        end_time: "s" = 400.0e-6, Range::closed(1.0e-9, 1.0),
            "latest simulated time; the run normally ends earlier, when the rod is at rest";
    }
}

impl Taylor3dParams {
    /// The `taylor` parameters of the same names (its own defaults for the
    /// rest), from which the material and the checks follow.
    pub fn taylor(&self) -> TaylorParams {
        let mut p = TaylorParams::default();
        for s in TAYLOR_PARAMS {
            if let Some(v) = self.get(s.name) {
                p.set(s.name, v);
            }
        }
        p
    }

    /// The `taylor` scene's cross-parameter checks (temperatures, nodes
    /// along the axis at the matched spacing).
    pub fn check_consistency(&self) -> crate::Result<()> {
        let taylor = self.taylor();
        // The material's (melt above room and initial temperature), as the
        // `taylor` row checks its choice's.
        crate::material::choice::MaterialChoice::JOHNSON_COOK_LINEAR
            .check_consistency(crate::material::choice::Prefix::None, |n| {
                Ok(taylor.get(n).unwrap_or(f64::NAN))
            })?;
        taylor.check_consistency()
    }

    /// The rod and the numerical choices.
    pub fn setup(&self) -> RodSetup {
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
        s.smoothing = self.smoothing_coefficient;
        s
    }

    /// The run at the instant of impact.
    pub fn build(&self) -> crate::Result<Mlpg3d> {
        Mlpg3d::new(self.setup(), TaylorSolver::material_of(&self.taylor()))
    }

    /// The lattice the run would use.
    pub fn lattice(&self) -> NodeLattice {
        let s = self.setup();
        NodeLattice::cylinder(s.cylinder, s.rings)
    }
}
