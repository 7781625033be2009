use meshless_impact::{Scene, Simulation};
fn main() {
    let mut s = Scene::builtin("noh").unwrap();
    for a in std::env::args().skip(1) {
        let (k, v) = a.split_once('=').unwrap();
        s.set_str(k, v).unwrap();
    }
    let mut sim = Simulation::new(s).unwrap();
    let r = sim.run();
    println!("{r:?} t={}", sim.time());
    for (sp, v) in sim.observable_specs().iter().zip(sim.observables()) {
        print!("{}={v:.4} ", sp.name);
    }
    println!();
    let snap = sim.snapshot();
    let f = |n: &str| snap.field(n).unwrap().data.clone();
    let (rho, v, p, e) = (
        f("density"),
        f("velocity"),
        f("pressure"),
        f("specific_energy"),
    );
    for i in (0..rho.len()).step_by(8).take(60) {
        println!(
            "r={:.4} rho={:.3} v={:.3} p={:.3} e={:.3}",
            snap.positions[i][0], rho[i], v[i], p[i], e[i]
        );
    }
}
