//! The observables of a rod striking an anvil (Taylor impact), computed from
//! particle positions and velocities and the particle sets that the scene's
//! builder tags, in any dimension.
//!
//! Points have `D` coordinates; the last is the rod's axis (Z, the anvil at
//! Z = 0 and the rod above it), the others span its cross-section. In the
//! axisymmetric form (D = 2) the first coordinate is the radius R itself;
//! in 3-D the radius is √(x² + y²).

/// Radial strain below which the rod counts as undeformed (0.2 %).
pub const UNDEFORMED_STRAIN: f64 = 0.002;

/// The particle sets of a rod, tagged by the scene's builder.
#[derive(Debug, Clone, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub struct RodSets {
    /// The particles of the impact face (on the anvil at the start).
    pub face: Vec<usize>,
    /// One generator of the mantle, in order from the impact face to the
    /// free end.
    pub mantle: Vec<usize>,
    /// The particle on the axis at the free end.
    pub tail: usize,
}

/// The rod observables at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RodObservables {
    /// Extent of the rod along the axis (m).
    pub rod_length: f64,
    /// Largest distance of a face particle from the axis (m).
    pub mushroom_radius: f64,
    /// Length of the part of the rod whose mantle has strained less than
    /// [`UNDEFORMED_STRAIN`] in radius, measured from the free end (m).
    pub undeformed_length: f64,
    /// Speed of the tail toward the anvil (m/s).
    pub tail_velocity: f64,
}

/// Distance of a point from the rod's axis.
#[inline]
pub fn radius<const D: usize>(p: &[f64; D]) -> f64 {
    if D == 2 {
        // The axisymmetric radius R, as it is (R >= 0).
        p[0]
    } else {
        p[..D - 1].iter().map(|x| x * x).sum::<f64>().sqrt()
    }
}

/// Coordinate of a point along the rod's axis.
#[inline]
pub fn axial<const D: usize>(p: &[f64; D]) -> f64 {
    p[D - 1]
}

impl RodObservables {
    /// The observables of a rod of initial radius `r0` whose particles are
    /// at `pos` with velocities `vel`.
    pub fn of<const D: usize>(sets: &RodSets, pos: &[[f64; D]], vel: &[[f64; D]], r0: f64) -> Self {
        RodObservables {
            rod_length: rod_length(pos),
            mushroom_radius: mushroom_radius(&sets.face, pos),
            undeformed_length: undeformed_length(&sets.mantle, pos, r0),
            tail_velocity: tail_velocity(sets.tail, vel),
        }
    }
}

/// [`RodObservables::rod_length`]: the extent of the particles at `pos`
/// along the axis (one pass over them, nothing allocated).
pub fn rod_length<const D: usize>(pos: &[[f64; D]]) -> f64 {
    let (zmin, zmax) = pos
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
            (lo.min(axial(x)), hi.max(axial(x)))
        });
    zmax - zmin
}

/// [`RodObservables::mushroom_radius`]: the largest distance from the axis
/// of the `face` particles.
pub fn mushroom_radius<const D: usize>(face: &[usize], pos: &[[f64; D]]) -> f64 {
    face.iter().map(|&i| radius(&pos[i])).fold(0.0, f64::max)
}

/// [`RodObservables::undeformed_length`] of a rod of initial radius `r0`
/// along the `mantle` generator (from the face to the free end): walks down
/// from the free end to the first particle strained past
/// [`UNDEFORMED_STRAIN`], and interpolates.
pub fn undeformed_length<const D: usize>(mantle: &[usize], pos: &[[f64; D]], r0: f64) -> f64 {
    let strain = |k: usize| radius(&pos[mantle[k]]) / r0 - 1.0;
    let z_of = |k: usize| axial(&pos[mantle[k]]);
    let last = mantle.len() - 1;
    let z_top = z_of(last);
    for k in (0..last).rev() {
        if strain(k) >= UNDEFORMED_STRAIN {
            let (s0, s1) = (strain(k + 1), strain(k));
            let frac = ((UNDEFORMED_STRAIN - s0) / (s1 - s0)).clamp(0.0, 1.0);
            let z = z_of(k + 1) + frac * (z_of(k) - z_of(k + 1));
            return z_top - z;
        }
    }
    z_top - z_of(0)
}

/// [`RodObservables::tail_velocity`]: the speed of the particle `tail`
/// toward the anvil.
pub fn tail_velocity<const D: usize>(tail: usize, vel: &[[f64; D]]) -> f64 {
    -axial(&vel[tail])
}

/// The rod's outline: `(axial, radius)` of each particle of the `mantle`
/// generator, from the impact face to the free end.
pub fn profile<const D: usize>(mantle: &[usize], pos: &[[f64; D]]) -> Vec<[f64; 2]> {
    mantle
        .iter()
        .map(|&i| [axial(&pos[i]), radius(&pos[i])])
        .collect()
}

/// The radius of an outline (as `profile` gives it, in increasing axial
/// order) at height `z`, linear between its points; `None` outside it.
pub fn profile_radius(outline: &[[f64; 2]], z: f64) -> Option<f64> {
    outline.windows(2).find_map(|w| {
        let ([z0, r0], [z1, r1]) = (w[0], w[1]);
        (z0 <= z && z <= z1).then(|| {
            if z1 > z0 {
                r0 + (z - z0) / (z1 - z0) * (r1 - r0)
            } else {
                r0.max(r1)
            }
        })
    })
}

/// How far the outline `a` lies from the outline `b`: the largest
/// `|r_a(z) / r_b(z) − 1|` over `samples` heights spread evenly over the
/// span the two share (their ends excluded, where one outline may hold a
/// corner the other has just passed), and the heights' span. `None` when
/// the outlines share no span.
pub fn profile_deviation(a: &[[f64; 2]], b: &[[f64; 2]], samples: usize) -> Option<f64> {
    let lo = a.first()?[0].max(b.first()?[0]);
    let hi = a.last()?[0].min(b.last()?[0]);
    if hi.partial_cmp(&lo) != Some(std::cmp::Ordering::Greater) || samples == 0 {
        return None;
    }
    (1..=samples)
        .map(|k| lo + (hi - lo) * k as f64 / (samples + 1) as f64)
        .map(|z| Some((profile_radius(a, z)? / profile_radius(b, z)? - 1.0).abs()))
        .try_fold(0.0f64, |m, d| Some(m.max(d?)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A rod of radius 1 and length 10 on a lattice (spacing 1/2), with its
    /// lowest `bulge` rows spread radially by `strain(row)`; in 2-D as the
    /// (R, Z) half plane, in 3-D as the full cross-section.
    fn rod<const D: usize>(strain: impl Fn(usize) -> f64) -> (RodSets, Vec<[f64; D]>) {
        let (nr, nz) = (3usize, 21usize);
        let mut pos = Vec::new();
        let mut sets = RodSets::default();
        for k in 0..nz {
            let z = 0.5 * k as f64;
            let s = 1.0 + strain(k);
            for j in 0..nr {
                let r = s * 0.5 * j as f64;
                // In 3-D, four points at each ring (+x, +y, -x, -y).
                let ring: Vec<[f64; D]> = if D == 2 || j == 0 {
                    vec![std::array::from_fn(|d| {
                        if d == D - 1 {
                            z
                        } else if d == 0 {
                            r
                        } else {
                            0.0
                        }
                    })]
                } else {
                    [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)]
                        .iter()
                        .map(|&(cx, cy)| std::array::from_fn(|d| [r * cx, r * cy, z][d + 3 - D]))
                        .collect()
                };
                for p in ring {
                    let i = pos.len();
                    if k == 0 {
                        sets.face.push(i);
                    }
                    if j == nr - 1 && radius(&p) > 0.0 && p[0] > 0.0 {
                        sets.mantle.push(i);
                    }
                    if k == nz - 1 && j == 0 {
                        sets.tail = i;
                    }
                    pos.push(p);
                }
            }
        }
        (sets, pos)
    }

    fn check<const D: usize>() {
        // The lowest rows bulge: 30 % at the face, 10 % at Z = 0.5,
        // 0.1 % at Z = 1, none above.
        let bulge = |k: usize| [0.3, 0.1, 0.001].get(k).copied().unwrap_or(0.0);
        let (sets, pos) = rod::<D>(bulge);
        let mut vel = vec![[0.0; D]; pos.len()];
        vel[sets.tail][D - 1] = -150.0;
        let o = RodObservables::of(&sets, &pos, &vel, 1.0);
        assert_eq!(o.rod_length, 10.0);
        assert!(
            (o.mushroom_radius - 1.3).abs() < 1e-15,
            "{}",
            o.mushroom_radius
        );
        assert_eq!(o.tail_velocity, 150.0);
        // The threshold 0.2 % lies between Z = 1 (0.1 %) and Z = 0.5 (10 %):
        // at Z = 1 - 0.5 (0.002 - 0.001) / (0.1 - 0.001).
        let z = 1.0 - 0.5 * (0.002 - 0.001) / (0.1 - 0.001);
        assert!((o.undeformed_length - (10.0 - z)).abs() < 1e-12, "{o:?}");
        // An undeformed rod: the whole length.
        let (sets, pos) = rod::<D>(|_| 0.0);
        let o = RodObservables::of(&sets, &pos, &vel, 1.0);
        assert_eq!((o.undeformed_length, o.mushroom_radius), (10.0, 1.0));
    }

    #[test]
    fn observables_of_a_bulged_rod_in_two_and_three_dimensions() {
        check::<2>();
        check::<3>();
        assert_eq!(radius(&[3.0, 4.0, -7.0]), 5.0);
        assert_eq!(radius(&[0.25, -7.0]), 0.25);
    }

    /// The outline of the bulged rod follows its mantle; the radius between
    /// two points is the chord's; an outline 2 % wider everywhere deviates
    /// by 2 %, and one that bulges only at the face by the bulge where the
    /// samples meet it.
    #[test]
    fn outlines_interpolate_and_compare() {
        let bulge = |k: usize| [0.3, 0.1, 0.001].get(k).copied().unwrap_or(0.0);
        let (sets, pos) = rod::<3>(bulge);
        let o = profile(&sets.mantle, &pos);
        assert_eq!(o.len(), 21);
        assert_eq!((o[0], o[20]), ([0.0, 1.3], [10.0, 1.0]));
        // Between Z = 0 (1.3) and 0.5 (1.1): at 0.125, 1.3 - 0.25 * 0.2.
        assert!((profile_radius(&o, 0.125).unwrap() - 1.25).abs() < 1e-15);
        assert_eq!(profile_radius(&o, 10.5), None);
        let wider: Vec<[f64; 2]> = o.iter().map(|&[z, r]| [z, 1.02 * r]).collect();
        let d = profile_deviation(&wider, &o, 50).unwrap();
        assert!((d - 0.02).abs() < 1e-14, "{d}");
        // Against the straight rod: the largest bulge a sample meets. With
        // 9 samples over (0, 10) the first is at Z = 1 (0.1 %).
        let (_, straight) = rod::<3>(|_| 0.0);
        let d = profile_deviation(&o, &profile(&sets.mantle, &straight), 9).unwrap();
        assert!((d - 0.001).abs() < 1e-14, "{d}");
        assert_eq!(profile_deviation(&o, &[[20.0, 1.0], [30.0, 1.0]], 9), None);
    }
}
