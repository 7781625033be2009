//! `meshless-impact sweep table1`: the twelve tests of Table 1 in parallel,
//! as a CSV table and a table on stdout.

use super::args::{SweepArgs, apply_sets};
use super::output::{check_output_file, write_csv_records};
use super::stop::{Stop, errln, outcome, outln};
use meshless_impact::{Error, Simulation, Table1Row};
use rayon::prelude::*;
use std::io::Write;
use std::path::Path;
use std::time::Instant;

/// Simulated values of one configuration: final length, undeformed length,
/// impact-face diameter, energy error, particles, steps, wall time.
type SweepValues = (f64, f64, f64, f64, usize, u64, f64);

/// One row of the Table 1 sweep.
struct SweepRow {
    row: Table1Row,
    result: Result<SweepValues, Error>,
}

pub(crate) fn sweep(a: SweepArgs) -> Result<(), Stop> {
    if a.name != "table1" {
        return Err(Error::UnknownScene {
            name: a.name,
            allowed: "table1".into(),
        }
        .into());
    }
    let rows = Table1Row::all();
    let mut scenes = Vec::new();
    for r in &rows {
        let mut s = r.scene();
        apply_sets(&mut s, &a.set)?;
        scenes.push(s);
    }
    check_output_file("--out", &a.out)?;
    let start = Instant::now();
    errln!(
        "running {} Table 1 configurations in parallel...",
        scenes.len()
    )?;
    let results: Vec<SweepRow> = rows
        .par_iter()
        .zip(scenes)
        .map(|(row, scene)| {
            let t0 = Instant::now();
            let result = Simulation::new(scene).and_then(|mut sim| {
                sim.run()?;
                let o = |n: &str| sim.observable(n).expect("taylor observable");
                Ok((
                    o("rod_length"),
                    o("undeformed_length"),
                    2.0 * o("mushroom_radius"),
                    o("energy_error"),
                    sim.particles(),
                    sim.steps(),
                    t0.elapsed().as_secs_f64(),
                ))
            });
            SweepRow { row: *row, result }
        })
        .collect();
    write_sweep(&a.out, &results, start.elapsed().as_secs_f64())
}

/// Columns of the sweep's CSV table.
const SWEEP_HEADER: [&str; 20] = [
    "test",
    "V_mps",
    "L0_mm",
    "Lf_sim_mm",
    "Lf_test_mm",
    "Lf_msph_mm",
    "Lf_err_pct",
    "Lu_sim_mm",
    "Lu_test_mm",
    "Lu_msph_mm",
    "Lu_err_pct",
    "Df_sim_mm",
    "Df_test_mm",
    "Df_msph_mm",
    "Df_err_pct",
    "energy_error",
    "particles",
    "steps",
    "wall_s",
    "error",
];

/// Writes the sweep's results: the CSV table to `out` first, then the table
/// and the error statistics on stdout (printed even when the CSV failed).
fn write_sweep(out: &Path, results: &[SweepRow], wall: f64) -> Result<(), Stop> {
    let pct = |sim: f64, exp: f64| 100.0 * (sim - exp) / exp;
    let (mut lf_err, mut df_err) = (Vec::new(), Vec::new());
    // CSV records and the lines of the table on stdout.
    let (mut records, mut lines) = (Vec::new(), Vec::new());
    for r in results {
        let t = &r.row;
        match &r.result {
            Ok((lf, lu, df, energy, n, steps, secs)) => {
                let (el, eu, ed) = (
                    pct(*lf, t.lf_test),
                    pct(*lu, t.lu_test),
                    pct(*df, t.df_test),
                );
                lf_err.push(el.abs());
                df_err.push(ed.abs());
                // Groups of (simulated, test, paper MSPH) in mm with the error in %.
                let groups = [
                    [lf * 1e3, t.lf_test * 1e3, t.lf_msph * 1e3, el],
                    [lu * 1e3, t.lu_test * 1e3, t.lu_msph * 1e3, eu],
                    [df * 1e3, t.df_test * 1e3, t.df_msph * 1e3, ed],
                ];
                let mut line = format!("{:>4} {:>5} {:>6.2}", t.test, t.v, t.l0 * 1e3);
                for g in &groups {
                    line += &format!(
                        " | {:>6.2} {:>6.2} {:>6.2} {:>+7.2}",
                        g[0], g[1], g[2], g[3]
                    );
                }
                lines.push(format!("{line} | {energy:>6.4} {secs:>7.1}"));
                let mut rec = vec![
                    t.test.to_string(),
                    t.v.to_string(),
                    (t.l0 * 1e3).to_string(),
                ];
                rec.extend(groups.iter().flatten().map(|x| x.to_string()));
                rec.extend([
                    energy.to_string(),
                    n.to_string(),
                    steps.to_string(),
                    secs.to_string(),
                    String::new(),
                ]);
                records.push(rec);
            }
            Err(e) => {
                lines.push(format!(
                    "{:>4} {:>5} {:>6.2} | failed: {e}",
                    t.test,
                    t.v,
                    t.l0 * 1e3
                ));
                let mut rec = vec![String::new(); SWEEP_HEADER.len()];
                rec[0] = t.test.to_string();
                rec[SWEEP_HEADER.len() - 1] = e.to_string();
                records.push(rec);
            }
        }
    }
    let written = write_csv_records(out, &SWEEP_HEADER, &records);

    let print = || -> Result<(), Stop> {
        outln!(
            "test     V     L0 |     Lf   test   MSPH    err% |     Lu   test   MSPH    err% \
             |     Df   test   MSPH    err% |  E err  wall s"
        )?;
        for line in &lines {
            outln!("{line}")?;
        }
        let stat = |v: &[f64]| {
            (
                v.iter().sum::<f64>() / v.len().max(1) as f64,
                v.iter().copied().fold(0.0, f64::max),
            )
        };
        let (lm, lx) = stat(&lf_err);
        let (dm, dx) = stat(&df_err);
        outln!(
            "final length |error|: mean {lm:.2}%, max {lx:.2}% (paper max 4.3%); \
             impact-face diameter |error|: mean {dm:.2}%, max {dx:.2}% (paper max 9.0%)"
        )?;
        if written.is_ok() {
            outln!("wall time {wall:.1} s; table written to {}", out.display())
        } else {
            outln!("wall time {wall:.1} s; table not written")
        }
    };
    let printed = print();

    let mut failures = Vec::new();
    if let Err(e) = written {
        failures.push(format!("--out: {e}"));
    }
    if lf_err.len() != results.len() {
        failures.push(format!(
            "{} of {} configurations failed",
            results.len() - lf_err.len(),
            results.len()
        ));
    }
    outcome(failures, printed)
}
