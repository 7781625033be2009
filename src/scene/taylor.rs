//! The `taylor` scene: a rod of 4340 steel striking a rigid smooth anvil
//! (House et al. test 7 by default), with Johnson-Cook strength, the linear
//! EOS, adiabatic heating, a rigid smooth anvil and a traction-free mantle and
//! top.

use super::Scene;
use super::params::{Range, param_table};
use super::registry::{FmuIdentity, SceneRow, restore};
use crate::observe::TAYLOR_OBSERVABLES;
use crate::solver::axisymmetric::TaylorSolver;

/// The registry row of the `taylor` scene.
pub static ROW: SceneRow = SceneRow {
    name: "taylor",
    title: "Taylor impact, House et al. test 7 (4340 steel, 181 m/s)",
    params: TAYLOR_PARAMS,
    observables: TAYLOR_OBSERVABLES,
    reference: || super::table1::Table1Row::all()[6].reference(),
    variants: super::table1::variants,
    check: |s| TaylorParams::from_values(s.values()).check_consistency(),
    build: |s: &Scene| {
        Ok(Box::new(TaylorSolver::new(TaylorParams::from_values(
            s.values(),
        ))?))
    },
    restore: restore::<TaylorSolver>,
    fmu: Some(FmuIdentity {
        model_identifier: "TaylorImpact",
        model_name: "TaylorImpact",
        description: "Taylor rod impact on a rigid anvil: axisymmetric Modified SPH (MSPH, Batra & Zhang 2008) \
                      with Johnson-Cook thermo-viscoplasticity; defaults are House et al. (1995) test 7 on 4340 steel",
    }),
};

param_table! {
    /// Parameters of the Taylor impact scene (SI units). Defaults are House et
    /// al. test 7 with the 4340 steel constants of Batra & Zhang (2008).
    TaylorParams, TAYLOR_PARAMS {
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
        particles_radial: "1" = 20.0, Range::integer(3.0, 200.0),
            "particles across the radius, axis and mantle included; axial spacing matches";
        smoothing_ratio: "1" = 1.5, Range::closed(0.5, 4.0),
            "smoothing length h divided by the particle spacing";
        smoothing_coefficient: "1" = 0.2, Range::closed(0.0, 0.5),
            "alpha_cs of the conservative smoothing (3.23)";
        smoothing_order: "1" = 1.0, Range::integer(1.0, 2.0),
            "velocity smoothing: 1 = the paper's (3.23), 2 = its bi-Laplacian (large strain)";
        shifting: "1" = 0.0, Range::closed(0.0, 1.0),
            "particle shifting beta: pairs closer than half the spacing push apart by up to beta times the spacing per step; 0 = Lagrangian, as the paper";
        end_time: "s" = 400.0e-6, Range::closed(1.0e-9, 1.0),
            "latest simulated time; the run normally ends earlier, when the rod is at rest";
    }
}

impl TaylorParams {
    /// Checks the cross-parameter constraints that single ranges cannot express.
    pub fn check_consistency(&self) -> crate::Result<()> {
        use crate::Error::Inconsistent;
        if self.melt_temperature <= self.room_temperature {
            return Err(Inconsistent(format!(
                "melt_temperature = {} K must exceed room_temperature = {} K",
                self.melt_temperature, self.room_temperature
            )));
        }
        if self.initial_temperature >= self.melt_temperature {
            return Err(Inconsistent(format!(
                "initial_temperature = {} K must be below melt_temperature = {} K",
                self.initial_temperature, self.melt_temperature
            )));
        }
        let n = self.particles_radial;
        let axial = (self.initial_length / (0.5 * self.initial_diameter / (n - 1.0))).round() + 1.0;
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
