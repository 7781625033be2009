//! Scenes: what is simulated (geometry, material, physics, boundaries,
//! observables, end condition) and its parameters. Scenes are built in
//! (`taylor`, `noh`, `table1-1` ... `table1-12`) or read from TOML files.

pub mod noh;
pub mod params;
pub mod penetration;
pub mod registry;
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

/// A complete, validated-on-demand description of one run: a kind of scene
/// and a value for each parameter of its table.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// Human-readable title.
    pub title: String,
    kind: SceneKind,
    /// One value per row of the kind's parameter table, in its order.
    values: Vec<f64>,
    /// Optional reference values (for example experimental results), by name.
    pub reference: BTreeMap<String, f64>,
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
        // Values are put as they are (a restored state is checked whole
        // afterwards); names must be the kind's.
        for (name, v) in params {
            let k = scene.index(&name).map_err(D::Error::custom)?;
            scene.values[k] = v;
        }
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

/// The `[material]` table of a scene file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct MaterialTable {
    #[serde(default)]
    strength: Option<String>,
    #[serde(default)]
    eos: Option<String>,
    #[serde(default)]
    preset: Option<String>,
}

impl Scene {
    /// The default scene of a kind, with default parameters.
    pub fn default_of(kind: SceneKind) -> Scene {
        let row = kind.row();
        Scene {
            title: row.title.to_string(),
            kind,
            values: kind.param_specs().iter().map(|p| p.default).collect(),
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
            scene.choose_material(m.strength.as_deref(), m.eos.as_deref(), m.preset.as_deref())?;
        }
        for (name, value) in &file.parameters {
            let v = match value {
                toml::Value::Float(f) => *f,
                toml::Value::Integer(i) => *i as f64,
                other => {
                    return Err(Error::ParseValue {
                        name: name.clone(),
                        text: other.to_string(),
                    });
                }
            };
            scene.set(name, v)?;
        }
        scene.validate()?;
        Ok(scene)
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
            out.push_str(&format!("{} = {:?}  # {}\n", spec.name, v, spec.unit));
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
        self.kind = kind;
        self.values = values;
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

    /// Current value of a parameter.
    pub fn get(&self, name: &str) -> Result<f64> {
        Ok(self.values[self.index(name)?])
    }

    /// Sets a parameter after checking its name and range. Cross-parameter
    /// constraints are checked by [`Scene::validate`].
    pub fn set(&mut self, name: &str, value: f64) -> Result<()> {
        let k = self.index(name)?;
        self.param_specs()[k].check(value)?;
        self.values[k] = value;
        Ok(())
    }

    /// Parses `text` as a number and sets the parameter.
    pub fn set_str(&mut self, name: &str, text: &str) -> Result<()> {
        self.index(name)?;
        let v: f64 = text.trim().parse().map_err(|_| Error::ParseValue {
            name: name.to_string(),
            text: text.to_string(),
        })?;
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
        crate::budget::check_memory((row.nodes)(self), row.memory)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
                            "unknown scene `{name}`; allowed: taylor, noh, taylor3d, penetration, table1-1,"
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
                4..16 => assert_eq!(scene, rows[k - 4].scene(), "{name}"),
                _ => {
                    assert_eq!(name, "taylor3d-aisi310");
                    assert_eq!(scene.kind().name(), "taylor3d");
                    assert_eq!(scene.get("yield_stress").unwrap(), 310.26e6);
                    assert_eq!(scene.get("initial_diameter").unwrap(), 7.62e-3);
                }
            }
        }
        assert_eq!(builtin_names().len(), 17);
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
            ("[material]\nmodel = \"bilinear\"\n", "unknown field"),
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
