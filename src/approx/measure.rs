//! The measurements behind the choices of this module, each asserting
//! that the choice is still the one its table makes (print the tables with
//! `cargo test --profile ci --lib approx::measure -- --nocapture`), and the
//! convergence tests of the nodal velocity gradients.

use crate::approx::mls::tests::jittered_cube;
use crate::approx::mls::{NodalShapes, SupportParams, Supports, distance};
use crate::approx::sphere::{Polyhedron, SphereRule, TestSphere, TriangleRule};
use crate::approx::weak::TractionOperator;

/// A quadratic velocity field and its gradient `L[a][b] = ∂v_a/∂x_b`.
fn quadratic(p: &[f64; 3]) -> ([f64; 3], [[f64; 3]; 3]) {
    let [x, y, z] = *p;
    (
        [x * x + y * z, 2.0 * y * y - x * z, z * z + 3.0 * x * y],
        [
            [2.0 * x, z, y],
            [-z, 4.0 * y, -x],
            [3.0 * y, 3.0 * x, 2.0 * z],
        ],
    )
}

/// Root-mean-square error of the collocated velocity gradient (eq. 4) of the
/// quadratic field over the nodes in [0.3, 0.7]³, relative to the largest
/// gradient entry there (about 2.8), on the unit cube with `n` nodes per
/// side (jitter as a fraction of the spacing), and the mean covering count.
fn gradient_error(n: usize, jitter: f64, params: SupportParams) -> (f64, f64) {
    let h = 1.0 / (n - 1) as f64;
    let pts = jittered_cube(n, h, jitter, 17);
    let sup = Supports::compute(&pts, params).unwrap();
    let shapes = NodalShapes::build(&pts, &sup).unwrap();
    let vel: Vec<[f64; 3]> = pts.iter().map(|p| quadratic(p).0).collect();
    let mut l = vec![[[0.0; 3]; 3]; pts.len()];
    shapes.velocity_gradients(&vel, &mut l);
    let (mut sum, mut count) = (0.0f64, 0usize);
    for (i, p) in pts.iter().enumerate() {
        if p.iter().all(|&x| (0.3..=0.7).contains(&x)) {
            let exact = quadratic(p).1;
            for a in 0..3 {
                for b in 0..3 {
                    sum += (l[i][a][b] - exact[a][b]).powi(2);
                    count += 1;
                }
            }
        }
    }
    let covering = shapes.nodes.len() as f64 / pts.len() as f64;
    ((sum / count as f64).sqrt() / 2.8, covering)
}

#[test]
fn linear_velocity_gives_the_exact_gradient() {
    let pts = jittered_cube(7, 2e-3, 0.3, 23);
    let sup = Supports::compute(&pts, SupportParams::default()).unwrap();
    let shapes = NodalShapes::build(&pts, &sup).unwrap();
    let g = [[1e3, -2e3, 5e2], [3e3, 4e2, -1e3], [-6e2, 2e3, 1.5e3]];
    let vel: Vec<[f64; 3]> = pts
        .iter()
        .map(|p| std::array::from_fn(|a| 7.0 + (0..3).map(|b| g[a][b] * p[b]).sum::<f64>()))
        .collect();
    let mut l = vec![[[0.0; 3]; 3]; pts.len()];
    shapes.velocity_gradients(&vel, &mut l);
    // Every node, the boundary ones too.
    let worst = l
        .iter()
        .flat_map(|li| (0..9).map(move |q| (li[q / 3][q % 3] - g[q / 3][q % 3]).abs()))
        .fold(0.0, f64::max);
    assert!(worst < 1e-12 * 3e3, "{worst:e}");
}

/// Measured order of the gradient error with refinement (h = 1/8, 1/16,
/// 1/32; RMS over the nodes in [0.3, 0.7]³). On the regular lattice the
/// symmetric stencil makes the gradient of a quadratic field exact, to
/// round-off, once the region is clear of the boundary (h ≤ 1/16). On a
/// lattice jittered by 0.3 h the error is first order, as a linear basis
/// gives on irregular nodes (the quadratic remainder's derivative is
/// `O(h)` times the stencil's asymmetry): measured RMS errors 1.05e-2,
/// 4.4e-3, 2.3e-3 (relative to the largest gradient; k = 10, factor 1.5),
/// orders 1.24 and 0.96 (with k = 14: orders 1.45 and 0.90; with a jitter
/// of 0.05 h, 2.6 pre-asymptotic and then 0.95). The bar asserted is
/// order > 0.85 and an error below 2.5e-3 at h = 1/32.
#[test]
fn quadratic_velocity_gradient_converges() {
    let p = SupportParams::default();
    let errors = |jitter: f64| -> Vec<f64> {
        [9, 17, 33]
            .iter()
            .map(|&n| gradient_error(n, jitter, p).0)
            .collect()
    };
    let regular = errors(0.0);
    assert!(regular[1] < 1e-14 && regular[2] < 1e-14, "{regular:?}");
    let e = errors(0.3);
    let order = (e[1] / e[2]).log2();
    assert!(order > 0.85 && e[2] < 2.5e-3, "{e:?} order {order}");
}

/// The table behind [`SupportParams::default`] (`cargo test --lib
/// the_default_supports -- --nocapture` prints it): the gradient error of the
/// quadratic field at h = 1/8 and 1/16 on the lattice jittered by 0.3 h,
/// its order, and the mean number of covering nodes (the cost), for k
/// named neighbours and the support factor. The default (k = 10, factor
/// 1.5) is the choice the table was made for: of every choice that covers
/// no more nodes (37.1), its error at h = 1/16 is the smallest (measured
/// 4.43e-3; the next 5.39e-3 at k = 14, factor 1.25), and it converges at
/// the first order that a linear basis gives on irregular nodes (measured
/// 1.24; asserted above 0.85, as [`quadratic_velocity_gradient_converges`]).
#[test]
fn the_default_supports_are_the_tables_choice() {
    let default = SupportParams::default();
    let mut rows = Vec::new();
    println!("k factor | err(h=1/8) err(h=1/16) order | covering nodes");
    for k in [6, 10, 14, 18, 26] {
        for factor in [1.1, 1.25, 1.5, 2.0] {
            let p = SupportParams {
                neighbours: k,
                factor,
            };
            let a = gradient_error(9, 0.3, p);
            let b = gradient_error(17, 0.3, p);
            let order = (a.0 / b.0).log2();
            println!(
                "{k:2} {factor:4} | {:.2e} {:.2e} {order:.2} | {:.1}",
                a.0, b.0, b.1
            );
            rows.push((p, b.0, order, b.1));
        }
    }
    let &(_, error, order, covering) = rows.iter().find(|r| r.0 == default).unwrap();
    assert!(order > 0.85, "order {order}");
    for (p, e, _, c) in &rows {
        if *c <= covering && *p != default {
            assert!(
                error < *e,
                "{p:?} covers {c:.1} nodes with error {e:.2e}, the default {covering:.1} with {error:.2e}"
            );
        }
    }
}

/// The table behind [`crate::approx::sphere::DEFAULT_RULE`] and
/// [`crate::approx::sphere::BOUNDARY_RULE`] (the module docs of
/// [`crate::approx::sphere`]; `cargo test --lib sphere_rules -- --nocapture`
/// prints it), measured as the docs say, with k = 14 named neighbours
/// (the supports' default when the rules were chosen): the default rule is
/// the cheapest whose operator error is below 1e-3 (measured 7.05e-4 with
/// 60 points; 1.29e-3 with 20), and the boundary rule the cheapest
/// octahedron rule, which cuts into halves and quarters, below it
/// (8.63e-4 with 216 points; 1.39e-3 with 96). At today's default k = 10
/// the same rule's operator error is 1.9e-3 (printed after the table): the
/// rule was not chosen again when the supports shrank (VALIDATION.md
/// notes it; only `weak_form = 0`, the paper's scheme, uses test spheres,
/// and changing the rule would move its seed-method bits).
#[test]
fn sphere_rules_are_the_tables_choice() {
    let rows = sphere_rule_table(SupportParams {
        neighbours: 14,
        factor: 1.5,
    });
    let meets = |r: &(Polyhedron, usize, TriangleRule, usize, f64, f64)| r.5 < 1e-3;
    let cheapest = |octahedron: bool| {
        rows.iter()
            .filter(|r| !octahedron || r.0 == Polyhedron::Octahedron)
            .filter(|r| meets(r))
            .min_by_key(|r| r.3)
            .map(|r| (r.0, r.1, r.2))
    };
    assert_eq!(cheapest(false), Some(crate::approx::sphere::DEFAULT_RULE));
    assert_eq!(cheapest(true), Some(crate::approx::sphere::BOUNDARY_RULE));
    let now = sphere_rule_table(SupportParams::default());
    let (a, f, t) = crate::approx::sphere::DEFAULT_RULE;
    let r = now.iter().find(|r| (r.0, r.1, r.2) == (a, f, t)).unwrap();
    println!(
        "with the supports' default (k = {}): the default rule's operator error {:.2e}",
        SupportParams::default().neighbours,
        r.5
    );
}

/// The rows of the sphere-rule table with supports `params`: rule,
/// points, field error, operator error.
fn sphere_rule_table(
    params: SupportParams,
) -> Vec<(Polyhedron, usize, TriangleRule, usize, f64, f64)> {
    let mut rows = Vec::new();
    let h = 1.0;
    let pts = jittered_cube(7, h, 0.3, 5);
    let sup = Supports::compute(&pts, params).unwrap();
    let kappa = [0.2, 0.4, 0.4]; // |κ| h = 0.6
    let f = |p: &[f64; 3]| (kappa[0] * p[0] + kappa[1] * p[1] + kappa[2] * p[2]).exp();
    let stress: Vec<[f64; 6]> = pts
        .iter()
        .map(|p| [f(p), f(p), f(p), 0.0, 0.0, 0.0])
        .collect();
    let inner: Vec<usize> = (0..pts.len())
        .filter(|&i| pts[i].iter().all(|&x| x > 0.7 && x < 5.3))
        .collect();
    let spheres: Vec<TestSphere> = (0..pts.len())
        .map(|i| TestSphere::whole(0.5 * distance(&pts[i], &pts[sup.named.of(i)[0]])))
        .collect();
    let cut = SphereRule::new(Polyhedron::Octahedron, 1, TriangleRule::One);
    let run = |rule: &SphereRule| {
        let op = TractionOperator::build(crate::isa::Isa::best(), &pts, &sup, &spheres, rule, &cut)
            .unwrap();
        let mut out = vec![[0.0; 3]; pts.len()];
        op.apply(&stress, &mut out);
        let f = inner
            .iter()
            .map(|&i| out[i].map(|x| x / op.volume[i]))
            .collect::<Vec<_>>();
        (f, op)
    };
    let (reference, refop) = run(&SphereRule::new(
        Polyhedron::Icosahedron,
        8,
        TriangleRule::Seven,
    ));
    // Largest |B_iJ − B_ref_iJ| over the largest |B_ref_iJ| of the row.
    let operator_error = |op: &TractionOperator| {
        let mut worst = 0.0f64;
        for &i in &inner {
            let (r0, r1) = (refop.offsets[i], refop.offsets[i + 1]);
            let big = refop.b[r0..r1]
                .iter()
                .flatten()
                .map(|x| x.abs())
                .fold(0.0, f64::max);
            for q in r0..r1 {
                let j = refop.nodes[q];
                let got = (op.offsets[i]..op.offsets[i + 1])
                    .find(|&p| op.nodes[p] == j)
                    .map_or([0.0; 3], |p| op.b[p]);
                for d in 0..3 {
                    worst = worst.max((got[d] - refop.b[q][d]).abs() / big);
                }
            }
        }
        worst
    };
    let knorm = (kappa.iter().map(|k| k * k).sum::<f64>()).sqrt();
    // The interpolation error too: F/V against the exact ∫ ∇f dV / V.
    let interp = inner
        .iter()
        .zip(&reference)
        .map(|(&i, r)| {
            let rr = 0.5 * distance(&pts[i], &pts[sup.named.of(i)[0]]);
            let kr = knorm * rr;
            let mean = 3.0 * (kr * kr.cosh() - kr.sinh()) / kr.powi(3);
            (0..3)
                .map(|d| (r[d] - kappa[d] * f(&pts[i]) * mean).abs() / (knorm * f(&pts[i])))
                .fold(0.0, f64::max)
        })
        .fold(0.0, f64::max);
    println!("interpolation error of the reference: {interp:.2e}");
    for (base, fr, tri) in [
        (Polyhedron::Icosahedron, 1, TriangleRule::One),
        (Polyhedron::Icosahedron, 1, TriangleRule::Three),
        (Polyhedron::Icosahedron, 2, TriangleRule::One),
        (Polyhedron::Icosahedron, 1, TriangleRule::Six),
        (Polyhedron::Icosahedron, 2, TriangleRule::Three),
        (Polyhedron::Icosahedron, 3, TriangleRule::Three),
        (Polyhedron::Icosahedron, 4, TriangleRule::Three),
        (Polyhedron::Octahedron, 2, TriangleRule::Three),
        (Polyhedron::Octahedron, 3, TriangleRule::Three),
        (Polyhedron::Octahedron, 4, TriangleRule::Three),
    ] {
        let rule = SphereRule::new(base, fr, tri);
        let (got, op) = run(&rule);
        let err = inner
            .iter()
            .zip(got.iter().zip(&reference))
            .map(|(&i, (g, r))| {
                (0..3)
                    .map(|d| (g[d] - r[d]).abs() / (knorm * f(&pts[i])))
                    .fold(0.0, f64::max)
            })
            .fold(0.0, f64::max);
        let operator = operator_error(&op);
        println!(
            "{base:?} f={fr} {tri:?}: {} triangles, {} points, error {err:.2e}, operator {operator:.2e}",
            rule.len() / rule.per_triangle,
            rule.len(),
        );
        rows.push((base, fr, tri, rule.len(), err, operator));
    }
    rows
}
