//! The run's guards and bounds, shared by every solver (the axisymmetric
//! and radial MSPH solvers in [`crate::solver`], the 3-D MLPG solver in
//! [`crate::solver::mlpg3d`]): the named stops (energy drift, spacing collapse, time
//! step collapse, NaN), the quiet end and its detector ([`QuietEnd`]), the
//! shifting bounds, and the checks of a restored run's clock and bounds. No
//! solver imports these from another solver's file.

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

/// The clock's getters of a solver, `time()` (s) and `steps()`, and with
/// `dt` also `dt()` (s), over its fields of those names: written once for
/// every solver (the fields stay in each solver's struct, flat in its saved
/// state).
macro_rules! clock_getters {
    () => {
        /// Simulated time (s).
        pub fn time(&self) -> f64 {
            self.time
        }

        /// Steps taken.
        pub fn steps(&self) -> u64 {
            self.steps
        }
    };
    (dt) => {
        $crate::run::clock_getters!();

        /// Current time step (s).
        pub fn dt(&self) -> f64 {
            self.dt
        }
    };
}
pub(crate) use clock_getters;

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

/// Checks the clock of a restored run (the message says what is wrong): a
/// finite time from zero; a positive step no longer than four times the
/// first (the step follows the wave speed, which a run cannot raise
/// fourfold, as that would take the density to a sixteenth; a forged step
/// of seconds would fling the particles across the lattice); steps taken
/// exactly when time has passed; and finite `bookkeeping` (energies, the
/// smallest spacing, ...).
pub(crate) fn check_restored_clock(
    time: f64,
    dt: f64,
    dt0: f64,
    steps: u64,
    bookkeeping: &[f64],
) -> std::result::Result<(), String> {
    if !bookkeeping
        .iter()
        .chain([&time, &dt])
        .all(|x| x.is_finite())
    {
        return Err("its clock and energies are not all finite and in range".into());
    }
    if !(time >= 0.0 && dt > 0.0 && dt <= 4.0 * dt0) {
        return Err("its clock are not all finite and in range".into());
    }
    if (steps == 0) != (time == 0.0) {
        return Err(format!(
            "its step count {steps} does not match its time {time}"
        ));
    }
    Ok(())
}

/// How fast a restored node may move, in units of the fastest speed at the
/// start (the nodes' speed plus the wave speed): a running solver never comes
/// near ten.
pub(crate) const RESTORED_SPEED_FACTOR: f64 = 10.0;

/// The physical bounds of a restored run, from a new run of its parameters:
/// no node faster than [`RESTORED_SPEED_FACTOR`] times the fastest speed at
/// the start, none further from the origin than the bodies' extent plus that
/// speed times the run's time. A forged state of finite but absurd values
/// (a velocity of 1e300, a node a light-year away) is refused by them.
pub(crate) struct RestoreBounds {
    /// Largest coordinate of the bodies at the start (m).
    pub extent: f64,
    speed: f64,
    reach: f64,
}

impl RestoreBounds {
    /// The bounds of a run whose nodes start at `start` with speeds up to
    /// `fastest` (m/s, node speed plus wave speed), restored at `time`.
    pub fn new<const D: usize>(start: &[[f64; D]], fastest: f64, time: f64) -> Self {
        let extent = start.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
        let speed = RESTORED_SPEED_FACTOR * fastest;
        RestoreBounds {
            extent,
            speed,
            reach: extent + speed * time,
        }
    }

    /// Refuses a node faster than the bound.
    pub fn speeds<const D: usize>(&self, what: &str, v: &[[f64; D]]) -> Result<(), String> {
        match v
            .iter()
            .position(|v| above(v.iter().map(|x| x * x).sum::<f64>().sqrt(), self.speed))
        {
            Some(i) => Err(format!(
                "its {what} are not physical: node {i} is faster than {} m/s",
                crate::error::number(self.speed)
            )),
            None => Ok(()),
        }
    }

    /// Refuses a place further out than the bodies can have gone.
    pub fn places<const D: usize>(&self, what: &str, x: &[[f64; D]]) -> Result<(), String> {
        match x
            .iter()
            .position(|x| x.iter().any(|c| above(c.abs(), self.reach)))
        {
            Some(i) => Err(format!(
                "its {what} are not physical: node {i} is further than {} m out",
                crate::error::number(self.reach)
            )),
            None => Ok(()),
        }
    }
}

/// Index and field of the first non-finite value, if any.
pub(crate) fn first_non_finite(fields: &[(&'static str, &[f64])]) -> Option<(&'static str, usize)> {
    fields
        .iter()
        .find_map(|(name, v)| v.iter().position(|x| !x.is_finite()).map(|i| (*name, i)))
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
