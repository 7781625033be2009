//! The `.vtu` snapshot writer, read back with vtkio's XML reader: points in
//! the R-Z plane (axisymmetric) or in space (3-D), one vertex cell per
//! particle, and every field with its values (two-component vectors padded
//! to three, the 3-D stress with its six), bit for bit (the arrays are
//! written as binary).

use crate::common;

use meshless_impact::{Field, Scene, Simulation, Snapshot};
use std::path::Path;
use vtkio::model::{Attribute, DataSet, ElementType, VertexNumbers};

#[test]
fn snapshot_round_trips_through_the_vtk_reader() {
    let positions = vec![
        [0.0, 0.0, 0.0],
        [1.5e-3, 2.0e-4, 0.0],
        [3.0e-3, -1.25e-5, 0.0],
    ];
    let snap = Snapshot {
        time: 2.5e-6,
        positions: positions.clone(),
        fields: vec![
            Field {
                name: "density",
                components: &["rho"],
                unit: "kg/m^3",
                data: vec![7850.0, 7851.25, 7849.5],
            },
            Field {
                name: "velocity",
                components: &["U_R", "U_Z"],
                unit: "m/s",
                data: vec![0.0, -208.0, 1.5, -207.25, 3.0, -1e-9],
            },
        ],
    };
    let dir = std::env::temp_dir().join(format!("mi_vtu_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("snap.vtu");
    snap.write_vtu(&path).unwrap();

    let vtu = read_vtu(&path);
    std::fs::remove_dir_all(&dir).ok();
    // (The XML format keeps no title or time: the time goes into the `.pvd`
    // collection, tests/suite/cli.rs.)
    let expect: Vec<f64> = positions.iter().flatten().copied().collect();
    assert_eq!(vtu.points, expect);
    assert_eq!(vtu.arrays.len(), 2);
    let expect = [
        ("density", 1, vec![7850.0, 7851.25, 7849.5]),
        (
            "velocity",
            3,
            vec![0.0, -208.0, 0.0, 1.5, -207.25, 0.0, 3.0, -1e-9, 0.0],
        ),
    ];
    for (a, (name, comps, values)) in vtu.arrays.iter().zip(expect) {
        assert_eq!(a.0, name);
        assert_eq!(a.1, comps, "{name}");
        assert_eq!(a.2, values, "{name}");
    }
}

/// A `.vtu` file as read back: its points (x, y, z interleaved) and its
/// point arrays (name, components, values).
struct Vtu {
    points: Vec<f64>,
    arrays: Vec<(String, u32, Vec<f64>)>,
}

/// Reads a snapshot file with vtkio's XML reader: one piece of vertex
/// cells, one per point.
fn read_vtu(path: &Path) -> Vtu {
    let vtk = vtkio::Vtk::import(path).unwrap();
    let DataSet::UnstructuredGrid { pieces, .. } = vtk.data else {
        panic!("not an unstructured grid");
    };
    assert_eq!(pieces.len(), 1);
    let piece = pieces
        .into_iter()
        .next()
        .unwrap()
        .into_loaded_piece_data(None)
        .unwrap();
    let points: Vec<f64> = piece.points.cast_into().unwrap();
    let n = points.len() / 3;
    let VertexNumbers::XML {
        connectivity,
        offsets,
    } = piece.cells.cell_verts
    else {
        panic!("cells not in the XML layout");
    };
    assert_eq!(connectivity, (0..n as u64).collect::<Vec<_>>());
    assert_eq!(offsets, (1..=n as u64).collect::<Vec<_>>());
    assert_eq!(piece.cells.types.len(), n);
    let arrays = piece
        .data
        .point
        .into_iter()
        .map(|a| match a {
            Attribute::DataArray(a) => {
                // XML keeps only the number of components (written as
                // scalars, read back as generic arrays but for the active
                // scalars).
                let comps = match a.elem {
                    ElementType::Scalars { num_comp, .. } => num_comp,
                    ElementType::Generic(n) => n,
                    ref e => panic!("{}: element type {e:?}", a.name),
                };
                (a.name.clone(), comps, a.data.cast_into().unwrap())
            }
            other => panic!("unexpected attribute {other:?}"),
        })
        .collect();
    Vtu { points, arrays }
}

/// `meshless-impact run taylor3d` (3 nodes across, to 4 us) with `--json`,
/// `--csv` and `--vtk-dir`: each snapshot holds 3-D points and the full
/// stress (6 components), with the bits of the library's snapshot of the
/// same run at the same moment; the collection lists them with their
/// times; the JSON has every 3-D observable and the CSV the run's history,
/// bit for bit.
#[test]
fn taylor3d_snapshots_hold_3d_points_and_the_full_stress() {
    let dir = std::env::temp_dir().join(format!("mi_vtu3d_{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).unwrap();
    let sets = [("particles_radial", 3.0), ("end_time", 4e-6)];
    let sets_text: Vec<String> = sets.iter().map(|(k, v)| format!("{k}={v:e}")).collect();
    let mut args = vec!["run", "taylor3d", "-q"];
    for s in &sets_text {
        args.extend(["--set", s.as_str()]);
    }
    let common::CliOutputs { json, csv, vtk } = common::run_cli_with_outputs(&args, &dir, "2e-6");

    // The same run through the library: its snapshots at 2 us and at the end.
    let mut scene = Scene::builtin("taylor3d").unwrap();
    for (k, v) in sets {
        scene.set(k, v).unwrap();
    }
    let mut sim = Simulation::new(scene).unwrap();
    sim.advance_to(2e-6).unwrap();
    let mid = sim.snapshot();
    sim.run().unwrap();
    let end = sim.snapshot();
    let n = sim.particles();
    assert_eq!(
        common::pvd_datasets(&vtk.join("particles.pvd")),
        [
            (mid.time, "particles_0000.vtu".to_string()),
            (end.time, "particles_0001.vtu".to_string())
        ]
    );
    for (k, snap) in [mid, end].iter().enumerate() {
        let vtu = read_vtu(&vtk.join(format!("particles_{k:04}.vtu")));
        assert_eq!(vtu.points.len(), 3 * n);
        let points: Vec<f64> = snap.positions.iter().flatten().copied().collect();
        assert_eq!(bits(&vtu.points), bits(&points), "snapshot {k}");
        // Truly 3-D: nodes off the axis in x and in y, and the rod's extent
        // along z is its length.
        let coord = |c: usize| vtu.points.iter().skip(c).step_by(3);
        assert!(coord(0).any(|x| *x < -1e-3) && coord(1).any(|y| *y > 1e-3));
        let (lo, hi) = coord(2).fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), z| {
            (a.min(*z), b.max(*z))
        });
        if k == 1 {
            assert_eq!(hi - lo, sim.observable("rod_length").unwrap());
        }
        let names: Vec<&str> = vtu.arrays.iter().map(|a| a.0.as_str()).collect();
        let want: Vec<&str> = snap.fields.iter().map(|f| f.name).collect();
        assert_eq!(names, want);
        for (a, f) in vtu.arrays.iter().zip(&snap.fields) {
            assert_eq!(a.1 as usize, f.components.len(), "{}", f.name);
            assert_eq!(bits(&a.2), bits(&f.data), "{} of snapshot {k}", f.name);
        }
        let stress = vtu.arrays.iter().find(|a| a.0 == "stress").unwrap();
        assert_eq!(stress.1, 6);
        assert_eq!(stress.2.len(), 6 * n);
        let velocity = vtu.arrays.iter().find(|a| a.0 == "velocity").unwrap();
        assert_eq!(velocity.1, 3);
    }

    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    for (spec, value) in sim.observable_specs().iter().zip(sim.observables()) {
        let got = &v[spec.name];
        let got = got.as_f64().or(got.as_bool().map(f64::from)).unwrap();
        assert_eq!(got.to_bits(), value.to_bits(), "{}", spec.name);
    }
    assert_eq!(v["particles"], n);
    assert!(v.get("mushroom_radius_spread").is_some());
    let mut rows = csv::Reader::from_path(&csv).unwrap();
    let header: Vec<String> = rows.headers().unwrap().iter().map(String::from).collect();
    let h = sim.history();
    assert_eq!(header[0], "time");
    assert_eq!(header[1..], h.names);
    let values: Vec<f64> = rows
        .records()
        .flat_map(|r| {
            r.unwrap()
                .iter()
                .map(|x| x.parse::<f64>().unwrap())
                .collect::<Vec<_>>()
        })
        .collect();
    let want: Vec<f64> = (0..h.len())
        .flat_map(|k| std::iter::once(h.times[k]).chain(h.row(k).iter().copied()))
        .collect();
    assert_eq!(bits(&values), bits(&want));
    std::fs::remove_dir_all(&dir).ok();
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}
