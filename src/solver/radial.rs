//! The radial MSPH solver of the cylindrical Noh problem, eqs. (4.1)-(4.4):
//! one-dimensional in R, ideal gas, energy equation. The MSPH system shrinks to
//! (f, f_R, f_RR); there is no strength, no anvil and no heating besides
//! compression and the conversion of the kinetic energy removed by
//! conservative smoothing into internal energy (which makes the smoothing
//! conservative, and is the only dissipation at the shock).
//!
//! Particles are cylindrical shells at `r_k = k D`, `k = 0 .. n-1`,
//! `D = outer_radius / (n - 1)`, each with the mass of its tributary shell (per
//! unit length). The particle on the axis keeps `U_R = 0`.
//!
//! The axis is a line of symmetry: particles within one support radius of it
//! are mirrored to `-r` (velocity reversed, scalars kept) so that the MSPH sums
//! and the smoothing of particles near the axis see a symmetric neighbourhood.
//!
//! A cold gas (P = 0, e = 0) converging on the axis has no pressure to stop
//! it, and the velocity smoothing cannot see a purely geometric convergence
//! (U_R = -1 everywhere), so the shock cannot start from smoothing alone. The
//! scene therefore adds a von Neumann-Richtmyer bulk artificial viscosity
//! `q = rho (c_q h^2 theta^2 + c_l h c |theta|)` in compression
//! (`theta = div U < 0`), zero otherwise, added to the pressure in the momentum
//! and energy equations (so the pair stays conservative), and a viscous signal
//! speed in the Courant condition.
//!
//! The density of a shell is its mass over its Lagrangian volume, the annulus
//! between the midpoints to its neighbours. The MSPH continuity equation (4.1)
//! with smoothed density was tried first and is not stable at the axis: the
//! smoothing mixes the axis density with the inflow and the shells there
//! collapse onto the axis particle.
//!
//! The conservative smoothing of the velocity is written in pairwise,
//! momentum-conserving form (it reduces to eq. (3.23) for equal masses). The
//! Shepard form of (3.23) does not conserve momentum where the particle
//! number density jumps, as it does by a factor of four across this shock:
//! it dragged the shocked gas inward and gave a shock radius of 0.159 instead
//! of 0.2 at t = 0.6. The density is not smoothed: it is the shell's mass over
//! its volume.

use super::{COURANT, first_degenerate, rows_mut};
use crate::approx::msph::{Msph1Rows, Row1};
use crate::error::{Error, Result};
use crate::kernel::kernel1;
use crate::material::ideal_gas::IdealGas;
use crate::neighbours::{NeighbourList, cell_list};
use crate::observe::{FieldSpec, NOH_OBSERVABLES};
use crate::solver::setup_struct;
use crate::solver::shared::{Clock, EnergyBook, check_derived, first_non_finite};
use rayon::prelude::*;

/// Window `(r_min, r_max)` of `post_shock_density`.
pub const POST_SHOCK_WINDOW: (f64, f64) = (0.1, 0.18);

/// Window `(r_min, r_max)` of `pre_shock_density_l1`.
pub const PRE_SHOCK_WINDOW: (f64, f64) = (0.25, 0.9);

setup_struct! {
    /// Parameters of the cylindrical Noh scene (dimensionless units of the
    /// problem: initial density 1, inflow speed 1): the setup the solver
    /// keeps and saves with its state; their table, defaults and ranges are
    /// the `noh` scene's.
    NohParams {
        particles_radial: "particles along the radius, the one on the axis included",
        outer_radius: "initial radius of the gas column; 1.5 keeps gas out to r = 0.9 at t = 0.6",
        gamma: "ratio of specific heats of the ideal gas",
        smoothing_ratio: "smoothing length h divided by the particle spacing",
        smoothing_coefficient: "alpha_cs of the conservative smoothing (3.23)",
        viscosity_quadratic: "c_q of the radial von Neumann-Richtmyer artificial viscosity",
        viscosity_linear: "c_l of the radial artificial viscosity",
        end_time: "simulated time at which the run ends",
    }
}

/// Inner and outer radius of each shell: the midpoints to its neighbours,
/// the axis for the first and its own radius for the last.
fn shell_bounds(r: &[f64]) -> Vec<(f64, f64)> {
    let n = r.len();
    (0..n)
        .map(|i| {
            let lo = if i == 0 { 0.0 } else { 0.5 * (r[i] + r[i - 1]) };
            let hi = if i + 1 < n {
                0.5 * (r[i] + r[i + 1])
            } else {
                r[i]
            };
            (lo, hi)
        })
        .collect()
}

/// Largest relative volume change of a particle in one step: near the axis
/// the hoop rate U_R / R, not h, sets the time scale.
pub const MAX_VOLUME_STRAIN: f64 = 0.02;

/// Exact post-shock density of the cylindrical Noh problem with gamma = 5/3.
pub const POST_SHOCK_DENSITY: f64 = 16.0;

/// A Noh run: its setup and its state, apart (it has no workspace).
#[derive(Debug, Clone)]
pub struct NohSolver {
    /// What the run is built from, and never changes.
    setup: SetupNoh,
    /// What the run changes: all that is saved.
    state: StateNoh,
}

/// What a Noh run is built from, from its scene, and never changes: the
/// parameters, the gas, the smoothing length and the masses. Not saved.
#[derive(Debug, Clone)]
struct SetupNoh {
    p: NohParams,
    gas: IdealGas,
    h: f64,
    mass: Vec<f64>,
}

impl SetupNoh {
    /// The digest of what the setup is made from, the parameters and the
    /// gas: the smoothing length and the masses follow from them.
    fn digest(&self) -> u64 {
        crate::solver::shared::setup_digest(&(&self.p, &self.gas))
    }
}

/// What a Noh run changes, and all that it saves (format 2 of
/// `src/state_format.rs`).
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct StateNoh {
    /// The digest of the setup of the run that made this state.
    setup_digest: u64,
    r: Vec<f64>,
    v: Vec<f64>,
    rho: Vec<f64>,
    e: Vec<f64>,
    pres: Vec<f64>,
    /// Artificial viscous pressure.
    q: Vec<f64>,
    /// Signal speed (sound plus viscous) for the Courant condition.
    signal: Vec<f64>,
    /// Divergence of the velocity, for the volume-change limit on the step.
    div: Vec<f64>,
    clock: Clock,
    /// The impact's kinetic energy; the internal energy is summed from the
    /// particles when asked.
    energy: EnergyBook<0>,
}

/// The run's state is all it saves.
impl serde::Serialize for NohSolver {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        self.state.serialize(s)
    }
}

impl NohSolver {
    /// Sets up the converging gas column. `p` must be validated.
    pub fn new(p: NohParams) -> Result<Self> {
        let n = p.particles_radial as usize;
        let d = p.outer_radius / (n - 1) as f64;
        let r: Vec<f64> = (0..n).map(|k| k as f64 * d).collect();
        let mass: Vec<f64> = r
            .iter()
            .map(|&rk| {
                let lo = (rk - 0.5 * d).max(0.0);
                let hi = (rk + 0.5 * d).min(p.outer_radius);
                std::f64::consts::PI * (hi * hi - lo * lo)
            })
            .collect();
        let v: Vec<f64> = (0..n).map(|k| if k == 0 { 0.0 } else { -1.0 }).collect();
        let initial_energy = mass.iter().zip(&v).map(|(m, v)| 0.5 * m * v * v).sum();
        let mut s = NohSolver {
            setup: SetupNoh {
                gas: IdealGas { gamma: p.gamma },
                h: p.smoothing_ratio * d,
                mass,
                p,
            },
            state: StateNoh {
                setup_digest: 0,
                rho: vec![1.0; n],
                e: vec![0.0; n],
                pres: vec![0.0; n],
                q: vec![0.0; n],
                signal: vec![0.0; n],
                div: vec![0.0; n],
                r,
                v,
                clock: Clock::default(),
                energy: EnergyBook::new(initial_energy),
            },
        };
        s.state.clock = Clock::start(s.stable_dt());
        check_derived("time step", s.state.clock.dt, "")?;
        s.state.setup_digest = s.setup.digest();
        Ok(s)
    }

    /// Number of particles.
    pub fn particles(&self) -> usize {
        self.state.r.len()
    }

    /// Checks a restored state against `fresh`, a new run of the same
    /// parameters (as [`super::axisymmetric::TaylorSolver`] does): what
    /// follows from the parameters must be the same bits, and every field
    /// one finite value per particle.
    pub(crate) fn check_restored(&self, fresh: &NohSolver) -> std::result::Result<(), String> {
        use crate::solver::shared::json;
        // The setup is the scene's (a restored run is built from it), and
        // the state one that a run of it made.
        if self.state.setup_digest != fresh.state.setup_digest {
            return Err(crate::solver::shared::NOT_ITS_SETUP.into());
        }
        if json(&(self.state.clock.dt0, self.state.energy.initial))
            != json(&(fresh.state.clock.dt0, fresh.state.energy.initial))
        {
            return Err("its first step or impact energy do not follow from its parameters".into());
        }
        let n = fresh.particles();
        let fields = [
            ("radii", &self.state.r),
            ("velocities", &self.state.v),
            ("densities", &self.state.rho),
            ("specific energies", &self.state.e),
            ("pressures", &self.state.pres),
            ("viscous pressures", &self.state.q),
            ("signal speeds", &self.state.signal),
            ("divergences", &self.state.div),
        ];
        for (what, f) in fields {
            if f.len() != n {
                return Err(format!("it holds {} {what} for {n} particles", f.len()));
            }
            if !f.iter().all(|x| x.is_finite()) {
                return Err(format!("its {what} are not all finite"));
            }
        }
        if !self.state.rho.iter().all(|&x| x > 0.0) {
            return Err("its densities are not all positive".into());
        }
        // Each step ends by taking the next one from the fields, so a
        // restored step is at most the stable one of its fields.
        let stable =
            self.state.clock.dt > 0.0 && self.state.clock.dt <= self.stable_dt() * (1.0 + 1e-9);
        if !(self.state.clock.time.is_finite() && self.state.clock.time >= 0.0 && stable) {
            return Err(format!(
                "its clock (t = {}, dt = {}) is not valid",
                self.state.clock.time, self.state.clock.dt
            ));
        }
        if (self.state.clock.steps == 0) != (self.state.clock.time == 0.0) {
            return Err(format!(
                "its step count {} does not match its time {}",
                self.state.clock.steps, self.state.clock.time
            ));
        }
        Ok(())
    }

    crate::solver::shared::clock_getters!(state.clock);

    /// Whether `end_time` has been reached.
    pub fn finished(&self) -> bool {
        self.state.clock.time >= self.setup.p.end_time
    }

    fn stable_dt(&self) -> f64 {
        let worst = (0..self.particles())
            .map(|i| {
                self.state.signal[i].max(
                    self.setup
                        .gas
                        .sound_speed(self.state.rho[i], self.state.pres[i]),
                ) + self.state.v[i].abs()
            })
            .fold(0.0, f64::max);
        let max_div = self.state.div.iter().fold(0.0f64, |m, d| m.max(d.abs()));
        (COURANT * self.setup.h / worst).min(MAX_VOLUME_STRAIN / max_div)
    }

    /// Positions of the real particles followed by their mirror images
    /// across the axis, and for each entry the real particle it copies.
    fn with_mirror(&self) -> (Vec<f64>, Vec<usize>) {
        let mut r = self.state.r.clone();
        let mut src: Vec<usize> = (0..r.len()).collect();
        for (k, &rk) in self.state.r.iter().enumerate().skip(1) {
            if rk < 2.0 * self.setup.h {
                r.push(-rk);
                src.push(k);
            }
        }
        (r, src)
    }

    /// MSPH first-derivative weights of every neighbour pair (CSR order).
    fn pair_weights(&self, nl: &NeighbourList, r: &[f64], vol: &[f64]) -> Result<Vec<f64>> {
        let n = self.particles();
        let mut w = vec![0.0; nl.indices.len()];
        let rows = rows_mut(&mut w, &nl.offsets);
        let h = self.setup.h;
        let status: Vec<std::result::Result<(), crate::approx::msph::Degenerate>> = rows
            .into_par_iter()
            .take(n)
            .enumerate()
            .map(|(i, row)| {
                let nb = nl.of(i);
                let m = Msph1Rows::new(i, nb, r, vol, h, [Row1::R])?;
                for (slot, &j) in row.iter_mut().zip(nb) {
                    *slot = m.weight(r[j], vol[j])[0];
                }
                Ok(())
            })
            .collect();
        first_degenerate(status, self.state.clock.time)?;
        Ok(w)
    }

    /// Advances one step (the last one is shortened to land on `end_time`).
    pub fn step(&mut self) -> Result<()> {
        let n = self.particles();
        let dt = self
            .state
            .clock
            .dt
            .min(self.setup.p.end_time - self.state.clock.time);
        let alpha = self.setup.p.smoothing_coefficient;
        let (r, src) = self.with_mirror();
        let mirrored = |f: &[f64], sign: f64| -> Vec<[f64; 1]> {
            src.iter()
                .enumerate()
                .map(|(k, &i)| [if k < n { f[i] } else { sign * f[i] }])
                .collect()
        };
        let vol: Vec<f64> = src
            .iter()
            .map(|&i| self.setup.mass[i] / self.state.rho[i])
            .collect();
        let pts: Vec<[f64; 2]> = r.iter().map(|&x| [x, 0.0]).collect();
        let nl = cell_list(&pts, 2.0 * self.setup.h);
        let w = self.pair_weights(&nl, &r, &vol)?;
        let deriv = |f: &[[f64; 1]], i: usize| -> f64 {
            let (a, b) = (nl.offsets[i], nl.offsets[i + 1]);
            nl.indices[a..b]
                .iter()
                .zip(&w[a..b])
                .map(|(&j, g)| g * (f[j][0] - f[i][0]))
                .sum()
        };
        // Momentum (4.2) with the radial viscous stress.
        let pq: Vec<f64> = self
            .state
            .pres
            .iter()
            .zip(&self.state.q)
            .map(|(p, q)| p + q)
            .collect();
        let pq = mirrored(&pq, 1.0);
        let v_half: Vec<f64> = (0..n)
            .into_par_iter()
            .map(|i| {
                if i == 0 {
                    0.0
                } else {
                    self.state.v[i] - dt * deriv(&pq, i) / self.state.rho[i]
                }
            })
            .collect();
        // Conservative smoothing of the velocity in pairwise form: particles i
        // and j exchange momentum alpha c_ij (v_j - v_i) with c_ij = c_ji, so
        // momentum is conserved; c_ij = m_i m_j W_ij / mean(M_i, M_j) with
        // M_i = sum_k m_k W_ik, which is eq. (3.23) for equal masses. The
        // kinetic energy it removes becomes heat, shared in proportion to each
        // particle's part of the pairwise dissipation.
        let m_ext = mirrored(&self.setup.mass, 1.0);
        let vh_m = mirrored(&v_half, -1.0);
        let kern = |i: usize, j: usize| kernel1(r[i] - r[j], self.setup.h).w;
        let big_m: Vec<f64> = (0..n)
            .map(|i| nl.of(i).iter().map(|&j| m_ext[j][0] * kern(i, j)).sum())
            .collect();
        let big_m_of = |j: usize| big_m[src[j]];
        let (dv, dissip): (Vec<f64>, Vec<f64>) = (0..n)
            .into_par_iter()
            .map(|i| {
                let (mut dp, mut d) = (0.0, 0.0);
                for &j in nl.of(i) {
                    let c = self.setup.mass[i] * m_ext[j][0] * kern(i, j)
                        / (0.5 * (big_m[i] + big_m_of(j)));
                    let diff = vh_m[j][0] - v_half[i];
                    dp += c * diff;
                    d += c * diff * diff;
                }
                (alpha * dp / self.setup.mass[i], 0.5 * alpha * d)
            })
            .unzip();
        let mut vs: Vec<f64> = (0..n).map(|i| v_half[i] + dv[i]).collect();
        vs[0] = 0.0;
        let lost: f64 = (0..n)
            .map(|i| 0.5 * self.setup.mass[i] * (v_half[i] * v_half[i] - vs[i] * vs[i]))
            .sum();
        let total: f64 = dissip.iter().sum();
        if lost > 0.0 && total > 0.0 {
            for i in 0..n {
                self.state.e[i] += lost * dissip[i] / total / self.setup.mass[i];
            }
        }
        // Continuity (4.1) and energy (4.3).
        let vs_m = mirrored(&vs, -1.0);
        let dvdr: Vec<f64> = (0..n).into_par_iter().map(|i| deriv(&vs_m, i)).collect();
        let div: Vec<f64> = (0..n)
            .map(|i| {
                if i == 0 {
                    2.0 * dvdr[0]
                } else {
                    dvdr[i] + vs[i] / self.state.r[i]
                }
            })
            .collect();
        // Density of each shell from its mass and its Lagrangian volume
        // (exact mass conservation in 1-D; see the module notes).
        let rn: Vec<f64> = (0..n).map(|i| self.state.r[i] + dt * vs[i]).collect();
        let rho_new: Vec<f64> = shell_bounds(&rn)
            .iter()
            .zip(&self.setup.mass)
            .map(|((lo, hi), m)| m / (std::f64::consts::PI * (hi * hi - lo * lo)))
            .collect();
        let (h, cq, cl) = (
            self.setup.h,
            self.setup.p.viscosity_quadratic,
            self.setup.p.viscosity_linear,
        );
        for i in 0..n {
            let rho = rho_new[i];
            let rho_mid = 0.5 * (self.state.rho[i] + rho);
            let c = self
                .setup
                .gas
                .sound_speed(self.state.rho[i], self.state.pres[i]);
            let g = div[i].min(0.0);
            self.state.q[i] = rho * (cq * h * h * g * g - cl * h * c * g);
            self.state.signal[i] = c + cl * c + cq * h * g.abs();
            self.state.div[i] = div[i];
            self.state.e[i] -= dt * (self.state.pres[i] + self.state.q[i]) * div[i] / rho_mid;
            self.state.rho[i] = rho;
            self.state.pres[i] = self.setup.gas.pressure(rho, self.state.e[i]);
            self.state.r[i] += dt * vs[i];
        }
        self.state.v = vs;
        self.state.clock.time += dt;
        self.state.clock.steps += 1;
        if let Some((field, i)) = first_non_finite(&[
            ("radius", &self.state.r),
            ("velocity", &self.state.v),
            ("density", &self.state.rho),
            ("specific energy", &self.state.e),
        ]) {
            return Err(Error::NonFinite {
                field,
                particle: i,
                time: self.state.clock.time,
            });
        }
        if let Some(i) = (1..n).find(|&i| self.state.r[i] <= 0.0) {
            return Err(Error::ThroughBoundary {
                particle: i,
                boundary: "axis",
                time: self.state.clock.time,
                position: self.state.r[i],
            });
        }
        self.state.clock.dt = self.stable_dt();
        self.state.clock.check_step(self.state.clock.dt)?;
        Ok(())
    }

    /// Exact density of the cylindrical Noh problem at radius `r`, time `t`.
    pub fn exact_density(r: f64, t: f64) -> f64 {
        if r < t / 3.0 {
            POST_SHOCK_DENSITY
        } else {
            1.0 + t / r
        }
    }

    /// Current values of [`NOH_OBSERVABLES`], in that order.
    pub fn observables(&self) -> Vec<f64> {
        let t = self.state.clock.time;
        let n = self.particles();
        // Shock: outermost particle whose density reaches the mean of the exact
        // pre- and post-shock values, interpolated to the crossing.
        let thresh = |r: f64| 0.5 * (POST_SHOCK_DENSITY + 1.0 + t / r.max(1e-12));
        let mut shock = 0.0;
        for i in (1..n).rev() {
            if self.state.rho[i] >= thresh(self.state.r[i]) {
                shock = self.state.r[i];
                if i + 1 < n {
                    let (a, b) = (
                        self.state.rho[i] - thresh(self.state.r[i]),
                        self.state.rho[i + 1] - thresh(self.state.r[i + 1]),
                    );
                    let f = a / (a - b);
                    shock = self.state.r[i] + f * (self.state.r[i + 1] - self.state.r[i]);
                }
                break;
            }
        }
        let mean_over = |lo: f64, hi: f64, f: &dyn Fn(usize) -> f64| -> f64 {
            let (mut s, mut c) = (0.0, 0usize);
            for i in 0..n {
                if self.state.r[i] >= lo && self.state.r[i] <= hi {
                    s += f(i);
                    c += 1;
                }
            }
            if c > 0 {
                return s / c as f64;
            }
            // No particle in the window (a very coarse run): the value of the
            // particle nearest to its centre.
            let mid = 0.5 * (lo + hi.min(self.state.r[n - 1]));
            let nearest = (0..n)
                .min_by(|&a, &b| {
                    (self.state.r[a] - mid)
                        .abs()
                        .total_cmp(&(self.state.r[b] - mid).abs())
                })
                .unwrap_or(0);
            f(nearest)
        };
        let (post_lo, post_hi) = POST_SHOCK_WINDOW;
        let (pre_lo, pre_hi) = PRE_SHOCK_WINDOW;
        let post = mean_over(post_lo, post_hi, &|i| self.state.rho[i]);
        let pre = mean_over(pre_lo, pre_hi, &|i| {
            let ex = 1.0 + t / self.state.r[i];
            (self.state.rho[i] - ex).abs() / ex
        });
        let l1 = mean_over(0.05, f64::INFINITY, &|i| {
            let ex = Self::exact_density(self.state.r[i], t);
            (self.state.rho[i] - ex).abs() / ex
        });
        let ke: f64 = self
            .setup
            .mass
            .iter()
            .zip(&self.state.v)
            .map(|(m, v)| 0.5 * m * v * v)
            .sum();
        let ie: f64 = self
            .setup
            .mass
            .iter()
            .zip(&self.state.e)
            .map(|(m, e)| m * e)
            .sum();
        let values = vec![
            shock,
            post,
            pre,
            l1,
            ke,
            ie,
            self.state.energy.error_given(ke, ie),
        ];
        debug_assert_eq!(values.len(), NOH_OBSERVABLES.len());
        values
    }

    /// The values of the particle field `name` (one of [`NOH_FIELDS`]),
    /// interleaved per particle.
    pub fn field(&self, name: &str) -> Option<Vec<f64>> {
        Some(match name {
            "position" => self.state.r.iter().flat_map(|&r| [r, 0.0]).collect(),
            "density" => self.state.rho.clone(),
            "velocity" => self.state.v.clone(),
            "pressure" => self.state.pres.clone(),
            "specific_energy" => self.state.e.clone(),
            _ => return None,
        })
    }
}

/// The particle fields of the Noh solver (positions in the R-Z plane, Z = 0).
pub const NOH_FIELDS: &[FieldSpec] = &[
    FieldSpec {
        name: "position",
        unit: "1",
        components: &["R", "Z"],
    },
    FieldSpec {
        name: "density",
        unit: "1",
        components: &["rho"],
    },
    FieldSpec {
        name: "velocity",
        unit: "1",
        components: &["R"],
    },
    FieldSpec {
        name: "pressure",
        unit: "1",
        components: &["P"],
    },
    FieldSpec {
        name: "specific_energy",
        unit: "1",
        components: &["e"],
    },
];

impl crate::model::Model for NohSolver {
    crate::model::inherent_basics!();
    fn field_specs(&self) -> &'static [FieldSpec] {
        NOH_FIELDS
    }
    /// 600 records over the run.
    fn record_interval(&self) -> f64 {
        self.setup.p.end_time / 600.0
    }
    fn load_state(
        &mut self,
        saved: crate::model::SavedSolver<'_>,
    ) -> std::result::Result<(), String> {
        self.state = crate::solver::shared::read_state(
            saved,
            &[
                ("p", "its parameters"),
                ("gas", "its gas"),
                ("h", "its smoothing length"),
                ("mass", "its masses"),
            ],
        )?;
        Ok(())
    }
    fn check_restored(&self, fresh: &dyn crate::model::Model) -> std::result::Result<(), String> {
        self.check_restored(crate::model::same_solver(fresh)?)
    }
}
