//! Cracks that open in tension, on three planes of a point (issue 68): the
//! Rajendran-Grove ceramic's tension in a smeared-crack form.
//!
//! The seed's model (`super::rajendran_grove`) has one crack radius per
//! point for cracks of every orientation, opened and grown by the same flaw
//! size in tension and in compression. With the seed's flaws (0.58 µm) a
//! plate never cracks in tension below its HEL; with flaws large enough to
//! spall (100 µm) the same isotropic cracks pulverize the plate wherever
//! any tension passes, and pulverized ceramic holds no compression either.
//! Here, when the constant `tensile_flaw_size` is set, tension is carried
//! by cracks of their own:
//!
//! - **Flaws.** Each point has flaws of radius `a_t` (the largest flaws,
//!   which open first in tension; `tensile_flaw_size`) on every plane. The
//!   seed's flaws (`a0`, with the density `N0`) stay the isotropic cracks
//!   that slide under compression.
//! - **Planes.** The first time a flaw would grow (the largest principal
//!   stress tensile, with a release rate past `G_c`), the point fixes three
//!   planes: the normals are the principal directions of that moment. They
//!   turn with the material's spin afterwards.
//! - **Growth.** The crack on plane `k` grows by eq. (24) with the opening
//!   constants `(n1+, n2+)` while the normal stress on its plane is
//!   tensile, at the release rate of aligned penny cracks (Kachanov 1992:
//!   normal compliance `B_n = 16 (1 - nu^2) / (3 E)`, shear `B_t = 32 (1 -
//!   nu^2) / (3 (2 - nu) E)`): `G = (3 a / 2 pi) (B_n sigma_n^2 + B_t
//!   tau^2) / 2`, which in pure tension is Sneddon's `4 (1 - nu^2)
//!   sigma_n^2 a / (pi E)`, so a plane opens at `sigma_n = K_IC sqrt(pi / (4
//!   a_t))` (the penny crack under normal tension). The stress that drives
//!   it is the point's stress with the openings of the start of the step.
//! - **Opening.** Each plane's cracks open by a normal strain `e_k >= 0`,
//!   state of the point, with the aligned penny cracks' compliance:
//!   `sigma_n = e / (B_n gamma)`, `gamma = N0 a^3` (the seed's flaw
//!   density), no stiffness once the plane has *split* (the critical crack
//!   density). The three openings are solved together in the planes'
//!   frame, `M (e - e_old) + e / (B_n gamma) = sigma_n` with `M = lambda + 2
//!   G delta`, over an active set of the planes that stay open; a shut
//!   plane carries its normal compression whole. The openings leave the
//!   matrix: its pressure is that of the density without them, and the
//!   point's elastic strain is that of the stress it carries.
//! - **Shear.** A plane carries its shear whole until it splits; a split
//!   plane slips beyond friction `mu |sigma_n|` in compression, and carries
//!   none in tension (the slip dissipates).
//! - The point's isotropic cracks then grow only under compression (matrix
//!   compression `eta >= 0`), as sliding cracks; in tension the planes
//!   carry the cracking.
//! - **Shielding** (off unless the constant `shield_radius` is set; the
//!   3-D solver only, `src/solver/mlpg3d/shielding.rs`): a plane that
//!   would start to grow inside the shielding zone of another point's
//!   crack of near the same orientation ([`Shield`]) does not, ever; it
//!   is *shielded*, and carries at most the normal stress at which its
//!   flaw would have started (the crack beside it takes the stretch:
//!   [`CrackPlanes::open_capped`]). Measured in
//!   `docs/notes/2026-12-01-crack-shielding.md`.

use super::tensor::{Full, matrix};
use std::f64::consts::PI;

/// The tensile cracks of a point: the three planes' normals and their crack
/// radii.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TensileCracks {
    /// The unit normals of the three planes (orthonormal, right-handed).
    pub normals: [[f64; 3]; 3],
    /// The crack radius on each plane (m).
    pub size: [f64; 3],
    /// The opening of each plane's cracks, as a normal strain (1): the
    /// share of the point's stretch across the plane that its cracks take.
    pub opening: [f64; 3],
    /// What crack shielding keeps of the planes, where the constants
    /// shield (`None` where they do not, so that the records of the point
    /// stay as short as before shielding; `None` in states saved before
    /// it was).
    #[serde(default)]
    pub shielding: Option<PlaneShielding>,
}

/// What crack shielding keeps of a point's three planes.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct PlaneShielding {
    /// How long each plane's crack has grown (s): 0 until it first grows
    /// past the point's flaw, then the time since. The crack's shielding
    /// zone grows with it.
    pub age: [f64; 3],
    /// Whether each plane is shielded: a plane that another crack's zone
    /// held when it would have started (`Shield`) never starts, and
    /// carries at most the stress at which its flaw would have
    /// (`CrackPlanes::open_capped`).
    pub shielded: [bool; 3],
}

/// The crack normals that shield a point (crack shielding, issue 68): a
/// plane of the point whose normal lies within 45° of one of them cannot
/// start to grow ([`CrackPlanes::step`]); a crack that has started goes on.
/// The 3-D solver gives each point the normals of the cracks of other
/// points whose shielding zones hold it (`src/solver/mlpg3d/shielding.rs`);
/// [`Shield::NONE`] everywhere else.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Shield {
    normals: [[f64; 3]; 3],
    len: usize,
}

impl Shield {
    /// No shielding.
    pub const NONE: Shield = Shield {
        normals: [[0.0; 3]; 3],
        len: 0,
    };

    /// The cosine of the largest angle between a plane's normal and a
    /// shielding crack's normal at which the crack shields the plane: 45°.
    pub const ALIGNED: f64 = std::f64::consts::FRAC_1_SQRT_2;

    /// Adds the normal `n` (a unit vector); false where three are held
    /// already (the normal is not added).
    pub fn add(&mut self, n: [f64; 3]) -> bool {
        if self.len == 3 {
            return false;
        }
        self.normals[self.len] = n;
        self.len += 1;
        true
    }

    /// How many normals it holds.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether it holds none.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Whether a plane of unit normal `n` is shielded: within 45° of a
    /// shielding normal.
    pub fn blocks(&self, n: &[f64; 3]) -> bool {
        self.normals[..self.len]
            .iter()
            .any(|s| dot(s, n).abs() >= Self::ALIGNED)
    }
}

/// What the tensile cracks need from the material's constants.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CrackPlanes {
    /// Poisson's ratio of the matrix.
    pub nu: f64,
    /// Young's modulus of the matrix (Pa).
    pub youngs_modulus: f64,
    /// Flaws per unit volume `N0` (1/m3).
    pub flaw_density: f64,
    /// Initial radius of the tensile flaws `a_t` (m).
    pub flaw_size: f64,
    /// Crack density at which a plane has split (1).
    pub critical_density: f64,
    /// Friction coefficient of a closed crack (1).
    pub friction: f64,
    /// Whether the planes keep what shielding needs
    /// ([`TensileCracks::shielding`]).
    pub shields: bool,
}

/// The [`Full`] tensor of a symmetric 3x3 matrix.
fn full(m: &[[f64; 3]; 3]) -> Full {
    [m[0][0], m[1][1], m[2][2], m[0][1], m[1][2], m[2][0]]
}

/// The dot product of two 3-vectors.
pub(crate) fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn apply(m: &[[f64; 3]; 3], v: &[f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| dot(&m[i], v))
}

/// The components `Q^T S Q` of the symmetric matrix `s` in the frame whose
/// axes are `normals`.
fn rotate_in(s: &[[f64; 3]; 3], normals: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let sn: [[f64; 3]; 3] = std::array::from_fn(|j| apply(s, &normals[j]));
    std::array::from_fn(|i| std::array::from_fn(|j| dot(&normals[i], &sn[j])))
}

/// The matrix `Q S' Q^T` of the frame components `s` back in the axes.
fn rotate_out(s: &[[f64; 3]; 3], normals: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    std::array::from_fn(|a| {
        std::array::from_fn(|b| {
            let mut sum = 0.0;
            for (i, ni) in normals.iter().enumerate() {
                for (j, nj) in normals.iter().enumerate() {
                    sum += ni[a] * s[i][j] * nj[b];
                }
            }
            sum
        })
    })
}

/// The eigenvalues and unit eigenvectors of a symmetric 3x3 matrix by
/// cyclic Jacobi rotations, largest eigenvalue first; the vectors a
/// right-handed frame.
pub fn principal(s: &[[f64; 3]; 3]) -> ([f64; 3], [[f64; 3]; 3]) {
    let mut m = *s;
    // Columns of v are the eigenvectors.
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _ in 0..50 {
        let off = m[0][1].powi(2) + m[1][2].powi(2) + m[0][2].powi(2);
        let diag = m[0][0].powi(2) + m[1][1].powi(2) + m[2][2].powi(2);
        if off <= 1e-32 * diag || off == 0.0 {
            break;
        }
        for (p, q) in [(0, 1), (1, 2), (0, 2)] {
            if m[p][q] == 0.0 {
                continue;
            }
            let theta = (m[q][q] - m[p][p]) / (2.0 * m[p][q]);
            let t = if theta == 0.0 {
                1.0
            } else {
                theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt())
            };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            for row in m.iter_mut() {
                let (a, b) = (row[p], row[q]);
                row[p] = c * a - s * b;
                row[q] = s * a + c * b;
            }
            for k in 0..3 {
                let (a, b) = (m[p][k], m[q][k]);
                m[p][k] = c * a - s * b;
                m[q][k] = s * a + c * b;
            }
            for row in v.iter_mut() {
                let (a, b) = (row[p], row[q]);
                row[p] = c * a - s * b;
                row[q] = s * a + c * b;
            }
        }
    }
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| m[b][b].total_cmp(&m[a][a]));
    let values = order.map(|k| m[k][k]);
    let mut vectors = order.map(|k| [v[0][k], v[1][k], v[2][k]]);
    // Right-handed: the third is the cross product of the first two.
    let [a, b, _] = vectors;
    vectors[2] = [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ];
    (values, vectors)
}

impl CrackPlanes {
    /// The normal compliance `B_n = 16 (1 - nu^2) / (3 E)` of aligned penny
    /// cracks per unit crack density (1/Pa).
    fn normal_compliance(&self) -> f64 {
        16.0 * (1.0 - self.nu * self.nu) / (3.0 * self.youngs_modulus)
    }

    /// The crack radius at which a plane has split (m).
    pub fn split_size(&self) -> f64 {
        (self.critical_density / self.flaw_density).cbrt()
    }

    /// The release rate (J/m2) of a crack of radius `a` on a plane with
    /// normal stress `sn` (tension positive) and resolved shear `tau`:
    /// `(3 a / 2 pi) (B_n sn^2 + B_t tau^2) / 2`, zero when the plane is
    /// in compression.
    pub fn release_rate(&self, a: f64, sn: f64, tau: f64) -> f64 {
        if sn.is_nan() || sn <= 0.0 {
            return 0.0;
        }
        let bn = self.normal_compliance();
        let bt = bn * 2.0 / (2.0 - self.nu);
        3.0 * a / (2.0 * PI) * 0.5 * (bn * sn * sn + bt * tau * tau)
    }

    /// The normal stress at which a plane of flaws `a` opens under pure
    /// tension with critical release rate `gc`: `sqrt(gc pi E / (4 (1 -
    /// nu^2) a))`, the penny crack's `K_IC sqrt(pi / (4 a))`.
    pub fn opening_stress(&self, a: f64, gc: f64) -> f64 {
        (gc * PI * self.youngs_modulus / (4.0 * (1.0 - self.nu * self.nu) * a)).sqrt()
    }

    /// The frame components of the stress `sigma` (tension positive) on the
    /// three planes: the normal stresses and the resolved shear magnitudes.
    fn tractions(normals: &[[f64; 3]; 3], sigma: &[[f64; 3]; 3]) -> ([f64; 3], [f64; 3]) {
        let s = rotate_in(sigma, normals);
        let normal = [s[0][0], s[1][1], s[2][2]];
        let shear = std::array::from_fn(|k| {
            let (i, j) = ((k + 1) % 3, (k + 2) % 3);
            (s[k][i] * s[k][i] + s[k][j] * s[k][j]).sqrt()
        });
        (normal, shear)
    }

    /// One step of the tensile cracks of a point under the effective stress
    /// `sigma` (tension positive, XX YY ZZ XY YZ ZX), with spin `spin` (`W_XY, W_YZ,
    /// W_ZX`) over `dt`: the planes turn with the spin, are fixed at the
    /// first growth, and grow by `speed(release_rate, open = true)`. A
    /// plane that `shield` blocks does not start to grow, and is shielded
    /// from then on (the planes are fixed all the same, so that
    /// [`CrackPlanes::open_capped`] can relieve it); one that has grown
    /// goes on.
    /// Returns the new cracks (`None` while no flaw has grown).
    #[allow(clippy::too_many_arguments)]
    pub fn step(
        &self,
        cracks: Option<TensileCracks>,
        sigma: &Full,
        spin: &[f64; 3],
        dt: f64,
        gc: f64,
        speed: impl Fn(f64) -> f64,
        shield: &Shield,
    ) -> Option<TensileCracks> {
        let s = matrix(sigma);
        let mut cracks = match cracks {
            Some(mut c) => {
                let w = [
                    [0.0, spin[0], -spin[2]],
                    [-spin[0], 0.0, spin[1]],
                    [spin[2], -spin[1], 0.0],
                ];
                for n in c.normals.iter_mut() {
                    let wn = apply(&w, n);
                    for (x, d) in n.iter_mut().zip(wn) {
                        *x += dt * d;
                    }
                }
                c.normals = orthonormal(c.normals);
                c
            }
            None => {
                let (values, vectors) = principal(&s);
                // False on NaN: no plane forms from a stress that is not a number.
                // (A shielded plane is fixed too, and does not grow below.)
                if !(values[0] > 0.0 && self.release_rate(self.flaw_size, values[0], 0.0) > gc) {
                    return None;
                }
                TensileCracks {
                    normals: vectors,
                    size: [self.flaw_size; 3],
                    opening: [0.0; 3],
                    shielding: None,
                }
            }
        };
        let (normal, shear) = Self::tractions(&cracks.normals, &s);
        let split = self.split_size();
        if self.shields && cracks.shielding.is_none() {
            cracks.shielding = Some(PlaneShielding::default());
        }
        for k in 0..3 {
            let a = cracks.size[k];
            if a >= split {
                if let Some(kept) = &mut cracks.shielding {
                    kept.age[k] += dt;
                }
                continue;
            }
            let held = cracks.shielding.is_some_and(|kept| kept.shielded[k]);
            if a <= self.flaw_size && (held || shield.blocks(&cracks.normals[k])) {
                if let Some(kept) = &mut cracks.shielding {
                    kept.shielded[k] = true;
                }
                continue;
            }
            let g = self.release_rate(a, normal[k], shear[k]);
            cracks.size[k] = (a + speed(g) * dt).min(split);
            if let Some(kept) = &mut cracks.shielding
                && cracks.size[k] > self.flaw_size
            {
                kept.age[k] += dt;
            }
        }
        Some(cracks)
    }

    /// The openings of the planes of `cracks` and the stress that the point
    /// carries, when the stress of its elastic strain with the openings of
    /// the start of the step is `sigma` (tension positive), in a solid of
    /// bulk modulus `k` and shear modulus `g`. A plane's cracks open in
    /// tension with the compliance of aligned penny cracks, `e = B_n gamma
    /// sigma_n` (Kachanov 1992), without limit once split, and never below
    /// zero: with `M = lambda + 2 G delta` the stiffness between the normal
    /// strains and stresses in the planes' frame, the open planes solve
    /// `M (e - e_old) + e / (B_n gamma) = sigma_nn`; a plane whose opening
    /// would fall below zero is shut (`e = 0`, its normal stress whatever
    /// the others leave, a compression crossing it whole). The shear
    /// stresses on a split plane slip beyond friction, `mu |sigma_n|` in
    /// compression and none in tension; a plane not yet split carries its
    /// shear whole.
    /// Returns the new openings and the carried stress, which is the
    /// stress of the point's elastic strain from then on (the slip is not
    /// elastic).
    pub fn open(&self, cracks: &TensileCracks, sigma: &Full, k: f64, g: f64) -> ([f64; 3], Full) {
        self.open_capped(cracks, sigma, k, g, [None; 3])
    }

    /// [`CrackPlanes::open`] with the normal stress of some planes capped:
    /// a plane with `caps[i] = Some(c)` opens with its flaws' compliance
    /// up to the normal stress `c`, and past it stretches at `c` (its
    /// opening whatever holds its stress at `c`). A shielded plane is so
    /// relieved: the crack whose zone holds it takes the stretch across it
    /// beyond the stress at which its own flaw would have started.
    pub fn open_capped(
        &self,
        cracks: &TensileCracks,
        sigma: &Full,
        k: f64,
        g: f64,
        caps: [Option<f64>; 3],
    ) -> ([f64; 3], Full) {
        let mut s = rotate_in(&matrix(sigma), &cracks.normals);
        let split = self.split_size();
        let bn = self.normal_compliance();
        // Each plane's normal stiffness 1 / (B_n gamma), 0 once split.
        let stiffness: [f64; 3] = std::array::from_fn(|k| {
            let a = cracks.size[k];
            if a >= split {
                0.0
            } else {
                1.0 / (bn * self.flaw_density * a * a * a)
            }
        });
        let lambda = k - 2.0 / 3.0 * g;
        let m = |i: usize, j: usize| lambda + if i == j { 2.0 * g } else { 0.0 };
        let old = cracks.opening;
        let normal0 = [s[0][0], s[1][1], s[2][2]];
        // The stress with openings e: sigma_nn - M (e - e_old).
        let stress = |e: &[f64; 3], i: usize| {
            normal0[i] - (0..3).map(|j| m(i, j) * (e[j] - old[j])).sum::<f64>()
        };
        let mut active: [bool; 3] = [true; 3];
        // Open planes held at their cap: the normal stress is the cap.
        let mut held: [bool; 3] = [false; 3];
        let mut e = [0.0; 3];
        let rounds = if caps.iter().any(Option::is_some) {
            8
        } else {
            4
        };
        for _ in 0..rounds {
            // The open set's system (M + diag(stiffness)) e = rhs; a held
            // plane's row M e = rhs - cap.
            let idx: Vec<usize> = (0..3).filter(|&i| active[i]).collect();
            let mut a = [[0.0; 3]; 3];
            let mut rhs = [0.0; 3];
            for (r, &i) in idx.iter().enumerate() {
                for (c, &j) in idx.iter().enumerate() {
                    a[r][c] = m(i, j)
                        + if i == j && !held[i] {
                            stiffness[i]
                        } else {
                            0.0
                        };
                }
                // The shut planes' e = 0 leaves only their old openings.
                rhs[r] = normal0[i] + (0..3).map(|j| m(i, j) * old[j]).sum::<f64>();
                if held[i] {
                    rhs[r] -= caps[i].unwrap_or(0.0);
                }
            }
            let x = solve_small(&a, &rhs, idx.len());
            e = [0.0; 3];
            for (r, &i) in idx.iter().enumerate() {
                e[i] = x[r];
            }
            let mut changed = false;
            for i in 0..3 {
                if active[i] && e[i] < 0.0 {
                    active[i] = false;
                    held[i] = false;
                    changed = true;
                } else if let (true, Some(cap)) = (active[i], caps[i]) {
                    // Past the cap with the flaws' compliance: held; held
                    // with less opening than the compliance gives at the
                    // cap: back to the compliance.
                    let over = e[i] * stiffness[i] > cap;
                    if over != held[i] {
                        held[i] = over;
                        changed = true;
                    }
                }
            }
            if !changed {
                break;
            }
        }
        for i in 0..3 {
            e[i] = e[i].max(0.0);
            s[i][i] = stress(&e, i);
        }
        // A shear component lies on two planes: a split one lets it slip
        // beyond friction, `mu |sigma_n|` in compression, none in tension.
        for (i, j) in [(0, 1), (1, 2), (0, 2)] {
            let mut t = s[i][j];
            for p in [i, j] {
                if cracks.size[p] >= split {
                    let held = self.friction * (-s[p][p]).max(0.0);
                    t = t.clamp(-held, held);
                }
            }
            s[i][j] = t;
            s[j][i] = t;
        }
        (e, full(&rotate_out(&s, &cracks.normals)))
    }
}

/// The solution of the leading `n` x `n` block of `a x = b` (`n` up to 3),
/// by Cramer's rule.
fn solve_small(a: &[[f64; 3]; 3], b: &[f64; 3], n: usize) -> [f64; 3] {
    match n {
        0 => [0.0; 3],
        1 => [b[0] / a[0][0], 0.0, 0.0],
        2 => {
            let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
            [
                (b[0] * a[1][1] - a[0][1] * b[1]) / det,
                (a[0][0] * b[1] - b[0] * a[1][0]) / det,
                0.0,
            ]
        }
        _ => {
            let det3 = |m: &[[f64; 3]; 3]| {
                m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
                    - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
                    + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
            };
            let det = det3(a);
            std::array::from_fn(|c| {
                let mut m = *a;
                for r in 0..3 {
                    m[r][c] = b[r];
                }
                det3(&m) / det
            })
        }
    }
}

/// The frame `n` made orthonormal again (Gram-Schmidt on the first two, the
/// third their cross product).
fn orthonormal(n: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let unit = |v: [f64; 3]| {
        let l = dot(&v, &v).sqrt();
        v.map(|x| x / l)
    };
    let a = unit(n[0]);
    let d = dot(&a, &n[1]);
    let b = unit(std::array::from_fn(|i| n[1][i] - d * a[i]));
    let c = [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ];
    [a, b, c]
}

#[cfg(test)]
mod tests {
    use super::*;

    const K: f64 = 150e9;
    const G: f64 = 80e9;

    /// Planes along the axes, at the flaws of `p`, intact.
    fn in_axes(p: &CrackPlanes) -> TensileCracks {
        TensileCracks {
            normals: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            size: [p.flaw_size; 3],
            opening: [0.0; 3],
            shielding: None,
        }
    }

    fn planes() -> CrackPlanes {
        CrackPlanes {
            nu: 0.25,
            youngs_modulus: 220e9,
            flaw_density: 1.83e10,
            flaw_size: 50e-6,
            critical_density: 0.75,
            friction: 0.72,
            shields: true,
        }
    }

    /// The eigen-decomposition reproduces the matrix and sorts the values.
    #[test]
    fn principal_frame() {
        let s = [[3.0, 1.0, 0.5], [1.0, -2.0, 0.25], [0.5, 0.25, 1.0]];
        let (w, v) = principal(&s);
        assert!(w[0] >= w[1] && w[1] >= w[2]);
        let back = rotate_out(&[[w[0], 0.0, 0.0], [0.0, w[1], 0.0], [0.0, 0.0, w[2]]], &v);
        for i in 0..3 {
            for j in 0..3 {
                assert!((back[i][j] - s[i][j]).abs() < 1e-12, "{back:?}");
            }
        }
        // Trace and right-handedness.
        assert!((w.iter().sum::<f64>() - 2.0).abs() < 1e-12);
        let c = [
            v[0][1] * v[1][2] - v[0][2] * v[1][1],
            v[0][2] * v[1][0] - v[0][0] * v[1][2],
            v[0][0] * v[1][1] - v[0][1] * v[1][0],
        ];
        assert!((dot(&c, &v[2]) - 1.0).abs() < 1e-12);
    }

    /// Sneddon's penny crack: in pure tension the release rate is
    /// `4 (1 - nu^2) sigma^2 a / (pi E)`, and the opening stress
    /// `K_IC sqrt(pi / (4 a))`.
    #[test]
    fn penny_crack_in_tension() {
        let p = planes();
        let (sn, a) = (0.3e9, 50e-6);
        let sneddon = 4.0 * (1.0 - p.nu * p.nu) * sn * sn * a / (PI * p.youngs_modulus);
        assert!((p.release_rate(a, sn, 0.0) / sneddon - 1.0).abs() < 1e-14);
        let k_ic: f64 = 3.25e6;
        let gc = k_ic * k_ic * (1.0 - p.nu * p.nu) / p.youngs_modulus;
        let onset = p.opening_stress(a, gc);
        assert!((onset / (k_ic * (PI / (4.0 * a)).sqrt()) - 1.0).abs() < 1e-14);
        assert_eq!(p.release_rate(a, -sn, 1e9), 0.0);
    }

    /// No plane forms below the opening stress; above it the planes are
    /// the principal directions and the plane under tension grows.
    #[test]
    fn planes_form_at_the_opening_stress() {
        let p = planes();
        let gc = 44.7;
        let onset = p.opening_stress(p.flaw_size, gc);
        let pull = |s: f64| [0.0, s, 0.0, 0.0, 0.0, 0.0];
        assert_eq!(
            p.step(
                None,
                &pull(0.99 * onset),
                &[0.0; 3],
                1e-9,
                gc,
                |_| 1000.0,
                &Shield::NONE
            ),
            None
        );
        let grow = |g: f64| if g > gc { 1000.0 } else { 0.0 };
        let c = p
            .step(
                None,
                &pull(1.01 * onset),
                &[0.0; 3],
                1e-9,
                gc,
                grow,
                &Shield::NONE,
            )
            .unwrap();
        assert!((c.normals[0][1].abs() - 1.0).abs() < 1e-12, "{c:?}");
        assert!((c.size[0] - (p.flaw_size + 1e-6)).abs() < 1e-15);
        // The other two planes carry no tension: they do not grow.
        assert_eq!(c.size[1], p.flaw_size);
        assert_eq!(c.size[2], p.flaw_size);
    }

    /// A shield within 45° of the plane under tension keeps it from
    /// starting (the planes are fixed), one beyond 45° does not; a shielded plane that
    /// has not grown stays at its flaw while one that has grown goes on,
    /// and the grown planes count their age.
    #[test]
    fn a_shield_keeps_aligned_planes_from_starting() {
        let p = planes();
        let gc = 44.7;
        let onset = p.opening_stress(p.flaw_size, gc);
        let pull = [0.0, 1.01 * onset, 0.0, 0.0, 0.0, 0.0];
        let grow = |g: f64| if g > gc { 1000.0 } else { 0.0 };
        let mut near = Shield::NONE;
        assert!(near.add([0.0, 0.8, 0.6]));
        let mut far = Shield::NONE;
        assert!(far.add([0.6, 0.0, 0.8]));
        let held = p
            .step(None, &pull, &[0.0; 3], 1e-9, gc, grow, &near)
            .unwrap();
        assert_eq!(held.size, [p.flaw_size; 3], "fixed, not grown");
        assert_eq!(held.shielding.unwrap().age, [0.0; 3]);
        let c = p
            .step(None, &pull, &[0.0; 3], 1e-9, gc, grow, &far)
            .unwrap();
        assert!(c.size[0] > p.flaw_size);
        assert_eq!(c.shielding.unwrap().age, [1e-9, 0.0, 0.0]);
        // Formed, with tension now across the second plane as well.
        let both = [onset * 1.01, onset * 1.01, 0.0, 0.0, 0.0, 0.0];
        let mut across = Shield::NONE;
        across.add([1.0, 0.0, 0.0]);
        across.add([0.0, 1.0, 0.0]);
        let frame = TensileCracks {
            normals: [[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
            ..c
        };
        let d = p
            .step(Some(frame), &both, &[0.0; 3], 1e-9, gc, grow, &across)
            .unwrap();
        assert!(d.size[0] > c.size[0], "a grown plane goes on");
        assert_eq!(d.size[1], p.flaw_size, "a shielded plane does not start");
        assert_eq!(d.shielding.unwrap().age, [2e-9, 0.0, 0.0]);
        let e = p
            .step(Some(frame), &both, &[0.0; 3], 1e-9, gc, grow, &Shield::NONE)
            .unwrap();
        assert!(e.size[1] > p.flaw_size);
    }

    /// A capped plane carries the stress of its flaws' compliance up to its
    /// cap and the cap past it; the uncapped planes are as without caps.
    #[test]
    fn a_capped_plane_carries_at_most_its_cap() {
        let p = planes();
        let c = in_axes(&p);
        let cap = 1e8;
        let low = [0.5e8, 0.0, 0.0, 0.0, 0.0, 0.0];
        assert_eq!(
            p.open_capped(&c, &low, K, G, [Some(cap), None, None]),
            p.open(&c, &low, K, G)
        );
        let high = [3e8, 1e8, -5e7, 0.0, 0.0, 0.0];
        let (e, carried) = p.open_capped(&c, &high, K, G, [Some(cap), None, None]);
        assert!((carried[0] - cap).abs() < 1e-6 * cap, "{carried:?}");
        let (e0, free) = p.open(&c, &high, K, G);
        assert!(free[0] > cap && e[0] > e0[0], "{free:?} {e:?} {e0:?}");
        // The plane along y keeps its flaws' compliance.
        let gamma = p.flaw_density * p.flaw_size.powi(3);
        let bn = 16.0 * (1.0 - p.nu * p.nu) / (3.0 * p.youngs_modulus);
        assert!((e[1] / (bn * gamma * carried[1]) - 1.0).abs() < 1e-9);
    }

    /// A split plane carries no tension across it and keeps the stresses
    /// along it; in compression it carries the normal stress whole and its
    /// shear up to friction.
    #[test]
    fn a_split_plane_carries_compression_only() {
        let p = planes();
        let c = TensileCracks {
            size: [p.split_size(), p.flaw_size, p.flaw_size],
            ..in_axes(&p)
        };
        let sigma = [2e8, 1e8, -5e7, 3e7, 0.0, 0.0];
        let carried = p.open(&c, &sigma, K, G).1;
        assert!(carried[0].abs() < 1e-6, "{carried:?}");
        assert_eq!(carried[3], 0.0);
        // The difference is the cracks' opening (Hooke's law inverted):
        // along x whatever frees the split plane, along y the compliance
        // of the y plane's flaws, `B_n gamma sigma_yy` (Kachanov), none
        // along z, where the plane is in compression.
        let (e, nu) = (
            9.0 * K * G / (3.0 * K + G),
            (3.0 * K - 2.0 * G) / (2.0 * (3.0 * K + G)),
        );
        let d: [f64; 3] = std::array::from_fn(|i| sigma[i] - carried[i]);
        let strain = |i: usize| (d[i] - nu * (d[(i + 1) % 3] + d[(i + 2) % 3])) / e;
        let gamma = p.flaw_density * p.flaw_size.powi(3);
        let bn = 16.0 * (1.0 - p.nu * p.nu) / (3.0 * p.youngs_modulus);
        assert!(strain(2).abs() < 1e-18, "{}", strain(2));
        assert!((strain(1) / (bn * gamma * carried[1]) - 1.0).abs() < 1e-9);
        assert!(strain(0) > 0.0);
        // The openings take their Poisson share out of the stress along z.
        let lambda = K - 2.0 / 3.0 * G;
        assert!((carried[2] - (-5e7 - lambda * (strain(0) + strain(1)))).abs() < 1e-6);
        // Compression across the split plane: whole; shear up to mu |sn|.
        let sigma = [-2e8, 0.0, 0.0, 3e8, 0.0, 0.0];
        let carried = p.open(&c, &sigma, K, G).1;
        assert!((carried[0] + 2e8).abs() < 1e-6);
        assert!((carried[3] - 0.72 * 2e8).abs() < 1e-6, "{carried:?}");
        // A frame turned about z by 30 degrees gives the same in its axes.
        let (sa, ca) = (0.5f64, 0.75f64.sqrt());
        let turned = TensileCracks {
            normals: [[ca, sa, 0.0], [-sa, ca, 0.0], [0.0, 0.0, 1.0]],
            ..c
        };
        let sigma_axes = full(&rotate_out(
            &matrix(&[2e8, 1e8, -5e7, 3e7, 0.0, 0.0]),
            &turned.normals,
        ));
        let back = matrix(&p.open(&turned, &sigma_axes, K, G).1);
        let inframe = full(&rotate_in(&back, &turned.normals));
        let unturned = p.open(&c, &[2e8, 1e8, -5e7, 3e7, 0.0, 0.0], K, G).1;
        for (a, b) in inframe.iter().zip(unturned) {
            assert!((a - b).abs() < 1e-6, "{inframe:?} {unturned:?}");
        }
    }

    /// The planes turn with the spin and stay orthonormal.
    #[test]
    fn planes_turn_with_the_material() {
        let p = planes();
        let c = in_axes(&p);
        // W_XY = -1/s over 1e-3 s in 1000 steps: about 1e-3 rad about z.
        let mut c = Some(c);
        for _ in 0..1000 {
            c = p.step(
                c,
                &[0.0; 6],
                &[-1.0, 0.0, 0.0],
                1e-6,
                44.7,
                |_| 0.0,
                &Shield::NONE,
            );
        }
        let n = c.unwrap().normals;
        let angle = n[0][1].atan2(n[0][0]);
        assert!((angle - 1e-3).abs() < 1e-8, "{angle}");
        for i in 0..3 {
            for j in 0..3 {
                let d = dot(&n[i], &n[j]);
                assert!((d - if i == j { 1.0 } else { 0.0 }).abs() < 1e-14);
            }
        }
    }
}
