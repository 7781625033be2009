//! The free elastic bar of the MLPG foundations (steel-like constants on
//! the ring lattice) with its exact fundamental period: shared by the
//! tests of `tests/suite/mlpg.rs` and the measurements of
//! `examples/explore/` (which includes this file by its path).

use meshless_impact::internals::mlpg::{
    BOUNDARY_RULE, Cylinder, DEFAULT_RULE, NodalShapes, NodeLattice, OMEGA_FACTOR, SphereRule,
    SupportParams, Supports, TestSphere, TractionOperator, distance, largest_eigenvalue,
    stable_step,
};
use std::f64::consts::PI;

/// Steel-like constants (Pa, kg/m³).
pub(crate) const E: f64 = 200e9;
pub(crate) const NU: f64 = 0.28;
pub(crate) const RHO: f64 = 8000.0;

/// Lamé constants.
pub(crate) fn lame() -> (f64, f64) {
    let mu = E / (2.0 * (1.0 + NU));
    let lambda = E * NU / ((1.0 + NU) * (1.0 - 2.0 * NU));
    (lambda, mu)
}

/// Hooke's law for this test only: the stress rate of a velocity gradient,
/// `σ̇ = λ tr(D) I + 2 μ D`, in `[xx, yy, zz, xy, yz, zx]`.
pub(crate) fn hooke_rate(l: &[[f64; 3]; 3]) -> [f64; 6] {
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
pub(crate) struct Bar {
    pub(crate) lattice: NodeLattice,
    pub(crate) shapes: NodalShapes,
    pub(crate) op: TractionOperator,
    pub(crate) spheres: Vec<TestSphere>,
    pub(crate) d_min: f64,
    /// Whether the forces see the boundary nodes' stresses made
    /// traction-free (`σ ← P σ P`, `P = I − ν⊗ν` for each cut normal ν).
    pub(crate) project: bool,
    /// α of the bi-Laplacian velocity smoothing `v ← v − α L(L v)`,
    /// `L v = Σ_J φ_J(x_i) v_J − v_i`, applied after each velocity update.
    pub(crate) smoothing: f64,
}

impl Bar {
    pub(crate) fn new(rings: usize, alpha: f64) -> Self {
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

    pub(crate) fn len(&self) -> usize {
        self.lattice.len()
    }

    /// `L v = Σ_J φ_J(x_i) v_J − v_i` at every node.
    pub(crate) fn mls_laplacian(&self, v: &[[f64; 3]]) -> Vec<[f64; 3]> {
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
    pub(crate) fn accelerations(&self, stress: &[[f64; 6]], force: &mut [[f64; 3]]) {
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
    pub(crate) fn stiffness(&self, u: &[f64], out: &mut [f64]) {
        self.stiffness_of(u, out, |stress, a| self.accelerations(stress, a));
    }

    /// [`Bar::stiffness`] with the accelerations of the stresses
    /// `accelerations` (a form's forces over its inertia).
    pub(crate) fn stiffness_of(
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
    pub(crate) fn fundamental_period(&self, periods: f64, safety: f64) -> (f64, f64, usize) {
        let (p, e, s, _) = self.damped_period(periods, safety, 0.0);
        (p, e, s)
    }

    /// [`Bar::fundamental_period`] with stiffness-proportional damping: the
    /// viscous stress `ζ (2 / ω_max) C : D` (ζ the damping ratio at the
    /// solver's `ω_max`) added to the stress the forces see, its work booked
    /// as dissipation, and the step shortened to the damped bound
    /// `(2 / ω_max)(√(1 + ζ²) − ζ)`. Also returns the dissipated fraction.
    pub(crate) fn damped_period(
        &self,
        periods: f64,
        safety: f64,
        zeta: f64,
    ) -> (f64, f64, usize, f64) {
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
pub(crate) fn traction_free(s: &[f64; 6], nu: [f64; 3]) -> [f64; 6] {
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
pub(crate) fn love_period(radius: f64, length: f64) -> f64 {
    let k = PI / length;
    let omega = (E / RHO).sqrt() * k / (1.0 + NU * NU * k * k * radius * radius / 2.0).sqrt();
    2.0 * PI / omega
}

/// `κ = ω_max d_min / c_p` of the discrete operator, by power iteration.
pub(crate) fn kappa(bar: &Bar) -> f64 {
    let (lambda, mu) = lame();
    let cp = ((lambda + 2.0 * mu) / RHO).sqrt();
    let w2 = largest_eigenvalue(3 * bar.len(), 600, |u, out| bar.stiffness(u, out));
    w2.sqrt() * bar.d_min / cp
}
