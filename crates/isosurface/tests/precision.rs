//! Double-precision extraction: an `f64` grid keeps `f64` end to end (vertices and normals),
//! so an exactly linear field gives its exact normal with every estimator (each of them is
//! exact for a linear field: central differences, the tetrahedral spline of eq. 8, and LSN's
//! face perps, which lie in the plane).

use wscg_isosurface::{marching_cubes, NormalMethod, ScalarGrid};

/// `f(x) = a . x - c` sampled at world points `(i hx, j hy, k hz)`.
fn linear<T: wscg_isosurface::Sample>(
    dims: [usize; 3],
    h: [f64; 3],
    a: [f64; 3],
    c: f64,
) -> Vec<T> {
    let mut v = Vec::with_capacity(dims.iter().product());
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                let p = [i as f64 * h[0], j as f64 * h[1], k as f64 * h[2]];
                v.push(T::from_f64(a[0] * p[0] + a[1] * p[1] + a[2] * p[2] - c));
            }
        }
    }
    v
}

const DIMS: [usize; 3] = [23, 19, 27];
const H: [f64; 3] = [0.7, 1.3, 0.45];
const A: [f64; 3] = [0.37, -0.81, 1.13];
const C: f64 = -1.9;

fn max_deviation(normals: &[[f64; 3]], want: [f64; 3]) -> f64 {
    normals
        .iter()
        .map(|n| (0..3).map(|i| (n[i] - want[i]).abs()).fold(0.0, f64::max))
        .fold(0.0, f64::max)
}

#[test]
fn linear_field_normals_are_exact_in_f64() {
    let values: Vec<f64> = linear(DIMS, H, A, C);
    let g = ScalarGrid::with_spacing(DIMS, H, &values).unwrap();
    let norm = (A[0] * A[0] + A[1] * A[1] + A[2] * A[2]).sqrt();
    let want = A.map(|x| x / norm);
    for method in [
        NormalMethod::lsn(),
        NormalMethod::spline(),
        NormalMethod::CentralDifference,
    ] {
        let mesh = marching_cubes(&g, 0.0, method).unwrap();
        assert!(mesh.vertices.len() > 500, "{}", mesh.vertices.len());
        assert_eq!(mesh.normals.len(), mesh.vertices.len());
        assert_eq!(mesh.stats.undefined, 0);
        let dev = max_deviation(&mesh.normals, want);
        assert!(dev < 1e-9, "{}: largest deviation {dev:e}", method.name());
        // The vertices lie on the plane a . x = c to double precision (world units).
        let off = mesh
            .vertices
            .iter()
            .map(|p| (A[0] * p[0] + A[1] * p[1] + A[2] * p[2] - C).abs())
            .fold(0.0, f64::max);
        assert!(
            off < 1e-12,
            "{}: vertex off the plane by {off:e}",
            method.name()
        );
    }
}

#[test]
fn f32_grids_stay_f32_and_lose_precision() {
    // The same field in f32: the normals are f32 and deviate by far more than 1e-9, which is
    // what the f64 path avoids (and what the test above would catch if it fell back to f32).
    let values: Vec<f32> = linear(DIMS, H, A, C);
    let g = ScalarGrid::with_spacing(DIMS, H.map(|h| h as f32), &values).unwrap();
    let mesh = marching_cubes(&g, 0.0f32, NormalMethod::lsn()).unwrap();
    let norm = (A[0] * A[0] + A[1] * A[1] + A[2] * A[2]).sqrt();
    let want = A.map(|x| x / norm);
    let n64: Vec<[f64; 3]> = mesh.normals.iter().map(|n| n.map(f64::from)).collect();
    let dev = max_deviation(&n64, want);
    assert!(dev > 1e-7 && dev < 1e-2, "{dev:e}");
}
