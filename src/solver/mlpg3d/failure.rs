//! The failure modes of a ceramic plate, measured from its nodes' damage:
//! the fracture cone's half-angle, the radial cracks on the rear face and
//! the comminuted zone under the projectile (issue 68).
//!
//! Every measure reads the damage at the material's place at impact (the
//! nodes' reference positions, carried when a node shifts), so that the
//! plate's dishing and the nodes' shifts do not move it: the struck face
//! is z = 0 and the rear face z = −h, the axis is x = y = 0. Nodes are
//! grouped in layers of one spacing through the thickness and in rings of
//! one spacing about the axis. A ring is *damaged* when at least half its
//! nodes are (a crack density at or past the plate's damaged threshold),
//! *comminuted* when at least half its nodes are comminuted (pulverized,
//! or split on all three tensile crack planes); rings with no
//! node are passed over. The quarter model is mirrored across its planes
//! into the whole plate before anything is counted.

/// The plate's nodes as the measures read them.
#[derive(Debug, Clone, Copy)]
pub struct PlateNodes<'a> {
    /// Each node's place at impact (m).
    pub reference: &'a [[f64; 3]],
    /// Each node's crack density γ = N0* a³.
    pub gamma: &'a [f64],
    /// Each node's crack density across the hoop direction, the one a
    /// radial crack reads (γ itself where the cracks lie in every
    /// orientation).
    pub radial: &'a [f64],
    /// Whether each node is comminuted: pulverized (its isotropic cracks
    /// at the critical density), or split on all three tensile crack
    /// planes (broken in every direction).
    pub pulverized: &'a [bool],
    /// The crack density at which a node counts as damaged.
    pub damaged: f64,
    /// The plate's thickness h (m).
    pub thickness: f64,
    /// The node spacing (m): the width of the layers, rings and sectors.
    pub spacing: f64,
    /// The quarter model x ≥ 0, y ≥ 0 (mirrored into the whole plate).
    pub quarter: bool,
}

/// The half-fraction rule of a ring or sector: at least half its nodes.
const MOST: f64 = 0.5;

impl PlateNodes<'_> {
    /// The radius about the axis of node `i` at impact.
    fn radius(&self, i: usize) -> f64 {
        let [x, y, _] = self.reference[i];
        (x * x + y * y).sqrt()
    }

    /// The layer of node `i` (0 at the struck face) and the number of
    /// layers.
    fn layer(&self, i: usize) -> usize {
        (-self.reference[i][2] / self.spacing).round().max(0.0) as usize
    }

    /// The outer radius of the run of rings from the axis in which `hit`
    /// holds for at least half the nodes, over the nodes `of`; 0 when the
    /// first ring with nodes fails.
    fn front(&self, of: impl Iterator<Item = usize>, hit: impl Fn(usize) -> bool) -> f64 {
        let mut rings: Vec<(u32, u32)> = Vec::new();
        for i in of {
            let k = (self.radius(i) / self.spacing) as usize;
            if rings.len() <= k {
                rings.resize(k + 1, (0, 0));
            }
            rings[k].0 += 1;
            rings[k].1 += u32::from(hit(i));
        }
        let mut outer = 0.0;
        for (k, &(n, h)) in rings.iter().enumerate() {
            if n == 0 {
                continue;
            }
            if f64::from(h) < MOST * f64::from(n) {
                break;
            }
            outer = (k + 1) as f64 * self.spacing;
        }
        outer
    }

    /// The fracture cone's half-angle (degrees from the axis): in each
    /// layer through the thickness, the damage front (the outer radius of
    /// the damaged rings from the axis), fitted by least squares as a
    /// straight line of the depth from the struck face to the rear face;
    /// the angle of that line from the axis. 90° − the angle is the cone's
    /// angle to the plate's faces. 0 when fewer than two layers have a
    /// front (no cone: nothing damaged under the projectile), and for a
    /// front at the same radius through the thickness (a cylinder, or a
    /// plate damaged to its rim); negative for a front wider at the struck
    /// face than at the rear (a crater).
    pub fn cone_half_angle(&self) -> f64 {
        let layers = (self.thickness / self.spacing).round() as usize + 1;
        let mut points = Vec::new();
        for k in 0..layers {
            let of = (0..self.reference.len()).filter(|&i| self.layer(i) == k);
            let r = self.front(of, |i| self.gamma[i] >= self.damaged);
            if r > 0.0 {
                points.push((k as f64 * self.spacing, r));
            }
        }
        if points.len() < 2 {
            return 0.0;
        }
        let n = points.len() as f64;
        let (sd, sr) = points
            .iter()
            .fold((0.0, 0.0), |(a, b), &(d, r)| (a + d, b + r));
        let (md, mr) = (sd / n, sr / n);
        let (mut sdd, mut sdr) = (0.0, 0.0);
        for &(d, r) in &points {
            sdd += (d - md) * (d - md);
            sdr += (d - md) * (r - mr);
        }
        if sdd == 0.0 {
            return 0.0;
        }
        (sdr / sdd).atan().to_degrees()
    }

    /// The radial cracks on the rear face: the nodes of the rear layer in
    /// the ring of one spacing either side of `radius` (m), in sectors of
    /// about one spacing of arc (at least 16), the quarter mirrored into
    /// the whole circle; a sector is cracked when at least half its nodes
    /// are damaged across the hoop direction (`radial`); the count is the
    /// number of runs of cracked sectors
    /// around the circle. 0 when no sector or every sector is cracked (a
    /// damaged ring is no radial crack).
    pub fn radial_crack_count(&self, radius: f64) -> f64 {
        let rear = (self.thickness / self.spacing).round() as usize;
        let sectors = ((std::f64::consts::TAU * radius / self.spacing).round() as usize).max(16);
        let mut tally = vec![(0u32, 0u32); sectors];
        let mut add = |phi: f64, hit: bool| {
            let s = ((phi.rem_euclid(std::f64::consts::TAU)) / std::f64::consts::TAU
                * sectors as f64) as usize;
            let t = &mut tally[s.min(sectors - 1)];
            t.0 += 1;
            t.1 += u32::from(hit);
        };
        for i in 0..self.reference.len() {
            if self.layer(i) != rear || (self.radius(i) - radius).abs() > self.spacing {
                continue;
            }
            let [x, y, _] = self.reference[i];
            let phi = y.atan2(x);
            let hit = self.radial[i] >= self.damaged;
            add(phi, hit);
            if self.quarter {
                use std::f64::consts::PI;
                add(PI - phi, hit);
                add(PI + phi, hit);
                add(-phi, hit);
            }
        }
        // Sectors with no node take the state of the sector before them.
        let states: Vec<Option<bool>> = tally
            .iter()
            .map(|&(n, h)| (n > 0).then(|| f64::from(h) >= MOST * f64::from(n)))
            .collect();
        let Some(start) = states.iter().position(Option::is_some) else {
            return 0.0;
        };
        let mut filled = vec![false; sectors];
        let mut last = states[start].unwrap_or(false);
        for k in 0..sectors {
            let s = (start + k) % sectors;
            if let Some(v) = states[s] {
                last = v;
            }
            filled[s] = last;
        }
        if filled.iter().all(|&c| c) {
            return 0.0;
        }
        // Runs: a cracked sector after an uncracked one, around the circle.
        (0..sectors)
            .filter(|&s| filled[s] && !filled[(s + sectors - 1) % sectors])
            .count() as f64
    }

    /// The comminuted zone's radius (m): the outer radius of the rings from
    /// the axis, over the whole thickness, in which at least half the nodes
    /// are comminuted; 0 when the ring at the axis is not.
    pub fn comminuted_radius(&self) -> f64 {
        self.front(0..self.reference.len(), |i| self.pulverized[i])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A plate of nodes on a square lattice of spacing `s`, radius `r`,
    /// thickness `h` (the whole plate, or the quarter x, y ≥ 0).
    fn plate(s: f64, r: f64, h: f64, quarter: bool) -> Vec<[f64; 3]> {
        let n = (r / s) as i64;
        let layers = (h / s).round() as i64;
        let mut v = Vec::new();
        for k in 0..=layers {
            for i in -n..=n {
                for j in -n..=n {
                    let (x, y) = (i as f64 * s, j as f64 * s);
                    if x * x + y * y > r * r || (quarter && (x < 0.0 || y < 0.0)) {
                        continue;
                    }
                    v.push([x, y, -(k as f64) * s]);
                }
            }
        }
        v
    }

    fn nodes<'a>(
        reference: &'a [[f64; 3]],
        gamma: &'a [f64],
        pulverized: &'a [bool],
        s: f64,
        h: f64,
        quarter: bool,
    ) -> PlateNodes<'a> {
        PlateNodes {
            reference,
            gamma,
            radial: gamma,
            pulverized,
            damaged: 0.1,
            thickness: h,
            spacing: s,
            quarter,
        }
    }

    #[test]
    fn a_cone_of_known_angle_is_measured() {
        let (s, r, h) = (0.25e-3, 40e-3, 5e-3);
        let x = plate(s, r, h, true);
        for angle in [30.0f64, 45.0, 63.0, 70.0] {
            let gamma: Vec<f64> = x
                .iter()
                .map(|p| {
                    let front = 5e-3 + (-p[2]) * angle.to_radians().tan();
                    if p[0].hypot(p[1]) <= front { 1.0 } else { 0.0 }
                })
                .collect();
            let none = vec![false; x.len()];
            let got = nodes(&x, &gamma, &none, s, h, true).cone_half_angle();
            // The front is found to a ring (one spacing) in each of 21 layers.
            assert!((got - angle).abs() < 1.5, "{angle}: {got}");
        }
    }

    #[test]
    fn a_cylinder_a_whole_plate_and_a_crater_are_not_cones() {
        let (s, r, h) = (0.5e-3, 20e-3, 5e-3);
        let x = plate(s, r, h, false);
        let none = vec![false; x.len()];
        let cyl: Vec<f64> = x
            .iter()
            .map(|p| f64::from(p[0].hypot(p[1]) <= 6e-3))
            .collect();
        // Zero to round-off in the fit.
        assert!(nodes(&x, &cyl, &none, s, h, false).cone_half_angle().abs() < 1e-9);
        let all = vec![1.0; x.len()];
        assert!(nodes(&x, &all, &none, s, h, false).cone_half_angle().abs() < 1e-9);
        let zero = vec![0.0; x.len()];
        assert_eq!(nodes(&x, &zero, &none, s, h, false).cone_half_angle(), 0.0);
        // Wider at the struck face: a crater, a negative angle.
        let crater: Vec<f64> = x
            .iter()
            .map(|p| f64::from(p[0].hypot(p[1]) <= 10e-3 + p[2]))
            .collect();
        let got = nodes(&x, &crater, &none, s, h, false).cone_half_angle();
        assert!((got + 45.0).abs() < 2.0, "{got}");
    }

    /// Damage in `wedges` (centre angles, rad) of half-width `half` on the
    /// rear face.
    fn wedges(x: &[[f64; 3]], h: f64, centres: &[f64], half: f64) -> Vec<f64> {
        x.iter()
            .map(|p| {
                let phi = p[1].atan2(p[0]);
                let near = centres.iter().any(|c| {
                    let d = (phi - c).rem_euclid(std::f64::consts::TAU);
                    d.min(std::f64::consts::TAU - d) <= half
                });
                f64::from(p[2] <= -h + 1e-9 && near)
            })
            .collect()
    }

    #[test]
    fn radial_cracks_are_counted_and_a_ring_is_none() {
        let (s, r, h) = (0.25e-3, 20e-3, 2e-3);
        let x = plate(s, r, h, false);
        let none = vec![false; x.len()];
        let six: Vec<f64> = (0..6)
            .map(|k| k as f64 * std::f64::consts::TAU / 6.0 + 0.2)
            .collect();
        let g = wedges(&x, h, &six, 0.08);
        assert_eq!(
            nodes(&x, &g, &none, s, h, false).radial_crack_count(10e-3),
            6.0
        );
        let ring = wedges(&x, h, &[0.0], 4.0);
        assert_eq!(
            nodes(&x, &ring, &none, s, h, false).radial_crack_count(10e-3),
            0.0
        );
        let zero = vec![0.0; x.len()];
        assert_eq!(
            nodes(&x, &zero, &none, s, h, false).radial_crack_count(10e-3),
            0.0
        );
        // Damage off the rear face is not counted.
        let top: Vec<f64> = x.iter().map(|p| f64::from(p[2] > -h + 1e-9)).collect();
        assert_eq!(
            nodes(&x, &top, &none, s, h, false).radial_crack_count(10e-3),
            0.0
        );
    }

    #[test]
    fn radial_cracks_read_the_damage_across_the_hoop_direction() {
        // A rear face damaged all round (a ring, as split planes of any
        // orientation read), with five wedges where the planes across the
        // hoop direction are split: five radial cracks, not none.
        let (s, r, h) = (0.25e-3, 20e-3, 2e-3);
        let x = plate(s, r, h, false);
        let none = vec![false; x.len()];
        let ring = wedges(&x, h, &[0.0], 4.0);
        let five: Vec<f64> = (0..5)
            .map(|k| k as f64 * std::f64::consts::TAU / 5.0 + 0.1)
            .collect();
        let hoop = wedges(&x, h, &five, 0.08);
        let mut plate = nodes(&x, &ring, &none, s, h, false);
        assert_eq!(plate.radial_crack_count(10e-3), 0.0);
        plate.radial = &hoop;
        assert_eq!(plate.radial_crack_count(10e-3), 5.0);
        // The cone reads the damage whatever its orientation.
        assert_eq!(
            plate.cone_half_angle(),
            nodes(&x, &ring, &none, s, h, false).cone_half_angle()
        );
    }

    #[test]
    fn the_quarter_is_mirrored_into_the_whole_plate() {
        let (s, r, h) = (0.25e-3, 20e-3, 2e-3);
        let x = plate(s, r, h, true);
        let none = vec![false; x.len()];
        // One crack at 45° (four in the plate) and one on the plane y = 0
        // (two: at 0 and 180°).
        let g = wedges(&x, h, &[std::f64::consts::FRAC_PI_4, 0.0], 0.08);
        assert_eq!(
            nodes(&x, &g, &none, s, h, true).radial_crack_count(10e-3),
            6.0
        );
        // The same cracks in the whole plate.
        let whole = plate(s, r, h, false);
        let none_w = vec![false; whole.len()];
        use std::f64::consts::{FRAC_PI_4, PI};
        let centres = [
            FRAC_PI_4,
            3.0 * FRAC_PI_4,
            5.0 * FRAC_PI_4,
            7.0 * FRAC_PI_4,
            0.0,
            PI,
        ];
        let gw = wedges(&whole, h, &centres, 0.08);
        assert_eq!(
            nodes(&whole, &gw, &none_w, s, h, false).radial_crack_count(10e-3),
            6.0
        );
    }

    #[test]
    fn the_comminuted_radius_is_the_pulverized_disc() {
        let (s, r, h) = (0.25e-3, 20e-3, 2e-3);
        let x = plate(s, r, h, true);
        let g = vec![0.0; x.len()];
        for rc in [2e-3, 7.3e-3] {
            let p: Vec<bool> = x.iter().map(|p| p[0].hypot(p[1]) <= rc).collect();
            let got = nodes(&x, &g, &p, s, h, true).comminuted_radius();
            assert!((got - rc).abs() <= s, "{rc}: {got}");
        }
        let none = vec![false; x.len()];
        assert_eq!(nodes(&x, &g, &none, s, h, true).comminuted_radius(), 0.0);
    }
}
