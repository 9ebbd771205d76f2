//! Joint bilateral mesh denoising (paper 04, section 3). The paper's algorithm box is missing
//! from our copy of the text; the steps below are reconstructed from the text, its Fig. 2 and
//! Fleishman et al. 2003, which it extends (choices marked "(R)").
//!
//! Per iteration, with `G(t; s) = exp(-t^2 / (2 s^2))`, unit area-weighted vertex normals `n`
//! and the `k` nearest vertices `q_i` of every vertex `v` (Euclidean, `v` excluded (R),
//! recomputed every iteration (R)):
//!
//! 1. **Denoise** (Jacobi): `d_i = |v - q_i|`, `o_i = n . (q_i - v)`, `c_i = |c_v - c_i|`
//!    (0-255 RGB), `w_i = G(d_i; s_d) G(o_i; s_o) G(c_i; s_c)`, `x' = sum w_i o_i / sum w_i`,
//!    `v' = v + x' n`.
//! 2. **Local anti-shrinking** (paper eq. 2): `x'' = sum w'_i x'_(i) / sum w'_i` with
//!    `w'_i = G(|v' - q'_i|; s_d)` (R: the spatial term only) over the same neighbours'
//!    own shifts, `v'' = v' - x'' n`.
//! 3. `s_o <- lambda s_o`.
//!
//! Boundary vertices (on an edge with one face), isolated vertices and vertices whose
//! normal is undefined stay in place.
//!
//! **Two-stage update (ours, beyond the paper; on when `normal_iterations > 0`, the
//! default).** Moving every vertex along its own vertex normal cannot restore a sharp
//! edge: at an edge that normal is the mean of both faces' normals, the neighbours of the
//! vertex's colour lie on one side only, and noise of half the MVD tilts the tangent plane
//! so much that the one-sided offsets are biased. On a coloured cube the paper's update
//! leaves the vertices within one MVD of an edge about as far from their true positions as
//! the best Laplacian smoothing does. The classical way bilateral methods keep edges is to
//! filter the normals first and then move the vertices to fit them (Zheng et al. 2011,
//! the paper's [ZFAT11]; the vertex update of Sun et al. 2007). Every iteration here:
//!
//! 1. **Joint bilateral normal filter** (`normal_iterations` passes): every face normal
//!    `m_f <- normalize(sum_g A_g G(|c_f - c_g|; s_d) G(|m_f - m_g|; s_n) G(|col_f - col_g|;
//!    s_c) m_g)` over the faces `g` sharing a vertex with `f` (`A` area, `c` centroid, `col`
//!    the mean colour of the face's vertices, 0-255): the paper's spatial and colour terms
//!    with a normal range term in place of the offset term, so that faces of different
//!    colour, or of clearly different orientation, do not mix.
//! 2. **Vertex update** (`vertex_iterations` steps): `v <- v + (1/|F_v|) sum_f m_f (m_f .
//!    (c_f - v))` over the faces `F_v` of `v`: every vertex moves towards the planes of its
//!    faces, so a vertex on an edge moves to the intersection of the two faces' planes.
//!
//! It does not use `k`, `sigma_o`, `lambda`, the anti-shrinking pass or the neighbour
//! rebuild (the plane fit does not shrink flat or edge regions). `normal_iterations = 0`
//! gives the paper's update above.

use rayon::prelude::*;
use wscg_math::knn_graph::knn_graph;
use wscg_math::mesh::Adjacency;
use wscg_math::vec3::{add_scaled, dist, dist2, dot, normalized_or_zero, sub};
use wscg_math::{Error, Result, TriMesh};

use crate::params::JbmdParams;

/// Vertices that the filter moves: used by a face, not on the boundary.
pub fn movable(mesh: &TriMesh) -> Vec<bool> {
    let mut m = vec![false; mesh.num_vertices()];
    for f in &mesh.faces {
        for &i in f {
            m[i as usize] = true;
        }
    }
    for e in mesh.boundary_edges() {
        m[e[0] as usize] = false;
        m[e[1] as usize] = false;
    }
    m
}

/// Checks the mesh for filtering: non-empty, finite, valid indices and colour count.
pub(crate) fn check_mesh(mesh: &TriMesh) -> Result<()> {
    if mesh.num_vertices() == 0 || mesh.num_faces() == 0 {
        return Err(Error::Empty("mesh"));
    }
    mesh.validate()
}

/// Statistics of one iteration of [`jbmd_trace`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IterStats {
    /// Offset range used in this iteration.
    pub sigma_o: f64,
    /// Largest vertex displacement of the iteration.
    pub max_move: f64,
}

/// Denoises `mesh` (paper 04): the new vertex positions, same connectivity.
///
/// Errors: an empty or invalid mesh, non-finite positions, bad parameters.
pub fn jbmd(mesh: &TriMesh, p: &JbmdParams) -> Result<Vec<[f64; 3]>> {
    jbmd_trace(mesh, p, |_, _, _| {}).map(|(v, _)| v)
}

/// [`jbmd`] calling `observe(iteration, positions, stats)` after every iteration (for error
/// curves such as the paper's Figs. 3, 5 and 8).
pub fn jbmd_trace(
    mesh: &TriMesh,
    p: &JbmdParams,
    mut observe: impl FnMut(usize, &[[f64; 3]], &IterStats),
) -> Result<(Vec<[f64; 3]>, Vec<IterStats>)> {
    p.validate()?;
    check_mesh(mesh)?;
    p.validate_for(mesh.num_vertices())?;
    let colors: Option<Vec<[f64; 3]>> = match (&mesh.colors, p.use_color) {
        (Some(c), true) => Some(c.iter().map(|v| v.map(|x| 255.0 * x as f64)).collect()),
        _ => None,
    };
    let moving = movable(mesh);
    let mut work = mesh.clone();
    let mut sigma_o = p.sigma_o;
    // Neighbours of vertex i: neighbors[i * k..(i + 1) * k] (fewer never happens: k < n).
    let mut neighbors: Vec<u32> = Vec::new();
    let k = p.k;
    // exp(-0.5 (d^2 / s_d^2 + o^2 / s_o^2 + c^2 / s_c^2)): one exponential per neighbour.
    let (id2, ic2) = (0.5 / (p.sigma_d * p.sigma_d), 0.5 / (p.sigma_c * p.sigma_c));
    let mut stats = Vec::with_capacity(p.iterations);
    let two_stage = (p.normal_iterations > 0).then(|| FaceRings::new(mesh, colors.as_deref(), ic2));
    for it in 0..p.iterations {
        wscg_math::cancel::check()?;
        if let Some(rings) = &two_stage {
            let before = work.positions.clone();
            two_stage_step(&mut work, rings, &moving, p, id2)?;
            let st = IterStats {
                sigma_o,
                max_move: max_distance(&work.positions, &before),
            };
            observe(it + 1, &work.positions, &st);
            stats.push(st);
            continue;
        }
        let normals = work.vertex_normals();
        let v = &work.positions;
        if it == 0 || p.rebuild_neighbors {
            neighbors = knn_graph(v, k)?;
        }
        let io2 = 0.5 / (sigma_o * sigma_o);
        // Pass 1: signed shifts along the normals.
        let shift: Vec<f64> = (0..v.len())
            .into_par_iter()
            .map(|i| {
                let n = normals[i];
                if !moving[i] || dot(n, n) == 0.0 {
                    return 0.0;
                }
                let (mut sw, mut swo) = (0.0, 0.0);
                for &j in &neighbors[i * k..(i + 1) * k] {
                    let j = j as usize;
                    let d = sub(v[j], v[i]);
                    let o = dot(n, d);
                    let mut e = dot(d, d) * id2 + o * o * io2;
                    if let Some(c) = &colors {
                        e += dist2(c[i], c[j]) * ic2;
                    }
                    let w = (-e).exp();
                    sw += w;
                    swo += w * o;
                }
                if sw > 1e-300 {
                    swo / sw
                } else {
                    0.0
                }
            })
            .collect();
        let v1: Vec<[f64; 3]> = (0..v.len())
            .into_par_iter()
            .map(|i| add_scaled(v[i], shift[i], normals[i]))
            .collect();
        // Pass 2: local anti-shrinking by the neighbours' own shifts.
        let next: Vec<[f64; 3]> = if p.anti_shrink {
            (0..v.len())
                .into_par_iter()
                .map(|i| {
                    let n = normals[i];
                    if !moving[i] || dot(n, n) == 0.0 {
                        return v1[i];
                    }
                    let (mut sw, mut sx) = (0.0, 0.0);
                    for &j in &neighbors[i * k..(i + 1) * k] {
                        let j = j as usize;
                        let w = (-dist2(v1[j], v1[i]) * id2).exp();
                        sw += w;
                        sx += w * shift[j];
                    }
                    let back = if sw > 1e-300 { sx / sw } else { 0.0 };
                    add_scaled(v1[i], -back, n)
                })
                .collect()
        } else {
            v1
        };
        let max_move = max_distance(&next, v);
        work.positions = next;
        let st = IterStats { sigma_o, max_move };
        observe(it + 1, &work.positions, &st);
        stats.push(st);
        sigma_o *= p.lambda;
    }
    Ok((work.positions, stats))
}

/// The largest distance between corresponding points of `a` and `b`.
fn max_distance(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    a.par_iter()
        .zip(b)
        .map(|(a, b)| dist(*a, *b))
        .reduce(|| 0.0, f64::max)
}

/// The fixed data of the two-stage update: the faces sharing a vertex with every face (the
/// face itself included), the colour factor of every such pair, and the faces of every
/// vertex.
struct FaceRings {
    /// Ring of face `f`: `ring[off[f]..off[f + 1]]`.
    off: Vec<usize>,
    ring: Vec<u32>,
    /// `G(|col_f - col_g|; s_c)` per ring entry (`None`: no colour term).
    color_w: Option<Vec<f64>>,
    vertex_faces: Adjacency,
}

impl FaceRings {
    /// `colors` on the 0-255 scale, `ic2 = 1 / (2 s_c^2)`.
    fn new(mesh: &TriMesh, colors: Option<&[[f64; 3]]>, ic2: f64) -> Self {
        let vertex_faces = mesh.vertex_faces();
        let (mut off, mut ring, mut buf) = (vec![0usize], Vec::new(), Vec::new());
        for f in &mesh.faces {
            buf.clear();
            for &i in f {
                buf.extend_from_slice(vertex_faces.neighbors(i as usize));
            }
            buf.sort_unstable();
            buf.dedup();
            ring.extend_from_slice(&buf);
            off.push(ring.len());
        }
        let color_w = colors.map(|c| {
            let mean = |f: usize| -> [f64; 3] {
                let t = mesh.faces[f];
                std::array::from_fn(|a| t.iter().map(|&i| c[i as usize][a]).sum::<f64>() / 3.0)
            };
            let face_col: Vec<[f64; 3]> = (0..mesh.faces.len()).map(mean).collect();
            (0..mesh.faces.len())
                .flat_map(|f| {
                    ring[off[f]..off[f + 1]]
                        .iter()
                        .map(move |&g| (f, g as usize))
                })
                .map(|(f, g)| (-dist2(face_col[f], face_col[g]) * ic2).exp())
                .collect()
        });
        Self {
            off,
            ring,
            color_w,
            vertex_faces,
        }
    }
}

/// Centroid of every face.
fn face_centroids(mesh: &TriMesh) -> Vec<[f64; 3]> {
    let v = &mesh.positions;
    mesh.faces
        .par_iter()
        .map(|t| std::array::from_fn(|a| t.iter().map(|&i| v[i as usize][a]).sum::<f64>() / 3.0))
        .collect()
}

/// One iteration of the two-stage update (module docs): the joint bilateral filter of the
/// face normals, then the vertex update that fits the filtered normals.
fn two_stage_step(
    work: &mut TriMesh,
    rings: &FaceRings,
    moving: &[bool],
    p: &JbmdParams,
    id2: f64,
) -> Result<()> {
    let (cf, af) = (face_centroids(work), work.face_areas());
    let in2 = 0.5 / (p.sigma_n * p.sigma_n);
    // A_g G(|c_f - c_g|; s_d) G(|col_f - col_g|; s_c) per ring entry: fixed while the
    // positions are.
    let (cf, af) = (&cf, &af);
    let fixed: Vec<f64> = (0..cf.len())
        .into_par_iter()
        .flat_map_iter(|f| {
            let (lo, hi) = (rings.off[f], rings.off[f + 1]);
            (lo..hi).map(move |r| {
                let g = rings.ring[r] as usize;
                let wc = rings.color_w.as_ref().map_or(1.0, |c| c[r]);
                af[g] * wc * (-dist2(cf[f], cf[g]) * id2).exp()
            })
        })
        .collect();
    let mut m = work.face_normals();
    for _ in 0..p.normal_iterations {
        wscg_math::cancel::check()?;
        m = (0..m.len())
            .into_par_iter()
            .map(|f| {
                let (lo, hi) = (rings.off[f], rings.off[f + 1]);
                let mut acc = [0.0; 3];
                for (r, &g) in (lo..hi).zip(&rings.ring[lo..hi]) {
                    let g = g as usize;
                    let w = fixed[r] * (-dist2(m[f], m[g]) * in2).exp();
                    acc = add_scaled(acc, w, m[g]);
                }
                normalized_or_zero(acc)
            })
            .collect();
    }
    for _ in 0..p.vertex_iterations {
        let cf = face_centroids(work);
        let x = &work.positions;
        let next: Vec<[f64; 3]> = (0..x.len())
            .into_par_iter()
            .map(|i| {
                let fs = rings.vertex_faces.neighbors(i);
                if !moving[i] || fs.is_empty() {
                    return x[i];
                }
                let mut d = [0.0; 3];
                for &f in fs {
                    let f = f as usize;
                    d = add_scaled(d, dot(m[f], sub(cf[f], x[i])), m[f]);
                }
                add_scaled(x[i], 1.0 / fs.len() as f64, d)
            })
            .collect();
        work.positions = next;
    }
    Ok(())
}
