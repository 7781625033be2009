//! The setup of a Taylor run: its parameters ([`TaylorParams`], which the
//! solver keeps in its setup, not in its saved state; their table, defaults
//! and ranges are the `taylor` scene's), and the rod on its (R, Z) lattice
//! at the instant of impact, of the material they describe.

use super::scheme::MsphScheme;
use super::{PipelineAxi, RodAxi, SetupAxi, StateAxi, TaylorSolver};
use crate::error::{Error, Result};
use crate::material::choice::{MaterialChoice, Prefix};
use crate::material::{Material, MaterialState};
use crate::solver::axisymmetric::boundary::Surface;
use crate::solver::setup_struct;
use crate::solver::shared::{Clock, EnergyBook, QuietEnd, check_derived};

setup_struct! {
    /// The parameters of a Taylor run that the solver keeps (SI units):
    /// those of the `taylor` scene's table. A run of another material
    /// choice takes its geometry, numerical parameters, density and initial
    /// temperature from here and its material from the scene's material
    /// block (`TaylorSolver::with_material`); the other material fields
    /// then keep their defaults and are not used.
    TaylorParams, with set {
        impact_speed: "speed of the rod toward the anvil",
        initial_length: "rod length L0",
        initial_diameter: "rod diameter D0",
        density: "reference mass density",
        shear_modulus: "shear modulus mu",
        bulk_modulus: "bulk modulus K of the linear EOS P = K(rho/rho0 - 1)",
        specific_heat: "specific heat C",
        taylor_quinney: "Taylor-Quinney coefficient: the fraction of plastic work that becomes heat",
        jc_a: "Johnson-Cook a (initial yield stress)",
        jc_b: "Johnson-Cook b (hardening modulus)",
        jc_n: "Johnson-Cook n (hardening exponent)",
        jc_c: "Johnson-Cook c (strain-rate sensitivity)",
        jc_m: "Johnson-Cook m (thermal softening exponent)",
        melt_temperature: "melting temperature T_M",
        room_temperature: "room temperature T_room",
        initial_temperature: "rod temperature at impact",
        ref_strain_rate: "reference strain rate of Johnson-Cook",
        particles_radial: "particles across the radius, axis and mantle included; axial spacing matches",
        smoothing_ratio: "smoothing length h divided by the particle spacing",
        smoothing_coefficient: "alpha_cs of the conservative smoothing (3.23)",
        smoothing_order: "velocity and density smoothing: 1 = the paper's (3.23), 2 = its bi-Laplacian",
        shifting: "particle shifting beta (0 = Lagrangian particles)",
        end_time: "latest simulated time",
    }
}

impl TaylorSolver {
    /// Sets up the rod at the instant of impact, of the material the
    /// parameters describe ([`TaylorSolver::material_of`]). `p` must be
    /// validated.
    pub fn new(p: TaylorParams) -> Result<Self> {
        Self::with_material(p, Self::material_of(&p))
    }

    /// The material of the parameters: Johnson-Cook strength, the linear
    /// equation of state, no damage (the material block of
    /// [`MaterialChoice::JOHNSON_COOK_LINEAR`] read from `p`).
    pub fn material_of(p: &TaylorParams) -> Material {
        MaterialChoice::JOHNSON_COOK_LINEAR
            .material(Prefix::None, |name| {
                p.get(name)
                    .ok_or_else(|| Error::Inconsistent(format!("no parameter {name}")))
            })
            .expect("TaylorParams has every parameter of Johnson-Cook and the linear EOS")
    }

    /// Sets up the rod at the instant of impact, of `material`: its
    /// constants take the place of the material parameters of `p` (all but
    /// `density`, which must be the reference density of its equation of
    /// state, as the lattice masses use it). `p` must be validated.
    pub fn with_material(p: TaylorParams, material: Material) -> Result<Self> {
        material.validate()?;
        if material.eos.reference_density() != Some(p.density) {
            return Err(Error::Inconsistent(format!(
                "the reference density of the equation of state ({:?} kg/m3) is not the rod's \
                 density {} kg/m3",
                material.eos.reference_density(),
                p.density
            )));
        }
        let nr = p.particles_radial as usize;
        let r0 = 0.5 * p.initial_diameter;
        let d = r0 / (nr - 1) as f64;
        let nz = (p.initial_length / d).round() as usize + 1;
        let dz = p.initial_length / (nz - 1) as f64;
        let h = p.smoothing_ratio * d;
        let n = nr * nz;
        let mut pos = Vec::with_capacity(n);
        let mut mass = Vec::with_capacity(n);
        for k in 0..nz {
            for i in 0..nr {
                let r = i as f64 * d;
                let r_in = (r - 0.5 * d).max(0.0);
                let r_out = (r + 0.5 * d).min(r0);
                let z_len = if k == 0 || k == nz - 1 { 0.5 * dz } else { dz };
                let vol = std::f64::consts::PI * (r_out * r_out - r_in * r_in) * z_len;
                pos.push([r, k as f64 * dz]);
                mass.push(p.density * vol);
            }
        }
        let mantle = Surface {
            particles: (0..nz).map(|k| k * nr + nr - 1).collect(),
            sign: 1.0,
        };
        let top = Surface {
            particles: (0..nr).map(|i| (nz - 1) * nr + i).collect(),
            sign: -1.0,
        };
        let face = Surface {
            particles: (0..nr).collect(),
            sign: 1.0,
        };
        let vel = vec![[0.0, -p.impact_speed]; n];
        let contact = (0..n).map(|i| i < nr).collect();
        let total_mass: f64 = mass.iter().sum();
        let mut s = TaylorSolver {
            state: StateAxi {
                setup_digest: 0,
                vel,
                rho: vec![p.density; n],
                dev: vec![[0.0; 4]; n],
                pressure: vec![0.0; n],
                eps_p: vec![0.0; n],
                temp: vec![p.initial_temperature; n],
                stress_bc: vec![[0.0; 4]; n],
                contact,
                on_axis: (0..n).map(|i| i.is_multiple_of(nr)).collect(),
                material_state: MaterialState::default(),
                pos,
                clock: Clock::default(),
                energy: EnergyBook::new(0.5 * total_mass * p.impact_speed * p.impact_speed),
                at_rest: false,
                quiet_since: QuietEnd::default(),
                min_spacing: 1.0,
            },
            setup: SetupAxi {
                rod: RodAxi::of(&p),
                scheme: MsphScheme::of(&p),
                material,
                nr,
                nz,
                h,
                r0,
                mass,
                mantle,
                top,
                face,
            },
            pipe: PipelineAxi::default(),
        };
        check_derived("wave speed", s.wave_speed(), " m/s")?;
        s.state.clock = Clock::start(s.stable_dt());
        check_derived("time step", s.state.clock.dt, " s")?;
        s.state.setup_digest = s.setup.digest();
        Ok(s)
    }
}
