//! The plates' materials and the state of a cell's material point.

use crate::error::{Error, Result};
use crate::material::johnson_holmquist::{Jh2, Jh2Point};
use crate::material::rajendran_grove::{CeramicPoint, RajendranGrove};
use crate::material::tensor::Full;
use crate::material::{Material, Point, PointState};

/// The material of a plate.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Layer {
    /// The Rajendran-Grove ceramic.
    Ceramic(RajendranGrove),
    /// A material of the shared material code (metals).
    Solid(Material),
    /// The Johnson-Holmquist ceramic (JH-2), stepped at its point by
    /// [`Jh2::step`] (it keeps its own density and takes no energy).
    Jh2(Jh2),
}

impl Layer {
    /// The reference density (kg/m3).
    pub fn density(&self) -> Result<f64> {
        match self {
            Layer::Ceramic(c) => Ok(c.density),
            Layer::Jh2(j) => Ok(j.constants().density),
            Layer::Solid(m) => m.eos.reference_density().ok_or_else(|| {
                Error::Inconsistent(
                    "a plate needs an equation of state with a reference density".into(),
                )
            }),
        }
    }

    pub(super) fn validate(&self) -> Result<()> {
        match self {
            // A cell is a slab of the whole face: no point of its own to draw
            // a flaw for (the scene `plate_impact` names these `plate_`).
            Layer::Ceramic(c) if c.tensile_flaw_scatter > 0.0 => Err(Error::OutOfRange {
                name: "tensile_flaw_scatter".to_string(),
                value: c.tensile_flaw_scatter,
                range: "0 in a uniaxial layer (its cells are slabs of the whole face)".to_string(),
            }),
            Layer::Ceramic(c) => c.validate(),
            Layer::Solid(m) => m.validate(),
            Layer::Jh2(j) => j.constants().validate(),
        }
    }

    pub(super) fn initial_state(&self) -> CellState {
        match self {
            Layer::Ceramic(c) => CellState::Ceramic(c.initial_point()),
            Layer::Jh2(j) => CellState::Jh2(j.initial_point()),
            Layer::Solid(m) => CellState::Solid(
                Point {
                    deviator: [0.0; 6],
                    pressure: 0.0,
                    plastic_strain: 0.0,
                    temperature: m.reference_temperature,
                },
                PointState::default(),
            ),
        }
    }

    /// The longitudinal wave speed at density `rho` in state `s`.
    pub(super) fn wave_speed(&self, rho: f64, s: &CellState) -> f64 {
        match (self, s) {
            (Layer::Ceramic(c), CellState::Ceramic(p)) => {
                (c.longitudinal_modulus(rho, p.porosity) / rho).sqrt()
            }
            (Layer::Solid(m), CellState::Solid(p, _)) => {
                (m.longitudinal_modulus(rho, p.pressure) / rho).sqrt()
            }
            (Layer::Jh2(j), CellState::Jh2(_)) => (j.longitudinal_modulus(rho) / rho).sqrt(),
            _ => unreachable!("a cell's state matches its layer"),
        }
    }

    /// The plate's material, through which its cells are updated
    /// ([`Material::update_with_energy`]). A ceramic plate's has placeholder
    /// thermal constants (specific heat 1 J/(kg K), reference temperature
    /// 0 K, no plastic heating): its cells keep their specific internal
    /// energy, which the ceramic's update takes, and no temperature. A JH-2
    /// plate has none (`None`): its cells are stepped by [`Jh2::step`].
    pub(super) fn material(&self) -> Option<Material> {
        match self {
            Layer::Ceramic(c) => Some(Material::ceramic(*c, 1.0, 0.0, 0.0)),
            Layer::Solid(m) => Some(*m),
            Layer::Jh2(_) => None,
        }
    }

    /// The longitudinal and bulk sound speeds `(c_L, c_B)` at the
    /// reference density, at rest (m/s).
    pub fn sound_speeds(&self) -> Result<(f64, f64)> {
        let rho = self.density()?;
        let (longitudinal, shear) = match self {
            Layer::Ceramic(c) => (
                c.longitudinal_modulus(rho, c.initial_porosity),
                c.porosity_factor(c.initial_porosity) * c.shear_modulus,
            ),
            Layer::Solid(m) => (m.longitudinal_modulus(rho, 0.0), m.shear_modulus),
            Layer::Jh2(j) => (j.longitudinal_modulus(rho), j.constants().shear_modulus),
        };
        Ok((
            (longitudinal / rho).sqrt(),
            ((longitudinal - 4.0 / 3.0 * shear) / rho).sqrt(),
        ))
    }
}

/// The state of a cell's material point. A metal's [`PointState`] holds
/// only caches (no damage), so it is not saved: it comes back empty and is
/// rebuilt at the next step with the same bits.
#[derive(Debug, Clone, Copy, serde::Serialize, serde::Deserialize)]
pub(super) enum CellState {
    Ceramic(CeramicPoint),
    Solid(Point<Full>, #[serde(skip)] PointState),
    Jh2(Jh2Point),
}

impl CellState {
    /// The cell's material point and its state, as [`Material`] updates
    /// them. A ceramic cell keeps no temperature: its point's is 0 K.
    pub(super) fn point(&self) -> (Point<Full>, PointState) {
        match self {
            CellState::Ceramic(p) => (
                Point {
                    deviator: p.deviator,
                    pressure: p.pressure,
                    plastic_strain: p.plastic_strain,
                    temperature: 0.0,
                },
                PointState::with_ceramic(p.vars()),
            ),
            CellState::Solid(p, s) => (*p, *s),
            CellState::Jh2(p) => (
                Point {
                    deviator: p.deviator,
                    pressure: p.pressure,
                    plastic_strain: p.plastic_strain,
                    temperature: 0.0,
                },
                PointState::default(),
            ),
        }
    }

    /// Keeps the point and the state a step of the material left.
    pub(super) fn set(&mut self, new: Point<Full>, state: PointState) {
        match self {
            CellState::Ceramic(p) => {
                let Some(vars) = state.ceramic() else {
                    unreachable!("a ceramic point's step leaves its variables")
                };
                *p = CeramicPoint::of(vars, new.deviator, new.pressure, new.plastic_strain);
            }
            CellState::Solid(p, s) => {
                *p = new;
                *s = state;
            }
            CellState::Jh2(_) => unreachable!("a JH-2 point is stepped by its model"),
        }
    }
}
