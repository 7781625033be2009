//! `meshless-impact run`: one scene to its end condition, with its
//! snapshots, histories and final values, and the summary on stdout.

use super::args::RunArgs;
use super::output::{check_output_dir, check_output_file, final_json, write_json, write_profile};
use super::resume::{RunHost, begin};
use super::signals;
use super::stop::{Stop, errln, outcome, outln};
use super::team;
use indicatif::{ProgressBar, ProgressStyle};
use meshless_impact::ranks::Handle;
use meshless_impact::{Error, Isa, Simulation};
use std::io::{IsTerminal, Write};
use std::time::{Duration, Instant};

pub(crate) fn fmt_duration(s: f64) -> String {
    if s < 1e-3 {
        format!("{:.2} us", s * 1e6)
    } else {
        format!("{s:.4} s")
    }
}

pub(crate) fn run(a: RunArgs) -> Result<(), Stop> {
    let team = team::join()?;
    let r = run_on(&team, a);
    team::quiet_unless_root(&*team, r)
}

/// The run on the ranks of `team` (one alone without MPI): every rank
/// steps the whole run, the passes over the nodes shared
/// ([`meshless_impact::ranks`]); rank 0 writes the outputs and prints.
fn run_on(team: &Handle, mut a: RunArgs) -> Result<(), Stop> {
    let began = begin(&a).and_then(|(mut sim, host)| {
        if let Some(name) = &a.isa {
            sim.set_isa(Isa::named(name).map_err(|e| Stop::failed(format!("--isa: {e}")))?);
        }
        if team.size() > 1 {
            sim.set_ranks(team.clone()).map_err(Stop::failed)?;
        }
        Ok((sim, host))
    });
    let (sim, mut host) = team::agree(&**team, began)?;
    if team.rank() > 0 {
        // Rank 0 writes and prints; the others hold the same run.
        // Every rank writes its piece of each VTK snapshot.
        (host.json, host.csv, host.checkpoint) = (None, None, None);
        host.profile = None;
        a.quiet = true;
    }
    run_sim(team, sim, host, &a)
}

/// The loop of [`run_on`] and the outputs of its end.
fn run_sim(team: &Handle, mut sim: Simulation, mut host: RunHost, a: &RunArgs) -> Result<(), Stop> {
    let end_time = sim.end_time();
    // Every output is checked before the run, so that a typo does not cost
    // the results of a long run; on several ranks, a failed check on any
    // stops all (the others would wait for it at the first step).
    let checked = check_outputs(team, &sim, &host).and_then(|()| {
        signals::install().map_err(|e| Stop::failed(format!("installing the signal handlers: {e}")))
    });
    team::agree(&**team, checked)?;
    // The first snapshot failure, reported after the run.
    let mut vtk_error = None;
    if host.vtk_dir.is_some() && host.vtk_next == 0 && sim.steps() == 0 {
        let due = host.vtk_times.iter().take_while(|&&t| t <= 0.0).count();
        if due > 0 {
            if let Err(e) = write_vtk(team, &sim, &mut host) {
                vtk_error = Some(e);
            }
            host.vtk_next = due;
        }
    }

    let start = Instant::now();
    let wall_before = host.wall_s;
    let show_bar = !a.quiet && std::io::stderr().is_terminal();
    let mut bar: Option<ProgressBar> = None;
    let mut last_draw = Instant::now();
    let mut last_checkpoint = (Instant::now(), sim.steps());
    let mut checkpoint_error: Option<Error> = None;
    // Snapshots need the state between steps, so the loop is written out here.
    let mut status = Ok(());
    let mut interrupted = None;
    // Another rank's failure at a step this rank passed (`team::diverged`).
    let mut diverged = None;
    // The whole loop runs on a worker of the thread pool, so a step does not
    // wake a worker from this thread and wait to be woken in turn.
    rayon::scope(|_| {
        while !sim.finished() {
            let signal = team::agree_signal(&**team, signals::received_number());
            if let Some(sig) = signals::named(signal) {
                interrupted = Some(sig);
                break;
            }
            // The damage variables stay apart among the ranks between
            // steps; shared before a snapshot, a checkpoint and the end.
            let stepped = sim.step_apart();
            if let Some(stop) =
                team::diverged(&**team, stepped.as_ref().err().map(|e| e.to_string()))
            {
                diverged = Some(stop);
                break;
            }
            if let Err(e) = stepped {
                status = Err(e);
                break;
            }
            while host.vtk_next < host.vtk_times.len()
                && sim.time() >= host.vtk_times[host.vtk_next]
            {
                sim.share();
                if let Err(e) = write_vtk(team, &sim, &mut host) {
                    vtk_error.get_or_insert(e);
                }
                host.vtk_next += 1;
            }
            // Rank 0 alone keeps the checkpoint, timed by its clock: the
            // ranks agree on when, so that all share the state first.
            let due = host.checkpoint.is_some()
                && !sim.finished()
                && (last_checkpoint.0.elapsed().as_secs_f64() >= host.checkpoint_every
                    || host
                        .checkpoint_steps
                        .is_some_and(|n| sim.steps() >= last_checkpoint.1 + n));
            if team::any(&**team, due) {
                sim.share();
            }
            if due {
                host.wall_s = wall_before + start.elapsed().as_secs_f64();
                if let Err(e) = save_checkpoint(&sim, &host) {
                    if checkpoint_error.is_none() {
                        let _ = errln!("warning: --checkpoint: {e}; the run goes on");
                    }
                    checkpoint_error.get_or_insert(e);
                }
                last_checkpoint = (Instant::now(), sim.steps());
            }
            if show_bar
                && start.elapsed() > Duration::from_secs(1)
                && last_draw.elapsed() > Duration::from_millis(100)
            {
                let b = bar.get_or_insert_with(|| {
                    let b = ProgressBar::new(1000);
                    b.set_style(
                        ProgressStyle::with_template(
                            "{spinner} [{elapsed_precise}] {bar:30} {msg}",
                        )
                        .expect("valid template"),
                    );
                    b
                });
                b.set_position(((sim.time() / end_time) * 1000.0) as u64);
                b.set_message(format!(
                    "t = {}, {} steps, {} particles",
                    fmt_duration(sim.time()),
                    sim.steps(),
                    sim.particles()
                ));
                last_draw = Instant::now();
            }
        }
    });
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    if let Some(stop) = diverged {
        return Err(stop);
    }
    // Every rank ends the loop at the same step: the state whole for the
    // outputs.
    sim.share();
    let wall = wall_before + start.elapsed().as_secs_f64();
    host.wall_s = wall;

    // Every output is written, even when the run stopped early or another
    // output failed; the failures are reported together at the end.
    let mut failures = Vec::new();
    if let Err(e) = &status {
        failures.push(e.to_string());
    }
    let mut saved_to = None;
    if interrupted.is_some()
        && let Some(path) = &host.checkpoint
    {
        match save_checkpoint(&sim, &host) {
            Ok(()) => saved_to = Some(path.clone()),
            Err(e) => failures.push(format!("--checkpoint: {e}")),
        }
    } else if let Some(e) = checkpoint_error {
        failures.push(format!("--checkpoint: {e}"));
    }
    // The final snapshot is the run's end's: an interrupted run writes it
    // when it is continued.
    if interrupted.is_none()
        && let Err(e) = write_vtk(team, &sim, &mut host)
    {
        vtk_error.get_or_insert(e);
    }
    if let Some(e) = vtk_error {
        failures.push(format!("--vtk-dir: {e}"));
    }
    if let Some(path) = &host.csv
        && let Err(e) = sim.history().write_csv(path)
    {
        failures.push(format!("--csv: {e}"));
    }
    if let Some(path) = &host.profile
        && let Err(e) = write_profile(path, &sim)
    {
        failures.push(format!("--profile: {e}"));
    }
    if let Some(path) = &host.json {
        let mut json = final_json(&sim, wall, status.as_ref().err());
        if let Some(sig) = interrupted {
            json["outcome"] = "interrupted".into();
            json["signal"] = sig.into();
        }
        if let Err(e) = write_json(path, &json) {
            failures.push(format!("--json: {e}"));
        }
    }
    if let Some(sig) = interrupted {
        let mut lines = vec![format!(
            "interrupted by {sig} at t = {}, step {}; the outputs hold the run so far",
            fmt_duration(sim.time()),
            sim.steps()
        )];
        lines.push(match &saved_to {
            Some(p) => format!(
                "checkpoint written to {0}; continue with `meshless-impact run --restart {0}`",
                p.display()
            ),
            None => "no checkpoint was asked for (--checkpoint FILE)".into(),
        });
        lines.extend(failures.into_iter().map(|f| format!("error: {f}")));
        return Err(Stop::Interrupted(lines));
    }
    if a.phases {
        print_phases(team, &sim);
    }
    let printed = if a.quiet {
        Ok(())
    } else {
        print_summary(&sim, wall)
    };
    outcome(failures, printed)
}

/// The checks of the outputs before a run (rank 0 holds every output but
/// the VTK pieces, which every rank writes).
fn check_outputs(team: &Handle, sim: &Simulation, host: &RunHost) -> Result<(), Stop> {
    if let Some(path) = &host.json {
        check_output_file("--json", path)?;
    }
    if let Some(path) = &host.csv {
        check_output_file("--csv", path)?;
    }
    if let Some(path) = &host.checkpoint {
        check_output_file("--checkpoint", path)?;
    }
    if let Some(path) = &host.profile {
        check_output_file("--profile", path)?;
        if sim.rod_profile().is_none() {
            return Err(Stop::failed(format!(
                "--profile: scene `{}` has no rod to outline",
                sim.kind().name()
            )));
        }
    }
    if let Some(dir) = &host.vtk_dir {
        let probe = if team.rank() == 0 {
            "particles.pvd".to_string()
        } else {
            piece_name(host.vtk_written.len(), team.rank())
        };
        check_output_dir("--vtk-dir", dir, &probe)?;
    }
    Ok(())
}

/// The file of rank `rank`'s piece of snapshot `k` on several ranks.
fn piece_name(k: usize, rank: usize) -> String {
    format!("particles_{k:04}_{rank}.vtu")
}

/// `--phases`: the solver's time by phase on stderr (on several ranks,
/// every rank's, printed by rank 0 in rank order), or a line saying that
/// the scene keeps none.
fn print_phases(team: &Handle, sim: &Simulation) {
    let table = match sim.phase_table() {
        Some(table) => table.trim_end().to_string(),
        None => {
            let _ = errln!(
                "--phases: scene `{}` keeps no time by phase (the 3-D scenes do)",
                sim.kind().name()
            );
            return;
        }
    };
    if team.size() == 1 {
        let _ = errln!("phases:\n{table}");
        return;
    }
    // Every rank's table, printed by rank 0 in rank order (the ranks'
    // own prints interleaved on the terminal).
    let (all, counts) = meshless_impact::ranks::all_gather_bytes(&**team, table.as_bytes());
    if team.rank() == 0 {
        let mut at = 0;
        for (rank, &count) in counts.iter().enumerate() {
            let text = String::from_utf8_lossy(&all[at..at + count]);
            at += count;
            let _ = errln!("phases of rank {rank} of {}:\n{text}", team.size());
        }
    }
}

/// Writes the next snapshot of the run into `--vtk-dir` (if given) and
/// rewrites the collection `particles.pvd`, so that it is whole even when
/// a run stops early. On several ranks each rank writes its share of the
/// particles as a piece (`particles_NNNN_R.vtu`), and rank 0 the parallel
/// file that joins them (`particles_NNNN.pvtu`), listed in the collection;
/// a piece that failed on any rank fails the snapshot on rank 0.
fn write_vtk(team: &Handle, sim: &Simulation, host: &mut RunHost) -> Result<(), Error> {
    let Some(dir) = host.vtk_dir.clone() else {
        return Ok(());
    };
    let k = host.vtk_written.len();
    let snapshot = sim.snapshot();
    let name = if team.size() == 1 {
        let name = format!("particles_{k:04}.vtu");
        snapshot.write_vtu(&dir.join(&name))?;
        name
    } else {
        let (rank, size) = (team.rank(), team.size());
        let rows = meshless_impact::ranks::share(snapshot.positions.len(), rank, size, 1);
        let mine = snapshot
            .piece(rows)
            .write_vtu(&dir.join(piece_name(k, rank)));
        if let Some((r, message)) = team::first_error(&**team, mine.err().map(|e| e.to_string())) {
            return Err(Error::io(
                dir.join(piece_name(k, r)),
                format!("rank {r}'s piece: {message}"),
            ));
        }
        let name = format!("particles_{k:04}.pvtu");
        if rank == 0 {
            let pieces: Vec<String> = (0..size).map(|r| piece_name(k, r)).collect();
            snapshot.write_pvtu(&dir.join(&name), &pieces)?;
        }
        name
    };
    host.vtk_written.push((sim.time(), name));
    if team.rank() == 0 {
        meshless_impact::write_pvd(&dir.join("particles.pvd"), &host.vtk_written)?;
    }
    Ok(())
}

/// Writes the checkpoint of `--checkpoint`: the run and `host`.
fn save_checkpoint(sim: &Simulation, host: &RunHost) -> Result<(), Error> {
    let Some(path) = &host.checkpoint else {
        return Ok(());
    };
    let value = serde_json::to_value(host).map_err(|e| Error::io(path, e))?;
    meshless_impact::checkpoint::save(path, sim, &value)
}

/// What the two columns of references mean, printed under a table that
/// has both.
const CONTINUUM_NOTE: &str = "continuum: the converged solution with the scene's material constants \
(LS-DYNA, Batra & Zhang 2008), which the default scheme converges to; experiment: House et al. (1995). \
They differ because the constants come from other tests (docs/guide/materials.md).";

fn print_summary(sim: &Simulation, wall: f64) -> Result<(), Stop> {
    outln!("scene: {}", sim.scene().title)?;
    outln!(
        "particles {}, steps {}, end time {}, wall time {:.2} s",
        sim.particles(),
        sim.steps(),
        fmt_duration(sim.time()),
        wall
    )?;
    if let Some(e) = sim.error() {
        outln!("stopped early: {e}")?;
    }
    let scene = sim.scene();
    let both = scene.has_continuum_reference();
    let against = |r: Option<f64>, v: f64| match r {
        Some(r) if r != 0.0 => (format!("{r:.6}"), format!("{:+.2}%", 100.0 * (v - r) / r)),
        _ => (String::new(), String::new()),
    };
    if both {
        outln!(
            "{:<24} {:>14} {:>14} {:>9} {:>14} {:>9}  unit",
            "observable",
            "value",
            "continuum",
            "error",
            "experiment",
            "error"
        )?;
    } else {
        outln!(
            "{:<24} {:>14} {:>14} {:>9}  unit",
            "observable",
            "value",
            "reference",
            "error"
        )?;
    }
    for (s, v) in sim.observable_specs().iter().zip(sim.observables()) {
        let (r, e) = against(scene.reference_of(s.name), v);
        let val = if s.is_bool() {
            (v != 0.0).to_string()
        } else {
            format!("{v:.6}")
        };
        if both {
            let (c, ce) = against(scene.continuum_reference_of(s.name), v);
            outln!(
                "{:<24} {:>14} {:>14} {:>9} {:>14} {:>9}  {}",
                s.name,
                val,
                c,
                ce,
                r,
                e,
                s.unit
            )?;
        } else {
            outln!("{:<24} {:>14} {:>14} {:>9}  {}", s.name, val, r, e, s.unit)?;
        }
    }
    if both {
        outln!("{CONTINUUM_NOTE}")?;
    }
    Ok(())
}
