//! Particle shifting (regularisation) for the axisymmetric solver: pairs of
//! particles closer than a fraction of the initial spacing push each other
//! apart, relative to the material, and the fields of a moved particle are
//! carried to its new place by a first-order Taylor expansion. Lagrangian
//! rows follow the material's stretch, e^(-eps) at the impact face, and fall
//! below any fixed fraction of the spacing once the plastic strain passes a
//! few; shifting lets the crowded particles leave the face centre instead.
//! A repulsion that grows as the pair closes is used rather than the
//! gradient of the kernel-summed number density (Lind et al. 2012, J.
//! Comput. Phys. 231, 1499): the Gaussian kernel's gradient vanishes as a
//! pair closes, and with it the face-centre rows paired up sooner than
//! without shifting (README, "Particle shifting").

use crate::kernel::{SUPPORT, kernel2};

/// The directions a particle may shift in.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Freedom {
    /// It stays where the material takes it (the surfaces, which carry the
    /// boundary conditions and the rod's outline).
    Fixed,
    /// Across the unit vector only (the component along it is removed): a
    /// particle pressed on the anvil moves along R, one on the axis along Z.
    Across([f64; 2]),
    /// Both.
    Both,
}

/// The neighbour candidates of the solver (padded rows, images included).
#[derive(Clone, Copy)]
pub(super) struct Candidates<'a> {
    /// Positions of the particles and then of their images.
    pub pos: &'a [[f64; 2]],
    pub nbr: &'a [u32],
    pub nbr_len: &'a [u32],
    pub stride: usize,
}

impl Candidates<'_> {
    /// Candidate neighbours of particle `i` (itself included).
    fn of(&self, i: usize) -> &[u32] {
        &self.nbr[i * self.stride..][..self.nbr_len[i] as usize]
    }
}

/// Shift of each particle: `beta D sum_j (1 - r_ij / l)^2 e_ij` over the
/// neighbours closer than `l` (`e_ij` the unit vector from `j` to `i`, `D`
/// the initial spacing), limited to `cap` in length and projected on the
/// directions the particle is free in. Mirror images count, so a particle
/// is pushed off the axis and the anvil by its own image as by any other.
/// A particle with an `outward` normal (nonzero: that of the nearest surface
/// particle, see [`surface_band`]) does not shift along it: pushed from
/// inside, it slides along the surface instead of passing out through it
/// between two surface particles (Lind et al. 2012 restrict shifting near a
/// free surface the same way).
pub(super) fn shifts(
    c: Candidates,
    free: &[Freedom],
    outward: &[[f64; 2]],
    spacing: f64,
    range: f64,
    beta: f64,
    cap: f64,
) -> Vec<[f64; 2]> {
    (0..free.len())
        .map(|i| {
            if free[i] == Freedom::Fixed {
                return [0.0; 2];
            }
            let xi = c.pos[i];
            let mut d = [0.0; 2];
            let range2 = range * range;
            for &j in c.of(i) {
                let xj = c.pos[j as usize];
                let (a, b) = (xi[0] - xj[0], xi[1] - xj[1]);
                let r2 = a * a + b * b;
                if r2 > 0.0 && r2 < range2 {
                    let r = r2.sqrt();
                    let w = beta * spacing * (1.0 - r / range).powi(2) / r;
                    d[0] += w * a;
                    d[1] += w * b;
                }
            }
            if let Freedom::Across(n) = free[i] {
                d = without_along(d, n);
            }
            let n = outward[i];
            if d[0] * n[0] + d[1] * n[1] > 0.0 {
                d = without_along(d, n);
            }
            let len = (d[0] * d[0] + d[1] * d[1]).sqrt();
            if len > cap {
                d = [d[0] * cap / len, d[1] * cap / len];
            }
            d
        })
        .collect()
}

/// `d` without its component along the unit vector `n`.
#[inline]
fn without_along(d: [f64; 2], n: [f64; 2]) -> [f64; 2] {
    let dn = d[0] * n[0] + d[1] * n[1];
    [d[0] - dn * n[0], d[1] - dn * n[1]]
}

/// The outward normal each particle may not shift along (zero where it
/// is free to): that of the nearest particle of a surface within `reach`,
/// given the surface particles with their outward normals. Only real
/// particles (index below `n`) that are not surface particles themselves
/// are marked.
pub(super) fn surface_band(
    c: Candidates,
    n: usize,
    surface: &[(usize, [f64; 2])],
    reach: f64,
) -> Vec<[f64; 2]> {
    let mut out = vec![[0.0; 2]; n];
    let mut nearest = vec![reach * reach; n];
    let mut on = vec![false; n];
    for &(s, _) in surface {
        on[s] = true;
    }
    for &(s, normal) in surface {
        let xs = c.pos[s];
        for &j in c.of(s) {
            let j = j as usize;
            if j >= n || on[j] {
                continue;
            }
            let (a, b) = (c.pos[j][0] - xs[0], c.pos[j][1] - xs[1]);
            let r2 = a * a + b * b;
            if r2 < nearest[j] {
                nearest[j] = r2;
                out[j] = normal;
            }
        }
    }
    out
}

/// Which particles of the axis column leave the axis, given their places
/// along Z from the bottom up and whether each may move across the axis.
/// Along the axis the repulsion of [`shifts`] only spreads a column as a
/// diffusion does, while at the face centre the material thins along Z as
/// e^(-eps) and spreads in R; so, walking up the column, a particle closer
/// than `crowd` to the axis particle below it leaves, unless that one has
/// just left (a crowded column sheds every other particle per pass).
pub(super) fn leaving(z: &[f64], may: &[bool], crowd: f64) -> Vec<bool> {
    let mut out = vec![false; z.len()];
    let mut below: Option<f64> = None;
    let mut just_left = false;
    for (k, (&zk, &mk)) in z.iter().zip(may).enumerate() {
        let crowded = below.is_some_and(|zb| zk - zb < crowd);
        if crowded && mk && !just_left {
            out[k] = true;
            just_left = true;
        } else {
            below = Some(zk);
            just_left = false;
        }
    }
    out
}

/// Gradient (d/dR, d/dZ) of each of the `K` components of `f` at particle
/// `i`, from its real neighbours (index below `n`) within the support, by
/// the kernel gradient corrected to be exact for linear fields:
/// `grad f_i = M^-1 sum_j (f_j - f_i) grad W_ij`,
/// `M = sum_j grad W_ij (x_j - x_i)^T`. `None` where `M` is singular.
pub(super) fn gradient<const K: usize>(
    c: Candidates,
    n: usize,
    h: f64,
    f: &[[f64; K]],
    i: usize,
) -> Option<[[f64; 2]; K]> {
    let xi = c.pos[i];
    let mut m = [[0.0; 2]; 2];
    let mut a = [[0.0; 2]; K];
    let reach2 = SUPPORT * SUPPORT * h * h;
    for &j in c.of(i) {
        let j = j as usize;
        if j >= n || j == i {
            continue;
        }
        let (dr, dz) = (c.pos[j][0] - xi[0], c.pos[j][1] - xi[1]);
        if dr * dr + dz * dz >= reach2 {
            continue;
        }
        let k = kernel2(-dr, -dz, h);
        let gw = [k.w_r, k.w_z];
        for p in 0..2 {
            m[p][0] += gw[p] * dr;
            m[p][1] += gw[p] * dz;
        }
        for q in 0..K {
            let df = f[j][q] - f[i][q];
            a[q][0] += df * gw[0];
            a[q][1] += df * gw[1];
        }
    }
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    let scale = (m[0][0] * m[0][0] + m[1][1] * m[1][1] + m[0][1] * m[0][1] + m[1][0] * m[1][0])
        .max(f64::MIN_POSITIVE);
    if det.abs() < 1e-6 * scale {
        return None;
    }
    // M g = a for each component.
    Some(std::array::from_fn(|q| {
        [
            (m[1][1] * a[q][0] - m[0][1] * a[q][1]) / det,
            (-m[1][0] * a[q][0] + m[0][0] * a[q][1]) / det,
        ]
    }))
}

/// Smallest and largest value of each of the `K` components of `f` over
/// particle `i` and its real neighbours (index below `n`) in the support.
fn bounds<const K: usize>(
    c: Candidates,
    n: usize,
    h: f64,
    f: &[[f64; K]],
    i: usize,
) -> ([f64; K], [f64; K]) {
    let (mut lo, mut hi) = (f[i], f[i]);
    let xi = c.pos[i];
    let reach2 = SUPPORT * SUPPORT * h * h;
    for &j in c.of(i) {
        let j = j as usize;
        let (dr, dz) = (c.pos[j][0] - xi[0], c.pos[j][1] - xi[1]);
        if j >= n || dr * dr + dz * dz >= reach2 {
            continue;
        }
        for q in 0..K {
            lo[q] = lo[q].min(f[j][q]);
            hi[q] = hi[q].max(f[j][q]);
        }
    }
    (lo, hi)
}

/// `f_i + dr_i . grad f_i` for the shifted particles (gradients taken from
/// the fields before any is moved), limited to the range of the values of
/// the particle and its neighbours: an ill-conditioned gradient (a particle
/// with few neighbours, or all to one side) would otherwise extrapolate
/// without bound, and shifting repeats it step after step (test 7 at 600
/// m/s reached 1060 plastic strain and 130 000 K at one particle, well
/// above melt, before the limit).
pub(super) fn carry<const K: usize>(
    c: Candidates,
    n: usize,
    h: f64,
    f: &mut [[f64; K]],
    d: &[[f64; 2]],
) {
    let moved: Vec<Option<[f64; K]>> = (0..d.len())
        .map(|i| {
            if d[i] == [0.0; 2] {
                return None;
            }
            let g = gradient(c, n, h, f, i)?;
            let (lo, hi) = bounds(c, n, h, f, i);
            Some(std::array::from_fn(|q| {
                (f[i][q] + d[i][0] * g[q][0] + d[i][1] * g[q][1]).clamp(lo[q], hi[q])
            }))
        })
        .collect();
    for (fi, m) in f.iter_mut().zip(moved) {
        if let Some(m) = m {
            *fi = m;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A lattice of `nx` by `ny` points at spacing `d`, with all pairs as
    /// candidates.
    fn lattice(nx: usize, ny: usize, d: f64) -> (Vec<[f64; 2]>, Vec<u32>, Vec<u32>, usize) {
        let pos: Vec<[f64; 2]> = (0..ny)
            .flat_map(|j| (0..nx).map(move |i| [i as f64 * d, j as f64 * d]))
            .collect();
        let n = pos.len();
        let nbr: Vec<u32> = (0..n).flat_map(|_| 0..n as u32).collect();
        (pos, nbr, vec![n as u32; n], n)
    }

    /// A crowded axis column sheds every other particle per pass, a sparse
    /// one none, and a particle that may not move stays (and still counts
    /// as the one below).
    #[test]
    fn a_crowded_axis_column_sheds_every_other_particle() {
        let all = [true; 7];
        let z = [0.0, 0.1, 0.2, 0.3, 0.4, 1.0, 1.1];
        let out = leaving(&z, &all, 0.3);
        assert_eq!(out, [false, true, false, true, false, false, true]);
        let sparse = [0.0, 0.35, 0.7, 1.05];
        assert_eq!(leaving(&sparse, &all[..4], 0.3), [false; 4]);
        let may = [true, false, true, true, true, true, true];
        let out = leaving(&z, &may, 0.3);
        assert_eq!(out, [false, false, true, false, true, false, true]);
    }

    #[test]
    fn gradients_of_linear_fields_are_exact_on_a_distorted_lattice() {
        let (mut pos, nbr, len, stride) = lattice(9, 9, 1.0);
        for (k, x) in pos.iter_mut().enumerate() {
            x[0] += 0.2 * ((k * 7) % 5) as f64 / 5.0;
            x[1] *= 0.3 + 0.05 * x[0];
        }
        let c = Candidates {
            pos: &pos,
            nbr: &nbr,
            nbr_len: &len,
            stride,
        };
        let f: Vec<[f64; 2]> = pos
            .iter()
            .map(|x| [2.0 + 3.0 * x[0] - 5.0 * x[1], -x[0] + 0.5 * x[1]])
            .collect();
        let g = gradient(c, pos.len(), 1.5, &f, 40).unwrap();
        let close = |a: f64, b: f64| (a - b).abs() < 1e-12;
        assert!(close(g[0][0], 3.0) && close(g[0][1], -5.0), "{g:?}");
        assert!(close(g[1][0], -1.0) && close(g[1][1], 0.5), "{g:?}");
        // Carried by a shift, a linear field takes its value at the new place.
        let mut d = vec![[0.0; 2]; pos.len()];
        d[40] = [0.03, -0.02];
        let mut moved = f.clone();
        carry(c, pos.len(), 1.5, &mut moved, &d);
        let (x, y) = (pos[40][0] + 0.03, pos[40][1] - 0.02);
        assert!(close(moved[40][0], 2.0 + 3.0 * x - 5.0 * y));
        assert!(close(moved[40][1], -x + 0.5 * y));
        assert!(
            moved
                .iter()
                .zip(&f)
                .enumerate()
                .all(|(i, (a, b))| i == 40 || a == b)
        );
    }

    #[test]
    fn a_carried_value_stays_within_its_neighbours_range() {
        // A kink with its minimum on particle 40's row: f = Z - Z_40 above,
        // a steep f = 40 (Z_40 - Z) below. The gradient at 40 is dominated
        // by the steep side, and a shift along +Z carries f_40 below every
        // neighbour's value without the limit.
        let (pos, nbr, len, stride) = lattice(9, 9, 1.0);
        let c = Candidates {
            pos: &pos,
            nbr: &nbr,
            nbr_len: &len,
            stride,
        };
        let z0 = pos[40][1];
        let f: Vec<[f64; 1]> = pos
            .iter()
            .map(|x| {
                let dz = x[1] - z0;
                [if dz >= 0.0 { dz } else { -40.0 * dz }]
            })
            .collect();
        let mut d = vec![[0.0; 2]; pos.len()];
        d[40] = [0.0, 0.05];
        let g = gradient(c, pos.len(), 1.5, &f, 40).unwrap();
        let unlimited = f[40][0] + 0.05 * g[0][1];
        let (lo, _) = bounds(c, pos.len(), 1.5, &f, 40);
        assert!(unlimited < lo[0], "{unlimited} {lo:?}");
        let mut moved = f.clone();
        carry(c, pos.len(), 1.5, &mut moved, &d);
        assert_eq!(moved[40][0], lo[0]);
    }

    #[test]
    fn close_pairs_push_apart_and_distant_ones_do_not() {
        // A lattice at the initial spacing: nobody is within the range.
        let (mut pos, nbr, len, stride) = lattice(5, 5, 1.0);
        let free = vec![Freedom::Both; pos.len()];
        let none = vec![[0.0; 2]; pos.len()];
        let c = Candidates {
            pos: &pos,
            nbr: &nbr,
            nbr_len: &len,
            stride,
        };
        let (beta, range) = (0.1, 0.5);
        assert!(
            shifts(c, &free, &none, 1.0, range, beta, 1.0)
                .iter()
                .all(|d| *d == [0.0; 2])
        );
        // Particle 12 (the centre) brought to 0.2 above particle 7: each is
        // pushed away from the other by beta D (1 - 0.2 / 0.5)^2 = 0.036.
        pos[12] = [2.0, 1.2];
        let c = Candidates {
            pos: &pos,
            nbr: &nbr,
            nbr_len: &len,
            stride,
        };
        let d = shifts(c, &free, &none, 1.0, range, beta, 1.0);
        let push = beta * (1.0f64 - 0.2 / 0.5).powi(2);
        assert!(
            (d[12][1] - push).abs() < 1e-15 && d[12][0] == 0.0,
            "{:?}",
            d[12]
        );
        assert!(
            (d[7][1] + push).abs() < 1e-15 && d[7][0] == 0.0,
            "{:?}",
            d[7]
        );
        assert!(
            d.iter()
                .enumerate()
                .all(|(i, d)| i == 7 || i == 12 || *d == [0.0; 2])
        );
        // The cap and the freedoms hold.
        let d = shifts(c, &free, &none, 1.0, range, beta, 0.01);
        assert!((d[12][1] - 0.01).abs() < 1e-15);
        let mut only_r = free.clone();
        only_r[12] = Freedom::Across([0.0, 1.0]);
        only_r[7] = Freedom::Fixed;
        let d = shifts(c, &only_r, &none, 1.0, range, beta, 1.0);
        assert_eq!((d[12], d[7]), ([0.0; 2], [0.0; 2]));
    }

    /// A particle in the gap between two surface particles, pushed from
    /// inside, moves out through the surface without the band and does not
    /// with it; the particle pushing it still moves inward, and particles
    /// beyond the reach or on the surface are not marked.
    #[test]
    fn the_surface_band_keeps_a_pushed_particle_from_passing_out() {
        let (mut pos, nbr, len, stride) = lattice(5, 5, 1.0);
        // The top row (20-24) is the surface, normal +Z, with a gap over
        // particle 17: 21 and 23 stand 0.4 to either side of it, 22 is gone.
        pos[21] = [1.6, 4.0];
        pos[23] = [2.4, 4.0];
        pos[22] = [2.0, 10.0];
        pos[17] = [2.0, 3.8];
        pos[12] = [2.0, 3.45];
        let c = Candidates {
            pos: &pos,
            nbr: &nbr,
            nbr_len: &len,
            stride,
        };
        let free = vec![Freedom::Both; pos.len()];
        let none = vec![[0.0; 2]; pos.len()];
        let (beta, range) = (0.1, 0.5);
        let d = shifts(c, &free, &none, 1.0, range, beta, 1.0);
        assert!(d[17][1] > 0.005, "{:?}", d[17]);
        let top = [20, 21, 22, 23, 24].map(|i| (i, [0.0, 1.0]));
        let band = surface_band(c, pos.len(), &top, 1.0);
        assert_eq!(band[17], [0.0, 1.0]);
        assert_eq!(band[12], [0.0, 1.0]);
        assert_eq!(band[7], [0.0; 2]);
        assert_eq!(band[21], [0.0; 2]);
        let d = shifts(c, &free, &band, 1.0, range, beta, 1.0);
        assert!(d[17][0].abs() < 1e-15 && d[17][1] == 0.0, "{:?}", d[17]);
        assert!(d[12][1] < -0.005, "{:?}", d[12]);
    }
}
