//! The local weak form with the Heaviside test function, eq. (10): over the
//! test sphere `Ω_s` of node `i`, the surface tractions balance the
//! sphere's inertia,
//!
//! `ρ V_s a_i = F_i = ∫_{L_s} σ·n dS`,
//!
//! with `σ` interpolated from the nodal stresses by the MLS shape functions
//! (the mixed method: no derivative of a shape function is taken here). As
//! `F_i` is linear in the nodal stresses, it is assembled as a sparse
//! operator, `F_i = Σ_J σ_J · B_iJ` with `B_iJ = ∫ φ_J n dS`, which the
//! solver rebuilds when the nodes have moved.
//!
//! Stresses are stored as 6 components `[xx, yy, zz, xy, yz, zx]`.

use crate::Result;
use crate::approx::mls::{Covers, PointShapes, ShapeRow, Supports, candidates_first, distance};
use crate::approx::sphere::{SphereRule, TestSphere};
use crate::isa::Isa;
use crate::neighbours::dist2;
use rayon::prelude::*;

/// The index in `[xx, yy, zz, xy, yz, zx]` of component `(a, b)`.
pub const VOIGT: [[usize; 3]; 3] = [[0, 3, 5], [3, 1, 4], [5, 4, 2]];

/// One row of the operator: the nodes and their `B_iJ`.
type Row = (Vec<usize>, Vec<[f64; 3]>);

/// The traction operator of every node's test sphere, in compressed rows.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TractionOperator {
    /// Row `i` is `offsets[i]..offsets[i + 1]`.
    pub offsets: Vec<usize>,
    /// Nodes `J` whose shape functions reach the sphere of `i`, ascending.
    pub nodes: Vec<usize>,
    /// `B_iJ = ∫_{L_s} φ_J n dS` (m²).
    pub b: Vec<[f64; 3]>,
    /// Volume of each (cut) test sphere `V_s` (m³).
    pub volume: Vec<f64>,
}

impl TractionOperator {
    /// Assembles the operator at the nodes `points` with their `supports`
    /// and test `spheres`, using the rule `whole` on whole spheres and the
    /// octahedral rule `cut` on cut ones. In parallel over nodes, the same
    /// bits for any number of threads; the first failing node (in index
    /// order) names the error.
    ///
    /// The same arithmetic as [`TractionOperator::build_plain`] in the same
    /// order, so the same bits, with less work around it: each node's
    /// candidates are first narrowed to those whose support can reach its
    /// sphere (`|x_i − x_J| ≤ r0_i + r_J`, with a margin), gathered into
    /// arrays of coordinates; at each quadrature point a squared distance
    /// (no root, no division) picks the few that may cover it, and only
    /// those get the exact test `|x − x_J| / r_J < 1` and the MLS sums
    /// ([`PointShapes`]), in the compiled copy `isa` (every copy gives the
    /// same bits).
    pub fn build(
        isa: Isa,
        points: &[[f64; 3]],
        supports: &Supports,
        spheres: &[TestSphere],
        whole: &SphereRule,
        cut: &SphereRule,
    ) -> Result<Self> {
        let reach = spheres.iter().map(|s| s.radius).fold(0.0, f64::max);
        // Each node's candidates (its row of `candidates_first`) are found
        // while the node is handled: no list of every node's candidates.
        if points.is_empty() {
            return Self::assemble(Vec::new(), spheres);
        }
        let radius = &supports.radius;
        // The candidates are those of one grid of cells `reach + max r_J`
        // (the plain twin's), found by class of radius.
        let within = reach + supports.max_radius();
        let within2 = within * within;
        let covers = Covers::new(points, radius, &supports.group, reach);
        let rows: Vec<Result<Row>> = (0..spheres.len())
            .into_par_iter()
            .map_init(
                || (PointShapes::default(), Vec::new()),
                |(ps, cand), i| {
                    let xi = points[i];
                    let r0 = spheres[i].radius;
                    // A margin far above round-off: the narrowing only has
                    // to keep every node that can cover a point.
                    let near = |j: usize| {
                        dist2(&xi, &points[j]) <= within2
                            && distance(&xi, &points[j]) <= (r0 + radius[j]) * (1.0 + 1e-9)
                    };
                    covers.sorted_into(&xi, i, near, cand);
                    ps.gather(cand.iter().copied(), points, radius);
                    let mut failed = None;
                    spheres[i].for_each_point(xi, whole, cut, |x, n, w| {
                        if failed.is_some() {
                            return;
                        }
                        if let Err(e) = ps.evaluate(isa, x, i) {
                            failed = Some(e);
                            return;
                        }
                        ps.accumulate(n, w);
                    });
                    if let Some(e) = failed {
                        return Err(e);
                    }
                    Ok(ps.row())
                },
            )
            .collect();
        Self::assemble(rows, spheres)
    }

    /// The plain twin of [`TractionOperator::build`]: one full MLS
    /// evaluation ([`ShapeRow::evaluate`]) over every candidate at every
    /// quadrature point. Kept as the reference the fast build is pinned to
    /// (the same bits, `tests::the_fast_build_gives_the_plain_bits`).
    pub fn build_plain(
        points: &[[f64; 3]],
        supports: &Supports,
        spheres: &[TestSphere],
        whole: &SphereRule,
        cut: &SphereRule,
    ) -> Result<Self> {
        let reach = spheres.iter().map(|s| s.radius).fold(0.0, f64::max);
        let list = candidates_first(points, spheres.len(), supports, reach);
        let rows: Vec<Result<Row>> = (0..spheres.len())
            .into_par_iter()
            .map_init(
                || (ShapeRow::default(), Vec::new(), Vec::new()),
                |(row, acc, touched), i| {
                    let cand = list.of(i);
                    acc.clear();
                    acc.resize(cand.len(), [0.0; 3]);
                    touched.clear();
                    touched.resize(cand.len(), false);
                    let mut failed = None;
                    spheres[i].for_each_point(points[i], whole, cut, |x, n, w| {
                        if failed.is_some() {
                            return;
                        }
                        if let Err(e) = row.evaluate(x, cand, points, &supports.radius, false, i) {
                            failed = Some(e);
                            return;
                        }
                        for (&s, &phi) in row.slot.iter().zip(&row.phi) {
                            touched[s] = true;
                            for d in 0..3 {
                                acc[s][d] += w * phi * n[d];
                            }
                        }
                    });
                    if let Some(e) = failed {
                        return Err(e);
                    }
                    let keep = || (0..cand.len()).filter(|&s| touched[s]);
                    Ok((
                        keep().map(|s| cand[s]).collect(),
                        keep().map(|s| acc[s]).collect(),
                    ))
                },
            )
            .collect();
        Self::assemble(rows, spheres)
    }

    /// The operator of the rows of every node, in node order (the first
    /// failed row's error).
    fn assemble(rows: Vec<Result<Row>>, spheres: &[TestSphere]) -> Result<Self> {
        // The rows' entries counted first, so that the operator is
        // allocated once at its size (no doubling beside the rows).
        let entries: usize = rows.iter().flatten().map(|(nodes, _)| nodes.len()).sum();
        let mut op = TractionOperator {
            offsets: Vec::with_capacity(rows.len() + 1),
            nodes: Vec::with_capacity(entries),
            b: Vec::with_capacity(entries),
            volume: spheres.iter().map(TestSphere::volume).collect(),
        };
        op.offsets.push(0);
        for row in rows {
            let (nodes, b) = row?;
            op.nodes.extend_from_slice(&nodes);
            op.b.extend_from_slice(&b);
            op.offsets.push(op.nodes.len());
        }
        Ok(op)
    }

    /// `F_i = Σ_J σ_J · B_iJ`, i.e. `F_i[b] = Σ_J Σ_a σ_J[a][b] B_iJ[a]`,
    /// for every node, into `out`, in parallel.
    pub fn apply(&self, stress: &[[f64; 6]], out: &mut [[f64; 3]]) {
        out.par_iter_mut().enumerate().for_each(|(i, f)| {
            *f = [0.0; 3];
            for q in self.offsets[i]..self.offsets[i + 1] {
                let (s, b) = (&stress[self.nodes[q]], self.b[q]);
                for c in 0..3 {
                    f[c] += s[VOIGT[0][c]] * b[0] + s[VOIGT[1][c]] * b[1] + s[VOIGT[2][c]] * b[2];
                }
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::approx::mls::tests::jittered_cube;
    use crate::approx::mls::{SupportParams, distance};
    use crate::approx::sphere::{ALPHA, BOUNDARY_RULE, DEFAULT_RULE, test_radii};

    /// The jittered cube, its supports, and whole test spheres by eq. (12)
    /// for the nodes at least one spacing inside (the others get none:
    /// radius 0 is skipped by the caller).
    fn setup(n: usize, h: f64) -> (Vec<[f64; 3]>, Supports, Vec<TestSphere>, Vec<usize>) {
        let pts = jittered_cube(n, h, 0.3, 5);
        let sup = Supports::compute(&pts, SupportParams::default()).unwrap();
        let nearest: Vec<f64> = (0..pts.len())
            .map(|i| distance(&pts[i], &pts[sup.named.of(i)[0]]))
            .collect();
        let lo = 0.7 * h;
        let hi = (n as f64 - 1.7) * h;
        let inner: Vec<usize> = (0..pts.len())
            .filter(|&i| pts[i].iter().all(|&x| x > lo && x < hi))
            .collect();
        // Distance to the box [0, (n−1)h]³ as the "boundary".
        let bdist: Vec<f64> = pts
            .iter()
            .map(|p| {
                p.iter()
                    .map(|&x| x.min((n as f64 - 1.0) * h - x))
                    .fold(f64::INFINITY, f64::min)
                    .max(1e-30)
            })
            .collect();
        let radii = test_radii(&nearest, &bdist, ALPHA);
        let spheres = radii.iter().map(|&r| TestSphere::whole(r)).collect();
        (pts, sup, spheres, inner)
    }

    /// The operator with the solver's rules.
    fn operator(pts: &[[f64; 3]], sup: &Supports, spheres: &[TestSphere]) -> TractionOperator {
        let (whole, cut) = (SphereRule::of(DEFAULT_RULE), SphereRule::of(BOUNDARY_RULE));
        TractionOperator::build(Isa::best(), pts, sup, spheres, &whole, &cut).unwrap()
    }

    #[test]
    fn constant_and_linear_stress_give_the_divergence_exactly() {
        let h = 1e-3;
        let (pts, sup, spheres, inner) = setup(7, h);
        let op = operator(&pts, &sup, &spheres);
        // σ = σ0 + G x: each component an affine function of x.
        let s0 = [3e8, -1e8, 2e8, 5e7, -4e7, 6e7];
        let g = [
            [2e11, -3e11, 1e11],
            [4e11, 1e11, -2e11],
            [-1e11, 5e11, 3e11],
        ];
        let lin = |p: &[f64; 3], c: usize| {
            let k = [(0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (2, 0)][c];
            s0[c] + g[k.0][0] * p[0] + g[k.1][1] * p[1] + g[(k.0 + k.1) % 3][2] * p[2]
        };
        let constant: Vec<[f64; 6]> = pts.iter().map(|_| s0).collect();
        let linear: Vec<[f64; 6]> = pts
            .iter()
            .map(|p| std::array::from_fn(|c| lin(p, c)))
            .collect();
        let mut f = vec![[0.0; 3]; pts.len()];
        op.apply(&constant, &mut f);
        let scale = 3e8 * 4.0 * std::f64::consts::PI * (ALPHA * h).powi(2);
        let worst = inner
            .iter()
            .map(|&i| f[i].iter().map(|x| x.abs()).fold(0.0, f64::max))
            .fold(0.0, f64::max);
        assert!(worst < 1e-14 * scale, "constant: {worst:e} of {scale:e}");
        op.apply(&linear, &mut f);
        // div σ_b = Σ_a ∂σ_ab/∂x_a.
        let div: [f64; 3] =
            std::array::from_fn(|b| (0..3).map(|a| slope(&lin, VOIGT[a][b], a)).sum());
        let dn = div.iter().map(|x| x.abs()).fold(0.0, f64::max);
        let mut worst = 0.0f64;
        for &i in &inner {
            for b in 0..3 {
                worst = worst.max((f[i][b] / op.volume[i] - div[b]).abs() / dn);
            }
        }
        assert!(worst < 1e-12, "linear: {worst:e}");
    }

    #[test]
    fn one_thread_and_two_give_the_same_bits() {
        let (pts, sup, spheres, _) = setup(6, 1.0);
        let build = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                let shapes = crate::approx::mls::NodalShapes::build(&pts, &sup).unwrap();
                let op = operator(&pts, &sup, &spheres);
                let again = Supports::compute(&pts, SupportParams::default()).unwrap();
                (shapes, op, again)
            })
        };
        let (a, b) = (build(1), build(2));
        assert!(a == b, "thread count changed the result");
    }

    #[test]
    fn the_fast_build_gives_the_plain_bits() {
        let (pts, sup, mut spheres, _) = setup(6, 1.0);
        // Cut spheres on the box faces, in turned frames, as the solver's
        // boundary nodes have them.
        let hi = 5.0;
        for (i, p) in pts.iter().enumerate() {
            let mut cut = [0i8; 3];
            for a in 0..3 {
                if p[a] < 0.3 {
                    cut[a] = -1;
                } else if p[a] > hi - 0.3 {
                    cut[a] = 1;
                }
            }
            if cut != [0; 3] {
                let (c, s) = (0.8f64, 0.6f64);
                spheres[i] = TestSphere {
                    radius: spheres[i].radius.max(0.3),
                    frame: [[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]],
                    cut,
                };
            }
        }
        let (whole, cut) = (SphereRule::of(DEFAULT_RULE), SphereRule::of(BOUNDARY_RULE));
        let plain = TractionOperator::build_plain(&pts, &sup, &spheres, &whole, &cut).unwrap();
        for isa in Isa::available() {
            let fast = TractionOperator::build(isa, &pts, &sup, &spheres, &whole, &cut).unwrap();
            assert!(
                fast == plain,
                "the {} copy changed the operator",
                isa.name()
            );
        }
        // The same error at the same node: a sphere too far out.
        spheres[3].radius = 50.0;
        let e =
            TractionOperator::build(Isa::best(), &pts, &sup, &spheres, &whole, &cut).unwrap_err();
        let p = TractionOperator::build_plain(&pts, &sup, &spheres, &whole, &cut).unwrap_err();
        assert_eq!(format!("{e:?}"), format!("{p:?}"));
    }

    /// ∂σ_c/∂x_a of a linear field, by a difference (exact for linear).
    fn slope(f: &impl Fn(&[f64; 3], usize) -> f64, c: usize, a: usize) -> f64 {
        let mut e = [0.0; 3];
        e[a] = 1.0;
        f(&e, c) - f(&[0.0; 3], c)
    }
}
