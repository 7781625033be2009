//! The reading of the target's free-surface velocity.

/// What the target's free-surface velocity has shown so far, read step by
/// step as an experimenter reads a VISAR record (see
/// [`PlateImpact::reading`](super::PlateImpact::reading)).
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FreeSurfaceReading {
    /// When the first wave reached the free surface (s): the first step
    /// whose velocity passed 1 % of the impact speed.
    pub arrival: Option<f64>,
    /// The elastic precursor (m/s): the velocity at the first step after
    /// the arrival where the velocity stopped rising (its first local
    /// maximum). Above the Hugoniot elastic limit this is the top of the
    /// elastic wave; below it, the whole elastic pulse.
    pub precursor: Option<f64>,
    /// The peak of the first pulse (m/s): the highest velocity before the
    /// velocity first fell by more than 5 % of the impact speed below it (more than the ringing behind a front).
    pub peak: f64,
    /// The lowest velocity after the peak until the velocity first rose
    /// again by more than 5 % of the impact speed (m/s): the pullback's
    /// minimum, before the spall signal or the next pulse.
    pub pullback_minimum: f64,
    /// Where the reading stands: 0 on the first pulse's rise, 1 on the
    /// fall after its peak, 2 once the velocity has risen again from the
    /// pullback's minimum (the spall signal or the next pulse), when the
    /// peak and the minimum are read.
    pub phase: u8,
    /// The velocity read at the step before (m/s).
    pub last: f64,
    /// The largest rise of the velocity in one step since the arrival
    /// (m/s), for the knee of a ramped precursor (`KNEE`).
    #[serde(default)]
    pub steepest: f64,
}

/// A precursor read at its knee ends where the velocity's rise in one step
/// falls below this fraction of the steepest rise of the front so far. A
/// JH-2 target's strength grows with pressure, so above the HEL its
/// free-surface velocity does not stop rising after the elastic front: it
/// ramps on until the plastic wave (for the example ceramic struck at
/// 1000 m/s, from 183 to 225 m/s over 0.2 us, at about a twentieth of the
/// front's rate), and the elastic precursor is the knee at the top of the
/// front.
pub const KNEE: f64 = 0.1;

impl FreeSurfaceReading {
    /// Reads the free-surface velocity `u` (m/s) at time `time` (s) of a run
    /// at `impact_speed` (m/s). With `knee` (a JH-2 target) the precursor
    /// ends also where the rise slows to [`KNEE`] of its steepest.
    pub(super) fn read(&mut self, time: f64, u: f64, impact_speed: f64, knee: bool) {
        let r = self;
        if r.arrival.is_none() {
            if u > 0.01 * impact_speed.abs() {
                r.arrival = Some(time);
            }
        } else if r.precursor.is_none() && (u < r.last || (knee && u - r.last < KNEE * r.steepest))
        {
            r.precursor = Some(r.last);
        }
        if knee && r.arrival.is_some() {
            r.steepest = r.steepest.max(u - r.last);
        }
        r.last = u;
        let slack = 0.05 * impact_speed.abs();
        match r.phase {
            0 => {
                if u > r.peak {
                    r.peak = u;
                } else if u < r.peak - slack {
                    r.phase = 1;
                }
                r.pullback_minimum = r.peak.min(u);
            }
            1 => {
                if u < r.pullback_minimum {
                    r.pullback_minimum = u;
                } else if u > r.pullback_minimum + slack {
                    r.phase = 2;
                }
            }
            _ => {}
        }
    }
}
