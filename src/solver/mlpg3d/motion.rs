//! The passes of steps 2 and 3 (module docs of [`super`]): the velocity
//! update with the anvil's hold and release, the velocity smoothing, the
//! contact between bodies and between pulverized nodes, the clamp of a held
//! rim, and the position update with the anvil's stop. Each is a function
//! over the node fields it reads and writes; the energies they remove are
//! added to the accumulators passed in, in node order.

use super::contact;
use super::geometry::Geometry;
use super::scratch::{ContactBuffers, ImageBuffers, Kick, Move, SmoothingBuffers};
use super::util::extended;
use super::util::kinetic;
use super::util::pin;
use crate::Error;
use crate::approx::mirror;
use crate::error::Result;
use crate::material::Marks;
use crate::solver::mlpg3d::kinetic1;
use crate::solver::shared::SHIFT_RANGE;
use rayon::iter::IndexedParallelIterator;
use rayon::iter::IntoParallelRefIterator;
use rayon::iter::IntoParallelRefMutIterator;
use rayon::iter::ParallelIterator;

/// What the passes of steps 2 and 3 read and none writes.
pub(super) struct Frame<'a> {
    /// The step (s).
    pub(super) dt: f64,
    /// The time at the start of the step (s).
    pub(super) now: f64,
    /// The nodal form (the nodal mass as inertia) rather than the sphere's.
    pub(super) nodal: bool,
    /// The smallest initial distance between named nodes (m).
    pub(super) spacing: f64,
    /// The contact reach between bodies (m).
    pub(super) reach: f64,
    /// The geometry of the last build.
    pub(super) geometry: &'a Geometry,
    pub(super) mass: &'a [f64],
    pub(super) rho: &'a [f64],
    /// The body of each node (several bodies; else empty).
    pub(super) group: &'a [u8],
    /// The symmetry planes of each node (quarter model; else empty).
    pub(super) plane: &'a [u8],
    /// The nodes held still (else empty).
    pub(super) held: &'a [bool],
    /// The ranks that share the passes over the nodes ([`crate::ranks`]).
    pub(super) ranks: &'a dyn crate::ranks::Ranks,
}

/// The velocities `v += dt F / inertia`; a node on the anvil is held while
/// the anvil pushes it and released, its release timed, when its force
/// pulls it away; the symmetry planes and a held rim pin it.
pub(super) fn kick(
    frame: &Frame,
    force: &[[f64; 3]],
    vel: &mut [[f64; 3]],
    contact: &mut [bool],
    reaction: &mut [f64],
    kicks: &mut [Kick],
) {
    let Frame {
        dt,
        now,
        nodal,
        mass,
        rho,
        plane,
        held: still,
        ..
    } = *frame;
    let volume = &frame.geometry.op.volume;
    vel.par_iter_mut()
        .zip(contact.par_iter_mut())
        .zip(reaction.par_iter_mut())
        .zip(kicks.par_iter_mut())
        .enumerate()
        .for_each(|(i, (((v, touch), reaction), out))| {
            let f = force[i];
            let inertia = if nodal { mass[i] } else { rho[i] * volume[i] };
            // A node held on the anvil loses the speed it had toward it
            // (only at impact: afterwards it is zero); the anvil's
            // reaction on a node at rest does no work.
            let held = if *touch {
                0.5 * mass[i] * v[2] * v[2]
            } else {
                0.0
            };
            for d in 0..3 {
                v[d] += dt * f[d] / inertia;
            }
            // The release is timed where the net axial force, linear
            // between the last step's (−reaction ≤ 0) and this one's
            // (> 0), crosses zero (the last step's length taken as this
            // one's: they differ only at a rebuild).
            let mut released = None;
            if *touch {
                if f[2] > 0.0 {
                    *touch = false;
                    released = Some(now - dt * f[2] / (f[2] + *reaction));
                    *reaction = 0.0;
                } else {
                    v[2] = 0.0;
                    *reaction = -f[2];
                }
            }
            if let Some(&on) = plane.get(i) {
                pin(v, on);
            }
            // A node of a clamped rim: the clamp's reaction cancels the
            // force, and does no work on a node that does not move.
            if still.get(i) == Some(&true) {
                *v = [0.0; 3];
            }
            *out = Kick { held, released };
        });
}

/// The velocity smoothing toward the MLS approximation at the node, with
/// `alpha` and `order` of [`RodSetup::smoothing`] and
/// [`RodSetup::smoothing_order`]; returns the kinetic energy it removed.
pub(super) fn smooth(
    frame: &Frame,
    (alpha, order): (f64, u32),
    vel: &mut Vec<[f64; 3]>,
    contact: &[bool],
    buffers: &mut SmoothingBuffers,
    ext_vel: &mut Vec<[f64; 3]>,
) -> f64 {
    let (g, mass, plane) = (frame.geometry, frame.mass, frame.plane);
    let images = &g.mirror;
    let n = vel.len();
    let shapes = &g.shapes;
    let vel_ext = extended(images, vel, ext_vel, mirror::vector);
    // The defect `w = H v = (I − Φ) v`; with order 2 the filter
    // is `M⁻¹ Hᵀ M H v`, symmetric in the mass inner product: `M w`
    // goes straight to `pass`, `Hᵀ M w` to `defect`, and `M⁻¹` is
    // applied in the update.
    let order2 = order >= 2;
    let weighted = if order2 {
        &mut buffers.pass
    } else {
        &mut buffers.defect
    };
    let row = |i: usize, out: &mut [f64; 3]| {
        let mut m = [0.0; 3];
        for q in shapes.row(i) {
            let vj = vel_ext[shapes.nodes[q]];
            for d in 0..3 {
                m[d] += shapes.phi[q] * vj[d];
            }
        }
        let w: [f64; 3] = std::array::from_fn(|d| vel[i][d] - m[d]);
        *out = if order2 { w.map(|c| mass[i] * c) } else { w };
    };
    if order2 && !g.pass_send.is_empty() {
        // Only the rows another rank's transpose reads travel
        // ([`Geometry::pass_send`]); the rest of the other ranks' rows are
        // not read, and are set to NaN so that a read would show.
        let ranks = frame.ranks;
        let own = g.rows[ranks.rank()].clone();
        crate::ranks::each_own_row(ranks, &g.rows, weighted, row);
        weighted[..own.start].fill([f64::NAN; 3]);
        weighted[own.end..].fill([f64::NAN; 3]);
        let get = |o: &[[f64; 3]], i: usize| o[i];
        let put = |o: &mut [[f64; 3]], i: usize, v: &[f64; 3]| o[i] = *v;
        crate::ranks::gather_listed(
            ranks,
            &g.pass_send,
            &mut buffers.wire,
            &mut weighted[..],
            (get, put),
        );
    } else {
        crate::ranks::each_row_in(frame.ranks, &g.rows, weighted, row);
    }
    if order2 {
        buffers.defect.resize(n + images.len(), [0.0; 3]);
        g.nodal
            .defect_transpose_on(frame.ranks, &buffers.pass, &mut buffers.defect);
        images.fold(n, &mut buffers.defect);
    }
    let defect = &buffers.defect;
    let vel_now: &[[f64; 3]] = vel;
    buffers
        .smooth
        .par_iter_mut()
        .enumerate()
        .for_each(|(i, out)| {
            let vel = vel_now;
            let mut v: [f64; 3] = if order2 {
                std::array::from_fn(|d| vel[i][d] - alpha * (defect[i][d] / mass[i]))
            } else {
                std::array::from_fn(|d| vel[i][d] - alpha * defect[i][d])
            };
            if contact[i] {
                v[2] = 0.0;
            }
            if let Some(&on) = plane.get(i) {
                pin(&mut v, on);
            }
            *out = v;
        });
    let before = kinetic(vel, mass);
    std::mem::swap(vel, &mut buffers.smooth);
    before - kinetic(vel, mass)
}

/// The contact between the bodies ([`Frame::group`] non-empty), then between
/// pulverized nodes closer than half a spacing (`marks`, with damage):
/// in the quarter model on the nodes and their images, the pairs with a
/// real node, each resolved on the images' velocities too, and only the
/// real nodes' kept. The kinetic energy removed is added to `dissipation`.
pub(super) fn collide(
    frame: &Frame,
    pos: &[[f64; 3]],
    marks: Option<&[Marks]>,
    vel: &mut [[f64; 3]],
    buffers: &mut ContactBuffers,
    ext: &mut ImageBuffers,
    dissipation: &mut f64,
) {
    let images = &frame.geometry.mirror;
    let (mass_real, plane, group) = (frame.mass, frame.plane, frame.group);
    let n = pos.len();
    buffers.pairs.clear();
    // No contact pass in a run of one body without damage: no copy.
    let real_pos = pos;
    let pos: &[[f64; 3]] = if group.is_empty() && marks.is_none() {
        real_pos
    } else {
        extended(images, real_pos, &mut ext.pos, mirror::vector)
    };
    let group_ext: &[u8] = if group.is_empty() {
        &[]
    } else {
        extended(images, group, &mut ext.group, mirror::same)
    };
    if !group.is_empty() {
        contact::pairs(pos, group_ext, frame.reach, frame.ranks, &mut buffers.pairs);
    }
    if let Some(marks) = marks {
        buffers.loose.clear();
        buffers.loose.extend(marks.iter().map(Marks::is_pulverized));
        let loose = extended(images, &buffers.loose, &mut ext.loose, mirror::same);
        contact::loose_pairs(
            pos,
            group_ext,
            loose,
            SHIFT_RANGE * frame.spacing,
            &mut buffers.pairs,
        );
    }
    if !images.is_empty() {
        buffers.pairs.retain(|&(i, _)| i < n);
    }
    if buffers.pairs.is_empty() {
        return;
    }
    if images.is_empty() {
        *dissipation += contact::resolve(&buffers.pairs, real_pos, mass_real, &buffers.before, vel);
    } else {
        let mass = extended(images, mass_real, &mut ext.mass, mirror::same);
        let before = extended(images, &buffers.before, &mut ext.before, mirror::vector);
        images.extend(vel, &mut ext.vel, mirror::vector);
        *dissipation +=
            contact::resolve_with_images(&buffers.pairs, pos, mass, before, &mut ext.vel, n);
        vel.copy_from_slice(&ext.vel[..n]);
        // What an impulse gave a node on a plane across it, its
        // image's impulse takes back in the whole body.
        for ((v, &on), &m) in vel.iter_mut().zip(plane).zip(mass_real) {
            if on != 0 {
                let before = kinetic1(*v, m);
                pin(v, on);
                *dissipation += before - kinetic1(*v, m);
            }
        }
    }
}

/// A held node (a clamped rim) stays still: what the smoothing and the
/// contact gave it this step (the forces' share the clamp took at once, in
/// [`kick`]) the clamp takes back, added to `dissipation`.
pub(super) fn clamp(frame: &Frame, vel: &mut [[f64; 3]], dissipation: &mut f64) {
    for ((v, &m), _) in vel
        .iter_mut()
        .zip(frame.mass)
        .zip(frame.held)
        .filter(|(_, h)| **h)
    {
        *dissipation += kinetic1(*v, m);
        *v = [0.0; 3];
    }
}

/// The positions `x += dt v`; with the `anvil`, a node that reaches z = 0
/// stops on it (its kinetic energy toward it lost), and one that passes it
/// by half a spacing is marked ([`Move::through`]).
pub(super) fn drift(
    frame: &Frame,
    anvil: bool,
    vel: &mut [[f64; 3]],
    pos: &mut [[f64; 3]],
    contact: &mut [bool],
    kicks: &[Kick],
    moves: &mut [Move],
) {
    let (dt, d0, mass) = (frame.dt, frame.spacing, frame.mass);
    vel.par_iter_mut()
        .zip(pos.par_iter_mut())
        .zip(contact.par_iter_mut())
        .zip(kicks.par_iter())
        .zip(moves.par_iter_mut())
        .enumerate()
        .for_each(|(i, ((((v, x), touch), kick), out))| {
            let mut through = None;
            for d in 0..3 {
                x[d] += dt * v[d];
            }
            let mut lost = 0.0;
            if anvil && !*touch && x[2] < 0.0 {
                if x[2] < -0.5 * d0 {
                    through = Some(x[2]);
                }
                x[2] = 0.0;
                lost = 0.5 * mass[i] * v[2] * v[2];
                v[2] = 0.0;
                *touch = true;
            }
            *out = Move {
                held: kick.held,
                lost,
                released: kick.released,
                through,
            };
        });
}

/// Books the position update in node order: the anvil's dissipation into
/// `dissipation`, the latest release into `last_release`; the first node
/// through the anvil is the error [`Error::ThroughBoundary`] at `time`.
pub(super) fn settle(
    moves: &[Move],
    dissipation: &mut f64,
    last_release: &mut f64,
    time: f64,
) -> Result<()> {
    // (dissipation, latest release) of the nodes, the first node through
    // the anvil stopping the sum, in the fixed order of `sums`.
    let join = |a: Result<(f64, f64)>, b: Result<(f64, f64)>| {
        let ((d, r), (e, s)) = (a?, b?);
        Ok((d + e, r.max(s)))
    };
    let (lost, released) = crate::approx::sums::ordered(
        moves.len(),
        || Ok((0.0, f64::NEG_INFINITY)),
        |acc, i| {
            let (d, r) = acc?;
            let m = &moves[i];
            if let Some(z) = m.through {
                return Err(Error::ThroughBoundary {
                    particle: i,
                    boundary: "anvil",
                    time,
                    position: z,
                });
            }
            Ok((d + (m.held + m.lost), m.released.map_or(r, |t| r.max(t))))
        },
        join,
    )?;
    *dissipation += lost;
    *last_release = last_release.max(released);
    Ok(())
}

/// In the quarter model, a node crossing a symmetry plane has passed its
/// own image: the error [`Error::ThroughBoundary`] at `time`.
pub(super) fn check_planes(pos: &[[f64; 3]], plane: &[u8], time: f64) -> Result<()> {
    if plane.is_empty() {
        return Ok(());
    }
    match super::util::first_where(pos, |x| x[0] < 0.0 || x[1] < 0.0).map(|i| (i, pos[i])) {
        Some((i, x)) => Err(Error::ThroughBoundary {
            particle: i,
            boundary: "symmetry plane",
            time,
            position: x[0].min(x[1]),
        }),
        None => Ok(()),
    }
}
