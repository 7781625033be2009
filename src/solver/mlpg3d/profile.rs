//! Wall time of the phases of the 3-D time loop, kept by every run at the
//! cost of two clock reads a phase (about 50 ns a step): the profile of
//! BENCHMARKS.md, "3-D MLPG speed".
//!
//! On request ([`PhaseTimes::count_serial`]) it also keeps each phase's
//! **serial time**: the processor time of the thread that steps the run.
//! That thread hands every parallel loop to the pool and sleeps until the
//! loop is done, so the time it spends on a processor is the time of the
//! step outside the parallel regions (the sums in node order, the
//! decisions, the bookkeeping between the loops), whatever the load of the
//! machine. One more clock read a phase (a system call, about 0.3 µs).

use std::time::{Duration, Instant};

/// A phase of [`crate::solver::mlpg3d::Mlpg3d::step`] (and of the geometry builds it
/// triggers).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// Total stress and the traction operator applied to it (step 1).
    Force,
    /// Velocity update, anvil contact (step 2).
    Kick,
    /// Velocity smoothing toward the MLS approximation (step 2).
    Smoothing,
    /// Positions and the anvil (step 3).
    Move,
    /// Node shifting and the carrying of the fields (step 3, with
    /// `shifting > 0`).
    Shift,
    /// The named pairs: the spacing check and the rules for recomputing
    /// the supports and rebuilding the operator (step 4).
    Pairs,
    /// Supports: the neighbour search and the named neighbours.
    Supports,
    /// MLS shape functions and gradients at the nodes.
    Shapes,
    /// The conforming correction of the gradients (`src/approx/conform.rs`;
    /// schemes with conforming gradients only).
    Conform,
    /// Test spheres: the Nanson normals and the test radii.
    Spheres,
    /// The traction operator: MLS at every quadrature point.
    Operator,
    /// Velocity gradients by collocation (step 5).
    Gradients,
    /// Material update, tallies and the finiteness checks (step 5).
    Material,
    /// Sums, energy check and the next step (step 6).
    Checks,
}

impl Phase {
    /// Every phase, in the order of the step.
    pub const ALL: [Phase; 14] = [
        Phase::Force,
        Phase::Kick,
        Phase::Smoothing,
        Phase::Move,
        Phase::Shift,
        Phase::Pairs,
        Phase::Supports,
        Phase::Shapes,
        Phase::Conform,
        Phase::Spheres,
        Phase::Operator,
        Phase::Gradients,
        Phase::Material,
        Phase::Checks,
    ];

    /// A short name.
    pub fn name(self) -> &'static str {
        match self {
            Phase::Force => "force assembly",
            Phase::Kick => "velocity update",
            Phase::Smoothing => "velocity smoothing",
            Phase::Move => "positions",
            Phase::Shift => "node shifting",
            Phase::Pairs => "spacing and rebuild checks",
            Phase::Supports => "supports (neighbour search)",
            Phase::Shapes => "MLS shapes at the nodes",
            Phase::Conform => "conforming correction",
            Phase::Spheres => "test spheres",
            Phase::Operator => "traction operator build",
            Phase::Gradients => "gradient collocation",
            Phase::Material => "material update",
            Phase::Checks => "sums and checks",
        }
    }
}

/// The processor time of the calling thread (Linux; `None` elsewhere or
/// when the clock cannot be read).
#[allow(unsafe_code)]
fn thread_cpu() -> Option<Duration> {
    #[cfg(target_os = "linux")]
    {
        let mut t = libc::timespec {
            tv_sec: 0,
            tv_nsec: 0,
        };
        // SAFETY: `t` is a valid, writable timespec for the call.
        let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut t) };
        (rc == 0).then(|| Duration::new(t.tv_sec as u64, t.tv_nsec as u32))
    }
    #[cfg(not(target_os = "linux"))]
    {
        None
    }
}

/// A phase's start: the wall clock and, when serial time is counted, the
/// stepping thread's processor time.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Stopwatch {
    at: Instant,
    cpu: Option<Duration>,
}

/// Accumulated wall time per [`Phase`], and the counts of the builds.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PhaseTimes {
    /// Wall time of each phase, indexed as [`Phase::ALL`].
    pub wall: [Duration; 14],
    /// Serial time of each phase (module docs), indexed as [`Phase::ALL`];
    /// zero unless [`PhaseTimes::count_serial`] turned it on.
    pub serial: [Duration; 14],
    /// Whether the serial time is counted.
    pub counting_serial: bool,
    /// Builds of the supports (the first included).
    pub supports: u64,
    /// Builds of the shapes, spheres and operator (the first included).
    pub operators: u64,
    /// Iterations of the conforming correction's conjugate gradients, over
    /// all builds.
    pub conform_iterations: u64,
}

impl PhaseTimes {
    /// The wall time of `phase`.
    pub fn of(&self, phase: Phase) -> Duration {
        self.wall[phase as usize]
    }

    /// The serial time of `phase`.
    pub fn serial_of(&self, phase: Phase) -> Duration {
        self.serial[phase as usize]
    }

    /// Turns the counting of serial time on or off (module docs), from the
    /// next phase on.
    pub fn count_serial(&mut self, on: bool) {
        self.counting_serial = on;
    }

    /// A clock started now.
    pub(crate) fn stopwatch(&self) -> Stopwatch {
        Stopwatch {
            at: Instant::now(),
            cpu: if self.counting_serial {
                thread_cpu()
            } else {
                None
            },
        }
    }

    /// Adds the time since `*since` to `phase` and restarts the clock.
    pub(crate) fn lap(&mut self, phase: Phase, since: &mut Stopwatch) {
        let now = self.stopwatch();
        self.wall[phase as usize] += now.at - since.at;
        if let (Some(a), Some(b)) = (since.cpu, now.cpu) {
            self.serial[phase as usize] += b.saturating_sub(a);
        }
        *since = now;
    }

    /// Sum over the phases.
    pub fn total(&self) -> Duration {
        self.wall.iter().sum()
    }

    /// Sum of the serial times over the phases.
    pub fn serial_total(&self) -> Duration {
        self.serial.iter().sum()
    }

    /// A table of the phases: seconds and share of the total (and, when
    /// counted, each phase's serial time and its share of the phase).
    pub fn table(&self) -> String {
        let total = self.total().as_secs_f64().max(f64::MIN_POSITIVE);
        let mut s = String::new();
        let serial = |p: Duration, of: f64| {
            format!(
                "   serial {:>8.3} s {:>5.1} %",
                p.as_secs_f64(),
                100.0 * p.as_secs_f64() / of.max(f64::MIN_POSITIVE)
            )
        };
        for p in Phase::ALL {
            let t = self.of(p).as_secs_f64();
            s += &format!(
                "{:<28} {:>9.3} s {:>5.1} %{}\n",
                p.name(),
                t,
                100.0 * t / total,
                if self.counting_serial {
                    serial(self.serial_of(p), t)
                } else {
                    String::new()
                }
            );
        }
        s += &format!(
            "{:<28} {:>9.3} s ({} support builds, {} operator builds, {} iterations of the \
             conforming correction){}\n",
            "total",
            total,
            self.supports,
            self.operators,
            self.conform_iterations,
            if self.counting_serial {
                serial(self.serial_total(), total)
            } else {
                String::new()
            }
        );
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The serial time is the stepping thread's processor time: a phase
    /// that computes on that thread books it (no more than its wall time),
    /// a phase that waits (as the thread waits for the pool) books almost
    /// none; with the counting off, nothing is booked.
    #[test]
    fn serial_time_counts_the_thread_on_a_processor_not_its_waits() {
        let mut p = PhaseTimes::default();
        let mut clock = p.stopwatch();
        std::thread::sleep(Duration::from_millis(20));
        p.lap(Phase::Force, &mut clock);
        assert_eq!(p.serial_total(), Duration::ZERO);
        p.count_serial(true);
        let mut clock = p.stopwatch();
        std::thread::sleep(Duration::from_millis(20));
        p.lap(Phase::Kick, &mut clock);
        let mut x = 1.0f64;
        for i in 0..20_000_000 {
            x = (x * 1.000_000_1 + i as f64).sqrt();
        }
        assert!(x.is_finite());
        p.lap(Phase::Move, &mut clock);
        if thread_cpu().is_none() {
            return;
        }
        let (waited, busy) = (p.serial_of(Phase::Kick), p.serial_of(Phase::Move));
        assert!(p.of(Phase::Kick) >= Duration::from_millis(20));
        assert!(waited < Duration::from_millis(5), "{waited:?}");
        assert!(busy > Duration::from_millis(1), "{busy:?}");
        assert!(
            busy <= p.of(Phase::Move) + Duration::from_millis(1),
            "{busy:?}"
        );
        assert!(p.table().contains("serial"));
    }
}
