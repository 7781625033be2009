//! What a plate-impact run reports: its observables and its fields, one
//! value per cell.

use super::PlateImpact;
use super::layer::{CellState, Layer};
use crate::observe::{FieldSpec, LOG10_NO_CRACKS};

/// The fields of a plate-impact run, one value per cell (a material point
/// at the cell's centre), flyer cells first.
pub const PLATE_IMPACT_FIELDS: &[FieldSpec] = &[
    FieldSpec {
        name: "position",
        unit: "m",
        components: &["x"],
    },
    FieldSpec {
        name: "velocity",
        unit: "m/s",
        components: &["v"],
    },
    FieldSpec {
        name: "density",
        unit: "kg/m3",
        components: &["rho"],
    },
    FieldSpec {
        name: "stress",
        unit: "Pa",
        components: &["sigma_xx"],
    },
    FieldSpec {
        name: "pressure",
        unit: "Pa",
        components: &["P"],
    },
    FieldSpec {
        name: "plastic_strain",
        unit: "1",
        components: &["eps_p"],
    },
    FieldSpec {
        name: "crack_size",
        unit: "m",
        components: &["a"],
    },
    FieldSpec {
        name: "log10_crack_density",
        unit: "1",
        components: &["log10_gamma"],
    },
    FieldSpec {
        name: "porosity",
        unit: "1",
        components: &["f"],
    },
    FieldSpec {
        name: "pulverized",
        unit: "bool",
        components: &["pulverized"],
    },
];

/// How far (a fraction of the impact speed) the first pulse's peak may pass
/// its precursor and still count as elastic for the spall reading: the
/// ringing behind an elastic front, about 1.5 % (`FreeSurfaceReading`'s
/// slack). Measured on AD85 below its HEL: the peak passes the precursor by
/// at most 0.4 % (5 µm cells); above it, by 11 % (500 m/s) and 7.5 %
/// (1000 m/s, rate-independent).
const ELASTIC_PULSE_SLACK: f64 = 0.015;

impl PlateImpact {
    /// Cells (the material points).
    pub fn particles(&self) -> usize {
        self.state.cells.len()
    }

    /// The observables of [`crate::observe::PLATE_IMPACT_OBSERVABLES`], in
    /// order.
    pub fn observables(&self) -> Vec<f64> {
        let target = self.setup.layers[1];
        let rho0 = target.density().unwrap_or(f64::NAN);
        let (c_l, c_b) = target.sound_speeds().unwrap_or((f64::NAN, f64::NAN));
        let r = self.state.reading;
        let precursor = r.precursor.unwrap_or(0.0);
        let pullback = r.peak - r.pullback_minimum;
        // The release that carries the pullback back to the free surface
        // runs at c_L where the whole pulse came in the elastic precursor
        // (a target struck below its HEL: ρ0 c_L du is the stress of an
        // elastic wave in uniaxial strain), and at the bulk speed c_B
        // behind a plastic wave (Novikov's reading for metals). The peak
        // may pass the precursor by the ringing behind the front
        // (`ELASTIC_PULSE_SLACK`).
        let slack = ELASTIC_PULSE_SLACK * self.setup.impact_speed.abs();
        let elastic = r.precursor.is_some_and(|u| u >= r.peak - slack);
        let c_release = if elastic { c_l } else { c_b };
        let spall_strength = if self.state.spall.is_some() {
            0.5 * rho0 * c_release * pullback
        } else {
            0.0
        };
        let max_damage = match &self.setup.layers[1] {
            Layer::Ceramic(m) => self
                .target_ceramic()
                .iter()
                .map(|p| p.vars().crack_density(m))
                .fold(0.0, f64::max),
            // JH-2: its damage D in place of the crack density.
            Layer::Jh2(_) => self.state.cells[self.setup.flyer_cells..]
                .iter()
                .map(|s| match s {
                    CellState::Jh2(p) => p.damage,
                    _ => 0.0,
                })
                .fold(0.0, f64::max),
            Layer::Solid(_) => 0.0,
        };
        let [kinetic, internal, contact] = self.energies();
        vec![
            self.free_surface_velocity(),
            precursor,
            0.5 * rho0 * c_l * precursor,
            r.peak,
            pullback,
            spall_strength,
            self.state.spall.map_or(0.0, |s| s.0),
            max_damage,
            kinetic,
            internal,
            contact,
            self.energy_error(),
        ]
    }

    /// The values of the field `name` ([`PLATE_IMPACT_FIELDS`]), one per
    /// cell, or `None` for another name.
    pub fn field(&self, name: &str) -> Option<Vec<f64>> {
        let cells = 0..self.state.cells.len();
        let ceramic = |c: usize| match (&self.state.cells[c], self.layer(c)) {
            (CellState::Ceramic(p), Layer::Ceramic(m)) => Some((p, m)),
            _ => None,
        };
        // A JH-2 cell's damage D, which it reports in place of the crack
        // density (log10 D) and, fully fractured (D = 1), as pulverized.
        let jh2_damage = |c: usize| match &self.state.cells[c] {
            CellState::Jh2(p) => Some(p.damage),
            _ => None,
        };
        let values: Vec<f64> = match name {
            "position" => cells
                .map(|c| {
                    let (a, b) = self.nodes(c);
                    0.5 * (self.state.x[a] + self.state.x[b])
                })
                .collect(),
            "velocity" => cells
                .map(|c| {
                    let (a, b) = self.nodes(c);
                    0.5 * (self.state.v[a] + self.state.v[b])
                })
                .collect(),
            "density" => cells
                .map(|c| {
                    let (a, b) = self.nodes(c);
                    self.setup.density0[c] * self.setup.length0[c]
                        / (self.state.x[b] - self.state.x[a])
                })
                .collect(),
            "stress" => self.state.stress.clone(),
            "pressure" => self
                .state
                .cells
                .iter()
                .map(|s| match s {
                    CellState::Ceramic(p) => p.pressure,
                    CellState::Solid(p, _) => p.pressure,
                    CellState::Jh2(p) => p.pressure,
                })
                .collect(),
            "plastic_strain" => self
                .state
                .cells
                .iter()
                .map(|s| match s {
                    CellState::Ceramic(p) => p.plastic_strain,
                    CellState::Solid(p, _) => p.plastic_strain,
                    CellState::Jh2(p) => p.plastic_strain,
                })
                .collect(),
            "crack_size" => cells
                .map(|c| ceramic(c).map_or(0.0, |(p, _)| p.crack_size))
                .collect(),
            "log10_crack_density" => cells
                .map(|c| {
                    if let Some(d) = jh2_damage(c) {
                        return d.log10().max(LOG10_NO_CRACKS);
                    }
                    ceramic(c).map_or(LOG10_NO_CRACKS, |(p, m)| {
                        p.vars().crack_density(m).log10().max(LOG10_NO_CRACKS)
                    })
                })
                .collect(),
            "porosity" => cells
                .map(|c| ceramic(c).map_or(0.0, |(p, _)| p.porosity))
                .collect(),
            "pulverized" => cells
                .map(|c| {
                    if let Some(d) = jh2_damage(c) {
                        return f64::from(u8::from(d >= 1.0));
                    }
                    ceramic(c).map_or(0.0, |(p, _)| f64::from(u8::from(p.pulverized.is_some())))
                })
                .collect(),
            _ => return None,
        };
        Some(values)
    }
}
