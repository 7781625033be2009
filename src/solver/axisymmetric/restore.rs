//! The checks of a restored Taylor run against a fresh one of the same
//! parameters.

use super::{LOST_CONTACT, LOST_SMOOTHING, TaylorSolver};
use crate::material::Damage;
use crate::solver::shared::json;

/// The fields of the setup ([`super::SetupAxi`]), which a saved state
/// does not hold, and what each is.
const SETUP_KEYS: &[(&str, &str)] = &[
    ("p", "its parameters"),
    ("rod", "its rod's parameters"),
    ("scheme", "its scheme"),
    ("material", "its material"),
    ("nr", "its lattice"),
    ("nz", "its lattice"),
    ("h", "its lattice"),
    ("r0", "its lattice"),
    ("mass", "its masses"),
    ("mantle", "its surfaces"),
    ("top", "its surfaces"),
    ("face", "its surfaces"),
];

impl TaylorSolver {
    /// Reads a saved state (of [`super::StateAxi`]) into this run, a new
    /// run of its scene, unchecked ([`TaylorSolver::check_restored`]). A
    /// state that holds a part of the setup is refused, naming it.
    pub(crate) fn load_state(
        &mut self,
        saved: crate::model::SavedSolver<'_>,
    ) -> std::result::Result<(), String> {
        self.state = crate::solver::shared::read_state(saved, SETUP_KEYS)?;
        Ok(())
    }

    /// Checks a restored state against `fresh`, a new run of the same
    /// parameters: the state made by a run of the same setup (its digest),
    /// what it holds that follows from the parameters (first step, impact
    /// energy) the same bits,
    /// and the evolving fields must have one finite, physical value per
    /// particle. A forged state that passes cannot index out of bounds or
    /// feed NaN into a step.
    pub(crate) fn check_restored(&self, fresh: &TaylorSolver) -> std::result::Result<(), String> {
        if self.state.setup_digest != fresh.state.setup_digest {
            return Err(crate::solver::shared::NOT_ITS_SETUP.into());
        }
        let same = |what: &str, a: String, b: String| {
            if a == b {
                Ok(())
            } else {
                Err(format!("its {what} does not follow from its parameters"))
            }
        };
        // The setup is the scene's (a restored run is built from it), and the
        // state one that a run of it made; what the state holds that follows
        // from the parameters must be its bits.
        same(
            "first step and impact energy",
            json(&(self.state.clock.dt0, self.state.energy.initial)),
            json(&(fresh.state.clock.dt0, fresh.state.energy.initial)),
        )?;
        let n = fresh.particles();
        let lens = [
            ("positions", self.state.pos.len()),
            ("velocities", self.state.vel.len()),
            ("densities", self.state.rho.len()),
            ("deviatoric stresses", self.state.dev.len()),
            ("pressures", self.state.pressure.len()),
            ("plastic strains", self.state.eps_p.len()),
            ("temperatures", self.state.temp.len()),
            ("boundary stresses", self.state.stress_bc.len()),
            ("contact flags", self.state.contact.len()),
            ("axis flags", self.state.on_axis.len()),
        ];
        for (what, len) in lens {
            if len != n {
                return Err(format!("it holds {len} {what} for {n} particles"));
            }
        }
        if self.state.material_state.has_damage()
            && matches!(self.setup.material.damage, Damage::None)
        {
            return Err("it holds damage variables, and its material has no damage model".into());
        }
        self.state.material_state.check_len(n)?;
        let finite = |what: &str, ok: bool| {
            if ok {
                Ok(())
            } else {
                Err(format!("its {what} are not all finite and in range"))
            }
        };
        let flat = |v: &[[f64; 2]]| v.iter().flatten().all(|x| x.is_finite());
        finite("positions", flat(&self.state.pos))?;
        finite("velocities", flat(&self.state.vel))?;
        finite(
            "densities",
            self.state.rho.iter().all(|&x| x.is_finite() && x > 0.0),
        )?;
        finite(
            "stresses",
            self.state
                .dev
                .iter()
                .chain(&self.state.stress_bc)
                .flatten()
                .chain(&self.state.pressure)
                .all(|x| x.is_finite()),
        )?;
        finite(
            "plastic strains",
            self.state.eps_p.iter().all(|&x| x.is_finite() && x >= 0.0),
        )?;
        finite(
            "temperatures",
            self.state.temp.iter().all(|&x| x.is_finite() && x > 0.0),
        )?;
        self.state.clock.check_restored(&[
            self.state.energy.internal,
            self.state.energy.lost[LOST_SMOOTHING],
            self.state.energy.lost[LOST_CONTACT],
            self.state.min_spacing,
            self.state.quiet_since.since().unwrap_or(0.0),
        ])?;
        // Finite is not enough: a velocity of 1e300 overflows the energies.
        let fastest = |v: &[f64; 2]| (v[0] * v[0] + v[1] * v[1]).sqrt();
        let bounds = crate::solver::shared::RestoreBounds::new(
            &fresh.state.pos,
            fresh.state.vel.iter().map(fastest).fold(0.0, f64::max) + fresh.wave_speed(),
            self.state.clock.time,
        );
        bounds.speeds("velocities", &self.state.vel)?;
        bounds.places("positions", &self.state.pos)?;
        self.state.material_state.check_cracks(bounds.extent)
    }
}
