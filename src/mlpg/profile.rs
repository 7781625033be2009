//! Wall time of the phases of the 3-D time loop, kept by every run at the
//! cost of two clock reads a phase (about 50 ns a step): the profile of
//! BENCHMARKS.md, "3-D MLPG speed".

use std::time::{Duration, Instant};

/// A phase of [`crate::mlpg::Mlpg3d::step`] (and of the geometry builds it
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
    /// The conforming correction of the gradients (`src/mlpg/conform.rs`;
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

/// Accumulated wall time per [`Phase`], and the counts of the builds.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PhaseTimes {
    /// Wall time of each phase, indexed as [`Phase::ALL`].
    pub wall: [Duration; 14],
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

    /// Adds the time since `*since` to `phase` and restarts the clock.
    pub(crate) fn lap(&mut self, phase: Phase, since: &mut Instant) {
        let now = Instant::now();
        self.wall[phase as usize] += now - *since;
        *since = now;
    }

    /// Sum over the phases.
    pub fn total(&self) -> Duration {
        self.wall.iter().sum()
    }

    /// A table of the phases: seconds and share of the total.
    pub fn table(&self) -> String {
        let total = self.total().as_secs_f64().max(f64::MIN_POSITIVE);
        let mut s = String::new();
        for p in Phase::ALL {
            let t = self.of(p).as_secs_f64();
            s += &format!(
                "{:<28} {:>9.3} s {:>5.1} %\n",
                p.name(),
                t,
                100.0 * t / total
            );
        }
        s += &format!(
            "{:<28} {:>9.3} s ({} support builds, {} operator builds, {} iterations of the \
             conforming correction)\n",
            "total", total, self.supports, self.operators, self.conform_iterations
        );
        s
    }
}
