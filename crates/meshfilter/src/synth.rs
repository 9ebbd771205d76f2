//! Synthetic coloured meshes with exact ground truth (paper 04's test data are private or
//! unavailable): a coloured cube with sharp edges whose colour edges coincide with them (S1),
//! a coloured octahedron (blunter edges, 109.5 degrees),
//! a fandisk-like CAD part with convex and concave creases and a
//! fillet (S2), an icosphere (S3), a plane with a colour step; and Gaussian noise along the
//! vertex normals.

use std::collections::HashMap;

use wscg_math::{Error, Result, TriMesh};

/// Saturated patch colours (`[0, 1]` RGB): the cube's six faces use the first six, the CAD
/// part's seven patches all.
const PALETTE: [[f32; 3]; 7] = [
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
    [1.0, 1.0, 0.0],
    [0.0, 1.0, 1.0],
    [1.0, 0.0, 1.0],
    [1.0, 0.5, 0.0],
];

/// The unit cube `[0, 1]^3`, each face an `n x n` grid of quads split into two triangles
/// (outward orientation), vertices shared along the edges; face `f` has colour
/// `PALETTE[f]` and an edge vertex keeps the colour of the first face that made it.
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
                col.push(PALETTE[f]);
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

/// The octahedron `|x| + |y| + |z| = 1` (dihedral angle 109.5 degrees), each face an `n`-step
/// triangular grid (outward orientation), vertices shared along the edges; the face of
/// octant `f` (bits: x < 0, y < 0, z < 0) has colour `PALETTE[f % 7]` (opposite faces
/// share a colour, adjacent ones never) and an edge vertex keeps the colour of the first
/// face that made it. `n = 24` gives 2306 vertices.
///
/// Errors: `n == 0` or too many vertices.
pub fn colored_octahedron(n: usize) -> Result<TriMesh> {
    if n == 0 || n > 2000 {
        return Err(Error::invalid("n", format!("must be in 1..=2000, got {n}")));
    }
    let ni = n as i64;
    let mut index: HashMap<[i64; 3], u32> = HashMap::new();
    let (mut pos, mut col, mut faces) = (Vec::new(), Vec::new(), Vec::new());
    for f in 0..8usize {
        let s = [0, 1, 2].map(|a| if f >> a & 1 == 1 { -1 } else { 1 });
        let (a, mut b, mut c) = ([s[0], 0, 0], [0, s[1], 0], [0, 0, s[2]]);
        // Outward: (b - a) x (c - a) along (sx, sy, sz).
        if s[0] * s[1] * s[2] < 0 {
            std::mem::swap(&mut b, &mut c);
        }
        let mut id = |i: i64, j: i64| -> u32 {
            let w = [ni - i - j, i, j];
            let key: [i64; 3] = std::array::from_fn(|k| w[0] * a[k] + w[1] * b[k] + w[2] * c[k]);
            *index.entry(key).or_insert_with(|| {
                pos.push(key.map(|v| v as f64 / n as f64));
                col.push(PALETTE[f % PALETTE.len()]);
                (pos.len() - 1) as u32
            })
        };
        for i in 0..ni {
            for j in 0..ni - i {
                faces.push([id(i, j), id(i + 1, j), id(i, j + 1)]);
                if i + j < ni - 1 {
                    faces.push([id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
                }
            }
        }
    }
    TriMesh::new(pos, faces)?.with_colors(col)
}

/// The vertices of [`colored_octahedron`]`(n)` within one grid row of an edge (some
/// coordinate at most `1/n` in magnitude).
pub fn octahedron_edge_band(n: usize, positions: &[[f64; 3]]) -> Vec<bool> {
    let tol = 1.0 / n as f64 + 1e-9;
    positions
        .iter()
        .map(|p| p.iter().any(|c| c.abs() <= tol))
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

/// One piece of the CAD part's profile.
#[derive(Clone, Copy, Debug)]
enum Piece {
    Line([f64; 2], [f64; 2]),
    /// Centre, radius, start and end angle (radians).
    Arc([f64; 2], f64, f64, f64),
}

impl Piece {
    fn length(&self) -> f64 {
        match *self {
            Piece::Line(a, b) => (b[0] - a[0]).hypot(b[1] - a[1]),
            Piece::Arc(_, r, t0, t1) => r * (t1 - t0).abs(),
        }
    }

    /// The point at parameter `t` in `[0, 1]`.
    fn at(&self, t: f64) -> [f64; 2] {
        match *self {
            Piece::Line(a, b) => [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])],
            Piece::Arc(c, r, t0, t1) => {
                let th = t0 + t * (t1 - t0);
                [c[0] + r * th.cos(), c[1] + r * th.sin()]
            }
        }
    }
}

/// Centre (x, y) of the CAD part's fillet, a quarter circle of radius [`FILLET_RADIUS`].
pub const FILLET_CENTER: [f64; 2] = [0.5, 1.5];
/// Radius of the CAD part's fillet.
pub const FILLET_RADIUS: f64 = 0.5;
/// Profile patch of the fillet in [`CadPart::patch`].
pub const FILLET_PATCH: u8 = 5;

/// The profile of the CAD part, counter-clockwise: bottom, right side, step (its end is a
/// concave crease), riser, top, the fillet (tangent to the top and the left side), left side.
fn cad_profile() -> [Piece; 7] {
    use std::f64::consts::{FRAC_PI_2, PI};
    [
        Piece::Line([0.0, 0.0], [3.0, 0.0]),
        Piece::Line([3.0, 0.0], [3.0, 1.0]),
        Piece::Line([3.0, 1.0], [1.5, 1.0]),
        Piece::Line([1.5, 1.0], [1.5, 2.0]),
        Piece::Line([1.5, 2.0], [0.5, 2.0]),
        Piece::Arc(FILLET_CENTER, FILLET_RADIUS, FRAC_PI_2, PI),
        Piece::Line([0.0, 1.5], [0.0, 0.0]),
    ]
}

/// The fandisk-like CAD part S2 with its per-vertex ground-truth labels.
#[derive(Clone, Debug)]
pub struct CadPart {
    /// The mesh, coloured by patch.
    pub mesh: TriMesh,
    /// Profile patch of every vertex (0..7, [`FILLET_PATCH`] the fillet); a vertex where two
    /// patches meet belongs to the patch that starts there.
    pub patch: Vec<u8>,
    /// Vertices within one sample spacing of a sharp crease (the four convex and the concave
    /// profile corners), by arc length along the profile.
    pub crease_band: Vec<bool>,
}

/// S2, a stand-in for the paper's coloured fandisk (section 4): a 2-D profile of straight
/// segments with four convex corners, one concave corner and a quarter-circle fillet (tangent
/// at both ends), extruded along z over `[0, 1]`; `n` samples per unit length, regular on
/// every patch (vertices exactly on the analytic surface), one colour per patch. The
/// extrusion is open: its two boundary loops
/// (z = 0 and z = 1) are what the filters hold fixed. `n = 20` gives 4116 vertices.
///
/// Errors: `n` outside `1..=500`.
pub fn cad_part(n: usize) -> Result<CadPart> {
    if n == 0 || n > 500 {
        return Err(Error::invalid("n", format!("must be in 1..=500, got {n}")));
    }
    let pieces = cad_profile();
    let h = 1.0 / n as f64;
    // Profile samples: (x, y, patch, arc length from the start).
    let mut prof: Vec<([f64; 2], u8, f64)> = Vec::new();
    let mut corners = Vec::new();
    let mut s0 = 0.0;
    for (p, piece) in pieces.iter().enumerate() {
        let len = piece.length();
        let m = ((len / h).round() as usize).max(1);
        // Two lines meet at a crease; the arc's ends are tangent joins.
        if matches!(
            (piece, pieces[(p + pieces.len() - 1) % pieces.len()]),
            (Piece::Line(..), Piece::Line(..))
        ) {
            corners.push(s0);
        }
        for i in 0..m {
            let t = i as f64 / m as f64;
            prof.push((piece.at(t), p as u8, s0 + t * len));
        }
        s0 += len;
    }
    let total = s0;
    let np = prof.len();
    let mut pos = Vec::with_capacity(np * (n + 1));
    let (mut col, mut patch, mut band) = (Vec::new(), Vec::new(), Vec::new());
    for j in 0..=n {
        let z = j as f64 / n as f64;
        for &(xy, p, s) in &prof {
            pos.push([xy[0], xy[1], z]);
            col.push(PALETTE[p as usize]);
            patch.push(p);
            let near = corners.iter().any(|&c: &f64| {
                let d = (s - c).abs();
                d.min(total - d) <= h * (1.0 + 1e-9)
            });
            band.push(near);
        }
    }
    let mut faces = Vec::with_capacity(2 * np * n);
    for j in 0..n {
        for i in 0..np {
            let id = |i: usize, j: usize| (j * np + i % np) as u32;
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            faces.push([a, b, c]);
            faces.push([a, c, d]);
        }
    }
    Ok(CadPart {
        mesh: TriMesh::new(pos, faces)?.with_colors(col)?,
        patch,
        crease_band: band,
    })
}

/// Default noise seed (the 64-bit golden-ratio constant).
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
