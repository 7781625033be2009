//! The nodes whose supports may reach a point, found among nodes of like
//! support radius.
//!
//! One grid with cells of the largest radius lists, around every point,
//! all nodes within that radius, and most of them cover nothing there:
//! in `penetration` a few nodes at the crater's edge grow supports 2.8
//! times the median, and the candidates of a row grew from 2.2 to 17
//! times the nodes that cover it (8 across, quarter model, over the first
//! 600 steps; the note of 2026-11-30 on the penetration step). Here the
//! nodes of each body are split into classes whose radii lie within a
//! factor [`RATIO`], each with its own grid of cells its largest radius
//! wide, so a point meets only nodes that could cover it. The caller's
//! exact test decides, and the list comes back ascending: the rows built
//! from it are the ones a single grid gives, to the bit.

use crate::neighbours::Cells;
use rayon::prelude::*;

/// The largest ratio of radii within one class.
const RATIO: f64 = 1.5;

/// Most classes in a body; the last holds every larger radius.
const MAX_CLASSES: usize = 8;

/// The relative margin of each class's grid radius: the grid only
/// narrows the candidates, so it must never drop one the caller's test
/// (with its own margins) would keep.
const MARGIN: f64 = 1e-6;

/// The grids of [`Covers`] for the nodes of one body.
struct Body<'a> {
    id: u8,
    classes: Vec<Cells<'a, 3>>,
}

/// The nodes whose support radius plus a reach may cover a point, by
/// body and class of radius.
pub(crate) struct Covers<'a> {
    group: &'a [u8],
    bodies: Vec<Body<'a>>,
}

impl<'a> Covers<'a> {
    /// The grids over `points`, node `j` of radius `radius[j]` and of body
    /// `group[j]` (one body when `group` is empty), for points within
    /// `reach` of the supports.
    pub(crate) fn new(points: &'a [[f64; 3]], radius: &[f64], group: &'a [u8], reach: f64) -> Self {
        assert_eq!(radius.len(), points.len(), "Covers: a radius per node");
        assert!(
            group.is_empty() || group.len() == points.len(),
            "Covers: a body per node"
        );
        // Minima and maxima: the same in any order, so on the pool.
        let smallest = radius
            .par_iter()
            .copied()
            .filter(|r| *r > 0.0)
            .reduce(|| f64::INFINITY, f64::min);
        // A radius that is not a number covers nothing (the caller's test
        // says so); an infinite one lands in the last class.
        let class = |r: f64| -> usize {
            if r > smallest {
                (((r / smallest).ln() / RATIO.ln()).floor() as usize).min(MAX_CLASSES - 1)
            } else {
                0
            }
        };
        let body = |j: usize| group.get(j).copied().unwrap_or(0);
        let key: Vec<u16> = (0..points.len())
            .into_par_iter()
            .map(|j| u16::from(body(j)) * MAX_CLASSES as u16 + class(radius[j]) as u16)
            .collect();
        let mut present = vec![false; 256 * MAX_CLASSES];
        for &k in &key {
            present[usize::from(k)] = true;
        }
        let mut bodies: Vec<Body> = Vec::new();
        for k in (0..present.len()).filter(|&k| present[k]) {
            let id = (k / MAX_CLASSES) as u8;
            // The class's nodes, ascending (an ordered collect).
            let members: Vec<usize> = (0..points.len())
                .into_par_iter()
                .filter(|&j| usize::from(key[j]) == k)
                .collect();
            let widest = members
                .par_iter()
                .map(|&j| radius[j])
                .reduce(|| 0.0, f64::max);
            let grid = Cells::members(points, &members, (reach + widest) * (1.0 + MARGIN))
                .expect("a present class has members");
            match bodies.last_mut() {
                Some(b) if b.id == id => b.classes.push(grid),
                _ => bodies.push(Body {
                    id,
                    classes: vec![grid],
                }),
            }
        }
        Covers { group, bodies }
    }

    /// The grids of the body of node `i`.
    fn of(&self, i: usize) -> &[Cells<'a, 3>] {
        let id = self.group.get(i).copied().unwrap_or(0);
        self.bodies
            .iter()
            .find(|b| b.id == id)
            .map_or(&[], |b| &b.classes)
    }

    /// Writes into `out` (cleared first), ascending, the nodes of node
    /// `i`'s body near `p` that pass `keep`: every node of the body
    /// within its radius plus the reach of `p` is offered to `keep`.
    pub(crate) fn sorted_into(
        &self,
        p: &[f64; 3],
        i: usize,
        mut keep: impl FnMut(usize) -> bool,
        out: &mut Vec<usize>,
    ) {
        out.clear();
        for grid in self.of(i) {
            grid.visit(p, |j| {
                if keep(j) {
                    out.push(j);
                }
            });
        }
        out.sort_unstable();
    }

    /// How many nodes [`Covers::sorted_into`] would list.
    pub(crate) fn count(
        &self,
        p: &[f64; 3],
        i: usize,
        mut keep: impl FnMut(usize) -> bool,
    ) -> usize {
        let mut n = 0;
        for grid in self.of(i) {
            grid.visit(p, |j| n += usize::from(keep(j)));
        }
        n
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against a search over every node: nodes of two bodies, radii
    /// spread over four classes and beyond the last, one radius not a
    /// number, with and without bodies.
    #[test]
    fn the_classes_find_what_a_search_over_every_node_finds() {
        let mut next = crate::test_rng::rng(7);
        let n = 1500;
        let points: Vec<[f64; 3]> = (0..n).map(|_| [next(), next(), 0.5 * next()]).collect();
        let mut radius: Vec<f64> = (0..n)
            .map(|_| 0.05 * (1.0 + 30.0 * next().powi(6)))
            .collect();
        radius[17] = f64::NAN;
        radius[18] = 0.0;
        let group: Vec<u8> = (0..n).map(|j| (j % 3 == 0) as u8 * 4).collect();
        for (group, reach) in [(&group[..], 0.0), (&[][..], 0.0), (&group[..], 0.03)] {
            let covers = Covers::new(&points, &radius, group, reach);
            let mut out = Vec::new();
            for i in 0..n {
                let p = points[i];
                let covering = |j: usize| {
                    let d = ((p[0] - points[j][0]).powi(2)
                        + (p[1] - points[j][1]).powi(2)
                        + (p[2] - points[j][2]).powi(2))
                    .sqrt();
                    d < radius[j] + reach
                };
                let want: Vec<usize> = (0..n)
                    .filter(|&j| group.is_empty() || group[j] == group[i])
                    .filter(|&j| covering(j))
                    .collect();
                covers.sorted_into(&p, i, covering, &mut out);
                assert_eq!(out, want, "node {i}");
                assert_eq!(covers.count(&p, i, covering), want.len());
            }
        }
    }
}
