use meshless_impact::{Scene, Simulation};
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let mut s = Scene::builtin(&args[1]).unwrap();
    let t_end: f64 = args[2].parse().unwrap();
    for a in &args[3..] {
        let (k, v) = a.split_once('=').unwrap();
        s.set_str(k, v).unwrap();
    }
    let mut sim = Simulation::new(s).unwrap();
    let r = sim.advance_to(t_end);
    println!(
        "{r:?} t={} energy_error={}",
        sim.time(),
        sim.observable("energy_error").unwrap()
    );
    let snap = sim.snapshot();
    let nr: usize = sim.scene().get("particles_radial").unwrap() as usize;
    let f = |n: &str| snap.field(n).unwrap().data.clone();
    let (v, st, e, rho, c) = (
        f("velocity"),
        f("stress"),
        f("plastic_strain"),
        f("density"),
        f("in_contact"),
    );
    print!("axis z: ");
    for k in 0..8 {
        print!("{:.3e} ", snap.positions[k * nr][1]);
    }
    println!();
    print!("face r: ");
    for k in 0..nr {
        print!("{:.3e} ", snap.positions[k][0]);
    }
    println!();
    let mut idx: Vec<usize> = (0..snap.positions.len()).collect();
    idx.sort_by(|&a, &b| (v[2 * b].hypot(v[2 * b + 1])).total_cmp(&v[2 * a].hypot(v[2 * a + 1])));
    for &i in idx.iter().take(15) {
        println!(
            "i={i} (ir={}, kz={}) r={:.4e} z={:.4e} v=({:.1},{:.1}) s=({:.2e},{:.2e},{:.2e},{:.2e}) eps={:.3} rho={:.1} contact={}",
            i % nr,
            i / nr,
            snap.positions[i][0],
            snap.positions[i][1],
            v[2 * i],
            v[2 * i + 1],
            st[4 * i],
            st[4 * i + 1],
            st[4 * i + 2],
            st[4 * i + 3],
            e[i],
            rho[i],
            c[i]
        );
    }
}
