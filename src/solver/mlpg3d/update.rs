//! The material pass of step 5 (module docs of [`super`]): from the
//! collocated velocity gradients, the rate of deformation and spin, the
//! density `ρ (1 − dt tr D)` and the shared [`Material::update`] in the
//! 3-D ([`Full`]) form, with each node's share of the step's energies and
//! its checks; then the sums over the nodes in node order.

use super::balance::Balance;
use super::balance::GRANULE;
use super::scratch::Tally;
use super::shielding::{self, Shielding};
use super::util::at_time;
use super::util::material_of;
use super::util::norm;
use crate::Error;
use crate::error::Result;
use crate::material::Point;
use crate::material::PointState;
use crate::material::tensor::Full;
use crate::material::tensor::SymTensor;
use crate::material::{Loading, Shield};
use crate::materials::Material;
use crate::solver::mlpg3d::Body;
use crate::solver::mlpg3d::kinetic1;
use rayon::iter::IndexedParallelIterator;
use rayon::iter::IntoParallelRefMutIterator;
use rayon::iter::ParallelIterator;
use rayon::slice::ParallelSliceMut;

/// What the material pass reads.
pub(super) struct MaterialInputs<'a> {
    /// The step (s).
    pub(super) dt: f64,
    /// The damping time `c` of the viscous stress (s).
    pub(super) damping_time: f64,
    /// The rod's material, the further bodies and each node's body.
    pub(super) rod: &'a Material,
    pub(super) others: &'a [Body],
    pub(super) group: &'a [u8],
    pub(super) mass: &'a [f64],
    pub(super) vel: &'a [[f64; 3]],
    /// The velocity gradient `L = ∂v/∂x` at each node.
    pub(super) grad: &'a [[[f64; 3]; 3]],
    /// The nodes' positions and the tensile cracks' shielding zones of the
    /// step's start, where a ceramic's cracks shield ([`Shielding`]).
    pub(super) shielding: Option<(&'a [[f64; 3]], &'a Shielding)>,
}

/// The node fields the material pass updates.
pub(super) struct MaterialFields<'a> {
    pub(super) dev: &'a mut [Full],
    pub(super) pressure: &'a mut [f64],
    pub(super) eps_p: &'a mut [f64],
    pub(super) temp: &'a mut [f64],
    pub(super) rho: &'a mut [f64],
    /// The viscous stress of the damping, from this step's rate.
    pub(super) visc: &'a mut [Full],
    pub(super) states: &'a mut [PointState],
}

/// Updates every node's material and writes its sums of the step (or the
/// first error met at it: the compression limit, a non-finite field) to
/// `results`. On several ranks every rank then holds every node's fields
/// where `whole` (else the caller sends them by the halo:
/// [`super::halo`]).
pub(super) fn update_material(
    (ranks, balance, whole): (&dyn crate::ranks::Ranks, &mut Balance, bool),
    input: &MaterialInputs,
    fields: MaterialFields,
    results: &mut [std::result::Result<Tally, (usize, Error)>],
) {
    if ranks.size() == 1 {
        update_rows(input, fields, results, 0);
        return;
    }
    // Each rank steps its share of the points (whole granules, balanced
    // by their cost: [`Balance`]), timing each granule; then every rank holds every point's fields ([`crate::ranks`]);
    // the damage variables stay with their rank until they are shared
    // (`MaterialState::after_pass`), the results too ([`sum_on`]).
    use crate::ranks::gather_parts;
    let parts = balance.parts(ranks, results.len()).to_vec();
    let own = parts[ranks.rank()].clone();
    let MaterialFields {
        dev,
        pressure,
        eps_p,
        temp,
        rho,
        visc,
        states,
    } = fields;
    let o = own.clone();
    update_granules(
        input,
        MaterialFields {
            dev: &mut dev[o.clone()],
            pressure: &mut pressure[o.clone()],
            eps_p: &mut eps_p[o.clone()],
            temp: &mut temp[o.clone()],
            rho: &mut rho[o.clone()],
            visc: &mut visc[o.clone()],
            states: &mut states[o.clone()],
        },
        &mut results[o],
        (own.start, balance.costs_of(&own)),
    );
    if whole {
        gather_parts(ranks, &parts, rho);
        gather_parts(ranks, &parts, dev);
        gather_parts(ranks, &parts, pressure);
        gather_parts(ranks, &parts, eps_p);
        gather_parts(ranks, &parts, temp);
        gather_parts(ranks, &parts, visc);
    }
}

/// The fields of a non-finite value, as [`encode`] numbers them.
const NON_FINITE_FIELDS: [&str; 4] = ["velocity", "density", "stress", "temperature"];

/// A point's result as it travels between ranks: `[0, the tally]`, or
/// `[1, point, compression, limit]` for [`Error::CompressionLimit`], or
/// `[2, point, field]` for [`Error::NonFinite`] (the only errors of the
/// pass).
fn encode(r: &std::result::Result<Tally, (usize, Error)>) -> [f64; 8] {
    match r {
        Ok(t) => [
            0.0,
            t.internal,
            t.plastic,
            t.damping,
            t.kinetic,
            t.momentum,
            t.mass,
            t.worst_speed,
        ],
        Err((
            i,
            Error::CompressionLimit {
                compression, limit, ..
            },
        )) => [1.0, *i as f64, *compression, *limit, 0.0, 0.0, 0.0, 0.0],
        Err((i, e)) => {
            let field = match e {
                Error::NonFinite { field, .. } => NON_FINITE_FIELDS
                    .iter()
                    .position(|f| f == field)
                    .unwrap_or(NON_FINITE_FIELDS.len()),
                _ => NON_FINITE_FIELDS.len(),
            };
            [2.0, *i as f64, field as f64, 0.0, 0.0, 0.0, 0.0, 0.0]
        }
    }
}

/// The result of [`encode`].
fn decode(w: &[f64; 8]) -> std::result::Result<Tally, (usize, Error)> {
    let i = w[1] as usize;
    match w[0] as u8 {
        0 => Ok(Tally {
            internal: w[1],
            plastic: w[2],
            damping: w[3],
            kinetic: w[4],
            momentum: w[5],
            mass: w[6],
            worst_speed: w[7],
        }),
        1 => Err((
            i,
            Error::CompressionLimit {
                particle: i,
                time: 0.0,
                compression: w[2],
                limit: w[3],
            },
        )),
        _ => Err((
            i,
            Error::NonFinite {
                field: NON_FINITE_FIELDS
                    .get(w[2] as usize)
                    .copied()
                    .unwrap_or("material state"),
                particle: i,
                time: 0.0,
            },
        )),
    }
}

/// The material pass over the points of `fields` and `results`, the first
/// of them point `start`.
fn update_rows(
    input: &MaterialInputs,
    fields: MaterialFields,
    results: &mut [std::result::Result<Tally, (usize, Error)>],
    start: usize,
) {
    fields
        .dev
        .par_iter_mut()
        .zip(fields.pressure.par_iter_mut())
        .zip(fields.eps_p.par_iter_mut())
        .zip(fields.temp.par_iter_mut())
        .zip(fields.rho.par_iter_mut())
        .zip(fields.visc.par_iter_mut())
        .zip(fields.states.par_iter_mut())
        .zip(results.par_iter_mut())
        .enumerate()
        .for_each(
            |(k, (((((((dev, p), eps), temp), rho), visc), state), out))| {
                let point = PointFields {
                    dev,
                    p,
                    eps,
                    temp,
                    rho,
                    visc,
                    state,
                };
                *out = update_point(input, start + k, point);
            },
        );
}

/// [`update_rows`] by granules of [`GRANULE`] points on the pool, each
/// granule's time added to its entry of `costs` (the balance's times of
/// these points' granules: [`Balance::costs_of`]). The same results.
fn update_granules(
    input: &MaterialInputs,
    fields: MaterialFields,
    results: &mut [std::result::Result<Tally, (usize, Error)>],
    (start, costs): (usize, &mut [f64]),
) {
    let g = GRANULE;
    fields
        .dev
        .par_chunks_mut(g)
        .zip(fields.pressure.par_chunks_mut(g))
        .zip(fields.eps_p.par_chunks_mut(g))
        .zip(fields.temp.par_chunks_mut(g))
        .zip(fields.rho.par_chunks_mut(g))
        .zip(fields.visc.par_chunks_mut(g))
        .zip(fields.states.par_chunks_mut(g))
        .zip(results.par_chunks_mut(g))
        .zip(costs.par_iter_mut())
        .enumerate()
        .for_each(
            |(c, ((((((((dev, p), eps), temp), rho), visc), states), out), cost))| {
                let watch = std::time::Instant::now();
                for k in 0..dev.len() {
                    let point = PointFields {
                        dev: &mut dev[k],
                        p: &mut p[k],
                        eps: &mut eps[k],
                        temp: &mut temp[k],
                        rho: &mut rho[k],
                        visc: &mut visc[k],
                        state: &mut states[k],
                    };
                    out[k] = update_point(input, start + c * g + k, point);
                }
                *cost += watch.elapsed().as_secs_f64();
            },
        );
}

/// One point's fields in the material pass.
struct PointFields<'a> {
    dev: &'a mut Full,
    p: &'a mut f64,
    eps: &'a mut f64,
    temp: &'a mut f64,
    rho: &'a mut f64,
    visc: &'a mut Full,
    state: &'a mut PointState,
}

/// The material pass at point `i`: its fields updated, and its sums of the
/// step or its error.
fn update_point(
    input: &MaterialInputs,
    i: usize,
    point: PointFields,
) -> std::result::Result<Tally, (usize, Error)> {
    let MaterialInputs {
        dt,
        damping_time: c,
        rod: rod_material,
        others,
        group,
        mass,
        vel,
        grad,
        shielding,
    } = *input;
    let PointFields {
        dev,
        p,
        eps,
        temp,
        rho,
        visc,
        state,
    } = point;
    let material = material_of(rod_material, others, group, i);
    let l = &grad[i];
    let d = |a: usize, b: usize| 0.5 * (l[a][b] + l[b][a]);
    let w = |a: usize, b: usize| 0.5 * (l[a][b] - l[b][a]);
    let rate: Full = [d(0, 0), d(1, 1), d(2, 2), d(0, 1), d(1, 2), d(2, 0)];
    let tr = rate[0] + rate[1] + rate[2];
    let rho_new = *rho * (1.0 - dt * tr);
    let before = Point {
        deviator: *dev,
        pressure: *p,
        plastic_strain: *eps,
        temperature: *temp,
    };
    material.seed_point(i as u64, Some(mass[i] / *rho), state);
    // The state before the step, kept only where cracks shield.
    let saved = shielding.map(|_| *state);
    let mut shield = Shield::NONE;
    // A plane that starts to grow inside another crack's
    // zone does not: the step again with it shielded.
    let new = loop {
        let load = Loading {
            dt,
            rate,
            spin: [w(0, 1), w(1, 2), w(2, 0)],
            density: rho_new,
            shield,
        };
        let new = material.update(&load, &before, state).map_err(|l| {
            (
                i,
                Error::CompressionLimit {
                    particle: i,
                    time: 0.0,
                    compression: l.compression,
                    limit: l.limit,
                },
            )
        })?;
        let (Some((pos, zones)), Some(saved)) = (shielding, saved) else {
            break new;
        };
        let held: Vec<[f64; 3]> = shielding::started(&saved, state)
            .into_iter()
            .filter(|n| zones.holds(i, &pos[i], n))
            .collect();
        if held.is_empty() || shield.len() + held.len() > 3 {
            break new;
        }
        for n in held {
            shield.add(n);
        }
        *state = saved;
    };
    let stress = |s: &Full, p: f64| -> Full { [s[0] - p, s[1] - p, s[2] - p, s[3], s[4], s[5]] };
    let mid: Full = {
        let (a, b) = (stress(dev, *p), stress(&new.deviator, new.pressure));
        std::array::from_fn(|k| 0.5 * (a[k] + b[k]))
    };
    let volume = mass[i] / rho_new;
    let bulk = material.eos.bulk_modulus(rho_new, new.pressure);
    let mu = material.shear_modulus;
    let v: Full = std::array::from_fn(|k| {
        let dev_rate = if k < 3 { rate[k] - tr / 3.0 } else { rate[k] };
        let vol = if k < 3 { bulk * tr } else { 0.0 };
        c * (vol + 2.0 * mu * dev_rate)
    });
    let t = Tally {
        internal: dt * volume * mid.double_dot(&rate),
        plastic: volume * new.deviator.von_mises() * (new.plastic_strain - *eps),
        damping: dt * volume * v.double_dot(&rate),
        kinetic: kinetic1(vel[i], mass[i]),
        momentum: mass[i] * vel[i][2],
        mass: mass[i],
        worst_speed: (material.wave_modulus(rho_new, new.pressure, state) / rho_new).sqrt()
            + norm(vel[i]),
    };
    *dev = new.deviator;
    *p = new.pressure;
    *eps = new.plastic_strain;
    *temp = new.temperature;
    *rho = rho_new;
    *visc = v;
    let finite = |x: &[f64]| x.iter().all(|v| v.is_finite());
    let bad = if !finite(&vel[i]) {
        Some("velocity")
    } else if !rho_new.is_finite() {
        Some("density")
    } else if !finite(dev) || !p.is_finite() {
        Some("stress")
    } else if !temp.is_finite() {
        Some("temperature")
    } else {
        None
    };
    if let Some(field) = bad {
        return Err((
            i,
            Error::NonFinite {
                field,
                particle: i,
                time: 0.0,
            },
        ));
    }
    Ok(t)
}

/// [`sum`] shared among `ranks`, each holding the results of its part
/// `parts[rank]` of [`update_material`] only: each sums the blocks of the
/// sums whose first point it holds ([`super::balance::blocks_of`]), the
/// results of a block's points on a later rank sent to it first, and the
/// blocks' sums (or their first error, [`encode`]) are joined on every
/// rank over the same tree (the same bits for any parts).
pub(super) fn sum_on(
    (ranks, parts): (&dyn crate::ranks::Ranks, &[std::ops::Range<usize>]),
    results: &mut [std::result::Result<Tally, (usize, Error)>],
    time: f64,
) -> Result<Tally> {
    if ranks.size() == 1 {
        return sum(results, time);
    }
    // A part's points before its first block's start (its head) lie in a
    // block that an earlier rank sums: their results go to every rank in
    // the wire form of `encode` (a few granules a rank at most).
    let head = |p: &std::ops::Range<usize>| {
        p.start
            ..p.end
                .min(p.start.next_multiple_of(crate::approx::sums::BLOCK))
    };
    if parts.iter().any(|p| !head(p).is_empty()) {
        let own = parts[ranks.rank()].clone();
        let mine: Vec<[f64; 8]> = results[head(&own)].iter().map(encode).collect();
        let heads = crate::ranks::all_gather_varying(ranks, &mine);
        let others = parts.iter().flat_map(head);
        for (i, w) in others.zip(&heads) {
            if !own.contains(&i) {
                results[i] = decode(w);
            }
        }
    }
    let results = &*results;
    type Point = std::result::Result<Tally, (usize, Error)>;
    let add = |t: Point, s: &Point| -> Point {
        let (t, s) = (t?, s.as_ref().map_err(|(i, e)| (*i, e.clone()))?);
        Ok(add_tally(t, s))
    };
    crate::approx::sums::ordered_on(
        ranks,
        results.len(),
        &super::balance::blocks_of(parts),
        (
            || Ok(Tally::default()),
            |t, i| add(t, &results[i]),
            |a, b| add(a, &b),
        ),
        (encode, decode),
    )
    .map_err(|(_, e)| at_time(e, time))
}

/// The sum of two tallies (the largest speed of the two).
fn add_tally(t: Tally, s: &Tally) -> Tally {
    Tally {
        internal: t.internal + s.internal,
        plastic: t.plastic + s.plastic,
        damping: t.damping + s.damping,
        kinetic: t.kinetic + s.kinetic,
        momentum: t.momentum + s.momentum,
        mass: t.mass + s.mass,
        worst_speed: t.worst_speed.max(s.worst_speed),
    }
}

/// The sums of the step over the nodes, on the pool in the fixed order of
/// [`crate::approx::sums`] (the same bits for any number of threads), or the
/// first node's error at `time`.
pub(super) fn sum(
    results: &[std::result::Result<Tally, (usize, Error)>],
    time: f64,
) -> Result<Tally> {
    let add = add_tally;
    crate::approx::sums::ordered(
        results.len(),
        || Ok(Tally::default()),
        |t, i| {
            let s = results[i]
                .as_ref()
                .map_err(|(_, e)| at_time(e.clone(), time))?;
            Ok(add(t?, s))
        },
        |a: Result<Tally>, b| Ok(add(a?, &b?)),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::approx::sums::BLOCK;
    use std::ops::Range;

    /// Shared among thread-ranks by parts cut inside the sums' blocks
    /// (granules, as the balance cuts them), each rank holding only its own
    /// part's results (the rest garbage), the sums have the bits of the
    /// one-rank sum, and the first error in point order still wins where
    /// it lies in a part's head (summed by the rank before).
    #[test]
    fn the_sums_by_parts_cut_inside_a_block_are_the_plain_ones() {
        let mut rng = crate::test_rng::rng(11);
        let n = 3 * BLOCK + 200;
        let plain: Vec<std::result::Result<Tally, (usize, Error)>> = (0..n)
            .map(|_| {
                Ok(Tally {
                    internal: rng() - 0.3,
                    plastic: rng(),
                    damping: rng() * 1e-3,
                    kinetic: rng(),
                    momentum: rng() - 0.5,
                    mass: rng(),
                    worst_speed: rng() * 5e3,
                })
            })
            .collect();
        let g = GRANULE;
        let cuts: [Vec<Range<usize>>; 3] = [
            vec![0..3 * g, 3 * g..n],
            vec![0..5 * g, 5 * g..6 * g, 6 * g..n],
            vec![
                0..g,
                g..BLOCK + 3 * g,
                BLOCK + 3 * g..2 * BLOCK + g,
                2 * BLOCK + g..n,
            ],
        ];
        let bits = |t: &Tally| {
            [
                t.internal,
                t.plastic,
                t.damping,
                t.kinetic,
                t.momentum,
                t.mass,
                t.worst_speed,
            ]
            .map(f64::to_bits)
        };
        for with_error in [false, true] {
            let mut plain = plain.clone();
            if with_error {
                // In the second part's head: point 5g lies in block 0.
                let (i, j) = (5 * g + 7, 2 * BLOCK + 5);
                for k in [i, j] {
                    plain[k] = Err((
                        k,
                        Error::NonFinite {
                            field: "stress",
                            particle: k,
                            time: 0.0,
                        },
                    ));
                }
            }
            let want = sum(&plain, 1.0);
            for parts in &cuts {
                let got = crate::ranks::tests::on_threads(parts.len(), |ranks| {
                    let own = parts[ranks.rank()].clone();
                    let mut mine: Vec<_> = (0..n)
                        .map(|i| {
                            if own.contains(&i) {
                                plain[i].clone()
                            } else {
                                Ok(Tally::default())
                            }
                        })
                        .collect();
                    sum_on((ranks, parts), &mut mine, 1.0)
                });
                for (rank, got) in got.iter().enumerate() {
                    match (&want, got) {
                        (Ok(w), Ok(t)) => {
                            assert_eq!(bits(w), bits(t), "{parts:?}, rank {rank}")
                        }
                        (Err(w), Err(e)) => {
                            assert_eq!(w.to_string(), e.to_string(), "{parts:?}, rank {rank}")
                        }
                        _ => panic!("{parts:?}, rank {rank}: {want:?} against {got:?}"),
                    }
                }
            }
            assert_eq!(want.is_err(), with_error);
        }
    }
}
