//! Particle shifting in the axisymmetric solver (src/solver/axisymmetric/shift.rs):
//! which way each particle may move, the shifts, the fields carried along,
//! and the crowded particles that leave the axis.

use super::mirror::fill_images;
use super::surfaces;
use super::surfaces::{FACE_ON_AXIS, TOP_ON_AXIS, normal_from_axis};
use super::workspace::Workspace;
use super::{AXIS_CROWD, AXIS_LEAVE, LOST_SMOOTHING, SURFACE_BAND, SetupAxi, StateAxi, kinetic1};
use crate::error::{Error, Result};
use crate::solver::axisymmetric::boundary::Surface;
use crate::solver::axisymmetric::shift::{
    Candidates, Freedom, carry, leaving, shifts, surface_band,
};
use crate::solver::shared::{SHIFT_CAP, SHIFT_RANGE};

/// The directions each particle may shift in: along the surface on the
/// mantle and the top (they carry the boundary conditions and the rod's
/// outline, which sliding keeps), none on the face row, the corners and
/// a surface particle on the anvil or the axis, along Z on the axis,
/// along R on the anvil, none on both.
fn freedoms(setup: &SetupAxi, state: &StateAxi, normals: &[(usize, [f64; 2])]) -> Vec<Freedom> {
    let mut free: Vec<Freedom> = state
        .contact
        .iter()
        .enumerate()
        .map(|(i, &touch)| match (state.on_axis[i], touch) {
            (true, true) => Freedom::Fixed,
            (true, false) => Freedom::Across([1.0, 0.0]),
            (false, true) => Freedom::Across([0.0, 1.0]),
            (false, false) => Freedom::Both,
        })
        .collect();
    // The surfaces slide along themselves: a particle of the mantle or
    // the top (not a corner, nor on the anvil) moves across its normal
    // only, so that the outline stays while crowded surface particles
    // spread along it. The face row and the corners stay. The normals
    // are those of [`surface_normals`] (mantle, then top).
    let m = setup.mantle.particles.len();
    for (s, normals) in [(&setup.mantle, &normals[..m]), (&setup.top, &normals[m..])] {
        let last = s.particles.len() - 1;
        for (k, &i) in s.particles.iter().enumerate() {
            let n = normals[k].1;
            free[i] =
                if k == 0 || k == last || state.contact[i] || state.on_axis[i] || n == [0.0; 2] {
                    Freedom::Fixed
                } else {
                    Freedom::Across(n)
                };
        }
    }
    for &i in &setup.face.particles {
        free[i] = Freedom::Fixed;
    }
    free
}

/// The particles of the surfaces (mantle, top, face row) with their
/// outward normals, as the traction-free condition takes them.
fn surface_normals(setup: &SetupAxi, state: &StateAxi) -> Vec<(usize, [f64; 2])> {
    let mut out = Vec::with_capacity(
        setup.mantle.particles.len() + setup.top.particles.len() + setup.face.particles.len(),
    );
    for (k, &i) in setup.mantle.particles.iter().enumerate() {
        out.push((i, setup.mantle.normal(k, &state.pos)));
    }
    for (s, on_axis) in [(&setup.top, TOP_ON_AXIS), (&setup.face, FACE_ON_AXIS)] {
        for (k, &i) in s.particles.iter().enumerate() {
            out.push((i, normal_from_axis(s, k, &state.pos, on_axis)));
        }
    }
    out
}

/// Particle shifting (src/solver/axisymmetric/shift.rs): pushes apart the pairs closer
/// than [`SHIFT_RANGE`] and carries the fields of the moved particles
/// along. The kinetic energy the carrying changes is booked with the
/// smoothing. With a `margin` ([`Workspace::shift_margin`]) only the
/// particles that may have a neighbour within the range are looked at.
/// Returns whether a particle moved, or the compression limit of the
/// equation of state at a moved particle.
pub(super) fn shift(
    setup: &SetupAxi,
    state: &mut StateAxi,
    ws: &mut Workspace,
    margin: Option<f64>,
) -> Result<bool> {
    let n = state.pos.len();
    let spacing = setup.spacing();
    let normals = surface_normals(setup, state);
    let mut free = freedoms(setup, state, &normals);
    if let Some(m) = margin {
        let reach = SHIFT_RANGE * spacing * (1.0 + 1e-9) + m;
        for (f, p) in free.iter_mut().zip(&ws.rows.part) {
            if p.min_d2 > reach * reach {
                *f = Freedom::Fixed;
            }
        }
        if free.iter().all(|f| *f == Freedom::Fixed) {
            return Ok(false);
        }
    }
    ws.fields.pos[..n].copy_from_slice(&state.pos);
    fill_images(&mut ws.fields.pos, n, &ws.lists.images);
    let c = Candidates {
        pos: &ws.fields.pos,
        nbr: &ws.lists.nbr,
        nbr_len: &ws.lists.nbr_len,
        stride: ws.lists.stride,
    };
    let outward = surface_band(c, n, &normals, SURFACE_BAND * spacing);
    let mut d = shifts(
        c,
        &free,
        &outward,
        spacing,
        SHIFT_RANGE * spacing,
        setup.scheme.shifting,
        SHIFT_CAP * spacing,
    );
    leave_axis(setup, state, &free, spacing, &mut d);
    if d.iter().all(|d| *d == [0.0; 2]) {
        return Ok(false);
    }
    let mut f: Vec<[f64; 9]> = (0..n)
        .map(|i| {
            let (v, s) = (state.vel[i], state.dev[i]);
            [
                v[0],
                v[1],
                s[0],
                s[1],
                s[2],
                s[3],
                state.rho[i],
                state.eps_p[i],
                state.temp[i],
            ]
        })
        .collect();
    carry(c, n, setup.h, &mut f, &d);
    let mut ke = [0.0; 2];
    for (i, (fi, di)) in f.iter().zip(&d).enumerate() {
        if *di == [0.0; 2] {
            continue;
        }
        ke[0] += kinetic1(state.vel[i], setup.mass[i]);
        state.vel[i] = [fi[0], fi[1]];
        ke[1] += kinetic1(state.vel[i], setup.mass[i]);
        // Each component was limited to its neighbours' range on its
        // own, which leaves a trace: the deviator (RR, ZZ, TT, RZ) is
        // made trace-free again (the mean normal stress stays −P).
        let m = (fi[2] + fi[3] + fi[4]) / 3.0;
        state.dev[i] = [fi[2] - m, fi[3] - m, fi[4] - m, fi[5]];
        state.rho[i] = fi[6];
        state.eps_p[i] = fi[7].max(0.0);
        state.temp[i] = fi[8];
        let p = setup
            .material
            .pressure(fi[6], fi[8])
            .map_err(|l| Error::CompressionLimit {
                particle: i,
                time: state.clock.time,
                compression: l.compression,
                limit: l.limit,
            })?;
        state.pressure[i] = p;
        let s = state.dev[i];
        state.stress_bc[i] = [s[0] - p, s[1] - p, s[2] - p, s[3]];
        if state.contact[i] {
            state.stress_bc[i][3] = 0.0;
        }
        state.pos[i] = [state.pos[i][0] + di[0], state.pos[i][1] + di[1]];
    }
    state.energy.lost[LOST_SMOOTHING] += ke[0] - ke[1];
    // A surface particle that slid carries the stress of its new place:
    // the traction-free condition again, on the new normals.
    let slid = |s: &Surface| s.particles.iter().any(|&i| d[i] != [0.0; 2]);
    if slid(&setup.mantle) || slid(&setup.top) {
        surfaces::apply_surface_stress_bc(setup, state);
    }
    Ok(true)
}

/// Moves crowded particles off the axis ([`leaving`]): each leaves by
/// [`AXIS_LEAVE`] along R, on top of its shift along Z, and from then on
/// is a ring with its own mirror image.
fn leave_axis(
    setup: &SetupAxi,
    state: &mut StateAxi,
    free: &[Freedom],
    spacing: f64,
    d: &mut [[f64; 2]],
) {
    let column: Vec<usize> = (0..state.pos.len())
        .step_by(setup.nr)
        .filter(|&i| state.on_axis[i])
        .collect();
    let z: Vec<f64> = column.iter().map(|&i| state.pos[i][1]).collect();
    let may: Vec<bool> = column
        .iter()
        .map(|&i| free[i] == Freedom::Across([1.0, 0.0]))
        .collect();
    for (&i, leaves) in column.iter().zip(leaving(&z, &may, AXIS_CROWD * spacing)) {
        if leaves {
            d[i] = [AXIS_LEAVE * spacing, d[i][1]];
            state.on_axis[i] = false;
        }
    }
}
