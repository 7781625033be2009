//! `modelDescription.xml` for FMI 3.0 and FMI 2.0, generated from
//! [`super::Fmu::variables`] (and so from the parameter and observable
//! tables of the FMU's scene row). `cargo xtask fmu` writes its output into the FMUs; there is no
//! hand-edited model description.

use super::{Fmu, LOG_CATEGORIES, VarKind, VarType, Variable};
use std::fmt::Write;

/// Which standard to describe.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FmiVersion {
    /// FMI 3.0 Co-Simulation.
    Fmi3,
    /// FMI 2.0 Co-Simulation.
    Fmi2,
}

/// SI base-unit exponents (kg, m, s, K, rad) of every unit string used in
/// the tables; `None` for a unit this generator does not know. A degree is
/// the radian with the factor of [`unit_factor`].
pub fn base_units(unit: &str) -> Option<&'static [(&'static str, i32)]> {
    Some(match unit {
        "1" => &[],
        "m" => &[("m", 1)],
        "s" => &[("s", 1)],
        "K" => &[("K", 1)],
        "m/s" => &[("m", 1), ("s", -1)],
        "1/s" => &[("s", -1)],
        "m3" => &[("m", 3)],
        "1/m3" => &[("m", -3)],
        "kg/m3" => &[("kg", 1), ("m", -3)],
        "Pa" => &[("kg", 1), ("m", -1), ("s", -2)],
        "J" => &[("kg", 1), ("m", 2), ("s", -2)],
        "J/m2" => &[("kg", 1), ("s", -2)],
        "J/(kg.K)" => &[("m", 2), ("s", -2), ("K", -1)],
        "deg" => &[("rad", 1)],
        _ => return None,
    })
}

/// The factor of a unit to its base units, where it is not 1: the degree,
/// pi / 180 rad.
pub fn unit_factor(unit: &str) -> Option<f64> {
    (unit == "deg").then_some(std::f64::consts::PI / 180.0)
}

/// Units of the tables that FMI's `BaseUnit` cannot express, its exponents
/// being integers: declared by name alone. Fracture toughness, Pa.m^(1/2),
/// is kg m^(-1/2) s^-2.
pub const NAME_ONLY_UNITS: &[&str] = &["Pa.m^(1/2)"];

/// Whether the model description can declare `unit`: by its base units
/// ([`base_units`]) or by name alone ([`NAME_ONLY_UNITS`]).
pub fn is_declared_unit(unit: &str) -> bool {
    base_units(unit).is_some() || NAME_ONLY_UNITS.contains(&unit)
}

/// The declared unit of a variable (none for flags).
fn declared_unit(v: &Variable) -> Option<&'static str> {
    match v.unit() {
        "bool" => None,
        u => Some(u),
    }
}

/// XML-escapes attribute text.
pub fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// A number as an xs:double (shortest round-trip form).
fn num(x: f64) -> String {
    format!("{x:?}")
}

/// The description of a variable as written in the model description: the
/// table's meaning plus, for parameters, the exact allowed interval (FMI
/// `min`/`max` are inclusive; the interval says which ends are open).
pub fn full_description(v: &Variable) -> String {
    match v.kind {
        VarKind::Parameter(p) => format!("{}; allowed {}", p.description, p.range),
        _ => v.description().to_string(),
    }
}

/// The name of the FMI 3 enumeration type of the parameter `name`.
fn enum_type(name: &str) -> String {
    format!("{name}_levels")
}

/// Default stop time of the experiment: the scene's `end_time` default.
fn default_stop_time(fmu: Fmu) -> f64 {
    fmu.kind()
        .param_specs()
        .iter()
        .find(|p| p.name == "end_time")
        .map(|p| p.default)
        .expect("every scene has end_time")
}

/// Default communication step of the experiment (1 µs).
pub const DEFAULT_STEP: f64 = 1.0e-6;

/// The model description of `fmu` in the given standard.
pub fn model_description(fmu: Fmu, version: FmiVersion) -> Result<String, String> {
    let vars: Vec<Variable> = fmu
        .variables()
        .into_iter()
        .filter(|v| version == FmiVersion::Fmi3 || v.kind != VarKind::Time)
        .collect();
    // FMI requires unique names: a scene's parameter and observable tables
    // must not share one.
    for (k, v) in vars.iter().enumerate() {
        if vars[..k].iter().any(|w| w.name == v.name) {
            return Err(format!(
                "variable name `{}` is used twice (a parameter and an output of the scene share it)",
                v.name
            ));
        }
    }
    let mut units: Vec<&str> = Vec::new();
    for v in &vars {
        if let Some(u) = declared_unit(v) {
            if !is_declared_unit(u) {
                return Err(format!(
                    "variable `{}`: unit `{u}` has no base-unit definition",
                    v.name
                ));
            }
            if !units.contains(&u) {
                units.push(u);
            }
        }
    }
    let token = fmu.token();
    let version_str = crate::VERSION;
    let identity = fmu.identity();
    let (model_name, model_identifier) = (identity.model_name, identity.model_identifier);
    let desc = identity.description;
    let mut x = String::new();
    x.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    match version {
        FmiVersion::Fmi3 => {
            writeln!(
                x,
                "<fmiModelDescription fmiVersion=\"3.0\" modelName=\"{model_name}\" description=\"{}\" \
                 instantiationToken=\"{token}\" version=\"{version_str}\" generationTool=\"meshless-impact {version_str}\" \
                 license=\"MIT OR Apache-2.0\" variableNamingConvention=\"flat\">",
                escape(desc)
            )
            .unwrap();
            writeln!(
                x,
                "  <CoSimulation modelIdentifier=\"{model_identifier}\" canHandleVariableCommunicationStepSize=\"true\" \
                 canGetAndSetFMUState=\"true\" canSerializeFMUState=\"true\" mightReturnEarlyFromDoStep=\"true\"/>"
            )
            .unwrap();
        }
        FmiVersion::Fmi2 => {
            writeln!(
                x,
                "<fmiModelDescription fmiVersion=\"2.0\" modelName=\"{model_name}\" description=\"{}\" \
                 guid=\"{token}\" version=\"{version_str}\" generationTool=\"meshless-impact {version_str}\" \
                 license=\"MIT OR Apache-2.0\" variableNamingConvention=\"flat\" numberOfEventIndicators=\"0\">",
                escape(desc)
            )
            .unwrap();
            writeln!(
                x,
                "  <CoSimulation modelIdentifier=\"{model_identifier}\" canHandleVariableCommunicationStepSize=\"true\" \
                 canNotUseMemoryManagementFunctions=\"true\" canGetAndSetFMUstate=\"true\" canSerializeFMUstate=\"true\"/>"
            )
            .unwrap();
        }
    }
    x.push_str("  <UnitDefinitions>\n");
    for u in &units {
        match base_units(u) {
            Some(exps) => {
                let mut attrs: String = exps.iter().map(|(b, e)| format!(" {b}=\"{e}\"")).collect();
                if let Some(f) = unit_factor(u) {
                    attrs.push_str(&format!(" factor=\"{f:?}\""));
                }
                writeln!(
                    x,
                    "    <Unit name=\"{}\">\n      <BaseUnit{attrs}/>\n    </Unit>",
                    escape(u)
                )
            }
            None => writeln!(x, "    <Unit name=\"{}\"/>", escape(u)),
        }
        .unwrap();
    }
    x.push_str("  </UnitDefinitions>\n");
    // FMI 3: an enumeration type per parameter with levels (the scheme),
    // named after it; FMI 2 declares it an Integer, its levels in the
    // description.
    let enums: Vec<&Variable> = vars
        .iter()
        .filter(|v| v.ty == VarType::Enumeration)
        .collect();
    if version == FmiVersion::Fmi3 && !enums.is_empty() {
        x.push_str("  <TypeDefinitions>\n");
        for v in &enums {
            let VarKind::Parameter(p) = v.kind else {
                continue;
            };
            writeln!(x, "    <EnumerationType name=\"{}\">", enum_type(p.name)).unwrap();
            for (k, level) in p.levels.iter().enumerate() {
                writeln!(
                    x,
                    "      <Item name=\"{}\" value=\"{k}\" description=\"{}\"/>",
                    level.name,
                    escape(level.description)
                )
                .unwrap();
            }
            x.push_str("    </EnumerationType>\n");
        }
        x.push_str("  </TypeDefinitions>\n");
    }
    x.push_str("  <LogCategories>\n");
    for (name, d) in LOG_CATEGORIES {
        writeln!(
            x,
            "    <Category name=\"{name}\" description=\"{}\"/>",
            escape(d)
        )
        .unwrap();
    }
    x.push_str("  </LogCategories>\n");
    writeln!(
        x,
        "  <DefaultExperiment startTime=\"0.0\" stopTime=\"{}\" stepSize=\"{}\"/>",
        num(default_stop_time(fmu)),
        num(DEFAULT_STEP)
    )
    .unwrap();
    x.push_str("  <ModelVariables>\n");
    for v in &vars {
        let unit_attr = declared_unit(v)
            .map(|u| format!(" unit=\"{}\"", escape(u)))
            .unwrap_or_default();
        let (causality, variability, initial) = match (v.kind, v.ty) {
            (VarKind::Time, _) => ("independent", "continuous", ""),
            (VarKind::Parameter(_), _) => ("parameter", "fixed", " initial=\"exact\""),
            (VarKind::Output(..), VarType::Float64) => {
                ("output", "continuous", " initial=\"calculated\"")
            }
            (VarKind::Output(..), _) => ("output", "discrete", " initial=\"calculated\""),
        };
        let bounds = match v.kind {
            VarKind::Parameter(p) => {
                let (min, max, start) = if matches!(v.ty, VarType::Int32 | VarType::Enumeration) {
                    (
                        format!("{}", p.range.min as i64),
                        format!("{}", p.range.max as i64),
                        format!("{}", p.default as i64),
                    )
                } else {
                    (num(p.range.min), num(p.range.max), num(p.default))
                };
                format!(" min=\"{min}\" max=\"{max}\" start=\"{start}\"")
            }
            _ => String::new(),
        };
        let d = escape(&full_description(v));
        match version {
            FmiVersion::Fmi3 => {
                let (elem, unit_attr) = match v.ty {
                    VarType::Float64 => ("Float64", unit_attr),
                    VarType::Int32 => ("Int32", String::new()),
                    VarType::Boolean => ("Boolean", String::new()),
                    VarType::Enumeration => (
                        "Enumeration",
                        format!(" declaredType=\"{}\"", enum_type(v.name)),
                    ),
                };
                // FMI 3: `initial` of the independent variable is not given.
                writeln!(
                    x,
                    "    <{elem} name=\"{}\" valueReference=\"{}\" description=\"{d}\" causality=\"{causality}\" \
                     variability=\"{variability}\"{initial}{unit_attr}{bounds}/>",
                    v.name, v.vr
                )
                .unwrap();
            }
            FmiVersion::Fmi2 => {
                let (elem, unit_attr) = match v.ty {
                    VarType::Float64 => ("Real", unit_attr),
                    VarType::Int32 | VarType::Enumeration => ("Integer", String::new()),
                    VarType::Boolean => ("Boolean", String::new()),
                };
                writeln!(
                    x,
                    "    <ScalarVariable name=\"{}\" valueReference=\"{}\" description=\"{d}\" causality=\"{causality}\" \
                     variability=\"{variability}\"{initial}>\n      <{elem}{unit_attr}{bounds}/>\n    </ScalarVariable>",
                    v.name, v.vr
                )
                .unwrap();
            }
        }
    }
    x.push_str("  </ModelVariables>\n");
    x.push_str("  <ModelStructure>\n");
    let outputs: Vec<(usize, &Variable)> = vars
        .iter()
        .enumerate()
        .filter(|(_, v)| matches!(v.kind, VarKind::Output(..)))
        .collect();
    match version {
        FmiVersion::Fmi3 => {
            for (_, v) in &outputs {
                writeln!(
                    x,
                    "    <Output valueReference=\"{}\" dependencies=\"\"/>",
                    v.vr
                )
                .unwrap();
            }
            for (_, v) in &outputs {
                writeln!(x, "    <InitialUnknown valueReference=\"{}\"/>", v.vr).unwrap();
            }
        }
        FmiVersion::Fmi2 => {
            x.push_str("    <Outputs>\n");
            for (k, _) in &outputs {
                writeln!(x, "      <Unknown index=\"{}\" dependencies=\"\"/>", k + 1).unwrap();
            }
            x.push_str("    </Outputs>\n    <InitialUnknowns>\n");
            for (k, _) in &outputs {
                writeln!(x, "      <Unknown index=\"{}\"/>", k + 1).unwrap();
            }
            x.push_str("    </InitialUnknowns>\n");
        }
    }
    x.push_str("  </ModelStructure>\n</fmiModelDescription>\n");
    Ok(x)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::observe::TAYLOR_OBSERVABLES;
    use crate::scene::taylor::TAYLOR_PARAMS;

    fn taylor() -> Fmu {
        Fmu::named("TaylorImpact").unwrap()
    }

    #[test]
    fn every_unit_of_the_tables_is_defined() {
        for fmu in Fmu::all() {
            for v in fmu.variables() {
                if let Some(u) = declared_unit(&v) {
                    assert!(is_declared_unit(u), "unit {u} of {}", v.name);
                }
            }
        }
    }

    /// Every FMU of the registry has a model description in both standards
    /// (unique names, every unit declared).
    #[test]
    fn every_fmu_is_described() {
        for fmu in Fmu::all() {
            for version in [FmiVersion::Fmi3, FmiVersion::Fmi2] {
                let id = fmu.identity().model_identifier;
                model_description(fmu, version).unwrap_or_else(|e| panic!("{id}: {e}"));
            }
        }
    }

    #[test]
    fn descriptions_list_every_table_row_once() {
        for version in [FmiVersion::Fmi3, FmiVersion::Fmi2] {
            let x = model_description(taylor(), version).unwrap();
            for p in TAYLOR_PARAMS {
                assert_eq!(
                    x.matches(&format!("name=\"{}\"", p.name)).count(),
                    1,
                    "{}",
                    p.name
                );
            }
            for o in TAYLOR_OBSERVABLES {
                assert_eq!(
                    x.matches(&format!("name=\"{}\"", o.name)).count(),
                    1,
                    "{}",
                    o.name
                );
            }
            assert!(x.contains(&taylor().token()));
            assert!(!x.contains("shock_radius"));
        }
        let x3 = model_description(taylor(), FmiVersion::Fmi3).unwrap();
        assert!(x3.contains("<Int32 name=\"particles_radial\""));
        assert!(x3.contains("<Boolean name=\"at_rest\""));
        assert!(x3.contains("start=\"181.0\""));
        let x2 = model_description(taylor(), FmiVersion::Fmi2).unwrap();
        assert!(x2.contains("canNotUseMemoryManagementFunctions=\"true\""));
        assert!(!x2.contains("name=\"time\""));
    }
}
