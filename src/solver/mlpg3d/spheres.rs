//! The test spheres of the deformed free boundary (module docs of
//! [`super`]): Nanson's normals of the boundary nodes, the cut planes, and
//! the interior nodes' radii shrunk to the tangent planes.

use super::util::extended;
use super::util::norm;
use crate::approx::lattice::Surfaces;
use crate::approx::mirror;
use crate::approx::mirror::Mirror;
use crate::approx::mls::NodalShapes;
use crate::approx::mls::Supports;
use crate::approx::mls::distance;
use crate::approx::sphere::ALPHA;
use crate::approx::sphere::TestSphere;
use crate::approx::sphere::test_radii;
use crate::solver::mlpg3d::Setup3d;
use crate::solver::mlpg3d::State3d;
use rayon::iter::IntoParallelIterator;
use rayon::iter::ParallelIterator;
/// The test spheres of the real nodes at the points `pts` (the real
/// nodes, then the images of `mirror`; see the module docs: the deformed
/// free boundary), from the lattice's surfaces (`setup`) and the state's
/// record of the last build (its reference places and contact flags).
pub(super) fn spheres(
    setup: &Setup3d,
    state: &State3d,
    pts: &[[f64; 3]],
    mirror: &Mirror,
    sup: &Supports,
    shapes: &NodalShapes,
) -> Vec<TestSphere> {
    let n = state.pos.len();
    // F⁻¹ = ∂X/∂x at every node.
    let mut finv = vec![[[0.0; 3]; 3]; n];
    let mut buf = Vec::new();
    let reference_ext = extended(mirror, &state.built_reference, &mut buf, mirror::vector);
    shapes.velocity_gradients(reference_ext, &mut finv);
    let surf = &setup.lattice.surfaces;
    let contact = &state.built_contact;
    let reference = &state.built_reference;
    // Current outward normals of the boundary planes through each node:
    // (mantle, face or top), zero when absent.
    let normals: Vec<[[f64; 3]; 2]> = (0..n)
        .into_par_iter()
        .map(|i| {
            let s = surf[i];
            let nanson = |big: [f64; 3]| nanson(&finv[i], big);
            let mut out = [[0.0; 3]; 2];
            if s.has(Surfaces::MANTLE) {
                out[0] = nanson(radial(reference[i]));
            }
            if s.has(Surfaces::FACE) {
                out[1] = if contact[i] {
                    [0.0, 0.0, -1.0]
                } else {
                    nanson([0.0, 0.0, -1.0])
                };
            } else if s.has(Surfaces::TOP) {
                out[1] = nanson([0.0, 0.0, 1.0]);
            }
            out
        })
        .collect();
    let mut normals_ext = Vec::new();
    let normals = extended(mirror, &normals, &mut normals_ext, |v, f| {
        v.map(|u| mirror::vector(&u, f))
    });
    let nearest: Vec<f64> = (0..n)
        .map(|i| {
            sup.named
                .of(i)
                .iter()
                .map(|&j| distance(&pts[i], &pts[j]))
                .fold(f64::INFINITY, f64::min)
        })
        .collect();
    // Distance of an interior node to the tangent planes of the
    // boundary nodes it names (infinite when it names none).
    let bdist: Vec<f64> = (0..n)
        .map(|i| {
            if !surf[i].interior() {
                return 0.0;
            }
            let mut b = f64::INFINITY;
            for &j in sup.named.of(i) {
                for nu in &normals[j] {
                    if *nu != [0.0; 3] {
                        let d: f64 = (0..3).map(|a| (pts[j][a] - pts[i][a]) * nu[a]).sum();
                        if d > 0.0 {
                            b = b.min(d);
                        }
                    }
                }
            }
            b
        })
        .collect();
    let radii = test_radii(&nearest, &bdist, ALPHA);
    (0..n)
        .map(|i| {
            let s = surf[i];
            if s.interior() {
                return TestSphere::whole(radii[i]);
            }
            let [nm, nf] = normals[i];
            let mut cut = [0i8; 3];
            // e3: the face's inward or the top's outward normal, else z.
            let e3 = if s.has(Surfaces::FACE) {
                cut[2] = -1;
                nf.map(|x| -x)
            } else if s.has(Surfaces::TOP) {
                cut[2] = 1;
                nf
            } else {
                [0.0, 0.0, 1.0]
            };
            let e1 = if s.has(Surfaces::MANTLE) {
                cut[0] = 1;
                nm
            } else {
                let p = pts[i];
                let r = (p[0] * p[0] + p[1] * p[1]).sqrt();
                if r > 0.0 {
                    [p[0] / r, p[1] / r, 0.0]
                } else {
                    [1.0, 0.0, 0.0]
                }
            };
            // Orthonormal frame: keep the plane that is not the mantle
            // (face or top) when both cut; else keep e1.
            let (e1, e3) = if cut[2] != 0 {
                (unit(reject(e1, e3)), e3)
            } else {
                (e1, unit(reject(e3, e1)))
            };
            let e2 = cross(e3, e1);
            TestSphere {
                radius: radii[i],
                frame: [e1, e2, e3],
                cut,
            }
        })
        .collect()
}

/// Nanson's current outward normal `n ∝ F⁻ᵀ N` of the reference normal
/// `big`, with `finv = F⁻¹ = ∂X/∂x` at the node.
pub(super) fn nanson(finv: &[[f64; 3]; 3], big: [f64; 3]) -> [f64; 3] {
    unit(std::array::from_fn(|b| {
        (0..3).map(|a| big[a] * finv[a][b]).sum::<f64>()
    }))
}

/// The mantle's reference normal at the reference place `x`: radial.
pub(super) fn radial(x: [f64; 3]) -> [f64; 3] {
    let r = (x[0] * x[0] + x[1] * x[1]).sqrt();
    [x[0] / r, x[1] / r, 0.0]
}

pub(super) fn unit(a: [f64; 3]) -> [f64; 3] {
    let l = norm(a);
    a.map(|x| x / l)
}

/// `a` without its component along the unit vector `u`.
pub(super) fn reject(a: [f64; 3], u: [f64; 3]) -> [f64; 3] {
    let d = a[0] * u[0] + a[1] * u[1] + a[2] * u[2];
    std::array::from_fn(|k| a[k] - d * u[k])
}

pub(super) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
