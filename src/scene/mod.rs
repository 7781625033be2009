//! Scenes: what is simulated (geometry, material, physics, boundaries,
//! observables, end condition) and its parameters. Scenes are built in
//! (`taylor`, `noh`, `table1-1` ... `table1-12`) or read from TOML files.

pub mod noh;
pub mod params;
pub mod table1;
pub mod taylor;

use crate::error::{Error, Result};
use crate::observe::{NOH_OBSERVABLES, ObservableSpec, TAYLOR_OBSERVABLES};
use noh::{NOH_PARAMS, NohParams};
use params::ParamSpec;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use taylor::{TAYLOR_PARAMS, TaylorParams};

/// The kinds of scene the solver composes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SceneKind {
    /// Axisymmetric Taylor rod impact on a rigid anvil.
    Taylor,
    /// Cylindrical Noh implosion of an ideal gas (1-D in R).
    Noh,
}

impl SceneKind {
    /// The scene's name as used on the command line and in scene files.
    pub fn name(self) -> &'static str {
        match self {
            SceneKind::Taylor => "taylor",
            SceneKind::Noh => "noh",
        }
    }

    /// Parameter table of this kind of scene.
    pub fn param_specs(self) -> &'static [ParamSpec] {
        match self {
            SceneKind::Taylor => TAYLOR_PARAMS,
            SceneKind::Noh => NOH_PARAMS,
        }
    }

    /// Observables this kind of scene reports, in output order.
    pub fn observable_specs(self) -> &'static [ObservableSpec] {
        match self {
            SceneKind::Taylor => TAYLOR_OBSERVABLES,
            SceneKind::Noh => NOH_OBSERVABLES,
        }
    }
}

/// Parameter values of a scene, by kind.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum SceneParams {
    /// Taylor impact parameters.
    Taylor(TaylorParams),
    /// Noh parameters.
    Noh(NohParams),
}

/// A complete, validated-on-demand description of one run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Scene {
    /// Human-readable title.
    pub title: String,
    /// Parameter values.
    pub params: SceneParams,
    /// Optional reference values (for example experimental results), by name.
    pub reference: BTreeMap<String, f64>,
}

/// Names of the built-in scenes.
pub fn builtin_names() -> Vec<String> {
    let mut v = vec!["taylor".to_string(), "noh".to_string()];
    v.extend((1..=12).map(|k| format!("table1-{k}")));
    v
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
        match kind {
            SceneKind::Taylor => Scene {
                title: "Taylor impact, House et al. test 7 (4340 steel, 181 m/s)".into(),
                params: SceneParams::Taylor(TaylorParams::default()),
                reference: table1::Table1Row::all()[6].reference(),
            },
            SceneKind::Noh => Scene {
                title: "Cylindrical Noh problem (gamma = 5/3)".into(),
                params: SceneParams::Noh(NohParams::default()),
                reference: BTreeMap::from([
                    ("shock_radius".to_string(), 0.2),
                    ("post_shock_density".to_string(), 16.0),
                ]),
            },
        }
    }

    /// A built-in scene by name: `taylor`, `noh`, or `table1-N` for the N-th
    /// configuration of Table 1 (N = 1..12). Only these exact names are
    /// accepted (no other case, sign, leading zero or spaces).
    pub fn builtin(name: &str) -> Result<Scene> {
        match name {
            "taylor" => Ok(Scene::default_of(SceneKind::Taylor)),
            "noh" => Ok(Scene::default_of(SceneKind::Noh)),
            // Compared with the spelled-out names, not parsed as a number,
            // so `table1-01` or `table1-+1` are not taken for `table1-1`.
            _ => (1..=12)
                .find(|k| name == format!("table1-{k}"))
                .map(|k| table1::Table1Row::all()[k - 1].scene())
                .ok_or_else(|| Error::UnknownScene {
                    name: name.to_string(),
                    allowed: builtin_names().join(", "),
                }),
        }
    }

    /// Parses a TOML scene (see `scenes/` for examples).
    pub fn from_toml_str(text: &str) -> Result<Scene> {
        let file: SceneFile = toml::from_str(text).map_err(|e| Error::SceneFile(e.to_string()))?;
        let kind = match file.scene.as_str() {
            "taylor" => SceneKind::Taylor,
            "noh" => SceneKind::Noh,
            other => {
                return Err(Error::UnknownScene {
                    name: other.to_string(),
                    allowed: "taylor, noh".into(),
                });
            }
        };
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
        match self.params {
            SceneParams::Taylor(_) => SceneKind::Taylor,
            SceneParams::Noh(_) => SceneKind::Noh,
        }
    }

    /// The parameter table of this scene.
    pub fn param_specs(&self) -> &'static [ParamSpec] {
        self.kind().param_specs()
    }

    fn spec(&self, name: &str) -> Result<&'static ParamSpec> {
        self.param_specs()
            .iter()
            .find(|s| s.name == name)
            .ok_or_else(|| Error::UnknownParameter {
                name: name.to_string(),
                scene: self.kind().name().to_string(),
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
        self.spec(name)?;
        Ok(match &self.params {
            SceneParams::Taylor(p) => p.get(name),
            SceneParams::Noh(p) => p.get(name),
        }
        .expect("table and struct agree"))
    }

    /// Sets a parameter after checking its name and range. Cross-parameter
    /// constraints are checked by [`Scene::validate`].
    pub fn set(&mut self, name: &str, value: f64) -> Result<()> {
        self.spec(name)?.check(value)?;
        let slot = match &mut self.params {
            SceneParams::Taylor(p) => p.slot(name),
            SceneParams::Noh(p) => p.slot(name),
        };
        *slot.expect("table and struct agree") = value;
        Ok(())
    }

    /// Parses `text` as a number and sets the parameter.
    pub fn set_str(&mut self, name: &str, text: &str) -> Result<()> {
        self.spec(name)?;
        let v: f64 = text.trim().parse().map_err(|_| Error::ParseValue {
            name: name.to_string(),
            text: text.to_string(),
        })?;
        self.set(name, v)
    }

    /// Checks every parameter against its range and the cross-parameter
    /// constraints.
    pub fn validate(&self) -> Result<()> {
        for spec in self.param_specs() {
            spec.check(self.get(spec.name)?)?;
        }
        match &self.params {
            SceneParams::Taylor(p) => p.check_consistency(),
            SceneParams::Noh(p) => p.check_consistency(),
        }
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
                0 => assert_eq!(scene, Scene::default_of(SceneKind::Taylor)),
                1 => assert_eq!(scene, Scene::default_of(SceneKind::Noh)),
                _ => assert_eq!(scene, rows[k - 2].scene(), "{name}"),
            }
        }
        assert_eq!(builtin_names().len(), 14);
    }
}
