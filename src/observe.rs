//! Observables (names, units, meanings), their time histories, particle
//! snapshots, and the writers for CSV, JSON and VTK (`.vtu` snapshots and
//! the `.pvd` collection that gives ParaView their times).

use crate::error::{Error, Result};
use std::path::Path;

/// One observable: a time history and a final value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObservableSpec {
    /// Name used by every interface.
    pub name: &'static str,
    /// SI unit ("1" for dimensionless, "bool" for flags stored as 0/1).
    pub unit: &'static str,
    /// Meaning.
    pub description: &'static str,
}

impl ObservableSpec {
    /// Whether the value is a flag (0 or 1).
    pub fn is_bool(&self) -> bool {
        self.unit == "bool"
    }
}

macro_rules! observables {
    ($table:ident, $doc:literal, $( $name:ident : $unit:literal, $desc:literal; )*) => {
        #[doc = $doc]
        pub const $table: &[ObservableSpec] = &[
            $( ObservableSpec { name: stringify!($name), unit: $unit, description: $desc }, )*
        ];
    };
}

observables! {
    TAYLOR_OBSERVABLES, "Observables of the Taylor scene, in output order.",
    rod_length: "m", "current length of the rod (highest minus lowest material point)";
    mushroom_radius: "m", "largest R among particles that started on the impact face";
    undeformed_length: "m", "length of the contiguous part from the free end where R/R0 - 1 < 0.2%";
    tail_velocity: "m/s", "axial velocity of the centre of the free end, positive toward the anvil";
    face_lift: "m", "axial gap between the centre of the impact face and the anvil";
    max_plastic_strain: "1", "largest effective plastic strain";
    max_temperature: "K", "highest temperature";
    kinetic_energy: "J", "kinetic energy of the rod";
    internal_energy: "J", "stress work stored and dissipated in the material (elastic plus plastic)";
    smoothing_dissipation: "J", "kinetic energy removed by the conservative smoothing of velocity";
    contact_dissipation: "J", "kinetic energy removed by the rigid anvil when it stops particles";
    energy_error: "1", "|kinetic + internal + dissipated - initial| / initial";
    at_rest: "bool", "the rod has stopped: the end condition of a run";
}

observables! {
    TAYLOR3D_OBSERVABLES, "Observables of the 3-D Taylor scene (MLPG), in output order: those of the Taylor scene, then its own.",
    rod_length: "m", "current length of the rod (highest minus lowest material point)";
    mushroom_radius: "m", "largest distance from the axis among nodes that started on the impact face";
    undeformed_length: "m", "length of the contiguous part from the free end where R/R0 - 1 < 0.2%";
    tail_velocity: "m/s", "axial velocity of the centre of the free end, positive toward the anvil";
    face_lift: "m", "axial gap between the centre of the impact face and the anvil";
    max_plastic_strain: "1", "largest effective plastic strain";
    max_temperature: "K", "highest temperature";
    kinetic_energy: "J", "kinetic energy of the rod";
    internal_energy: "J", "stress work stored and dissipated in the material (elastic plus plastic)";
    smoothing_dissipation: "J", "kinetic energy removed by the velocity smoothing toward the MLS approximation (smoothing_coefficient)";
    contact_dissipation: "J", "kinetic energy removed by the rigid anvil when it stops nodes";
    energy_error: "1", "|kinetic + internal + dissipated - initial| / initial";
    at_rest: "bool", "the rod has stopped or left the anvil: the end condition of a run";
    mushroom_radius_spread: "1", "(max - min) / mean of the distance from the axis of the impact face's outer ring";
    damping_dissipation: "J", "work of the viscous stress of the stiffness-proportional damping";
    plastic_work: "J", "plastic part of the internal energy (flow stress times plastic strain increment)";
}

observables! {
    NOH_OBSERVABLES, "Observables of the Noh scene, in output order.",
    shock_radius: "1", "outermost radius where the density reaches the mean of the exact pre- and post-shock values";
    post_shock_density: "1", "mean density over 0.1 <= r <= 0.18";
    pre_shock_density_l1: "1", "mean relative error of the density against 1 + t/r over 0.25 <= r <= 0.9";
    density_l1: "1", "mean relative density error against the exact solution over all particles with r >= 0.05";
    kinetic_energy: "1", "kinetic energy per unit length of the gas column";
    internal_energy: "1", "internal energy per unit length (smoothing heat included)";
    energy_error: "1", "|kinetic + internal - initial| / initial";
}

/// Time histories of a scene's observables: one row per recorded time.
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct History {
    /// Observable names (columns after time).
    pub names: Vec<String>,
    /// Recorded times.
    pub times: Vec<f64>,
    /// Row-major values, `times.len() * names.len()`.
    pub values: Vec<f64>,
}

impl History {
    /// A history saved before some of the scene's observables existed
    /// (those added after the others, at the end of the list): when its
    /// names are the first of `specs`' names, the later ones are added as
    /// columns that read 0 in every record so far (they were not recorded
    /// then; the records after a restart hold their values). Returns the
    /// names added; a history of other names is left as it is (and refused
    /// by the check of a restored run).
    pub(crate) fn adopt_later_observables(&mut self, specs: &[ObservableSpec]) -> Vec<String> {
        let (had, now) = (self.names.len(), specs.len());
        if had >= now
            || specs[..had]
                .iter()
                .zip(&self.names)
                .any(|(s, n)| s.name != n)
        {
            return Vec::new();
        }
        let rows = self.times.len();
        if self.values.len() != rows * had {
            return Vec::new();
        }
        let mut values = Vec::with_capacity(rows * now);
        for r in 0..rows {
            values.extend_from_slice(&self.values[r * had..(r + 1) * had]);
            values.extend(std::iter::repeat_n(0.0, now - had));
        }
        self.values = values;
        let added: Vec<String> = specs[had..].iter().map(|s| s.name.to_string()).collect();
        self.names.extend(added.iter().cloned());
        added
    }

    /// An empty history for these observables.
    pub fn new(specs: &[ObservableSpec]) -> Self {
        History {
            names: specs.iter().map(|s| s.name.to_string()).collect(),
            times: Vec::new(),
            values: Vec::new(),
        }
    }

    /// Appends a row.
    pub fn push(&mut self, time: f64, row: &[f64]) {
        debug_assert_eq!(row.len(), self.names.len());
        self.times.push(time);
        self.values.extend_from_slice(row);
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.times.len()
    }

    /// True when nothing was recorded.
    pub fn is_empty(&self) -> bool {
        self.times.is_empty()
    }

    /// The `k`-th row.
    pub fn row(&self, k: usize) -> &[f64] {
        let n = self.names.len();
        &self.values[k * n..(k + 1) * n]
    }

    /// The column of the observable `name`, if it exists.
    pub fn column(&self, name: &str) -> Option<Vec<f64>> {
        let c = self.names.iter().position(|n| *n == name)?;
        Some((0..self.len()).map(|k| self.row(k)[c]).collect())
    }

    /// Writes the history as CSV with a header `time,<names...>`, whole
    /// ([`crate::files::write_whole`]).
    pub fn write_csv(&self, path: &Path) -> Result<()> {
        crate::files::write_whole(path, |out| {
            let mut w = csv::Writer::from_writer(out);
            let mut header = vec!["time"];
            header.extend(self.names.iter().map(String::as_str));
            w.write_record(&header)?;
            for k in 0..self.len() {
                let mut rec = vec![format!("{:e}", self.times[k])];
                rec.extend(self.row(k).iter().map(|v| format!("{v:e}")));
                w.write_record(&rec)?;
            }
            w.flush()
        })
    }
}

/// Name, unit and components of a particle field.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FieldSpec {
    /// Field name (for example `stress`); the first field of every scene is
    /// `position`.
    pub name: &'static str,
    /// Unit.
    pub unit: &'static str,
    /// Names of the components, in storage order.
    pub components: &'static [&'static str],
}

/// A rod solver's field table: position, density and velocity with the
/// coordinates `axes`, pressure, stress with the components `stress`,
/// plastic strain, temperature and the contact flag.
pub(crate) const fn rod_fields(
    axes: &'static [&'static str],
    stress: &'static [&'static str],
) -> [FieldSpec; 8] {
    [
        FieldSpec {
            name: "position",
            unit: "m",
            components: axes,
        },
        FieldSpec {
            name: "density",
            unit: "kg/m3",
            components: &["rho"],
        },
        FieldSpec {
            name: "velocity",
            unit: "m/s",
            components: axes,
        },
        FieldSpec {
            name: "pressure",
            unit: "Pa",
            components: &["P"],
        },
        FieldSpec {
            name: "stress",
            unit: "Pa",
            components: stress,
        },
        FieldSpec {
            name: "plastic_strain",
            unit: "1",
            components: &["eps_p"],
        },
        FieldSpec {
            name: "temperature",
            unit: "K",
            components: &["T"],
        },
        FieldSpec {
            name: "in_contact",
            unit: "bool",
            components: &["contact"],
        },
    ]
}

/// One named particle field of a snapshot.
#[derive(Debug, Clone, PartialEq)]
pub struct Field {
    /// Field name (for example `stress`).
    pub name: &'static str,
    /// Names of the components, in storage order.
    pub components: &'static [&'static str],
    /// Unit.
    pub unit: &'static str,
    /// Interleaved values, `particles * components.len()`.
    pub data: Vec<f64>,
}

/// Particle positions and fields at one time.
#[derive(Debug, Clone, PartialEq)]
pub struct Snapshot {
    /// Simulated time.
    pub time: f64,
    /// Particle positions as points in space, as the VTK files hold them:
    /// (x, y, z) in 3-D (z along the rod axis, the anvil at z = 0), (R, Z, 0)
    /// in the axisymmetric scenes (x = R, y = Z), (R, 0, 0) in Noh.
    pub positions: Vec<[f64; 3]>,
    /// Fields; which ones depends on the scene.
    pub fields: Vec<Field>,
}

impl Snapshot {
    /// The field called `name`.
    pub fn field(&self, name: &str) -> Option<&Field> {
        self.fields.iter().find(|f| f.name == name)
    }

    /// Writes the snapshot as a VTK XML unstructured grid (`.vtu`) of vertex
    /// cells at [`Snapshot::positions`] (in the axisymmetric scenes the R-Z
    /// plane, x = R, y = Z), readable by ParaView. Two-component vectors
    /// are padded to three; every other field keeps its components (the
    /// 3-D stress its six). The file holds no time: list it in a
    /// [`write_pvd`] collection for that.
    pub fn write_vtu(&self, path: &Path) -> Result<()> {
        use vtkio::model::*;
        let n = self.positions.len();
        let points: Vec<f64> = self.positions.iter().flatten().copied().collect();
        let mut point_data = Vec::new();
        for f in &self.fields {
            let nc = f.components.len();
            let (num_comp, data): (u32, Vec<f64>) = if nc == 2 {
                (
                    3,
                    f.data.chunks(2).flat_map(|c| [c[0], c[1], 0.0]).collect(),
                )
            } else {
                (nc as u32, f.data.clone())
            };
            point_data.push(Attribute::DataArray(DataArray {
                name: f.name.to_string(),
                elem: ElementType::Scalars {
                    num_comp,
                    lookup_table: None,
                },
                data: data.into(),
            }));
        }
        let vtk = Vtk {
            version: Version::new_xml(1, 0),
            // Kept by the legacy format only: the XML file has no title, and
            // the snapshot's time goes into the `.pvd` collection
            // ([`write_pvd`]).
            title: format!("meshless-impact t = {:e} s", self.time),
            byte_order: ByteOrder::LittleEndian,
            file_path: None,
            data: DataSet::inline(UnstructuredGridPiece {
                points: points.into(),
                cells: Cells {
                    cell_verts: VertexNumbers::XML {
                        connectivity: (0..n as u64).collect(),
                        offsets: (1..=n as u64).collect(),
                    },
                    types: vec![CellType::Vertex; n],
                },
                data: Attributes {
                    point: point_data,
                    cell: vec![],
                },
            }),
        };
        crate::files::write_whole(path, |w| {
            vtk.write_xml(w)
                .map_err(|e| std::io::Error::other(format!("{e:?}")))
        })
    }
}

impl Snapshot {
    /// The particles `rows` of this snapshot (one rank's piece of a run on
    /// several, [`crate::ranks::share`]): their positions and every field's
    /// values.
    pub fn piece(&self, rows: std::ops::Range<usize>) -> Snapshot {
        Snapshot {
            time: self.time,
            positions: self.positions[rows.clone()].to_vec(),
            fields: self
                .fields
                .iter()
                .map(|f| {
                    let k = f.components.len();
                    Field {
                        data: f.data[rows.start * k..rows.end * k].to_vec(),
                        ..f.clone()
                    }
                })
                .collect(),
        }
    }

    /// Writes the parallel file (`.pvtu`) that joins `pieces`, the `.vtu`
    /// files of this snapshot's pieces ([`Snapshot::piece`],
    /// [`Snapshot::write_vtu`]) named relative to it: ParaView opens it as
    /// one data set. It declares the points and this snapshot's fields as
    /// the pieces hold them (64-bit floats; two components padded to three).
    pub fn write_pvtu(&self, path: &Path, pieces: &[String]) -> Result<()> {
        use quick_xml::Writer;
        let array = |w: &mut Writer<Vec<u8>>, name: Option<&str>, comps: usize| {
            let comps = comps.to_string();
            let mut e = w
                .create_element("PDataArray")
                .with_attributes([("type", "Float64"), ("NumberOfComponents", comps.as_str())]);
            if let Some(name) = name {
                e = e.with_attribute(("Name", name));
            }
            e.write_empty().map(drop)
        };
        write_xml(path, |w| {
            w.create_element("VTKFile")
                .with_attributes([
                    ("type", "PUnstructuredGrid"),
                    ("version", "1.0"),
                    ("byte_order", "LittleEndian"),
                    ("header_type", "UInt64"),
                ])
                .write_inner_content(|w| {
                    w.create_element("PUnstructuredGrid")
                        .with_attribute(("GhostLevel", "0"))
                        .write_inner_content(|w| {
                            w.create_element("PPointData").write_inner_content(|w| {
                                for f in &self.fields {
                                    let k = f.components.len();
                                    array(w, Some(f.name), if k == 2 { 3 } else { k })?;
                                }
                                Ok::<_, quick_xml::Error>(())
                            })?;
                            w.create_element("PPoints")
                                .write_inner_content(|w| array(w, None, 3))?;
                            for piece in pieces {
                                w.create_element("Piece")
                                    .with_attribute(("Source", piece.as_str()))
                                    .write_empty()?;
                            }
                            Ok::<_, quick_xml::Error>(())
                        })
                        .map(drop)
                })
                .map(drop)
        })
    }
}

/// Writes the XML file `path`: the declaration, then what `body` writes
/// (indented by two), then a final newline, whole.
fn write_xml(
    path: &Path,
    body: impl FnOnce(&mut quick_xml::Writer<Vec<u8>>) -> std::result::Result<(), quick_xml::Error>,
) -> Result<()> {
    use quick_xml::events::{BytesDecl, Event};
    let mut w = quick_xml::Writer::new_with_indent(Vec::new(), b' ', 2);
    w.write_event(Event::Decl(BytesDecl::new("1.0", None, None)))
        .and_then(|()| body(&mut w))
        .map_err(|e| Error::io(path, e))?;
    let mut bytes = w.into_inner();
    bytes.push(b'\n');
    crate::files::write_whole_bytes(path, &bytes)
}

/// Writes a ParaView collection (`.pvd`) of snapshot files with their
/// times: `snapshots` holds (time in s, file name relative to the `.pvd`).
/// The `.vtu` format has no place for the time of a snapshot, so ParaView
/// takes it from here (open the `.pvd` to step through the run in time).
pub fn write_pvd(path: &Path, snapshots: &[(f64, String)]) -> Result<()> {
    write_xml(path, |w| {
        w.create_element("VTKFile")
            .with_attributes([
                ("type", "Collection"),
                ("version", "0.1"),
                ("byte_order", "LittleEndian"),
            ])
            .write_inner_content(|w| {
                w.create_element("Collection")
                    .write_inner_content(|w| {
                        for (time, file) in snapshots {
                            w.create_element("DataSet")
                                .with_attributes([
                                    ("timestep", format!("{time:e}").as_str()),
                                    ("part", "0"),
                                    ("file", file.as_str()),
                                ])
                                .write_empty()?;
                        }
                        Ok::<_, quick_xml::Error>(())
                    })
                    .map(drop)
            })
            .map(drop)
    })
}

observables! {
    PENETRATION_OBSERVABLES, "Observables of the penetration scene (a projectile through a plate, 3-D MLPG), in output order.",
    projectile_velocity: "m/s", "axial velocity of the projectile's centre of mass, positive in its direction of flight; its final value is the residual velocity";
    projectile_extent: "m", "extent of the projectile along the axis (highest minus lowest node): its current length (the parameter `projectile_length` is its initial length)";
    projectile_clearance: "m", "depth of the projectile's highest node below the plate's original back face (z = -plate_thickness): positive once the whole projectile has passed it, negative while any of it is above";
    hole_radius: "m", "radius of the channel about the axis free of intact (not pulverized) plate material within the plate's original thickness: the distance from the axis of the nearest such plate node (0, to round-off, before the plate is pierced)";
    damaged_fraction: "1", "mass fraction of the plate whose crack density has grown past 1% of its value at pulverization and past twice its initial value";
    pulverized_fraction: "1", "mass fraction of the plate that is pulverized";
    max_damage: "1", "largest crack density gamma = N0* a^3 in the plate";
    kinetic_energy: "J", "kinetic energy of both bodies";
    internal_energy: "J", "stress work stored and dissipated in both bodies' materials";
    contact_dissipation: "J", "kinetic energy removed by the contact between the bodies (perfectly inelastic along the line of centres)";
    smoothing_dissipation: "J", "kinetic energy removed by the velocity smoothing toward the MLS approximation";
    energy_error: "1", "|kinetic + internal + dissipated - initial| / initial";
    shot_outcome: "1", "what the shot has come to, decided by the state (README, \"Ballistic limit\"): 0 undecided, 1 perforated (the projectile wholly past the plate's original back face and faster along the flight than the intact plate around the hole), 2 stopped (not perforated, and no faster than the plate's centre of mass)";
    cone_half_angle: "deg", "half-angle from the axis of the plate's fracture cone: in each layer of nodes through the thickness (at the material's place at impact), the outer radius of the rings about the axis in which at least half the nodes are damaged (as damaged_fraction counts them), fitted as a straight line of the depth from the struck to the rear face; 0 with fewer than two layers damaged or a front at one radius through the thickness (a cylinder, a plate damaged to its rim); negative for a crater, wider at the struck face (methods/penetration.md, \"Failure modes\")";
    radial_crack_count: "1", "radial cracks on the plate's rear face: in the ring of one node spacing either side of radial_crack_radius from the axis (by default the projectile's diameter), sectors of about one spacing of arc (at least 16, the quarter model mirrored into the whole plate) are cracked when at least half their nodes are damaged; the count of runs of cracked sectors around the circle, 0 when none or all are (a damaged ring is no radial crack)";
    comminuted_radius: "m", "radius of the comminuted zone under the projectile: the outer radius of the rings about the axis (at the material's place at impact, over the whole thickness) in which at least half the plate nodes are comminuted (pulverized, or split on all three tensile crack planes); 0 when the ring at the axis is not";
}

/// The log10 crack-density field's value where there are no cracks (a
/// metal, a projectile), and its floor.
pub const LOG10_NO_CRACKS: f64 = -12.0;

observables! {
    PLATE_IMPACT_OBSERVABLES, "Observables of the plate-impact scene (a flyer on a target in uniaxial strain), in output order; stresses and energies per unit area of the plates.",
    free_surface_velocity: "m/s", "velocity of the target's free (back) surface, positive along the flight";
    precursor_velocity: "m/s", "the free surface's velocity at its first local maximum after the first wave arrived (0 before): the elastic precursor, or the whole elastic pulse under the HEL";
    precursor_stress: "Pa", "rho0 c_L u / 2 of the precursor with the target's reference density and longitudinal sound speed: the Hugoniot elastic limit when the impact passes it";
    peak_velocity: "m/s", "the peak of the first pulse: the highest free-surface velocity before it first fell by 5 % of impact_speed";
    pullback_velocity: "m/s", "the peak less the lowest velocity after it, until the velocity rose again by 5 % of impact_speed (the spall signal or the next pulse): the pullback";
    spall_strength: "Pa", "rho0 c du / 2 of the pullback du, with c the target's longitudinal sound speed c_L where the whole pulse came in the elastic precursor (the peak within 1.5 % of impact_speed of it: a target struck below its HEL) and its bulk sound speed c_B behind a plastic wave, once a target cell has failed in tension (0 before, and in a target that has not)";
    spall_depth: "m", "depth below the target's impact face (reference configuration) of the first target cell that failed in tension: a ceramic pulverized in expansion, or a JH-2 cell pulled below the tensile limit of its damage (0 while none has)";
    max_damage: "1", "largest crack density gamma = N0* a^3 in the target (for a JH-2 target its largest damage D; 0 for a metal target)";
    kinetic_energy: "J/m2", "kinetic energy of both plates per unit area";
    internal_energy: "J/m2", "stress work stored and dissipated in both plates per unit area";
    contact_dissipation: "J/m2", "kinetic energy lost in the inelastic meeting of the contact nodes, per unit area";
    energy_error: "1", "|kinetic + internal + dissipated - initial| / initial";
}
