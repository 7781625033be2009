//! Scenes: what is simulated (geometry, material, physics, boundaries,
//! observables, end condition) and its parameters. Scenes are built in
//! (`taylor`, `noh`, `table1-1` ... `table1-12`) or read from TOML files.

pub mod noh;
pub mod params;
pub mod penetration;
pub mod plate_impact;
pub mod reference;
pub mod registry;
pub mod row;
pub mod table1;
pub mod taylor;
pub mod taylor3d;

use crate::error::{Error, Result};
use crate::material::choice::{EosKind, MaterialChoice, Prefix, StrengthKind};
use crate::material::presets::Preset;
use crate::observe::ObservableSpec;
use params::ParamSpec;
use registry::SceneRow;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// A kind of scene: a handle to its row of the scene registry
/// (`registry::SCENES`) and, for a scene with a body, the choice of its
/// material models ([`MaterialChoice`]), which sets the parameter table.
/// Two kinds are equal when they are the same row with the same choice.
#[derive(Clone, Copy)]
pub struct SceneKind {
    row: &'static SceneRow,
    material: Option<MaterialChoice>,
}

impl PartialEq for SceneKind {
    fn eq(&self, other: &Self) -> bool {
        std::ptr::eq(self.row, other.row) && self.material == other.material
    }
}

impl Eq for SceneKind {}

impl std::fmt::Debug for SceneKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "SceneKind({self})")
    }
}

impl std::fmt::Display for SceneKind {
    /// The name, with the material choice when it is not the default one:
    /// `taylor`, `taylor (strength = bilinear, eos = linear)`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match (self.material, self.row.material.as_ref()) {
            (Some(c), Some(slot)) if c != slot.default => write!(f, "{} ({c})", self.row.name),
            _ => write!(f, "{}", self.row.name),
        }
    }
}

impl SceneKind {
    /// The kind called `name` (`taylor`, `noh`, ...), as the registry lists
    /// it, with its default material choice.
    pub fn named(name: &str) -> Result<SceneKind> {
        registry::row(name).map(SceneKind::default_of_row)
    }

    /// The default kind of a registry row.
    pub(crate) fn default_of_row(row: &'static SceneRow) -> SceneKind {
        SceneKind {
            row,
            material: row.material.as_ref().map(|m| m.default),
        }
    }

    /// The same scene with the material models `choice`; an error for a
    /// scene with no material to choose.
    pub fn with_material(self, choice: MaterialChoice) -> Result<SceneKind> {
        if self.row.material.is_none() {
            return Err(Error::UnknownModel {
                key: "material".into(),
                name: choice.to_string(),
                allowed: format!("none: scene `{}` has no material to choose", self.row.name),
            });
        }
        Ok(SceneKind {
            material: Some(choice),
            ..self
        })
    }

    /// The material models chosen, for a scene with a body.
    pub fn material(self) -> Option<MaterialChoice> {
        self.material
    }

    /// The kind's registry row.
    pub(crate) fn row(self) -> &'static SceneRow {
        self.row
    }

    /// The scene's name as used on the command line and in scene files.
    pub fn name(self) -> &'static str {
        self.row.name
    }

    /// Parameter table of this kind of scene: for a scene with a body, the
    /// table of its material choice, which lists only the parameters the
    /// chosen models use.
    pub fn param_specs(self) -> &'static [ParamSpec] {
        match (self.material, self.row.material.as_ref()) {
            (Some(c), Some(slot)) => (slot.params)(c),
            _ => self.row.params,
        }
    }

    /// Observables this kind of scene reports, in output order.
    pub fn observable_specs(self) -> &'static [ObservableSpec] {
        self.row.observables
    }

    /// The particle (node) fields of a run of this kind, in the order a run
    /// gives them ([`crate::Simulation::field_specs`]).
    pub fn field_specs(self) -> &'static [crate::observe::FieldSpec] {
        self.row.fields
    }

    /// The key of this kind in saved states: its name with a capital
    /// (`Taylor`).
    pub(crate) fn saved_key(self) -> String {
        let mut c = self.name().chars();
        c.next()
            .map(|f| f.to_uppercase().chain(c).collect())
            .unwrap_or_default()
    }

    /// The kind whose [`SceneKind::saved_key`] is `key`.
    pub(crate) fn with_saved_key(key: &str) -> Option<SceneKind> {
        registry::SCENES
            .iter()
            .map(|row| SceneKind::default_of_row(row))
            .find(|k| k.saved_key() == key)
    }
}

/// The suffix of a reference that is the converged continuum solution with
/// the scene's own constants (`mushroom_radius_continuum`), beside the
/// reference under the observable's own name, which for the rod scenes is
/// the experiment's.
pub const CONTINUUM_SUFFIX: &str = "_continuum";

/// A complete, validated-on-demand description of one run: a kind of scene
/// and a value for each parameter of its table.
///
/// **Schemes.** A parameter with named levels (the `scheme` of the rod
/// scenes, [`crate::Level`]) sets other parameters of the table (the
/// scheme's knobs). A knob set by hand ([`Scene::set`]) overrides the
/// scheme whatever the order of the two: choosing a scheme changes only
/// the knobs not set by hand.
#[derive(Debug, Clone)]
pub struct Scene {
    /// Human-readable title.
    pub title: String,
    kind: SceneKind,
    /// One value per row of the kind's parameter table, in its order.
    values: Vec<f64>,
    /// Per row: set by hand (a scheme then leaves it alone).
    by_hand: Vec<bool>,
    /// Optional reference values (for example experimental results), by name.
    pub reference: BTreeMap<String, f64>,
}

impl PartialEq for Scene {
    /// The same run: title, kind, values and references (which knobs were
    /// set by hand is not compared).
    fn eq(&self, other: &Self) -> bool {
        self.title == other.title
            && self.kind == other.kind
            && self.values == other.values
            && self.reference == other.reference
    }
}

/// Names of the built-in scenes: the registry rows' own names, then the
/// named variants they offer (`table1-1` ... `table1-12` of `taylor`).
pub fn builtin_names() -> Vec<String> {
    let rows = registry::SCENES.iter();
    rows.clone()
        .map(|row| row.name.to_string())
        .chain(rows.flat_map(|row| (row.variants)().into_iter().map(|(name, _)| name)))
        .collect()
}

/// Parameters whose default moved after scenes without them were saved,
/// with the value such a scene ran with: `conform_preconditioner` was
/// added with Jacobi's (0) as its default on 2026-11-30 and became the
/// levels (1) the same day; a state or checkpoint saved before names no
/// preconditioner and ran with Jacobi's. The ceramic's default moved from
/// `ad85_seed` (0) to `ad85_planes_freund` on 2026-11-30 (issue 68): a
/// scene saved before `plate_ceramic` (2026-11-28) or
/// `plate_tensile_flaw_size` (2026-11-29) existed ran with the seed's set
/// and no tensile flaws.
const SAVED_WITHOUT: &[(&str, f64)] = &[
    ("conform_preconditioner", 0.0),
    ("plate_ceramic", 0.0),
    ("plate_tensile_flaw_size", 0.0),
];

/// A [`Scene`] as saved: its kind's parameters by name, under the kind's
/// name with a capital (`{"Taylor": {"impact_speed": 181.0, ...}}`).
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct SavedScene {
    title: String,
    /// The material models, for a scene with a body (absent: the default).
    #[serde(default)]
    material: Option<MaterialChoice>,
    params: BTreeMap<String, BTreeMap<String, f64>>,
    reference: BTreeMap<String, f64>,
}

impl Serialize for Scene {
    fn serialize<S: serde::Serializer>(
        &self,
        serializer: S,
    ) -> std::result::Result<S::Ok, S::Error> {
        let params = self
            .param_specs()
            .iter()
            .zip(&self.values)
            .map(|(spec, v)| (spec.name.to_string(), *v))
            .collect();
        SavedScene {
            title: self.title.clone(),
            material: self.kind.material,
            params: BTreeMap::from([(self.kind.saved_key(), params)]),
            reference: self.reference.clone(),
        }
        .serialize(serializer)
    }
}

impl<'de> Deserialize<'de> for Scene {
    fn deserialize<D: serde::Deserializer<'de>>(
        deserializer: D,
    ) -> std::result::Result<Self, D::Error> {
        use serde::de::Error as _;
        let saved = SavedScene::deserialize(deserializer)?;
        let mut entries = saved.params.into_iter();
        let (Some((key, params)), None) = (entries.next(), entries.next()) else {
            return Err(D::Error::custom("a scene has the parameters of one kind"));
        };
        let mut kind = SceneKind::with_saved_key(&key)
            .ok_or_else(|| D::Error::custom(format!("unknown kind of scene `{key}`")))?;
        if let Some(choice) = saved.material {
            kind = kind.with_material(choice).map_err(D::Error::custom)?;
        }
        let mut scene = Scene::default_of(kind);
        scene.title = saved.title;
        scene.reference = saved.reference;
        // A scene saved before a parameter existed ran with the value it
        // had then, not with today's default.
        for &(name, then) in SAVED_WITHOUT {
            if !params.contains_key(name)
                && let Ok(k) = scene.index(name)
            {
                scene.values[k] = then;
            }
        }
        // Values are put as they are (a restored state is checked whole
        // afterwards); names must be the kind's.
        for (name, v) in params {
            let k = scene.index(&name).map_err(D::Error::custom)?;
            scene.values[k] = v;
        }
        scene.mark_overrides();
        Ok(scene)
    }
}

/// The shape of a TOML scene file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneFile {
    scene: String,
    #[serde(default)]
    title: Option<String>,
    #[serde(default)]
    material: Option<MaterialTable>,
    #[serde(default)]
    parameters: BTreeMap<String, toml::Value>,
    #[serde(default)]
    reference: BTreeMap<String, f64>,
}

/// The `[material]` table of a scene file (and of a material file,
/// `--preset-file`): the models or a preset, then constants by parameter
/// name, which override the preset's.
#[derive(Debug, Deserialize)]
struct MaterialTable {
    #[serde(default)]
    strength: Option<String>,
    #[serde(default)]
    eos: Option<String>,
    #[serde(default)]
    preset: Option<String>,
    /// Constants of the material by parameter name (`jc_a = 8.1e8`).
    #[serde(flatten)]
    constants: BTreeMap<String, toml::Value>,
}

/// The shape of a material file: a `[material]` table alone.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct MaterialFile {
    material: MaterialTable,
}

impl Scene {
    /// The default scene of a kind, with default parameters.
    pub fn default_of(kind: SceneKind) -> Scene {
        let row = kind.row();
        let specs = kind.param_specs();
        Scene {
            title: row.title.to_string(),
            kind,
            values: specs.iter().map(|p| p.default).collect(),
            by_hand: vec![false; specs.len()],
            reference: (row.reference)(),
        }
    }

    /// A built-in scene by name: a registry row's name (`taylor`, `noh`)
    /// or one of the named variants a row offers (`table1-N` for the N-th
    /// configuration of Table 1, N = 1..12). Only these exact names are
    /// accepted (no other case, sign, leading zero or spaces).
    pub fn builtin(name: &str) -> Result<Scene> {
        for row in registry::SCENES {
            if row.name == name {
                return Ok(Scene::default_of(SceneKind::default_of_row(row)));
            }
            if let Some((_, scene)) = (row.variants)().into_iter().find(|(n, _)| n == name) {
                return Ok(scene);
            }
        }
        Err(Error::UnknownScene {
            name: name.to_string(),
            allowed: builtin_names().join(", "),
        })
    }

    /// Parses a TOML scene (see `scenes/` for examples).
    pub fn from_toml_str(text: &str) -> Result<Scene> {
        let file: SceneFile = toml::from_str(text).map_err(|e| Error::SceneFile(e.to_string()))?;
        let kind = SceneKind::named(&file.scene)?;
        let mut scene = Scene::default_of(kind);
        scene.reference = file.reference;
        if let Some(t) = file.title {
            scene.title = t;
        }
        if let Some(m) = &file.material {
            scene.apply_material_table(m)?;
        }
        let pairs = file.parameters.iter().map(|(n, v)| (n.as_str(), v));
        for (name, value) in scene.schemes_first(pairs) {
            let v = scene.toml_value(name, value)?;
            scene.set(name, v)?;
        }
        scene.validate()?;
        Ok(scene)
    }

    /// The number a TOML value gives the parameter `name`: a float, an
    /// integer, or a text that the parameter parses (a level's name).
    fn toml_value(&self, name: &str, value: &toml::Value) -> Result<f64> {
        match value {
            toml::Value::Float(f) => Ok(*f),
            toml::Value::Integer(i) => Ok(*i as f64),
            toml::Value::String(text) => self.spec(name)?.parse(text),
            other => Err(Error::ParseValue {
                name: name.to_string(),
                text: other.to_string(),
            }),
        }
    }

    /// Applies a `[material]` table: its models or preset, then its
    /// constants, each of which must be a constant of the scene's material
    /// ([`Scene::material_names`]).
    fn apply_material_table(&mut self, m: &MaterialTable) -> Result<()> {
        if m.strength.is_some() || m.eos.is_some() || m.preset.is_some() {
            self.choose_material(m.strength.as_deref(), m.eos.as_deref(), m.preset.as_deref())?;
        }
        let allowed = self.material_names();
        for (name, value) in &m.constants {
            if !allowed.contains(&name.as_str()) {
                return Err(Error::SceneFile(format!(
                    "[material] `{name}` is not a constant of the material of scene `{}`; allowed: strength, eos, preset, {}",
                    self.kind.name(),
                    allowed.join(", ")
                )));
            }
            let v = self.toml_value(name, value)?;
            self.set(name, v)?;
        }
        Ok(())
    }

    /// Applies a material file (`--preset-file`): a TOML file with a
    /// `[material]` table alone, as a scene file's (`calibrate` writes
    /// one as `material.toml`). Nothing changes on an error.
    pub fn apply_material_file(&mut self, path: impl AsRef<std::path::Path>) -> Result<()> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        let file: MaterialFile = toml::from_str(&text)
            .map_err(|e| Error::SceneFile(format!("{}: {e}", path.display())))?;
        let mut next = self.clone();
        next.apply_material_table(&file.material)
            .map_err(|e| match e {
                Error::SceneFile(m) => Error::SceneFile(format!("{}: {m}", path.display())),
                other => other,
            })?;
        *self = next;
        Ok(())
    }

    /// The names of the scene's parameters that are constants of its
    /// materials (the material blocks' and the ceramic plate's), in table
    /// order.
    pub fn material_names(&self) -> Vec<&'static str> {
        use crate::material::ceramic_block::PLATE_CERAMIC;
        let in_a_block = |name: &str| {
            Prefix::ALL
                .iter()
                .any(|p| p.block().iter().any(|b| b.spec.name == name))
                || PLATE_CERAMIC.iter().any(|s| s.name == name)
        };
        self.param_specs()
            .iter()
            .map(|s| s.name)
            .filter(|n| in_a_block(n))
            .collect()
    }

    /// The scene's material as a material file (`--preset-file`): a
    /// `[material]` table with the models (where the scene has a choice of
    /// them) and every constant of [`Scene::material_names`], each written
    /// so that it reads back bit for bit.
    pub fn material_toml(&self) -> String {
        let mut out = String::from("[material]\n");
        if let Some(c) = self.kind.material {
            out.push_str(&format!(
                "strength = \"{}\"\neos = \"{}\"\n",
                c.strength.name(),
                c.eos.name()
            ));
        }
        for name in self.material_names() {
            let spec = self.spec(name).expect("own name");
            let v = self.get(name).expect("own name");
            out.push_str(&format!("{name} = {v:?}  # {}\n", spec.unit));
        }
        out
    }

    /// Reads a TOML scene file.
    pub fn from_file(path: impl AsRef<std::path::Path>) -> Result<Scene> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        Scene::from_toml_str(&text).map_err(|e| match e {
            Error::SceneFile(m) => Error::SceneFile(format!("{}: {m}", path.display())),
            other => other,
        })
    }

    /// Writes the scene as TOML, every parameter included (and the
    /// `[material]` table when the models are not the default ones).
    pub fn to_toml(&self) -> String {
        let mut out = format!(
            "scene = \"{}\"\ntitle = {}\n\n",
            self.kind().name(),
            toml::Value::String(self.title.clone())
        );
        if let (Some(c), Some(slot)) = (self.kind.material, &self.kind.row.material)
            && c != slot.default
        {
            out.push_str(&format!(
                "[material]\nstrength = \"{}\"\neos = \"{}\"\n\n",
                c.strength.name(),
                c.eos.name()
            ));
        }
        out.push_str("[parameters]\n");
        for spec in self.param_specs() {
            let v = self.get(spec.name).expect("name from own table");
            if let Some(level) = spec.level(v) {
                out.push_str(&format!(
                    "{} = \"{}\"  # {}: {}\n",
                    spec.name,
                    level.name,
                    spec.level_names(),
                    level.description
                ));
            } else if let Some((by, level)) = self.set_by_level(spec.name) {
                // Written as a comment: the scheme sets it, and a value
                // written here would override another scheme chosen later.
                out.push_str(&format!(
                    "# {} = {:?}  # {}, set by {by} = \"{}\"\n",
                    spec.name, v, spec.unit, level.name
                ));
            } else {
                out.push_str(&format!("{} = {:?}  # {}\n", spec.name, v, spec.unit));
            }
        }
        if !self.reference.is_empty() {
            out.push_str("\n[reference]\n");
            for (k, v) in &self.reference {
                out.push_str(&format!("{k} = {v:?}\n"));
            }
        }
        out
    }

    /// The kind of this scene.
    pub fn kind(&self) -> SceneKind {
        self.kind
    }

    /// The parameter table of this scene.
    pub fn param_specs(&self) -> &'static [ParamSpec] {
        self.kind.param_specs()
    }

    /// The values of the parameters, in the order of
    /// [`Scene::param_specs`].
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// `pairs` of parameter names and values with the parameters that have
    /// levels (the schemes) first, each group in its order: set in this
    /// order, the knobs given with a scheme override it.
    pub fn schemes_first<'a, T>(
        &self,
        pairs: impl IntoIterator<Item = (&'a str, T)>,
    ) -> Vec<(&'a str, T)> {
        let (mut schemes, knobs): (Vec<_>, Vec<_>) = pairs
            .into_iter()
            .partition(|(name, _)| self.spec(name).is_ok_and(|s| !s.levels.is_empty()));
        schemes.extend(knobs);
        schemes
    }

    /// The row of the parameter `name`.
    pub fn spec(&self, name: &str) -> Result<&'static ParamSpec> {
        Ok(&self.param_specs()[self.index(name)?])
    }

    /// The level that sets `name` to its current value, with the name of
    /// the parameter of that level, where `name` was not set by hand (the
    /// scheme's value, not an override).
    fn set_by_level(&self, name: &str) -> Option<(&'static str, &'static params::Level)> {
        let k = self.index(name).ok()?;
        if self.by_hand[k] {
            return None;
        }
        self.param_specs()
            .iter()
            .zip(&self.values)
            .filter_map(|(spec, v)| Some((spec.name, spec.level(*v)?)))
            .find(|(_, level)| {
                level
                    .sets
                    .iter()
                    .any(|(n, x)| *n == name && *x == self.values[k])
            })
    }

    /// Marks as set by hand every knob whose value is not its level's (a
    /// scene whose values were put whole, as a saved state's).
    fn mark_overrides(&mut self) {
        let specs = self.param_specs();
        for (spec, v) in specs.iter().zip(self.values.clone()) {
            if let Some(level) = spec.level(v) {
                for (name, x) in level.sets {
                    if let Ok(k) = self.index(name) {
                        self.by_hand[k] = self.values[k] != *x;
                    }
                }
            }
        }
    }

    /// The level of the parameter `name` (a scheme), if it has levels.
    pub fn level(&self, name: &str) -> Result<Option<&'static params::Level>> {
        let k = self.index(name)?;
        Ok(self.param_specs()[k].level(self.values[k]))
    }

    /// Position of the parameter `name` in the table.
    fn index(&self, name: &str) -> Result<usize> {
        self.param_specs()
            .iter()
            .position(|s| s.name == name)
            .ok_or_else(|| Error::UnknownParameter {
                name: name.to_string(),
                scene: self.kind.to_string(),
                allowed: self
                    .param_specs()
                    .iter()
                    .map(|s| s.name)
                    .collect::<Vec<_>>()
                    .join(", "),
            })
    }

    /// Chooses the material models of the scene's body: the models
    /// `choice` take the place of the current ones. The parameters the two
    /// tables share keep their values; the new model's parameters start at
    /// their defaults.
    pub fn set_material(&mut self, choice: MaterialChoice) -> Result<()> {
        let kind = self.kind.with_material(choice)?;
        let values = kind
            .param_specs()
            .iter()
            .map(|spec| self.get(spec.name).unwrap_or(spec.default))
            .collect();
        let by_hand = kind
            .param_specs()
            .iter()
            .map(|spec| self.index(spec.name).is_ok_and(|k| self.by_hand[k]))
            .collect();
        self.kind = kind;
        self.values = values;
        self.by_hand = by_hand;
        Ok(())
    }

    /// Chooses the material by names, as the `[material]` table of a scene
    /// file, the CLI's `--strength`, `--eos` and `--preset` and the C ABI's
    /// `mi_sim_set_material` give them: a `preset` takes its models and sets
    /// every parameter of them to its values (a `strength` or `eos` given
    /// with it must be the preset's own); `strength` and `eos` replace the
    /// current models (see [`Scene::set_material`]). Unknown names are refused
    /// with the list of known ones; nothing changes on an error.
    pub fn choose_material(
        &mut self,
        strength: Option<&str>,
        eos: Option<&str>,
        preset: Option<&str>,
    ) -> Result<()> {
        let strength = strength.map(StrengthKind::named).transpose()?;
        let eos = eos.map(EosKind::named).transpose()?;
        let preset = preset.map(Preset::named).transpose()?;
        let current = match (self.kind.material, &self.kind.row.material) {
            (Some(c), _) => c,
            (None, _) => {
                let name = [strength.map(|s| s.name()), eos.map(|e| e.name())]
                    .into_iter()
                    .flatten()
                    .chain(preset.map(|p| p.name))
                    .collect::<Vec<_>>()
                    .join(", ");
                return Err(Error::UnknownModel {
                    key: "material".into(),
                    name,
                    allowed: format!(
                        "none: scene `{}` has no material to choose",
                        self.kind.name()
                    ),
                });
            }
        };
        let mut next = self.clone();
        let choice = match preset {
            Some(p) => {
                for (given, own) in [
                    (strength.map(|s| s.name()), p.choice.strength.name()),
                    (eos.map(|e| e.name()), p.choice.eos.name()),
                ] {
                    if let Some(given) = given
                        && given != own
                    {
                        return Err(Error::Inconsistent(format!(
                            "preset `{}` has {}; `{given}` contradicts it (give the preset and set its \
                             parameters, or name the models without a preset)",
                            p.name, p.choice
                        )));
                    }
                }
                p.choice
            }
            None => MaterialChoice {
                strength: strength.unwrap_or(current.strength),
                eos: eos.unwrap_or(current.eos),
            },
        };
        next.set_material(choice)?;
        if let Some(p) = preset {
            for spec in p.choice.param_specs(Prefix::None) {
                let v = p
                    .value(spec.name)
                    .expect("a preset gives every parameter of its models");
                next.set(spec.name, v)?;
            }
        }
        *self = next;
        Ok(())
    }
    /// The reference under the observable `name` itself (for the rod
    /// scenes the experiment's), if the scene has one.
    pub fn reference_of(&self, name: &str) -> Option<f64> {
        self.reference.get(name).copied()
    }

    /// The converged continuum reference of the observable `name`
    /// (`NAME_continuum` in the reference table), if the scene has one.
    pub fn continuum_reference_of(&self, name: &str) -> Option<f64> {
        self.reference
            .get(&format!("{name}{CONTINUUM_SUFFIX}"))
            .copied()
    }

    /// Whether the scene has both an experiment's and a converged
    /// continuum reference for some observable: its tables then show both.
    pub fn has_continuum_reference(&self) -> bool {
        self.reference.keys().any(|k| {
            k.strip_suffix(CONTINUUM_SUFFIX)
                .is_some_and(|name| self.reference.contains_key(name))
        })
    }

    /// Current value of a parameter.
    pub fn get(&self, name: &str) -> Result<f64> {
        Ok(self.values[self.index(name)?])
    }

    /// Sets a parameter after checking its name and range. Cross-parameter
    /// constraints are checked by [`Scene::validate`]. A parameter with
    /// levels (a scheme) also sets the knobs of its level that were not set
    /// by hand; any other parameter is then set by hand, and a scheme chosen
    /// before or after leaves it alone.
    pub fn set(&mut self, name: &str, value: f64) -> Result<()> {
        let k = self.index(name)?;
        let spec = self.param_specs()[k];
        spec.check(value)?;
        match spec.level(value) {
            Some(level) => {
                let mut next = self.values.clone();
                for (knob, x) in level.sets {
                    let j = self.index(knob)?;
                    if !self.by_hand[j] {
                        next[j] = *x;
                    }
                }
                next[k] = value;
                self.values = next;
            }
            None => {
                // A knob set to the value its scheme gives it stays the
                // scheme's: a host that sets every parameter to its start
                // value has still chosen no knob.
                let scheme_value = self.set_by_level(name).map(|_| self.values[k]);
                self.by_hand[k] = self.by_hand[k] || scheme_value != Some(value);
                self.values[k] = value;
            }
        }
        Ok(())
    }

    /// Parses `text` as a number (or the name of a level, for a parameter
    /// with levels) and sets the parameter.
    pub fn set_str(&mut self, name: &str, text: &str) -> Result<()> {
        let v = self.spec(name)?.parse(text)?;
        self.set(name, v)
    }

    /// Checks every parameter against its range and the cross-parameter
    /// constraints.
    pub fn validate(&self) -> Result<()> {
        for (spec, v) in self.param_specs().iter().zip(&self.values) {
            spec.check(*v)?;
        }
        // A reference is a measured or exact value: a number.
        if let Some((name, &value)) = self.reference.iter().find(|(_, v)| !v.is_finite()) {
            return Err(Error::OutOfRange {
                name: format!("[reference] {name}"),
                value,
                range: "a finite number".into(),
            });
        }
        let row = self.kind.row();
        (row.check)(self)?;
        crate::budget::check_memory((row.nodes)(self), (row.memory)(self))
    }

    /// The run's node count as the memory budget estimates it from the
    /// parameters, before anything is built.
    pub fn estimated_nodes(&self) -> f64 {
        (self.kind.row().nodes)(self)
    }

    /// The peak bytes a node of the run's solver (and scheme) that the
    /// memory budget estimates: for the 3-D scenes, an upper bound on the
    /// heap's peak a node within twice it (`tests/mlpg_alloc.rs`).
    pub fn memory_per_node(&self) -> f64 {
        (self.kind.row().memory)(self).bytes
    }

    /// The run's estimated peak memory (bytes) that the memory budget
    /// checks ([`crate::memory_budget`]): a base for the program and
    /// [`Scene::estimated_nodes`] at [`Scene::memory_per_node`].
    pub fn memory_estimate(&self) -> f64 {
        let row = self.kind.row();
        crate::budget::estimate(self.estimated_nodes(), (row.memory)(self))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fields a scene's row declares (what the reference pages list)
    /// are the fields a run of it gives, for every built-in scene and
    /// material choice.
    #[test]
    fn every_rows_fields_are_its_runs_fields() {
        for name in builtin_names() {
            let mut scene = Scene::builtin(&name).unwrap();
            // Coarse, where the scene has a resolution across: the fields
            // do not depend on it.
            let _ = scene.set("particles_radial", 3.0);
            let run = crate::Simulation::new(scene.clone()).unwrap();
            let names = |f: &[crate::observe::FieldSpec]| {
                f.iter()
                    .map(|s| (s.name, s.unit, s.components))
                    .collect::<Vec<_>>()
            };
            assert_eq!(
                names(scene.kind().field_specs()),
                names(run.field_specs()),
                "{name}"
            );
        }
    }

    #[test]
    fn unknown_parameter_lists_allowed_names() {
        let mut s = Scene::builtin("taylor").unwrap();
        let e = s.set("impact_sped", 100.0).unwrap_err();
        let msg = e.to_string();
        assert!(
            msg.contains("impact_sped") && msg.contains("impact_speed, initial_length"),
            "{msg}"
        );
        // Noh does not take strength parameters.
        let mut n = Scene::builtin("noh").unwrap();
        assert!(matches!(
            n.set("jc_a", 1.0),
            Err(Error::UnknownParameter { .. })
        ));
    }

    #[test]
    fn out_of_range_and_non_finite_values_are_rejected_with_the_range() {
        let mut s = Scene::builtin("taylor").unwrap();
        for (name, v) in [
            ("density", -1.0),
            ("initial_diameter", 0.0),
            ("impact_speed", f64::NAN),
            ("impact_speed", f64::INFINITY),
            ("particles_radial", 0.0),
            ("particles_radial", 20.5),
            ("smoothing_coefficient", 0.6),
        ] {
            let e = s.set(name, v).unwrap_err();
            let msg = e.to_string();
            assert!(msg.contains(name) && msg.contains("allowed"), "{msg}");
        }
        assert_eq!(s, Scene::builtin("taylor").unwrap(), "nothing changed");
        assert!(matches!(
            s.set_str("jc_a", "lots"),
            Err(Error::ParseValue { .. })
        ));
    }

    #[test]
    fn inconsistent_temperatures_are_rejected() {
        let mut s = Scene::builtin("taylor").unwrap();
        s.set("melt_temperature", 250.0).unwrap();
        assert!(matches!(s.validate(), Err(Error::Inconsistent(_))));
    }

    #[test]
    fn toml_round_trip_and_errors() {
        let s = Scene::builtin("table1-3").unwrap();
        let back = Scene::from_toml_str(&s.to_toml()).unwrap();
        assert_eq!(s, back);
        assert!(matches!(
            Scene::from_toml_str("scene = \"taylor\"\n[parameters]\nfoo = 1\n"),
            Err(Error::UnknownParameter { .. })
        ));
        assert!(matches!(
            Scene::from_toml_str("scene = \"cube\"\n"),
            Err(Error::UnknownScene { .. })
        ));
        assert!(matches!(
            Scene::from_toml_str("scene = "),
            Err(Error::SceneFile(_))
        ));
        assert!(matches!(
            Scene::builtin("table1-13"),
            Err(Error::UnknownScene { .. })
        ));
    }

    #[test]
    fn builtin_accepts_only_the_exact_names() {
        for name in [
            "table1-01",
            "table1-+1",
            "table1-0",
            "table1-13",
            "table1- 1",
            "table1-1 ",
            "TAYLOR",
            "Noh",
            "table1-",
            "",
        ] {
            match Scene::builtin(name) {
                Err(e @ Error::UnknownScene { .. }) => {
                    let msg = e.to_string();
                    assert!(
                        msg.starts_with(&format!(
                            "unknown scene `{name}`; allowed: taylor, noh, taylor3d, penetration, plate_impact, table1-1,"
                        )),
                        "{msg}"
                    );
                    assert!(msg.ends_with("table1-12, taylor3d-aisi310"), "{msg}");
                }
                other => panic!("`{name}` accepted or refused oddly: {other:?}"),
            }
        }
        let rows = table1::Table1Row::all();
        for (k, name) in builtin_names().iter().enumerate() {
            let scene = Scene::builtin(name).unwrap();
            match k {
                0 => assert_eq!(
                    scene,
                    Scene::default_of(SceneKind::named("taylor").unwrap())
                ),
                1 => assert_eq!(scene, Scene::default_of(SceneKind::named("noh").unwrap())),
                2 => assert_eq!(
                    scene,
                    Scene::default_of(SceneKind::named("taylor3d").unwrap())
                ),
                3 => assert_eq!(
                    scene,
                    Scene::default_of(SceneKind::named("penetration").unwrap())
                ),
                4 => assert_eq!(
                    scene,
                    Scene::default_of(SceneKind::named("plate_impact").unwrap())
                ),
                5..17 => assert_eq!(scene, rows[k - 5].scene(), "{name}"),
                _ => {
                    assert_eq!(name, "taylor3d-aisi310");
                    assert_eq!(scene.kind().name(), "taylor3d");
                    assert_eq!(scene.get("yield_stress").unwrap(), 310.26e6);
                    assert_eq!(scene.get("initial_diameter").unwrap(), 7.62e-3);
                }
            }
        }
        assert_eq!(builtin_names().len(), 18);
    }

    /// A `[material]` table chooses the models; the table then lists only
    /// their parameters, a preset sets them all and `[parameters]` may
    /// override them; a parameter of other models is refused by name, as
    /// are unknown names and a preset contradicted by `strength` or `eos`.
    #[test]
    fn material_table_chooses_the_models_and_their_parameters() {
        let s = Scene::from_toml_str(
            "scene = \"taylor\"\n[material]\nstrength = \"bilinear\"\neos = \"mie_gruneisen\"\n\
             [parameters]\nyield_stress = 3e8\neos_s = 1.5\n",
        )
        .unwrap();
        assert_eq!(
            s.kind().material(),
            Some(MaterialChoice::BILINEAR_MIE_GRUNEISEN)
        );
        assert_eq!(s.get("yield_stress").unwrap(), 3e8);
        assert_eq!(s.get("eos_s").unwrap(), 1.5);
        assert_eq!(s.get("eos_c0").unwrap(), 4578.0);
        for gone in ["jc_a", "bulk_modulus", "melt_temperature"] {
            let e = s.get(gone).unwrap_err().to_string();
            assert!(
                e.contains(gone) && e.contains("strength = bilinear, eos = mie_gruneisen"),
                "{e}"
            );
        }
        let back = Scene::from_toml_str(&s.to_toml()).unwrap();
        assert_eq!(back, s);
        // The default choice writes no [material] table.
        assert!(
            !Scene::builtin("taylor")
                .unwrap()
                .to_toml()
                .contains("[material]")
        );

        let p = Scene::from_toml_str(
            "scene = \"taylor\"\n[material]\npreset = \"ofhc_copper_jc\"\n\
             [parameters]\njc_a = 1e8\n",
        )
        .unwrap();
        assert_eq!(p.get("density").unwrap(), 8960.0);
        assert_eq!(p.get("jc_a").unwrap(), 1e8);
        assert_eq!(p.get("jc_b").unwrap(), 292e6);

        for (text, needle) in [
            (
                "[material]\nstrength = \"johnson_cook\"\n[parameters]\nyield_stress = 1e8\n",
                "unknown parameter `yield_stress`",
            ),
            (
                "[material]\nstrength = \"plastic\"\n",
                "johnson_cook, bilinear",
            ),
            ("[material]\npreset = \"ofhc_copper\"\n", "ofhc_copper_jc"),
            (
                "[material]\npreset = \"tungsten_seed\"\nstrength = \"johnson_cook\"\n",
                "contradicts",
            ),
            (
                "[material]\nmodel = \"bilinear\"\n",
                "`model` is not a constant of the material of scene `taylor`; allowed: strength, eos, preset, density",
            ),
            (
                "[material]\njc_a = \"hard\"\n",
                "`jc_a`: cannot parse `hard`",
            ),
        ] {
            let e = Scene::from_toml_str(&format!("scene = \"taylor\"\n{text}"))
                .unwrap_err()
                .to_string();
            assert!(e.contains(needle), "{text}: {e}");
        }
        let e = Scene::from_toml_str("scene = \"noh\"\n[material]\neos = \"linear\"\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("no material"), "{e}");
    }

    /// Every scheme of every scene names knobs of its table with values in
    /// their ranges, every level of a scheme sets the same knobs, and the
    /// table's defaults are the default level's values (for every material
    /// choice).
    #[test]
    fn schemes_set_knobs_of_their_tables_and_the_defaults_are_the_default_scheme() {
        let mut seen = 0;
        for row in registry::SCENES {
            let kind = SceneKind::default_of_row(row);
            let choices: Vec<SceneKind> = match &row.material {
                Some(_) => MaterialChoice::ALL
                    .iter()
                    .map(|c| kind.with_material(*c).unwrap())
                    .collect(),
                None => vec![kind],
            };
            for kind in choices {
                let specs = kind.param_specs();
                for spec in specs.iter().filter(|p| !p.levels.is_empty()) {
                    seen += 1;
                    let knobs: Vec<&str> = spec.levels[0].sets.iter().map(|(n, _)| *n).collect();
                    for level in spec.levels {
                        let names: Vec<&str> = level.sets.iter().map(|(n, _)| *n).collect();
                        assert_eq!(names, knobs, "{kind} {}", level.name);
                        for (n, v) in level.sets {
                            let knob = specs.iter().find(|p| p.name == *n).unwrap();
                            knob.check(*v).unwrap();
                        }
                    }
                    let default = &spec.levels[spec.default as usize];
                    for (n, v) in default.sets {
                        let knob = specs.iter().find(|p| p.name == *n).unwrap();
                        assert_eq!(knob.default, *v, "{kind}: {n}");
                    }
                }
            }
        }
        // taylor's and taylor3d's schemes for each of four choices,
        // penetration's scheme, its run_until, its plate_rim, its
        // plate_node_order, its plate_model and its plate_ceramic,
        // plate_impact's two plate materials and its plate_ceramic.
        assert_eq!(seen, 17);
    }

    /// A scheme sets its knobs; a knob set by hand overrides it whichever
    /// comes first; a knob set to the value its scheme gives it stays the
    /// scheme's; names and numbers both choose a level; unknown names list
    /// the known ones.
    #[test]
    fn a_scheme_sets_its_knobs_and_a_knob_set_by_hand_overrides_it() {
        let mut s = Scene::builtin("taylor").unwrap();
        assert_eq!(s.level("scheme").unwrap().unwrap().name, "large_strain");
        s.set_str("scheme", "paper").unwrap();
        assert_eq!(s.get("smoothing_order").unwrap(), 1.0);
        assert_eq!(s.get("smoothing_ratio").unwrap(), 1.5);
        assert_eq!(s.get("shifting").unwrap(), 0.0);
        // By hand after the scheme, then the scheme again: the knob stays.
        s.set("shifting", 0.05).unwrap();
        s.set_str("scheme", "large_strain").unwrap();
        assert_eq!(s.get("shifting").unwrap(), 0.05);
        assert_eq!(s.get("smoothing_order").unwrap(), 2.0);
        // By hand before the scheme: the knob stays.
        let mut t = Scene::builtin("taylor").unwrap();
        t.set("smoothing_ratio", 3.0).unwrap();
        t.set("scheme", 1.0).unwrap();
        assert_eq!(t.get("smoothing_ratio").unwrap(), 3.0);
        assert_eq!(t.get("smoothing_order").unwrap(), 1.0);
        // Every knob set to its start value (as an FMI host may) chooses no
        // knob: the paper's scheme then sets them all.
        let mut u = Scene::builtin("taylor").unwrap();
        for spec in u.param_specs() {
            u.set(spec.name, spec.default).unwrap();
        }
        u.set_str("scheme", "paper").unwrap();
        let mut paper = Scene::builtin("taylor").unwrap();
        paper.set_str("scheme", "paper").unwrap();
        assert_eq!(u, paper);
        let e = u.set_str("scheme", "fast").unwrap_err().to_string();
        assert!(
            e.contains("scheme") && e.contains("large_strain, paper"),
            "{e}"
        );
        assert!(u.set("scheme", 2.0).is_err());
        assert_eq!(u, paper, "nothing changes on an error");
        assert!(
            Scene::builtin("noh")
                .unwrap()
                .set_str("scheme", "paper")
                .is_err()
        );
    }

    /// A scene file chooses the scheme by name, its knobs override it in
    /// any order, and a written scene reads back the same, its scheme's
    /// knobs as comments (so that another scheme chosen in the file
    /// takes effect).
    #[test]
    fn scene_files_choose_the_scheme_by_name() {
        let s = Scene::from_toml_str(
            "scene = \"taylor\"\n[parameters]\nshifting = 0.2\nscheme = \"paper\"\n",
        )
        .unwrap();
        assert_eq!(s.level("scheme").unwrap().unwrap().name, "paper");
        assert_eq!(s.get("shifting").unwrap(), 0.2);
        assert_eq!(s.get("smoothing_order").unwrap(), 1.0);
        let text = s.to_toml();
        assert!(text.contains("scheme = \"paper\""), "{text}");
        assert!(text.contains("# smoothing_order = 1.0"), "{text}");
        assert!(text.contains("\nshifting = 0.2"), "{text}");
        assert_eq!(Scene::from_toml_str(&text).unwrap(), s);
        let other = text.replace("scheme = \"paper\"", "scheme = \"large_strain\"");
        let o = Scene::from_toml_str(&other).unwrap();
        assert_eq!(o.get("smoothing_order").unwrap(), 2.0);
        assert_eq!(o.get("shifting").unwrap(), 0.2);
        let e = Scene::from_toml_str("scene = \"taylor\"\n[parameters]\nscheme = \"fast\"\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("fast") && e.contains("large_strain, paper"),
            "{e}"
        );
    }

    /// The combinations that cannot work are refused when the scene is
    /// validated, with both parameters named: conforming gradients
    /// (`weak_form = 2`, the 3-D default) on the quarter model.
    #[test]
    fn unworkable_scheme_combinations_are_refused_by_name() {
        for scene in ["taylor3d", "penetration"] {
            let mut s = Scene::builtin(scene).unwrap();
            s.set("weak_form", 2.0).unwrap();
            s.set("symmetry", 1.0).unwrap();
            let e = s.validate().unwrap_err().to_string();
            assert!(
                e.contains("weak_form = 2") && e.contains("symmetry = 1"),
                "{scene}: {e}"
            );
            s.set("weak_form", 1.0).unwrap();
            s.validate().unwrap();
        }
    }

    /// Changing the models keeps the parameters both tables share.
    #[test]
    fn set_material_keeps_shared_values() {
        let mut s = Scene::builtin("taylor").unwrap();
        s.set("density", 8000.0).unwrap();
        s.set("particles_radial", 7.0).unwrap();
        s.choose_material(Some("bilinear"), None, None).unwrap();
        assert_eq!(s.get("density").unwrap(), 8000.0);
        assert_eq!(s.get("particles_radial").unwrap(), 7.0);
        assert_eq!(s.get("hardening_modulus").unwrap(), 510e6);
        s.choose_material(Some("johnson_cook"), None, None).unwrap();
        assert_eq!(s.get("jc_a").unwrap(), 792e6);
        let before = s.clone();
        assert!(
            s.choose_material(Some("bilinear"), Some("nope"), None)
                .is_err()
        );
        assert_eq!(s, before, "nothing changes on an error");
    }
}
