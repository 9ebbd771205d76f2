//! Synthetic coloured meshes with exact ground truth (paper 04's test data are private or
//! unavailable): a coloured cube with sharp edges whose colour edges coincide with them, an
//! icosphere, a plane with a colour step; and Gaussian noise along the vertex normals.

use std::collections::HashMap;

use wscg_math::{Error, Result, TriMesh};

/// Saturated colours of the cube's six faces (`[0, 1]` RGB).
const FACE_COLORS: [[f32; 3]; 6] = [
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
    [1.0, 1.0, 0.0],
    [0.0, 1.0, 1.0],
    [1.0, 0.0, 1.0],
];

/// The unit cube `[0, 1]^3`, each face an `n x n` grid of quads split into two triangles
/// (outward orientation), vertices shared along the edges; face `f` has colour
/// `FACE_COLORS[f]` and an edge vertex keeps the colour of the first face that made it.
/// `n = 30` gives 5402 vertices and 10800 faces.
///
/// Errors: `n == 0` or too many vertices.
pub fn colored_cube(n: usize) -> Result<TriMesh> {
    if n == 0 || n > 2000 {
        return Err(Error::invalid("n", format!("must be in 1..=2000, got {n}")));
    }
    // (origin, u, v) in integer grid units; u x v points outwards.
    let sides: [([i64; 3], [i64; 3], [i64; 3]); 6] = [
        ([0, 0, 0], [0, 1, 0], [1, 0, 0]),
        ([0, 0, 1], [1, 0, 0], [0, 1, 0]),
        ([0, 0, 0], [1, 0, 0], [0, 0, 1]),
        ([0, 1, 0], [0, 0, 1], [1, 0, 0]),
        ([0, 0, 0], [0, 0, 1], [0, 1, 0]),
        ([1, 0, 0], [0, 1, 0], [0, 0, 1]),
    ];
    let ni = n as i64;
    let mut index: HashMap<[i64; 3], u32> = HashMap::new();
    let (mut pos, mut col, mut faces) = (Vec::new(), Vec::new(), Vec::new());
    for (f, (o, u, v)) in sides.iter().enumerate() {
        let mut id = |i: i64, j: i64| -> u32 {
            let key: [i64; 3] = std::array::from_fn(|a| o[a] * ni + i * u[a] + j * v[a]);
            *index.entry(key).or_insert_with(|| {
                pos.push(key.map(|c| c as f64 / n as f64));
                col.push(FACE_COLORS[f]);
                (pos.len() - 1) as u32
            })
        };
        for j in 0..ni {
            for i in 0..ni {
                let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
                faces.push([a, b, c]);
                faces.push([a, c, d]);
            }
        }
    }
    TriMesh::new(pos, faces)?.with_colors(col)
}

/// The vertices of [`colored_cube`]`(n)` within one grid step `1/n` of a cube edge (the
/// "edge band" where sharp features are judged).
pub fn cube_edge_band(n: usize, positions: &[[f64; 3]]) -> Vec<bool> {
    let tol = 1.0 / n as f64 + 1e-9;
    positions
        .iter()
        .map(|p| p.iter().filter(|&&c| c <= tol || c >= 1.0 - tol).count() >= 2)
        .collect()
}

/// An icosphere of radius 1 (`subdivisions`; 4 gives 2562 vertices), one colour.
pub fn icosphere(subdivisions: u32) -> Result<TriMesh> {
    let m = TriMesh::icosphere(subdivisions, 1.0)?;
    let n = m.num_vertices();
    m.with_colors(vec![[0.8, 0.6, 0.4]; n])
}

/// A flat `n x n` grid on the unit square (z = 0) whose left half (x < 0.5) is red and right
/// half blue: a colour edge without a geometric edge.
pub fn colored_plane(n: usize) -> Result<TriMesh> {
    let m = TriMesh::grid(n, n, 1.0, 1.0)?;
    let c = m
        .positions
        .iter()
        .map(|p| {
            if p[0] < 0.5 {
                [1.0, 0.0, 0.0]
            } else {
                [0.0, 0.0, 1.0]
            }
        })
        .collect();
    m.with_colors(c)
}

/// Default noise seed of the specification.
pub const NOISE_SEED: u64 = 0x9E37_79B9_7F4A_7C15;

/// `mesh` with every vertex moved along its (area-weighted) normal by `N(0, sigma^2)`, or in
/// all three directions when `isotropic`.
///
/// Errors: `sigma` negative or not finite.
pub fn add_noise(mesh: &TriMesh, sigma: f64, isotropic: bool, seed: u64) -> Result<TriMesh> {
    if !(sigma.is_finite() && sigma >= 0.0) {
        return Err(Error::invalid(
            "sigma",
            format!("must be finite and >= 0, got {sigma}"),
        ));
    }
    let n = mesh.num_vertices();
    let e = wscg_math::rng::normal_vec(seed, 3 * n, 0.0, sigma)?;
    let normals = mesh.vertex_normals();
    let mut out = mesh.clone();
    for (i, p) in out.positions.iter_mut().enumerate() {
        if isotropic {
            for a in 0..3 {
                p[a] += e[3 * i + a];
            }
        } else {
            for a in 0..3 {
                p[a] += e[3 * i] * normals[i][a];
            }
        }
    }
    Ok(out)
}
