//! The MLPG foundations working together: a free 3-D elastic bar (linear
//! elastic, small strain, no plasticity) on the ring lattice, integrated by
//! central differences (Newmark β = 0, γ = 1/2), against the period of its
//! fundamental longitudinal mode; and the highest frequency of its discrete
//! operator behind the stable time step.

use meshless_impact::internals::mlpg::{
    ALPHA, BOUNDARY_RULE, Cylinder, DEFAULT_RULE, NodalOperator, NodalShapes, NodeLattice,
    OMEGA_FACTOR, OMEGA_FACTOR_NODAL, SphereRule, SupportParams, Supports, TestSphere,
    TractionOperator, distance, largest_eigenvalue, stable_step,
};
use std::f64::consts::PI;

/// Steel-like constants (Pa, kg/m³).
const E: f64 = 200e9;
const NU: f64 = 0.28;
const RHO: f64 = 8000.0;

/// Lamé constants.
fn lame() -> (f64, f64) {
    let mu = E / (2.0 * (1.0 + NU));
    let lambda = E * NU / ((1.0 + NU) * (1.0 - 2.0 * NU));
    (lambda, mu)
}

/// Hooke's law for this test only: the stress rate of a velocity gradient,
/// `σ̇ = λ tr(D) I + 2 μ D`, in `[xx, yy, zz, xy, yz, zx]`.
fn hooke_rate(l: &[[f64; 3]; 3]) -> [f64; 6] {
    let (lambda, mu) = lame();
    let d = |a: usize, b: usize| 0.5 * (l[a][b] + l[b][a]);
    let tr = d(0, 0) + d(1, 1) + d(2, 2);
    [
        lambda * tr + 2.0 * mu * d(0, 0),
        lambda * tr + 2.0 * mu * d(1, 1),
        lambda * tr + 2.0 * mu * d(2, 2),
        2.0 * mu * d(0, 1),
        2.0 * mu * d(1, 2),
        2.0 * mu * d(2, 0),
    ]
}

/// A bar of radius 2 mm and length 20 mm on the ring lattice, with its
/// shapes, test spheres and traction operator.
struct Bar {
    lattice: NodeLattice,
    shapes: NodalShapes,
    op: TractionOperator,
    spheres: Vec<TestSphere>,
    d_min: f64,
    /// Whether the forces see the boundary nodes' stresses made
    /// traction-free (`σ ← P σ P`, `P = I − ν⊗ν` for each cut normal ν).
    project: bool,
    /// α of the bi-Laplacian velocity smoothing `v ← v − α L(L v)`,
    /// `L v = Σ_J φ_J(x_i) v_J − v_i`, applied after each velocity update.
    smoothing: f64,
}

impl Bar {
    fn new(rings: usize, alpha: f64) -> Self {
        let cyl = Cylinder {
            radius: 2e-3,
            length: 20e-3,
        };
        let lattice = NodeLattice::cylinder(cyl, rings);
        let pts = &lattice.position;
        let sup = Supports::compute(pts, SupportParams::default()).unwrap();
        let shapes = NodalShapes::build(pts, &sup).unwrap();
        let nearest: Vec<f64> = (0..pts.len())
            .map(|i| distance(&pts[i], &pts[sup.named.of(i)[0]]))
            .collect();
        let bdist: Vec<f64> = pts.iter().map(|p| cyl.distance_to_surface(p)).collect();
        let radii = meshless_impact::internals::mlpg::test_radii(&nearest, &bdist, alpha);
        let spheres: Vec<TestSphere> = (0..pts.len())
            .map(|i| {
                let (frame, cut) = lattice.boundary_frame(i);
                TestSphere {
                    radius: radii[i],
                    frame,
                    cut,
                }
            })
            .collect();
        let op = TractionOperator::build(
            meshless_impact::Isa::best(),
            pts,
            &sup,
            &spheres,
            &SphereRule::of(DEFAULT_RULE),
            &SphereRule::of(BOUNDARY_RULE),
        )
        .unwrap();
        let d_min = nearest.iter().copied().fold(f64::INFINITY, f64::min);
        Bar {
            lattice,
            shapes,
            op,
            spheres,
            d_min,
            project: false,
            smoothing: 0.0,
        }
    }

    fn len(&self) -> usize {
        self.lattice.len()
    }

    /// `L v = Σ_J φ_J(x_i) v_J − v_i` at every node.
    fn mls_laplacian(&self, v: &[[f64; 3]]) -> Vec<[f64; 3]> {
        (0..self.len())
            .map(|i| {
                let mut m = [0.0; 3];
                for q in self.shapes.row(i) {
                    for d in 0..3 {
                        m[d] += self.shapes.phi[q] * v[self.shapes.nodes[q]][d];
                    }
                }
                std::array::from_fn(|d| m[d] - v[i][d])
            })
            .collect()
    }

    /// Accelerations of the stresses: `a_i = F_i / (ρ V_s)`.
    fn accelerations(&self, stress: &[[f64; 6]], force: &mut [[f64; 3]]) {
        if self.project {
            let projected: Vec<[f64; 6]> = stress
                .iter()
                .zip(&self.spheres)
                .map(|(s, sp)| {
                    let mut s = *s;
                    for (axis, &c) in sp.cut.iter().enumerate() {
                        if c != 0 {
                            s = traction_free(&s, sp.frame[axis]);
                        }
                    }
                    s
                })
                .collect();
            self.op.apply(&projected, force);
        } else {
            self.op.apply(stress, force);
        }
        for (f, v) in force.iter_mut().zip(&self.op.volume) {
            *f = f.map(|x| x / (RHO * v));
        }
    }

    /// The linear operator `u ↦ −a(σ(u))`, `σ = C : sym(∇u)`, on flat
    /// vectors: its eigenvalues are ω².
    fn stiffness(&self, u: &[f64], out: &mut [f64]) {
        self.stiffness_of(u, out, |stress, a| self.accelerations(stress, a));
    }

    /// [`Bar::stiffness`] with the accelerations of the stresses
    /// `accelerations` (a form's forces over its inertia).
    fn stiffness_of(
        &self,
        u: &[f64],
        out: &mut [f64],
        accelerations: impl Fn(&[[f64; 6]], &mut [[f64; 3]]),
    ) {
        let n = self.len();
        let disp: Vec<[f64; 3]> = (0..n)
            .map(|i| [u[3 * i], u[3 * i + 1], u[3 * i + 2]])
            .collect();
        let mut l = vec![[[0.0; 3]; 3]; n];
        self.shapes.velocity_gradients(&disp, &mut l);
        let stress: Vec<[f64; 6]> = l.iter().map(hooke_rate).collect();
        let mut a = vec![[0.0; 3]; n];
        accelerations(&stress, &mut a);
        for i in 0..n {
            for d in 0..3 {
                out[3 * i + d] = -a[i][d];
            }
        }
    }

    /// Runs the fundamental longitudinal mode of the free bar,
    /// `v_z = V cos(π z / L)`, for `periods` expected periods with the
    /// step `stable_step(c_p, d_min, safety)`; returns the measured period
    /// (from the zero crossings of the modal velocity) and the largest
    /// relative energy error over the run.
    fn fundamental_period(&self, periods: f64, safety: f64) -> (f64, f64, usize) {
        let (p, e, s, _) = self.damped_period(periods, safety, 0.0);
        (p, e, s)
    }

    /// [`Bar::fundamental_period`] with stiffness-proportional damping: the
    /// viscous stress `ζ (2 / ω_max) C : D` (ζ the damping ratio at the
    /// solver's `ω_max`) added to the stress the forces see, its work booked
    /// as dissipation, and the step shortened to the damped bound
    /// `(2 / ω_max)(√(1 + ζ²) − ζ)`. Also returns the dissipated fraction.
    fn damped_period(&self, periods: f64, safety: f64, zeta: f64) -> (f64, f64, usize, f64) {
        let (lambda, mu) = lame();
        let cp = ((lambda + 2.0 * mu) / RHO).sqrt();
        let omega_max = OMEGA_FACTOR * cp / self.d_min;
        let c = 2.0 * zeta / omega_max;
        let dt = stable_step(cp, self.d_min, safety) * ((1.0 + zeta * zeta).sqrt() - zeta);
        let n = self.len();
        let len = self.lattice.cylinder.length;
        let pos = &self.lattice.position;
        let mode: Vec<f64> = pos.iter().map(|p| (PI * p[2] / len).cos()).collect();
        let mass: Vec<f64> = self.lattice.volume.iter().map(|v| RHO * v).collect();
        let v0 = 1.0;
        let mut vel: Vec<[f64; 3]> = mode.iter().map(|m| [0.0, 0.0, v0 * m]).collect();
        let mut stress = vec![[0.0; 6]; n];
        let mut strain = vec![[0.0; 6]; n];
        let mut l = vec![[[0.0; 3]; 3]; n];
        let mut acc = vec![[0.0; 3]; n];
        let modal_norm: f64 = mode.iter().zip(&mass).map(|(m, w)| w * m * m).sum();
        let kinetic = |vel: &[[f64; 3]]| -> f64 {
            0.5 * vel
                .iter()
                .zip(&mass)
                .map(|(v, m)| m * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]))
                .sum::<f64>()
        };
        let e0 = kinetic(&vel);
        let steps = (periods * 2.0 * len / (E / RHO).sqrt() / dt).ceil() as usize;
        let mut crossings = Vec::new();
        let mut q_prev = v0;
        let mut energy_error = 0.0f64;
        let mut dissipated = 0.0;
        let mut total = vec![[0.0; 6]; n];
        // Central differences: v holds v^{n+1/2} (= v^0, as a^0 = 0).
        for step in 0..steps {
            self.shapes.velocity_gradients(&vel, &mut l);
            for i in 0..n {
                let rate = hooke_rate(&l[i]);
                for c in 0..6 {
                    stress[i][c] += dt * rate[c];
                }
                let d = |a: usize, b: usize| 0.5 * (l[i][a][b] + l[i][b][a]);
                let eps = [d(0, 0), d(1, 1), d(2, 2), d(0, 1), d(1, 2), d(2, 0)];
                for c in 0..6 {
                    strain[i][c] += dt * eps[c];
                }
                // The viscous stress c C : D and its power.
                let visc = rate.map(|x| c * x);
                let power = visc[0] * eps[0]
                    + visc[1] * eps[1]
                    + visc[2] * eps[2]
                    + 2.0 * (visc[3] * eps[3] + visc[4] * eps[4] + visc[5] * eps[5]);
                dissipated += dt * self.lattice.volume[i] * power;
                total[i] = std::array::from_fn(|k| stress[i][k] + visc[k]);
            }
            self.accelerations(&total, &mut acc);
            // Kinetic energy at the integer step, from the two half steps.
            let half: Vec<[f64; 3]> = vel
                .iter()
                .zip(&acc)
                .map(|(v, a)| std::array::from_fn(|d| v[d] + 0.5 * dt * a[d]))
                .collect();
            for (v, a) in vel.iter_mut().zip(&acc) {
                for d in 0..3 {
                    v[d] += dt * a[d];
                }
            }
            if self.smoothing > 0.0 {
                let before = kinetic(&vel);
                let l1 = self.mls_laplacian(&vel);
                let l2 = self.mls_laplacian(&l1);
                for (v, l) in vel.iter_mut().zip(&l2) {
                    for d in 0..3 {
                        v[d] -= self.smoothing * l[d];
                    }
                }
                dissipated += before - kinetic(&vel);
            }
            let elastic: f64 = (0..n)
                .map(|i| {
                    let (s, e) = (&stress[i], &strain[i]);
                    let w = s[0] * e[0]
                        + s[1] * e[1]
                        + s[2] * e[2]
                        + 2.0 * (s[3] * e[3] + s[4] * e[4] + s[5] * e[5]);
                    0.5 * self.lattice.volume[i] * w
                })
                .sum();
            energy_error =
                energy_error.max((kinetic(&half) + elastic + dissipated - e0).abs() / e0);
            let q: f64 = (0..n).map(|i| mass[i] * mode[i] * half[i][2]).sum::<f64>() / modal_norm;
            if (q_prev > 0.0) != (q > 0.0) {
                let t = (step as f64 + q_prev / (q_prev - q)) * dt;
                crossings.push(t);
            }
            q_prev = q;
        }
        assert!(crossings.len() >= 3, "{crossings:?}");
        let periods = (crossings.len() - 1) / 2;
        (
            (crossings[2 * periods] - crossings[0]) / periods as f64,
            energy_error,
            steps,
            dissipated / e0,
        )
    }
}

/// `P σ P` with `P = I − ν⊗ν`: the stress with no traction on the plane of
/// unit normal ν.
fn traction_free(s: &[f64; 6], nu: [f64; 3]) -> [f64; 6] {
    use meshless_impact::internals::mlpg::VOIGT;
    let m = |a: usize, b: usize| s[VOIGT[a][b]];
    let p = |a: usize, b: usize| (a == b) as u8 as f64 - nu[a] * nu[b];
    let out = |a: usize, b: usize| -> f64 {
        (0..3)
            .map(|k| (0..3).map(|l| p(a, k) * m(k, l) * p(l, b)).sum::<f64>())
            .sum()
    };
    [
        out(0, 0),
        out(1, 1),
        out(2, 2),
        out(0, 1),
        out(1, 2),
        out(2, 0),
    ]
}

/// The period of the fundamental mode of a free bar with Love's lateral
/// inertia correction: `ω = c k / √(1 + ν² k² R² / 2)`, `k = π / L`.
fn love_period(radius: f64, length: f64) -> f64 {
    let k = PI / length;
    let omega = (E / RHO).sqrt() * k / (1.0 + NU * NU * k * k * radius * radius / 2.0).sqrt();
    2.0 * PI / omega
}

/// A uniform stress on the bar: no force on an interior node (round-off);
/// on a boundary node, whose sphere is cut by `c` planes with outward
/// normals `ν_k`, the force on the curved part, `−σ·Σ_k ν_k π r² / 2^(c−1)`
/// (the divergence theorem), within the cut rule's measured error (7.3e-4
/// of `π r²` on a hemisphere).
#[test]
fn uniform_stress_on_interior_and_boundary_nodes() {
    let bar = Bar::new(3, ALPHA);
    let s = [3e8, -2e8, 5e8, 1e8, -4e7, 7e7];
    let stress = vec![s; bar.len()];
    let mut f = vec![[0.0; 3]; bar.len()];
    bar.op.apply(&stress, &mut f);
    let (mut interior, mut boundary) = (0.0f64, 0.0f64);
    for (sp, fi) in bar.spheres.iter().zip(&f) {
        let scale = 5e8 * PI * sp.radius * sp.radius;
        let cuts = sp.cut.iter().filter(|&&c| c != 0).count() as i32;
        let mut expected = [0.0; 3];
        if cuts > 0 {
            let area = PI * sp.radius * sp.radius / 2f64.powi(cuts - 1);
            for (axis, &c) in sp.cut.iter().enumerate() {
                let nu = sp.frame[axis].map(|x| x * c as f64);
                for b in 0..3 {
                    for a in 0..3 {
                        expected[b] -=
                            area * s[meshless_impact::internals::mlpg::VOIGT[a][b]] * nu[a];
                    }
                }
            }
        }
        let err = (0..3)
            .map(|b| (fi[b] - expected[b]).abs())
            .fold(0.0, f64::max)
            / scale;
        if cuts == 0 {
            interior = interior.max(err);
        } else {
            boundary = boundary.max(err);
        }
    }
    println!("uniform stress: interior {interior:.2e}, boundary {boundary:.2e}");
    assert!(interior < 1e-13, "{interior:e}");
    assert!(boundary < 1e-3, "{boundary:e}");
}

/// `κ = ω_max d_min / c_p` of the discrete operator, by power iteration.
fn kappa(bar: &Bar) -> f64 {
    let (lambda, mu) = lame();
    let cp = ((lambda + 2.0 * mu) / RHO).sqrt();
    let w2 = largest_eigenvalue(3 * bar.len(), 600, |u, out| bar.stiffness(u, out));
    w2.sqrt() * bar.d_min / cp
}

/// `κ` of the nodal Galerkin form (`weak_form = 1`): the operator
/// `u ↦ M⁻¹ Gᵀ V C G u`, G the collocated gradients, V the nodal volumes.
fn kappa_nodal(bar: &Bar) -> f64 {
    let (lambda, mu) = lame();
    let cp = ((lambda + 2.0 * mu) / RHO).sqrt();
    let n = bar.len();
    let op = NodalOperator::build(&bar.shapes, n);
    let volume = &bar.lattice.volume;
    let w2 = largest_eigenvalue(3 * n, 600, |u, out| {
        bar.stiffness_of(u, out, |stress, a| {
            op.apply(stress, volume, a);
            for (a, v) in a.iter_mut().zip(volume) {
                *a = a.map(|x| x / (RHO * v));
            }
        })
    });
    w2.sqrt() * bar.d_min / cp
}

/// Measured κ of the nodal form: 1.8618 (2 rings), 1.8207 (3), 1.7921
/// (4), 1.8045 (5), under `OMEGA_FACTOR_NODAL` = 1.95; above the sphere
/// form's `OMEGA_FACTOR` = 1.52 even with its safety factor (1.52 / 0.9 =
/// 1.69), so the nodal form needs its own step.
#[test]
fn highest_frequency_of_the_nodal_operator() {
    for rings in [2, 3] {
        let k = kappa_nodal(&Bar::new(rings, ALPHA));
        println!("rings {rings}: nodal kappa {k:.4}");
        assert!(
            k < OMEGA_FACTOR_NODAL && k > OMEGA_FACTOR / 0.9,
            "rings {rings}: nodal kappa {k}"
        );
    }
}

/// Measured κ: 1.4475 (2 rings, 399 nodes) and 1.4507 (3 rings, 1147
/// nodes), under `OMEGA_FACTOR` = 1.52.
#[test]
fn highest_frequency_of_the_elastic_operator() {
    for rings in [2, 3] {
        let k = kappa(&Bar::new(rings, ALPHA));
        println!("rings {rings}: kappa {k:.4}");
        assert!(
            k < OMEGA_FACTOR && k > 0.9 * OMEGA_FACTOR - 0.2,
            "rings {rings}: kappa {k}"
        );
    }
}

/// The fundamental longitudinal period of the free bar over 1.3 periods at
/// the stable step (safety 0.9) against Love's bar: measured errors
/// +0.81 % (2 rings) and +0.22 % (3 rings); the energy error over the run
/// 6.2e-2 and 1.7e-2. Over longer runs the energy grows: see `alpha_table`,
/// `unstable_modes_of_the_bar` and `sphere::ALPHA`.
#[test]
fn elastic_bar_fundamental_period() {
    let expected = love_period(2e-3, 20e-3);
    for (rings, tol_period, tol_energy) in [(2, 1e-2, 0.1), (3, 4e-3, 0.03)] {
        let bar = Bar::new(rings, ALPHA);
        let (period, energy, steps) = bar.fundamental_period(1.3, 0.9);
        let err = period / expected - 1.0;
        println!(
            "rings {rings}: {} nodes, {steps} steps, period error {err:.4e}, energy error {energy:.3e}",
            bar.len()
        );
        assert!(err.abs() < tol_period, "rings {rings}: period error {err}");
        assert!(energy < tol_energy, "rings {rings}: energy error {energy}");
    }
}

/// The measurement behind `sphere::ALPHA`: for each α, κ and, over 5
/// periods at a third of the stable step, the period error and the largest
/// energy error, at 3 rings.
#[test]
#[ignore = "measurement: prints the table behind sphere::ALPHA"]
fn alpha_table() {
    let expected = love_period(2e-3, 20e-3);
    for alpha in [0.5, 0.6, 0.7, 0.8, 0.9, 0.99] {
        for rings in [2, 3] {
            let bar = Bar::new(rings, alpha);
            let (period, energy, _) = bar.fundamental_period(5.0, 0.3);
            println!(
                "alpha {alpha} rings {rings}: kappa {:.3}, period error {:.2e}, energy error {energy:.2e}",
                kappa(&bar),
                period / expected - 1.0
            );
        }
    }
}

/// The spectrum of the semi-discrete operator `ü = −K u` of the free bar
/// (dense, by nalgebra's Schur form): the eigenvalues `λ = ω²` that are not
/// real and positive, the growth rate `max |Im √λ|` they give, and where
/// the eigenvector of the fastest-growing one lives.
#[test]
#[ignore = "measurement: the unstable modes of the free bar"]
fn unstable_modes_of_the_bar() {
    use nalgebra::{Complex, DMatrix, DVector};
    for (rings, alpha) in [(2, 0.5), (2, 0.9), (3, 0.9)] {
        let bar = Bar::new(rings, alpha);
        let n = 3 * bar.len();
        let mut k = DMatrix::<f64>::zeros(n, n);
        let mut e = vec![0.0; n];
        let mut col = vec![0.0; n];
        for j in 0..n {
            e[j] = 1.0;
            bar.stiffness(&e, &mut col);
            e[j] = 0.0;
            for i in 0..n {
                k[(i, j)] = col[i];
            }
        }
        let eig = k.clone().complex_eigenvalues();
        let lmax = eig.iter().map(|l| l.norm()).fold(0.0, f64::max);
        let period = love_period(2e-3, 20e-3);
        let mut bad: Vec<(f64, Complex<f64>)> = eig
            .iter()
            .map(|l| (l.sqrt().im.abs(), *l))
            .filter(|(g, _)| *g * period > 1e-3)
            .collect();
        bad.sort_by(|a, b| b.0.total_cmp(&a.0));
        println!(
            "rings {rings}, alpha {alpha}: {} eigenvalues, |λ|max {lmax:.3e}, {} growing (growth × period > 1e-3); fastest:",
            eig.len(),
            bad.len()
        );
        for (g, l) in bad.iter().take(6) {
            println!(
                "  λ = {:.3e} {:+.3e}i, growth × period {:.3}",
                l.re,
                l.im,
                g * period
            );
        }
        // The eigenvector of the fastest: inverse iteration with its shift.
        let Some(&(_, shift)) = bad.first() else {
            continue;
        };
        let kc = k.map(|x| Complex::new(x, 0.0))
            - DMatrix::<Complex<f64>>::identity(n, n) * (shift * Complex::new(1.0 + 1e-9, 0.0));
        let lu = kc.lu();
        let mut x = DVector::<Complex<f64>>::from_element(n, Complex::new(1.0, 0.0));
        for _ in 0..3 {
            x = lu.solve(&x).unwrap();
            let norm = x.norm();
            x /= Complex::new(norm, 0.0);
        }
        let mut amp: Vec<(f64, usize)> = (0..bar.len())
            .map(|i| ((0..3).map(|d| x[3 * i + d].norm_sqr()).sum::<f64>(), i))
            .collect();
        amp.sort_by(|a, b| b.0.total_cmp(&a.0));
        let share: f64 = amp.iter().take(10).map(|a| a.0).sum();
        println!("  its ten largest nodes hold {:.1} % of it:", 100.0 * share);
        for (a, i) in amp.iter().take(10) {
            let p = bar.lattice.position[*i];
            println!(
                "    node {i} at ({:.2}, {:.2}, {:.2}) mm, {:?}, {:.1} %",
                p[0] * 1e3,
                p[1] * 1e3,
                p[2] * 1e3,
                bar.lattice.surfaces[*i],
                100.0 * a
            );
        }
    }
}

/// The measurement behind the solver's damping (`mlpg::solver::DAMPING`):
/// stiffness-proportional (Rayleigh) damping `σ_v = c C : D` with
/// `c = 2 ζ / ω_max`, ζ the damping ratio at the solver's `ω_max`. Each
/// eigenvalue `λ` of the undamped operator `K` gives the modes
/// `s² + c λ s + λ = 0` of `ü = −K u − c K u̇`; the table prints the
/// fastest growth `max Re s` times the fundamental period, then, from 5
/// periods of the fundamental mode at 0.9 of the damped stable step, the
/// period error, the largest energy error (dissipation booked) and the
/// fraction dissipated.
#[test]
#[ignore = "measurement: prints the table behind the solver's damping"]
fn damping_table() {
    use nalgebra::{Complex, DMatrix};
    let period = love_period(2e-3, 20e-3);
    let (lambda, mu) = lame();
    let cp = ((lambda + 2.0 * mu) / RHO).sqrt();
    let project = std::env::var("MLPG_PROJECT").is_ok();
    let smoothing: f64 = std::env::var("MLPG_SMOOTH")
        .map(|s| s.parse().unwrap())
        .unwrap_or(0.0);
    let periods: f64 = std::env::var("MLPG_PERIODS")
        .map(|s| s.parse().unwrap())
        .unwrap_or(5.0);
    let zetas: Vec<f64> = match std::env::var("MLPG_ZETA") {
        Ok(z) => z.split(',').map(|x| x.parse().unwrap()).collect(),
        Err(_) => vec![0.0, 0.02, 0.04, 0.06, 0.08, 0.1, 0.15],
    };
    let eigen = std::env::var("MLPG_NOEIG").is_err();
    let ring_list: Vec<usize> = if std::env::var("MLPG_RINGS2").is_ok() {
        vec![2]
    } else {
        vec![2, 3]
    };
    for rings in ring_list {
        let mut bar = Bar::new(rings, ALPHA);
        bar.project = project;
        bar.smoothing = smoothing;
        let n = if eigen { 3 * bar.len() } else { 0 };
        let mut k = DMatrix::<f64>::zeros(n, n);
        let mut e = vec![0.0; n];
        let mut col = vec![0.0; n];
        for j in 0..n {
            e[j] = 1.0;
            bar.stiffness(&e, &mut col);
            e[j] = 0.0;
            for i in 0..n {
                k[(i, j)] = col[i];
            }
        }
        let eig = if eigen {
            k.complex_eigenvalues().iter().copied().collect()
        } else {
            Vec::<Complex<f64>>::new()
        };
        let omega_max = OMEGA_FACTOR * cp / bar.d_min;
        for &zeta in &zetas {
            let c = 2.0 * zeta / omega_max;
            let growth = eig
                .iter()
                .map(|l| {
                    // s = (−cλ ± √(c²λ² − 4λ)) / 2
                    let root = (l * l * (c * c) - l * 4.0).sqrt();
                    let a = (-l * c + root) * 0.5;
                    let b = (-l * c - root) * 0.5;
                    a.re.max(b.re)
                })
                .fold(f64::NEG_INFINITY, f64::max);
            if eigen && zeta == *zetas.last().unwrap() {
                let mut worst: Vec<(f64, Complex<f64>)> = eig
                    .iter()
                    .map(|l| {
                        let root = (l * l * (c * c) - l * 4.0).sqrt();
                        let a = (-l * c + root) * 0.5;
                        let b = (-l * c - root) * 0.5;
                        (a.re.max(b.re), *l)
                    })
                    .collect();
                worst.sort_by(|a, b| b.0.total_cmp(&a.0));
                let lmax = eig.iter().map(|l| l.norm()).fold(0.0, f64::max);
                for (g, l) in worst.iter().take(8) {
                    println!(
                        "   growth x period {:.3}: lambda/|lambda|max = {:.3e} {:+.3e}i",
                        g * period,
                        l.re / lmax,
                        l.im / lmax
                    );
                }
            }
            let (p, energy, _, lost) = bar.damped_period(periods, 0.9, zeta);
            let _ = Complex::new(0.0, 0.0);
            println!(
                "rings {rings} zeta {zeta}: c {c:.3e} s, growth x period {:.3}, period error {:.2e}, \
                 energy error {energy:.2e}, dissipated {lost:.2e}",
                growth * period,
                p / period - 1.0
            );
        }
    }
}
