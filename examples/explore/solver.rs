//! Explorations of the 3-D solver's runs (moved from
//! `tests/suite/mlpg_solver.rs`).

use crate::rod::*;
use meshless_impact::internals::mlpg::{
    Cylinder, Forces, Mlpg3d, Penetration, RodSetup, Surfaces, penetration,
};
use meshless_impact::{Scene, Taylor3dParams};

/// Exploration: an elastic Taylor impact at 10 m/s, printed (RINGS, ZETA;
/// WEAK = 1 the nodal form, ALPHA the smoothing, every EVERY steps, and
/// with HELD the anvil's pressure).
pub fn explore_elastic_rebound() {
    let rings: usize = std::env::var("RINGS")
        .map(|s| s.parse().unwrap())
        .unwrap_or(3);
    let zeta: f64 = std::env::var("ZETA")
        .map(|s| s.parse().unwrap())
        .unwrap_or(0.1);
    let cyl = Cylinder {
        radius: 2e-3,
        length: 20e-3,
    };
    let mut setup = RodSetup::new(cyl, rings, 10.0, 40e-6);
    setup.damping = zeta;
    if let Ok(w) = std::env::var("WEAK") {
        setup.scheme.forces = match w.as_str() {
            "0" => Forces::Sphere,
            _ => Forces::Nodal,
        };
    }
    if let Ok(a) = std::env::var("ALPHA") {
        setup.scheme.smoothing = a.parse().unwrap();
    }
    let every: usize = std::env::var("EVERY")
        .map(|s| s.parse().unwrap())
        .unwrap_or(20);
    let mut s = Mlpg3d::new(setup, elastic()).unwrap();
    let cbar = (youngs() / RHO).sqrt();
    let t0 = std::time::Instant::now();
    let mut k = 0;
    while !s.finished() {
        if let Err(e) = s.step() {
            println!("error {e}");
            break;
        }
        k += 1;
        if k % every == 0 {
            let e = s.energies();
            let r = s.rod();
            println!(
                "t {:.3} us len/L0-1 {:.3e} tail {:.3} KE {:.3e} int {:.3e} damp {:.3e} cont {:.3e} err {:.3e} rebuilds {} contact {}",
                s.time() * 1e6,
                r.rod_length / cyl.length - 1.0,
                r.tail_velocity,
                e.kinetic / e.initial,
                e.internal / e.initial,
                e.damping / e.initial,
                e.contact / e.initial,
                e.error,
                s.rebuilds(),
                s.in_contact().iter().filter(|&&c| c).count()
            );
            if std::env::var("HELD").is_ok() {
                println!("  the anvil's pressure {:.3e} Pa", -face_traction(&s));
            }
        }
    }
    let e = s.energies();
    let r = s.rod();
    println!(
        "{} nodes, {} steps, {:.2} s; release {:.4} us vs 2L/cbar {:.4} us; length/L0-1 {:.3e}; tail {:.3}; energy error {:.3e}, damping {:.3e}, contact {:.3e}",
        s.particles(),
        s.steps(),
        t0.elapsed().as_secs_f64(),
        s.last_release() * 1e6,
        2.0 * cyl.length / cbar * 1e6,
        r.rod_length / cyl.length - 1.0,
        r.tail_velocity,
        e.error,
        e.damping / e.initial,
        e.contact / e.initial
    );
}

/// Exploration: `taylor3d` at its defaults but without the velocity
/// smoothing until it stops (or the scene file `MI_SCENE_FILE` with its own
/// settings, `--set`-like overrides in `MI_SET`, "name=value,..."); prints
/// the closest pair of nodes with their reference places.
pub fn explore_taylor3d_stop() {
    let mut s = match std::env::var("MI_SCENE_FILE") {
        Ok(path) => {
            let mut scene = Scene::from_file(&path).unwrap();
            for kv in std::env::var("MI_SET").unwrap_or_default().split(',') {
                if let Some((k, v)) = kv.split_once('=') {
                    scene.set(k, v.parse().unwrap()).unwrap();
                }
            }
            let choice = scene.kind().material().unwrap();
            let material = choice
                .material(meshless_impact::materials::Prefix::None, |n| scene.get(n))
                .unwrap();
            Taylor3dParams::of(&scene).build_with(material).unwrap()
        }
        Err(_) => Taylor3dParams {
            smoothing_coefficient: 0.0,
            ..Taylor3dParams::default()
        }
        .build()
        .unwrap(),
    };
    let err = loop {
        if s.finished() {
            break None;
        }
        if let Err(e) = s.step() {
            break Some(e);
        }
    };
    println!("stop at {:.3} us: {err:?}", s.time() * 1e6);
    let (x, x0) = (s.positions(), &s.lattice().position);
    let mut best = (f64::INFINITY, 0, 0);
    for i in 0..x.len() {
        for j in 0..i {
            let d = (0..3)
                .map(|k| (x[i][k] - x[j][k]).powi(2))
                .sum::<f64>()
                .sqrt();
            if d < best.0 {
                best = (d, i, j);
            }
        }
    }
    let (d, i, j) = best;
    println!("closest {d:.3e} m between");
    for k in [i, j] {
        println!(
            "  node {k}: now {:?}, at impact {:?}, {:?}, contact {}",
            x[k],
            x0[k],
            s.lattice().surfaces[k],
            s.in_contact()[k]
        );
    }
}

/// Exploration: the phase profile of `taylor3d` run to its end
/// (`PARTICLES_RADIAL`, default 6; `PRECONDITIONER`, the
/// `conform_preconditioner`, default the scene's), or for `STEPS` steps when that is set,
/// printed with the wall time of the construction and of the loop per
/// node-step, and each phase's serial time (BENCHMARKS.md, "3-D MLPG
/// speed"); with `MI_SCENE_FILE` or `MI_SET` set, of that scene instead
/// (as `explore_energy_jump`).
pub fn explore_taylor3d_profile() {
    let across: f64 = std::env::var("PARTICLES_RADIAL")
        .map(|s| s.parse().unwrap())
        .unwrap_or(6.0);
    let built = std::time::Instant::now();
    let mut s = if std::env::var("MI_SCENE_FILE").is_ok() || std::env::var("MI_SET").is_ok() {
        build3d(&wilkins_or_env_scene())
    } else {
        let p = Taylor3dParams {
            particles_radial: across,
            conform_preconditioner: std::env::var("PRECONDITIONER")
                .map(|s| s.parse().unwrap())
                .unwrap_or(Taylor3dParams::default().conform_preconditioner),
            ..Taylor3dParams::default()
        };
        p.build().unwrap()
    };
    let construction = built.elapsed().as_secs_f64();
    let construction_table = s.profile().table();
    s.count_serial(true);
    profile_loop(construction, construction_table, &mut s);
}

/// Exploration: the phase profile of the built-in `penetration` scene with
/// the overrides `MI_SET` ("name=value,..."), run to its end or for `STEPS`
/// steps, printed as `taylor3d_profile` prints.
pub fn explore_penetration_profile() {
    let mut scene = Scene::builtin("penetration").unwrap();
    for kv in std::env::var("MI_SET").unwrap_or_default().split(',') {
        if let Some((k, v)) = kv.split_once('=') {
            scene.set(k, v.parse().unwrap()).unwrap();
        }
    }
    let built = std::time::Instant::now();
    let mut s = penetration(&scene).unwrap();
    let construction = built.elapsed().as_secs_f64();
    let construction_table = s.run().profile().table();
    s.count_serial(true);
    profile_loop(construction, construction_table, &mut s);
}

/// A 3-D run whose phases are profiled.
trait Profiled {
    fn done(&self) -> bool;
    fn step_count(&self) -> u64;
    fn step_once(&mut self);
    /// Nodes, the phase table and the serial time.
    fn report(&self) -> (usize, String, std::time::Duration);
}

/// [`Profiled`] for a run type with `finished`, `steps` and `step`, its
/// report from `$report`.
macro_rules! profiled {
    ($run:ty, |$s:ident| $report:expr) => {
        impl Profiled for $run {
            fn done(&self) -> bool {
                self.finished()
            }
            fn step_count(&self) -> u64 {
                self.steps()
            }
            fn step_once(&mut self) {
                self.step().unwrap()
            }
            fn report(&self) -> (usize, String, std::time::Duration) {
                let $s = self;
                $report
            }
        }
    };
}

profiled!(Mlpg3d, |run| {
    let p = run.profile();
    (run.particles(), p.table(), p.serial_total())
});
profiled!(Penetration, |run| run.run().report());

/// The process's processor time (user and system) from /proc/self/stat.
fn process_cpu() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = stat.rsplit_once(')').map(|p| p.1).unwrap_or("");
    let f: Vec<f64> = after
        .split_whitespace()
        .map(|x| x.parse().unwrap_or(0.0))
        .collect();
    // utime and stime are fields 14 and 15 (11 and 12 after the name).
    (f.get(11).unwrap_or(&0.0) + f.get(12).unwrap_or(&0.0)) / 100.0
}

/// Steps `s` until it finishes (or `STEPS` steps) and prints the profile
/// of the loop: wall per node-step, the phases with their serial time, and
/// the serial share of the loop's wall time.
fn profile_loop(construction: f64, construction_table: String, s: &mut impl Profiled) {
    let steps: Option<u64> = std::env::var("STEPS").ok().map(|s| s.parse().unwrap());
    let threads = rayon::current_num_threads();
    let (t0, cpu0) = (std::time::Instant::now(), process_cpu());
    let first = s.step_count();
    while !s.done() && steps.is_none_or(|n| s.step_count() < n) {
        s.step_once();
    }
    let wall = t0.elapsed().as_secs_f64();
    let cpu = process_cpu() - cpu0;
    let (particles, table, serial) = s.report();
    let taken = s.step_count() - first;
    let node_steps = particles as f64 * taken as f64;
    let serial = serial.as_secs_f64();
    println!(
        "{particles} nodes, {threads} threads; the construction {construction:.2} s wall:\n\
         {construction_table}\n{taken} steps, {wall:.2} s wall in the loop ({:.3} us per \
         node-step), {cpu:.2} s of processor time; the phases since the construction's \
         first:\n{table}serial time {serial:.3} s: {:.2} % of the loop's wall time; with the \
         parallel work (processor time less the serial) spread evenly over the {threads} \
         threads, {:.2} %",
        wall / node_steps * 1e6,
        100.0 * serial / wall,
        100.0 * serial / (serial + (cpu - serial).max(0.0) / threads as f64)
    );
}

/// Exploration: the face region of the Wilkins bar in 3-D
/// (`scenes/wilkins_copper_3d.toml`, `MI_SET` overrides as in
/// `explore_taylor3d_stop`): every 2.5 µs the nodes on the anvil (face and
/// interior), the releases since the last line, the energy error and the
/// spread, and the five fastest nodes of the face region with their
/// height, surfaces, contact, pressure and plastic strain.
pub fn explore_wilkins3d_face() {
    let scene = wilkins_or_env_scene();
    let mut s = build3d(&scene);
    let mut next = 2.5e-6;
    let mut releases = 0usize;
    let mut recontacts = 0usize;
    let mut before: Vec<bool> = s.in_contact().to_vec();
    let err = loop {
        if s.finished() {
            break None;
        }
        if let Err(e) = s.step() {
            break Some(e);
        }
        for (b, &c) in before.iter_mut().zip(s.in_contact()) {
            if *b && !c {
                releases += 1;
            } else if !*b && c {
                recontacts += 1;
            }
            *b = c;
        }
        if s.time() >= next {
            next += 2.5e-6;
            let surf = &s.lattice().surfaces;
            let c = s.in_contact();
            let face_on = (0..c.len())
                .filter(|&i| c[i] && !surf[i].interior())
                .count();
            let inner_on = (0..c.len()).filter(|&i| c[i] && surf[i].interior()).count();
            let e = s.energies();
            println!(
                "t {:.1} us: on anvil {face_on} surface + {inner_on} interior, releases {releases}, re-contacts {recontacts}, energy error {:.4}, spread {:.4}",
                s.time() * 1e6,
                e.error,
                s.mushroom_radius_spread()
            );
            releases = 0;
            recontacts = 0;
            let (x, v) = (s.positions(), s.velocities());
            let p = s.field("pressure").unwrap();
            let eps = s.field("plastic_strain").unwrap();
            let mut near: Vec<usize> = (0..x.len()).filter(|&i| x[i][2] < 2e-3).collect();
            let speed = |i: usize| (v[i][0].powi(2) + v[i][1].powi(2) + v[i][2].powi(2)).sqrt();
            near.sort_by(|&a, &b| speed(b).total_cmp(&speed(a)));
            for &i in near.iter().take(5) {
                println!(
                    "   node {i}: z {:.3} mm r {:.3} mm (at impact z {:.3}), v {:?}, {:?}, contact {}, p {:.2} GPa, eps {:.2}",
                    x[i][2] * 1e3,
                    radius_mm(x[i]),
                    s.lattice().position[i][2] * 1e3,
                    v[i].map(|a| (a * 10.0).round() / 10.0),
                    surf[i],
                    c[i],
                    p[i] * 1e-9,
                    eps[i]
                );
            }
        }
    };
    println!("stop at {:.3} us: {err:?}", s.time() * 1e6);
}

/// Exploration: the Wilkins bar in 3-D (`MI_SCENE_FILE`, `MI_SET` as in
/// `explore_taylor3d_stop`) stepped to rest, then its impact face: the
/// largest distance from the axis over the face's nodes (the observable
/// `mushroom_radius`), and over the face's outer ring (the nodes on both
/// the face and the mantle) its largest, smallest and mean distance and
/// the spread of those radii by azimuth. The ring's mean is the radius an
/// axisymmetric solver measures (its ring is one particle); the largest
/// over the face is that plus the ring's scatter.
pub fn explore_wilkins3d_ring() {
    let scene = wilkins_or_env_scene();
    let mut s = build3d(&scene);
    let t0 = std::time::Instant::now();
    while !s.finished() {
        s.step().unwrap();
    }
    let rod = s.rod();
    let lattice = s.lattice();
    let x = s.positions();
    let r = |i: usize| x[i][0].hypot(x[i][1]);
    let ring: Vec<usize> = lattice
        .sets
        .face
        .iter()
        .copied()
        .filter(|&i| lattice.surfaces[i].has(Surfaces::MANTLE))
        .collect();
    let radii: Vec<f64> = ring.iter().map(|&i| r(i)).collect();
    let mean = radii.iter().sum::<f64>() / radii.len() as f64;
    let (lo, hi) = radii
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), &v| (a.min(v), b.max(v)));
    let sd = (radii.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / radii.len() as f64).sqrt();
    let face_max = lattice.sets.face.iter().map(|&i| r(i)).fold(0.0, f64::max);
    println!(
        "{} nodes, at rest {} at {:.2} us, {:.1} s: length {:.4} mm; face radius (largest over the \
         face) {:.4} mm (check {:.4}); outer ring of {} nodes: mean {:.4} mm, sd {:.4} mm, \
         smallest {:.4} mm, largest {:.4} mm; spread {:.4}; energy error {:.4}",
        s.particles(),
        s.at_rest(),
        s.time() * 1e6,
        t0.elapsed().as_secs_f64(),
        rod.rod_length * 1e3,
        rod.mushroom_radius * 1e3,
        face_max * 1e3,
        ring.len(),
        mean * 1e3,
        sd * 1e3,
        lo * 1e3,
        hi * 1e3,
        s.mushroom_radius_spread(),
        s.energies().error
    );
}

/// Exploration: where a jump of the energy error comes from. The scene
/// file `MI_SCENE_FILE` (default the Wilkins bar in 3-D) with `MI_SET`
/// overrides is run while the energy error stays below `MI_JUMP` (default
/// 0.02); at the first step past it, the eight nodes of lowest density
/// (with their surfaces and place) and the five nodes whose stress work
/// `V Δp` and plastic strain changed most in that step are printed with
/// their place, surfaces, contact, density ratio and nearest neighbour.
pub fn explore_energy_jump() {
    let scene = wilkins_or_env_scene();
    let jump: f64 = std::env::var("MI_JUMP")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0.02);
    let mut s = build3d(&scene);
    let rho0 = scene.get("density").unwrap_or(8930.0);
    loop {
        let (p0, e0) = (
            s.field("pressure").unwrap(),
            s.field("plastic_strain").unwrap(),
        );
        let (x0, err0) = (s.positions().to_vec(), s.energies().error);
        let step = s.step();
        let err = s.energies().error;
        if step.is_err() || err > jump || s.finished() {
            println!(
                "t {:.3} us: energy error {err0:.4} -> {err:.4}, {step:?}",
                s.time() * 1e6
            );
            let (p, e, x) = (
                s.field("pressure").unwrap(),
                s.field("plastic_strain").unwrap(),
                s.positions(),
            );
            let rho = s.field("density").unwrap();
            let mut by: Vec<(f64, usize)> = (0..p.len())
                .map(|i| ((p[i] - p0[i]).abs() + 1e9 * (e[i] - e0[i]).abs(), i))
                .collect();
            by.sort_by(|a, b| b.0.total_cmp(&a.0));
            let mut low: Vec<(f64, usize)> = (0..p.len()).map(|i| (rho[i] / rho0, i)).collect();
            low.sort_by(|a, b| a.0.total_cmp(&b.0));
            for &(ratio, i) in low.iter().take(8) {
                println!(
                    "  lowest density: node {i}, rho/rho0 {ratio:.3}, {:?}, r {:.3} mm z {:.3} mm (impact z {:.3})",
                    s.lattice().surfaces[i],
                    radius_mm(x[i]),
                    x[i][2] * 1e3,
                    s.lattice().position[i][2] * 1e3,
                );
            }
            for &(_, i) in by.iter().take(5) {
                let nearest = (0..x.len())
                    .filter(|&j| j != i)
                    .map(|j| {
                        (0..3)
                            .map(|k| (x[i][k] - x[j][k]).powi(2))
                            .sum::<f64>()
                            .sqrt()
                    })
                    .fold(f64::INFINITY, f64::min);
                let moved = (0..3)
                    .map(|k| (x[i][k] - x0[i][k]).powi(2))
                    .sum::<f64>()
                    .sqrt();
                println!(
                    "  node {i}: r {:.3} mm z {:.3} mm (impact z {:.3}), {:?}, contact {}, p {:.2} -> {:.2} GPa, eps {:.3} -> {:.3}, rho/rho0 {:.3}, nearest {:.1} um, moved {:.2} um",
                    radius_mm(x[i]),
                    x[i][2] * 1e3,
                    s.lattice().position[i][2] * 1e3,
                    s.lattice().surfaces[i],
                    s.in_contact()[i],
                    p0[i] * 1e-9,
                    p[i] * 1e-9,
                    e0[i],
                    e[i],
                    rho[i] / rho0,
                    nearest * 1e6,
                    moved * 1e6
                );
            }
            break;
        }
    }
}

/// Exploration: the elastic rebound of [`elastic_rebound`] at the rings
/// listed in `RINGS` ("5,7,9"), in both forms, with the default smoothing
/// and without: when the anvil's pressure ends, when the last node lets
/// go, the front's speed, the length and the energy error (the table of
/// VALIDATION.md, "3-D MLPG mixed method: the time loop").
pub fn explore_contact_by_rings() {
    let rings = std::env::var("RINGS").unwrap_or_else(|_| "5,7,9".into());
    for rings in rings.split(',').map(|r| r.parse::<usize>().unwrap()) {
        for form in [Forces::Sphere, Forces::Nodal] {
            for alpha in [meshless_impact::internals::mlpg::SMOOTHING, 0.0] {
                let (s, passing, unloaded) = elastic_rebound_with(rings, alpha, form);
                let [front, contact, length] = rebound_errors(&s, passing);
                println!(
                    "rings {rings} ({} nodes), {form:?}, alpha {alpha}: pressure zero at {:.4} us, \
                     last release {:.4} us (contact {contact:+.3e}), front {front:+.3e}, \
                     length {length:+.3e}, energy error {:.3e}",
                    s.particles(),
                    unloaded * 1e6,
                    s.last_release() * 1e6,
                    s.energies().error
                );
            }
        }
    }
}

/// The scene of the explorations: the file `MI_SCENE_FILE` (default the
/// Wilkins bar in 3-D) with the `MI_SET` overrides ("name=value,...").
fn wilkins_or_env_scene() -> Scene {
    let path = std::env::var("MI_SCENE_FILE").unwrap_or_else(|_| {
        concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/wilkins_copper_3d.toml").into()
    });
    let mut scene = Scene::from_file(&path).unwrap();
    for kv in std::env::var("MI_SET").unwrap_or_default().split(',') {
        if let Some((k, v)) = kv.split_once('=') {
            scene.set(k, v.parse().unwrap()).unwrap();
        }
    }
    scene
}

/// The distance of `x` from the rod's axis, in mm (the explorations' prints).
fn radius_mm(x: [f64; 3]) -> f64 {
    x[0].hypot(x[1]) * 1e3
}
