//! What a Taylor run reports: its observables, its particle fields and the
//! rod's particle sets.

use super::{LOST_CONTACT, LOST_SMOOTHING, TaylorSolver, kinetic};
use crate::observe::{FieldSpec, TAYLOR_OBSERVABLES};
use crate::rod::{self, RodSets};
use crate::solver::shared::SolidNodes;

impl TaylorSolver {
    fn kinetic_energy(&self) -> f64 {
        kinetic(&self.state.vel, &self.setup.mass)
    }

    fn energy_error(&self) -> f64 {
        self.energy_error_with(self.kinetic_energy())
    }

    /// The energy error with the kinetic energy given (the update pass sums
    /// it in chunks).
    pub(super) fn energy_error_with(&self, kinetic: f64) -> f64 {
        self.state.energy.error(kinetic)
    }

    /// The centre-of-mass axial velocity toward the anvil.
    pub fn centre_of_mass_speed(&self) -> f64 {
        let (mut mv, mut m) = (0.0, 0.0);
        for (v, mi) in self.state.vel.iter().zip(&self.setup.mass) {
            mv -= mi * v[1];
            m += mi;
        }
        mv / m
    }

    /// The rod's particle sets: the face row, the mantle column from the
    /// face up, and the tail on the axis.
    pub fn rod_sets(&self) -> RodSets {
        let (nr, nz) = (self.setup.nr, self.setup.nz);
        RodSets {
            face: self.setup.face.particles.clone(),
            mantle: (0..nz).map(|k| k * nr + nr - 1).collect(),
            tail: (nz - 1) * nr,
        }
    }

    /// Current values of [`TAYLOR_OBSERVABLES`], in that order.
    pub fn observables(&self) -> Vec<f64> {
        (0..TAYLOR_OBSERVABLES.len())
            .map(|k| self.observable(k).expect("one value per row of the table"))
            .collect()
    }

    /// The current value of the `k`-th of [`TAYLOR_OBSERVABLES`] alone
    /// (`None` past the table): the rod's length and the largest plastic
    /// strain and temperature take one pass over the particles, the
    /// kinetic energy and the energy error one sum; the others read the
    /// face, the mantle generator, the tail or a total kept by the step.
    /// Nothing is allocated; the bits are those of
    /// [`TaylorSolver::observables`].
    pub fn observable(&self, k: usize) -> Option<f64> {
        Some(match TAYLOR_OBSERVABLES.get(k)?.name {
            "rod_length" => rod::rod_length(&self.state.pos),
            "mushroom_radius" => rod::mushroom_radius(&self.setup.face.particles, &self.state.pos),
            "undeformed_length" => {
                rod::undeformed_length(&self.setup.mantle.particles, &self.state.pos, self.setup.r0)
            }
            "tail_velocity" => {
                rod::tail_velocity((self.setup.nz - 1) * self.setup.nr, &self.state.vel)
            }
            "face_lift" => self.state.pos[0][1],
            "max_plastic_strain" => self.state.eps_p.iter().copied().fold(0.0, f64::max),
            "max_temperature" => self
                .state
                .temp
                .iter()
                .copied()
                .fold(f64::NEG_INFINITY, f64::max),
            "kinetic_energy" => self.kinetic_energy(),
            "internal_energy" => self.state.energy.internal,
            "smoothing_dissipation" => self.state.energy.lost[LOST_SMOOTHING],
            "contact_dissipation" => self.state.energy.lost[LOST_CONTACT],
            "energy_error" => self.energy_error(),
            "at_rest" => {
                if self.state.at_rest {
                    1.0
                } else {
                    0.0
                }
            }
            other => unreachable!("the Taylor observable `{other}` has no formula"),
        })
    }

    /// The values of the particle field `name` (one of [`TAYLOR_FIELDS`]),
    /// interleaved per particle.
    pub fn field(&self, name: &str) -> Option<Vec<f64>> {
        SolidNodes {
            pos: &self.state.pos,
            vel: &self.state.vel,
            rho: &self.state.rho,
            pressure: &self.state.pressure,
            eps_p: &self.state.eps_p,
            temp: &self.state.temp,
            contact: &self.state.contact,
        }
        .field(name, || {
            self.state
                .dev
                .iter()
                .zip(&self.state.pressure)
                .flat_map(|(d, p)| [d[0] - p, d[1] - p, d[2] - p, d[3]])
                .collect()
        })
    }
}

/// The particle fields of the Taylor solver.
pub const TAYLOR_FIELDS: &[FieldSpec] =
    &crate::observe::rod_fields(&["R", "Z"], &["RR", "ZZ", "TT", "RZ"]);
