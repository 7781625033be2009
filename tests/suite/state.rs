//! Saved states edited by hand (forged) are refused with `InvalidState`, the
//! way a new scene with the same values would be refused; an unedited state
//! is accepted and resumes (issue: forged saved states are accepted).

use crate::common::{self, bits};

use meshless_impact::{Scene, Simulation};
use serde_json::{Value, json};

/// A coarse run of `name` advanced to `t`, and its saved state as JSON.
fn saved(name: &str, sets: &[(&str, f64)], t: f64) -> (Simulation, Value) {
    let mut scene = Scene::builtin(name).unwrap();
    for (k, v) in sets {
        scene.set(k, *v).unwrap();
    }
    let mut sim = Simulation::new(scene).unwrap();
    sim.advance_to(t).unwrap();
    let state = serde_json::from_slice(&sim.serialize_state()).unwrap();
    (sim, state)
}

/// The solver's state inside a saved simulation (`{"Taylor": {...}}`).
fn solver<'a>(state: &'a mut Value, kind: &str) -> &'a mut Value {
    &mut state["solver"][kind]
}

/// Sets the anvil's reaction of the first `taylor3d` node whose contact
/// flag is `held` to `value`.
fn set_reaction(state: &mut Value, held: bool, value: f64) {
    let node = solver(state, "Taylor3d")["contact"]
        .as_array()
        .unwrap()
        .iter()
        .position(|c| c == &json!(held))
        .unwrap();
    solver(state, "Taylor3d")["reaction"][node] = json!(value);
}

/// Asserts that the edited state is refused with `InvalidState`, and
/// returns the message.
fn refused(state: &Value) -> String {
    let bytes = serde_json::to_vec(state).unwrap();
    match Simulation::deserialize_state(&bytes) {
        Ok(_) => panic!("a forged state was accepted"),
        Err(e) => {
            assert_eq!(e.name(), "InvalidState", "{e}");
            e.to_string()
        }
    }
}

#[test]
fn an_unedited_state_is_accepted_and_resumes() {
    for (name, sets, t) in [
        ("taylor", &[("particles_radial", 5.0)][..], 5e-6),
        ("noh", &[("particles_radial", 100.0)][..], 0.1),
    ] {
        let (mut sim, state) = saved(name, sets, t);
        let bytes = serde_json::to_vec(&state).unwrap();
        let mut back = Simulation::deserialize_state(&bytes).unwrap();
        sim.run().unwrap();
        back.run().unwrap();
        assert_eq!(sim.observables(), back.observables());
    }
}

/// Each edit a forger might make to a Taylor state, each refused with a
/// message that says what is wrong.
#[test]
fn forged_taylor_states_are_refused() {
    let (_, base) = saved("taylor", &[("particles_radial", 5.0)], 5e-6);
    type Edit = fn(&mut Value);
    let edits: [(&str, Edit, &str); 12] = [
        (
            "scene parameter out of range",
            |s| s["scene"]["params"]["Taylor"]["density"] = json!(-5.0),
            "density",
        ),
        (
            "solver parameters differ from the scene's",
            |s| solver(s, "Taylor")["p"]["density"] = json!(8000.0),
            "parameters",
        ),
        (
            "a particle removed",
            |s| {
                solver(s, "Taylor")["vel"].as_array_mut().unwrap().pop();
            },
            "velocities",
        ),
        (
            "a mass changed",
            |s| solver(s, "Taylor")["mass"] = json!([1.0]),
            "masses",
        ),
        (
            "a surface index past the particles",
            |s| solver(s, "Taylor")["mantle"] = json!({"particles": [100000]}),
            "surfaces",
        ),
        (
            "a negative density",
            |s| solver(s, "Taylor")["rho"][7] = json!(-1.0),
            "densities",
        ),
        (
            "a negative temperature",
            |s| solver(s, "Taylor")["temp"][2] = json!(-300.0),
            "temperatures",
        ),
        (
            "a zero time step",
            |s| solver(s, "Taylor")["clock"]["dt"] = json!(0.0),
            "clock",
        ),
        (
            "steps reset at a later time",
            |s| solver(s, "Taylor")["clock"]["steps"] = json!(0),
            "step count",
        ),
        (
            "a record interval of zero (the hang)",
            |s| s["record_interval"] = json!(0.0),
            "record",
        ),
        (
            "the next record far in the past (the record loop would not end)",
            |s| s["next_record"] = json!(-985633.9),
            "record",
        ),
        (
            "a history row cut short",
            |s| {
                s["history"]["values"].as_array_mut().unwrap().pop();
            },
            "history",
        ),
    ];
    for (what, edit, says) in edits {
        let mut state = base.clone();
        edit(&mut state);
        let msg = refused(&state);
        assert!(msg.contains(says), "{what}: {msg}");
    }
}

#[test]
fn forged_noh_states_are_refused() {
    let (_, base) = saved("noh", &[("particles_radial", 100.0)], 0.1);
    let mut s = base.clone();
    solver(&mut s, "Noh")["r"].as_array_mut().unwrap().pop();
    assert!(refused(&s).contains("radii"));
    let mut s = base.clone();
    solver(&mut s, "Noh")["rho"][5] = json!(0.0);
    assert!(refused(&s).contains("densities"));
    let mut s = base.clone();
    solver(&mut s, "Noh")["mass"] = json!([2.0]);
    assert!(refused(&s).contains("masses"));
    let mut s = base;
    s["scene"]["params"]["Noh"]["end_time"] = json!(5e-324);
    assert!(refused(&s).contains("end_time"));
}

/// A run of a chosen material (a preset, bilinear strength) saved and
/// restored goes on to the same bits, its material choice included; a
/// state whose scene claims other models than its solver ran, or whose
/// solver's material was edited, is refused.
#[test]
fn a_preset_run_round_trips_and_a_forged_material_is_refused() {
    let mut scene = Scene::builtin("taylor").unwrap();
    scene
        .choose_material(None, None, Some("copper_wilkins_bilinear"))
        .unwrap();
    scene.set("particles_radial", 5.0).unwrap();
    let mut sim = Simulation::new(scene.clone()).unwrap();
    sim.advance_to(5e-6).unwrap();
    let bytes = sim.serialize_state();
    let mut back = Simulation::deserialize_state(&bytes).unwrap();
    assert_eq!(back.scene(), &scene);
    assert_eq!(back.kind(), scene.kind());
    sim.advance_to(10e-6).unwrap();
    back.advance_to(10e-6).unwrap();
    let bits =
        |s: &Simulation| -> Vec<u64> { s.observables().iter().map(|v| v.to_bits()).collect() };
    assert_eq!(bits(&sim), bits(&back));

    let base: Value = serde_json::from_slice(&bytes).unwrap();
    assert_eq!(
        base["scene"]["material"],
        json!({"strength": "bilinear", "eos": "linear"})
    );
    // The scene says Johnson-Cook: its table then has no hardening_modulus.
    let mut s = base.clone();
    s["scene"]["material"] = json!({"strength": "johnson_cook", "eos": "linear"});
    let msg = refused(&s);
    assert!(
        msg.contains("unknown parameter `hardening_modulus`"),
        "{msg}"
    );
    // The scene says Johnson-Cook with its parameters, the solver ran bilinear.
    let mut s = base.clone();
    s["scene"]["material"] = json!({"strength": "johnson_cook", "eos": "linear"});
    let params = s["scene"]["params"]["Taylor"].as_object_mut().unwrap();
    params.remove("yield_stress");
    params.remove("hardening_modulus");
    let msg = refused(&s);
    assert!(msg.contains("material"), "{msg}");
    // The solver's hardening edited.
    let mut s = base.clone();
    solver(&mut s, "Taylor")["material"]["strength"]["Bilinear"]["hardening_modulus"] = json!(1e9);
    let msg = refused(&s);
    assert!(msg.contains("material"), "{msg}");
    // An unknown model name.
    let mut s = base;
    s["scene"]["material"]["strength"] = json!("plastic");
    let msg = refused(&s);
    assert!(msg.contains("plastic"), "{msg}");
}

/// A `taylor3d` run (3 nodes across the radius) saved mid-way, as JSON
/// (`Simulation::serialize_state`, the solver's `ModelState::save`) and as
/// a copy (`ModelState::boxed_clone`), restored and run to rest, gives the
/// bits of the run that was not interrupted: clock, observables, every 3-D
/// field and the histories. (The FMU state, postcard: src/fmi/state.rs and
/// tests/fmu/test_taylor3d.py.)
#[test]
fn a_taylor3d_run_saved_mid_way_resumes_to_the_bits_of_the_whole_run() {
    let sets = [("particles_radial", 3.0)];
    let whole = common::run(Scene::builtin("taylor3d").unwrap(), &sets);
    assert_eq!(whole.observable("at_rest"), Some(1.0));
    let (mid, state) = saved("taylor3d", &sets, 10e-6);
    assert!(
        mid.steps() > 10 && mid.steps() < whole.steps() / 2,
        "mid-way"
    );
    let mut back = Simulation::deserialize_state(&serde_json::to_vec(&state).unwrap()).unwrap();
    let mut copy = mid.clone();
    assert_eq!(bits(&back), bits(&mid), "restored as saved");
    back.run().unwrap();
    copy.run().unwrap();
    assert_eq!(bits(&back), bits(&whole), "restored from JSON");
    assert_eq!(bits(&copy), bits(&whole), "copied");
}

/// Each edit a forger might make to a `taylor3d` state (as for `taylor`,
/// forged_taylor_states_are_refused), each refused with `InvalidState` and a
/// message that says what is wrong.
#[test]
fn forged_taylor3d_states_are_refused() {
    let (_, base) = saved("taylor3d", &[("particles_radial", 3.0)], 3e-6);
    type Edit = fn(&mut Value);
    let edits: [(&str, Edit, &str); 16] = [
        (
            "scene parameter out of range",
            |s| s["scene"]["params"]["Taylor3d"]["density"] = json!(-5.0),
            "density",
        ),
        (
            "the solver's setup differs from the scene's",
            |s| solver(s, "Taylor3d")["setup"]["impact_speed"] = json!(200.0),
            "parameters",
        ),
        (
            "the material edited",
            |s| solver(s, "Taylor3d")["material"]["shear_modulus"] = json!(80e9),
            "material",
        ),
        (
            "a node removed",
            |s| {
                solver(s, "Taylor3d")["pos"].as_array_mut().unwrap().pop();
            },
            "positions",
        ),
        (
            "a mass changed",
            |s| solver(s, "Taylor3d")["mass"] = json!([1.0]),
            "masses",
        ),
        (
            "a contact flag removed",
            |s| {
                solver(s, "Taylor3d")["contact"]
                    .as_array_mut()
                    .unwrap()
                    .pop();
            },
            "contact",
        ),
        (
            "the anvil pulling on a node it holds",
            |s| set_reaction(s, true, -1.0),
            "anvil reactions",
        ),
        (
            "the anvil pushing on a node off it",
            |s| set_reaction(s, false, 1.0),
            "anvil reactions",
        ),
        (
            "a negative density",
            |s| solver(s, "Taylor3d")["rho"][7] = json!(-1.0),
            "densities",
        ),
        (
            "a negative plastic strain",
            |s| solver(s, "Taylor3d")["eps_p"][7] = json!(-0.5),
            "plastic strains",
        ),
        (
            "a negative temperature",
            |s| solver(s, "Taylor3d")["temp"][2] = json!(-300.0),
            "temperatures",
        ),
        (
            "a zero time step",
            |s| solver(s, "Taylor3d")["clock"]["dt"] = json!(0.0),
            "clock",
        ),
        (
            "a time step of seconds",
            |s| solver(s, "Taylor3d")["clock"]["dt"] = json!(1.0),
            "clock",
        ),
        (
            "steps reset at a later time",
            |s| solver(s, "Taylor3d")["clock"]["steps"] = json!(0),
            "step count",
        ),
        (
            "a record interval of zero (the hang)",
            |s| s["record_interval"] = json!(0.0),
            "record",
        ),
        (
            "a history row cut short",
            |s| {
                s["history"]["values"].as_array_mut().unwrap().pop();
            },
            "history",
        ),
    ];
    let mut wrong = Vec::new();
    for (what, edit, says) in edits {
        let mut state = base.clone();
        edit(&mut state);
        match Simulation::deserialize_state(&serde_json::to_vec(&state).unwrap()) {
            Ok(_) => wrong.push(format!("{what}: accepted")),
            Err(e) if e.name() != "InvalidState" || !e.to_string().contains(says) => {
                wrong.push(format!("{what}: {e}"))
            }
            Err(_) => {}
        }
    }
    assert!(wrong.is_empty(), "{wrong:#?}");
    // The unedited state loads.
    Simulation::deserialize_state(&serde_json::to_vec(&base).unwrap()).unwrap();
}

/// The `Mlpg3d` run inside a saved 3-D state: `taylor3d`'s solver, or the
/// run of a `penetration`.
fn run3d(state: &mut Value) -> &mut Value {
    let solver = state["solver"].as_object_mut().unwrap();
    let (_, s) = solver.iter_mut().next().unwrap();
    if s.get("run").is_some() {
        &mut s["run"]
    } else {
        s
    }
}

/// Issue 48, failures 5 and 6: forged states with finite but absurd values
/// loaded. A support position of ±1e300 in the quarter model hung the next
/// step (the search of the supports grew its layer for ever); a velocity
/// or a crack of 1e300 made the observables infinite with success. Each is
/// refused by the physical bounds of a restored run (no node ten times
/// faster than impact plus wave speed, none further out than the bodies
/// could have gone, no crack larger than the bodies), and an unedited
/// state of the same runs still loads.
#[test]
fn forged_states_with_absurd_finite_values_are_refused() {
    let quarter = [("particles_radial", 3.0), ("symmetry", 1.0)];
    let (_, pen) = saved("penetration", &quarter, 3e-7);
    let (_, rod3d) = saved("taylor3d", &[("particles_radial", 3.0)], 1e-6);
    let (_, rod) = saved("taylor", &[("particles_radial", 5.0)], 2e-6);
    for base in [&pen, &rod3d, &rod] {
        let bytes = serde_json::to_vec(base).unwrap();
        Simulation::deserialize_state(&bytes).unwrap();
    }
    for huge in [1e300, -1e300] {
        for field in ["supports_at", "pos", "built_at", "reference"] {
            let mut s = pen.clone();
            run3d(&mut s)[field][5][2] = json!(huge);
            let e = refused(&s);
            assert!(e.contains("not physical"), "{field}: {e}");
        }
        let mut s = pen.clone();
        run3d(&mut s)["vel"][7][2] = json!(huge);
        assert!(refused(&s).contains("faster than"));
        let mut s = rod3d.clone();
        run3d(&mut s)["vel"][0][2] = json!(huge);
        assert!(refused(&s).contains("faster than"));
        let mut s = rod.clone();
        solver(&mut s, "Taylor")["vel"][3][1] = json!(huge);
        assert!(refused(&s).contains("faster than"));
        let mut s = rod.clone();
        solver(&mut s, "Taylor")["pos"][3][0] = json!(huge);
        assert!(refused(&s).contains("not physical"));
    }
    let mut s = pen.clone();
    // The damage variables: one entry a node, `null` where none yet.
    let points = run3d(&mut s)["material_state"].as_array_mut().unwrap();
    let cracked = points.iter_mut().find(|p| !p.is_null()).unwrap();
    cracked["crack_size"] = json!(1e300);
    assert!(refused(&s).contains("crack"));
}

/// Issue 48, failure 9: a scene file's `[reference]` table took `nan` and
/// `±inf` (printed as "NaN%", and the library then refused its own state).
#[test]
fn a_reference_that_is_not_a_number_is_refused() {
    for bad in ["nan", "inf", "-inf"] {
        let text = format!("scene = \"taylor\"\n[reference]\nrod_length = {bad}\n");
        let e = Scene::from_toml_str(&text).unwrap_err();
        assert!(e.to_string().contains("[reference] rod_length"), "{e}");
    }
    let ok = Scene::from_toml_str("scene = \"taylor\"\n[reference]\nrod_length = 0.02\n").unwrap();
    assert_eq!(ok.reference["rod_length"], 0.02);
}

/// Issue 48, failure 8: the state saved after a stop loads back (here
/// `EnergyDrift`: test 7 at 6 across without the velocity smoothing); a
/// run stopped on a non-finite field has no state to save
/// (`Simulation::check_savable`, `MI_NON_FINITE` from `mi_sim_state_save`).
#[test]
fn a_state_saved_after_a_stop_loads_back() {
    let mut scene = Scene::builtin("taylor").unwrap();
    scene.set("particles_radial", 6.0).unwrap();
    scene.set("smoothing_coefficient", 0.0).unwrap();
    let mut sim = Simulation::new(scene).unwrap();
    let e = sim.run().unwrap_err();
    assert_eq!(e.name(), "EnergyDrift", "{e}");
    sim.check_savable().unwrap();
    let back = Simulation::deserialize_state(&sim.serialize_state()).unwrap();
    assert_eq!(back.time(), sim.time());
}

/// Runs with the ceramics of issue 68 saved mid-way resume to the bits of
/// the whole run: the JH-2 plate (its damage and bulking) and a plate with
/// tensile crack planes (their frames, crack sizes and openings), in
/// `plate_impact` and, as a quarter model at 3 across, in `penetration`.
#[test]
fn runs_of_the_new_ceramics_saved_mid_way_resume_to_the_same_bits() {
    /// A scene, its settings, the time it is saved at and the time it runs to.
    type Case<'a> = (&'a str, &'a [(&'a str, f64)], f64, f64);
    let cases: [Case; 3] = [
        (
            "plate_impact",
            &[
                ("flyer_material", 7.0),
                ("target_material", 7.0),
                ("impact_speed", 1000.0),
            ],
            0.5e-6,
            1.2e-6,
        ),
        (
            "plate_impact",
            &[("plate_ceramic", 2.0), ("impact_speed", 200.0)],
            0.9e-6,
            2.0e-6,
        ),
        (
            "penetration",
            &[
                ("plate_ceramic", 2.0),
                ("particles_radial", 3.0),
                ("symmetry", 1.0),
            ],
            4e-6,
            6e-6,
        ),
    ];
    for (name, sets, saved_at, until) in cases {
        let (mut sim, state) = saved(name, sets, saved_at);
        let bytes = serde_json::to_vec(&state).unwrap();
        let mut back = Simulation::deserialize_state(&bytes).unwrap();
        assert_eq!(bits(&back), bits(&sim), "{name} {sets:?}: as saved");
        sim.advance_to(until).unwrap();
        back.advance_to(until).unwrap();
        assert_eq!(bits(&back), bits(&sim), "{name} {sets:?}: continued");
        // The state held what the new models keep.
        let text = String::from_utf8(bytes).unwrap();
        let kept = if sets.iter().any(|(k, _)| *k == "plate_ceramic") {
            "\"opening\""
        } else {
            "\"bulking\""
        };
        assert!(text.contains(kept), "{name}: {kept}");
    }
}
