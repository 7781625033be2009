//! The clock of a run: simulated time, steps taken, the current step and
//! the first one. One struct for every solver, saved as one object.

use super::guards::check_time_step;
use super::restore::check_restored_clock;

/// Simulated time, steps, the current stable step and the first.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Clock {
    /// Simulated time (s).
    pub time: f64,
    /// Steps taken.
    pub steps: u64,
    /// The step the next one takes (s); zero for a solver that chooses each
    /// step as it takes it (the plate impact's).
    pub dt: f64,
    /// The first step (s): the reference of the time-step floor.
    pub dt0: f64,
}

impl Clock {
    /// A clock at zero whose first step is `dt`.
    pub fn start(dt: f64) -> Clock {
        Clock {
            time: 0.0,
            steps: 0,
            dt,
            dt0: dt,
        }
    }

    /// Stops a run whose step `dt` fell below the floor, a fraction of the
    /// first ([`check_time_step`]).
    pub fn check_step(&self, dt: f64) -> crate::Result<()> {
        check_time_step(dt, self.dt0, self.time)
    }

    /// Checks a restored clock with the solver's `bookkeeping` (energies,
    /// the smallest spacing, ...): see [`check_restored_clock`].
    pub fn check_restored(&self, bookkeeping: &[f64]) -> Result<(), String> {
        check_restored_clock(self.time, self.dt, self.dt0, self.steps, bookkeeping)
    }
}

/// Inside `impl` of a solver with a [`Clock`] at the field path given
/// (`clock`, `state.clock`): its getters `time()` (s) and `steps()`, and
/// after `; dt` also `dt()` (s).
macro_rules! clock_getters {
    ($($f:ident).+) => {
        /// Simulated time (s).
        pub fn time(&self) -> f64 {
            self.$($f).+.time
        }

        /// Steps taken.
        pub fn steps(&self) -> u64 {
            self.$($f).+.steps
        }
    };
    ($($f:ident).+ ; dt) => {
        $crate::solver::shared::clock_getters!($($f).+);

        /// Current time step (s).
        pub fn dt(&self) -> f64 {
            self.$($f).+.dt
        }
    };
}
pub(crate) use clock_getters;

#[cfg(test)]
mod tests {
    use super::*;

    /// A clock started at `dt` has taken no step, and refuses a step below
    /// the floor (a 10⁻⁴ of the first) and a NaN, but not one above it.
    #[test]
    fn the_step_floor_is_a_fraction_of_the_first_step() {
        let c = Clock::start(2e-9);
        assert_eq!((c.time, c.steps, c.dt, c.dt0), (0.0, 0, 2e-9, 2e-9));
        assert!(c.check_step(3e-13).is_ok());
        assert_eq!(c.check_step(1e-13).unwrap_err().name(), "TimeStepCollapse");
        assert_eq!(
            c.check_step(f64::NAN).unwrap_err().name(),
            "TimeStepCollapse"
        );
    }
}
