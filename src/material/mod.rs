//! Material models, one per file, composed into a [`Material`]: an
//! equation of state ([`Eos`]), a strength model ([`Strength`]) and a
//! damage model ([`Damage`]), with the elastic and thermal constants. They
//! work over the symmetric tensors of [`tensor`], in the axisymmetric
//! (4-component) and the 3-D (6-component) form alike.
//!
//! A solver keeps a [`MaterialState`] next to its material (per-particle
//! state of the models: the Johnson-Cook memo, and the ceramic's damage
//! variables, which it saves) and calls [`Material::update`] once per
//! particle and step.
//!
//! A scene chooses the models by name ([`choice`]: `strength =
//! "johnson_cook" | "bilinear"`, `eos = "linear" | "mie_gruneisen"`) or
//! takes a named material ([`presets`]); its parameter table then lists only
//! what the chosen models use, alone or under a body's prefix. A plate of
//! Rajendran-Grove ceramic takes its constants from [`ceramic_block`].

pub mod bilinear;
pub mod ceramic_block;
pub mod choice;
pub mod eos;
pub mod ideal_gas;
pub mod johnson_cook;
// The JH-2 point model, not yet wired into a material; its tests use it.
#[allow(dead_code)]
pub mod jh2_block;
pub mod johnson_holmquist;
pub mod mie_gruneisen;
pub mod presets;
pub mod rajendran_grove;
mod state;
pub mod tensile_cracks;
pub mod tensor;

use crate::error::Result;
use crate::params::Range;
use bilinear::Bilinear;
use eos::LinearEos;
use ideal_gas::IdealGas;
use johnson_cook::JohnsonCook;
use johnson_holmquist::Jh2;
use mie_gruneisen::{CompressionLimit, MieGruneisen, check};
use rajendran_grove::{CeramicPoint, RajendranGrove};
pub use state::{Marks, MaterialState, PointState};
use state::{Memo, Vars};
pub use tensile_cracks::Shield;
use tensor::{Full, SymTensor, radial_return};

/// Equation of state: the pressure from the density and the specific
/// internal energy.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Eos {
    /// `P = K (rho / rho0 - 1)`, no energy dependence.
    Linear(LinearEos),
    /// Mie-Grüneisen with a `U_s`-`u_p` reference curve.
    MieGruneisen(MieGruneisen),
    /// `P = (gamma - 1) rho e`.
    IdealGas(IdealGas),
}

impl Eos {
    /// Pressure at density `rho` and specific internal energy `e` (J/kg,
    /// from the reference state).
    #[inline]
    pub fn pressure(&self, rho: f64, e: f64) -> std::result::Result<f64, CompressionLimit> {
        match self {
            Eos::Linear(l) => Ok(l.pressure(rho)),
            Eos::MieGruneisen(m) => m.pressure(rho, e),
            Eos::IdealGas(g) => Ok(g.pressure(rho, e)),
        }
    }

    /// The bulk modulus `rho c^2` that sets the sound speed at density `rho`
    /// and pressure `p`.
    #[inline]
    pub fn bulk_modulus(&self, rho: f64, p: f64) -> f64 {
        match self {
            Eos::Linear(l) => l.bulk_modulus,
            Eos::MieGruneisen(m) => m.tangent_bulk_modulus(rho, p),
            Eos::IdealGas(g) => g.gamma * p.max(0.0),
        }
    }

    /// The density at which the pressure of the reference state is zero
    /// (none for a gas).
    pub fn reference_density(&self) -> Option<f64> {
        match self {
            Eos::Linear(l) => Some(l.density),
            Eos::MieGruneisen(m) => Some(m.density),
            Eos::IdealGas(_) => None,
        }
    }
}

/// Strength model: the flow stress of J2 plasticity.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Strength {
    /// Johnson-Cook thermo-viscoplasticity (Batra & Zhang eq. (3.7)); its
    /// return takes the flow stress of the start of the step.
    JohnsonCook(JohnsonCook),
    /// Bilinear isotropic hardening; its return is exact for linear
    /// hardening.
    Bilinear(Bilinear),
}

/// Damage model, which also says how a point is updated: without damage,
/// by the equation of state and the strength model (a J2 update); with the
/// ceramic, by the ceramic alone.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Damage {
    /// No damage: the J2 update of the equation of state and the strength
    /// model.
    None,
    /// The Rajendran-Grove ceramic (seed 004, section 4; the module
    /// `rajendran_grove`): micro-cracks, pores and pulverization. Its
    /// moduli fall with the crack density and its pressure depends on the
    /// porosity, so it owns the whole update of its points: its porous
    /// pressure (eqs. 16-18) stands in for the equation of state and its
    /// Gurson and Mohr-Coulomb strengths (eqs. 21, 25) for the strength
    /// model. Build it with [`Material::ceramic`].
    RajendranGrove(RajendranGrove),
    /// The Johnson-Holmquist ceramic JH-2 (JH94; the module
    /// `johnson_holmquist`): its pressure with bulking stands in for the
    /// equation of state and its damaged strength surfaces for the
    /// strength model, so it owns the whole update of its points, as the
    /// Rajendran-Grove ceramic does. Build it with [`Material::jh2`].
    Jh2(Jh2),
}

/// A material: equation of state, strength and damage models, with the
/// elastic and thermal constants the update needs.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Material {
    /// Equation of state.
    pub eos: Eos,
    /// Strength model.
    pub strength: Strength,
    /// Damage model.
    pub damage: Damage,
    /// Shear modulus G (Pa).
    pub shear_modulus: f64,
    /// Specific heat c (J/(kg K)).
    pub specific_heat: f64,
    /// Fraction of the plastic work that heats the material (1).
    pub taylor_quinney: f64,
    /// Temperature of the reference state (K), where the specific internal
    /// energy that the equation of state sees is zero.
    pub reference_temperature: f64,
}

/// What a particle undergoes in one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Loading<T: SymTensor> {
    /// Time step (s).
    pub dt: f64,
    /// Rate of deformation D (1/s).
    pub rate: T,
    /// Spin W (1/s).
    pub spin: T::Spin,
    /// Density at the end of the step (kg/m3).
    pub density: f64,
    /// The cracks of other points that shield this one (only a ceramic's
    /// tensile planes read it; [`Shield::NONE`] but in the 3-D solver with
    /// crack shielding on).
    pub shield: Shield,
}

/// The mechanical state of a particle that a material updates.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Point<T> {
    /// Deviatoric stress (Pa).
    pub deviator: T,
    /// Pressure, positive in compression (Pa).
    pub pressure: f64,
    /// Effective plastic strain (1).
    pub plastic_strain: f64,
    /// Temperature (K).
    pub temperature: f64,
}

impl Material {
    /// Refuses constants out of physical range, by name.
    pub fn validate(&self) -> Result<()> {
        let positive = Range::open_closed(0.0, f64::MAX);
        let non_negative = Range::closed(0.0, f64::MAX);
        check("shear_modulus", self.shear_modulus, non_negative)?;
        check("specific_heat", self.specific_heat, positive)?;
        check(
            "taylor_quinney",
            self.taylor_quinney,
            Range::closed(0.0, 1.0),
        )?;
        check(
            "reference_temperature",
            self.reference_temperature,
            non_negative,
        )?;
        match &self.eos {
            Eos::Linear(l) => {
                check("bulk_modulus", l.bulk_modulus, positive)?;
                check("density", l.density, positive)?;
            }
            Eos::MieGruneisen(m) => m.validate()?,
            Eos::IdealGas(g) => check("gamma", g.gamma, Range::open_closed(1.0, 10.0))?,
        }
        if let Strength::Bilinear(b) = &self.strength {
            check("yield_stress", b.yield_stress, non_negative)?;
            check("hardening_modulus", b.hardening_modulus, non_negative)?;
        }
        // A model that owns its points' update keeps its intact solid in
        // the slots it stands in for ([`Material::ceramic`],
        // [`Material::jh2`]); anything else is a contradiction.
        let (c, t, tr) = (
            self.specific_heat,
            self.taylor_quinney,
            self.reference_temperature,
        );
        let (intact, name, builder) = match &self.damage {
            Damage::None => return Ok(()),
            Damage::RajendranGrove(rg) => {
                rg.validate()?;
                (
                    Material::ceramic(*rg, c, t, tr),
                    "Rajendran-Grove",
                    "ceramic",
                )
            }
            Damage::Jh2(j) => {
                j.constants().validate()?;
                (Material::jh2(*j, c, t, tr), "JH-2", "jh2")
            }
        };
        if (self.eos, self.strength, self.shear_modulus)
            != (intact.eos, intact.strength, intact.shear_modulus)
        {
            return Err(crate::Error::Inconsistent(format!(
                "a {name} material holds its own moduli, pressure and strength: \
                 build it with Material::{builder}"
            )));
        }
        Ok(())
    }

    /// A material of Rajendran-Grove ceramic ([`Damage::RajendranGrove`])
    /// with its thermal constants. The equation-of-state and strength slots
    /// hold the intact dense matrix (linear pressure of bulk modulus
    /// `beta1` at the initial density, perfectly plastic at `C1`), for what
    /// reads them outside the update; the update of a point and
    /// [`Material::longitudinal_modulus`] use the ceramic itself.
    pub fn ceramic(
        c: RajendranGrove,
        specific_heat: f64,
        taylor_quinney: f64,
        reference_temperature: f64,
    ) -> Material {
        Material {
            eos: Eos::Linear(LinearEos {
                bulk_modulus: c.bulk_modulus(),
                density: c.density,
            }),
            strength: Strength::Bilinear(Bilinear {
                yield_stress: c.c1,
                hardening_modulus: 0.0,
            }),
            damage: Damage::RajendranGrove(c),
            shear_modulus: c.shear_modulus,
            specific_heat,
            taylor_quinney,
            reference_temperature,
        }
    }

    /// A material of JH-2 ceramic ([`Damage::Jh2`]) with its thermal
    /// constants. The equation-of-state and strength slots hold the intact
    /// solid (linear pressure of bulk modulus `K1` at `rho0`, perfectly
    /// plastic at the strength of the HEL, `sigma_HEL`), for what reads
    /// them outside the update; the update of a point and
    /// [`Material::longitudinal_modulus`] use the model itself.
    pub fn jh2(
        j: Jh2,
        specific_heat: f64,
        taylor_quinney: f64,
        reference_temperature: f64,
    ) -> Material {
        let c = j.constants();
        Material {
            eos: Eos::Linear(LinearEos {
                bulk_modulus: c.k[0],
                density: c.density,
            }),
            strength: Strength::Bilinear(Bilinear {
                yield_stress: j.limit().strength,
                hardening_modulus: 0.0,
            }),
            damage: Damage::Jh2(j),
            shear_modulus: c.shear_modulus,
            specific_heat,
            taylor_quinney,
            reference_temperature,
        }
    }

    /// The specific internal energy the equation of state sees at
    /// temperature `temp`: the heat `c (T - T_ref)` above the reference
    /// state. (The solvers track temperature, heated by the plastic work;
    /// the elastic energy of compression is in the reference curve.)
    #[inline]
    pub fn energy(&self, temp: f64) -> f64 {
        self.specific_heat * (temp - self.reference_temperature)
    }

    /// Pressure at density `rho` and temperature `temp`.
    #[inline]
    pub fn pressure(&self, rho: f64, temp: f64) -> std::result::Result<f64, CompressionLimit> {
        self.eos.pressure(rho, self.energy(temp))
    }

    /// The longitudinal modulus `rho c^2 + 4/3 G` that sets the elastic wave
    /// speed at density `rho` and pressure `p`.
    ///
    /// A ceramic's modulus depends on its porosity: without a point's state
    /// this is the one of the intact point at the initial porosity
    /// ([`Material::wave_modulus`] takes the state).
    #[inline]
    pub fn longitudinal_modulus(&self, rho: f64, p: f64) -> f64 {
        match &self.damage {
            Damage::RajendranGrove(c) => c.longitudinal_modulus(rho, c.initial_porosity),
            Damage::Jh2(j) => j.longitudinal_modulus(rho),
            Damage::None => self.eos.bulk_modulus(rho, p) + 4.0 / 3.0 * self.shear_modulus,
        }
    }

    /// The longitudinal modulus of a point in state `state` at density
    /// `rho` and pressure `p`: [`Material::longitudinal_modulus`], but for
    /// a ceramic at the point's own porosity, with the shear modulus of the
    /// uncracked porous solid and the density of its matrix (cracks only
    /// soften it, so the wave speed is bounded from above, as a stable
    /// time step needs).
    pub fn wave_modulus(&self, rho: f64, p: f64, state: &PointState) -> f64 {
        match (&self.damage, state.ceramic()) {
            // The matrix's density: the point's, less its tensile cracks'
            // openings (a point whose cracks have opened is stiffer than its
            // density says once they close).
            (Damage::RajendranGrove(c), Some(v)) => {
                let opened: f64 = v.tensile.map_or(0.0, |t| t.opening.iter().sum());
                c.longitudinal_modulus(rho * (1.0 + opened), v.porosity)
            }
            (Damage::Jh2(j), _) => j.longitudinal_modulus(rho),
            _ => self.longitudinal_modulus(rho, p),
        }
    }

    /// Gives a point of a ceramic whose tensile flaws scatter
    /// ([`RajendranGrove::tensile_flaw_scatter`]) its own flaw before its
    /// first step, drawn from `key` (its node or cell index) for its
    /// `volume` where the solver knows it
    /// ([`RajendranGrove::tensile_flaw_volume`]); any other point is left as
    /// it is.
    pub(crate) fn seed_point(&self, key: u64, volume: Option<f64>, state: &mut PointState) {
        if let Damage::RajendranGrove(c) = &self.damage
            && c.tensile_flaw_scatter > 0.0
            && state.ceramic().is_none()
        {
            let mut vars = c.initial_point().vars();
            vars.tensile_flaw = c.tensile_flaw_of(key, volume);
            state.vars = Vars::Ceramic(vars);
        }
    }

    /// One step of a particle, by the update its material has: the J2
    /// update of the equation of state and the strength model
    /// ([`Damage::None`]), or the ceramic's own update
    /// ([`Damage::RajendranGrove`]), whose porous pressure takes the heat
    /// `c (T - T_ref)` of the point's temperature at the start of the step
    /// as its specific internal energy. Returns the new state, or the
    /// compression limit of the equation of state.
    #[inline]
    pub(crate) fn update<T: SymTensor>(
        &self,
        load: &Loading<T>,
        old: &Point<T>,
        state: &mut PointState,
    ) -> std::result::Result<Point<T>, CompressionLimit> {
        match &self.damage {
            Damage::None => self.update_j2(load, old, state),
            Damage::RajendranGrove(c) => {
                Ok(self.update_ceramic(c, load, old, self.energy(old.temperature), state))
            }
            Damage::Jh2(j) => Ok(self.update_jh2(j, load, old, state)),
        }
    }

    /// [`Material::update`] for a solver that keeps each point's specific
    /// internal energy `energy` (J/kg, from the reference state) at the
    /// start of the step, as the plate-impact cells do (the work of their
    /// total stress, artificial viscosity included): the ceramic's porous
    /// pressure takes it instead of the heat of the temperature. The J2
    /// update is the same as [`Material::update`]'s: its pressure is at the
    /// point's new temperature.
    #[inline]
    pub(crate) fn update_with_energy<T: SymTensor>(
        &self,
        load: &Loading<T>,
        old: &Point<T>,
        energy: f64,
        state: &mut PointState,
    ) -> std::result::Result<Point<T>, CompressionLimit> {
        match &self.damage {
            Damage::None => self.update_j2(load, old, state),
            Damage::RajendranGrove(c) => Ok(self.update_ceramic(c, load, old, energy, state)),
            Damage::Jh2(j) => Ok(self.update_jh2(j, load, old, state)),
        }
    }

    /// One step of a point of a material without damage: the Jaumann-rate
    /// trial deviator, the J2 radial return on the strength model's flow
    /// stress, heating by the Taylor-Quinney fraction of the plastic work,
    /// then the pressure at the new density and temperature.
    #[inline]
    fn update_j2<T: SymTensor>(
        &self,
        load: &Loading<T>,
        old: &Point<T>,
        state: &mut PointState,
    ) -> std::result::Result<Point<T>, CompressionLimit> {
        let mu = self.shear_modulus;
        let trial = old
            .deviator
            .jaumann_trial(&load.rate, &load.spin, mu, load.dt);
        let ret = match &self.strength {
            Strength::JohnsonCook(jc) => {
                let (eps_p, temp) = (old.plastic_strain, old.temperature);
                let f = &mut state.memo;
                if f.eps_p != eps_p || f.temp != temp {
                    *f = Memo {
                        eps_p,
                        temp,
                        hardening: jc.hardening(eps_p),
                        thermal: jc.thermal(temp),
                    };
                }
                let sy = jc.strength(f.hardening, load.rate.norm(), f.thermal);
                radial_return(&trial, sy, mu, 0.0)
            }
            Strength::Bilinear(b) => radial_return(
                &trial,
                b.flow_stress(old.plastic_strain),
                mu,
                b.hardening_modulus,
            ),
        };
        let temperature = old.temperature
            + self.taylor_quinney * ret.plastic_work / (load.density * self.specific_heat);
        Ok(Point {
            deviator: ret.stress,
            pressure: self.pressure(load.density, temperature)?,
            plastic_strain: old.plastic_strain + ret.plastic_strain,
            temperature,
        })
    }

    /// One step of a ceramic point at specific internal energy `energy`
    /// ([`RajendranGrove`]'s update, in 3-D components whatever the
    /// solver's form; its damage variables in `state`, the intact ones
    /// before its first step), heated by the Taylor-Quinney fraction of its
    /// plastic work.
    fn update_ceramic<T: SymTensor>(
        &self,
        c: &RajendranGrove,
        load: &Loading<T>,
        old: &Point<T>,
        energy: f64,
        state: &mut PointState,
    ) -> Point<T> {
        let full = Loading::<Full> {
            dt: load.dt,
            rate: load.rate.to_full(),
            spin: T::spin_to_full(&load.spin),
            density: load.density,
            shield: load.shield,
        };
        let vars = state
            .ceramic()
            .copied()
            .unwrap_or_else(|| c.initial_point().vars());
        let mut point = CeramicPoint::of(
            &vars,
            old.deviator.to_full(),
            old.pressure,
            old.plastic_strain,
        );
        let work = c.update(&full, energy, &mut point);
        state.vars = Vars::Ceramic(point.vars());
        let stress = (&point.deviator, point.pressure, point.plastic_strain);
        self.heated(stress, work, old.temperature, load.density)
    }

    /// The state of a point of a model that owns its update: its deviator,
    /// pressure and plastic strain `(s, p, eps_p)` in 3-D components, and
    /// the temperature `temp` raised by the Taylor-Quinney fraction of the
    /// plastic work `work` (J/m3) at density `rho`.
    fn heated<T: SymTensor>(
        &self,
        (s, p, eps_p): (&Full, f64, f64),
        work: f64,
        temp: f64,
        rho: f64,
    ) -> Point<T> {
        Point {
            deviator: T::from_full(s),
            pressure: p,
            plastic_strain: eps_p,
            temperature: temp + self.taylor_quinney * work / (rho * self.specific_heat),
        }
    }

    /// One step of a JH-2 point ([`Jh2::step_to_density`] at the solver's
    /// density, in 3-D components whatever the solver's form; its state in
    /// `state`, the intact point before its first step), heated by the
    /// Taylor-Quinney fraction of its plastic work. JH-2's pressure takes
    /// no energy.
    fn update_jh2<T: SymTensor>(
        &self,
        j: &Jh2,
        load: &Loading<T>,
        old: &Point<T>,
        state: &mut PointState,
    ) -> Point<T> {
        let mut point = state.jh2().copied().unwrap_or_else(|| j.initial_point());
        let rate = load.rate.to_full();
        let spin = T::spin_to_full(&load.spin);
        let work = j.step_to_density(&mut point, &rate, &spin, load.dt, load.density);
        state.vars = Vars::Jh2(point);
        let stress = (&point.deviator, point.pressure, point.plastic_strain);
        self.heated(stress, work, old.temperature, load.density)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rajendran_grove::CeramicVars;
    use tensor::Axisymmetric;

    fn steel(strength: Strength, eos: Eos) -> Material {
        Material {
            eos,
            strength,
            damage: Damage::None,
            shear_modulus: 77e9,
            specific_heat: 477.0,
            taylor_quinney: 0.9,
            reference_temperature: 293.0,
        }
    }

    fn jc() -> Strength {
        Strength::JohnsonCook(JohnsonCook {
            a: 792e6,
            b: 510e6,
            n: 0.26,
            c: 0.014,
            m: 1.03,
            melt_temperature: 1793.0,
            room_temperature: 293.0,
            ref_strain_rate: 1.0,
        })
    }

    fn linear() -> Eos {
        Eos::Linear(LinearEos {
            bulk_modulus: 159e9,
            density: 7850.0,
        })
    }

    /// A state at zero pressure and room temperature.
    fn unloaded<T>(deviator: T, plastic_strain: f64) -> Point<T> {
        Point {
            deviator,
            pressure: 0.0,
            plastic_strain,
            temperature: 293.0,
        }
    }

    /// The same loading in the axisymmetric and the 3-D form gives the same
    /// state, the memo is refreshed when the state moves and reused when it
    /// does not, and heating follows the plastic work.
    #[test]
    fn update_in_both_forms() {
        let m = steel(jc(), linear());
        let axi = Loading::<Axisymmetric> {
            dt: 1e-7,
            rate: [2e4, -5e4, 2e4, 1e4],
            spin: 3e3,
            density: 7900.0,
            shield: Shield::NONE,
        };
        let full = Loading::<Full> {
            dt: axi.dt,
            rate: [2e4, -5e4, 2e4, 1e4, 0.0, 0.0],
            spin: [3e3, 0.0, 0.0],
            density: axi.density,
            shield: Shield::NONE,
        };
        let (old, old6) = (unloaded([0.0; 4], 0.0), unloaded([0.0; 6], 0.0));
        let (mut s4, mut s6) = (PointState::default(), PointState::default());
        let a = m.update(&axi, &old, &mut s4).unwrap();
        let b = m.update(&full, &old6, &mut s6).unwrap();
        // A strain increment of 5e-3 in Z: past yield.
        assert!(a.plastic_strain > 0.0, "{a:?}");
        assert!((a.plastic_strain - b.plastic_strain).abs() < 1e-12 * a.plastic_strain);
        for c in 0..4 {
            assert!((a.deviator[c] - b.deviator[c]).abs() < 1e-9 * a.deviator[0].abs());
        }
        let Strength::JohnsonCook(j) = jc() else {
            unreachable!()
        };
        let work = a.plastic_strain * j.flow_stress(0.0, axi.rate.norm(), 293.0);
        let heat = 0.9 * work / (7900.0 * 477.0);
        assert!((a.temperature - 293.0 - heat).abs() < 1e-9);
        assert_eq!(a.pressure, 159e9 * (7900.0 / 7850.0 - 1.0));
        // The memo holds the factors of the old state.
        assert_eq!(s4.memo.eps_p, 0.0);
        assert_eq!(s4.memo.hardening, 792e6);
        // A second step from the new state refreshes it.
        let c = m.update(&axi, &a, &mut s4).unwrap();
        assert_eq!(s4.memo.eps_p, a.plastic_strain);
        assert!(c.plastic_strain > a.plastic_strain);
    }

    /// The bilinear strength gives the exact return of linear hardening,
    /// with the heating of the plastic work under the flow-stress line.
    #[test]
    fn bilinear_update() {
        let b = Bilinear {
            yield_stress: 400e6,
            hardening_modulus: 1e9,
        };
        let m = steel(Strength::Bilinear(b), linear());
        let load = Loading::<Full> {
            dt: 1e-7,
            rate: [0.0, 0.0, 0.0, 5e4, 0.0, 0.0],
            spin: [0.0; 3],
            density: 7850.0,
            shield: Shield::NONE,
        };
        let old = unloaded([0.0; 6], 0.1);
        let new = m.update(&load, &old, &mut PointState::default()).unwrap();
        // Trial shear 2 G D dt, von Mises sqrt(3) times that.
        let s_trial = 3f64.sqrt() * 2.0 * 77e9 * 5e4 * 1e-7;
        let deps = (s_trial - b.flow_stress(0.1)) / (3.0 * 77e9 + 1e9);
        assert!((new.plastic_strain - 0.1 - deps).abs() < 1e-12);
        let sy = b.flow_stress(0.1 + deps);
        assert!((new.deviator.von_mises() - sy).abs() < 1e-6 * sy);
        let work = 0.5 * (b.flow_stress(0.1) + sy) * deps;
        assert!((new.temperature - 293.0 - 0.9 * work / (7850.0 * 477.0)).abs() < 1e-9);
        assert_eq!(new.pressure, 0.0);
    }

    /// Mie-Grüneisen sees the heat above the reference temperature, and a
    /// compression past its limit is refused.
    #[test]
    fn mie_gruneisen_update() {
        let mg = MieGruneisen {
            density: 7850.0,
            c0: 4570.0,
            s: 1.49,
            gruneisen: 1.93,
        };
        let m = steel(jc(), Eos::MieGruneisen(mg));
        assert!(m.validate().is_ok());
        let hot = m.pressure(7850.0, 393.0).unwrap();
        assert!((hot - 1.93 * 7850.0 * 477.0 * 100.0).abs() < 1e-6 * hot);
        assert_eq!(m.pressure(7850.0, 293.0).unwrap(), 0.0);
        let load = Loading::<Axisymmetric> {
            dt: 1e-9,
            rate: [0.0; 4],
            spin: 0.0,
            density: 7850.0 * 4.0,
            shield: Shield::NONE,
        };
        let old = unloaded([0.0; 4], 0.0);
        let err = m.update(&load, &old, &mut PointState::default());
        assert!(err.is_err(), "{err:?}");
    }

    /// A strain path through compression past the elastic limit, shear
    /// with spin, and tension until the cracks pulverize the point: the
    /// rates of each leg (3-D components) and its number of steps.
    fn ceramic_path() -> Vec<(Full, [f64; 3], usize)> {
        vec![
            // Uniaxial strain along Y at 1e5/s: past the HEL (log strain
            // about 0.025) by 0.035.
            ([0.0, -1e5, 0.0, 0.0, 0.0, 0.0], [0.0; 3], 350),
            // Shear in XY with spin, under the compression.
            ([0.0, 0.0, 0.0, 5e4, 0.0, 0.0], [2e4, 0.0, 0.0], 200),
            // Unloading into triaxial tension: the cracks open and grow
            // until the point pulverizes, and it is pulled on after that.
            ([1e5, 1e5, 1e5, 0.0, 0.0, 0.0], [0.0; 3], 2000),
        ]
    }

    /// The ceramic material steps a point exactly as the ceramic's own
    /// point update does (its analytic checks are in
    /// [`rajendran_grove`]), to the bit, in the 3-D form and, over an
    /// axisymmetric path, in the axisymmetric form; the point is heated by
    /// the Taylor-Quinney fraction of the plastic work the point update
    /// returns. The path pulverizes the point, so every branch is taken.
    #[test]
    fn ceramic_material_steps_as_the_point_update() {
        let c = RajendranGrove::ad85();
        let (heat, tq, t0) = (750.0, 0.9, 293.0);
        let m = Material::ceramic(c, heat, tq, t0);
        assert!(m.validate().is_ok());
        let dt = 1e-9;
        let mut twin = c.initial_point();
        let mut twin_temp = t0;
        let mut rho = c.density;
        let mut full = unloaded([0.0; 6], 0.0);
        let mut axi = unloaded([0.0; 4], 0.0);
        let (mut s6, mut s4) = (PointState::default(), PointState::default());
        let mut steps = 0;
        let mut least_porosity = c.initial_porosity;
        for (rate, spin, n) in ceramic_path() {
            for _ in 0..n {
                rho *= 1.0 - dt * (rate[0] + rate[1] + rate[2]);
                let load = Loading::<Full> {
                    dt,
                    rate,
                    spin,
                    density: rho,
                    shield: Shield::NONE,
                };
                let work = c.update(&load, m.energy(twin_temp), &mut twin);
                twin_temp += tq * work / (rho * heat);
                full = m.update(&load, &full, &mut s6).unwrap();
                assert_eq!(full.deviator, twin.deviator, "step {steps}");
                assert_eq!(full.pressure, twin.pressure, "step {steps}");
                assert_eq!(full.plastic_strain, twin.plastic_strain);
                assert_eq!(full.temperature, twin_temp);
                assert_eq!(s6.ceramic(), Some(&twin.vars()));
                least_porosity = least_porosity.min(twin.porosity);
                // The same path in (R, Z, theta) as (X, Y, Z): the legs
                // have no YZ or ZX part.
                let load4 = Loading::<Axisymmetric> {
                    dt,
                    rate: Axisymmetric::from_full(&rate),
                    spin: spin[0],
                    density: rho,
                    shield: Shield::NONE,
                };
                axi = m.update(&load4, &axi, &mut s4).unwrap();
                assert_eq!(axi.deviator.to_full(), twin.deviator);
                assert_eq!(axi.pressure, twin.pressure);
                assert_eq!(axi.temperature, twin_temp);
                steps += 1;
            }
        }
        let v = s6.ceramic().unwrap();
        assert!(least_porosity < 0.095, "pores closed: {least_porosity}");
        assert!(v.pulverized.is_some(), "pulverized at the end: {v:?}");
        assert!(twin_temp > t0 && full.plastic_strain > 0.0);
    }

    /// The JH-2 material steps a point exactly as the JH-2 point model does
    /// (its analytic checks are in [`johnson_holmquist`]), to the bit, in
    /// the 3-D form, with the density the solver gives it; the point is
    /// heated by the Taylor-Quinney fraction of its plastic work. The path
    /// passes the HEL, shears and is pulled apart, so the point is damaged
    /// and fractured and every branch is taken.
    #[test]
    fn jh2_material_steps_as_the_point_model() {
        let j = johnson_holmquist::JohnsonHolmquist::example_ceramic()
            .model()
            .unwrap();
        let (heat, tq, t0) = (750.0, 0.9, 293.0);
        let m = Material::jh2(j, heat, tq, t0);
        assert!(m.validate().is_ok());
        let dt = 1e-9;
        let mut twin = j.initial_point();
        let mut twin_temp = t0;
        let mut full = unloaded([0.0; 6], 0.0);
        let mut state = PointState::default();
        for (rate, spin, n) in ceramic_path() {
            for _ in 0..n {
                let work = j.step_with_spin(&mut twin, &rate, &spin, dt);
                twin_temp += tq * work / (twin.density * heat);
                let load = Loading::<Full> {
                    dt,
                    rate,
                    spin,
                    density: twin.density,
                    shield: Shield::NONE,
                };
                full = m.update(&load, &full, &mut state).unwrap();
                assert_eq!(full.deviator, twin.deviator);
                assert_eq!(full.pressure, twin.pressure);
                assert_eq!(full.plastic_strain, twin.plastic_strain);
                assert_eq!(full.temperature, twin_temp);
                assert_eq!(state.jh2(), Some(&twin));
            }
        }
        assert_eq!(twin.damage, 1.0);
        assert!(full.plastic_strain > 0.0 && twin_temp > t0);
        // The wave speed: the intact solid's K1 + 4/3 G at rho0.
        let c = j.constants();
        let expected = c.k[0] + 4.0 / 3.0 * c.shear_modulus;
        let got = m.wave_modulus(c.density, 0.0, &state);
        assert!((got / expected - 1.0).abs() < 1e-12, "{got} {expected}");
        // The slots hold the intact solid: anything else is refused.
        let mut bad = m;
        bad.shear_modulus *= 2.0;
        assert!(bad.validate().is_err());
        // A state with JH-2 points saves them and reads them back, in JSON
        // and in postcard, beside a ceramic point and a point with none;
        // a damage past 1 is refused by the check of a restored state.
        let mut ceramic = PointState::default();
        let rg = RajendranGrove::ad85();
        let squeeze = Loading::<Full> {
            dt: 1e-9,
            rate: [0.0, -1e5, 0.0, 0.0, 0.0, 0.0],
            spin: [0.0; 3],
            density: rg.density * (1.0 + 1e-4),
            shield: Shield::NONE,
        };
        Material::ceramic(rg, heat, tq, t0)
            .update(&squeeze, &unloaded([0.0; 6], 0.0), &mut ceramic)
            .unwrap();
        let saved = MaterialState {
            points: vec![state, ceramic, PointState::default()],
            ..MaterialState::default()
        };
        let json = serde_json::to_string(&saved).unwrap();
        assert!(json.starts_with("{\"ceramic\":[null,{"), "{json}");
        let from_json: MaterialState = serde_json::from_str(&json).unwrap();
        let bytes = postcard::to_allocvec(&saved).unwrap();
        let from_postcard: MaterialState = postcard::from_bytes(&bytes).unwrap();
        for back in [&from_json, &from_postcard] {
            assert_eq!(back.points.len(), 3);
            assert_eq!(back.points[0].jh2(), Some(&twin));
            assert_eq!(back.points[1].ceramic(), ceramic.ceramic());
            assert!(back.points[2].jh2().is_none() && back.points[2].ceramic().is_none());
            assert!(back.check_len(3).is_ok());
        }
        let mut forged = from_json;
        if let Vars::Jh2(j) = &mut forged.points[0].vars {
            j.damage = 1.5;
        }
        assert!(forged.check_len(3).is_err());
    }

    /// The ceramic's wave modulus at its initial density and porosity is
    /// `beta1 + 4/3 R_g G` (the matrix is neither compressed nor
    /// stretched), with Mackenzie's `R_g` typed out; a compressed point is
    /// stiffer; the state's porosity is the one used.
    #[test]
    fn ceramic_wave_modulus() {
        let c = RajendranGrove::ad85();
        let m = Material::ceramic(c, 750.0, 0.9, 293.0);
        let (k, g, f0) = (150e9, 88e9, 0.1);
        let rg = 1.0 - (6.0 * k + 12.0 * g) / (9.0 * k + 8.0 * g) * f0;
        let at_rest = m.longitudinal_modulus(c.density, 0.0);
        assert!((at_rest - (k + 4.0 / 3.0 * rg * g)).abs() < 1e-12 * at_rest);
        assert!(m.longitudinal_modulus(1.05 * c.density, 1e9) > at_rest);
        // A point whose pores have closed to 5%: its matrix is less
        // compressed at the same density, and its shear modulus higher.
        let state = PointState {
            vars: Vars::Ceramic(CeramicVars {
                porosity: 0.05,
                ..c.initial_point().vars()
            }),
            ..PointState::default()
        };
        let rho = c.density * 0.95 / 0.9;
        let eta: f64 = 0.9 * rho / (0.95 * c.density) - 1.0;
        assert!(eta.abs() < 1e-15);
        let rg5 = 1.0 - (6.0 * k + 12.0 * g) / (9.0 * k + 8.0 * g) * 0.05;
        let want = k + 4.0 / 3.0 * rg5 * g;
        let got = m.wave_modulus(rho, 0.0, &state);
        assert!((got - want).abs() < 1e-9 * want, "{got} {want}");
        // A material without damage ignores the state.
        let steel = steel(jc(), linear());
        assert_eq!(
            steel.wave_modulus(7900.0, 1e8, &state),
            steel.longitudinal_modulus(7900.0, 1e8)
        );
    }

    /// Every bit of a point's damage variables.
    fn damage_bits(p: &PointState) -> Option<Vec<u64>> {
        p.ceramic().map(|v| {
            let mut x = v.elastic_strain.to_vec();
            x.extend([v.crack_size, v.porosity]);
            if let Some(q) = v.pulverized {
                x.extend([q.bulk_modulus, q.shear_modulus, q.volumetric_strain]);
            }
            x.iter().map(|f| f.to_bits()).collect()
        })
    }

    /// The state of four ceramic points stepped along [`ceramic_path`] by
    /// 100, 400 and 2550 steps (intact and elastic, compacted and sheared,
    /// pulverized), the last never stepped.
    fn ceramic_state() -> MaterialState {
        let c = RajendranGrove::ad85();
        let m = Material::ceramic(c, 750.0, 0.9, 293.0);
        let mut state = MaterialState::default();
        state.fit(4);
        let dt = 1e-9;
        let mut rho = c.density;
        let mut point = unloaded([0.0; 6], 0.0);
        let mut k = 0;
        for (rate, spin, n) in ceramic_path() {
            for _ in 0..n {
                rho *= 1.0 - dt * (rate[0] + rate[1] + rate[2]);
                let load = Loading::<Full> {
                    dt,
                    rate,
                    spin,
                    density: rho,
                    shield: Shield::NONE,
                };
                let mut step = state.points_mut()[0];
                point = m.update(&load, &point, &mut step).unwrap();
                state.points_mut()[0] = step;
                k += 1;
                match k {
                    100 => state.points_mut()[1] = step,
                    400 => state.points_mut()[2] = step,
                    _ => {}
                }
            }
        }
        // Point 0 is the pulverized one; 3 has not stepped.
        state
    }

    /// On several ranks the material pass leaves the damage variables
    /// apart and the marks whole: after `after_pass` every rank's marks are
    /// those of every point's own variables (pulverized, open tensile
    /// cracks and their openings, JH-2 and comminuted), while a rank's
    /// points outside its part keep what they held; after `share` every
    /// rank holds every point's variables, and a second `share` changes
    /// nothing. `share_now` shares at once. Between them a new split
    /// (`hand_over`): each rank then holds current variables on its new
    /// part and at each point that changed rank, and the rest as it was
    /// (`gather_records_listed`). Oracle: the whole state, and
    /// `Marks::of` against the `PointState` queries it stands for.
    #[test]
    fn the_ranks_keep_the_variables_apart_and_the_marks_whole() {
        use crate::material::johnson_holmquist::Jh2Point;
        use crate::material::tensile_cracks::TensileCracks;
        let base = ceramic_state();
        let mut whole = MaterialState::default();
        for k in 0..5 {
            for (i, p) in base.points.iter().enumerate() {
                let mut p = *p;
                if let (1, Vars::Ceramic(c)) = (k % 3, &mut p.vars) {
                    c.tensile = Some(TensileCracks {
                        normals: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
                        size: [2e-4, 1e-4, 1e-4],
                        opening: [1e-4 * (i + 1) as f64, 0.0, 0.0],
                        shielding: None,
                    });
                }
                if k == 2 && i == 3 {
                    p.vars = Vars::Jh2(Jh2Point {
                        deviator: [0.0; 6],
                        pressure: 1e9,
                        density: 3700.0,
                        plastic_strain: 0.1,
                        damage: 1.0,
                        bulking: 0.0,
                        failed: false,
                    });
                }
                whole.points.push(p);
            }
        }
        let n = whole.points.len();
        let all: Vec<Marks> = whole.points.iter().map(Marks::of).collect();
        for (m, p) in all.iter().zip(&whole.points) {
            assert_eq!(m.is_pulverized(), p.is_pulverized());
            assert_eq!(m.has_open_cracks(), p.has_open_cracks());
            assert_eq!(m.is_jh2(), p.jh2().is_some());
            assert_eq!(m.is_comminuted(), p.is_comminuted());
            assert_eq!(m.opened().to_bits(), p.opened().to_bits());
        }
        assert!(all.iter().any(Marks::has_open_cracks) && all.iter().any(Marks::is_jh2));
        assert!(all.iter().any(Marks::is_pulverized) && all.iter().any(Marks::is_comminuted));
        for size in [2, 3, 4] {
            for share_now in [false, true] {
                let got = crate::ranks::tests::on_threads(size, |ranks| {
                    let parts = crate::ranks::shares(ranks, n, 3);
                    let own = parts[ranks.rank()].clone();
                    // Outside its part a rank holds stale variables.
                    let mut mine = MaterialState {
                        points: (0..n)
                            .map(|i| {
                                if own.contains(&i) {
                                    whole.points[i]
                                } else {
                                    base.points[3]
                                }
                            })
                            .collect(),
                        ..MaterialState::default()
                    };
                    mine.fit(n);
                    let mut wire = Vec::new();
                    mine.after_pass(ranks, &parts, share_now, &mut wire);
                    let marks = mine.marks().to_vec();
                    let apart: Vec<Vars> = mine.points.iter().map(|p| p.vars).collect();
                    // A new split: each cut moved on by two points (rank
                    // 0's part grows, the last one's shrinks).
                    let moved: Vec<std::ops::Range<usize>> = parts
                        .iter()
                        .enumerate()
                        .map(|(r, p)| {
                            let cut = |c: usize| if c == 0 || c == n { c } else { (c + 2).min(n) };
                            cut(p.start)..if r + 1 == size { n } else { cut(p.end) }
                        })
                        .collect();
                    mine.hand_over(ranks, &moved, &mut wire);
                    let handed: Vec<Vars> = mine.points.iter().map(|p| p.vars).collect();
                    mine.share(ranks, &mut wire);
                    let shared: Vec<Vars> = mine.points.iter().map(|p| p.vars).collect();
                    mine.share(ranks, &mut wire);
                    let again: Vec<Vars> = mine.points.iter().map(|p| p.vars).collect();
                    let mine_now = moved[ranks.rank()].clone();
                    (
                        own,
                        marks,
                        apart,
                        (parts, moved, mine_now, handed),
                        shared,
                        again,
                    )
                });
                let expected: Vec<Vars> = whole.points.iter().map(|p| p.vars).collect();
                for (own, marks, apart, (parts, moved, mine_now, handed), shared, again) in got {
                    // After the hand-over each rank holds current variables
                    // on its new part and at every point that changed rank;
                    // any other point is as it was.
                    let owner = |p: &[std::ops::Range<usize>], i: usize| {
                        p.iter().position(|r| r.contains(&i))
                    };
                    let mut travelled = 0;
                    for i in 0..n {
                        let went = owner(&parts, i) != owner(&moved, i);
                        travelled += usize::from(went);
                        if mine_now.contains(&i) || went {
                            assert_eq!(handed[i], expected[i], "{size} ranks, handed point {i}");
                        } else {
                            assert_eq!(handed[i], apart[i], "{size} ranks, point {i}");
                        }
                    }
                    assert!(travelled > 0, "the split moved");
                    assert_eq!(marks, all, "{size} ranks");
                    for i in 0..n {
                        let stale = base.points[3].vars;
                        let before = if own.contains(&i) || share_now {
                            &expected[i]
                        } else {
                            &stale
                        };
                        assert_eq!(&apart[i], before, "{size} ranks, point {i}");
                    }
                    assert_eq!(shared, expected, "{size} ranks");
                    assert_eq!(again, expected, "{size} ranks");
                }
            }
        }
    }

    /// A state with ceramic points round-trips through postcard and JSON
    /// with the same bits in every damage variable, a point without
    /// variables stays without, and the caches come back empty; a state
    /// without damage saves as the empty payload (one byte in postcard,
    /// `null` in JSON).
    #[test]
    fn material_state_saves_only_the_damage() {
        let state = ceramic_state();
        let p = &state.points;
        assert!(p[0].ceramic().unwrap().pulverized.is_some(), "{:?}", p[0]);
        assert!(p[1].ceramic().unwrap().pulverized.is_none());
        let c = RajendranGrove::ad85();
        assert!(p[2].ceramic().unwrap().porosity < c.initial_porosity);
        assert!(p[3].ceramic().is_none());
        let bytes = postcard::to_allocvec(&state).unwrap();
        let text = serde_json::to_string(&state).unwrap();
        let from_postcard: MaterialState = postcard::from_bytes(&bytes).unwrap();
        let from_json: MaterialState = serde_json::from_str(&text).unwrap();
        for back in [&from_postcard, &from_json] {
            assert_eq!(back.points.len(), 4);
            for (a, b) in state.points.iter().zip(&back.points) {
                assert_eq!(damage_bits(a), damage_bits(b));
                assert!(b.memo.eps_p.is_nan() && b.memo.temp.is_nan());
            }
            back.check_len(4).unwrap();
        }
        // The payload: Some, four entries, the last None (then no JH-2
        // points).
        assert_eq!(bytes[..2], [1, 4]);
        assert_eq!(*bytes.last().unwrap(), 0);
        assert!(text.starts_with("[{\"elastic_strain\":") && text.ends_with(",null]"));

        // Steel: the Johnson-Cook memo is filled, and not saved.
        let m = steel(jc(), linear());
        let mut steel_state = MaterialState::default();
        steel_state.fit(3);
        let load = Loading::<Full> {
            dt: 1e-7,
            rate: [0.0, 0.0, 0.0, 5e4, 0.0, 0.0],
            spin: [0.0; 3],
            density: 7850.0,
            shield: Shield::NONE,
        };
        for s in steel_state.points_mut() {
            m.update(&load, &unloaded([0.0; 6], 0.0), s).unwrap();
            assert_eq!(s.memo.eps_p, 0.0);
        }
        assert!(!steel_state.has_damage());
        // In postcard the pair (ceramic, JH-2): neither.
        assert_eq!(postcard::to_allocvec(&steel_state).unwrap(), [0, 0]);
        assert_eq!(serde_json::to_string(&steel_state).unwrap(), "null");
        let back: MaterialState = postcard::from_bytes(&[0, 0]).unwrap();
        assert!(back.points.is_empty());
        back.check_len(3).unwrap();
    }

    /// A restored state with damage variables for another number of
    /// particles, or with variables out of range, is refused, saying what
    /// is wrong.
    #[test]
    fn restored_material_state_is_checked() {
        let state = ceramic_state();
        state.check_len(4).unwrap();
        let e = state.check_len(5).unwrap_err();
        assert_eq!(e, "it holds 4 damage states for 5 particles");
        assert!(state.check_len(3).is_err());
        let forged = |edit: fn(&mut CeramicVars)| {
            let mut s = state.clone();
            let Vars::Ceramic(v) = &mut s.points[1].vars else {
                panic!("a ceramic point")
            };
            edit(v);
            s.check_len(4)
        };
        type Edit = fn(&mut CeramicVars);
        let edits: [Edit; 5] = [
            |v| v.porosity = 1.0,
            |v| v.porosity = -0.01,
            |v| v.crack_size = 0.0,
            |v| v.elastic_strain[4] = f64::NAN,
            |v| {
                v.pulverized = Some(rajendran_grove::Pulverized {
                    bulk_modulus: 1e11,
                    shear_modulus: 0.0,
                    volumetric_strain: 0.0,
                })
            },
        ];
        for edit in edits {
            let e = forged(edit).unwrap_err();
            assert_eq!(
                e,
                "its damage variables are not all finite and in range (particle 1)"
            );
        }
        assert!(forged(|v| v.porosity = 0.2).is_ok());
    }

    /// A ceramic material refuses a constant out of range by name, and
    /// slots that contradict the ceramic.
    #[test]
    fn ceramic_material_is_validated() {
        let c = RajendranGrove {
            initial_porosity: 0.7,
            ..RajendranGrove::ad85()
        };
        match Material::ceramic(c, 750.0, 0.9, 293.0).validate() {
            Err(crate::Error::OutOfRange { name, .. }) => assert_eq!(name, "initial_porosity"),
            other => panic!("{other:?}"),
        }
        let odd = Material {
            shear_modulus: 1e9,
            ..Material::ceramic(RajendranGrove::ad85(), 750.0, 0.9, 293.0)
        };
        let err = odd.validate().unwrap_err();
        assert_eq!(err.name(), "Inconsistent", "{err}");
    }

    /// Constants out of range are refused by name.
    #[test]
    fn validate_names_the_constant() {
        let bad = Material {
            shear_modulus: -1.0,
            ..steel(jc(), linear())
        };
        let names = |m: Material| match m.validate() {
            Err(crate::Error::OutOfRange { name, .. }) => name,
            other => panic!("{other:?}"),
        };
        assert_eq!(names(bad), "shear_modulus");
        let soft = Strength::Bilinear(Bilinear {
            yield_stress: 1e8,
            hardening_modulus: -1e9,
        });
        assert_eq!(names(steel(soft, linear())), "hardening_modulus");
    }
}
