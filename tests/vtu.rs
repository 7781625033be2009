//! The `.vtu` snapshot writer, read back with vtkio's XML reader: points in
//! the R-Z plane, one vertex cell per particle, and every field with its
//! values (two-component vectors padded to three), bit for bit (the arrays
//! are written as binary).

use meshless_impact::observe::{Field, Snapshot};
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

    let vtk = vtkio::Vtk::import(&path).unwrap();
    std::fs::remove_dir_all(&dir).ok();
    // (The XML format keeps no title or time: the time goes into the `.pvd`
    // collection, tests/cli.rs.)
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
    let expect: Vec<f64> = positions.iter().flatten().copied().collect();
    assert_eq!(points, expect);
    let VertexNumbers::XML {
        connectivity,
        offsets,
    } = piece.cells.cell_verts
    else {
        panic!("cells not in the XML layout");
    };
    assert_eq!(connectivity, vec![0, 1, 2]);
    assert_eq!(offsets, vec![1, 2, 3]);
    assert_eq!(piece.cells.types.len(), 3);

    let arrays: Vec<_> = piece
        .data
        .point
        .into_iter()
        .map(|a| match a {
            Attribute::DataArray(a) => a,
            other => panic!("unexpected attribute {other:?}"),
        })
        .collect();
    assert_eq!(arrays.len(), 2);
    let expect = [
        ("density", 1, vec![7850.0, 7851.25, 7849.5]),
        (
            "velocity",
            3,
            vec![0.0, -208.0, 0.0, 1.5, -207.25, 0.0, 3.0, -1e-9, 0.0],
        ),
    ];
    for (a, (name, comps, values)) in arrays.iter().zip(expect) {
        assert_eq!(a.name, name);
        // XML keeps only the number of components (written as scalars,
        // read back as generic arrays but for the active scalars).
        let n = match a.elem {
            ElementType::Scalars { num_comp, .. } => num_comp,
            ElementType::Generic(n) => n,
            ref e => panic!("{name}: element type {e:?}"),
        };
        assert_eq!(n, comps, "{name}");
        let got: Vec<f64> = a.data.cast_into().unwrap();
        assert_eq!(got, values, "{name}");
    }
}
