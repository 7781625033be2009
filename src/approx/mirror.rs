//! The quarter model of a normal impact: the symmetry planes `x = 0` and
//! `y = 0` by mirror images of the nodes near them.
//!
//! A normal impact of a cylinder on a cylinder (or on the anvil) is
//! symmetric under `x → −x` and `y → −y`, and so is the ring lattice
//! ([`crate::approx::lattice`]: ring `k` has nodes at the angles `2π l / (6 k)`).
//! The quarter model keeps the nodes with `x ≥ 0` and `y ≥ 0`
//! ([`crate::approx::lattice::NodeLattice::quarter`]): a node on a plane keeps its share
//! of the node (half its volume and mass, a quarter on the axis) and has
//! no velocity across the plane.
//!
//! The nodes of the other three quarters are images: at each computation of
//! the supports every node within a layer of the planes gets its images
//! (across `x = 0`, `y = 0`, and both when it is near both), whose fields
//! are its own reflected (vectors by their components, symmetric tensors
//! by `σ' = R σ R`). Rows (supports named, shapes, test spheres, forces)
//! are computed for the real nodes only; the images are columns. With the
//! layer at least twice the largest support radius, every row is the full
//! model's row (the `k` nearest of a node and every node whose support
//! covers it or its test sphere are within the layer):
//!
//! - gathers (the MLS velocity, the velocity gradients of eq. 4, the sphere
//!   form's tractions, the shifting's carry) read the images' reflected
//!   fields: the full model's sums;
//! - adjoint sums (the nodal form's forces `F = −Gᵀ V σ` and the order-2
//!   smoothing's `Hᵀ`) scatter onto the images too, and [`Mirror::fold`]
//!   adds each image's share back onto its node, reflected: the derivative
//!   of the quarter's stress power, a quarter of the full model's, with
//!   respect to the quarter's velocities (with the shares of the nodes on
//!   the planes as their masses);
//! - the support radius of a node is the largest of its own and of its
//!   images' (a node's image is named by the real nodes near the plane as
//!   the node itself is named by their images).
//!
//! So the quarter model is the full model restricted to a quarter, up to the
//! order of the sums and of the contact's Gauss-Seidel sweep; it costs a
//! quarter of the rows (`tests/suite/penetration.rs` compares the two).

/// Bit of a node on, or an image across, the plane `x = 0`.
pub const X: u8 = 1;
/// Bit of a node on, or an image across, the plane `y = 0`.
pub const Y: u8 = 2;

/// The mirror images of one computation of the supports: image `k` is
/// index `n + k` of the extended arrays (after the `n` real nodes).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Mirror {
    /// The real node each image reflects.
    pub source: Vec<usize>,
    /// The planes each image is reflected across ([`X`], [`Y`] or both).
    pub flip: Vec<u8>,
}

impl Mirror {
    /// The images of the nodes at `pos` (the real ones) within `layer` of
    /// the planes, in node order (`X`, then `Y`, then both): a node on a
    /// plane (`plane[i]`, bits [`X`], [`Y`]) has no image across it.
    pub fn choose(pos: &[[f64; 3]], plane: &[u8], layer: f64) -> Self {
        let mut m = Mirror::default();
        for (i, (x, &on)) in pos.iter().zip(plane).enumerate() {
            let near_x = on & X == 0 && x[0] < layer;
            let near_y = on & Y == 0 && x[1] < layer;
            for (near, flip) in [(near_x, X), (near_y, Y), (near_x && near_y, X | Y)] {
                if near {
                    m.source.push(i);
                    m.flip.push(flip);
                }
            }
        }
        m
    }

    /// Number of images.
    pub fn len(&self) -> usize {
        self.source.len()
    }

    /// True for the full model (no images).
    pub fn is_empty(&self) -> bool {
        self.source.is_empty()
    }

    /// `out` = the real values, then each image's (`reflect(value, flip)`).
    pub fn extend<T: Copy>(&self, real: &[T], out: &mut Vec<T>, reflect: impl Fn(&T, u8) -> T) {
        out.clear();
        out.extend_from_slice(real);
        out.extend(
            self.source
                .iter()
                .zip(&self.flip)
                .map(|(&s, &f)| reflect(&real[s], f)),
        );
    }

    /// Adds each image's entry (index `n + k`, reflected back) onto its
    /// node's, in image order (the same bits for any number of threads).
    pub fn fold(&self, n: usize, ext: &mut [[f64; 3]]) {
        for (k, (&s, &f)) in self.source.iter().zip(&self.flip).enumerate() {
            let g = vector(&ext[n + k], f);
            for d in 0..3 {
                ext[s][d] += g[d];
            }
        }
    }
}

/// A vector (or a place) reflected across the planes of `flip`.
#[inline]
pub fn vector(v: &[f64; 3], flip: u8) -> [f64; 3] {
    let sx = if flip & X != 0 { -1.0 } else { 1.0 };
    let sy = if flip & Y != 0 { -1.0 } else { 1.0 };
    [sx * v[0], sy * v[1], v[2]]
}

/// A symmetric tensor `[xx, yy, zz, xy, yz, zx]` reflected, `R σ R`.
#[inline]
pub fn tensor(s: &[f64; 6], flip: u8) -> [f64; 6] {
    let sx = if flip & X != 0 { -1.0 } else { 1.0 };
    let sy = if flip & Y != 0 { -1.0 } else { 1.0 };
    [s[0], s[1], s[2], sx * sy * s[3], sy * s[4], sx * s[5]]
}

/// A value that reflects to itself (scalars, body tags).
#[inline]
pub fn same<T: Copy>(v: &T, _flip: u8) -> T {
    *v
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A tensor reflected is `R σ R` written out, and a reflection twice is
    /// the identity.
    #[test]
    fn reflections_are_r_sigma_r() {
        let s = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        let full = |s: &[f64; 6]| [[s[0], s[3], s[5]], [s[3], s[1], s[4]], [s[5], s[4], s[2]]];
        for flip in 0..4u8 {
            let r = vector(&[1.0, 1.0, 1.0], flip);
            let m = full(&s);
            let want: [[f64; 3]; 3] =
                std::array::from_fn(|a| std::array::from_fn(|b| r[a] * m[a][b] * r[b]));
            assert_eq!(full(&tensor(&s, flip)), want, "flip {flip}");
            assert_eq!(tensor(&tensor(&s, flip), flip), s);
            assert_eq!(
                vector(&vector(&[1.0, 2.0, 3.0], flip), flip),
                [1.0, 2.0, 3.0]
            );
        }
    }

    /// The fold is the adjoint of the extension: `<E u, w> = <u, Eᵀ w>` for
    /// any real field `u` and extended field `w` (the nodal form's forces in
    /// the quarter model are the derivative of its stress power).
    #[test]
    fn the_fold_is_the_adjoint_of_the_extension() {
        let mut uniform = crate::test_rng::rng(7);
        let mut rnd = || uniform() - 0.5;
        let pos: Vec<[f64; 3]> = (0..200)
            .map(|_| [rnd() + 0.5, rnd() + 0.5, rnd()])
            .collect();
        let plane: Vec<u8> = (0..200).map(|i| (i % 7 == 0) as u8 * X).collect();
        let m = Mirror::choose(&pos, &plane, 0.3);
        assert!(m.len() > 50, "{}", m.len());
        let u: Vec<[f64; 3]> = (0..200).map(|_| [rnd(), rnd(), rnd()]).collect();
        let w: Vec<[f64; 3]> = (0..200 + m.len()).map(|_| [rnd(), rnd(), rnd()]).collect();
        let mut eu = Vec::new();
        m.extend(&u, &mut eu, vector);
        let dot = |a: &[[f64; 3]], b: &[[f64; 3]]| -> f64 {
            a.iter()
                .zip(b)
                .map(|(x, y)| x[0] * y[0] + x[1] * y[1] + x[2] * y[2])
                .sum()
        };
        let mut fw = w.clone();
        m.fold(200, &mut fw);
        let (a, b) = (dot(&eu, &w), dot(&u, &fw[..200]));
        assert!((a - b).abs() < 1e-12 * a.abs().max(1.0), "{a} {b}");
    }

    /// Images of the nodes near the planes only, none across a plane a node
    /// is on, and the fold adds an image's entry back reflected.
    #[test]
    fn images_and_fold() {
        let pos = [
            [0.5, 0.5, 0.0],
            [0.0, 0.5, 0.0],
            [3.0, 0.2, 1.0],
            [3.0, 3.0, 0.0],
        ];
        let plane = [0, X, 0, 0];
        let m = Mirror::choose(&pos, &plane, 1.0);
        assert_eq!(m.source, vec![0, 0, 0, 1, 2]);
        assert_eq!(m.flip, vec![X, Y, X | Y, Y, Y]);
        let mut ext = Vec::new();
        m.extend(&pos, &mut ext, vector);
        assert_eq!(ext[4], [-0.5, 0.5, 0.0]);
        assert_eq!(ext[6], [-0.5, -0.5, 0.0]);
        assert_eq!(ext[8], [3.0, -0.2, 1.0]);
        let mut f = vec![[0.0; 3]; 9];
        f[6] = [1.0, 2.0, 3.0];
        f[8] = [1.0, 1.0, 1.0];
        m.fold(4, &mut f);
        assert_eq!(f[0], [-1.0, -2.0, 3.0]);
        assert_eq!(f[2], [1.0, -1.0, 1.0]);
    }
}
