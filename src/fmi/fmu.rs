//! The FMU description: which FMUs the registry declares ([`Fmu`]), their
//! variables ([`Variable`], of a [`VarType`] and a [`VarKind`]) and value
//! references, and the instantiation token derived from them. The single
//! source of the value references: the glue and the model description
//! ([`super::model_description`]) both read [`Fmu::variables`].

use crate::SceneKind;
use crate::observe::ObservableSpec;
use crate::scene::params::ParamSpec;
use crate::scene::registry::{FmuIdentity, SceneRow};

/// One FMU: a kind of scene (a registry row and its material choice) with
/// an FMU identity.
#[derive(Clone, Copy)]
pub struct Fmu(SceneKind, FmuIdentity);

impl std::fmt::Debug for Fmu {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Fmu({})", self.identity().model_identifier)
    }
}

impl PartialEq for Fmu {
    fn eq(&self, other: &Self) -> bool {
        self.0 == other.0
    }
}

impl Fmu {
    /// Every FMU the registry declares, in its order.
    pub fn all() -> Vec<Fmu> {
        crate::scene::registry::fmus()
            .into_iter()
            .map(|(kind, id)| Fmu(kind, id))
            .collect()
    }

    /// The FMU whose model identifier is `id`.
    pub fn named(id: &str) -> Option<Fmu> {
        Fmu::all()
            .into_iter()
            .find(|f| f.identity().model_identifier == id)
    }

    /// The FMU whose instantiation token (GUID) is `token`.
    pub fn with_token(token: &str) -> Option<Fmu> {
        Fmu::all().into_iter().find(|f| f.token() == token)
    }

    /// The model identifier, name and description.
    pub fn identity(self) -> FmuIdentity {
        self.1
    }

    /// The scene row it packages.
    pub fn row(self) -> &'static SceneRow {
        self.0.row()
    }

    /// The scene kind it runs (its material choice included).
    pub fn kind(self) -> SceneKind {
        self.0
    }

    /// Every variable of the FMU: `time` (value reference 0, listed only in
    /// the FMI 3 model description), then the scene's parameters in table
    /// order (value references 1, 2, ...), then its observables in table
    /// order. This is the single source of the value references.
    pub fn variables(self) -> Vec<Variable> {
        let mut out = vec![Variable {
            vr: VR_TIME,
            name: "time",
            ty: VarType::Float64,
            kind: VarKind::Time,
        }];
        let mut vr = 1;
        for p in self.0.param_specs() {
            out.push(Variable {
                vr,
                name: p.name,
                ty: if !p.levels.is_empty() {
                    VarType::Enumeration
                } else if p.range.integer {
                    VarType::Int32
                } else {
                    VarType::Float64
                },
                kind: VarKind::Parameter(p),
            });
            vr += 1;
        }
        for (k, o) in self.0.observable_specs().iter().enumerate() {
            out.push(Variable {
                vr,
                name: o.name,
                ty: if o.is_bool() {
                    VarType::Boolean
                } else {
                    VarType::Float64
                },
                kind: VarKind::Output(k, o),
            });
            vr += 1;
        }
        out
    }

    /// The instantiation token (FMI 3) / GUID (FMI 2): a deterministic hash
    /// of the model identifier, the crate version and the generated
    /// variable list, formatted as a GUID.
    pub fn token(self) -> String {
        // 128-bit FNV-1a over a canonical text of everything a host relies on.
        let mut text = format!("{} {}\n", self.identity().model_identifier, crate::VERSION);
        for v in self.variables() {
            text.push_str(&format!("{} {} {:?} {}", v.vr, v.name, v.ty, v.unit()));
            if let VarKind::Parameter(p) = v.kind {
                text.push_str(&format!(" {:e} {}", p.default, p.range));
            }
            text.push('\n');
        }
        let mut h: u128 = 0x6c62272e07bb014262b821756295c58d;
        for b in text.bytes() {
            h ^= b as u128;
            h = h.wrapping_mul(0x0000000001000000000000000000013B);
        }
        let s = format!("{h:032x}");
        format!(
            "{{{}-{}-{}-{}-{}}}",
            &s[0..8],
            &s[8..12],
            &s[12..16],
            &s[16..20],
            &s[20..32]
        )
    }

    /// The FMU an instantiation asks for: the one whose token it gives, or
    /// with no token the first FMU; otherwise a message for the log.
    pub(crate) fn for_instantiation(function: &str, token: Option<&str>) -> Result<Fmu, String> {
        let Some(token) = token else {
            return Ok(Fmu::all()[0]);
        };
        Fmu::with_token(token).ok_or_else(|| {
            let known: Vec<String> = Fmu::all()
                .into_iter()
                .map(|f| format!("`{}` ({})", f.token(), f.identity().model_identifier))
                .collect();
            format!(
                "{function}: instantiation token `{token}` is not one of this library's FMUs: {}",
                known.join(", ")
            )
        })
    }
}

/// The FMI type of a variable.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VarType {
    /// `Float64` (FMI 3) / `Real` (FMI 2).
    Float64,
    /// `Int32` (FMI 3) / `Integer` (FMI 2).
    Int32,
    /// `Boolean`.
    Boolean,
    /// `Enumeration` (a parameter with named levels, the `scheme`): read and
    /// written as Int64 in FMI 3, declared as an `Integer` with its levels
    /// in the description in FMI 2 (read and written as Integer).
    Enumeration,
}

/// Where a variable's value lives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum VarKind {
    /// The independent variable `time` (FMI 3 only).
    Time,
    /// A scene parameter: causality parameter, variability fixed.
    Parameter(&'static ParamSpec),
    /// An observable, by its index in the scene's observable table:
    /// causality output.
    Output(usize, &'static ObservableSpec),
}

/// One variable of the FMU.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Variable {
    /// Value reference.
    pub vr: u32,
    /// Name (the same as the CLI's).
    pub name: &'static str,
    /// FMI type.
    pub ty: VarType,
    /// What the variable is.
    pub kind: VarKind,
}

impl Variable {
    /// SI unit as written in the tables ("1" dimensionless, "bool" flag).
    pub fn unit(&self) -> &'static str {
        match self.kind {
            VarKind::Time => "s",
            VarKind::Parameter(p) => p.unit,
            VarKind::Output(_, o) => o.unit,
        }
    }

    /// One-line meaning.
    pub fn description(&self) -> &'static str {
        match self.kind {
            VarKind::Time => "simulated time",
            VarKind::Parameter(p) => p.description,
            VarKind::Output(_, o) => o.description,
        }
    }
}

/// Value reference of `time` (FMI 3).
pub const VR_TIME: u32 = 0;

#[cfg(test)]
mod tests {
    use super::super::instance::{Instance, Standard};
    use super::super::log::LogSink;
    use super::super::taylor_fmu;
    use super::*;
    use crate::observe::TAYLOR_OBSERVABLES;
    use crate::scene::taylor::TAYLOR_PARAMS;

    #[test]
    fn variables_follow_the_tables() {
        let vars = taylor_fmu().variables();
        assert_eq!(
            vars.len(),
            1 + TAYLOR_PARAMS.len() + TAYLOR_OBSERVABLES.len()
        );
        assert_eq!(vars[0].name, "time");
        for (k, v) in vars.iter().enumerate() {
            assert_eq!(v.vr as usize, k, "value references are dense");
        }
        let pr = vars.iter().find(|v| v.name == "particles_radial").unwrap();
        assert_eq!(pr.ty, VarType::Int32);
        let rest = vars.iter().find(|v| v.name == "at_rest").unwrap();
        assert_eq!(rest.ty, VarType::Boolean);
        assert!(
            vars.iter()
                .all(|v| !matches!(v.name, "shock_radius" | "post_shock_density"))
        );
    }

    #[test]
    fn one_library_serves_every_fmu_of_the_registry() {
        let all = Fmu::all();
        assert!(all.contains(&taylor_fmu()));
        for (k, f) in all.iter().enumerate() {
            let id = f.identity().model_identifier;
            assert_eq!(Fmu::named(id), Some(*f), "{id}");
            assert_eq!(Fmu::with_token(&f.token()), Some(*f), "{id}");
            assert_eq!(Fmu::for_instantiation("x", Some(&f.token())), Ok(*f));
            for g in &all[k + 1..] {
                assert_ne!(id, g.identity().model_identifier);
                assert_ne!(f.token(), g.token());
            }
            // Its variables are its scene's tables.
            let n = 1 + f.kind().param_specs().len() + f.row().observables.len();
            assert_eq!(f.variables().len(), n, "{id}");
            assert_eq!(
                Instance::new(Standard::Fmi3, *f, "t", LogSink::None, false)
                    .scene
                    .kind(),
                f.kind()
            );
        }
        // No token: the first FMU; an unknown one: an error naming the known.
        assert_eq!(Fmu::for_instantiation("x", None), Ok(all[0]));
        let e = Fmu::for_instantiation("fmi3InstantiateCoSimulation", Some("{nope}")).unwrap_err();
        assert!(
            e.contains("`{nope}`") && e.contains(&taylor_fmu().token()),
            "{e}"
        );
        assert!(e.contains("TaylorImpact"), "{e}");
    }

    #[test]
    fn token_is_deterministic_and_guid_shaped() {
        let t = taylor_fmu().token();
        assert_eq!(t, taylor_fmu().token());
        assert_eq!(t.len(), 38);
        assert!(t.starts_with('{') && t.ends_with('}'));
    }
}
