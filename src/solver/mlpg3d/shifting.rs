//! Node shifting in the run ([`crate::solver::mlpg3d::shift`] holds the shifts and
//! the carry): who may move where, and the carry of the moved nodes'
//! fields.

use super::LOST_SMOOTHING;
use super::geometry::Geometry;
use super::scratch::CARRIED;
use super::scratch::Scratch;
use super::scratch::{ImageBuffers, ShiftBuffers};
use super::shift::Freedom;
use super::shift::carry_shifted_on;
use super::shift::exchange;
use super::shift::shifts_on;
use super::spheres::nanson;
use super::spheres::radial;
use super::util::extended;
use super::util::kinetic;
use super::util::material_of;
use super::util::pin;
use crate::Error;
use crate::approx::lattice::Surfaces;
use crate::approx::mirror;
use crate::error::Result;
use crate::material::Marks;
use crate::material::tensor::Full;
use crate::materials::Material;
use crate::solver::mlpg3d::Body;
use crate::solver::mlpg3d::Setup3d;
use crate::solver::mlpg3d::State3d;
use crate::solver::mlpg3d::kinetic1;
use crate::solver::shared::SHIFT_CAP;
use crate::solver::shared::SHIFT_RANGE;

/// Node shifting ([`super::shift`]): pushes apart the pairs closer than
/// [`SHIFT_RANGE`] of the initial spacing and carries the fields of the
/// moved nodes to their new places with the shapes of the last build.
/// An interior node on the anvil moves in its plane. With the sphere
/// form the surfaces (face, mantle, top) stay put (measured: letting
/// the surface nodes move in their tangent planes, the face nodes on
/// the anvil in its plane, made the Wilkins bar in 3-D stop earlier,
/// EnergyDrift at 44.7 µs against 55.6 µs); with the nodal form, which
/// has no test sphere to cut, a node of the mantle alone moves in the
/// mantle's tangent plane (its Nanson normal, as the sphere form's cut
/// planes) and a face node held on the anvil in the anvil's plane, while
/// edges, the top and the free face stay put (measured: with the mantle
/// fixed, two mantle nodes of the Wilkins bar's bulge close to the
/// guard at 59.6 µs; README, "3-D MLPG mixed method"). The moved nodes
/// take their stress, density, plastic strain, temperature and
/// reference place by [`carry_shifted_on`], and their velocities by [`carry_shifted_on`] or,
/// with [`RodSetup::conservative_carry`], by [`exchange`] (the momentum
/// drawn from the nodes around). The kinetic energy the carrying
/// changes is booked with the smoothing. A ceramic node whose tensile
/// cracks stand open moves but keeps its stress, density, plastic strain
/// and temperature, which hold its openings; the density carried to the
/// others is the matrix density (a neighbour's openings' volume left
/// out). Fails with the compression limit of the equation of state at a
/// moved node.
pub(super) fn shift(
    setup: &Setup3d,
    state: &mut State3d,
    (g, ranks): (&mut Geometry, &dyn crate::ranks::Ranks),
    scratch: &mut Scratch,
) -> Result<()> {
    // The frame of the shifting's passes over `geometry`.
    macro_rules! frame {
        ($geometry:expr) => {
            ShiftFrame {
                geometry: $geometry,
                spacing: setup.d_min0,
                anvil: setup.anvil,
                nodal: setup.rod.scheme.forces.nodal(),
                surfaces: &setup.lattice.surfaces,
                contact: &state.contact,
                plane: &setup.plane,
                held: &setup.held,
                mass: &setup.mass,
                // Without damage variables no point has any to read (the
                // same values as reading each point's empty ones, without
                // the visit).
                marks: if setup.damage_vars() {
                    state.material_state.marks()
                } else {
                    &[]
                },
                materials: (&setup.material, &setup.others, &setup.group),
                time: state.clock.time,
            }
        };
    }
    let frame = frame!(&*g);
    let (buffers, ext) = (&mut scratch.shifting, &mut scratch.images);
    let images = &g.mirror;
    let reference = extended(images, &state.reference, &mut ext.built, mirror::vector);
    // Only this rank's rows: the shifts read their own node's freedom.
    freedoms(&frame, ranks, reference, &mut buffers.free);
    let pos = extended(images, &state.pos, &mut ext.pos, mirror::vector);
    let (spacing, step_scale) = (frame.spacing, setup.rod.step_scale());
    shifts_on(
        (ranks, &g.rows),
        pos,
        &g.shapes,
        &buffers.free,
        (
            spacing,
            SHIFT_RANGE * spacing,
            setup.rod.scheme.shifting * step_scale,
            SHIFT_CAP * spacing * step_scale,
        ),
        (&mut buffers.shift, &mut buffers.shift_wire),
    );
    // A node on a symmetry plane moves in it; a held node stays.
    for (d, &on) in buffers.shift.iter_mut().zip(frame.plane) {
        pin(d, on);
    }
    for (d, _) in buffers
        .shift
        .iter_mut()
        .zip(frame.held)
        .filter(|(_, h)| **h)
    {
        *d = [0.0; 3];
    }
    if buffers.shift.iter().all(|d| *d == [0.0; 3]) {
        return Ok(());
    }
    let conservative = setup.rod.conservative_carry;
    if conservative {
        // The conservative carry reads every shifted node's row.
        g.held.follow_shifted(ranks, &mut g.shapes, &buffers.shift);
    }
    let frame = frame!(&*g);
    let mut fields = ShiftedFields {
        pos: &mut state.pos,
        vel: &mut state.vel,
        dev: &mut state.dev,
        pressure: &mut state.pressure,
        rho: &mut state.rho,
        eps_p: &mut state.eps_p,
        temp: &mut state.temp,
        reference: &mut state.reference,
    };
    let carried = pack_read(
        &fields,
        &frame,
        (ranks, &g.rows),
        &buffers.shift,
        (&mut buffers.carried, &mut buffers.read),
    );
    // Only the shifted nodes' rows: the unpacking reads no other.
    carry_shifted_on(
        (ranks, &g.rows),
        &g.shapes,
        carried,
        &buffers.shift,
        (&mut buffers.carried_out, &mut buffers.wire),
    );
    let mut ke = [0.0; 2];
    if conservative {
        ke[0] = kinetic(fields.vel, frame.mass);
        exchange_velocities(&frame, fields.vel, buffers, ext);
    }
    unpack(&frame, &mut fields, buffers, conservative, &mut ke)?;
    if conservative {
        ke[1] = kinetic(fields.vel, frame.mass);
    }
    state.energy.lost[LOST_SMOOTHING] += ke[0] - ke[1];
    state.shift_dissipation += ke[0] - ke[1];
    Ok(())
}

/// What the shifting reads and does not write.
struct ShiftFrame<'a> {
    geometry: &'a Geometry,
    /// The smallest initial distance between named nodes (m).
    spacing: f64,
    anvil: bool,
    nodal: bool,
    surfaces: &'a [Surfaces],
    contact: &'a [bool],
    plane: &'a [u8],
    held: &'a [bool],
    mass: &'a [f64],
    /// The marks of each node's damage variables (empty before the first
    /// step, and in a run whose materials keep no damage variables).
    marks: &'a [Marks],
    /// The rod's material, the further bodies and each node's body.
    materials: (&'a Material, &'a [Body], &'a [u8]),
    time: f64,
}

/// The node fields a shift moves or carries.
struct ShiftedFields<'a> {
    pos: &'a mut [[f64; 3]],
    vel: &'a mut [[f64; 3]],
    dev: &'a mut [Full],
    pressure: &'a mut [f64],
    rho: &'a mut [f64],
    eps_p: &'a mut [f64],
    temp: &'a mut [f64],
    reference: &'a mut [[f64; 3]],
}

/// How each node may move (`reference`: the reference places, extended
/// by the images): the nodes of this rank's part of the shapes' rows
/// ([`shifts_on`]'s).
fn freedoms(
    frame: &ShiftFrame,
    ranks: &dyn crate::ranks::Ranks,
    reference: &[[f64; 3]],
    free: &mut [Freedom],
) {
    let (surf, contact, anvil, nodal) = (frame.surfaces, frame.contact, frame.anvil, frame.nodal);
    let (shapes, marks) = (&frame.geometry.shapes, frame.marks);
    crate::ranks::each_own_row(ranks, &frame.geometry.rows, free, |i, f| {
        // A pulverized node stays put: its ceramic state (pulverized,
        // its porosity) is not carried, so carrying its neighbours'
        // stress and density to it created energy (the penetration at
        // 4 across: energy error 18.8 % against 0.46 % with it fixed;
        // README, "Ballistic penetration"); the contact of pulverized
        // nodes keeps them apart.
        // A node whose tensile cracks stand open moves, but keeps its
        // stress and density ([`unpack`]): held still, such nodes under
        // the rod's edge collapsed (`ad85_planes` at 800 m/s, 6 across:
        // spacing collapse at 6.0 µs).
        let pulverized = marks.get(i).is_some_and(Marks::is_pulverized);
        *f = if pulverized {
            Freedom::Fixed
        } else if !anvil {
            Freedom::Unbounded
        } else if nodal && surf[i] == Surfaces(Surfaces::MANTLE) {
            // F⁻¹ = ∂X/∂x at this node only (eq. 4 on the reference places).
            let finv = shapes.gradient(i, reference);
            Freedom::InPlane(nanson(&finv, radial(reference[i])))
        } else if nodal && surf[i] == Surfaces(Surfaces::FACE) && contact[i] {
            Freedom::InPlane([0.0, 0.0, 1.0])
        } else if !surf[i].interior() {
            Freedom::Fixed
        } else if contact[i] {
            Freedom::InPlane([0.0, 0.0, 1.0])
        } else {
            Freedom::Free
        };
    });
}

/// The carried fields ([`CARRIED`]) of the columns that the carry of this
/// rank's shifted nodes reads ([`carry_shifted_on`] over `parts`): each
/// such node's and those of its shapes' row (an image's reflected from
/// its node), written into `out` (the columns: the nodes, then the
/// images); every other entry is left as it was, and nothing reads it.
/// Each column is packed once (`read`, a buffer, marks those packed).
/// (Every node packed and the images extended cost every rank of
/// `penetration`, 8 across, about 0.9 ms a step for the few dozen nodes
/// that shift.)
fn pack_read<'a>(
    fields: &ShiftedFields,
    frame: &ShiftFrame,
    (ranks, parts): (&dyn crate::ranks::Ranks, &[std::ops::Range<usize>]),
    shift: &[[f64; 3]],
    (out, read): (&'a mut Vec<[f64; CARRIED]>, &mut Vec<bool>),
) -> &'a [[f64; CARRIED]] {
    let (images, shapes) = (&frame.geometry.mirror, &frame.geometry.shapes);
    let n = fields.pos.len();
    let columns = n + images.source.len();
    out.resize(columns, [0.0; CARRIED]);
    read.clear();
    read.resize(columns, false);
    let shifted = || {
        parts[ranks.rank()]
            .clone()
            .filter(|&i| shift[i] != [0.0; 3])
    };
    let row = |i: usize| std::iter::once(i).chain(shapes.row(i).map(|q| shapes.nodes[q]));
    for j in shifted().flat_map(row) {
        if !read[j] {
            read[j] = true;
            out[j] = if j < n {
                pack(fields, frame.marks, j)
            } else {
                let k = j - n;
                reflect_carried(&pack(fields, frame.marks, images.source[k]), images.flip[k])
            };
        }
    }
    out
}

/// The carried fields of node `i` ([`CARRIED`]).
fn pack(fields: &ShiftedFields, marks: &[Marks], i: usize) -> [f64; CARRIED] {
    let (v, s, x) = (fields.vel[i], fields.dev[i], fields.reference[i]);
    let opened = marks.get(i).map_or(0.0, Marks::opened);
    [
        v[0],
        v[1],
        v[2],
        s[0],
        s[1],
        s[2],
        s[3],
        s[4],
        s[5],
        fields.rho[i] * (1.0 + opened),
        fields.eps_p[i],
        fields.temp[i],
        x[0],
        x[1],
        x[2],
    ]
}

/// The conservative carry's velocities ([`exchange`]): each moved node's
/// momentum increment drawn from the nodes around it (the images'
/// increments folded onto their nodes), then the anvil and the planes
/// pin them.
fn exchange_velocities(
    frame: &ShiftFrame,
    vel: &mut [[f64; 3]],
    buffers: &mut ShiftBuffers,
    ext: &mut ImageBuffers,
) {
    let (images, n) = (&frame.geometry.mirror, vel.len());
    let vel_ext = extended(images, vel, &mut ext.vel, mirror::vector);
    let mass = extended(images, frame.mass, &mut ext.mass, mirror::same);
    exchange(
        &frame.geometry.shapes,
        vel_ext,
        mass,
        &buffers.shift,
        &mut buffers.share,
        &mut buffers.momentum,
    );
    images.fold(n, &mut buffers.momentum);
    for (i, p) in buffers.momentum.iter().enumerate().take(n) {
        if *p == [0.0; 3] {
            continue;
        }
        let v = &mut vel[i];
        for k in 0..3 {
            v[k] += p[k] / frame.mass[i];
        }
        if frame.contact[i] {
            v[2] = 0.0;
        }
        if let Some(&on) = frame.plane.get(i) {
            pin(v, on);
        }
    }
}

/// The moved nodes take their carried fields (their velocities too unless
/// `conservative`, their kinetic energy before and after added to `ke`),
/// the pressure of their new density and temperature, and their new
/// places. Fails with the compression limit at a moved node.
fn unpack(
    frame: &ShiftFrame,
    fields: &mut ShiftedFields,
    buffers: &ShiftBuffers,
    conservative: bool,
    ke: &mut [f64; 2],
) -> Result<()> {
    let (rod, others, group) = frame.materials;
    let mass = frame.mass;
    for (i, (f, di)) in buffers.carried_out.iter().zip(&buffers.shift).enumerate() {
        if *di == [0.0; 3] {
            continue;
        }
        if !conservative {
            ke[0] += kinetic1(fields.vel[i], mass[i]);
            let mut v = [f[0], f[1], f[2]];
            if frame.contact[i] {
                v[2] = 0.0;
            }
            if let Some(&on) = frame.plane.get(i) {
                pin(&mut v, on);
            }
            fields.vel[i] = v;
            ke[1] += kinetic1(v, mass[i]);
        }
        fields.reference[i] = [f[12], f[13], f[14]];
        fields.pos[i] = std::array::from_fn(|k| fields.pos[i][k] + di[k]);
        if frame
            .marks
            .get(i)
            .is_some_and(|m| m.has_open_cracks() || m.is_jh2())
        {
            // A node whose tensile cracks stand open keeps its stress,
            // density and heat: they hold its openings, which are its own.
            // So does a JH-2 node: its damage and bulking are its own, and
            // its pressure that of its density.
            // Measured (`ad85_planes` at 800 m/s, 6 across, quarter): with
            // its neighbours' stress and matrix density carried to it,
            // EnergyDrift at 15.4 µs; kept, energy error 0.05 % at 20 µs.
            continue;
        }
        // Each component was limited to its neighbours' range on its
        // own, which leaves a trace: the deviator is made trace-free
        // again (the mean normal stress stays −P).
        let m = (f[3] + f[4] + f[5]) / 3.0;
        fields.dev[i] = [f[3] - m, f[4] - m, f[5] - m, f[6], f[7], f[8]];
        // The matrix density was carried: the node's own openings take
        // their volume out of it again.
        let opened = frame.marks.get(i).map_or(0.0, Marks::opened);
        fields.rho[i] = f[9] / (1.0 + opened);
        fields.eps_p[i] = f[10];
        fields.temp[i] = f[11];
        fields.pressure[i] = material_of(rod, others, group, i)
            .pressure(fields.rho[i], f[11])
            .map_err(|l| Error::CompressionLimit {
                particle: i,
                time: frame.time,
                compression: l.compression,
                limit: l.limit,
            })?;
    }
    Ok(())
}

/// The carried fields of a shifted node reflected ([`CARRIED`]).
pub(super) fn reflect_carried(f: &[f64; CARRIED], flip: u8) -> [f64; CARRIED] {
    let v = mirror::vector(&[f[0], f[1], f[2]], flip);
    let s = mirror::tensor(&[f[3], f[4], f[5], f[6], f[7], f[8]], flip);
    let x = mirror::vector(&[f[12], f[13], f[14]], flip);
    [
        v[0], v[1], v[2], s[0], s[1], s[2], s[3], s[4], s[5], f[9], f[10], f[11], x[0], x[1], x[2],
    ]
}
