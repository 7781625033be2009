//! `meshless-impact report --quick`: the report regenerates, every file it
//! links exists, the Noh error falls with resolution at a positive observed
//! order, the elastic impact rebounds as theory says, and every case of the
//! stability matrix ends the way it is expected to (finished with finite
//! outputs, or stopped or refused with a named error).

use std::collections::BTreeMap;
use std::path::Path;

type Rows = Vec<BTreeMap<String, String>>;

fn read_csv(path: &Path) -> Rows {
    let mut r = csv::Reader::from_path(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let header = r.headers().unwrap().clone();
    r.records()
        .map(|rec| {
            let rec = rec.unwrap();
            header
                .iter()
                .zip(rec.iter())
                .map(|(k, v)| (k.to_string(), v.to_string()))
                .collect()
        })
        .collect()
}

/// The number the report prints in bold after `label` (`**label 0.83**`).
fn bold_number(text: &str, label: &str) -> f64 {
    let start = format!("**{label} ");
    let at = text
        .find(&start)
        .unwrap_or_else(|| panic!("no `{start}` in the report"))
        + start.len();
    let value = &text[at..at + text[at..].find("**").unwrap()];
    value
        .parse()
        .unwrap_or_else(|_| panic!("{label} = `{value}` is not a number"))
}

fn num(row: &BTreeMap<String, String>, key: &str) -> f64 {
    row[key]
        .parse()
        .unwrap_or_else(|_| panic!("{key} = `{}` is not a number", row[key]))
}

/// A recording (golden), not a criterion: the outcome of each stability
/// case in quick mode (6 particles across the radius unless the case sets
/// it), as the code gave it when recorded, the named stops included. What
/// it pins is behaviour: a case that changes its outcome fails the test
/// until the change is understood and re-recorded with its reason, as the
/// comments below record. Whether an outcome is right is argued in the
/// comments and in VALIDATION.md, not by this table: a stop here (the
/// paper's scheme at 600 m/s, `SpacingCollapse`) is the named error the
/// stability matrix expects of that case.
const EXPECTED: &[(&str, &str)] = &[
    ("elastic_10mps", "finished"),
    // The paper's scheme at 6 across: 400 m/s reaches rest; at 600 and
    // 800 m/s the rows at the impact face close below the spacing guard.
    ("speed_400", "finished"),
    ("speed_600", "SpacingCollapse"),
    ("speed_800", "SpacingCollapse"),
    ("bulk_x10", "finished"),
    ("bulk_x100", "finished"),
    ("soft_plastic", "EnergyDrift"),
    ("near_melt", "EnergyDrift"),
    ("coarse_3", "finished"),
    ("coarse_4", "finished"),
    ("fine", "finished"),
    ("aspect_0.5", "finished"),
    ("aspect_20", "finished"),
    ("smoothing_ratio_1.0", "SingularMomentMatrix"),
    ("smoothing_ratio_3.0", "finished"),
    // The large-strain scheme at 6 across: 400 and 600 m/s, the soft and the
    // near-melt rod run to their end with no named stop now that crowded
    // axis particles may leave the axis (README, "Particle shifting"); before, 600 m/s and the near-melt
    // rod stopped with `SpacingCollapse` on the axis column. 800 m/s stopped
    // with `SpacingCollapse` at the folding rim until the mantle slid along
    // itself; it is now quiet at 69.9 us (energy error 0.062).
    ("large_strain_400", "finished"),
    ("large_strain_600", "finished"),
    ("large_strain_800", "finished"),
    ("large_strain_soft", "finished"),
    ("large_strain_near_melt", "finished"),
    ("smoothing_coefficient_0", "EnergyDrift"),
    ("noh_50", "finished"),
    ("noh_fine", "finished"),
    ("noh_small_column", "Inconsistent"),
    ("invalid_density", "OutOfRange"),
    ("invalid_diameter", "OutOfRange"),
    ("invalid_speed_nan", "OutOfRange"),
    ("invalid_speed_inf", "OutOfRange"),
    ("invalid_melt", "Inconsistent"),
    ("invalid_particles", "OutOfRange"),
    ("invalid_name", "UnknownParameter"),
    // The 3-D MLPG solver at 3 nodes across with its default scheme,
    // large_strain (2026-11-28): the stiff rods and the rod at 600 m/s
    // finish. With the seed's scheme (the default before) the stiff rods'
    // energy error passed the bound (x10 at 11 us, x100 within 9 steps), and
    // so did the rod at 600 m/s, slowly (10.02 % at 34.2 us).
    ("taylor3d_bulk_x10", "finished"),
    ("taylor3d_bulk_x100", "finished"),
    ("taylor3d_speed_600", "finished"),
    ("taylor3d_coarse_3", "finished"),
    ("taylor3d_invalid_density", "OutOfRange"),
    ("taylor3d_invalid_diameter", "OutOfRange"),
    ("taylor3d_invalid_speed_nan", "OutOfRange"),
    ("taylor3d_invalid_speed_inf", "OutOfRange"),
    ("taylor3d_invalid_melt", "Inconsistent"),
    ("taylor3d_invalid_particles", "OutOfRange"),
    ("taylor3d_invalid_name", "UnknownParameter"),
    ("taylor3d_invalid_damping", "OutOfRange"),
    // The penetration rows at 3 nodes across (2546 nodes): a 2 mm plate
    // holds fewer than three layers at that spacing and is refused (the
    // full report runs it at 6 across); 2000 m/s finishes since pulverized
    // nodes do not shift (before, it lost its energy balance at 11.9 µs).
    ("penetration_speed_500", "finished"),
    ("penetration_speed_1000", "finished"),
    ("penetration_speed_2000", "finished"),
    ("penetration_plate_2mm", "Inconsistent"),
    ("penetration_plate_10mm", "finished"),
    ("penetration_invalid_porosity", "OutOfRange"),
    ("penetration_invalid_thickness", "OutOfRange"),
    ("penetration_invalid_speed_nan", "OutOfRange"),
    ("penetration_invalid_particles", "OutOfRange"),
    ("penetration_invalid_plate_diameter", "Inconsistent"),
    ("penetration_invalid_name", "UnknownParameter"),
    // The plate-impact rows (AD85 on AD85 unless named; energy errors
    // 6e-4 to 1.1e-2 at 3000 m/s, measured 2026-11-28).
    ("plate_impact_speed_10", "finished"),
    ("plate_impact_speed_100", "finished"),
    ("plate_impact_speed_1000", "finished"),
    ("plate_impact_speed_3000", "finished"),
    ("plate_impact_tungsten_3000", "finished"),
    ("plate_impact_thin", "finished"),
    ("plate_impact_invalid_material", "OutOfRange"),
    ("plate_impact_invalid_thickness", "OutOfRange"),
    ("plate_impact_invalid_speed_nan", "OutOfRange"),
    ("plate_impact_invalid_cell", "OutOfRange"),
    ("plate_impact_invalid_cells", "Inconsistent"),
    ("plate_impact_invalid_porosity", "OutOfRange"),
    ("plate_impact_invalid_name", "UnknownParameter"),
];

#[test]
fn quick_report_regenerates_and_meets_its_claims() {
    let dir = crate::common::scratch("report", "quick");
    crate::common::cli_stdout([
        std::ffi::OsStr::new("report"),
        "--quick".as_ref(),
        "--out".as_ref(),
        dir.as_os_str(),
    ]);

    // Every linked table and figure exists; figures are SVG.
    let index = std::fs::read_to_string(dir.join("index.md")).unwrap();
    assert!(index.contains("report --out") && index.contains("--quick"));
    let mut links = 0;
    for part in index.split("](").skip(1) {
        let file = &part[..part.find(')').unwrap()];
        let text =
            std::fs::read_to_string(dir.join(file)).unwrap_or_else(|e| panic!("{file}: {e}"));
        if file.ends_with(".svg") {
            assert!(text.starts_with("<svg"), "{file}");
        }
        links += 1;
    }
    assert!(links >= 20, "{links} links");

    // Noh: the L1 density error and the shock-position error fall as the
    // resolution rises, at a positive observed order.
    let noh = read_csv(&dir.join("noh_convergence.csv"));
    assert_eq!(noh.len(), 3);
    let l1: Vec<f64> = noh.iter().map(|r| num(r, "density_l1")).collect();
    let shock: Vec<f64> = noh.iter().map(|r| num(r, "shock_error")).collect();
    for k in 1..l1.len() {
        assert!(l1[k] < l1[k - 1], "density L1 error {l1:?}");
        assert!(shock[k] < shock[k - 1], "shock error {shock:?}");
    }
    // The observed orders the report states (least-squares fits over the
    // resolutions; the report's own unit tests check the fit).
    let order = bold_number(&index, "density L1");
    assert!(order > 0.5, "observed order {order}");
    assert!(bold_number(&index, "shock position") > 0.0);

    // Taylor test 7: the final length moves toward the finest run.
    let taylor = read_csv(&dir.join("taylor_convergence.csv"));
    let lf: Vec<f64> = taylor.iter().map(|r| num(r, "Lf_mm")).collect();
    let finest = *lf.last().unwrap();
    assert!((lf[0] - finest).abs() > (lf[1] - finest).abs(), "{lf:?}");
    assert!(taylor.iter().all(|r| r["outcome"] == "finished"));

    // Test 7 in 3-D beside it: at rest, the final length within 2 % of the
    // experiment (the scene's reference, data/house1995_4340_table1.csv),
    // the face's radius nearly the same all around the axis.
    let taylor3d = read_csv(&dir.join("taylor3d_convergence.csv"));
    assert_eq!(taylor3d.len(), 1);
    let exp = 1e3
        * meshless_impact::Scene::builtin("taylor3d")
            .unwrap()
            .reference["rod_length"];
    for r in &taylor3d {
        assert_eq!(r["outcome"], "finished");
        let lf = num(r, "Lf_mm");
        assert!(
            (lf - exp).abs() < 0.02 * exp,
            "3-D Lf {lf} mm, experiment {exp} mm"
        );
        assert!(num(r, "face_radius_spread") < 0.02, "{r:?}");
        assert!(num(r, "wall_s") > 0.0);
    }
    assert!(index.contains("taylor_error_vs_time_solvers.svg"));

    // The large-strain benchmarks, the Wilkins bar in 3-D among them: each
    // at rest with its energy error below 5 % (the large-deformation
    // issue's bound for every run).
    let benches = read_csv(&dir.join("benchmarks.csv"));
    let scenes: Vec<&str> = benches.iter().map(|r| r["scene"].as_str()).collect();
    assert_eq!(
        scenes,
        [
            "wilkins_copper.toml",
            "crmo4_dynela.toml",
            "wilkins_copper_3d.toml"
        ]
    );
    for r in &benches {
        assert_eq!(r["outcome"], "finished", "{r:?}");
        assert!(num(r, "energy_error") < 0.05, "{r:?}");
    }

    // The seed's penetration case at 4 across with the default ceramic
    // (`ad85_planes_freund`, tensile crack planes): pictures at 4, 8, 12
    // and 20 µs; the damaged fraction and the comminuted zone (nodes split
    // on all three planes: a split is final) only grow, the zone is there
    // from 4 µs; the projectile slows and leaves within 20 % of the seed's
    // 1240 m/s (measured 1147.6 m/s, comminuted radius 15.0 then 21.7 mm).
    let zones = read_csv(&dir.join("penetration_zones.csv"));
    let times: Vec<f64> = zones.iter().map(|r| num(r, "time_us")).collect();
    assert_eq!(times.len(), 4, "{times:?}");
    for (t, want) in times.iter().zip([4.0, 8.0, 12.0, 20.0]) {
        assert!((t - want).abs() < 0.1, "{times:?}");
        assert!(index.contains(&format!("penetration_damage_{want:.0}us.svg")));
    }
    for column in ["damaged_fraction", "comminuted_radius_mm"] {
        let c: Vec<f64> = zones.iter().map(|r| num(r, column)).collect();
        assert!(
            c[0] > 0.0 && c.windows(2).all(|w| w[1] >= w[0]),
            "{column}: {c:?}"
        );
    }
    let v: Vec<f64> = zones
        .iter()
        .map(|r| num(r, "projectile_velocity_mps"))
        .collect();
    assert!(v.windows(2).all(|w| w[1] < w[0]), "{v:?}");
    assert!((v[3] / 1240.0 - 1.0).abs() < 0.2, "{v:?}");

    // The ballistic-limit sweep at 3 across (quarter model), each shot to
    // its outcome, with the default ceramic: the plate cracks in tension
    // and every shot perforates (500 m/s at 45.9 µs with 362.2 m/s), the
    // faster shot leaving faster, so the shots do not bracket the limit.
    // (With the seed's set, `ad85_seed`, 500 m/s stopped:
    // tests/suite/penetration.rs.)
    let shots = read_csv(&dir.join("ballistic_limit.csv"));
    let outcomes: Vec<(f64, &str)> = shots
        .iter()
        .map(|r| (num(r, "impact_speed_mps"), r["outcome"].as_str()))
        .collect();
    assert_eq!(
        outcomes,
        [
            (500.0, "perforated"),
            (1000.0, "perforated"),
            (1500.0, "perforated")
        ]
    );
    let residual: Vec<f64> = shots
        .iter()
        .map(|r| num(r, "residual_velocity_mps"))
        .collect();
    assert!(
        residual.windows(2).all(|w| 0.0 < w[0] && w[0] < w[1])
            && residual
                .iter()
                .zip([500.0, 1000.0, 1500.0])
                .all(|(r, v)| *r < v),
        "{residual:?}"
    );
    assert!(index.contains("the shots do not bracket the ballistic limit"));
    assert!(index.contains("ballistic_limit.svg"));

    // The stability matrix: each case ends as expected, and no output of any
    // case holds a NaN or an infinity.
    let cases = read_csv(&dir.join("stability.csv"));
    let got: Vec<(&str, &str)> = cases
        .iter()
        .map(|r| (r["case"].as_str(), r["outcome"].as_str()))
        .collect();
    assert_eq!(got, EXPECTED);
    for r in &cases {
        let name = r["case"].as_str();
        assert_eq!(r["non_finite_outputs"], "none", "{name}");
        let refused = ["OutOfRange", "Inconsistent", "UnknownParameter"];
        if refused.contains(&r["outcome"].as_str()) {
            assert_eq!(r["steps"], "0", "{name}: refused before running");
            assert!(!r["message"].is_empty(), "{name}");
            continue;
        }
        let e = num(r, "energy_error");
        assert!(e.is_finite() && e >= 0.0, "{name}: energy_error {e}");
        assert!(num(r, "max_speed_mps").is_finite(), "{name}");
        if r["outcome"] == "finished" {
            assert!(e < 0.5, "{name}: energy_error {e}");
        } else {
            assert!(!r["message"].is_empty(), "{name}");
        }
    }

    // Elastic impact at 10 m/s: no plastic strain, the rod rebounds with its
    // initial length, and contact lasts two transits of the bar wave.
    let elastic: BTreeMap<String, f64> = read_csv(&dir.join("elastic_impact.csv"))
        .iter()
        .map(|r| (r["quantity"].clone(), num(r, "value")))
        .collect();
    assert_eq!(elastic["max_plastic_strain"], 0.0);
    assert!(elastic["length_change"].abs() < 0.1, "{elastic:?}");
    let (t, t_bar) = (elastic["contact_duration"], elastic["two_L0_over_c_bar"]);
    assert!(
        (t - t_bar).abs() < 0.05 * t_bar,
        "contact {t} µs vs 2 L0/c_bar {t_bar} µs"
    );
    assert!(elastic["final_tail_velocity"] < -9.0, "{elastic:?}");
    assert!(elastic["energy_error"] < 0.05, "{elastic:?}");
    std::fs::remove_dir_all(&dir).ok();
}

/// The committed report (`docs/report/index.md`) was made by the code's
/// physics: the digest it records is the one `meshless-impact report
/// --digest` prints now (the bits of small runs of every solver). A change
/// that moves any solver's bits fails this test until the report is
/// generated again (`meshless-impact report --out docs/report`), so that
/// its figures are never older than the code.
#[test]
fn the_committed_report_was_made_by_this_code() {
    let index = concat!(env!("CARGO_MANIFEST_DIR"), "/docs/report/index.md");
    let text = std::fs::read_to_string(index).unwrap();
    let label = "Physics digest: `";
    let at = text
        .find(label)
        .unwrap_or_else(|| panic!("no physics digest in {index}"))
        + label.len();
    let recorded = &text[at..at + text[at..].find('`').unwrap()];
    let now = crate::common::cli_stdout(["report", "--digest"]);
    let now = now.trim();
    assert_eq!(
        recorded, now,
        "docs/report was made by other physics: generate it again \
         (meshless-impact report --out docs/report)"
    );
    assert!(
        text.contains("Mode: **full**"),
        "the committed report is not the full one"
    );
}
