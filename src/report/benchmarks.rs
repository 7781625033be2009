//! Section 6 of the report: the large-strain benchmark bars of `scenes/`
//! (the Wilkins copper bar and the 42CrMo4 bar, and the Wilkins bar in 3-D)
//! beside their converged finite-element references, at three resolutions.

use super::runner::{Probe, run_case};
use super::{Doc, Plan, Table, pct, sig};
use meshless_impact::Result;
use meshless_impact::Scene;

/// A benchmark scene file as shipped in `scenes/`, and the resolutions
/// (particles or nodes across the radius) of the full and the quick report.
struct Bench {
    file: &'static str,
    text: &'static str,
    full: &'static [f64],
    quick: f64,
}

/// The benchmarks: the axisymmetric bars at 20, 31 and 41 across, the 3-D
/// bar at 6, 8 and 11 (VALIDATION.md, "The staggered lattice").
const BENCHES: [Bench; 3] = [
    Bench {
        file: "wilkins_copper.toml",
        text: include_str!("../../scenes/wilkins_copper.toml"),
        full: &[20.0, 31.0, 41.0],
        quick: 8.0,
    },
    Bench {
        file: "crmo4_dynela.toml",
        text: include_str!("../../scenes/crmo4_dynela.toml"),
        full: &[20.0, 31.0, 41.0],
        quick: 8.0,
    },
    Bench {
        file: "wilkins_copper_3d.toml",
        text: include_str!("../../scenes/wilkins_copper_3d.toml"),
        full: &[6.0, 8.0, 11.0],
        quick: 4.0,
    },
];

/// Runs each benchmark at each resolution of the plan, one run at a time.
pub(crate) fn run(plan: &Plan, doc: &mut Doc) -> Result<()> {
    let mut t = Table::new(
        "benchmarks",
        &[
            "scene",
            "across",
            "outcome",
            "end_us",
            "Lf_mm",
            "Lf_ref_mm",
            "Lf_err",
            "Rf_mm",
            "Rf_ref_mm",
            "Rf_err",
            "energy_error",
            "min_spacing_ratio",
            "wall_s",
        ],
    );
    for b in &BENCHES {
        let resolutions = if plan.quick {
            std::slice::from_ref(&b.quick)
        } else {
            b.full
        };
        for &n in resolutions {
            let scene = Scene::from_toml_str(b.text).and_then(|mut s| {
                s.set("particles_radial", n)?;
                Ok(s)
            });
            let reference = scene.as_ref().map(|s| s.reference.clone()).ok();
            let r = run_case(
                scene,
                &Probe {
                    wall_budget: plan.wall_budget,
                    ..Probe::default()
                },
            );
            let rf = |k: &str| reference.as_ref().and_then(|m| m.get(k)).copied();
            let (lf, rr) = (r.get("rod_length"), r.get("mushroom_radius"));
            let (lf_ref, rf_ref) = (
                rf("rod_length").unwrap_or(f64::NAN),
                rf("mushroom_radius").unwrap_or(f64::NAN),
            );
            t.push(vec![
                b.file.to_string(),
                format!("{n}"),
                r.outcome.label().to_string(),
                format!("{:.2}", r.time * 1e6),
                format!("{:.3}", lf * 1e3),
                format!("{:.3}", lf_ref * 1e3),
                pct(lf, lf_ref),
                format!("{:.3}", rr * 1e3),
                format!("{:.3}", rf_ref * 1e3),
                pct(rr, rf_ref),
                sig(r.get("energy_error"), 3),
                sig(r.min_spacing, 3),
                sig(r.wall_s, 3),
            ]);
        }
    }
    doc.para(
        "## 6. Large-strain benchmarks beside their references\n\n\
         The Wilkins copper bar (face radius 7.15 mm and length 21.42 mm, the mean \
         of published finite-element solutions) and the 42CrMo4 Johnson-Cook bar \
         (axisymmetric DynELA and Abaqus: Lf 26.54 mm, Df 11.16 mm), from their scene \
         files (`meshless-impact run --scene-file scenes/NAME.toml --set \
         particles_radial=N`), which choose the large-strain scheme: h = 2.0 \
         spacings, velocity smoothing of order 2 and particle shifting (README). \
         The Wilkins bar in 3-D (`wilkins_copper_3d.toml`, MLPG, the whole body) \
         chooses the staggered lattice, conforming gradients and the order-2 \
         smoothing (README, \"The staggered lattice\"); N counts nodes across the \
         radius. Runs go one at a time, each on every core. Rf is the impact-face \
         radius.",
    );
    doc.table(&t)
}
