//! The check of a restored plate-impact run.

use super::layer::{CellState, Layer};
use super::{LOST_CONTACT, PlateImpact};

impl PlateImpact {
    /// Checks a restored run against `fresh`, a new run of the same
    /// parameters: made by a run of the same setup (plates, cells, masses,
    /// end time: its digest), the same impact energy, finite
    /// fields, cells of positive length, speeds and cracks a run can reach,
    /// and a clock within the run.
    pub fn check_restored(&self, fresh: &PlateImpact) -> std::result::Result<(), String> {
        // The setup is the scene's (a restored run is built from it), and
        // the state one that a run of it made.
        if self.state.setup_digest != fresh.state.setup_digest {
            return Err(crate::solver::shared::NOT_ITS_SETUP.into());
        }
        if self.state.energy.initial.to_bits() != fresh.state.energy.initial.to_bits() {
            return Err("its impact energy does not follow from its parameters".into());
        }
        let (nodes, cells) = (fresh.state.x.len(), fresh.state.cells.len());
        for (what, f, n) in [
            ("positions", &self.state.x, nodes),
            ("velocities", &self.state.v, nodes),
            ("stresses", &self.state.stress, cells),
            ("specific energies", &self.state.specific_energy, cells),
        ] {
            if f.len() != n || !f.iter().all(|x| x.is_finite()) {
                return Err(format!("its {what} are not {n} finite numbers"));
            }
        }
        if self.state.cells.len() != cells {
            return Err(format!(
                "it holds {} cell states for {cells} cells",
                self.state.cells.len()
            ));
        }
        // The fastest a run can move: the impact speed plus twice the
        // fastest wave, with room.
        let c_max = self
            .setup
            .layers
            .iter()
            .filter_map(|l| l.sound_speeds().ok())
            .map(|(c, _)| c)
            .fold(0.0, f64::max);
        let bound = 10.0 * (self.setup.impact_speed.abs() + c_max);
        if self.state.v.iter().any(|v| v.abs() > bound) {
            return Err(format!("a node moves faster than {bound} m/s"));
        }
        let thickness: f64 = fresh.setup.length0.iter().sum();
        for c in 0..cells {
            let (a, b) = self.nodes(c);
            let length = self.state.x[b] - self.state.x[a];
            // NaN fails the range (the positions are finite, checked above).
            if !(length > 0.0 && length <= 100.0 * self.setup.length0[c]) {
                return Err(format!("its cell {c} has an impossible length"));
            }
            let ok = match (&self.state.cells[c], self.layer(c)) {
                (CellState::Ceramic(p), Layer::Ceramic(_)) => {
                    p.crack_size.is_finite()
                        && p.crack_size > 0.0
                        && p.crack_size <= thickness
                        && (0.0..1.0).contains(&p.porosity)
                        && p.pressure.is_finite()
                        && p.plastic_strain.is_finite()
                        && p.deviator
                            .iter()
                            .chain(&p.elastic_strain)
                            .all(|x| x.is_finite())
                }
                (CellState::Jh2(p), Layer::Jh2(_)) => {
                    p.pressure.is_finite()
                        && p.plastic_strain.is_finite()
                        && p.plastic_strain >= 0.0
                        && (0.0..=1.0).contains(&p.damage)
                        && p.bulking.is_finite()
                        && p.density.is_finite()
                        && p.density > 0.0
                        && p.deviator.iter().all(|x| x.is_finite())
                }
                (CellState::Solid(p, _), Layer::Solid(_)) => {
                    p.pressure.is_finite()
                        && p.plastic_strain.is_finite()
                        && p.temperature.is_finite()
                        && p.deviator.iter().all(|x| x.is_finite())
                }
                _ => false,
            };
            if !ok {
                return Err(format!(
                    "its cell {c}'s material state is not one a run can reach"
                ));
            }
        }
        let clock = self.state.clock.time.is_finite()
            && self.state.clock.time >= 0.0
            && self.state.clock.time <= self.setup.end_time
            && ((self.state.clock.steps == 0) == (self.state.clock.time == 0.0));
        if !clock {
            return Err(format!(
                "its clock (t = {}, {} steps) is not valid",
                self.state.clock.time, self.state.clock.steps
            ));
        }
        let r = self.state.reading;
        let finite = r.peak.is_finite()
            && r.pullback_minimum.is_finite()
            && r.steepest.is_finite()
            && r.steepest >= 0.0
            && r.last.abs() <= bound
            && r.phase <= 2
            && r.arrival
                .is_none_or(|t| t.is_finite() && t <= self.state.clock.time)
            && r.precursor
                .is_none_or(|u| u.is_finite() && u.abs() <= bound)
            && r.peak.abs() <= bound
            && r.pullback_minimum.abs() <= bound
            && self.state.energy.lost[LOST_CONTACT].is_finite()
            && self.state.energy.lost[LOST_CONTACT] >= 0.0
            && self.state.spall.is_none_or(|(d, t)| {
                d >= 0.0 && d <= thickness && t >= 0.0 && t <= self.state.clock.time
            });
        if !finite {
            return Err("its free-surface reading or spall is not one a run can reach".into());
        }
        Ok(())
    }
}
