//! Scenes: what is simulated (geometry, material, physics, boundaries,
//! observables, end condition) and its parameters. Scenes are built in
//! (`taylor`, `noh`, `table1-1` ... `table1-12`) or read from TOML files.

pub mod noh;
pub mod params;
pub mod registry;
pub mod table1;
pub mod taylor;

use crate::error::{Error, Result};
use crate::observe::ObservableSpec;
use params::ParamSpec;
use registry::SceneRow;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// A kind of scene: a handle to its row of the scene registry
/// ([`registry::SCENES`]). Two kinds are equal when they are the same row.
#[derive(Clone, Copy)]
pub struct SceneKind(&'static SceneRow);

impl PartialEq for SceneKind {
    fn eq(&self, other: &Self) -> bool {
        std::ptr::eq(self.0, other.0)
    }
}

impl Eq for SceneKind {}

impl std::fmt::Debug for SceneKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "SceneKind({})", self.0.name)
    }
}

impl SceneKind {
    /// The kind called `name` (`taylor`, `noh`, ...), as the registry lists
    /// it.
    pub fn named(name: &str) -> Result<SceneKind> {
        registry::row(name).map(SceneKind)
    }

    /// The kind's registry row.
    pub fn row(self) -> &'static SceneRow {
        self.0
    }

    /// The scene's name as used on the command line and in scene files.
    pub fn name(self) -> &'static str {
        self.0.name
    }

    /// Parameter table of this kind of scene.
    pub fn param_specs(self) -> &'static [ParamSpec] {
        self.0.params
    }

    /// Observables this kind of scene reports, in output order.
    pub fn observable_specs(self) -> &'static [ObservableSpec] {
        self.0.observables
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
            .map(|row| SceneKind(row))
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
        let kind = SceneKind::with_saved_key(&key)
            .ok_or_else(|| D::Error::custom(format!("unknown kind of scene `{key}`")))?;
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
    parameters: BTreeMap<String, toml::Value>,
    #[serde(default)]
    reference: BTreeMap<String, f64>,
}

impl Scene {
    /// The default scene of a kind, with default parameters.
    pub fn default_of(kind: SceneKind) -> Scene {
        let row = kind.row();
        Scene {
            title: row.title.to_string(),
            kind,
            values: row.params.iter().map(|p| p.default).collect(),
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
                return Ok(Scene::default_of(SceneKind(row)));
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

    /// Writes the scene as TOML, every parameter included.
    pub fn to_toml(&self) -> String {
        let mut out = format!(
            "scene = \"{}\"\ntitle = {}\n\n[parameters]\n",
            self.kind().name(),
            toml::Value::String(self.title.clone())
        );
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
                scene: self.kind.name().to_string(),
                allowed: self
                    .param_specs()
                    .iter()
                    .map(|s| s.name)
                    .collect::<Vec<_>>()
                    .join(", "),
            })
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
        (self.kind.row().check)(self)
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
                            "unknown scene `{name}`; allowed: taylor, noh, table1-1,"
                        )),
                        "{msg}"
                    );
                    assert!(msg.ends_with("table1-12"), "{msg}");
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
                _ => assert_eq!(scene, rows[k - 2].scene(), "{name}"),
            }
        }
        assert_eq!(builtin_names().len(), 14);
    }
}
