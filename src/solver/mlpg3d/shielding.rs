//! Crack shielding (obscuration) among the ceramic's tensile cracks
//! (issue 68), on when a ceramic's `shield_radius` is set.
//!
//! A tensile crack that has started to grow unloads the material beside it
//! across its own plane, over a zone that grows with the crack: the
//! obscuration zone of Denoual & Hild (2000; Forquin & Hild 2010), inside
//! which no new crack of that orientation starts. Here a plane `k` of a
//! node `j` that has grown for a time `t_k` shields, around the node's
//! position `x_j` with the plane's normal `n_k`, every point `x`
//!
//! - within `R = min(n1+ C_R t_k, shield_radius)` of `x_j`, the distance
//!   its crack has run at the opening cracks' terminal speed
//!   ([`crate::material::rajendran_grove::RajendranGrove::shield_speed`]),
//! - off the crack's own plane, `|(x - x_j) . n_k| > w / 2` with `w` the
//!   smallest radial spacing of the bodies (on its plane the crack runs on:
//!   those points may crack),
//!
//! for the planes of that point whose normals lie within 45° of `n_k`
//! ([`Shield`]). A point's plane that would start to grow in a step where a
//! zone of the step's start holds it does not; a plane that has grown goes
//! on. So the first cracks to start, at the weakest flaws or the highest
//! stress, keep their neighbours from cracking alike over a length that
//! grows with time: how many cracks a ring of material gets depends on how
//! fast its tension rises against how fast the zones spread, as in Grady's
//! and Mott's fragmentation, not on the node spacing alone.
//!
//! The zones are those of the start of the step, the same on every thread
//! and rank (each rank holds every node's state); in the quarter model a
//! crack's images across `x = 0` and `y = 0` shield too.

use super::util::material_of;
use crate::approx::mirror::{self, X, Y};
use crate::material::tensile_cracks::{TensileCracks, dot};
use crate::material::{Damage, Material, PointState, Shield};
use crate::solver::mlpg3d::Body;
use std::collections::HashMap;

/// A crack that shields: where, its plane's normal, its zone's radius.
#[derive(Debug, Clone, Copy)]
struct Zone {
    node: usize,
    pos: [f64; 3],
    normal: [f64; 3],
    radius: f64,
}

/// The shielding zones of a step's start, in cells of the largest radius.
#[derive(Debug)]
pub(super) struct Shielding {
    cell: f64,
    half_width: f64,
    zones: Vec<Zone>,
    cells: HashMap<[i64; 3], Vec<u32>>,
}

/// The largest `shield_radius` of the materials of a run (0: none shields).
pub(super) fn largest_radius(rod: &Material, others: &[Body]) -> f64 {
    std::iter::once(rod)
        .chain(others.iter().map(|b| &b.material))
        .map(|m| match &m.damage {
            Damage::RajendranGrove(c) if c.tensile_flaw_size > 0.0 => c.shield_radius,
            _ => 0.0,
        })
        .fold(0.0, f64::max)
}

impl Shielding {
    /// The zones of the nodes' cracks in `states` at `pos`; `width` the
    /// smallest radial spacing, `quarter` whether the run is the quarter
    /// model. `None` where no material shields.
    pub(super) fn of(
        (rod, others, group): (&Material, &[Body], &[u8]),
        states: &[PointState],
        pos: &[[f64; 3]],
        width: f64,
        quarter: bool,
    ) -> Option<Shielding> {
        let cell = largest_radius(rod, others);
        if cell <= 0.0 {
            return None;
        }
        let mut zones = Vec::new();
        for (node, (state, &x)) in states.iter().zip(pos).enumerate() {
            let (Damage::RajendranGrove(c), Some(vars)) = (
                &material_of(rod, others, group, node).damage,
                state.ceramic(),
            ) else {
                continue;
            };
            let Some(cracks) = vars.tensile else { continue };
            if c.shield_radius <= 0.0 {
                continue;
            }
            for k in 0..3 {
                let age = cracks.shielding.map_or(0.0, |kept| kept.age[k]);
                let radius = (c.shield_speed() * age).min(c.shield_radius);
                if radius <= 0.0 {
                    continue;
                }
                let n = cracks.normals[k];
                zones.push(Zone {
                    node,
                    pos: x,
                    normal: n,
                    radius,
                });
                if quarter {
                    // The images whose zones reach into the quarter.
                    for bits in [X, Y, X | Y] {
                        let near =
                            (bits & X == 0 || x[0] < radius) && (bits & Y == 0 || x[1] < radius);
                        if near {
                            zones.push(Zone {
                                node,
                                pos: mirror::vector(&x, bits),
                                normal: mirror::vector(&n, bits),
                                radius,
                            });
                        }
                    }
                }
            }
        }
        Some(Self::index(zones, cell, width))
    }

    /// The zones in cells of side `cell`, for planes `width` thick.
    fn index(zones: Vec<Zone>, cell: f64, width: f64) -> Shielding {
        let mut cells: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
        for (z, zone) in zones.iter().enumerate() {
            cells
                .entry(Self::cell_of(cell, &zone.pos))
                .or_default()
                .push(z as u32);
        }
        Shielding {
            cell,
            half_width: 0.5 * width,
            zones,
            cells,
        }
    }

    fn cell_of(cell: f64, x: &[f64; 3]) -> [i64; 3] {
        x.map(|v| (v / cell).floor() as i64)
    }

    /// Whether a plane of normal `n` of node `node` at `x` lies in a zone of
    /// another node's crack that shields it.
    pub(super) fn holds(&self, node: usize, x: &[f64; 3], n: &[f64; 3]) -> bool {
        let c = Self::cell_of(self.cell, x);
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let Some(list) = self.cells.get(&[c[0] + dx, c[1] + dy, c[2] + dz]) else {
                        continue;
                    };
                    for &z in list {
                        let zone = &self.zones[z as usize];
                        if zone.node == node || dot(n, &zone.normal).abs() < Shield::ALIGNED {
                            continue;
                        }
                        let d = [x[0] - zone.pos[0], x[1] - zone.pos[1], x[2] - zone.pos[2]];
                        if dot(&d, &d) <= zone.radius * zone.radius
                            && dot(&d, &zone.normal).abs() > self.half_width
                        {
                            return true;
                        }
                    }
                }
            }
        }
        false
    }
}

/// The normals of the tensile planes of a point that started to grow in
/// the step from `before` to `after` (up to three).
pub(super) fn started(before: &PointState, after: &PointState) -> Vec<[f64; 3]> {
    let old = before.ceramic().and_then(|v| v.tensile);
    let Some(new) = after.ceramic().and_then(|v| v.tensile) else {
        return Vec::new();
    };
    (0..3)
        .filter(|&k| {
            let age = |c: &TensileCracks| c.shielding.map_or(0.0, |kept| kept.age[k]);
            age(&new) > 0.0 && old.is_none_or(|o| age(&o) == 0.0)
        })
        .map(|k| new.normals[k])
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A crack across x at the origin with a zone of 2 mm shields planes
    /// within 45° of its own beside it (off its plane, inside the zone),
    /// neither those on its plane, nor those outside the zone, nor planes
    /// across it, nor its own node.
    #[test]
    fn a_zone_shields_parallel_planes_beside_its_crack() {
        let s = Shielding::index(
            vec![Zone {
                node: 0,
                pos: [0.0; 3],
                normal: [1.0, 0.0, 0.0],
                radius: 2e-3,
            }],
            5e-3,
            0.5e-3,
        );
        let across = [1.0, 0.0, 0.0];
        let tilted = [0.8, 0.6, 0.0];
        let steep = [0.6, 0.8, 0.0];
        assert!(s.holds(1, &[1e-3, 0.0, 0.0], &across));
        assert!(s.holds(1, &[-1.5e-3, 1e-3, 0.0], &tilted));
        assert!(!s.holds(1, &[1e-3, 0.0, 0.0], &steep));
        assert!(!s.holds(1, &[0.2e-3, 1.5e-3, 0.0], &across), "on its plane");
        assert!(!s.holds(1, &[2.1e-3, 0.0, 0.0], &across), "outside");
        assert!(!s.holds(0, &[1e-3, 0.0, 0.0], &across), "its own node");
        // Across a cell's boundary.
        assert!(s.holds(1, &[-1e-3, 0.0, -1e-3], &across));
    }
}
