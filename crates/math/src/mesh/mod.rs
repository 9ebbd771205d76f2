//! [`TriMesh`]: an indexed triangle mesh with optional per-vertex normals and colours,
//! connectivity queries ([`Adjacency`]) and area / volume / normal computations. The
//! generators of test and demo surfaces are in [`shapes`]; OBJ and PLY files are read and
//! written by [`crate::io`] (feature `io-mesh`).
//!
//! # Conventions
//!
//! - `positions[i] = [x, y, z]` is vertex `i`, in whatever length unit the data uses (files
//!   carry no unit; areas are in that unit squared, volumes in that unit cubed).
//! - `faces[f] = [a, b, c]` are zero-based indices into `positions`. A triangle is oriented
//!   counter-clockwise: its normal is `(p_b - p_a) x (p_c - p_a)` (right-hand rule), and a
//!   closed mesh is *outward oriented* when every face normal points out of the enclosed
//!   solid, which makes [`TriMesh::signed_volume`] positive.
//! - `normals`, when present, are per-vertex vectors (one per position). They are whatever the
//!   producer stored: unit length is not enforced.
//! - `colors`, when present, are per-vertex RGB values in `[0, 1]`, stored as in the file (no
//!   gamma conversion).
//!
//! The methods assume a *valid* mesh (every face index `< positions.len()`, see
//! [`TriMesh::validate`]); the constructors and readers guarantee this, and the methods panic
//! (index out of bounds) if the public fields were later changed into an invalid state.
//!
//! Per-face work runs in parallel with rayon. Every sum is taken over fixed-size chunks in a
//! fixed order, so results are bit-identical for any number of threads.
//!

use rayon::prelude::*;

use crate::error::{ensure_finite, Error, Result};
use crate::reduce::{chunked_sum, SUM_CHUNK};
use crate::vec3::{add, cross, dot, norm, normalized_or_zero, sub};

pub mod shapes;

pub use shapes::MAX_ICOSPHERE_SUBDIVISIONS;

/// Smallest number of items per rayon task for cheap per-face or per-vertex work.
const PAR_MIN_LEN: usize = 2048;

/// Key of the undirected edge `{a, b}`: smaller index in the high 32 bits.
#[inline]
fn edge_key(a: u32, b: u32) -> u64 {
    let (lo, hi) = if a < b { (a, b) } else { (b, a) };
    (u64::from(lo) << 32) | u64::from(hi)
}

#[inline]
fn edge_from_key(k: u64) -> [u32; 2] {
    [(k >> 32) as u32, k as u32]
}

/// Component-wise sum of `f(item)` over `items`, deterministic for any thread count.
fn chunked_sum3<T: Sync>(items: &[T], f: impl Fn(&T) -> [f64; 3] + Sync) -> [f64; 3] {
    let partial: Vec<[f64; 3]> = items
        .par_chunks(SUM_CHUNK)
        .map(|c| c.iter().map(&f).fold([0.0; 3], add))
        .collect();
    partial.into_iter().fold([0.0; 3], add)
}

// ------------------------------------------------------------------------------------------
// Adjacency
// ------------------------------------------------------------------------------------------

/// A compressed (CSR-like) list of neighbour lists: row `i` holds
/// `indices[offsets[i]..offsets[i + 1]]`.
///
/// Returned by [`TriMesh::vertex_adjacency`] (rows: vertices, entries: vertices),
/// [`TriMesh::vertex_faces`] (rows: vertices, entries: faces) and
/// [`TriMesh::face_adjacency`] (rows: faces, entries: faces). Every row is sorted in
/// increasing order and holds no duplicates.
#[derive(Clone, Debug, PartialEq, Eq, Default)]
pub struct Adjacency {
    /// Row starts, length `rows + 1`, non-decreasing, `offsets[0] == 0` and
    /// `offsets[rows] == indices.len()`.
    pub offsets: Vec<usize>,
    /// Concatenated neighbour lists.
    pub indices: Vec<u32>,
}

impl Adjacency {
    /// Number of rows (vertices or faces).
    pub fn len(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    /// True when there are no rows.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Neighbours of row `i`, sorted increasingly.
    ///
    /// # Panics
    /// If `i >= self.len()`.
    pub fn neighbors(&self, i: usize) -> &[u32] {
        &self.indices[self.offsets[i]..self.offsets[i + 1]]
    }

    /// Number of neighbours of row `i`.
    ///
    /// # Panics
    /// If `i >= self.len()`.
    pub fn degree(&self, i: usize) -> usize {
        self.offsets[i + 1] - self.offsets[i]
    }

    /// Iterates over the rows' neighbour lists in order.
    pub fn iter(&self) -> impl Iterator<Item = &[u32]> + '_ {
        self.offsets
            .windows(2)
            .map(move |w| &self.indices[w[0]..w[1]])
    }

    /// Builds an adjacency with `rows` rows from `(row, entry)` pairs sorted by row (and by
    /// entry within a row) without duplicates.
    fn from_sorted_pairs(rows: usize, pairs: &[(u32, u32)]) -> Self {
        let mut offsets = vec![0usize; rows + 1];
        for &(r, _) in pairs {
            offsets[r as usize + 1] += 1;
        }
        for i in 0..rows {
            offsets[i + 1] += offsets[i];
        }
        Adjacency {
            offsets,
            indices: pairs.iter().map(|p| p.1).collect(),
        }
    }
}

// ------------------------------------------------------------------------------------------
// TriMesh: construction and validation
// ------------------------------------------------------------------------------------------

/// An indexed triangle mesh. See the [module documentation](self) for the conventions.
///
/// Build one with [`TriMesh::new`] (validated), a generator ([`TriMesh::icosphere`],
/// [`TriMesh::cube`], [`TriMesh::grid`]) or a reader ([`TriMesh::read`]). `Default` is the
/// empty mesh.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct TriMesh {
    /// Vertex positions `[x, y, z]`, length `V`.
    pub positions: Vec<[f64; 3]>,
    /// Triangles as zero-based vertex indices, counter-clockwise, length `F`.
    pub faces: Vec<[u32; 3]>,
    /// Optional per-vertex normals, length `V` when present.
    pub normals: Option<Vec<[f64; 3]>>,
    /// Optional per-vertex RGB colours in `[0, 1]`, length `V` when present.
    pub colors: Option<Vec<[f32; 3]>>,
}

/// Checks the positions: at most `u32::MAX` of them and all finite.
fn check_positions(positions: &[[f64; 3]]) -> Result<()> {
    if positions.len() > u32::MAX as usize {
        return Err(Error::LimitExceeded(format!(
            "a mesh has at most {} vertices (u32 indices), got {}",
            u32::MAX,
            positions.len()
        )));
    }
    ensure_finite("positions", positions.as_flattened())
}

/// Checks the faces: at most `u32::MAX` of them, indices `< num_vertices`, three distinct
/// indices per face. The error names the first bad face.
fn check_faces(faces: &[[u32; 3]], num_vertices: usize) -> Result<()> {
    if faces.len() > u32::MAX as usize {
        return Err(Error::LimitExceeded(format!(
            "a mesh has at most {} faces, got {}",
            u32::MAX,
            faces.len()
        )));
    }
    let bad = faces
        .par_iter()
        .with_min_len(PAR_MIN_LEN)
        .position_first(|f| {
            f.iter().any(|&i| i as usize >= num_vertices)
                || f[0] == f[1]
                || f[1] == f[2]
                || f[0] == f[2]
        });
    let Some(k) = bad else { return Ok(()) };
    let f = faces[k];
    if let Some(&i) = f.iter().find(|&&i| i as usize >= num_vertices) {
        Err(Error::invalid(
            "faces",
            format!(
                "face {k} = {f:?} refers to vertex {i}, but the mesh has {num_vertices} \
                 vertices (valid indices are 0..{num_vertices})"
            ),
        ))
    } else {
        Err(Error::invalid(
            "faces",
            format!(
                "face {k} = {f:?} repeats a vertex index; a triangle needs three distinct \
                 vertices"
            ),
        ))
    }
}

/// Checks per-vertex normals: one per vertex, all finite.
fn check_normals(normals: &[[f64; 3]], num_vertices: usize) -> Result<()> {
    if normals.len() != num_vertices {
        return Err(Error::ShapeMismatch(format!(
            "`normals` has {} entries but the mesh has {num_vertices} vertices",
            normals.len()
        )));
    }
    ensure_finite("normals", normals.as_flattened())
}

/// Checks per-vertex colours: one per vertex, finite, every component in `[0, 1]`.
fn check_colors(colors: &[[f32; 3]], num_vertices: usize) -> Result<()> {
    if colors.len() != num_vertices {
        return Err(Error::ShapeMismatch(format!(
            "`colors` has {} entries but the mesh has {num_vertices} vertices",
            colors.len()
        )));
    }
    let flat = colors.as_flattened();
    ensure_finite("colors", flat)?;
    if let Some(i) = flat.iter().position(|&c| !(0.0..=1.0).contains(&c)) {
        return Err(Error::invalid(
            "colors",
            format!(
                "component {} at flat index {i} (vertex {}) is outside [0, 1]",
                flat[i],
                i / 3
            ),
        ));
    }
    Ok(())
}

impl TriMesh {
    /// Creates a mesh from vertex positions and triangles, without normals or colours.
    ///
    /// - `positions`: `V` points `[x, y, z]`, all finite.
    /// - `faces`: `F` triangles of zero-based indices into `positions`, counter-clockwise
    ///   (see the [module documentation](self)); every index `< V`, three distinct indices per
    ///   triangle. An empty mesh (no faces, or nothing at all) is allowed.
    ///
    /// Errors: a NaN or infinite coordinate ([`Error::NonFinite`] naming `positions`, flat
    /// index `3 * vertex + axis`); an index out of range or repeated within a face
    /// ([`Error::InvalidArgument`] naming `faces`, with the face number and the index); more
    /// than `u32::MAX` vertices or faces ([`Error::LimitExceeded`]).
    pub fn new(positions: Vec<[f64; 3]>, faces: Vec<[u32; 3]>) -> Result<Self> {
        check_positions(&positions)?;
        check_faces(&faces, positions.len())?;
        Ok(TriMesh {
            positions,
            faces,
            normals: None,
            colors: None,
        })
    }

    /// Returns the mesh with per-vertex RGB colours `colors` (one per vertex, components in
    /// `[0, 1]`).
    ///
    /// Errors: a length other than the vertex count ([`Error::ShapeMismatch`]); NaN or
    /// infinity ([`Error::NonFinite`] naming `colors`); a component outside `[0, 1]`
    /// ([`Error::InvalidArgument`] naming `colors`).
    pub fn with_colors(mut self, colors: Vec<[f32; 3]>) -> Result<Self> {
        check_colors(&colors, self.positions.len())?;
        self.colors = Some(colors);
        Ok(self)
    }

    /// Returns the mesh with per-vertex normals `normals` (one per vertex, finite; they are
    /// stored as given, not normalised).
    ///
    /// Errors: a length other than the vertex count ([`Error::ShapeMismatch`]); NaN or
    /// infinity ([`Error::NonFinite`] naming `normals`).
    pub fn with_normals(mut self, normals: Vec<[f64; 3]>) -> Result<Self> {
        check_normals(&normals, self.positions.len())?;
        self.normals = Some(normals);
        Ok(self)
    }

    /// Checks every invariant that [`TriMesh::new`], [`TriMesh::with_normals`] and
    /// [`TriMesh::with_colors`] check, for a mesh whose public fields were set directly.
    ///
    /// Errors: as those three functions.
    pub fn validate(&self) -> Result<()> {
        check_positions(&self.positions)?;
        check_faces(&self.faces, self.positions.len())?;
        if let Some(n) = &self.normals {
            check_normals(n, self.positions.len())?;
        }
        if let Some(c) = &self.colors {
            check_colors(c, self.positions.len())?;
        }
        Ok(())
    }

    /// Number of vertices `V`.
    pub fn num_vertices(&self) -> usize {
        self.positions.len()
    }

    /// Number of triangles `F`.
    pub fn num_faces(&self) -> usize {
        self.faces.len()
    }

    /// True when the mesh has no faces.
    pub fn is_empty(&self) -> bool {
        self.faces.is_empty()
    }

    // --------------------------------------------------------------------------------------
    // Geometry
    // --------------------------------------------------------------------------------------

    /// `(p_b - p_a) x (p_c - p_a)` of face `f`: normal direction, length twice the area.
    #[inline]
    fn face_cross(&self, f: &[u32; 3]) -> [f64; 3] {
        let a = self.positions[f[0] as usize];
        let b = self.positions[f[1] as usize];
        let c = self.positions[f[2] as usize];
        cross(sub(b, a), sub(c, a))
    }

    /// Unit normal of every face (length `F`), oriented by the right-hand rule; the zero
    /// vector for a face of zero area.
    pub fn face_normals(&self) -> Vec<[f64; 3]> {
        self.faces
            .par_iter()
            .with_min_len(PAR_MIN_LEN)
            .map(|f| normalized_or_zero(self.face_cross(f)))
            .collect()
    }

    /// Area of every face (length `F`), in squared length units.
    pub fn face_areas(&self) -> Vec<f64> {
        self.faces
            .par_iter()
            .with_min_len(PAR_MIN_LEN)
            .map(|f| 0.5 * norm(self.face_cross(f)))
            .collect()
    }

    /// Per-vertex normals (length `V`): the area-weighted mean of the unit normals of the
    /// faces around each vertex, `n_i = normalize(sum_f A_f n_f)`, normalised to unit length.
    /// The zero vector for a vertex that no face uses or whose faces' normals cancel.
    pub fn vertex_normals(&self) -> Vec<[f64; 3]> {
        // |cross| = 2 A_f, so summing the raw cross products weights by area.
        let crosses: Vec<[f64; 3]> = self
            .faces
            .par_iter()
            .with_min_len(PAR_MIN_LEN)
            .map(|f| self.face_cross(f))
            .collect();
        let mut acc = vec![[0.0f64; 3]; self.positions.len()];
        for (f, c) in self.faces.iter().zip(&crosses) {
            for &i in f {
                let a = &mut acc[i as usize];
                *a = add(*a, *c);
            }
        }
        acc.par_iter_mut()
            .with_min_len(PAR_MIN_LEN)
            .for_each(|n| *n = normalized_or_zero(*n));
        acc
    }

    /// Sets [`TriMesh::normals`] to [`TriMesh::vertex_normals`].
    pub fn compute_vertex_normals(&mut self) {
        self.normals = Some(self.vertex_normals());
    }

    /// Total surface area (sum of the face areas), in squared length units.
    pub fn total_area(&self) -> f64 {
        chunked_sum(&self.faces, |f| 0.5 * norm(self.face_cross(f)))
    }

    /// Axis-aligned bounding box `(min, max)` of all vertices (used or not); `None` when the
    /// mesh has no vertices.
    pub fn bounding_box(&self) -> Option<([f64; 3], [f64; 3])> {
        let first = *self.positions.first()?;
        Some(
            self.positions
                .iter()
                .fold((first, first), |(mut lo, mut hi), p| {
                    for k in 0..3 {
                        lo[k] = lo[k].min(p[k]);
                        hi[k] = hi[k].max(p[k]);
                    }
                    (lo, hi)
                }),
        )
    }

    /// Mean of the vertex positions (every vertex weighted equally); `None` when the mesh has
    /// no vertices. See [`TriMesh::area_centroid`] for the centroid of the surface.
    pub fn centroid(&self) -> Option<[f64; 3]> {
        if self.positions.is_empty() {
            return None;
        }
        let s = chunked_sum3(&self.positions, |p| *p);
        let n = self.positions.len() as f64;
        Some([s[0] / n, s[1] / n, s[2] / n])
    }

    /// Centroid of the surface: the mean of the face centroids weighted by face area; `None`
    /// when the total area is zero.
    pub fn area_centroid(&self) -> Option<[f64; 3]> {
        let total = self.total_area();
        if total <= 0.0 || !total.is_finite() {
            return None;
        }
        let s = chunked_sum3(&self.faces, |f| {
            let w = 0.5 * norm(self.face_cross(f)) / 3.0;
            let p = f
                .iter()
                .fold([0.0; 3], |acc, &i| add(acc, self.positions[i as usize]));
            [w * p[0], w * p[1], w * p[2]]
        });
        Some([s[0] / total, s[1] / total, s[2] / total])
    }

    /// Enclosed volume by the divergence theorem, `sum_f p_a . (p_b x p_c) / 6`, in cubed
    /// length units.
    ///
    /// Positive for a closed, outward-oriented mesh, negative when it is inward oriented. For
    /// an open mesh it is the signed volume of the cones from the origin to its faces.
    pub fn signed_volume(&self) -> f64 {
        chunked_sum(&self.faces, |f| {
            let a = self.positions[f[0] as usize];
            let b = self.positions[f[1] as usize];
            let c = self.positions[f[2] as usize];
            dot(a, cross(b, c))
        }) / 6.0
    }

    // --------------------------------------------------------------------------------------
    // Connectivity
    // --------------------------------------------------------------------------------------

    /// `(edge key, face)` for the three edges of every face, sorted by key then face.
    fn edge_face_pairs(&self) -> Vec<(u64, u32)> {
        let mut pairs: Vec<(u64, u32)> = self
            .faces
            .par_iter()
            .enumerate()
            .with_min_len(PAR_MIN_LEN)
            .flat_map_iter(|(fi, f)| {
                let fi = fi as u32;
                [
                    (edge_key(f[0], f[1]), fi),
                    (edge_key(f[1], f[2]), fi),
                    (edge_key(f[2], f[0]), fi),
                ]
            })
            .collect();
        pairs.par_sort_unstable();
        pairs
    }

    /// Unique undirected edges `[a, b]` with `a < b`, sorted lexicographically.
    pub fn edges(&self) -> Vec<[u32; 2]> {
        let mut keys: Vec<u64> = self
            .faces
            .par_iter()
            .with_min_len(PAR_MIN_LEN)
            .flat_map_iter(|f| {
                [
                    edge_key(f[0], f[1]),
                    edge_key(f[1], f[2]),
                    edge_key(f[2], f[0]),
                ]
            })
            .collect();
        keys.par_sort_unstable();
        keys.dedup();
        keys.into_iter().map(edge_from_key).collect()
    }

    /// Vertex-to-vertex adjacency (`V` rows): the vertices joined to each vertex by an edge,
    /// sorted. Symmetric: `j` is in row `i` exactly when `i` is in row `j`.
    pub fn vertex_adjacency(&self) -> Adjacency {
        let edges = self.edges();
        let n = self.positions.len();
        let mut offsets = vec![0usize; n + 1];
        for e in &edges {
            offsets[e[0] as usize + 1] += 1;
            offsets[e[1] as usize + 1] += 1;
        }
        for i in 0..n {
            offsets[i + 1] += offsets[i];
        }
        let mut cursor = offsets.clone();
        let mut indices = vec![0u32; offsets[n]];
        // Edges are sorted by (a, b) with a < b, so row v first receives the neighbours a < v
        // (from edges (a, v), increasing a) and then those b > v (from edges (v, b),
        // increasing b): every row comes out sorted.
        for e in &edges {
            let (a, b) = (e[0] as usize, e[1] as usize);
            indices[cursor[a]] = e[1];
            cursor[a] += 1;
            indices[cursor[b]] = e[0];
            cursor[b] += 1;
        }
        Adjacency { offsets, indices }
    }

    /// Vertex-to-face incidence (`V` rows): the faces using each vertex, sorted.
    pub fn vertex_faces(&self) -> Adjacency {
        let n = self.positions.len();
        let mut offsets = vec![0usize; n + 1];
        for f in &self.faces {
            for &i in f {
                offsets[i as usize + 1] += 1;
            }
        }
        for i in 0..n {
            offsets[i + 1] += offsets[i];
        }
        let mut cursor = offsets.clone();
        let mut indices = vec![0u32; offsets[n]];
        for (fi, f) in self.faces.iter().enumerate() {
            for &i in f {
                indices[cursor[i as usize]] = fi as u32;
                cursor[i as usize] += 1;
            }
        }
        Adjacency { offsets, indices }
    }

    /// Face-to-face adjacency (`F` rows): the faces sharing at least one edge with each face,
    /// sorted. On a closed 2-manifold every face has exactly three neighbours; an edge shared
    /// by `k > 2` faces (non-manifold) makes all `k` faces neighbours of each other.
    pub fn face_adjacency(&self) -> Adjacency {
        let ef = self.edge_face_pairs();
        let mut pairs: Vec<(u32, u32)> = Vec::with_capacity(ef.len());
        for group in ef.chunk_by(|x, y| x.0 == y.0) {
            for (i, &(_, f)) in group.iter().enumerate() {
                for (j, &(_, g)) in group.iter().enumerate() {
                    if i != j && f != g {
                        pairs.push((f, g));
                    }
                }
            }
        }
        pairs.par_sort_unstable();
        pairs.dedup();
        Adjacency::from_sorted_pairs(self.faces.len(), &pairs)
    }

    /// Edges used by exactly one face, as `[a, b]` with `a < b`, sorted.
    pub fn boundary_edges(&self) -> Vec<[u32; 2]> {
        self.edge_face_pairs()
            .chunk_by(|x, y| x.0 == y.0)
            .filter(|g| g.len() == 1)
            .map(|g| edge_from_key(g[0].0))
            .collect()
    }

    /// True when the mesh has at least one face and no boundary edge (every edge is shared by
    /// two or more faces). Orientation and manifoldness are not checked.
    pub fn is_closed(&self) -> bool {
        !self.faces.is_empty()
            && self
                .edge_face_pairs()
                .chunk_by(|x, y| x.0 == y.0)
                .all(|g| g.len() >= 2)
    }

    /// Euler characteristic `V - E + F`, with `V` counting every vertex (used or not) and `E`
    /// the unique undirected edges. 2 for a closed surface of genus 0, 1 for a disc.
    pub fn euler_characteristic(&self) -> i64 {
        self.positions.len() as i64 - self.edges().len() as i64 + self.faces.len() as i64
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    pub(crate) fn angle(a: [f64; 3], b: [f64; 3]) -> f64 {
        (dot(a, b) / (norm(a) * norm(b))).clamp(-1.0, 1.0).acos()
    }

    fn tetra() -> TriMesh {
        // Outward-oriented tetrahedron on the unit axes.
        TriMesh::new(
            vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 1.0],
            ],
            vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        )
        .unwrap()
    }

    #[test]
    fn new_rejects_out_of_range_index() {
        let e = TriMesh::new(
            vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            vec![[0, 1, 2], [0, 1, 7]],
        )
        .unwrap_err();
        match &e {
            Error::InvalidArgument { name, reason } => {
                assert_eq!(*name, "faces");
                assert!(reason.contains("face 1"), "{reason}");
                assert!(reason.contains('7'), "{reason}");
            }
            other => panic!("unexpected error {other:?}"),
        }
    }

    #[test]
    fn new_rejects_repeated_index_and_non_finite() {
        let p = vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let e = TriMesh::new(p.clone(), vec![[0, 1, 1]]).unwrap_err();
        let repeats = matches!(
            &e,
            Error::InvalidArgument { name: "faces", reason } if reason.contains("repeats")
        );
        assert!(repeats, "{e}");
        let mut bad = p.clone();
        bad[1][2] = f64::NAN;
        let e = TriMesh::new(bad, vec![[0, 1, 2]]).unwrap_err();
        assert!(
            matches!(
                e,
                Error::NonFinite {
                    name: "positions",
                    index: 5
                }
            ),
            "{e}"
        );
        // Empty meshes are allowed.
        assert!(TriMesh::new(vec![], vec![]).unwrap().is_empty());
        assert!(TriMesh::new(p, vec![]).is_ok());
    }

    #[test]
    fn with_colors_and_normals_validate() {
        let m = tetra();
        assert!(matches!(
            m.clone().with_colors(vec![[0.5; 3]; 3]).unwrap_err(),
            Error::ShapeMismatch(_)
        ));
        assert!(matches!(
            m.clone().with_colors(vec![[0.5, 1.5, 0.0]; 4]).unwrap_err(),
            Error::InvalidArgument { name: "colors", .. }
        ));
        assert!(matches!(
            m.clone()
                .with_colors(vec![[0.5, f32::NAN, 0.0]; 4])
                .unwrap_err(),
            Error::NonFinite {
                name: "colors",
                index: 1
            }
        ));
        assert!(matches!(
            m.clone().with_normals(vec![[0.0; 3]; 5]).unwrap_err(),
            Error::ShapeMismatch(_)
        ));
        assert!(matches!(
            m.clone()
                .with_normals(vec![[f64::INFINITY, 0.0, 0.0]; 4])
                .unwrap_err(),
            Error::NonFinite {
                name: "normals",
                index: 0
            }
        ));
        let ok = m.with_colors(vec![[0.0, 0.5, 1.0]; 4]).unwrap();
        assert!(ok.validate().is_ok());
        let mut broken = ok;
        broken.faces.push([0, 1, 9]);
        assert!(broken.validate().is_err());
    }

    #[test]
    fn tetrahedron_geometry() {
        let m = tetra();
        assert!((m.signed_volume() - 1.0 / 6.0).abs() < 1e-15);
        let expected_area = 1.5 + 3f64.sqrt() / 2.0;
        assert!((m.total_area() - expected_area).abs() < 1e-14);
        assert!(m.is_closed());
        assert_eq!(m.euler_characteristic(), 2);
        assert_eq!(m.edges().len(), 6);
        let fnormals = m.face_normals();
        assert_eq!(fnormals[0], [0.0, 0.0, -1.0]);
        let s = 1.0 / 3f64.sqrt();
        assert!(fnormals[3].iter().all(|v| (v - s).abs() < 1e-15));
        let (lo, hi) = m.bounding_box().unwrap();
        assert_eq!((lo, hi), ([0.0; 3], [1.0; 3]));
        assert_eq!(m.centroid().unwrap(), [0.25; 3]);
        // Flipping every face flips the volume.
        let mut flipped = m.clone();
        for f in &mut flipped.faces {
            f.swap(1, 2);
        }
        assert!((flipped.signed_volume() + 1.0 / 6.0).abs() < 1e-15);
    }

    #[test]
    fn zero_area_faces_and_isolated_vertices_get_zero_normals() {
        let m = TriMesh::new(
            vec![[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [5.0, 5.0, 5.0]],
            vec![[0, 1, 2]],
        )
        .unwrap();
        assert_eq!(m.face_normals(), vec![[0.0; 3]]);
        assert_eq!(m.face_areas(), vec![0.0]);
        assert_eq!(m.vertex_normals(), vec![[0.0; 3]; 4]);
        assert_eq!(m.area_centroid(), None);
        assert_eq!(TriMesh::default().bounding_box(), None);
        assert_eq!(TriMesh::default().centroid(), None);
        assert!(!TriMesh::default().is_closed());
    }

    fn check_adjacency_symmetric(a: &Adjacency) {
        for i in 0..a.len() {
            let row = a.neighbors(i);
            assert!(row.windows(2).all(|w| w[0] < w[1]), "row {i} not sorted");
            for &j in row {
                assert_ne!(j as usize, i);
                assert!(a.neighbors(j as usize).binary_search(&(i as u32)).is_ok());
            }
        }
    }

    #[test]
    fn adjacency_is_symmetric_and_consistent() {
        for m in [
            TriMesh::icosphere(2, 1.0).unwrap(),
            TriMesh::grid(5, 4, 1.0, 1.0).unwrap(),
            TriMesh::cube(1.0).unwrap(),
        ] {
            let va = m.vertex_adjacency();
            assert_eq!(va.len(), m.num_vertices());
            check_adjacency_symmetric(&va);
            assert_eq!(va.indices.len(), 2 * m.edges().len());
            for e in m.edges() {
                assert!(va.neighbors(e[0] as usize).contains(&e[1]));
            }
            let fa = m.face_adjacency();
            assert_eq!(fa.len(), m.num_faces());
            check_adjacency_symmetric(&fa);
            let vf = m.vertex_faces();
            assert_eq!(vf.indices.len(), 3 * m.num_faces());
            for (fi, f) in m.faces.iter().enumerate() {
                for &v in f {
                    assert!(vf.neighbors(v as usize).contains(&(fi as u32)));
                }
            }
            for row in vf.iter() {
                assert!(row.windows(2).all(|w| w[0] < w[1]));
            }
            if m.is_closed() {
                assert!((0..fa.len()).all(|f| fa.degree(f) == 3));
            }
        }
        // Icosphere valences: the 12 original vertices have 5 neighbours, the rest 6.
        let va = TriMesh::icosphere(2, 1.0).unwrap().vertex_adjacency();
        let fives = (0..va.len()).filter(|&i| va.degree(i) == 5).count();
        assert_eq!(fives, 12);
        assert!((0..va.len()).all(|i| matches!(va.degree(i), 5 | 6)));
    }

    #[test]
    fn sums_are_independent_of_thread_count() {
        let m = TriMesh::icosphere(5, 1.0).unwrap();
        let run = |threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| (m.total_area(), m.signed_volume(), m.vertex_normals()))
        };
        let a = run(1);
        let b = run(3);
        assert_eq!(a.0.to_bits(), b.0.to_bits());
        assert_eq!(a.1.to_bits(), b.1.to_bits());
        assert_eq!(a.2, b.2);
    }
}
