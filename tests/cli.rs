//! The command-line program: errors, outputs and the documented JSON keys.

use std::process::Command;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_meshless-impact"))
}

#[test]
fn unknown_parameter_is_a_clear_error_listing_allowed_names() {
    let out = bin()
        .args(["run", "--set", "impact_sped=200"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("unknown parameter `impact_sped`") && err.contains("impact_speed"),
        "{err}"
    );
}

#[test]
fn out_of_range_value_names_parameter_value_and_range() {
    for (set, needle) in [
        ("density=-5", "`density` = -5"),
        ("initial_diameter=0", "`initial_diameter` = 0"),
        ("impact_speed=nan", "`impact_speed` = NaN"),
        ("impact_speed=inf", "`impact_speed` = inf"),
        ("particles_radial=0", "`particles_radial` = 0"),
        ("melt_temperature=200", "melt_temperature"),
        ("melt_temperature=293", "must exceed room_temperature"),
    ] {
        let out = bin().args(["run", "--set", set]).output().unwrap();
        assert!(!out.status.success(), "{set}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(needle), "{set}: {err}");
    }
}

#[test]
fn json_has_every_observable_and_run_facts() {
    let dir = std::env::temp_dir().join(format!("mi-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let json = dir.join("out.json");
    let csv = dir.join("hist.csv");
    let vtk = dir.join("vtk");
    let out = bin()
        .args([
            "run",
            "-q",
            "--set",
            "particles_radial=4",
            "--set",
            "end_time=3e-6",
        ])
        .arg("--json")
        .arg(&json)
        .arg("--csv")
        .arg(&csv)
        .arg("--vtk-dir")
        .arg(&vtk)
        .args(["--vtk-times", "1e-6"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    for spec in meshless_impact::TAYLOR_OBSERVABLES {
        assert!(v.get(spec.name).is_some(), "missing {}", spec.name);
    }
    for k in ["particles", "steps", "end_time", "wall_time_s"] {
        assert!(v.get(k).is_some(), "missing {k}");
    }
    assert!(v["end_time"].as_f64().unwrap() >= 3e-6);
    let hist = std::fs::read_to_string(&csv).unwrap();
    assert!(hist.starts_with("time,rod_length,mushroom_radius"));
    assert!(hist.lines().count() > 10);
    // Two snapshots (1 us and the final state), readable as VTK XML.
    for k in 0..2 {
        let path = vtk.join(format!("particles_{k:04}.vtu"));
        let text = std::fs::read_to_string(&path).unwrap();
        for name in [
            "density",
            "velocity",
            "stress",
            "pressure",
            "plastic_strain",
            "temperature",
        ] {
            assert!(
                text.contains(&format!("Name=\"{name}\"")),
                "{name} in {}",
                path.display()
            );
        }
    }
    // The collection lists both snapshots with their times: the first step
    // at or after 1 us, and the end of the run.
    let pvd = std::fs::read_to_string(vtk.join("particles.pvd")).unwrap();
    let mut reader = quick_xml::Reader::from_str(&pvd);
    let mut sets = Vec::new();
    loop {
        match reader.read_event().unwrap() {
            quick_xml::events::Event::Empty(e) if e.name().as_ref() == b"DataSet" => {
                let attr = |k: &str| {
                    e.try_get_attribute(k)
                        .unwrap()
                        .unwrap()
                        .unescape_value()
                        .unwrap()
                        .into_owned()
                };
                sets.push((attr("timestep").parse::<f64>().unwrap(), attr("file")));
            }
            quick_xml::events::Event::Eof => break,
            _ => {}
        }
    }
    assert_eq!(sets.len(), 2, "{pvd}");
    assert_eq!(sets[0].1, "particles_0000.vtu");
    assert_eq!(sets[1].1, "particles_0001.vtu");
    assert!(sets[0].0 >= 1e-6 && sets[0].0 < 1.1e-6, "{pvd}");
    assert_eq!(sets[1].0, v["end_time"].as_f64().unwrap(), "{pvd}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn params_lists_units_defaults_and_ranges() {
    let out = bin().args(["params", "taylor"]).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("impact_speed") && text.contains("m/s") && text.contains("181"));
    let out = bin().args(["params", "noh"]).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(!text.contains("jc_a"), "Noh takes no strength parameters");
}
