//! The per-particle state of a material's models: a point's caches and
//! damage variables ([`PointState`]), and the state of every particle of a
//! run with its saved form ([`MaterialState`]).

use super::johnson_holmquist::Jh2Point;
use super::rajendran_grove::CeramicVars;

/// Per-particle state of the models, kept from step to step.
#[derive(Debug, Clone, Copy)]
pub struct PointState {
    /// Johnson-Cook hardening and thermal factors with the plastic strain
    /// and temperature they were computed for: reused while both stay the
    /// same (a particle that does not yield), which spares two `powf` and
    /// gives the same bits.
    pub(super) memo: Memo,
    /// The damage model's variables: none for a material without damage,
    /// and for a damaging point before its first step (it then starts from
    /// the intact state: [`RajendranGrove::initial_point`](super::rajendran_grove::RajendranGrove::initial_point),
    /// [`Jh2::initial_point`](super::johnson_holmquist::Jh2::initial_point)).
    /// One slot for either model, so that the state of a point costs no
    /// more for a second model.
    pub(super) vars: Vars,
}

/// The variables of a point's damage model ([`PointState`]).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(super) enum Vars {
    /// No damage model, or no step yet.
    #[default]
    None,
    /// A Rajendran-Grove ceramic point.
    Ceramic(CeramicVars),
    /// A JH-2 point.
    Jh2(Jh2Point),
}

/// The Johnson-Cook factors of a point ([`PointState`]'s memo).
#[derive(Debug, Clone, Copy)]
pub(super) struct Memo {
    pub(super) eps_p: f64,
    pub(super) temp: f64,
    pub(super) hardening: f64,
    pub(super) thermal: f64,
}

impl Default for PointState {
    /// Matches no state (NaN equals nothing).
    fn default() -> Self {
        PointState {
            memo: Memo {
                eps_p: f64::NAN,
                temp: f64::NAN,
                hardening: 0.0,
                thermal: 0.0,
            },
            vars: Vars::None,
        }
    }
}

impl PointState {
    /// The state of a ceramic point with variables `vars` (empty caches).
    pub(crate) fn with_ceramic(vars: CeramicVars) -> Self {
        PointState {
            vars: Vars::Ceramic(vars),
            ..PointState::default()
        }
    }

    /// The ceramic variables of the point, if its material has them and it
    /// has taken a step.
    pub fn ceramic(&self) -> Option<&CeramicVars> {
        match &self.vars {
            Vars::Ceramic(v) => Some(v),
            _ => None,
        }
    }

    /// The JH-2 state of the point, if its material is JH-2 and it has
    /// taken a step.
    pub fn jh2(&self) -> Option<&Jh2Point> {
        match &self.vars {
            Vars::Jh2(j) => Some(j),
            _ => None,
        }
    }

    /// Whether the point is a pulverized ceramic (its material has the
    /// Rajendran-Grove model and the point has reached pulverization).
    pub fn is_pulverized(&self) -> bool {
        self.ceramic().is_some_and(|v| v.pulverized.is_some())
    }

    /// The volumetric strain that the point's open tensile cracks take (the
    /// sum of their openings; 0 without them): its matrix density is its
    /// density times `1 + opened`.
    pub fn opened(&self) -> f64 {
        self.ceramic()
            .and_then(|v| v.tensile)
            .map_or(0.0, |t| t.opening.iter().sum())
    }

    /// Whether the point is comminuted: a pulverized Rajendran-Grove
    /// ceramic, or a JH-2 point fully damaged (D = 1: fractured, its
    /// strength the fractured one's).
    pub fn is_comminuted(&self) -> bool {
        self.is_pulverized() || self.jh2().is_some_and(|j| j.damage >= 1.0)
    }

    /// Whether the point is a ceramic whose tensile cracks stand open (any
    /// opening above zero): its matrix density is not its density.
    pub fn has_open_cracks(&self) -> bool {
        self.ceramic()
            .and_then(|v| v.tensile)
            .is_some_and(|t| t.opening.iter().any(|&e| e > 0.0))
    }
}

/// Per-particle state of a material's models, owned next to the material:
/// caches (the Johnson-Cook memo) and, for a material with damage, the
/// damage variables, which are physical state.
///
/// **Saved form.** A solver saves this state with its run: serde writes
/// only the damage variables, as `Option<Vec<Option<CeramicVars>>>`, one
/// entry per particle (`None` for a point that has none yet), and writes
/// `None` when no point has any (a run without damage: one byte in
/// postcard, `null` in JSON). The caches are not saved; they come back
/// empty and are rebuilt at the next step with the same bits. A restored
/// state must be checked against the run's particle count
/// ([`MaterialState::check_len`]).
///
/// **On several ranks** the material pass leaves each rank's damage
/// variables current on its own part of the particles only, and every
/// rank's [`Marks`] current on every particle
/// ([`MaterialState::after_pass`]); [`MaterialState::share`] makes every
/// rank's variables whole again before anything reads them all.
#[derive(Debug, Clone, Default)]
pub struct MaterialState {
    pub(super) points: Vec<PointState>,
    /// What the solver's passes read of every particle's variables, kept
    /// current on every rank ([`Marks`]).
    pub(super) marks: Vec<Marks>,
    /// The parts of the ranks that stepped the particles, while each
    /// rank holds current variables on its own part only; `None` when
    /// every rank holds every particle's.
    pub(super) apart: Option<Vec<std::ops::Range<usize>>>,
}

/// A particle's damage variables as they travel between the ranks.
#[derive(serde::Serialize, serde::Deserialize)]
enum Wire {
    None,
    Ceramic(CeramicVars),
    Jh2(Jh2Point),
}

impl Wire {
    /// The variables of `p`.
    fn of(p: &PointState) -> Wire {
        match p.vars {
            Vars::None => Wire::None,
            Vars::Ceramic(c) => Wire::Ceramic(c),
            Vars::Jh2(j) => Wire::Jh2(j),
        }
    }

    /// `p` takes the variables `w`.
    fn put(p: &mut PointState, w: Wire) {
        p.vars = match w {
            Wire::None => Vars::None,
            Wire::Ceramic(c) => Vars::Ceramic(c),
            Wire::Jh2(j) => Vars::Jh2(j),
        }
    }
}

/// What the solver's passes read of a particle's damage variables besides
/// its own (a neighbour's openings, whether it is pulverized): a few
/// numbers that travel between ranks every step, where the variables
/// themselves travel only when something reads them all
/// ([`MaterialState::share`]).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
#[repr(C)]
pub struct Marks {
    /// [`PointState::opened`].
    opened: f64,
    /// The flags [`Marks::PULVERIZED`], [`Marks::OPEN`], [`Marks::JH2`] and
    /// [`Marks::COMMINUTED`] (an integer below 16, held as a float so that
    /// the marks travel as plain numbers).
    flags: f64,
}

impl Marks {
    const PULVERIZED: u8 = 1;
    const OPEN: u8 = 2;
    const JH2: u8 = 4;
    const COMMINUTED: u8 = 8;

    /// The marks of `point`.
    pub fn of(point: &PointState) -> Self {
        let flag = |on: bool, bit: u8| if on { bit } else { 0 };
        let flags = flag(point.is_pulverized(), Self::PULVERIZED)
            | flag(point.has_open_cracks(), Self::OPEN)
            | flag(point.jh2().is_some(), Self::JH2)
            | flag(point.is_comminuted(), Self::COMMINUTED);
        Marks {
            opened: point.opened(),
            flags: f64::from(flags),
        }
    }

    fn has(&self, bit: u8) -> bool {
        (self.flags as u8) & bit != 0
    }

    /// [`PointState::is_pulverized`].
    pub fn is_pulverized(&self) -> bool {
        self.has(Self::PULVERIZED)
    }

    /// [`PointState::has_open_cracks`].
    pub fn has_open_cracks(&self) -> bool {
        self.has(Self::OPEN)
    }

    /// Whether the point holds JH-2 variables ([`PointState::jh2`]).
    pub fn is_jh2(&self) -> bool {
        self.has(Self::JH2)
    }

    /// [`PointState::is_comminuted`].
    pub fn is_comminuted(&self) -> bool {
        self.has(Self::COMMINUTED)
    }

    /// [`PointState::opened`].
    pub fn opened(&self) -> f64 {
        self.opened
    }
}

impl MaterialState {
    /// Sizes the state for `n` particles (new ones start empty).
    pub fn fit(&mut self, n: usize) {
        crate::approx::buffers::fit(&mut self.points, n, PointState::default());
        // A restored state brings no marks: they are those of its points.
        if self.marks.len() != self.points.len() {
            self.marks.clear();
            self.marks.extend(self.points.iter().map(Marks::of));
        }
    }

    /// The particles' states, to be cut into chunks.
    pub fn points_mut(&mut self) -> &mut [PointState] {
        &mut self.points
    }

    /// Every particle's [`Marks`] (current on every rank).
    pub fn marks(&self) -> &[Marks] {
        &self.marks
    }

    /// After each rank of `ranks` has stepped the points of its part
    /// `parts[rank]` (the whole run on one rank): the marks of its points,
    /// then every rank's marks on every rank. The damage variables stay
    /// apart, each rank's current on its own part, until
    /// [`MaterialState::share`], unless `share_now`; on one rank there is
    /// nothing to share.
    pub fn after_pass(
        &mut self,
        ranks: &dyn crate::ranks::Ranks,
        parts: &[std::ops::Range<usize>],
        share_now: bool,
        wire: &mut Vec<u8>,
    ) {
        use rayon::prelude::*;
        let own = parts[ranks.rank()].clone();
        self.marks.resize(self.points.len(), Marks::default());
        self.marks[own.clone()]
            .par_iter_mut()
            .zip(&self.points[own])
            .for_each(|(m, p)| *m = Marks::of(p));
        if ranks.size() == 1 {
            return;
        }
        crate::ranks::gather_parts(ranks, parts, &mut self.marks);
        self.apart = Some(parts.to_vec());
        if share_now {
            self.share(ranks, wire);
        }
    }

    /// Every rank's damage variables on every rank, where they are apart
    /// ([`MaterialState::after_pass`]): a collective call, which every rank
    /// makes at the same point of a run. The variables travel in records
    /// of one width through `wire` (the caller's, kept from one call to
    /// the next: [`crate::ranks::gather_records`]). The caches stay each
    /// rank's own: they give the same bits whether kept or rebuilt.
    pub fn share(&mut self, ranks: &dyn crate::ranks::Ranks, wire: &mut Vec<u8>) {
        let Some(parts) = self.apart.take() else {
            return;
        };
        crate::ranks::gather_records(ranks, &parts, &mut self.points, wire, Wire::of, Wire::put);
    }

    /// The split of the points among the ranks moves from the parts of the
    /// last pass to `new` (a collective call, at the same point of a run
    /// on every rank): where the variables are apart, each point whose rank
    /// changes travels from its last rank to the others
    /// ([`crate::ranks::gather_records_listed`]), so that each rank holds
    /// current variables on its part of `new`; the others stay apart.
    /// (Every point shared at each new split: `penetration`, 8 across,
    /// quarter, to 20 µs, on 2 ranks, 3.0 s a rank in the marks, the
    /// shares and the sums, against 1.1 s with the hand-over.)
    pub fn hand_over(
        &mut self,
        ranks: &dyn crate::ranks::Ranks,
        new: &[std::ops::Range<usize>],
        wire: &mut Vec<u8>,
    ) {
        let Some(old) = self.apart.take() else {
            return;
        };
        let lists: Vec<Vec<usize>> = old
            .iter()
            .zip(new)
            .map(|(o, n)| o.clone().filter(|i| !n.contains(i)).collect())
            .collect();
        crate::ranks::gather_records_listed(
            ranks,
            &lists,
            &mut self.points,
            wire,
            Wire::of,
            Wire::put,
        );
        self.apart = Some(new.to_vec());
    }

    /// Whether some point holds damage variables.
    pub fn has_damage(&self) -> bool {
        self.points.iter().any(|p| p.vars != Vars::None)
    }

    /// Checks a restored state for a run of `n` particles (the message
    /// says what is wrong): it holds no damage variables, or one entry per
    /// particle, each finite and physical (porosity in [0, 1), a positive
    /// crack radius, positive frozen moduli once pulverized). A state that
    /// passes cannot leave a particle without its damage variables, give it
    /// another's, or feed NaN into a step.
    pub fn check_len(&self, n: usize) -> std::result::Result<(), String> {
        if !self.has_damage() {
            return Ok(());
        }
        let len = self.points.len();
        if len != n {
            return Err(format!("it holds {len} damage states for {n} particles"));
        }
        match self.points.iter().position(|p| {
            p.ceramic().is_some_and(|v| !physical(v)) || p.jh2().is_some_and(|j| !physical_jh2(j))
        }) {
            Some(i) => Err(format!(
                "its damage variables are not all finite and in range (particle {i})"
            )),
            None => Ok(()),
        }
    }
}

impl MaterialState {
    /// Refuses a crack larger than `extent`, the bodies' size: no running
    /// model grows one (a forged state's 1e300 would make every
    /// observable infinite).
    pub fn check_cracks(&self, extent: f64) -> std::result::Result<(), String> {
        match self.points.iter().position(|p| {
            p.ceramic()
                .is_some_and(|v| v.crack_size.is_nan() || v.crack_size > extent)
        }) {
            Some(i) => Err(format!(
                "its crack at particle {i} is larger than the bodies ({} m)",
                crate::error::number(extent)
            )),
            None => Ok(()),
        }
    }
}

/// Whether the state of a JH-2 point is finite and physical: a positive
/// density, damage in [0, 1], bulking not below zero.
fn physical_jh2(j: &Jh2Point) -> bool {
    j.deviator.iter().all(|x| x.is_finite())
        && j.pressure.is_finite()
        && j.density.is_finite()
        && j.density > 0.0
        && j.plastic_strain.is_finite()
        && j.plastic_strain >= 0.0
        && (0.0..=1.0).contains(&j.damage)
        && j.bulking.is_finite()
        && j.bulking >= 0.0
}

/// Whether the variables of a ceramic point are finite and physical.
fn physical(v: &CeramicVars) -> bool {
    v.elastic_strain.iter().all(|x| x.is_finite())
        && v.crack_size.is_finite()
        && v.crack_size > 0.0
        && (0.0..1.0).contains(&v.porosity)
        && v.pulverized.is_none_or(|p| {
            p.bulk_modulus.is_finite()
                && p.bulk_modulus > 0.0
                && p.shear_modulus.is_finite()
                && p.shear_modulus > 0.0
                && p.volumetric_strain.is_finite()
        })
        && v.tensile.is_none_or(|t| {
            // Unit normals, crack radii above zero, openings not below.
            t.normals
                .iter()
                .all(|n| ((n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt() - 1.0).abs() < 1e-9)
                && t.size.iter().all(|a| a.is_finite() && *a > 0.0)
                && t.opening.iter().all(|e| e.is_finite() && *e >= 0.0)
        })
}

/// The saved form: the damage variables only, `None` when no point has any.
/// With JH-2 points, a human-readable format (JSON) writes
/// `{"ceramic": <that form>, "jh2": [<JH-2 point or null>, ...]}` (a state
/// without them keeps the form of format 2, so files written before read
/// back as they were); a binary one (postcard, the FMU state) always writes
/// the pair `(ceramic, jh2)`, `jh2` being `None` when no point has one.
impl serde::Serialize for MaterialState {
    fn serialize<S: serde::Serializer>(
        &self,
        serializer: S,
    ) -> std::result::Result<S::Ok, S::Error> {
        struct Damage<'a>(&'a [PointState]);
        impl serde::Serialize for Damage<'_> {
            fn serialize<S: serde::Serializer>(
                &self,
                serializer: S,
            ) -> std::result::Result<S::Ok, S::Error> {
                serializer.collect_seq(self.0.iter().map(PointState::ceramic))
            }
        }
        struct Jh2s<'a>(&'a [PointState]);
        impl serde::Serialize for Jh2s<'_> {
            fn serialize<S: serde::Serializer>(
                &self,
                serializer: S,
            ) -> std::result::Result<S::Ok, S::Error> {
                serializer.collect_seq(self.0.iter().map(PointState::jh2))
            }
        }
        use serde::ser::SerializeStruct as _;
        let ceramic = self
            .points
            .iter()
            .any(|p| p.ceramic().is_some())
            .then_some(Damage(&self.points));
        let jh2 = self
            .points
            .iter()
            .any(|p| p.jh2().is_some())
            .then_some(Jh2s(&self.points));
        match (serializer.is_human_readable(), jh2) {
            (true, None) => ceramic.serialize(serializer),
            (true, Some(jh2)) => {
                let mut both = serializer.serialize_struct("MaterialState", 2)?;
                both.serialize_field("ceramic", &ceramic)?;
                both.serialize_field("jh2", &jh2)?;
                both.end()
            }
            (false, jh2) => (ceramic, jh2).serialize(serializer),
        }
    }
}

/// The per-point variables of the saved form.
type SavedCeramic = Option<Vec<Option<CeramicVars>>>;
type SavedJh2 = Option<Vec<Option<Jh2Point>>>;

/// Reads the saved form back: the damage variables, with empty caches (not
/// yet checked: [`MaterialState::check_len`]).
impl<'de> serde::Deserialize<'de> for MaterialState {
    fn deserialize<D: serde::Deserializer<'de>>(
        deserializer: D,
    ) -> std::result::Result<Self, D::Error> {
        /// The JSON form with JH-2 points.
        #[derive(serde::Deserialize)]
        #[serde(deny_unknown_fields)]
        struct Both {
            ceramic: SavedCeramic,
            jh2: SavedJh2,
        }
        /// The JSON forms: without JH-2 points (format 2's) or with them.
        #[derive(serde::Deserialize)]
        #[serde(untagged)]
        enum Human {
            Ceramic(SavedCeramic),
            Both(Both),
        }
        let (ceramic, jh2) = if deserializer.is_human_readable() {
            match Human::deserialize(deserializer)? {
                Human::Ceramic(c) => (c, None),
                Human::Both(b) => (b.ceramic, b.jh2),
            }
        } else {
            <(SavedCeramic, SavedJh2)>::deserialize(deserializer)?
        };
        let (ceramic, jh2) = (ceramic.unwrap_or_default(), jh2.unwrap_or_default());
        let n = ceramic.len().max(jh2.len());
        let points = (0..n)
            .map(|i| {
                let vars = match (
                    ceramic.get(i).copied().flatten(),
                    jh2.get(i).copied().flatten(),
                ) {
                    (None, None) => Vars::None,
                    (Some(c), None) => Vars::Ceramic(c),
                    (None, Some(j)) => Vars::Jh2(j),
                    (Some(_), Some(_)) => {
                        return Err(serde::de::Error::custom(format!(
                            "its particle {i} holds the variables of two damage models"
                        )));
                    }
                };
                Ok(PointState {
                    vars,
                    ..PointState::default()
                })
            })
            .collect::<std::result::Result<Vec<_>, D::Error>>()?;
        Ok(MaterialState {
            points,
            ..MaterialState::default()
        })
    }
}

impl MaterialState {
    /// The particles' states (empty before the first step).
    pub fn points(&self) -> &[PointState] {
        &self.points
    }
}
