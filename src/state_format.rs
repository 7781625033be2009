//! The format of a saved run ([`crate::Simulation::serialize_state`]) and
//! the readers of the formats before it.
//!
//! A saved run carries its format's number under the key `format`. This
//! build writes [`FORMAT`] and reads every format from 1 up: a state of an
//! older format is brought up to this one in its JSON tree, one format at a
//! time, before it is read; a newer or unknown one is refused, naming both
//! numbers. `tests/data/states/` holds a state of each format, written by
//! the build that introduced it, and `tests/suite/state_files.rs` holds
//! this build to loading each and going on to the same bits.
//!
//! | Format | Written by | What changed |
//! | --- | --- | --- |
//! | 1 | up to 2026-11-29 (no `format` key) | — |
//! | 2 | from 2026-11-29 | the clock and the energy book of every solver in one place each; every solver saves its state alone (node fields, the 3-D record of the last build, clock, energy, material state, tallies) with the digest of its setup, not the setup |

use crate::solver::shared::digest_json;
use serde_json::{Map, Value};

/// The format this build writes.
pub const FORMAT: u32 = 2;

/// Brings a saved run of any format this build reads up to [`FORMAT`], in
/// place; the message says why one cannot be.
pub(crate) fn upgrade(saved: &mut Value) -> Result<(), String> {
    let root = saved
        .as_object_mut()
        .ok_or("it is not a saved run: a JSON object with its scene, solver and history")?;
    let format = match root.get("format") {
        None => 1,
        Some(v) => v
            .as_u64()
            .filter(|&f| f >= 1)
            .ok_or_else(|| format!("its format {v} is not a format number (1 to {FORMAT})"))?,
    };
    if format > u64::from(FORMAT) {
        return Err(format!(
            "it is of format {format}, newer than this build's {FORMAT}: load it with the build \
             that wrote it, or a newer one"
        ));
    }
    if format < 2 {
        from_1(root)?;
    }
    root.insert("format".into(), Value::from(FORMAT));
    Ok(())
}

/// Format 1 to 2: each solver's clock (`time`, `steps`, `dt`, `dt0`) and
/// energy book (the energy at the start, the internal energy and the
/// losses, in the order of the solver's balance) gathered under `clock`
/// and `energy`; the setup of the Taylor and 3-D runs dropped (a restored
/// run is built from its scene; a penetration run saves its run's state
/// alone) and its digest kept, and so the plate impact's and the Noh
/// run's; the plate impact's cell energies renamed `specific_energy` and
/// its cell states `cells`; and every field that a
/// state of format 1 may lack (it was read with a default) put in with that
/// default.
fn from_1(root: &mut Map<String, Value>) -> Result<(), String> {
    let solver = root
        .get_mut("solver")
        .and_then(Value::as_object_mut)
        .ok_or("it holds no solver")?;
    let Some((kind, state)) = solver.iter_mut().next() else {
        return Err("it holds no solver".into());
    };
    let state = state
        .as_object_mut()
        .ok_or_else(|| format!("its solver {kind} is not an object"))?;
    match kind.as_str() {
        "Taylor" => {
            defaults(
                state,
                &[
                    ("material_state", Value::Null),
                    ("quiet_since", Value::Null),
                ],
            );
            // The setup follows from the scene: the digest of what it is
            // made from stays.
            let made_from = taylor_made_from(state)?;
            drop_setup(
                state,
                &made_from,
                &[
                    "p", "material", "nr", "nz", "h", "r0", "mass", "mantle", "top", "face",
                ],
            )?;
            clock(state)?;
            energy(
                state,
                "initial_energy",
                Some("internal_energy"),
                &["smoothing_dissipation", "contact_dissipation"],
            )
        }
        "Noh" => {
            // The setup follows from the scene: the digest of what it is
            // made from stays.
            let made_from = parts(state, &["p", "gas"])?;
            drop_setup(state, &made_from, &["p", "gas", "h", "mass"])?;
            clock(state)?;
            energy(state, "initial_energy", None, &[])
        }
        "Plate_impact" => {
            // The cells' specific energies make room for the book, their
            // states for the state; the setup follows from the scene, its
            // digest stays.
            let energies = take(state, "energy")?;
            state.insert("specific_energy".into(), energies);
            let cells = take(state, "state")?;
            state.insert("cells".into(), cells);
            let made_from = parts(
                state,
                &["layers", "flyer_cells", "impact_speed", "end_time"],
            )?;
            drop_setup(
                state,
                &made_from,
                &[
                    "layers",
                    "flyer_cells",
                    "impact_speed",
                    "mass",
                    "length0",
                    "density0",
                    "end_time",
                ],
            )?;
            clock(state)?;
            energy(state, "initial_kinetic", None, &["contact_loss"])
        }
        "Taylor3d" => mlpg(state),
        "Penetration" => {
            // The run's state alone: the plate and the projectile follow
            // from the scene.
            let mut run = match state.remove("run") {
                Some(Value::Object(run)) => run,
                _ => return Err("its penetration run is missing".into()),
            };
            mlpg(&mut run)?;
            *state = run;
            Ok(())
        }
        other => Err(format!("its solver {other} is not one this build knows")),
    }
}

/// Puts in each key of `defaults` that `state` lacks, with its value: what
/// the solvers' `serde(default)` marks gave the fields that states saved
/// before them lack (format 2 has no such marks).
fn defaults(state: &mut Map<String, Value>, defaults: &[(&str, Value)]) {
    for (key, value) in defaults {
        state
            .entry(key.to_string())
            .or_insert_with(|| value.clone());
    }
}

/// What a Taylor run's setup is made from, as format 2 takes its digest:
/// the rod (its impact, geometry, density, temperature, resolution and
/// end), the typed scheme and the material, from the parameters `p` and
/// the material of a format-1 state.
fn taylor_made_from(state: &Map<String, Value>) -> Result<Value, String> {
    let p = state
        .get("p")
        .and_then(Value::as_object)
        .ok_or("its solver has no parameters")?;
    let get = |key: &str| {
        p.get(key)
            .cloned()
            .ok_or_else(|| format!("its parameters have no {key}"))
    };
    let mut rod = Map::new();
    for key in [
        "impact_speed",
        "initial_length",
        "initial_diameter",
        "density",
        "initial_temperature",
        "particles_radial",
        "end_time",
    ] {
        rod.insert(key.into(), get(key)?);
    }
    let order = get("smoothing_order")?
        .as_f64()
        .ok_or("its smoothing order is not a number")?;
    let mut scheme = Map::new();
    scheme.insert("smoothing_ratio".into(), get("smoothing_ratio")?);
    scheme.insert("smoothing".into(), get("smoothing_coefficient")?);
    scheme.insert(
        "order".into(),
        Value::from(if order >= 1.5 { "BiLaplacian" } else { "Paper" }),
    );
    scheme.insert("shifting".into(), get("shifting")?);
    let material = state
        .get("material")
        .cloned()
        .ok_or("its solver has no material")?;
    Ok(Value::Array(vec![
        Value::Object(rod),
        Value::Object(scheme),
        material,
    ]))
}

/// The values of `keys` in `state`, in that order, as one JSON array: what
/// a solver's setup is made from, whose digest a state of format 2 carries
/// (the solvers take it of the same values as a tuple).
fn parts(state: &Map<String, Value>, keys: &[&str]) -> Result<Value, String> {
    keys.iter()
        .map(|key| {
            state
                .get(*key)
                .cloned()
                .ok_or_else(|| format!("its solver has no {key}"))
        })
        .collect::<Result<Vec<_>, _>>()
        .map(Value::Array)
}

/// Drops the fields `keys` of a format-1 solver's setup from `state` and
/// keeps the digest of `made_from` (what the setup is made from) in their
/// place, as `setup_digest`.
fn drop_setup(
    state: &mut Map<String, Value>,
    made_from: &Value,
    keys: &[&str],
) -> Result<(), String> {
    for key in keys {
        take(state, key)?;
    }
    state.insert("setup_digest".into(), Value::from(digest_json(made_from)));
    Ok(())
}

/// Moves `key` out of `state`, or says that it is missing.
fn take(state: &mut Map<String, Value>, key: &str) -> Result<Value, String> {
    state
        .remove(key)
        .ok_or_else(|| format!("its solver has no {key}"))
}

/// `time`, `steps`, `dt` and `dt0` under `clock` (a solver without a
/// stored step, the plate impact's, has neither `dt` nor `dt0`).
fn clock(state: &mut Map<String, Value>) -> Result<(), String> {
    let mut clock = Map::new();
    for key in ["time", "steps"] {
        clock.insert(key.into(), take(state, key)?);
    }
    for key in ["dt", "dt0"] {
        clock.insert(key.into(), state.remove(key).unwrap_or(Value::from(0.0)));
    }
    state.insert("clock".into(), Value::Object(clock));
    Ok(())
}

/// The energy book under `energy`: `initial` from `initial`, `internal`
/// from `internal` (zero for a solver that sums it from its cells), and the
/// `lost` terms in the order given.
fn energy(
    state: &mut Map<String, Value>,
    initial: &str,
    internal: Option<&str>,
    lost: &[&str],
) -> Result<(), String> {
    let mut book = Map::new();
    book.insert("initial".into(), take(state, initial)?);
    let internal = match internal {
        Some(key) => take(state, key)?,
        None => Value::from(0.0),
    };
    book.insert("internal".into(), internal);
    let lost = lost
        .iter()
        .map(|key| take(state, key))
        .collect::<Result<Vec<_>, _>>()?;
    book.insert("lost".into(), Value::Array(lost));
    state.insert("energy".into(), Value::Object(book));
    Ok(())
}

/// The fields of a 3-D run's setup, which format 1 saved and format 2
/// builds from the scene.
const MLPG_SETUP: &[&str] = &[
    "setup",
    "material",
    "lattice",
    "others",
    "group",
    "anvil",
    "reach",
    "mass",
    "plane",
    "held",
    "d_min0",
    "damping_time",
];

/// The 3-D solver's state of format 1 in format 2: the setup dropped (it
/// follows from the scene) and the digest of what it is made from kept,
/// taken as format 2 takes it (the rod's setup with its scheme typed, the
/// material, the further bodies, the anvil); the clock and the energy book
/// gathered.
fn mlpg(state: &mut Map<String, Value>) -> Result<(), String> {
    let empty = || Value::Array(Vec::new());
    defaults(
        state,
        &[
            ("material_state", Value::Null),
            ("reference", empty()),
            ("built_reference", empty()),
            ("built_contact", empty()),
            ("built_rho", empty()),
            ("built_multipliers", empty()),
            ("reaction", empty()),
            ("shift_dissipation", Value::from(0.0)),
            ("others", empty()),
            ("group", empty()),
            ("anvil", Value::Bool(true)),
            ("reach", Value::from(0.0)),
            ("plane", empty()),
            ("held", empty()),
        ],
    );
    if let Some(others) = state.get_mut("others").and_then(Value::as_array_mut) {
        for body in others.iter_mut().filter_map(Value::as_object_mut) {
            defaults(body, &[("clamped_rim", Value::Bool(false))]);
        }
    }
    let mut rod = match state.get("setup") {
        Some(Value::Object(rod)) => rod.clone(),
        _ => return Err("its setup is not an object".into()),
    };
    typed_scheme(&mut rod)?;
    state.insert("setup".into(), Value::Object(rod));
    let made_from = parts(state, &["setup", "material", "others", "anvil"])?;
    drop_setup(state, &made_from, MLPG_SETUP)?;
    clock(state)?;
    energy(
        state,
        "initial_energy",
        Some("internal_energy"),
        &[
            "damping_dissipation",
            "contact_dissipation",
            "smoothing_dissipation",
        ],
    )
}

/// The rod's setup of format 1 as format 2 has it: the weak form, the
/// conforming flag, the smoothing's order and coefficient, the shifting
/// and the lattice under one typed `scheme`.
fn typed_scheme(rod: &mut Map<String, Value>) -> Result<(), String> {
    defaults(
        rod,
        &[
            ("base", Value::from(0.0)),
            ("quarter", Value::Bool(false)),
            ("conservative_carry", Value::Bool(false)),
            ("weak_form", Value::from("Sphere")),
        ],
    );
    let weak_form = take(rod, "weak_form")?;
    let conforming = rod.remove("conforming").unwrap_or(Value::Bool(false));
    let forces = match (weak_form.as_str(), conforming.as_bool()) {
        (Some("Sphere"), _) => "Sphere",
        (Some("Nodal"), Some(true)) => "Conforming",
        (Some("Nodal"), _) => "Nodal",
        _ => return Err(format!("its weak form {weak_form} is not Sphere or Nodal")),
    };
    let order = match rod.remove("smoothing_order").and_then(|v| v.as_u64()) {
        Some(2) => "Two",
        // A state saved before the order was saved smooths to order 1.
        _ => "One",
    };
    let lattice = match rod.remove("staggered").and_then(|v| v.as_bool()) {
        Some(true) => "Staggered",
        _ => "Aligned",
    };
    let mut scheme = Map::new();
    scheme.insert("forces".into(), Value::from(forces));
    scheme.insert("order".into(), Value::from(order));
    scheme.insert("smoothing".into(), take(rod, "smoothing")?);
    scheme.insert(
        "shifting".into(),
        rod.remove("shifting").unwrap_or(Value::from(0.0)),
    );
    scheme.insert("lattice".into(), Value::from(lattice));
    rod.insert("scheme".into(), Value::Object(scheme));
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    /// A newer format, and a format that is not a number, are refused
    /// naming them.
    #[test]
    fn newer_and_unknown_formats_are_refused() {
        let mut newer = json!({"format": FORMAT + 1, "solver": {}});
        let e = upgrade(&mut newer).unwrap_err();
        assert!(e.contains(&format!("format {}", FORMAT + 1)), "{e}");
        for bad in [json!("two"), json!(0), json!(-1), json!(1.5)] {
            let mut s = json!({"format": bad, "solver": {}});
            let e = upgrade(&mut s).unwrap_err();
            assert!(e.contains("is not a format number"), "{e}");
        }
        let e = upgrade(&mut json!([1, 2])).unwrap_err();
        assert!(e.contains("not a saved run"), "{e}");
    }

    /// A state of this format passes unchanged.
    #[test]
    fn the_current_format_is_left_as_it_is() {
        let mut s = json!({"format": FORMAT, "solver": {"Noh": {"clock": 1}}});
        let before = s.clone();
        upgrade(&mut s).unwrap();
        assert_eq!(s, before);
    }
}
