//! The checks of a restored run against a fresh one of the same
//! parameters.

use super::*;

impl Mlpg3d {
    /// Checks a restored run against `fresh`, a new run of the same
    /// parameters: what follows from them (setup, material, lattice, masses,
    /// first step, damping time, impact energy) must be the same bits, and
    /// every node field must have one finite value per node.
    pub(crate) fn check_restored(&self, fresh: &Mlpg3d) -> std::result::Result<(), String> {
        use crate::solver::shared::json;
        let fixed = |s: &Mlpg3d| {
            json(&(
                &s.setup,
                &s.material,
                (&s.others, &s.group, s.anvil, s.reach, &s.plane, &s.held),
                &s.lattice,
                &s.mass,
                s.clock.dt0,
                s.d_min0,
                s.damping_time,
                s.energy.initial,
            ))
        };
        if fixed(self) != fixed(fresh) {
            return Err("its lattice, masses or material do not follow from its parameters".into());
        }
        let n = fresh.particles();
        let vectors = [
            ("positions", &self.pos),
            ("velocities", &self.vel),
            ("support positions", &self.supports_at),
            ("build positions", &self.built_at),
            ("reference places", &self.reference),
            ("reference places at the build", &self.built_reference),
        ];
        for (what, f) in vectors {
            if f.len() != n || !f.iter().flatten().all(|x| x.is_finite()) {
                return Err(format!("its {what} are not {n} finite vectors"));
            }
        }
        let tensors = [("deviators", &self.dev), ("viscous stresses", &self.visc)];
        for (what, f) in tensors {
            if f.len() != n || !f.iter().flatten().all(|x| x.is_finite()) {
                return Err(format!("its {what} are not {n} finite tensors"));
            }
        }
        // Each with the least physical value.
        let scalars = [
            ("densities", &self.rho, f64::MIN_POSITIVE),
            ("densities at the build", &self.built_rho, f64::MIN_POSITIVE),
            ("pressures", &self.pressure, f64::NEG_INFINITY),
            ("plastic strains", &self.eps_p, 0.0),
            ("temperatures", &self.temp, f64::MIN_POSITIVE),
        ];
        for (what, f, least) in scalars {
            if f.len() != n || !f.iter().all(|&x| x.is_finite() && x >= least) {
                return Err(format!("its {what} are not {n} finite, physical values"));
            }
        }
        if !(self.built_multipliers.is_empty() || self.built_multipliers.len() == n)
            || !self
                .built_multipliers
                .iter()
                .flatten()
                .all(|x| x.is_finite())
        {
            return Err(format!(
                "its multipliers of the conforming correction are not none or {n} finite vectors"
            ));
        }
        if self.contact.len() != n || self.built_contact.len() != n {
            return Err(format!("its contact flags are not {n}"));
        }
        // The anvil holds only the nodes on it, and pushes.
        if self.reaction.len() != n
            || !self
                .reaction
                .iter()
                .zip(&self.contact)
                .all(|(&r, &c)| r.is_finite() && r >= 0.0 && (c || r == 0.0))
        {
            return Err(format!(
                "its anvil reactions are not {n} finite values, at least zero, and zero off the anvil"
            ));
        }
        // The quarter model's nodes stay on their side of the planes, those
        // on a plane on it, with no velocity across it.
        for (i, &on) in self.plane.iter().enumerate() {
            let (x, v) = (self.pos[i], self.vel[i]);
            let off = |bit: u8, d: usize| {
                if on & bit != 0 {
                    x[d] != 0.0 || v[d] != 0.0
                } else {
                    x[d] < 0.0
                }
            };
            if off(mirror::X, 0) || off(mirror::Y, 1) {
                return Err(format!("its node {i} is off its side of a symmetry plane"));
            }
        }
        if self.damaging() && self.clock.steps > 0 && !self.material_state.has_damage() {
            return Err("its damage variables are missing".into());
        }
        self.material_state.check_len(n)?;
        crate::solver::shared::check_restored_clock(
            self.clock.time,
            self.clock.dt,
            self.clock.dt0,
            self.clock.steps,
            &[
                self.min_spacing,
                self.energy.internal,
                self.plastic_work,
                self.energy.lost[LOST_DAMPING],
                self.energy.lost[LOST_CONTACT],
                self.energy.lost[LOST_SMOOTHING],
                self.shift_dissipation,
                self.quiet_since.since().unwrap_or(0.0),
                self.last_release,
            ],
        )?;
        // Finite is not enough: a position of 1e300 overflows the search
        // of the supports, a velocity of 1e300 the energies.
        let bounds = crate::solver::shared::RestoreBounds::new(
            &fresh.pos,
            fresh.vel.iter().map(|v| norm(*v)).fold(0.0, f64::max) + fresh.wave_speed(),
            self.clock.time,
        );
        bounds.speeds("velocities", &self.vel)?;
        for (what, f) in [
            ("positions", &self.pos),
            ("support positions", &self.supports_at),
            ("build positions", &self.built_at),
            ("reference places", &self.reference),
            ("reference places at the build", &self.built_reference),
        ] {
            bounds.places(what, f)?;
        }
        self.material_state.check_cracks(bounds.extent)
    }
}
