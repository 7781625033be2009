//! Section 6 of the report: the two large-strain benchmark bars of `scenes/`
//! (the Wilkins copper bar and the 42CrMo4 bar) beside their converged
//! finite-element references, at three resolutions.

use super::runner::{Probe, run_case};
use super::{Doc, Plan, Table, pct, sig};
use meshless_impact::Result;
use meshless_impact::Scene;

/// The benchmark scene files, as shipped in `scenes/`.
const SCENES: [(&str, &str); 2] = [
    (
        "wilkins_copper.toml",
        include_str!("../../scenes/wilkins_copper.toml"),
    ),
    (
        "crmo4_dynela.toml",
        include_str!("../../scenes/crmo4_dynela.toml"),
    ),
];

/// Runs each benchmark at each resolution of the plan, one run at a time.
pub(crate) fn run(plan: &Plan, doc: &mut Doc) -> Result<()> {
    let resolutions: &[f64] = if plan.quick {
        &[8.0]
    } else {
        &[20.0, 31.0, 41.0]
    };
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
    for (file, text) in SCENES {
        for &n in resolutions {
            let scene = Scene::from_toml_str(text).and_then(|mut s| {
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
                file.to_string(),
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
         Runs go one at a time, each on every core. Rf is the impact-face radius.",
    );
    doc.table(&t)
}
