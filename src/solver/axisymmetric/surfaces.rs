//! The stress boundary conditions on the rod's surfaces: traction-free on
//! the mantle, the top and the part of the impact face off the anvil, no
//! shear on the anvil.

use super::{SetupAxi, StateAxi};
use crate::solver::axisymmetric::boundary::{Surface, corner_free, traction_free};

/// The outward normal of the top at the axis.
pub(super) const TOP_ON_AXIS: [f64; 2] = [0.0, 1.0];
/// The outward normal of the impact face at the axis.
pub(super) const FACE_ON_AXIS: [f64; 2] = [0.0, -1.0];

/// The outward normal at the `k`-th particle of a surface that starts on
/// the axis (the top or the face): `on_axis` for the particle on the axis,
/// where the surface is flat by symmetry, else [`Surface::normal`].
pub(super) fn normal_from_axis(
    s: &Surface,
    k: usize,
    pos: &[[f64; 2]],
    on_axis: [f64; 2],
) -> [f64; 2] {
    if k == 0 { on_axis } else { s.normal(k, pos) }
}

/// Stress used by the momentum equation: the traction-free and
/// smooth-contact conditions applied on the surfaces of `setup` to the
/// constitutive stress `dev - p I` of `state` (which the update pass writes
/// for every particle), in its `stress_bc`.
pub(super) fn apply_surface_stress_bc(setup: &SetupAxi, state: &mut StateAxi) {
    let n = state.pos.len();
    let (nr, nz) = (setup.nr, setup.nz);
    for (k, &i) in setup.mantle.particles.iter().enumerate() {
        let s = &state.stress_bc[i];
        state.stress_bc[i] = if k == nz - 1 || (k == 0 && !state.contact[i]) {
            corner_free(s)
        } else {
            traction_free(s, setup.mantle.normal(k, &state.pos))
        };
    }
    for (k, &i) in setup.top.particles.iter().enumerate().take(nr - 1) {
        let n = normal_from_axis(&setup.top, k, &state.pos, TOP_ON_AXIS);
        state.stress_bc[i] = traction_free(&state.stress_bc[i], n);
    }
    for (k, &i) in setup.face.particles.iter().enumerate().take(nr - 1) {
        if state.contact[i] {
            // Smooth anvil: no shear traction.
            state.stress_bc[i][3] = 0.0;
        } else {
            let n = normal_from_axis(&setup.face, k, &state.pos, FACE_ON_AXIS);
            state.stress_bc[i] = traction_free(&state.stress_bc[i], n);
        }
    }
    // Particles that started elsewhere but touch the anvil (a folded
    // mantle) carry no shear there either.
    for i in 0..n {
        if state.contact[i] && i >= setup.nr {
            state.stress_bc[i][3] = 0.0;
        }
    }
}
