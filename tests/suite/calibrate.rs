//! Calibration (`meshless-impact calibrate`, `meshless_impact::calibrate`):
//! twin experiments whose truth is known (shots made by the solver itself
//! with moved constants), the identifiability flag, the calibrated
//! material's bits, and each bad input.

use meshless_impact::calibrate::{Calibration, Free, Options, Outcome, parse_shots};
use meshless_impact::{Scene, Simulation};
use std::path::Path;
use std::process::Command;

/// The coarse resolution of the small twins (under a second a run).
const COARSE: f64 = 8.0;

/// The `taylor` scene at the small twins' resolution.
fn base() -> Scene {
    let mut s = Scene::builtin("taylor").unwrap();
    s.set("particles_radial", COARSE).unwrap();
    s
}

/// An experiments file of shots made by the solver with `truth` at each
/// (impact_speed, initial_length): rod_length and mushroom_radius.
fn twin_csv(truth: &[(&str, f64)], shots: &[(f64, f64)]) -> String {
    let mut csv = String::from("shot,impact_speed,initial_length,rod_length,mushroom_radius\n");
    for (k, (v, l)) in shots.iter().enumerate() {
        let mut s = base();
        for (name, x) in truth
            .iter()
            .chain(&[("impact_speed", *v), ("initial_length", *l)])
        {
            s.set(name, *x).unwrap();
        }
        let mut sim = Simulation::new(s).unwrap();
        sim.run().unwrap();
        let o = |n: &str| sim.observable(n).unwrap();
        csv += &format!(
            "s{k},{v},{l},{:?},{:?}\n",
            o("rod_length"),
            o("mushroom_radius")
        );
    }
    csv
}

/// The truth of the small twin: Johnson-Cook A and B moved +13.6 % and
/// -11.8 % from the house steel's.
const TRUTH: [(&str, f64); 2] = [("jc_a", 900e6), ("jc_b", 450e6)];

/// Three shots: two speeds on one rod, a third speed on a shorter one.
const SHOTS: [(f64, f64); 3] = [(180.0, 0.02529), (240.0, 0.02529), (280.0, 0.01519)];

fn free(scene: &Scene) -> Vec<Free> {
    vec![
        Free::parse("jc_a=600e6:1200e6", scene).unwrap(),
        Free::parse("jc_b=200e6:900e6", scene).unwrap(),
    ]
}

/// Two free constants, three shots: recovered within 0.5 % (VALIDATION.md,
/// "Calibration"), converged, in at most 40 forward runs; with a coarser
/// stage first as well.
#[test]
fn a_small_twin_is_recovered() {
    let scene = base();
    let csv = twin_csv(&TRUTH, &SHOTS);
    let shots = parse_shots(&csv, Path::new("twin.csv"), &scene).unwrap();
    for coarse in [None, Some(("particles_radial".to_string(), 6.0))] {
        let options = Options {
            coarse: coarse.clone(),
            ..Options::default()
        };
        let fit = Calibration::new(scene.clone(), free(&scene), shots.clone(), options).unwrap();
        let r = fit.run(&|_| {}).unwrap();
        assert_eq!(r.outcome, Outcome::Converged, "coarse {coarse:?}");
        for ((name, truth), got) in TRUTH.iter().zip(&r.parameters) {
            let err = (got - truth) / truth;
            assert!(
                err.abs() < 5e-3,
                "{name}: {got:e} against {truth:e} (coarse {coarse:?})"
            );
        }
        assert!(r.runs <= 40, "{} runs (coarse {coarse:?})", r.runs);
        assert!(r.identifiable.iter().all(Result::is_ok));
        // The residuals after are the fit's: below 0.1 % everywhere.
        for (shot, v) in r.shots.iter().zip(&r.fitted) {
            for (m, sim) in shot.observed.iter().zip(&v.values) {
                assert!(((sim - m.value) / m.value).abs() < 1e-3, "{}", shot.label);
            }
        }
        if coarse.is_some() {
            assert!(r.runs_coarse > 0);
        }
    }
}

/// One impact speed, three rods: the strain-rate constant C is flagged as
/// not determined by the data (a correlation over 0.95 with A, or a
/// relative standard error over 50 %), while A stays determined.
#[test]
fn one_speed_cannot_tell_the_rate_constant() {
    let scene = base();
    let one_speed = [(220.0, 0.01519), (220.0, 0.02529), (220.0, 0.03797)];
    let csv = twin_csv(&[("jc_a", 850e6), ("jc_c", 0.02)], &one_speed);
    let shots = parse_shots(&csv, Path::new("one_speed.csv"), &scene).unwrap();
    let free = vec![
        Free::parse("jc_a=600e6:1200e6", &scene).unwrap(),
        Free::parse("jc_b=200e6:900e6", &scene).unwrap(),
        Free::parse("jc_c=0.001:0.1", &scene).unwrap(),
    ];
    let r = Calibration::new(scene, free, shots, Options::default())
        .unwrap()
        .run(&|_| {})
        .unwrap();
    let why = r.identifiable[2].clone().unwrap_err();
    assert!(
        why.contains("correlation") || why.contains("relative standard error"),
        "{why}"
    );
}

fn program() -> Command {
    Command::new(env!("CARGO_BIN_EXE_meshless-impact"))
}

/// Runs `calibrate` on the experiments `csv` with `args`; returns (success,
/// stdout, stderr).
fn calibrate(dir: &Path, csv: &str, args: &[&str]) -> (bool, String, String) {
    std::fs::create_dir_all(dir).unwrap();
    let shots = dir.join("shots.csv");
    std::fs::write(&shots, csv).unwrap();
    let out = program()
        .arg("calibrate")
        .arg("taylor")
        .arg("--shots")
        .arg(&shots)
        .arg("--out")
        .arg(dir.join("out"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A fresh, empty scratch folder for one test, removed when it passes.
fn scratch(name: &str) -> crate::common::TestDir {
    crate::common::scratch("calibrate", name)
}

/// The calibrated material (`material.toml`, `run --preset-file`)
/// reproduces the fit's final runs bit for bit.
#[test]
fn the_calibrated_material_reproduces_the_fits_runs() {
    let dir = scratch("material");
    let csv = twin_csv(&TRUTH, &SHOTS);
    let (ok, stdout, stderr) = calibrate(
        &dir,
        &csv,
        &[
            "--free",
            "jc_a=600e6:1200e6",
            "--free",
            "jc_b=200e6:900e6",
            "--set",
            "particles_radial=8",
        ],
    );
    assert!(ok, "{stdout}\n{stderr}");
    assert!(
        stdout.contains("converged") && stdout.contains("jc_a"),
        "{stdout}"
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("out/calibration.json")).unwrap())
            .unwrap();
    assert!(std::fs::metadata(dir.join("out/fit.svg")).unwrap().len() > 1000);
    for e in json["experiments"].as_array().unwrap() {
        let run_json = dir.join("run.json");
        let status = program()
            .args(["run", "taylor", "-q", "--preset-file"])
            .arg(dir.join("out/material.toml"))
            .args(["--set", "particles_radial=8"])
            .arg("--set")
            .arg(format!("impact_speed={}", e["settings"]["impact_speed"]))
            .arg("--set")
            .arg(format!(
                "initial_length={}",
                e["settings"]["initial_length"]
            ))
            .arg("--json")
            .arg(&run_json)
            .status()
            .unwrap();
        assert!(status.success());
        let run: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&run_json).unwrap()).unwrap();
        for name in ["rod_length", "mushroom_radius"] {
            let (a, b) = (
                run[name].as_f64().unwrap(),
                e["fitted"][name].as_f64().unwrap(),
            );
            assert_eq!(a.to_bits(), b.to_bits(), "{name} of shot {}", e["shot"]);
        }
    }
    // The same file as a scene file's [material] table.
    let material = std::fs::read_to_string(dir.join("out/material.toml")).unwrap();
    let scene = Scene::from_toml_str(&format!(
        "scene = \"taylor\"\n{material}\n[parameters]\nparticles_radial = 8\n"
    ))
    .unwrap();
    let fitted = json["parameters"]["jc_a"].as_f64().unwrap();
    assert_eq!(scene.get("jc_a").unwrap().to_bits(), fitted.to_bits());
    let _ = std::fs::remove_dir_all(&dir);
}

/// Each bad input gets an error that names the file, line and column or
/// the parameter, before any run.
#[test]
fn bad_input_is_refused_by_name() {
    let dir = scratch("bad");
    let good_free = ["--free", "jc_a=600e6:1200e6", "--set", "particles_radial=6"];
    let cases: [(&str, &str, &[&str], &[&str]); 9] = [
        (
            "malformed CSV",
            "impact_speed,rod_length\n181,0.0346\n200,0.03,7\n",
            &good_free,
            &["shots.csv", "line 3"],
        ),
        (
            "unknown column",
            "impact_speed,rod_lenght\n181,0.0346\n",
            &good_free,
            &[
                "line 1, column 2",
                "`rod_lenght` is neither a parameter nor an observable",
            ],
        ),
        (
            "not a number",
            "impact_speed,rod_length\n181,long\n",
            &good_free,
            &["line 2, column 2", "`long` is not a number"],
        ),
        (
            "non-finite observable",
            "impact_speed,rod_length\n181,inf\n",
            &good_free,
            &["line 2, column 2", "not a finite number"],
        ),
        (
            "negative sigma",
            "impact_speed,rod_length,sigma_rod_length\n181,0.0346,-1e-4\n",
            &good_free,
            &["line 2, column 3", "must be positive"],
        ),
        (
            "free parameter without bounds",
            "impact_speed,rod_length\n181,0.0346\n",
            &["--free", "jc_a"],
            &["--free jc_a", "NAME=LO:HI"],
        ),
        (
            "bounds outside the allowed range",
            "impact_speed,rod_length\n181,0.0346\n",
            &["--free", "jc_n=0:0.5"],
            &["jc_n (lower bound of --free)", "(0, 5]"],
        ),
        (
            "fewer measurements than free parameters",
            "impact_speed,rod_length\n181,0.0346\n",
            &["--free", "jc_a=600e6:1200e6", "--free", "jc_b=200e6:900e6"],
            &["1 measurements cannot determine 2 free parameters"],
        ),
        (
            "a setting out of its range",
            "impact_speed,rod_length\n-5,0.0346\n",
            &good_free,
            &["line 2, column 1", "impact_speed"],
        ),
    ];
    for (what, csv, args, expect) in cases {
        let (ok, stdout, stderr) = calibrate(&dir, csv, args);
        assert!(!ok, "{what}: accepted\n{stdout}");
        for e in expect {
            assert!(stderr.contains(e), "{what}: `{e}` not in\n{stderr}");
        }
        assert!(!dir.join("out/calibration.json").exists(), "{what}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A fit that reaches its cap says so (outcome `run_cap`, exit status 1)
/// and keeps the best point so far, written whole.
#[test]
fn a_fit_at_its_cap_keeps_the_best_point() {
    let dir = scratch("cap");
    let csv = twin_csv(&TRUTH, &SHOTS);
    let (ok, _, stderr) = calibrate(
        &dir,
        &csv,
        &[
            "--free",
            "jc_a=600e6:1200e6",
            "--free",
            "jc_b=200e6:900e6",
            "--set",
            "particles_radial=8",
            "--max-runs",
            "12",
        ],
    );
    assert!(!ok && stderr.contains("cap of 12 forward runs"), "{stderr}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("out/calibration.json")).unwrap())
            .unwrap();
    assert_eq!(json["outcome"], "run_cap");
    assert!(json["runs"].as_u64().unwrap() <= 12);
    assert!(json["objective_fitted"].as_f64() <= json["objective_before"].as_f64());
    assert!(dir.join("out/material.toml").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

/// The shipped experiments file of Table 1 holds the table's settings and
/// measurements (data/house1995_4340_table1.csv), in SI units.
#[test]
fn the_table_1_experiments_file_is_the_table() {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("data/calibration/house1995_4340_shots.csv");
    let shots =
        meshless_impact::calibrate::read_shots(&path, &Scene::builtin("taylor").unwrap()).unwrap();
    let rows = meshless_impact::Table1Row::all();
    assert_eq!(shots.len(), rows.len());
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs();
    for (s, r) in shots.iter().zip(&rows) {
        assert_eq!(s.label, format!("test{}", r.test));
        let setting = |n: &str| s.settings.iter().find(|(k, _)| k == n).unwrap().1;
        let measured = |n: &str| s.observed.iter().find(|m| m.name == n).unwrap().value;
        assert!(close(setting("impact_speed"), r.v) && close(setting("initial_length"), r.l0));
        assert!(close(setting("initial_diameter"), r.d0));
        assert!(close(measured("rod_length"), r.lf_test));
        assert!(
            close(measured("mushroom_radius"), 0.5 * r.df_test),
            "{}",
            s.label
        );
    }
}

/// A measured outline (`run --profile`'s file) fits the rod's shape: with
/// one shot's outline beside the lengths and faces, the twin's constants
/// are recovered and the outline's largest relative error after the fit
/// is below 0.5 % (it was over 1 % at the start).
#[test]
fn an_outline_is_fitted_as_well() {
    let dir = scratch("outline");
    std::fs::create_dir_all(&dir).unwrap();
    let profile = dir.join("s0_outline.csv");
    let status = program()
        .args(["run", "taylor", "-q", "--set", "particles_radial=8"])
        .args(["--set", "jc_a=900e6", "--set", "jc_b=450e6"])
        .args([
            "--set",
            "impact_speed=240",
            "--set",
            "initial_length=0.02529",
        ])
        .arg("--profile")
        .arg(&profile)
        .status()
        .unwrap();
    assert!(status.success());
    let mut csv = twin_csv(&TRUTH, &SHOTS);
    // The outline belongs to the second shot (240 m/s on the 25.29 mm rod).
    csv = csv.replacen("mushroom_radius\n", "mushroom_radius,outline\n", 1);
    let rows: Vec<String> = csv
        .lines()
        .enumerate()
        .map(|(k, l)| match k {
            0 => l.to_string(),
            2 => format!("{l},s0_outline.csv"),
            _ => format!("{l},"),
        })
        .collect();
    let (ok, stdout, stderr) = calibrate(
        &dir,
        &(rows.join("\n") + "\n"),
        &[
            "--free",
            "jc_a=600e6:1200e6",
            "--free",
            "jc_b=200e6:900e6",
            "--set",
            "particles_radial=8",
        ],
    );
    assert!(ok, "{stdout}\n{stderr}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("out/calibration.json")).unwrap())
            .unwrap();
    let outline = &json["experiments"][1]["outline"];
    let (before, after) = (
        outline["largest_relative_error_before"].as_f64().unwrap(),
        outline["largest_relative_error_fitted"].as_f64().unwrap(),
    );
    assert!(before > 0.01 && after < 0.005, "{before} -> {after}");
    for (name, truth) in TRUTH {
        let got = json["parameters"][name].as_f64().unwrap();
        assert!(((got - truth) / truth).abs() < 5e-3, "{name}: {got:e}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A fit gives the same bits on one thread and on two: its runs are
/// batches on the thread pool, collected in order.
#[test]
fn a_fit_is_the_same_on_one_thread_and_two() {
    let scene = base();
    let csv = twin_csv(&TRUTH, &SHOTS);
    let shots = parse_shots(&csv, Path::new("twin.csv"), &scene).unwrap();
    let fit = Calibration::new(scene.clone(), free(&scene), shots, Options::default()).unwrap();
    crate::common::same_on_one_thread_and_two(|| {
        let r = fit.run(&|_| {}).unwrap();
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        (
            bits(&r.parameters),
            r.fitted.iter().map(|v| bits(&v.values)).collect::<Vec<_>>(),
            r.runs,
        )
    });
}
