//! Figures like the paper's for Taylor test 7: time histories and maps of
//! effective plastic strain and temperature in the R-Z plane.

use super::convergence::{FACE_LIFT_WINDOW, MAP_TIMES};
use super::plot::{self, Axes, Series};
use super::runner::CaseRun;
use super::{Doc, Plan, Table, sig};
use meshless_impact::Result;

/// The paper's values quoted beside the maps (section 4.2.1 of the paper).
const PAPER_PEAK_STRAIN: f64 = 0.84;
const PAPER_MAX_TEMPERATURE_15US: f64 = 486.5;

pub(super) fn test7(plan: &Plan, doc: &mut Doc, run: CaseRun) -> Result<()> {
    let h = &run.history;
    let t_us: Vec<f64> = h.times.iter().map(|t| t * 1e6).collect();
    let col = |n: &str, scale: f64| -> Vec<(f64, f64)> {
        let c = h.column(n).expect("taylor observable");
        t_us.iter().zip(c).map(|(t, v)| (*t, v * scale)).collect()
    };
    doc.para(&format!(
        "## 2. Taylor test 7: time histories and maps\n\n\
         Test 7 at {} particles across the radius ({} particles), {}: the run of \
         section 1.2 at that resolution. Histories are recorded 64 times per elastic \
         transit L0/Ce; the face lift during the first 3 µs after every step.",
        plan.figures,
        run.particles,
        run.outcome.label()
    ));
    let mut hist = Table::new(
        "test7_history",
        &[
            "time_us",
            "tail_velocity_mps",
            "rod_length_mm",
            "mushroom_radius_mm",
            "face_lift_um",
        ],
    );
    let (tail, len, rad, lift) = (
        col("tail_velocity", 1.0),
        col("rod_length", 1e3),
        col("mushroom_radius", 1e3),
        col("face_lift", 1e6),
    );
    for k in 0..t_us.len() {
        hist.push(vec![
            sig(t_us[k], 5),
            sig(tail[k].1, 5),
            sig(len[k].1, 5),
            sig(rad[k].1, 5),
            sig(lift[k].1, 4),
        ]);
    }
    hist.write_csv(doc.dir)?;
    doc.files.push("test7_history.csv".into());
    let ax = |title, y| Axes::linear(title, "time (µs)", y);
    doc.lines(
        "test7_tail_velocity.svg",
        ax("Test 7: tail axial velocity", "velocity (m/s)"),
        &[Series::line("tail_velocity", tail)],
    )?;
    doc.lines(
        "test7_length_radius.svg",
        ax("Test 7: rod length and impact-face radius", "length (mm)"),
        &[
            Series::line("rod_length", len),
            Series::line("mushroom_radius", rad),
        ],
    )?;
    let lift: Vec<(f64, f64)> = run
        .per_step
        .iter()
        .map(|(t, v)| (t * 1e6, v[0] * 1e6))
        .collect();
    let mut lt = Table::new("test7_face_lift", &["time_us", "face_lift_um"]);
    for (t, v) in &lift {
        lt.push(vec![sig(*t, 5), sig(*v, 4)]);
    }
    lt.write_csv(doc.dir)?;
    doc.files.push("test7_face_lift.csv".into());
    doc.lines(
        "test7_face_lift.svg",
        ax(
            "Test 7: lift of the impact-face centre, first 3 µs",
            "face lift (µm)",
        ),
        &[Series::line("face_lift", lift.clone())],
    )?;
    // When the face centre leaves and touches the anvil again, and how high it goes.
    let off = lift.iter().find(|p| p.1 > 0.0).map(|p| p.0);
    let back = off.and_then(|t0| lift.iter().find(|p| p.0 > t0 && p.1 <= 0.0).map(|p| p.0));
    let top = lift.iter().map(|p| p.1).fold(0.0, f64::max);
    let us = |t: Option<f64>| t.map_or("—".to_string(), |t| format!("{t:.2} µs"));
    doc.para(&format!(
        "Histories: [test7_history.csv](test7_history.csv), face lift after every step \
         to {} µs: [test7_face_lift.csv](test7_face_lift.csv). The face centre leaves \
         the anvil at {}, rises to {:.1} µm and touches again at {} (paper: leaves at \
         about 1 µs, about 0.03 mm, back at 2.4 µs).",
        FACE_LIFT_WINDOW * 1e6,
        us(off),
        top,
        us(back)
    ));
    let mut peaks = Table::new(
        "test7_map_peaks",
        &[
            "time_us",
            "peak_plastic_strain",
            "paper_peak_plastic_strain",
            "max_temperature_K",
            "paper_max_temperature_K",
        ],
    );
    for (k, snap) in run.snapshots.iter().enumerate() {
        let eps = &snap.field("plastic_strain").expect("taylor field").data;
        let temp = &snap.field("temperature").expect("taylor field").data;
        let label = format!("{:.0}us", MAP_TIMES[k] * 1e6);
        let mut mt = Table::new(
            &format!("test7_map_{label}"),
            &["R_mm", "Z_mm", "plastic_strain", "temperature_K"],
        );
        for (i, p) in snap.positions.iter().enumerate() {
            mt.push(vec![
                sig(p[0] * 1e3, 5),
                sig(p[1] * 1e3, 5),
                sig(eps[i], 4),
                sig(temp[i], 5),
            ]);
        }
        mt.write_csv(doc.dir)?;
        doc.files.push(format!("{}.csv", mt.name));
        let time = format!("{:.1} µs", snap.time * 1e6);
        for (field, values, unit) in [
            ("plastic_strain", eps, "effective plastic strain"),
            ("temperature", temp, "temperature (K)"),
        ] {
            let file = format!("test7_{field}_{label}.svg");
            let title = format!("Test 7, t = {time}: {unit}");
            plot::map(&doc.dir.join(&file), &title, &snap.positions, values)?;
            doc.image(&file, &title);
        }
        let max = |v: &[f64]| v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        peaks.push(vec![
            format!("{:.1}", snap.time * 1e6),
            sig(max(eps), 3),
            if k == 0 {
                "—".into()
            } else {
                format!("≈ {PAPER_PEAK_STRAIN} (final, text)")
            },
            sig(max(temp), 4),
            if k == 0 {
                format!("{PAPER_MAX_TEMPERATURE_15US}")
            } else {
                "≈ 500 (final, text)".into()
            },
        ]);
    }
    doc.para(
        "Peak values on the maps beside the paper's (section 4.2.1: 486.5 K at 15 µs \
         with MSPH; peak strain 84% and maximum temperature about 500 K in the \
         mushroomed region at the end). Particle values: test7_map_15us.csv, \
         test7_map_30us.csv.",
    );
    doc.table(&peaks)?;
    Ok(())
}
