//! The run's guards and bounds, shared by every solver: the named stops
//! (energy drift, spacing collapse, time step collapse, NaN), the quiet end
//! and its detector ([`QuietEnd`]), and the shifting bounds.

/// Smallest distance between two neighbouring particles (every pair, mirror
/// images included), relative to the initial spacing, below which a run
/// stops with [`crate::Error::SpacingCollapse`]: particles that close no longer
/// resolve the material between them.
pub const SPACING_COLLAPSE_BOUND: f64 = 0.1;

/// Longest shift of a particle in one step, relative to the initial
/// spacing.
pub const SHIFT_CAP: f64 = 0.05;

/// Range of the shifting repulsion, relative to the initial spacing: pairs
/// closer than this push each other apart.
pub const SHIFT_RANGE: f64 = 0.5;

/// Energy error past which a run stops with [`crate::Error::EnergyDrift`], for
/// every solver: 0.1, above the largest error met at any output of runs
/// that finish (7.8 %, a 3-node-across rod's first steps) and below what
/// diverging runs walk through before they stop (README, "Errors and exit
/// status").
pub const ENERGY_ERROR_BOUND: f64 = 0.1;

/// The rod is quiet (at rest though still touching the anvil) once its
/// kinetic energy has stayed at or below this fraction of the impact energy
/// for [`QUIET_TRANSITS`] elastic transits.
pub const QUIET_FRACTION: f64 = 0.01;

/// Length of the quiet window in elastic transits `L0 / Ce`: two, the period
/// of the rod's slowest (free-free) longitudinal mode, so the rod's own
/// ringing cannot pass as rest.
pub const QUIET_TRANSITS: f64 = 2.0;

/// The quiet end of a run, the rest detector every solver of a rod on the
/// anvil shares: the rod is at rest once its kinetic energy has stayed at
/// or below [`QUIET_FRACTION`] of the impact energy for [`QUIET_TRANSITS`]
/// elastic transits (a flange pressed flat on the anvil never leaves it,
/// and the rod rings elastically on it for ever).
///
/// A solver keeps one as a field and saves it as the time since which the
/// run has been quiet, or `null` (serde: the bare option, the format of the
/// `quiet_since` field it replaces), and calls [`QuietEnd::at_rest`] at the
/// end of each step.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(transparent)]
pub struct QuietEnd {
    since: Option<f64>,
}

impl QuietEnd {
    /// Whether the run is at rest at the end of a step at `time` with
    /// `kinetic` energy, out of `initial_energy`: the window
    /// `QUIET_TRANSITS * length / wave_speed` (the rod's length and
    /// elastic wave speed) has passed since the kinetic energy last rose
    /// above [`QUIET_FRACTION`] of the initial energy.
    pub fn at_rest(
        &mut self,
        time: f64,
        kinetic: f64,
        initial_energy: f64,
        length: f64,
        wave_speed: f64,
    ) -> bool {
        if kinetic <= QUIET_FRACTION * initial_energy {
            let since = *self.since.get_or_insert(time);
            let window = QUIET_TRANSITS * length / wave_speed;
            time - since >= window
        } else {
            self.since = None;
            false
        }
    }

    /// The time since which the run has been quiet, if it is.
    pub fn since(&self) -> Option<f64> {
        self.since
    }
}

/// The smallest accepted step, as a fraction of the first step: below it the
/// run stops with [`crate::Error::TimeStepCollapse`].
pub const MIN_DT_FRACTION: f64 = 1e-4;

/// A value as JSON text, to compare restored state with a fresh build bit
/// for bit (serde_json writes every f64 so that it reads back the same).
pub(crate) fn json<T: serde::Serialize>(v: &T) -> String {
    serde_json::to_string(v).unwrap_or_default()
}

/// Refuses a quantity derived from the parameters (a wave speed, a time
/// step, a record interval) that is not a positive finite number, so that no
/// loop can start with a step of zero or a NaN: each parameter can be in its
/// range while a product or quotient of them overflows or underflows.
pub(crate) fn check_derived(name: &str, value: f64, unit: &str) -> crate::Result<()> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(crate::Error::Inconsistent(format!(
            "the {name} derived from the parameters is {value}{unit}, not a positive finite number"
        )))
    }
}

/// Whether `value` is above `bound`, or NaN: a guard written with it stops
/// on a NaN (a plain `value > bound` lets NaN through).
pub(crate) fn above(value: f64, bound: f64) -> bool {
    value.is_nan() || value > bound
}

/// Whether `value` is below `bound`, or NaN: see [`above`].
pub(crate) fn below(value: f64, bound: f64) -> bool {
    value.is_nan() || value < bound
}

/// Stops a run whose smallest neighbour distance, relative to the initial
/// spacing, fell below [`SPACING_COLLAPSE_BOUND`]; `hint` ends the message
/// (a scheme that would help, or nothing).
pub(crate) fn check_spacing(ratio: f64, time: f64, hint: &'static str) -> crate::Result<()> {
    if below(ratio, SPACING_COLLAPSE_BOUND) {
        Err(crate::Error::SpacingCollapse {
            ratio,
            bound: SPACING_COLLAPSE_BOUND,
            time,
            hint,
        })
    } else {
        Ok(())
    }
}

/// Stops a run whose stable step fell below [`MIN_DT_FRACTION`] of the first.
pub(crate) fn check_time_step(dt: f64, dt0: f64, time: f64) -> crate::Result<()> {
    if below(dt, MIN_DT_FRACTION * dt0) {
        Err(crate::Error::TimeStepCollapse {
            dt,
            time,
            min: MIN_DT_FRACTION * dt0,
        })
    } else {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A quiet end saves as the bare option it replaces, in JSON and in
    /// postcard, and reads back.
    #[test]
    fn quiet_end_keeps_the_format_of_its_option() {
        for since in [None, Some(1.25e-5)] {
            let q = QuietEnd { since };
            assert_eq!(json(&q), json(&since));
            let bytes = postcard::to_allocvec(&q).unwrap();
            assert_eq!(bytes, postcard::to_allocvec(&since).unwrap());
            let back: QuietEnd = postcard::from_bytes(&bytes).unwrap();
            assert_eq!(back, q);
            let back: QuietEnd = serde_json::from_str(&json(&since)).unwrap();
            assert_eq!(back, q);
        }
    }

    /// At rest once quiet for the window, the clock of the window restarted
    /// by a rise of the kinetic energy.
    #[test]
    fn quiet_end_waits_for_the_whole_window() {
        // Window: QUIET_TRANSITS * 2 / 1 = 4 (s).
        let at = |q: &mut QuietEnd, t: f64, ke: f64| q.at_rest(t, ke, 100.0, 2.0, 1.0);
        let mut q = QuietEnd::default();
        assert!(!at(&mut q, 1.0, 0.5));
        assert_eq!(q.since(), Some(1.0));
        assert!(!at(&mut q, 4.0, 0.5));
        assert!(!at(&mut q, 4.5, 2.0));
        assert_eq!(q.since(), None);
        assert!(!at(&mut q, 5.0, 1.0));
        assert!(at(&mut q, 9.0, 1.0));
    }
}
