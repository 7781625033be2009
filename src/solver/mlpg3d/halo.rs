//! The material fields' halo among the ranks: after the material pass each
//! rank sends the other ranks only the rows of its part that they read,
//! not its whole part.
//!
//! The material pass writes, at the points of each rank's part
//! ([`super::balance::Balance`]), the deviator, the viscous stress, the
//! pressure, the plastic strain, the temperature and the density. Until
//! the next pass they are read:
//!
//! - by the rank's own next material pass, at its own points;
//! - by the nodal forces (the stresses, and the density in the nodal
//!   volumes `m / ρ`), at the nodes `i` of the columns this rank holds
//!   (`NodalOperator::nodes`);
//! - by the shifting's carry, at the nodes of the shapes' rows of this
//!   rank's part (`Geometry::rows`), the images' by their nodes;
//! - the density by the wave speed of a body without a reference density,
//!   at node 0 (`mlpg3d::wave_speed`), and by a build of the geometry at
//!   every node (the step makes the density whole before one:
//!   `step::follow`; the build changes what each rank reads, but nothing
//!   reads the other fields between it and the next exchange, which sends
//!   by the new lists).
//!
//! Each rank lists the nodes it reads outside its own part; the lists are
//! gathered once for each build of the geometry and split of the points,
//! and their union, split by the parts, is what each rank sends
//! ([`crate::ranks::gather_listed`]). Every value a rank reads is then the
//! value of the whole gather, so the bits are those of the whole gather
//! (`tests/mpi.rs` compares 1-4 ranks). The other rows stay stale on a
//! rank until [`Halo::make_whole`], which the solver's `share` calls before
//! anything reads them all (the outputs, a checkpoint, the end), and which
//! the step does itself where the points' split is about to move.

use super::geometry::Geometry;
use crate::material::tensor::Full;
use crate::ranks::Ranks;
use std::ops::Range;

/// The numbers of one node's record: the deviator, the viscous stress, the
/// pressure, the plastic strain, the temperature and the density.
const RECORD: usize = 16;

/// The material fields the halo carries.
pub(super) struct HaloFields<'a> {
    pub(super) dev: &'a mut [Full],
    pub(super) visc: &'a mut [Full],
    pub(super) pressure: &'a mut [f64],
    pub(super) eps_p: &'a mut [f64],
    pub(super) temp: &'a mut [f64],
    pub(super) rho: &'a mut [f64],
}

impl<'a> HaloFields<'a> {
    /// The halo's fields of `state`.
    pub(super) fn of(state: &'a mut super::State3d) -> Self {
        HaloFields {
            dev: &mut state.dev,
            visc: &mut state.visc,
            pressure: &mut state.pressure,
            eps_p: &mut state.eps_p,
            temp: &mut state.temp,
            rho: &mut state.rho,
        }
    }
}

/// What each rank sends after the material pass, and whether the fields
/// are apart. Rebuilt, never saved.
#[derive(Debug, Clone, Default)]
pub(super) struct Halo {
    /// Whether `send` was made for the current geometry (cleared at each
    /// build and when the ranks are set).
    current: bool,
    /// The points' parts that `send` was made for.
    parts: Vec<Range<usize>>,
    /// Each rank's points that another rank reads, ascending.
    send: Vec<Vec<usize>>,
    /// The records as they travel, kept from step to step.
    wire: Vec<[f64; RECORD]>,
    /// The fields are whole only at the nodes each rank reads, since the
    /// last exchange.
    apart: bool,
    /// A test's checks: the lists widened by one support, and the rows a
    /// rank neither owns nor receives poisoned (NaN) at each exchange.
    wider: bool,
    poison: bool,
}

impl Halo {
    /// The lists are made again before the next exchange (a build of the
    /// geometry, or new ranks).
    pub(super) fn forget(&mut self) {
        self.current = false;
    }

    /// A test's checks (the fields on `Halo`).
    #[cfg(test)]
    pub(super) fn check(&mut self, wider: bool, poison: bool) {
        (self.wider, self.poison) = (wider, poison);
        self.current = false;
    }

    /// Whether the rows a rank neither owns nor receives are poisoned (a
    /// test's check: the shapes' rows then go by their lists however many
    /// they are, [`super::held`]).
    pub(super) fn poisons(&self) -> bool {
        self.poison
    }

    /// Whether the lists are widened by one support (a test's check).
    pub(super) fn wider(&self) -> bool {
        self.wider
    }

    /// The fields are whole again on every rank (a restored state).
    pub(super) fn whole(&mut self) {
        self.apart = false;
    }

    /// The nodes each rank sends, made again where the geometry or the
    /// parts changed (a collective call: one gather of the lists).
    fn lists(
        &mut self,
        ranks: &dyn Ranks,
        g: &Geometry,
        parts: &[Range<usize>],
        shifting: bool,
    ) -> &[Vec<usize>] {
        if !self.current || self.parts != parts {
            let n = parts.last().map_or(0, |p| p.end);
            let me = ranks.rank();
            let mine = reads_outside(g, (me, parts[me].clone()), n, (shifting, self.wider));
            let all = crate::ranks::all_gather_varying(ranks, &mine);
            let mut read = vec![false; n];
            for &i in &all {
                read[i] = true;
            }
            self.send = parts
                .iter()
                .map(|p| p.clone().filter(|&i| read[i]).collect())
                .collect();
            self.parts = parts.to_vec();
            self.current = true;
        }
        &self.send
    }

    /// After the material pass over each rank's `parts`: every rank sends
    /// the other ranks the rows of its part they read (the geometry `g`'s
    /// forces, and its carry where `shifting`). Nothing on one rank.
    pub(super) fn exchange(
        &mut self,
        ranks: &dyn Ranks,
        (g, shifting): (&Geometry, bool),
        parts: &[Range<usize>],
        f: HaloFields,
    ) {
        if ranks.size() == 1 {
            return;
        }
        let mut wire = std::mem::take(&mut self.wire);
        let mut f = f;
        let lists = self.lists(ranks, g, parts, shifting);
        crate::ranks::gather_listed(ranks, lists, &mut wire, &mut f, (pack, unpack));
        if self.poison {
            let mut whole = vec![false; f.dev.len()];
            for i in self
                .send
                .iter()
                .flatten()
                .copied()
                .chain(parts[ranks.rank()].clone())
            {
                whole[i] = true;
            }
            for i in (0..whole.len()).filter(|&i| !whole[i]) {
                unpack(&mut f, i, &[f64::NAN; RECORD]);
            }
        }
        self.wire = wire;
        self.apart = true;
    }

    /// Every node's fields whole on every rank, where they are apart: each
    /// rank's part gathered (the points' `parts` of the last pass, whose
    /// rank holds each point's current value). A collective call.
    pub(super) fn make_whole(&mut self, ranks: &dyn Ranks, parts: &[Range<usize>], f: HaloFields) {
        if !self.apart {
            return;
        }
        use crate::ranks::gather_parts;
        gather_parts(ranks, parts, f.dev);
        gather_parts(ranks, parts, f.visc);
        gather_parts(ranks, parts, f.pressure);
        gather_parts(ranks, parts, f.eps_p);
        gather_parts(ranks, parts, f.temp);
        gather_parts(ranks, parts, f.rho);
        self.apart = false;
    }

    /// Some of the fields, `fields`, whole on every rank where the fields
    /// are apart (the rest stay apart): what a reader of those alone needs
    /// (a build of the geometry reads the density, `step::follow`; the
    /// observables the plastic strain and the temperature,
    /// [`super::Mlpg3d::share_observed`]). A collective call.
    pub(super) fn make_some_whole(
        &self,
        ranks: &dyn Ranks,
        parts: &[Range<usize>],
        fields: &mut [&mut [f64]],
    ) {
        if self.apart {
            for f in fields {
                crate::ranks::gather_parts(ranks, parts, f);
            }
        }
    }
}

/// Node `i`'s record.
fn pack(f: &HaloFields, i: usize) -> [f64; RECORD] {
    let mut r = [0.0; RECORD];
    r[..6].copy_from_slice(&f.dev[i]);
    r[6..12].copy_from_slice(&f.visc[i]);
    (r[12], r[13], r[14], r[15]) = (f.pressure[i], f.eps_p[i], f.temp[i], f.rho[i]);
    r
}

/// Node `i`'s fields from its record.
fn unpack(f: &mut HaloFields, i: usize, r: &[f64; RECORD]) {
    f.dev[i] = std::array::from_fn(|k| r[k]);
    f.visc[i] = std::array::from_fn(|k| r[6 + k]);
    (f.pressure[i], f.eps_p[i], f.temp[i], f.rho[i]) = (r[12], r[13], r[14], r[15]);
}

/// The nodes outside `own` (of `n`) that this rank reads: node 0 (the
/// density of the wave speed's fallback), the nodes of the nodal
/// operator's columns it holds, and where `shifting` the nodes of the
/// shapes' rows of its part `g.rows[rank]` (an image by its node),
/// ascending; where `wider`, with the nodes of their shapes' rows too (one
/// support more: a test's check).
fn reads_outside(
    g: &Geometry,
    (rank, own): (usize, Range<usize>),
    n: usize,
    (shifting, wider): (bool, bool),
) -> Vec<usize> {
    let mut read = vec![false; n];
    if n > 0 {
        read[0] = true;
    }
    g.mark_column_reads(&mut read);
    if shifting {
        for i in g.rows[rank].clone() {
            read[i] = true;
            for q in g.shapes.row(i) {
                let j = g.shapes.nodes[q];
                read[if j < n { j } else { g.mirror.source[j - n] }] = true;
            }
        }
    }
    if wider {
        let first: Vec<usize> = (0..n).filter(|&i| read[i]).collect();
        for i in first {
            for q in g.shapes.row(i) {
                let j = g.shapes.nodes[q];
                read[if j < n { j } else { g.mirror.source[j - n] }] = true;
            }
        }
    }
    (0..n).filter(|&i| read[i] && !own.contains(&i)).collect()
}

#[cfg(test)]
mod tests {
    use super::super::tests::plastic_steel;
    use super::super::{Mlpg3d, RodSetup};
    use crate::approx::lattice::Cylinder;
    use crate::solver::mlpg3d::scheme::{Forces, SmoothingOrder};

    /// The bits of a run's node fields after `steps` steps of a quarter
    /// rod (nodal forces, order-2 smoothing, shifting), on `ranks` or
    /// alone, with the halo's checks `(wider, poison)`.
    fn run(ranks: Option<crate::ranks::Handle>, check: (bool, bool), steps: usize) -> Vec<u64> {
        let mut sim = quarter_rod(ranks, check);
        for _ in 0..steps {
            sim.step().unwrap();
        }
        sim.share();
        let s = &sim.state;
        let mut bits = Vec::new();
        let mut put = |v: f64| bits.push(v.to_bits());
        s.pos.iter().chain(&s.vel).flatten().for_each(|&v| put(v));
        s.dev.iter().chain(&s.visc).flatten().for_each(|&v| put(v));
        s.pressure
            .iter()
            .chain(&s.eps_p)
            .chain(&s.temp)
            .chain(&s.rho)
            .chain(&s.built_rho)
            .for_each(|&v| put(v));
        bits
    }

    /// The quarter rod of [`run`], on `ranks` or alone, with the halo's
    /// checks `(wider, poison)`.
    fn quarter_rod(ranks: Option<crate::ranks::Handle>, check: (bool, bool)) -> Mlpg3d {
        quarter_rod_of(ranks, check, plastic_steel(), 400.0)
    }

    /// The quarter rod of [`run`] of `material` at `speed` (m/s).
    fn quarter_rod_of(
        ranks: Option<crate::ranks::Handle>,
        check: (bool, bool),
        material: crate::material::Material,
        speed: f64,
    ) -> Mlpg3d {
        let cylinder = Cylinder {
            radius: 2e-3,
            length: 60e-3,
        };
        let mut setup = RodSetup::new(cylinder, 4, speed, 1.0);
        setup.quarter = true;
        setup.scheme.forces = Forces::Nodal;
        setup.scheme.order = SmoothingOrder::Two;
        setup.scheme.shifting = 0.1;
        let mut sim = Mlpg3d::new(setup, material).unwrap();
        if let Some(r) = ranks {
            sim.set_ranks(r);
        }
        sim.pipe.halo.check(check.0, check.1);
        sim
    }

    /// On 2 and 3 ranks (threads) the halo gives the bits of one rank,
    /// with every row a rank neither owns nor receives poisoned (NaN) at
    /// each exchange, so that a read of one would show; and a halo one
    /// support wider gives the same bits. 120 steps of a quarter rod 60 mm
    /// long at 400 m/s (2299 nodes, so that each of 2 and 3 ranks owns
    /// blocks of the material pass's 1024 points; plastic flow, up to 31
    /// nodes shifted a step, rebuilds of the geometry, and the points'
    /// split moved every 10 steps). In this run every shifted node's row
    /// is read by the forces too: the carry's own reads are kept, but no
    /// test here shows them needed.
    #[test]
    fn the_halo_gives_the_bits_of_one_rank_with_the_rest_poisoned() {
        let steps = 120;
        let alone = run(None, (false, false), steps);
        for size in [2, 3] {
            for check in [(false, true), (true, true)] {
                let got =
                    crate::ranks::tests::on_thread_handles(size, |h| run(Some(h), check, steps));
                for (rank, bits) in got.iter().enumerate() {
                    assert!(
                        *bits == alone,
                        "{size} ranks, rank {rank}, checks {check:?}"
                    );
                }
            }
        }
    }
    /// The shapes' rows each rank holds ([`super::super::held`]: only the
    /// rows its passes read, the rest marked unread) give the bits of one
    /// rank with the conservative carry too, which reads every shifted
    /// node's row: the quarter rod of [`run`] with the carry, 120 steps on
    /// 2 and 3 ranks, its rows apart on every rank from its first build on
    /// the ranks.
    #[test]
    fn the_rows_apart_give_the_bits_of_one_rank_with_the_conservative_carry() {
        let run = |ranks: Option<crate::ranks::Handle>| {
            let several = ranks.is_some();
            let mut sim = quarter_rod(ranks, (false, true));
            sim.setup.rod.conservative_carry = true;
            let mut apart = 0;
            for _ in 0..120 {
                sim.step().unwrap();
                apart += usize::from(sim.pipe.geometry.as_ref().unwrap().held.apart());
            }
            // Apart from the first build on the ranks on (the geometry
            // built before the ranks were set holds every row).
            let builds = sim.state.rebuilds;
            assert!(builds >= 3, "{builds} builds");
            assert!(
                if several { apart >= 60 } else { apart == 0 },
                "{apart} steps apart"
            );
            sim.share();
            let s = &sim.state;
            s.pos
                .iter()
                .chain(&s.vel)
                .flatten()
                .chain(&s.pressure)
                .map(|v| v.to_bits())
                .collect::<Vec<u64>>()
        };
        let alone = run(None);
        for size in [2, 3] {
            let got = crate::ranks::tests::on_thread_handles(size, |h| run(Some(h)));
            for (rank, bits) in got.iter().enumerate() {
                assert!(*bits == alone, "{size} ranks, rank {rank}");
            }
        }
    }

    /// A record's share ([`Mlpg3d::share_observed`]: the plastic strain
    /// and the temperature of the material fields, the rest left apart and
    /// poisoned) gives every rank the observables of one rank: the same
    /// quarter rod on 2 and 3 ranks, its 16 observables read on every rank
    /// at 12 of its 120 steps. (Without the share, rank 1 reads neither the
    /// impact face's plastic strain nor its heat.)
    #[test]
    fn a_records_share_gives_every_rank_the_observables_of_one() {
        let observed = |ranks: Option<crate::ranks::Handle>| {
            let mut sim = quarter_rod(ranks, (false, true));
            let mut bits = Vec::new();
            for step in 1..=120 {
                sim.step().unwrap();
                // Off the steps where the points' split moves (every
                // 10th), which gather the fields whole.
                if step % 10 == 5 {
                    sim.share_observed();
                    bits.extend(sim.observables().iter().map(|v| v.to_bits()));
                }
            }
            bits
        };
        let alone = observed(None);
        for size in [2, 3] {
            let got = crate::ranks::tests::on_thread_handles(size, |h| observed(Some(h)));
            for (rank, bits) in got.iter().enumerate() {
                assert!(*bits == alone, "{size} ranks, rank {rank}");
            }
        }
    }

    /// Where the material pass's split of the points among the ranks moves,
    /// the damage variables of the points that change rank go with them
    /// (`MaterialState::hand_over`; the others stay apart): a quarter AD85
    /// rod at 600 m/s, 150 steps on 2 and 3 ranks, gives the bits of one
    /// rank in its node fields and in every point's damage variables, the
    /// split moved (a block of each rank booked dear in turn, and the
    /// moves counted) while the impact face cracks. Without
    /// the hand-over, rank 1's new points step from stale variables and
    /// the bits differ.
    #[test]
    fn the_damage_variables_follow_their_points_to_a_new_rank() {
        use crate::material::rajendran_grove::RajendranGrove;
        let steps = 150;
        let ceramic =
            || crate::material::Material::ceramic(RajendranGrove::ad85(), 880.0, 1.0, 293.0);
        let run = |ranks: Option<crate::ranks::Handle>| {
            let mut sim = quarter_rod_of(ranks, (false, false), ceramic(), 600.0);
            let n = sim.state.pos.len();
            let mut splits = Vec::new();
            for step in 0..steps {
                sim.step().unwrap();
                // The first block made dear, then the last, in turn, by
                // the rank that holds it: the split moves every 10 steps
                // whatever the clock measures.
                let rank = sim.pipe.ranks.rank();
                let own = sim.pipe.balance.parts(&*sim.pipe.ranks, n)[rank].clone();
                let dear = if (step / 10) % 2 == 0 { 0 } else { n - 1 };
                if own.contains(&dear) {
                    let align = super::super::balance::GRANULE;
                    sim.pipe.balance.book(dear / align, 1.0);
                }
                let parts = sim.pipe.balance.parts(&*sim.pipe.ranks, n).to_vec();
                if splits.last() != Some(&parts) {
                    splits.push(parts);
                }
            }
            sim.share();
            let s = &sim.state;
            let mut bits: Vec<u64> = s.vel.iter().flatten().map(|v| v.to_bits()).collect();
            bits.extend(s.dev.iter().flatten().map(|v| v.to_bits()));
            bits.extend(s.pressure.iter().chain(&s.rho).map(|v| v.to_bits()));
            let damage = postcard::to_allocvec(&s.material_state).expect("the state encodes");
            (bits, damage, splits.len())
        };
        let (bits, damage, _) = run(None);
        assert!(damage.len() > 1000, "the rod has damage variables");
        for size in [2, 3] {
            let got = crate::ranks::tests::on_thread_handles(size, |h| run(Some(h)));
            for (rank, (b, d, splits)) in got.iter().enumerate() {
                assert!(*splits > 1, "{size} ranks: the split moved");
                assert!(*b == bits, "{size} ranks, rank {rank}: the node fields");
                assert!(
                    *d == damage,
                    "{size} ranks, rank {rank}: the damage variables"
                );
            }
        }
    }
}
