//! The checks of a restored run that every solver shares: its clock and
//! bookkeeping ([`check_restored_clock`]), the physical bounds of its nodes
//! ([`RestoreBounds`]) and the first value that is not finite.

use super::guards::above;

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

/// Refuses a saved state (as JSON) that holds one of the `keys` of its
/// solver's setup (each with what it is): a saved run holds only what the
/// run changes, and its setup follows from its parameters.
pub(crate) fn refuse_setup(saved: &serde_json::Value, keys: &[(&str, &str)]) -> Result<(), String> {
    match keys.iter().find(|(key, _)| saved.get(key).is_some()) {
        Some((key, what)) => Err(format!(
            "it holds {what} (`{key}`), which follows from its parameters: a saved run holds \
             only what the run changes"
        )),
        None => Ok(()),
    }
}

/// Why a state made by a run of another setup is refused.
pub(crate) const NOT_ITS_SETUP: &str = "it was saved by a run of other parameters or another \
     material than its scene's (the digest of its setup differs)";

/// The digest of a solver's setup: FNV-1a over the text of its JSON tree
/// (keys sorted, each number in its shortest exact form), which a saved
/// state carries so that it is loaded only into a run of the same setup.
/// `src/state_format.rs` takes the digest of a format-1 state's setup the
/// same way ([`digest_json`]).
pub(crate) fn setup_digest<T: serde::Serialize>(setup: &T) -> u64 {
    digest_json(&serde_json::to_value(setup).expect("a setup holds finite numbers"))
}

/// FNV-1a (64 bits) over the text of `value`.
pub(crate) fn digest_json(value: &serde_json::Value) -> u64 {
    value
        .to_string()
        .bytes()
        .fold(0xcbf2_9ce4_8422_2325, |h, b| {
            (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
        })
}

/// A saved state of a solver, read: refused, naming it, when it holds one
/// of the `setup_keys` of the solver's setup ([`refuse_setup`]), else read
/// as an `S` (not yet checked). Every solver's `load_state` reads so.
pub(crate) fn read_state<S: serde::de::DeserializeOwned>(
    saved: crate::model::SavedSolver<'_>,
    setup_keys: &[(&str, &str)],
) -> Result<S, String> {
    if let crate::model::SavedSolver::Json(value) = &saved {
        refuse_setup(value, setup_keys)?;
    }
    crate::model::read_saved(saved)
}
