//! The mirror images and the candidate neighbour lists of the axisymmetric
//! solver, with a skin: built from the positions, and built again once a
//! particle has moved more than half the skin or the images change.

use super::mirror::{Image, Mirror, fill_images};
use super::workspace::{BatchTally, KineticChange, Tally, Workspace};
use super::{MIN_LEN, SKIN, SetupAxi, StateAxi};
use crate::kernel::SUPPORT;
use crate::lanes::W;
use crate::neighbours::padded_rows;
use crate::solver::axisymmetric::pairs::PairPass;
use crate::solver::axisymmetric::scheme::SmoothingOrder;
use crate::solver::shared::SPACING_COLLAPSE_BOUND;

/// Height above the anvil below which a particle counts as on it and has
/// no mirror image across it: half the spacing guard, so that a particle
/// and its own image are never closer than the guard allows.
fn anvil_gap(setup: &SetupAxi) -> f64 {
    0.5 * SPACING_COLLAPSE_BOUND * setup.spacing()
}

/// Whether particle `i` is mirrored across the anvil: it lies within
/// `reach` of it and above [`Self::anvil_gap`], it is neither in contact
/// nor a particle of the impact face (the face row is the plane of
/// symmetry itself), and the face particle nearest to it in R is pressed
/// on the anvil. A mirror image carries tension as well as compression,
/// so above a part of the face that has left the anvil there is none:
/// that part is a free surface.
fn anvil_image(setup: &SetupAxi, state: &StateAxi, i: usize, reach: f64) -> bool {
    let [r, z] = state.pos[i];
    if i < setup.nr || state.contact[i] || z < anvil_gap(setup) || z >= reach {
        return false;
    }
    let nearest = (0..setup.nr)
        .min_by(|&a, &b| {
            let (da, db) = ((state.pos[a][0] - r).abs(), (state.pos[b][0] - r).abs());
            da.total_cmp(&db)
        })
        .expect("a face row");
    state.contact[nearest]
}

/// Rebuilds the mirror images and the candidate neighbour lists, with a
/// skin of [`SKIN`] h, from the current positions.
pub(super) fn rebuild_neighbours(setup: &SetupAxi, state: &StateAxi, ws: &mut Workspace) {
    let n = state.pos.len();
    let nr = setup.nr;
    let reach = (SUPPORT + SKIN) * setup.h;
    ws.lists.images.clear();
    for i in 0..n {
        let axis = !state.on_axis[i] && state.pos[i][0] < reach;
        let anvil = anvil_image(setup, state, i, reach);
        let source = i as u32;
        for (yes, mirror) in [
            (axis, Mirror::Axis),
            (anvil, Mirror::Anvil),
            (axis && anvil, Mirror::Both),
        ] {
            if yes {
                ws.lists.images.push(Image { source, mirror });
            }
        }
    }
    let m = n + ws.lists.images.len();
    ws.fields.pos.resize(m, [0.0; 2]);
    ws.fields.pos[..n].copy_from_slice(&state.pos);
    fill_images(&mut ws.fields.pos, n, &ws.lists.images);
    ws.lists.stride = padded_rows(
        &ws.fields.pos,
        n,
        reach,
        W,
        ws.lists.stride,
        &mut ws.lists.nbr,
        &mut ws.lists.nbr_len,
    );
    let stride = ws.lists.stride;
    ws.lists.built_at.clear();
    ws.lists.built_at.extend_from_slice(&state.pos);
    ws.lists.face_contact.clear();
    ws.lists
        .face_contact
        .extend_from_slice(&state.contact[..nr]);
    ws.lists.axis_count = axis_count(state);
    // Whole batches of W rows.
    let rows = n.next_multiple_of(W) * stride;
    ws.rows.act.resize(rows, 0);
    ws.rows.wr.resize(rows, 0.0);
    ws.rows.wz.resize(rows, 0.0);
    ws.rows.wk.resize(rows, 0.0);
    ws.fields.vol.resize(m, 0.0);
    ws.fields.sbc.resize(m, [0.0; 4]);
    ws.fields.vel.resize(m, [0.0; 2]);
    ws.fields.vel_s.resize(m, [0.0; 2]);
    if setup.scheme.order == SmoothingOrder::BiLaplacian {
        ws.fields.lap.resize(m, [0.0; 2]);
        ws.fields.lap_rho.resize(m, [0.0]);
    }
    ws.fields.rho.resize(m, [0.0]);
    ws.rows.part.resize(n, PairPass::default());
    ws.grads.resize(n, [0.0; 4]);
    ws.sums.batches.resize(n.div_ceil(W), BatchTally::default());
    ws.sums
        .smoothing
        .resize(n.div_ceil(MIN_LEN), KineticChange::default());
    ws.sums
        .tallies
        .resize(n.div_ceil(MIN_LEN), Tally::default());
}

/// Whether a particle moved more than half the skin since the lists were
/// built (or they were never built), a particle mirrored across the
/// anvil has come down onto it (its image would meet it), or a particle
/// of the impact face has touched or left the anvil (which changes the
/// images).
pub(super) fn needs_rebuild(setup: &SetupAxi, state: &StateAxi, ws: &Workspace) -> bool {
    if ws.lists.built_at.len() != state.pos.len()
        || ws.lists.face_contact[..] != state.contact[..setup.nr]
        || ws.lists.axis_count != axis_count(state)
    {
        return true;
    }
    let gap = anvil_gap(setup);
    if ws.lists.images.iter().any(|im| {
        let i = im.source as usize;
        im.mirror == Mirror::Anvil && (state.contact[i] || state.pos[i][1] < gap)
    }) {
        return true;
    }
    let limit = 0.5 * SKIN * setup.h;
    let limit2 = limit * limit;
    state.pos.iter().zip(&ws.lists.built_at).any(|(x, x0)| {
        let (a, b) = (x[0] - x0[0], x[1] - x0[1]);
        a * a + b * b > limit2
    })
}

/// Number of particles on the axis (particles only ever leave it).
fn axis_count(state: &StateAxi) -> usize {
    state.on_axis.iter().filter(|&&a| a).count()
}
