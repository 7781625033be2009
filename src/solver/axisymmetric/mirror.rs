//! Mirror images across the axis R = 0 and the anvil Z = 0: a particle near
//! either sees a symmetric neighbourhood (the anvil is rigid and smooth),
//! the velocity component and the shear stress odd across the plane, the
//! rest even.

use crate::solver::axisymmetric::boundary::Stress;

/// The plane or planes a mirror image is reflected across: the axis R = 0,
/// the anvil Z = 0, or both (an image of a particle near the axis and the
/// anvil).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Mirror {
    Axis,
    Anvil,
    Both,
}

impl Mirror {
    /// Whether R (and the R components of vectors) change sign.
    pub fn flips_r(self) -> bool {
        self != Mirror::Anvil
    }
    /// Whether Z (and the Z components of vectors) change sign.
    pub fn flips_z(self) -> bool {
        self != Mirror::Axis
    }
}

/// A mirror image of a real particle.
#[derive(Debug, Clone, Copy)]
pub(super) struct Image {
    pub source: u32,
    pub mirror: Mirror,
}

/// A field value as seen at a mirror image.
pub(super) trait Mirrored: Copy {
    fn mirrored(self, m: Mirror) -> Self;
}

/// Scalars (volume, density) are even across both planes.
impl Mirrored for f64 {
    fn mirrored(self, _: Mirror) -> Self {
        self
    }
}

impl Mirrored for [f64; 1] {
    fn mirrored(self, _: Mirror) -> Self {
        self
    }
}

/// Vectors in (R, Z), positions and velocities: the component normal to the
/// plane changes sign.
impl Mirrored for [f64; 2] {
    fn mirrored(self, m: Mirror) -> Self {
        [
            if m.flips_r() { -self[0] } else { self[0] },
            if m.flips_z() { -self[1] } else { self[1] },
        ]
    }
}

/// Stresses (RR, ZZ, theta-theta, RZ): the shear changes sign across one
/// plane and is even across both.
impl Mirrored for Stress {
    fn mirrored(self, m: Mirror) -> Self {
        let odd = m.flips_r() != m.flips_z();
        [
            self[0],
            self[1],
            self[2],
            if odd { -self[3] } else { self[3] },
        ]
    }
}

/// Writes the image values `f[n + k] = f[images[k].source]` mirrored.
pub(super) fn fill_images<T: Mirrored>(f: &mut [T], n: usize, images: &[Image]) {
    let (real, out) = f.split_at_mut(n);
    for (img, im) in out.iter_mut().zip(images) {
        *img = real[im.source as usize].mirrored(im.mirror);
    }
}
