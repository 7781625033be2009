//! The node lattice of a solid cylinder (radius `R0`, length `L0`, axis along
//! z, impact face at z = 0): concentric rings in equally spaced layers.
//!
//! # The lattice
//!
//! With `n` rings across the radius the radial spacing is `Δ = R0 / n`.
//! Ring `k` (k = 0..=n) lies at radius `k Δ` and holds `6 k` nodes (one on
//! the axis for k = 0), at the angles `2π l / (6 k)`, so every ring has a
//! node at angle 0 and the nodes of a ring are `2π k Δ / (6 k) ≈ 1.047 Δ`
//! apart: a hexagon-like pattern of nearly uniform density. The layers lie
//! at `z = j Δz`, j = 0..=nz, with `nz = round(L0 / Δ)` and `Δz = L0 / nz`.
//! The outermost ring lies on the mantle, the first and last layers on the
//! face and the top: the global boundary carries nodes, as the seed's
//! boundary treatment (section 3.2) expects.
//!
//! # The nodal volumes (lumped mass)
//!
//! A node carries its share of the annulus of its ring, `(k ± 1/2) Δ`
//! clipped to `[0, R0]`, times its share of the layer, `j Δz ± Δz / 2`
//! clipped to `[0, L0]`, divided by the number of nodes of the ring:
//! `π (Δ/2)²` for the axis node, `(π/3) Δ²` for an inner ring node and
//! `π (R0² − (R0 − Δ/2)²) / (6 n)` on the mantle. The volumes sum to
//! `π R0² L0` exactly: measured with a compensated sum, a relative error of
//! at most 2.2e-16 (one ulp) for n = 1..=12 (77 to 56 749 nodes). Each
//! node's mass is `ρ V`.
//!
//! For comparison, a simple cubic lattice of spacing `Δ` clipped to the
//! cylinder (cell centres inside the circle, each carrying `Δ³`) misses the
//! cross-section by a staircase error that does not fall monotonically:
//! measured +7.0 %, +1.9 %, +0.16 %, +0.59 % of `π R0²` for 5, 10, 15, 20
//! cells across the diameter — and its mantle nodes are not on the mantle,
//! so the rod observables would start from a ragged radius. That is why
//! the rings are used.

use crate::rod::RodSets;
use std::f64::consts::PI;

/// Which parts of the global boundary a node lies on (bit flags).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub struct Surfaces(pub u8);

impl Surfaces {
    /// The impact face, z = 0.
    pub const FACE: u8 = 1;
    /// The free end, z = L0.
    pub const TOP: u8 = 2;
    /// The mantle, √(x² + y²) = R0.
    pub const MANTLE: u8 = 4;

    /// True when the node lies on the surface `flag`.
    pub fn has(self, flag: u8) -> bool {
        self.0 & flag != 0
    }

    /// True when the node lies on no part of the boundary.
    pub fn interior(self) -> bool {
        self.0 == 0
    }
}

/// A solid cylinder with its axis along z and its base (the impact face) at
/// z = 0.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Cylinder {
    /// Radius R0 (m).
    pub radius: f64,
    /// Length L0 (m).
    pub length: f64,
}

impl Cylinder {
    /// Volume π R0² L0.
    pub fn volume(&self) -> f64 {
        PI * self.radius * self.radius * self.length
    }

    /// Distance from a point inside the cylinder to its surface (the
    /// nearest of the mantle, the face and the top); zero on the surface.
    pub fn distance_to_surface(&self, p: &[f64; 3]) -> f64 {
        let rho = (p[0] * p[0] + p[1] * p[1]).sqrt();
        (self.radius - rho)
            .min(p[2])
            .min(self.length - p[2])
            .max(0.0)
    }
}

/// The nodes of a cylinder on the ring lattice, in structure-of-arrays form.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct NodeLattice {
    /// The cylinder filled.
    pub cylinder: Cylinder,
    /// Node positions (m).
    pub position: Vec<[f64; 3]>,
    /// Nodal volumes (m³); they sum to the cylinder's volume.
    pub volume: Vec<f64>,
    /// The parts of the boundary each node lies on.
    pub surfaces: Vec<Surfaces>,
    /// The face, one mantle generator (angle 0, face to top) and the tail
    /// (the axis node of the top layer), for `RodObservables` (`src/rod.rs`).
    pub sets: RodSets,
    /// Radial spacing Δ = R0 / rings (m).
    pub radial_spacing: f64,
    /// Axial spacing Δz = L0 / layers (m).
    pub axial_spacing: f64,
}

impl NodeLattice {
    /// The ring lattice of `cylinder` with `rings ≥ 1` rings across the
    /// radius (the radial spacing is `R0 / rings`).
    pub fn cylinder(cylinder: Cylinder, rings: usize) -> Self {
        Self::cylinder_with(cylinder, rings, false)
    }

    /// The ring lattice, with the odd layers turned by half a node's angle
    /// on every ring when `staggered` (ring `k` of an odd layer at the
    /// angles `2π (l + 1/2) / (6 k)`): the nodes of neighbouring layers
    /// then interleave instead of standing on the same radial lines, so
    /// that layers pressed together over the impact face, whose rings
    /// have spread to several times their spacing around the
    /// circumference, still fill the gaps between each other's nodes
    /// (README, "3-D MLPG mixed method": the staggered lattice). Each
    /// layer keeps its six-fold symmetry and its mirror symmetry in the
    /// planes `x = 0` and `y = 0`; the volumes and surfaces are the same.
    /// The mantle generator of [`NodeLattice::sets`] then zig-zags by half
    /// a node's angle from layer to layer (its nodes' radii are what the
    /// rod observables read).
    pub fn cylinder_with(cylinder: Cylinder, rings: usize, staggered: bool) -> Self {
        let rings = rings.max(1);
        let (r0, l0) = (cylinder.radius, cylinder.length);
        let dr = r0 / rings as f64;
        let layers = ((l0 / dr).round() as usize).max(1);
        let dz = l0 / layers as f64;
        // Area per node of each ring: the annulus (k ± 1/2) Δ clipped to R0.
        let ring_area = |k: usize| {
            let outer = ((k as f64 + 0.5) * dr).min(r0);
            let inner = ((k as f64 - 0.5) * dr).max(0.0);
            PI * (outer * outer - inner * inner) / nodes_on_ring(k) as f64
        };
        let per_layer: usize = (0..=rings).map(nodes_on_ring).sum();
        let n = per_layer * (layers + 1);
        let mut lattice = NodeLattice {
            cylinder,
            position: Vec::with_capacity(n),
            volume: Vec::with_capacity(n),
            surfaces: Vec::with_capacity(n),
            sets: RodSets::default(),
            radial_spacing: dr,
            axial_spacing: dz,
        };
        for j in 0..=layers {
            let z = if j == layers { l0 } else { j as f64 * dz };
            let thickness = if j == 0 || j == layers { dz / 2.0 } else { dz };
            for k in 0..=rings {
                let r = if k == rings { r0 } else { k as f64 * dr };
                let count = nodes_on_ring(k);
                let turn = if staggered && j % 2 == 1 { 0.5 } else { 0.0 };
                for l in 0..count {
                    let theta = 2.0 * PI * (l as f64 + turn) / count as f64;
                    let i = lattice.position.len();
                    let mut s = 0;
                    if j == 0 {
                        s |= Surfaces::FACE;
                        lattice.sets.face.push(i);
                    }
                    if j == layers {
                        s |= Surfaces::TOP;
                        if k == 0 {
                            lattice.sets.tail = i;
                        }
                    }
                    if k == rings {
                        s |= Surfaces::MANTLE;
                        if l == 0 {
                            lattice.sets.mantle.push(i);
                        }
                    }
                    lattice.position.push([r * theta.cos(), r * theta.sin(), z]);
                    lattice.volume.push(ring_area(k) * thickness);
                    lattice.surfaces.push(Surfaces(s));
                }
            }
        }
        lattice
    }

    /// The quarter `x ≥ 0`, `y ≥ 0` of the lattice (the quarter model,
    /// `src/approx/mirror.rs`), with the planes each kept node lies on (bits
    /// `X`, `Y` of `src/approx/mirror.rs`). A node on a plane (the
    /// ring nodes at angles 0 and π/2, the axis) is put exactly on it and
    /// keeps its share of its volume: half, a quarter on the axis. The
    /// volumes sum to a quarter of the cylinder's; the sets keep the face
    /// nodes of the quarter, the mantle generator (at angle 0) and the tail.
    pub fn quarter(&self) -> (Self, Vec<u8>) {
        use crate::approx::mirror::{X, Y};
        let tol = 1e-9 * self.radial_spacing;
        let mut index = vec![usize::MAX; self.len()];
        let mut out = NodeLattice {
            cylinder: self.cylinder,
            position: Vec::new(),
            volume: Vec::new(),
            surfaces: Vec::new(),
            sets: RodSets::default(),
            radial_spacing: self.radial_spacing,
            axial_spacing: self.axial_spacing,
        };
        let mut plane = Vec::new();
        for (i, p) in self.position.iter().enumerate() {
            if p[0] < -tol || p[1] < -tol {
                continue;
            }
            let mut on = 0;
            let mut q = *p;
            let mut share = 1.0;
            if q[0].abs() <= tol {
                q[0] = 0.0;
                on |= X;
                share *= 0.5;
            }
            if q[1].abs() <= tol {
                q[1] = 0.0;
                on |= Y;
                share *= 0.5;
            }
            index[i] = out.position.len();
            out.position.push(q);
            out.volume.push(self.volume[i] * share);
            out.surfaces.push(self.surfaces[i]);
            plane.push(on);
        }
        let keep = |list: &[usize]| -> Vec<usize> {
            list.iter()
                .filter(|&&i| index[i] != usize::MAX)
                .map(|&i| index[i])
                .collect()
        };
        out.sets = RodSets {
            face: keep(&self.sets.face),
            mantle: keep(&self.sets.mantle),
            tail: index[self.sets.tail],
        };
        (out, plane)
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.position.len()
    }

    /// The nodes in the order of [`bisection_order`] of their positions,
    /// with the nodes' `extra` values (the symmetry planes of the quarter
    /// model, say) and the sets following them.
    pub fn bisected<T: Copy>(&self, extra: &[T]) -> (Self, Vec<T>) {
        let order = bisection_order(&self.position);
        let mut index = vec![0; order.len()];
        for (new, &old) in order.iter().enumerate() {
            index[old] = new;
        }
        let out = NodeLattice {
            cylinder: self.cylinder,
            position: order.iter().map(|&i| self.position[i]).collect(),
            volume: order.iter().map(|&i| self.volume[i]).collect(),
            surfaces: order.iter().map(|&i| self.surfaces[i]).collect(),
            sets: RodSets {
                face: self.sets.face.iter().map(|&i| index[i]).collect(),
                mantle: self.sets.mantle.iter().map(|&i| index[i]).collect(),
                tail: index.get(self.sets.tail).copied().unwrap_or(self.sets.tail),
            },
            radial_spacing: self.radial_spacing,
            axial_spacing: self.axial_spacing,
        };
        let extra = if extra.is_empty() {
            Vec::new()
        } else {
            order.iter().map(|&i| extra[i]).collect()
        };
        (out, extra)
    }

    /// True when there are no nodes.
    pub fn is_empty(&self) -> bool {
        self.position.is_empty()
    }

    /// The outward unit normals of the boundary planes through node `i`
    /// (none inside, one on a face or the mantle, two on an edge), as the
    /// local frame `[e1, e2, e3]` (e1 radial, e2 tangential, e3 = z) and
    /// the sign of each frame axis that points out of the body (0 when that
    /// axis is not cut): the input of [`crate::approx::sphere::TestSphere`].
    pub fn boundary_frame(&self, i: usize) -> ([[f64; 3]; 3], [i8; 3]) {
        let p = self.position[i];
        let rho = (p[0] * p[0] + p[1] * p[1]).sqrt();
        let (c, s) = if rho > 0.0 {
            (p[0] / rho, p[1] / rho)
        } else {
            (1.0, 0.0)
        };
        let frame = [[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]];
        let f = self.surfaces[i];
        let mut out = [0i8; 3];
        if f.has(Surfaces::MANTLE) {
            out[0] = 1;
        }
        if f.has(Surfaces::FACE) {
            out[2] = -1;
        } else if f.has(Surfaces::TOP) {
            out[2] = 1;
        }
        (frame, out)
    }
}

/// Nodes on ring `k`: one on the axis, `6 k` on the others.
fn nodes_on_ring(k: usize) -> usize {
    if k == 0 { 1 } else { 6 * k }
}

/// Nodes a leaf of [`bisection_order`]: within a leaf the nodes keep
/// their order (ascending index).
const BISECTION_LEAF: usize = 64;

/// The indices of `points` in the order of a recursive coordinate
/// bisection: the points are halved by count across the longest side of
/// their bounding box (the lower coordinate first, ties by index), and
/// each half is ordered the same way, down to [`BISECTION_LEAF`] points,
/// which keep their order. Every contiguous range of the order is then a
/// few compact pieces of space, whatever the body's shape: what the ranks'
/// parts of the nodes, which are ranges of the nodes' order, need (the
/// rings' layer-by-layer order cuts a thin, wide plate into layers, each
/// read across its whole face by the next: docs/notes/2026-12-02-mpi-eleventh-steps.md).
/// A function of the points alone: the same order on every rank.
pub fn bisection_order(points: &[[f64; 3]]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..points.len()).collect();
    bisect(points, &mut order);
    order
}

/// [`bisection_order`] of the points of `part`, in place.
fn bisect(points: &[[f64; 3]], part: &mut [usize]) {
    if part.len() <= BISECTION_LEAF {
        part.sort_unstable();
        return;
    }
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for &i in part.iter() {
        for d in 0..3 {
            lo[d] = lo[d].min(points[i][d]);
            hi[d] = hi[d].max(points[i][d]);
        }
    }
    let axis = (0..3).fold(0, |a, d| if hi[d] - lo[d] > hi[a] - lo[a] { d } else { a });
    part.sort_by(|&a, &b| points[a][axis].total_cmp(&points[b][axis]).then(a.cmp(&b)));
    let (first, second) = part.split_at_mut(part.len() / 2);
    bisect(points, first);
    bisect(points, second);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rod::RodObservables;

    #[test]
    fn ring_lattice_volumes_sum_to_the_cylinder() {
        let cyl = Cylinder {
            radius: 3.8e-3,
            length: 38e-3,
        };
        for (rings, staggered) in (1..=12).flat_map(|r| [(r, false), (r, true)]) {
            let lat = NodeLattice::cylinder_with(cyl, rings, staggered);
            // Compensated (Neumaier) sum: the error left is the lattice's.
            let (mut total, mut comp) = (0.0f64, 0.0f64);
            for &v in &lat.volume {
                let t = total + v;
                comp += if total.abs() >= v.abs() {
                    (total - t) + v
                } else {
                    (v - t) + total
                };
                total = t;
            }
            let err = ((total + comp) / cyl.volume() - 1.0).abs();
            assert!(err < 1e-15, "rings {rings}: {err:e}");
            // Every node inside or on the cylinder, on the boundary iff tagged.
            for (p, s) in lat.position.iter().zip(&lat.surfaces) {
                let d = cyl.distance_to_surface(p);
                assert!(d >= 0.0);
                assert_eq!(d < 1e-12 * cyl.length, !s.interior(), "{p:?}");
            }
            let per_layer = 1 + 3 * rings * (rings + 1);
            assert_eq!(lat.len() % per_layer, 0);
            assert_eq!(lat.sets.face.len(), per_layer);
            // Staggered: a ring node of layer 1 stands half a node's angle
            // from the nodes of its ring in layer 0, otherwise above one.
            for (i, p) in lat.position[per_layer..2 * per_layer].iter().enumerate() {
                let below = lat.position[i];
                let r = below[0].hypot(below[1]);
                if r == 0.0 {
                    continue;
                }
                let k = (r / lat.radial_spacing).round();
                let turned = (p[1].atan2(p[0]) - below[1].atan2(below[0])).rem_euclid(2.0 * PI);
                let want = if staggered { PI / (6.0 * k) } else { 0.0 };
                assert!((turned - want).abs() < 1e-12, "rings {rings}, node {i}");
            }
        }
    }

    /// The quarter keeps a quarter of the volume (to round-off), every
    /// node of the full lattice is one of its nodes or an image of one (the
    /// staggered lattice too: it keeps the mirror symmetry), and the nodes
    /// on the planes are exactly on them.
    #[test]
    fn the_quarter_is_a_quarter() {
        use crate::approx::mirror::{X, Y, vector};
        let cyl = Cylinder {
            radius: 5e-3,
            length: 10e-3,
        };
        for (rings, staggered) in (1..=6).flat_map(|r| [(r, false), (r, true)]) {
            let full = NodeLattice::cylinder_with(cyl, rings, staggered);
            let (q, plane) = full.quarter();
            let v: f64 = q.volume.iter().sum();
            assert!(
                (4.0 * v / cyl.volume() - 1.0).abs() < 1e-14,
                "rings {rings}"
            );
            for (p, &on) in q.position.iter().zip(&plane) {
                assert!(p[0] >= 0.0 && p[1] >= 0.0);
                assert_eq!(on & X != 0, p[0] == 0.0);
                assert_eq!(on & Y != 0, p[1] == 0.0);
            }
            let close = |a: &[f64; 3], b: &[f64; 3]| (0..3).all(|d| (a[d] - b[d]).abs() < 1e-12);
            for p in &full.position {
                assert!(
                    q.position
                        .iter()
                        .any(|r| (0..4).any(|f| close(&vector(r, f), p))),
                    "{p:?}"
                );
            }
            assert_eq!(q.sets.mantle.len(), full.sets.mantle.len());
            assert_eq!(q.position[q.sets.tail], [0.0, 0.0, cyl.length]);
        }
    }

    #[test]
    fn rod_observables_of_the_undeformed_lattice() {
        let cyl = Cylinder {
            radius: 3.8e-3,
            length: 38e-3,
        };
        let lat = NodeLattice::cylinder(cyl, 4);
        let mut vel = vec![[0.0; 3]; lat.len()];
        for v in &mut vel {
            v[2] = -181.0;
        }
        let o = RodObservables::of::<3>(&lat.sets, &lat.position, &vel, cyl.radius);
        assert_eq!(o.rod_length, cyl.length);
        assert!((o.mushroom_radius - cyl.radius).abs() < 1e-15);
        assert!((o.undeformed_length - cyl.length).abs() < 1e-15);
        assert_eq!(o.tail_velocity, 181.0);
        // The mantle generator runs from the face to the top at angle 0.
        let m = &lat.sets.mantle;
        assert_eq!(m.len(), 41);
        assert!(
            m.windows(2)
                .all(|w| lat.position[w[1]][2] > lat.position[w[0]][2])
        );
        assert!(m.iter().all(|&i| lat.position[i][1] == 0.0));
        assert_eq!(lat.position[lat.sets.tail], [0.0, 0.0, cyl.length]);
    }

    /// The bisection's order of a thin, wide plate (a quarter, 20 rings,
    /// 4 layers: 1 715 nodes) is a permutation that carries each node's
    /// volume, surfaces, plane and sets with it; its first half lies on
    /// one side of a plane across the plate's longest side; and its
    /// contiguous quarters are compact: the nodes with a neighbour (within
    /// 1.5 spacings) in another quarter are under a third of those of the
    /// rings' layer-by-layer quarters (the measured reason for the order:
    /// docs/notes/2026-12-02-mpi-eleventh-steps.md).
    #[test]
    fn the_bisection_order_cuts_a_plate_into_compact_pieces() {
        let plate = Cylinder {
            radius: 20.0,
            length: 4.0,
        };
        let (lat, plane) = NodeLattice::cylinder(plate, 20).quarter();
        let (cut, on) = lat.bisected(&plane);
        let n = lat.len();
        let order = bisection_order(&lat.position);
        let mut seen = vec![false; n];
        for (new, &old) in order.iter().enumerate() {
            assert!(!seen[old], "node {old} twice");
            seen[old] = true;
            assert_eq!(cut.position[new], lat.position[old]);
            assert_eq!(cut.volume[new], lat.volume[old]);
            assert_eq!(cut.surfaces[new], lat.surfaces[old]);
            assert_eq!(on[new], plane[old]);
        }
        for (&a, &b) in cut.sets.face.iter().zip(&lat.sets.face) {
            assert_eq!(cut.position[a], lat.position[b]);
        }
        // The first cut: across x or y (the quarter is 20 wide, 4 thick).
        let half = n / 2;
        let axis = if (0..half).all(|i| cut.position[i][0] <= cut.position[half][0]) {
            0
        } else {
            1
        };
        let edge = (0..half)
            .map(|i| cut.position[i][axis])
            .fold(f64::MIN, f64::max);
        assert!(
            (half..n).all(|i| cut.position[i][axis] >= edge),
            "not cut by a plane"
        );
        // Nodes with a neighbour in another of four contiguous ranges.
        let ghosts = |x: &[[f64; 3]]| {
            let part = |i: usize| 4 * i / n;
            (0..n)
                .filter(|&i| {
                    (0..n).any(|j| {
                        let d: f64 = (0..3).map(|k| (x[i][k] - x[j][k]).powi(2)).sum();
                        part(j) != part(i) && d < 2.25
                    })
                })
                .count()
        };
        let (rings, bisection) = (ghosts(&lat.position), ghosts(&cut.position));
        assert!(3 * bisection < rings, "{bisection} against {rings}");
    }
}
