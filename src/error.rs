//! The typed error of the core. Every variant names what went wrong, with the
//! offending value and, for input errors, the allowed range.

/// The approximation whose moment matrix
/// [`Error::SingularMomentMatrix`] names.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MomentMethod {
    /// MSPH of the axisymmetric solver: the kernel's support, set by
    /// `smoothing_ratio`.
    Msph,
    /// MLS of the 3-D MLPG solver: the supports of the `k` named
    /// neighbours times the support factor.
    Mls,
}

impl MomentMethod {
    /// What to change.
    pub fn hint(self) -> &'static str {
        match self {
            MomentMethod::Msph => "increase smoothing_ratio",
            MomentMethod::Mls => {
                "the MLS supports cover too few nodes off a plane (the lattice is too coarse or too distorted)"
            }
        }
    }
}

impl std::fmt::Display for MomentMethod {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            MomentMethod::Msph => "MSPH",
            MomentMethod::Mls => "MLS",
        })
    }
}

/// Errors returned by the core library.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// A parameter value is outside its allowed range (or NaN/infinite).
    #[error("parameter `{name}` = {} is out of range: allowed {range}", number(*.value))]
    OutOfRange {
        /// Parameter name.
        name: String,
        /// Rejected value.
        value: f64,
        /// Allowed range, in interval notation.
        range: String,
    },
    /// A parameter name that the scene does not have.
    #[error("unknown parameter `{name}` for scene `{scene}`; allowed: {allowed}")]
    UnknownParameter {
        /// The unknown name.
        name: String,
        /// Scene name.
        scene: String,
        /// Comma-separated list of allowed names.
        allowed: String,
    },
    /// A scene name that does not exist.
    #[error("unknown scene `{name}`; allowed: {allowed}")]
    UnknownScene {
        /// The unknown name.
        name: String,
        /// Comma-separated list of scene names.
        allowed: String,
    },
    /// A material model or preset name that does not exist (`key` is
    /// `strength`, `eos` or `preset`), or a material choice that the scene
    /// cannot take.
    #[error("unknown {key} `{name}`; allowed: {allowed}")]
    UnknownModel {
        /// What was named: `strength`, `eos` or `preset`.
        key: String,
        /// The unknown name.
        name: String,
        /// Comma-separated list of allowed names.
        allowed: String,
    },
    /// A parameter value that could not be parsed as a number.
    #[error("parameter `{name}`: cannot parse `{text}` as a number")]
    ParseValue {
        /// Parameter name.
        name: String,
        /// Text given.
        text: String,
    },
    /// Parameters that are each in range but inconsistent together.
    #[error("inconsistent parameters: {0}")]
    Inconsistent(String),
    /// A scene file that could not be read or parsed.
    #[error("scene file: {0}")]
    SceneFile(String),
    /// An experiments file of a calibration that could not be read or
    /// does not fit the scene: the message names the file, the line and the
    /// column.
    #[error("experiments file {0}")]
    ShotsFile(String),
    /// The moment matrix of a particle or node is singular or too
    /// ill-conditioned: MSPH's (axisymmetric solver) or MLS's (3-D MLPG).
    #[error(
        "singular {method} moment matrix at particle {particle} (t = {time:.4e} s, condition number {condition:.3e}): \
         too few or collinear neighbours; {}", method.hint()
    )]
    SingularMomentMatrix {
        /// The approximation whose moment matrix failed.
        method: MomentMethod,
        /// Particle index.
        particle: usize,
        /// Simulated time.
        time: f64,
        /// Estimated 1-norm condition number.
        condition: f64,
    },
    /// A field became NaN or infinite.
    #[error("non-finite {field} at particle {particle} (t = {time:.4e} s)")]
    NonFinite {
        /// Field name.
        field: &'static str,
        /// Particle index.
        particle: usize,
        /// Simulated time.
        time: f64,
    },
    /// A particle moved through a rigid boundary (the anvil or the axis).
    #[error(
        "particle {particle} passed through the {boundary} (t = {time:.4e} s, position {position:.4e} m)"
    )]
    ThroughBoundary {
        /// Particle index.
        particle: usize,
        /// "anvil", "axis" or "symmetry plane".
        boundary: &'static str,
        /// Simulated time.
        time: f64,
        /// The offending coordinate.
        position: f64,
    },
    /// The time step collapsed: the run left the domain where the explicit
    /// integrator can make progress.
    #[error("time step collapsed to {dt:.3e} s (t = {time:.4e} s), below {min:.3e} s")]
    TimeStepCollapse {
        /// Current step.
        dt: f64,
        /// Simulated time.
        time: f64,
        /// Smallest accepted step.
        min: f64,
    },
    /// The energy balance drifted past its bound.
    #[error("energy error {error:.3e} exceeds the bound {bound} (t = {time:.4e} s)")]
    EnergyDrift {
        /// Relative energy error.
        error: f64,
        /// Bound.
        bound: f64,
        /// Simulated time.
        time: f64,
    },
    /// Two neighbouring particles came closer than a fraction of the initial
    /// spacing: the particle arrangement collapsed, and the MSPH sums that
    /// follow would be garbage.
    #[error(
        "particle spacing collapsed to {ratio:.3e} of the initial spacing, below the bound {bound} (t = {time:.4e} s){hint}"
    )]
    SpacingCollapse {
        /// Smallest neighbour distance over the initial spacing.
        ratio: f64,
        /// Bound on that ratio.
        bound: f64,
        /// Simulated time.
        time: f64,
        /// What to try, or empty.
        hint: &'static str,
    },
    /// A particle was compressed to or past the singular point of its
    /// equation of state (Mie-Grüneisen: `1 - (s - 1) mu = 0`).
    #[error(
        "compression mu = {compression:.4e} at particle {particle} reached the limit {limit:.4e} \
         of the Mie-Grüneisen equation of state, 1 / (eos_s - 1) (t = {time:.4e} s)"
    )]
    CompressionLimit {
        /// Particle index.
        particle: usize,
        /// Simulated time.
        time: f64,
        /// The compression `rho / rho0 - 1` reached.
        compression: f64,
        /// The singular compression.
        limit: f64,
    },
    /// A run whose estimated peak memory exceeds the memory budget: refused
    /// before it allocates (`MI_MEMORY_BUDGET` sets the budget).
    #[error(
        "the run would have {nodes:.0} nodes and need about {} of memory ({:.1} kB a node, BENCHMARKS.md), \
         over the memory budget of {}: lower particles_radial or the bodies' sizes, or raise the budget \
         with the environment variable MI_MEMORY_BUDGET (bytes, or with a suffix K, M, G, T: 32G)",
        gib(*.estimate), .per_node / 1000.0, gib(*.budget)
    )]
    MemoryBudget {
        /// Nodes (particles) of the run.
        nodes: f64,
        /// Estimated peak memory (bytes).
        estimate: f64,
        /// The budget (bytes).
        budget: f64,
        /// Peak bytes per node of the solver, measured.
        per_node: f64,
    },
    /// The caller cancelled the run from a progress callback.
    #[error("run cancelled by the caller at t = {time:.4e} s")]
    Cancelled {
        /// Simulated time when cancelled.
        time: f64,
    },
    /// Bytes that are not a serialized simulation state.
    #[error("invalid serialized state: {0}")]
    InvalidState(String),
    /// A file given as a checkpoint that cannot be continued: which fault,
    /// and the detail ([`crate::checkpoint`]).
    #[error("checkpoint {path} is {fault}: {detail}")]
    Checkpoint {
        /// The file.
        path: String,
        /// What is wrong with it.
        fault: crate::checkpoint::CheckpointFault,
        /// The detail: what was found, and what to do.
        detail: String,
    },
    /// An input/output failure while writing results.
    #[error("I/O error on {path}: {message}")]
    Io {
        /// File path.
        path: String,
        /// System message.
        message: String,
    },
}

impl Error {
    /// The variant's name (for example `"EnergyDrift"`): a stable label for
    /// tables and tests.
    pub fn name(&self) -> &'static str {
        match self {
            Error::OutOfRange { .. } => "OutOfRange",
            Error::UnknownParameter { .. } => "UnknownParameter",
            Error::UnknownScene { .. } => "UnknownScene",
            Error::UnknownModel { .. } => "UnknownModel",
            Error::ParseValue { .. } => "ParseValue",
            Error::Inconsistent(_) => "Inconsistent",
            Error::SceneFile(_) => "SceneFile",
            Error::ShotsFile(_) => "ShotsFile",
            Error::SingularMomentMatrix { .. } => "SingularMomentMatrix",
            Error::NonFinite { .. } => "NonFinite",
            Error::ThroughBoundary { .. } => "ThroughBoundary",
            Error::TimeStepCollapse { .. } => "TimeStepCollapse",
            Error::EnergyDrift { .. } => "EnergyDrift",
            Error::SpacingCollapse { .. } => "SpacingCollapse",
            Error::CompressionLimit { .. } => "CompressionLimit",
            Error::MemoryBudget { .. } => "MemoryBudget",
            Error::Cancelled { .. } => "Cancelled",
            Error::InvalidState(_) => "InvalidState",
            Error::Checkpoint { fault, .. } => fault.name(),
            Error::Io { .. } => "Io",
        }
    }

    /// Builds an [`Error::Io`] from a path and an I/O error.
    pub fn io(path: impl AsRef<std::path::Path>, e: impl std::fmt::Display) -> Self {
        Error::Io {
            path: path.as_ref().display().to_string(),
            message: e.to_string(),
        }
    }
}

/// Result alias of the core.
pub type Result<T> = std::result::Result<T, Error>;

/// Bytes in GiB, one decimal (`8.0 GiB`).
fn gib(bytes: f64) -> String {
    format!("{:.1} GiB", bytes / (1024.0 * 1024.0 * 1024.0))
}

/// A number as a person reads it: plain decimals for everyday magnitudes,
/// and the exponent form for very small or very large ones (`1.6e-298`
/// rather than three hundred zeros).
pub fn number(x: f64) -> String {
    let a = x.abs();
    if a != 0.0 && a.is_finite() && !(1e-4..1e15).contains(&a) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}
