//! The checks of a restored Taylor run against a fresh one of the same
//! parameters.

use super::{LOST_CONTACT, LOST_SMOOTHING, TaylorSolver};
use crate::material::Damage;
use crate::solver::shared::json;

impl TaylorSolver {
    /// Checks a restored state against `fresh`, a new run of the same
    /// parameters: what follows from the parameters (lattice, masses,
    /// material, surfaces, first step, impact energy) must be the same bits,
    /// and the evolving fields must have one finite, physical value per
    /// particle. A forged state that passes cannot index out of bounds or
    /// feed NaN into a step.
    pub(crate) fn check_restored(&self, fresh: &TaylorSolver) -> std::result::Result<(), String> {
        let same = |what: &str, a: String, b: String| {
            if a == b {
                Ok(())
            } else {
                Err(format!("its {what} does not follow from its parameters"))
            }
        };
        same("parameters", json(&self.p), json(&fresh.p))?;
        same("material", json(&self.material), json(&fresh.material))?;
        same(
            "lattice",
            json(&(self.nr, self.nz, self.h, self.r0)),
            json(&(fresh.nr, fresh.nz, fresh.h, fresh.r0)),
        )?;
        same("masses", json(&self.mass), json(&fresh.mass))?;
        same(
            "surfaces",
            json(&(&self.mantle, &self.top, &self.face)),
            json(&(&fresh.mantle, &fresh.top, &fresh.face)),
        )?;
        same(
            "first step and impact energy",
            json(&(self.clock.dt0, self.energy.initial)),
            json(&(fresh.clock.dt0, fresh.energy.initial)),
        )?;
        let n = fresh.particles();
        let lens = [
            ("positions", self.pos.len()),
            ("velocities", self.vel.len()),
            ("densities", self.rho.len()),
            ("deviatoric stresses", self.dev.len()),
            ("pressures", self.pressure.len()),
            ("plastic strains", self.eps_p.len()),
            ("temperatures", self.temp.len()),
            ("boundary stresses", self.stress_bc.len()),
            ("contact flags", self.contact.len()),
            ("axis flags", self.on_axis.len()),
        ];
        for (what, len) in lens {
            if len != n {
                return Err(format!("it holds {len} {what} for {n} particles"));
            }
        }
        if self.material_state.has_damage() && matches!(self.material.damage, Damage::None) {
            return Err("it holds damage variables, and its material has no damage model".into());
        }
        self.material_state.check_len(n)?;
        let finite = |what: &str, ok: bool| {
            if ok {
                Ok(())
            } else {
                Err(format!("its {what} are not all finite and in range"))
            }
        };
        let flat = |v: &[[f64; 2]]| v.iter().flatten().all(|x| x.is_finite());
        finite("positions", flat(&self.pos))?;
        finite("velocities", flat(&self.vel))?;
        finite(
            "densities",
            self.rho.iter().all(|&x| x.is_finite() && x > 0.0),
        )?;
        finite(
            "stresses",
            self.dev
                .iter()
                .chain(&self.stress_bc)
                .flatten()
                .chain(&self.pressure)
                .all(|x| x.is_finite()),
        )?;
        finite(
            "plastic strains",
            self.eps_p.iter().all(|&x| x.is_finite() && x >= 0.0),
        )?;
        finite(
            "temperatures",
            self.temp.iter().all(|&x| x.is_finite() && x > 0.0),
        )?;
        self.clock.check_restored(&[
            self.energy.internal,
            self.energy.lost[LOST_SMOOTHING],
            self.energy.lost[LOST_CONTACT],
            self.min_spacing,
            self.quiet_since.since().unwrap_or(0.0),
        ])?;
        // Finite is not enough: a velocity of 1e300 overflows the energies.
        let fastest = |v: &[f64; 2]| (v[0] * v[0] + v[1] * v[1]).sqrt();
        let bounds = crate::solver::shared::RestoreBounds::new(
            &fresh.pos,
            fresh.vel.iter().map(fastest).fold(0.0, f64::max) + fresh.wave_speed(),
            self.clock.time,
        );
        bounds.speeds("velocities", &self.vel)?;
        bounds.places("positions", &self.pos)?;
        self.material_state.check_cracks(bounds.extent)
    }
}
