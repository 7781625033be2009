//! Sensitivity to the smoothing length and the conservative-smoothing
//! coefficient (the paper's Figs. 14 and 15), and Table 1 against experiment
//! and the paper's MSPH values.

use super::plot::{Axes, Series};
use super::runner::{CaseRun, run_parallel, scene};
use super::{Doc, Plan, Table, pct, sig};
use meshless_impact::Result;
use meshless_impact::Table1Row;

const RATIOS: [f64; 3] = [1.5, 2.0, 2.5];
const COEFFICIENTS: [f64; 6] = [0.0, 0.1, 0.2, 0.3, 0.4, 0.5];

fn tail_history(run: &CaseRun) -> Vec<(f64, f64)> {
    let h = &run.history;
    h.column("tail_velocity")
        .map(|c| h.times.iter().zip(c).map(|(t, v)| (t * 1e6, v)).collect())
        .unwrap_or_default()
}

pub(super) fn smoothing(plan: &Plan, doc: &mut Doc) -> Result<()> {
    let n = plan.resolution;
    let cases: Vec<(&str, f64)> = RATIOS
        .iter()
        .map(|&v| ("smoothing_ratio", v))
        .chain(COEFFICIENTS.iter().map(|&v| ("smoothing_coefficient", v)))
        .collect();
    super::progress!("report: {} smoothing cases in parallel", cases.len());
    let runs = run_parallel(
        cases
            .iter()
            .map(|&(name, v)| {
                scene(
                    "taylor",
                    &[("particles_radial", n), ("scheme", 1.0), (name, v)],
                )
            })
            .collect(),
        plan.wall_budget,
    );
    let reference = meshless_impact::Scene::builtin("taylor")?.reference;
    let mut t = Table::new(
        "sensitivity_smoothing",
        &[
            "parameter",
            "value",
            "outcome",
            "end_time_us",
            "steps",
            "wall_s",
            "Lf_mm",
            "Lf_vs_exp",
            "Df_mm",
            "Df_vs_exp",
            "Lu_mm",
            "energy_error",
            "smoothing_dissipation_J",
            "min_spacing_ratio",
        ],
    );
    for ((name, v), r) in cases.iter().zip(&runs) {
        let (lf, df) = (r.get("rod_length"), 2.0 * r.get("mushroom_radius"));
        t.push(vec![
            name.to_string(),
            v.to_string(),
            r.outcome.label().to_string(),
            sig(r.time * 1e6, 4),
            r.steps.to_string(),
            sig(r.wall_s, 3),
            format!("{:.3}", lf * 1e3),
            pct(lf, reference["rod_length"]),
            format!("{:.3}", df * 1e3),
            pct(df, 2.0 * reference["mushroom_radius"]),
            format!("{:.3}", r.get("undeformed_length") * 1e3),
            sig(r.get("energy_error"), 3),
            sig(r.get("smoothing_dissipation"), 4),
            sig(r.min_spacing, 3),
        ]);
    }
    doc.para(&format!(
        "## 3. Sensitivity to the smoothing length and to alpha_cs (Figs. 14 and 15)\n\n\
         Test 7 at {n} particles across the radius with the paper's scheme \
         (`scheme = paper`: smoothing_ratio 1.5, smoothing_coefficient 0.2, the \
         smoothing (3.23), no shifting), one parameter changed. A run that stops \
         early is shown up to its stop."
    ));
    doc.table(&t)?;
    let mut hist = Table::new(
        "sensitivity_tail_velocity",
        &["parameter", "value", "time_us", "tail_velocity_mps"],
    );
    for ((name, v), r) in cases.iter().zip(&runs) {
        for (t_us, u) in tail_history(r) {
            hist.push(vec![
                name.to_string(),
                v.to_string(),
                sig(t_us, 5),
                sig(u, 5),
            ]);
        }
    }
    hist.write_csv(doc.dir)?;
    doc.files.push("sensitivity_tail_velocity.csv".into());
    for (param, file, title, label) in [
        (
            "smoothing_ratio",
            "fig14_smoothing_length.svg",
            "Tail velocity for h = 1.5, 2.0, 2.5 x spacing (Fig. 14)",
            "h/spacing",
        ),
        (
            "smoothing_coefficient",
            "fig15_smoothing_coefficient.svg",
            "Tail velocity for alpha_cs = 0 ... 0.5 (Fig. 15)",
            "alpha_cs",
        ),
    ] {
        let series: Vec<Series> = cases
            .iter()
            .zip(&runs)
            .filter(|((n, _), _)| *n == param)
            .map(|((_, v), r)| Series::line(format!("{label} = {v}"), tail_history(r)))
            .collect();
        doc.lines(
            file,
            Axes::linear(title, "time (µs)", "tail velocity (m/s)"),
            &series,
        )?;
    }
    doc.para("Histories: [sensitivity_tail_velocity.csv](sensitivity_tail_velocity.csv).");
    Ok(())
}

pub(super) fn table1(plan: &Plan, doc: &mut Doc) -> Result<()> {
    let n = plan.resolution;
    let rows = Table1Row::all();
    super::progress!("report: Table 1, {} tests in parallel", rows.len());
    let runs = run_parallel(
        rows.iter()
            .map(|r| {
                let mut s = r.scene();
                s.set("particles_radial", n).map(|_| s)
            })
            .collect(),
        plan.wall_budget,
    );
    let mut t = Table::new(
        "table1",
        &[
            "test",
            "V_mps",
            "L0_mm",
            "D0_mm",
            "Lf_sim",
            "Lf_exp",
            "Lf_paper",
            "Lf_err",
            "Lu_sim",
            "Lu_exp",
            "Lu_paper",
            "Lu_err",
            "Df_sim",
            "Df_exp",
            "Df_paper",
            "Df_err",
            "energy_error",
            "min_spacing_ratio",
            "wall_s",
            "outcome",
        ],
    );
    // Parity points: (experiment, simulated) and (experiment, paper), mm.
    let mut ours = [Vec::new(), Vec::new(), Vec::new()];
    let mut paper = [Vec::new(), Vec::new(), Vec::new()];
    let (mut lf_err, mut df_err) = (Vec::new(), Vec::new());
    for (row, r) in rows.iter().zip(&runs) {
        let sim = [
            r.get("rod_length"),
            r.get("undeformed_length"),
            2.0 * r.get("mushroom_radius"),
        ];
        let exp = [row.lf_test, row.lu_test, row.df_test];
        let pap = [row.lf_msph, row.lu_msph, row.df_msph];
        let mut cells = vec![
            row.test.to_string(),
            row.v.to_string(),
            format!("{:.2}", row.l0 * 1e3),
            format!("{:.2}", row.d0 * 1e3),
        ];
        for k in 0..3 {
            cells.push(format!("{:.2}", sim[k] * 1e3));
            cells.push(format!("{:.2}", exp[k] * 1e3));
            cells.push(format!("{:.2}", pap[k] * 1e3));
            cells.push(pct(sim[k], exp[k]));
            ours[k].push((exp[k] * 1e3, sim[k] * 1e3));
            paper[k].push((exp[k] * 1e3, pap[k] * 1e3));
        }
        if r.finished() {
            lf_err.push((100.0 * (sim[0] - exp[0]) / exp[0]).abs());
            df_err.push((100.0 * (sim[2] - exp[2]) / exp[2]).abs());
        }
        cells.extend([
            sig(r.get("energy_error"), 3),
            sig(r.min_spacing, 3),
            sig(r.wall_s, 3),
            r.outcome.label().to_string(),
        ]);
        t.push(cells);
    }
    let stat = |v: &[f64]| {
        (
            v.iter().sum::<f64>() / v.len().max(1) as f64,
            v.iter().copied().fold(0.0, f64::max),
        )
    };
    let ((lm, lx), (dm, dx)) = (stat(&lf_err), stat(&df_err));
    doc.para(&format!(
        "## 4. Table 1: simulated, experimental and the paper's MSPH values\n\n\
         The twelve House et al. tests at {n} particles across the radius \
         (`meshless-impact sweep table1 --set particles_radial={n}`). Lengths in mm; \
         errors against experiment."
    ));
    doc.table(&t)?;
    doc.para(&format!(
        "Final length |error|: mean {lm:.2}%, largest {lx:.2}% (the paper's largest: \
         4.3%). Impact-face diameter |error|: mean {dm:.2}%, largest {dx:.2}% (the \
         paper's largest: 9.0%). {} of 12 runs finished.",
        lf_err.len()
    ));
    let names = ["Lf", "Lu", "Df"];
    let mut series = Vec::new();
    for k in 0..3 {
        series.push(Series::markers(
            format!("{} (this solver)", names[k]),
            ours[k].clone(),
        ));
        series.push(Series::markers(
            format!("{} (paper's MSPH)", names[k]),
            paper[k].clone(),
        ));
    }
    doc.lines(
        "table1_parity.svg",
        Axes {
            title: "Table 1: simulated against experiment",
            x: "experiment (mm)",
            y: "simulated (mm)",
            log_x: false,
            log_y: false,
            diagonal: true,
        },
        &series,
    )?;
    Ok(())
}
