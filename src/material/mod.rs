//! Material models, one per file, composed into a [`Material`]: an
//! equation of state ([`Eos`]), a strength model ([`Strength`]) and a
//! damage model ([`Damage`]), with the elastic and thermal constants. They
//! work over the symmetric tensors of [`tensor`], in the axisymmetric
//! (4-component) and the 3-D (6-component) form alike.
//!
//! A solver keeps a [`MaterialState`] next to its material (per-particle
//! state of the models: today the Johnson-Cook memo, later damage
//! variables) and calls [`Material::update`] once per particle and step.
//!
//! A scene chooses the models by name ([`choice`]: `strength =
//! "johnson_cook" | "bilinear"`, `eos = "linear" | "mie_gruneisen"`) or
//! takes a named material ([`presets`]); its parameter table then lists only
//! what the chosen models use, alone or under a body's prefix.

pub mod bilinear;
pub mod choice;
pub mod eos;
pub mod ideal_gas;
pub mod johnson_cook;
pub mod mie_gruneisen;
pub mod presets;
pub mod rajendran_grove;
pub mod tensor;

use crate::error::Result;
use crate::scene::params::Range;
use bilinear::Bilinear;
use eos::LinearEos;
use ideal_gas::IdealGas;
use johnson_cook::JohnsonCook;
use mie_gruneisen::{CompressionLimit, MieGruneisen, check};
use tensor::{SymTensor, radial_return};

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

/// Damage model: acts on a particle's state after the strength model and
/// the equation of state, with what a damage law needs (pressure, stress,
/// strain rate, plastic strain and its increment, time step).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Damage {
    /// No damage: the state is left as it is.
    None,
}

impl Damage {
    /// Applies the damage law to the particle state `point` (in place),
    /// after a step of `load` that added `plastic_increment` to its plastic
    /// strain; the damage variables live in `state`.
    #[inline]
    pub(crate) fn apply<T: SymTensor>(
        &self,
        load: &Loading<T>,
        plastic_increment: f64,
        point: &mut Point<T>,
        state: &mut PointState,
    ) {
        let _ = (load, plastic_increment, point, state);
        match self {
            Damage::None => {}
        }
    }
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
}

/// The mechanical state of a particle that a material updates.
#[derive(Debug, Clone, Copy, PartialEq)]
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

/// Per-particle state of the models, kept from step to step.
#[derive(Debug, Clone, Copy)]
pub struct PointState {
    /// Johnson-Cook hardening and thermal factors with the plastic strain
    /// and temperature they were computed for: reused while both stay the
    /// same (a particle that does not yield), which spares two `powf` and
    /// gives the same bits.
    memo: Memo,
}

#[derive(Debug, Clone, Copy)]
struct Memo {
    eps_p: f64,
    temp: f64,
    hardening: f64,
    thermal: f64,
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
        }
    }
}

/// Per-particle state of a material's models, owned next to the material.
/// It holds caches only today (rebuilt after a restore); damage variables
/// will join it.
#[derive(Debug, Clone, Default)]
pub struct MaterialState {
    points: Vec<PointState>,
}

impl MaterialState {
    /// Sizes the state for `n` particles (new ones start empty).
    pub fn fit(&mut self, n: usize) {
        self.points.resize(n, PointState::default());
    }

    /// The particles' states, to be cut into chunks.
    pub fn points_mut(&mut self) -> &mut [PointState] {
        &mut self.points
    }
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
        Ok(())
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
    #[inline]
    pub fn longitudinal_modulus(&self, rho: f64, p: f64) -> f64 {
        self.eos.bulk_modulus(rho, p) + 4.0 / 3.0 * self.shear_modulus
    }

    /// One step of a particle: the Jaumann-rate trial deviator, the J2
    /// radial return on the strength model's flow stress, heating by the
    /// Taylor-Quinney fraction of the plastic work, the pressure at the new
    /// density and temperature, then the damage model. Returns the new
    /// state, or the compression limit of the equation of state.
    #[inline]
    pub(crate) fn update<T: SymTensor>(
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
        let mut new = Point {
            deviator: ret.stress,
            pressure: self.pressure(load.density, temperature)?,
            plastic_strain: old.plastic_strain + ret.plastic_strain,
            temperature,
        };
        self.damage.apply(load, ret.plastic_strain, &mut new, state);
        Ok(new)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tensor::{Axisymmetric, Full};

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
        };
        let full = Loading::<Full> {
            dt: axi.dt,
            rate: [2e4, -5e4, 2e4, 1e4, 0.0, 0.0],
            spin: [3e3, 0.0, 0.0],
            density: axi.density,
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
        };
        let old = unloaded([0.0; 4], 0.0);
        let err = m.update(&load, &old, &mut PointState::default());
        assert!(err.is_err(), "{err:?}");
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
