//! The checks of a restored run against a fresh one of the same
//! parameters.

use super::LOST_CONTACT;
use super::LOST_DAMPING;
use super::LOST_SMOOTHING;
use super::util::norm;
use crate::approx::mirror;
use crate::solver::mlpg3d::Mlpg3d;
/// The fields of the setup ([`Setup3d`]), which a saved state does not
/// hold, and what each is.
const SETUP_KEYS: &[(&str, &str)] = &[
    ("setup", "the rod's setup"),
    ("material", "its material"),
    ("lattice", "its lattice"),
    ("others", "its bodies"),
    ("group", "its bodies' nodes"),
    ("anvil", "its anvil"),
    ("reach", "its contact reach"),
    ("mass", "its masses"),
    ("plane", "its symmetry planes"),
    ("held", "its held nodes"),
    ("d_min0", "its first spacing"),
    ("damping_time", "its damping time"),
];

impl Mlpg3d {
    /// Reads a saved state (of [`State3d`]) into this run, a new run of its
    /// scene, unchecked ([`Mlpg3d::check_restored`]); the geometry is
    /// rebuilt at the next step from the state's record of the last build.
    /// A state that holds a part of the setup is refused, naming it.
    pub(crate) fn load_state(
        &mut self,
        saved: crate::model::SavedSolver<'_>,
    ) -> std::result::Result<(), String> {
        self.state = crate::solver::shared::read_state(saved, SETUP_KEYS)?;
        self.pipe.geometry = None;
        // Every rank reads the same state: whole on each.
        self.pipe.halo.whole();
        self.pipe.halo.forget();
        Ok(())
    }

    /// Checks a restored run against `fresh`, a new run of the same
    /// parameters: what the state holds that follows from them (the first
    /// step, the impact energy) must be the same bits, and every node field
    /// must have one finite value per node of the setup.
    pub(crate) fn check_restored(&self, fresh: &Mlpg3d) -> std::result::Result<(), String> {
        use crate::solver::shared::json;
        // The setup is the scene's (a restored run is built from it), and
        // the state must be one that a run of this setup made.
        if self.state.setup_digest != fresh.state.setup_digest {
            return Err(crate::solver::shared::NOT_ITS_SETUP.into());
        }
        // What the state holds that follows from the parameters: its bits.
        let fixed = |s: &Mlpg3d| json(&(s.state.clock.dt0, s.state.energy.initial));
        if fixed(self) != fixed(fresh) {
            return Err("its lattice, masses or material do not follow from its parameters".into());
        }
        let n = fresh.particles();
        let vectors = [
            ("positions", &self.state.pos),
            ("velocities", &self.state.vel),
            ("support positions", &self.state.supports_at),
            ("build positions", &self.state.built_at),
            ("reference places", &self.state.reference),
            ("reference places at the build", &self.state.built_reference),
        ];
        for (what, f) in vectors {
            if f.len() != n || !f.iter().flatten().all(|x| x.is_finite()) {
                return Err(format!("its {what} are not {n} finite vectors"));
            }
        }
        let tensors = [
            ("deviators", &self.state.dev),
            ("viscous stresses", &self.state.visc),
        ];
        for (what, f) in tensors {
            if f.len() != n || !f.iter().flatten().all(|x| x.is_finite()) {
                return Err(format!("its {what} are not {n} finite tensors"));
            }
        }
        // Each with the least physical value.
        let scalars = [
            ("densities", &self.state.rho, f64::MIN_POSITIVE),
            (
                "densities at the build",
                &self.state.built_rho,
                f64::MIN_POSITIVE,
            ),
            ("pressures", &self.state.pressure, f64::NEG_INFINITY),
            ("plastic strains", &self.state.eps_p, 0.0),
            ("temperatures", &self.state.temp, f64::MIN_POSITIVE),
        ];
        for (what, f, least) in scalars {
            if f.len() != n || !f.iter().all(|&x| x.is_finite() && x >= least) {
                return Err(format!("its {what} are not {n} finite, physical values"));
            }
        }
        if !(self.state.built_multipliers.is_empty() || self.state.built_multipliers.len() == n)
            || !self
                .state
                .built_multipliers
                .iter()
                .flatten()
                .all(|x| x.is_finite())
        {
            return Err(format!(
                "its multipliers of the conforming correction are not none or {n} finite vectors"
            ));
        }
        if self.state.contact.len() != n || self.state.built_contact.len() != n {
            return Err(format!("its contact flags are not {n}"));
        }
        // The anvil holds only the nodes on it, and pushes.
        if self.state.reaction.len() != n
            || !self
                .state
                .reaction
                .iter()
                .zip(&self.state.contact)
                .all(|(&r, &c)| r.is_finite() && r >= 0.0 && (c || r == 0.0))
        {
            return Err(format!(
                "its anvil reactions are not {n} finite values, at least zero, and zero off the anvil"
            ));
        }
        // The quarter model's nodes stay on their side of the planes, those
        // on a plane on it, with no velocity across it.
        for (i, &on) in self.setup.plane.iter().enumerate() {
            let (x, v) = (self.state.pos[i], self.state.vel[i]);
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
        if self.setup.damaging()
            && self.state.clock.steps > 0
            && !self.state.material_state.has_damage()
        {
            return Err("its damage variables are missing".into());
        }
        self.state.material_state.check_len(n)?;
        crate::solver::shared::check_restored_clock(
            self.state.clock.time,
            self.state.clock.dt,
            self.state.clock.dt0,
            self.state.clock.steps,
            &[
                self.state.min_spacing,
                self.state.energy.internal,
                self.state.plastic_work,
                self.state.energy.lost[LOST_DAMPING],
                self.state.energy.lost[LOST_CONTACT],
                self.state.energy.lost[LOST_SMOOTHING],
                self.state.shift_dissipation,
                self.state.quiet_since.since().unwrap_or(0.0),
                self.state.last_release,
            ],
        )?;
        // Finite is not enough: a position of 1e300 overflows the search
        // of the supports, a velocity of 1e300 the energies.
        let bounds = crate::solver::shared::RestoreBounds::new(
            &fresh.state.pos,
            fresh.state.vel.iter().map(|v| norm(*v)).fold(0.0, f64::max) + fresh.wave_speed(),
            self.state.clock.time,
        );
        bounds.speeds("velocities", &self.state.vel)?;
        for (what, f) in [
            ("positions", &self.state.pos),
            ("support positions", &self.state.supports_at),
            ("build positions", &self.state.built_at),
            ("reference places", &self.state.reference),
            ("reference places at the build", &self.state.built_reference),
        ] {
            bounds.places(what, f)?;
        }
        self.state.material_state.check_cracks(bounds.extent)
    }
}
