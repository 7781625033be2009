//! Materials composed from parts, run in the Taylor solver: the bilinear
//! strength model against its Johnson-Cook emulation on the Wilkins copper
//! bar, and the Mie-Grüneisen equation of state.

use meshless_impact::material::bilinear::Bilinear;
use meshless_impact::material::mie_gruneisen::MieGruneisen;
use meshless_impact::material::{Eos, Material, Strength};
use meshless_impact::scene::taylor::TaylorParams;
use meshless_impact::solver::axisymmetric::TaylorSolver;
use meshless_impact::{Error, Scene, TAYLOR_OBSERVABLES};

/// The Wilkins copper bar of scenes/wilkins_copper.toml (its large-strain
/// scheme, to rest) at `particles_radial` across.
fn wilkins(particles_radial: f64) -> TaylorParams {
    let mut scene = Scene::from_file(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenes/wilkins_copper.toml"
    ))
    .unwrap();
    scene.set("particles_radial", particles_radial).unwrap();
    scene.validate().unwrap();
    assert_eq!(scene.kind().name(), "taylor");
    TaylorParams::from_values(scene.values())
}

/// Runs to the end condition; the observable `name` at the end.
fn run_to_rest(mut s: TaylorSolver) -> Result<impl Fn(&str) -> f64, Error> {
    while !s.finished() {
        s.step()?;
    }
    let values = s.observables();
    Ok(move |name: &str| {
        let k = TAYLOR_OBSERVABLES
            .iter()
            .position(|o| o.name == name)
            .unwrap();
        values[k]
    })
}

/// Issue 19's criterion: the Wilkins bar with the bilinear strength model
/// (400 MPa + 100 MPa eps_p) ends within 0.1% of its Johnson-Cook emulation
/// (n = 1, c = 0, no heating) in rod length and impact-face radius. The two
/// flow stresses are the same function; the returns differ (Johnson-Cook
/// takes the yield stress of the start of the step, the bilinear return the
/// consistent one of linear hardening).
#[test]
fn bilinear_wilkins_bar_matches_its_johnson_cook_emulation() {
    let p = wilkins(10.0);
    let jc = TaylorSolver::new(p).unwrap();
    let bilinear = Material {
        strength: Strength::Bilinear(Bilinear {
            yield_stress: 400e6,
            hardening_modulus: 100e6,
        }),
        ..TaylorSolver::material_of(&p)
    };
    let bl = TaylorSolver::with_material(p, bilinear).unwrap();
    let (a, b) = (run_to_rest(jc).unwrap(), run_to_rest(bl).unwrap());
    assert_eq!(a("at_rest"), 1.0);
    assert_eq!(b("at_rest"), 1.0);
    for name in ["rod_length", "mushroom_radius"] {
        let (x, y) = (a(name), b(name));
        let rel = (y - x).abs() / x;
        println!("{name}: Johnson-Cook {x:.6e} m, bilinear {y:.6e} m, relative {rel:.2e}");
        assert!(rel < 1e-3, "{name}: {x} vs {y}");
    }
    // Each run deformed: the face grew past its 3.2 mm radius.
    assert!(a("mushroom_radius") > 1.5 * 3.2e-3);
}

/// A compression to the singular point of the Mie-Grüneisen curve stops the
/// run with the named error, not a NaN. (A rod reaches it only by a violent
/// impact, which the spacing guard stops first: here one particle of a saved
/// state is given 1.5 times the density, past the limit mu = 1/9 of s = 10.)
#[test]
fn mie_gruneisen_compression_limit_is_a_named_error() {
    let p = wilkins(5.0);
    let mg = Material {
        eos: Eos::MieGruneisen(MieGruneisen {
            density: p.density,
            c0: 3940.0,
            s: 10.0,
            gruneisen: 2.0,
        }),
        ..TaylorSolver::material_of(&p)
    };
    let mut s = TaylorSolver::with_material(p, mg).unwrap();
    s.step().unwrap();
    let mut state = serde_json::to_value(&s).unwrap();
    let k = 2 * 5 + 2;
    state["rho"][k] = (1.5 * p.density).into();
    let mut s: TaylorSolver = serde_json::from_value(state).unwrap();
    let err = s.step().unwrap_err();
    assert_eq!(err.name(), "CompressionLimit", "{err}");
    assert!(err.to_string().contains("Mie-Grüneisen"), "{err}");
    match err {
        Error::CompressionLimit {
            particle,
            compression,
            limit,
            ..
        } => {
            assert_eq!(particle, k);
            assert!(
                compression >= limit && limit == 1.0 / 9.0,
                "{compression} {limit}"
            );
        }
        other => panic!("{other}"),
    }
}

/// A material whose equation of state has another reference density than
/// the rod, and Mie-Grüneisen constants out of range, are refused.
#[test]
fn inconsistent_materials_are_refused() {
    let p = wilkins(5.0);
    let mg = |c0: f64, density: f64| Material {
        eos: Eos::MieGruneisen(MieGruneisen {
            density,
            c0,
            s: 1.5,
            gruneisen: 2.0,
        }),
        ..TaylorSolver::material_of(&p)
    };
    let err = TaylorSolver::with_material(p, mg(3940.0, 8000.0))
        .err()
        .unwrap();
    assert_eq!(err.name(), "Inconsistent", "{err}");
    let err = TaylorSolver::with_material(p, mg(-1.0, p.density))
        .err()
        .unwrap();
    assert!(
        matches!(&err, Error::OutOfRange { name, .. } if name == "eos_c0"),
        "{err}"
    );
}
