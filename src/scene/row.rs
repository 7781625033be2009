//! A row of the scene registry ([`SceneRow`]): everything about one kind
//! of scene in one place, with the FMU it is packaged as ([`FmuIdentity`])
//! and the choice of its body's materials ([`MaterialSlot`]). Each scene's
//! module declares its row with these types; `registry.rs` lists the rows.
//! Nothing here imports a scene's module.

use super::Scene;
use super::params::ParamSpec;
use crate::budget::MemoryPerNode;
use crate::error::Result;
use crate::material::choice::MaterialChoice;
use crate::model::Model;
use crate::observe::ObservableSpec;
use std::collections::BTreeMap;

/// How a scene kind is packaged as an FMU.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FmuIdentity {
    /// The model identifier: the name of the shared library inside the FMU.
    pub model_identifier: &'static str,
    /// The model name shown by hosts.
    pub model_name: &'static str,
    /// One-line description in the model description.
    pub description: &'static str,
}

/// How a kind of scene lets its body's material models be chosen
/// ([`MaterialChoice`]): each choice has a parameter table of its own, with
/// only the parameters its models use, and may have an FMU of its own.
pub struct MaterialSlot {
    /// The choice of the default scene (its table is the row's `params`).
    pub default: MaterialChoice,
    /// The parameter table of each choice.
    pub params: fn(MaterialChoice) -> &'static [ParamSpec],
    /// The FMUs of the other choices (the default choice's FMU is the row's
    /// `fmu`): one FMU per choice, so that each lists only its parameters.
    pub fmus: &'static [(MaterialChoice, FmuIdentity)],
}

/// One kind of scene.
pub struct SceneRow {
    /// Name on the command line, in scene files and in the C ABI.
    pub name: &'static str,
    /// Title of the default scene.
    pub title: &'static str,
    /// Parameters, with units, defaults and ranges (of the default
    /// material choice, where the row has one).
    pub params: &'static [ParamSpec],
    /// The choice of material models, if the scene has a body to choose for.
    pub material: Option<MaterialSlot>,
    /// Observables, in output order.
    pub observables: &'static [ObservableSpec],
    /// The particle (node) fields of the scene's solver, as a run gives
    /// them ([`crate::Simulation::field_specs`]; a unit test holds the two
    /// together), so that the reference pages list them without a run.
    pub fields: &'static [crate::observe::FieldSpec],
    /// Reference values of the default scene (experiment or exact solution),
    /// keyed like the observables they compare with.
    pub reference: fn() -> BTreeMap<String, f64>,
    /// Named variants of the default scene that are built in (for example
    /// `table1-1` ... `table1-12`), in order.
    pub variants: fn() -> Vec<(String, Scene)>,
    /// Cross-parameter checks of a scene of this kind (each value is
    /// already in its range).
    pub check: fn(&Scene) -> Result<()>,
    /// The nodes (particles) a run of a valid scene of this kind will have,
    /// from its parameters alone (before anything is allocated).
    pub nodes: fn(&Scene) -> f64,
    /// The peak memory per node of a run of a valid scene of this kind
    /// (of its solver, and of its scheme where the schemes differ): with
    /// `nodes`, what the memory budget checks ([`crate::budget`]).
    pub memory: fn(&Scene) -> MemoryPerNode,
    /// Builds the initial state of a run of a valid scene of this kind.
    pub build: fn(&Scene) -> Result<Box<dyn Model>>,
    /// The FMU of this kind (of its default material choice), if it has one.
    pub fmu: Option<FmuIdentity>,
}

/// No named variants.
pub(crate) fn no_variants() -> Vec<(String, Scene)> {
    Vec::new()
}
