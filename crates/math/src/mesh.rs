//! [`TriMesh`]: an indexed triangle mesh with optional per-vertex normals and colours,
//! connectivity queries ([`Adjacency`]), area / volume / normal computations, generators for
//! test and demo surfaces, and OBJ / PLY file IO.
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
//! # Files
//!
//! - Wavefront OBJ: [`TriMesh::read_obj`] / [`TriMesh::write_obj`]. `v x y z [r g b]`, `vn`,
//!   and `f` lines (with `v`, `v/t`, `v//n`, `v/t/n` corners, negative = relative indices);
//!   polygons are triangulated as fans; groups, objects, materials, texture coordinates and
//!   every other statement are ignored. The reader is a small one written here rather than the
//!   `tobj` crate: `tobj` 4 (as configured in this workspace, without its `use_f64` feature)
//!   parses coordinates as `f32`, renumbers vertices in order of first use, drops vertices no
//!   face uses, and duplicates the vertices shared between `g`/`o` groups (which opens closed
//!   meshes). This reader keeps the file's vertices, their order and their `f64` values.
//! - Stanford PLY (ASCII, binary little and big endian): [`TriMesh::read_ply`] /
//!   [`TriMesh::write_ply`], parsed with `ply-rs`. The binary payload is written here because
//!   `ply-rs` 0.1.3 writes wrong list lengths in binary files.
//! - [`TriMesh::read`] / [`TriMesh::write`] pick the format from the file extension.
//!
//! Readers never modify their input, report every malformed, truncated or empty file as an
//! error naming the path ([`Error::Format`]; [`Error::Io`] when the file cannot be read), and
//! check the element counts announced by a PLY header against the size of the file before
//! reading, so a hostile header cannot make them allocate without bound.

use std::collections::HashMap;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

use ply_rs::parser::Parser as PlyParser;
use ply_rs::ply::{
    Addable, ElementDef, Encoding, Header, Property, PropertyAccess, PropertyDef, PropertyType,
    ScalarType,
};
use ply_rs::writer::Writer as PlyWriter;
use rayon::prelude::*;

use crate::error::{ensure_finite, ensure_positive, read_file, Error, Result};
use crate::reduce::{chunked_sum, SUM_CHUNK};
use crate::vec3::{add, cross, dot, norm, normalized_or_zero, sub};

/// Largest subdivision level accepted by [`TriMesh::icosphere`] (level 10 has 10,485,762
/// vertices and 20,971,520 faces).
pub const MAX_ICOSPHERE_SUBDIVISIONS: u32 = 10;

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

    // --------------------------------------------------------------------------------------
    // Generators
    // --------------------------------------------------------------------------------------

    /// A geodesic sphere of radius `radius` centred at the origin: the regular icosahedron
    /// with every triangle split `subdivisions` times into four, new vertices projected onto
    /// the sphere. Closed and outward oriented, with `10 * 4^k + 2` vertices,
    /// `30 * 4^k` edges and `20 * 4^k` faces for `k = subdivisions`. No normals or colours
    /// (see [`TriMesh::compute_vertex_normals`]).
    ///
    /// Errors: `radius` not finite and > 0, or `subdivisions` above
    /// [`MAX_ICOSPHERE_SUBDIVISIONS`] ([`Error::InvalidArgument`]).
    pub fn icosphere(subdivisions: u32, radius: f64) -> Result<Self> {
        ensure_positive("radius", radius)?;
        if subdivisions > MAX_ICOSPHERE_SUBDIVISIONS {
            return Err(Error::invalid(
                "subdivisions",
                format!(
                    "must be at most {MAX_ICOSPHERE_SUBDIVISIONS}, got {subdivisions} \
                     (the mesh grows by 4x per level)"
                ),
            ));
        }
        let t = (1.0 + 5.0f64.sqrt()) / 2.0;
        let mut positions: Vec<[f64; 3]> = [
            [-1.0, t, 0.0],
            [1.0, t, 0.0],
            [-1.0, -t, 0.0],
            [1.0, -t, 0.0],
            [0.0, -1.0, t],
            [0.0, 1.0, t],
            [0.0, -1.0, -t],
            [0.0, 1.0, -t],
            [t, 0.0, -1.0],
            [t, 0.0, 1.0],
            [-t, 0.0, -1.0],
            [-t, 0.0, 1.0],
        ]
        .into_iter()
        .map(normalized_or_zero)
        .collect();
        let mut faces: Vec<[u32; 3]> = vec![
            [0, 11, 5],
            [0, 5, 1],
            [0, 1, 7],
            [0, 7, 10],
            [0, 10, 11],
            [1, 5, 9],
            [5, 11, 4],
            [11, 10, 2],
            [10, 7, 6],
            [7, 1, 8],
            [3, 9, 4],
            [3, 4, 2],
            [3, 2, 6],
            [3, 6, 8],
            [3, 8, 9],
            [4, 9, 5],
            [2, 4, 11],
            [6, 2, 10],
            [8, 6, 7],
            [9, 8, 1],
        ];
        for _ in 0..subdivisions {
            let mut mid: HashMap<u64, u32> = HashMap::with_capacity(faces.len() * 3 / 2);
            let mut midpoint = |a: u32, b: u32, positions: &mut Vec<[f64; 3]>| -> u32 {
                *mid.entry(edge_key(a, b)).or_insert_with(|| {
                    let p = add(positions[a as usize], positions[b as usize]);
                    positions.push(normalized_or_zero(p));
                    (positions.len() - 1) as u32
                })
            };
            let mut next = Vec::with_capacity(faces.len() * 4);
            for &[a, b, c] in &faces {
                let ab = midpoint(a, b, &mut positions);
                let bc = midpoint(b, c, &mut positions);
                let ca = midpoint(c, a, &mut positions);
                next.extend_from_slice(&[[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
            }
            faces = next;
        }
        positions
            .par_iter_mut()
            .with_min_len(PAR_MIN_LEN)
            .for_each(|p| *p = [p[0] * radius, p[1] * radius, p[2] * radius]);
        TriMesh::new(positions, faces)
    }

    /// An axis-aligned cube of edge length `size` centred at the origin (corners at
    /// `+-size / 2`): 8 vertices, 12 triangles, closed and outward oriented.
    ///
    /// Errors: `size` not finite and > 0 ([`Error::InvalidArgument`]).
    pub fn cube(size: f64) -> Result<Self> {
        ensure_positive("size", size)?;
        let h = 0.5 * size;
        // Vertex i has x = bit 0, y = bit 1, z = bit 2.
        let positions = (0..8u32)
            .map(|i| {
                let c = |bit: u32| if i & (1 << bit) != 0 { h } else { -h };
                [c(0), c(1), c(2)]
            })
            .collect();
        let faces = vec![
            [0, 2, 1], // -z
            [1, 2, 3],
            [4, 5, 6], // +z
            [5, 7, 6],
            [0, 1, 5], // -y
            [0, 5, 4],
            [2, 6, 7], // +y
            [2, 7, 3],
            [0, 4, 6], // -x
            [0, 6, 2],
            [1, 3, 7], // +x
            [1, 7, 5],
        ];
        TriMesh::new(positions, faces)
    }

    /// A flat rectangular sheet in the plane `z = 0` covering `[0, width] x [0, height]`,
    /// split into `nx x ny` square-cornered cells of two triangles each (every cell cut along
    /// the same diagonal), with normals along `+z`. Open (not closed), useful for cloth.
    ///
    /// Vertex `(i, j)`, `0 <= i <= nx`, `0 <= j <= ny`, has index `j * (nx + 1) + i` and
    /// position `(i * width / nx, j * height / ny, 0)`; there are `(nx + 1) * (ny + 1)`
    /// vertices, `2 * nx * ny` faces and `2 * (nx + ny)` boundary edges.
    ///
    /// Errors: `nx` or `ny` zero, `width` or `height` not finite and > 0
    /// ([`Error::InvalidArgument`]); more than `u32::MAX` vertices or faces
    /// ([`Error::LimitExceeded`]).
    pub fn grid(nx: usize, ny: usize, width: f64, height: f64) -> Result<Self> {
        if nx == 0 {
            return Err(Error::invalid("nx", "must be at least 1 cell"));
        }
        if ny == 0 {
            return Err(Error::invalid("ny", "must be at least 1 cell"));
        }
        ensure_positive("width", width)?;
        ensure_positive("height", height)?;
        let too_big = || {
            Error::LimitExceeded(format!(
                "a {nx} x {ny} grid has more than {} vertices or faces",
                u32::MAX
            ))
        };
        let nv = (nx + 1)
            .checked_mul(ny + 1)
            .filter(|&n| n <= u32::MAX as usize)
            .ok_or_else(too_big)?;
        nx.checked_mul(ny)
            .and_then(|c| c.checked_mul(2))
            .filter(|&n| n <= u32::MAX as usize)
            .ok_or_else(too_big)?;
        let positions: Vec<[f64; 3]> = (0..nv)
            .into_par_iter()
            .with_min_len(PAR_MIN_LEN)
            .map(|k| {
                let (i, j) = (k % (nx + 1), k / (nx + 1));
                [
                    i as f64 * width / nx as f64,
                    j as f64 * height / ny as f64,
                    0.0,
                ]
            })
            .collect();
        let faces: Vec<[u32; 3]> = (0..nx * ny)
            .into_par_iter()
            .with_min_len(PAR_MIN_LEN)
            .flat_map_iter(|c| {
                let (i, j) = (c % nx, c / nx);
                let v00 = (j * (nx + 1) + i) as u32;
                let v10 = v00 + 1;
                let v01 = v00 + nx as u32 + 1;
                let v11 = v01 + 1;
                [[v00, v10, v11], [v00, v11, v01]]
            })
            .collect();
        TriMesh::new(positions, faces)
    }

    // --------------------------------------------------------------------------------------
    // File IO
    // --------------------------------------------------------------------------------------

    /// Reads an `.obj` or `.ply` file, chosen by the (case-insensitive) extension; see
    /// [`TriMesh::read_obj`] and [`TriMesh::read_ply`].
    ///
    /// Errors: another or no extension ([`Error::UnsupportedFormat`] naming it); otherwise as
    /// the reader.
    pub fn read(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        match MeshFormat::from_path(path)? {
            MeshFormat::Obj => TriMesh::read_obj(path),
            MeshFormat::Ply => TriMesh::read_ply(path),
        }
    }

    /// Writes an `.obj` or `.ply` file (PLY as binary little endian), chosen by the
    /// (case-insensitive) extension; see [`TriMesh::write_obj`] and [`TriMesh::write_ply`].
    ///
    /// Errors: another or no extension ([`Error::UnsupportedFormat`] naming it); otherwise as
    /// the writer.
    pub fn write(&self, path: impl AsRef<Path>) -> Result<()> {
        let path = path.as_ref();
        match MeshFormat::from_path(path)? {
            MeshFormat::Obj => self.write_obj(path),
            MeshFormat::Ply => self.write_ply(path, PlyEncoding::BinaryLittleEndian),
        }
    }

    /// Reads a Wavefront OBJ file.
    ///
    /// - `v x y z`, `v x y z w` (divided by `w`) or `v x y z r g b` lines give the vertices in
    ///   file order. Colours are kept when every vertex has one; they are taken as `[0, 1]`
    ///   values, or as `0..=255` values (divided by 255) when any component exceeds 1.
    /// - `f` lines with three or more corners (`v`, `v/t`, `v//n` or `v/t/n`; 1-based, or
    ///   negative for relative to the latest vertex) give the faces; polygons are split into a
    ///   fan of triangles around their first corner.
    /// - Normals (`vn`) are kept when they are per vertex: every vertex's corners all name the
    ///   same normal (vertices no face uses get the zero vector), or no corner names one and
    ///   there are exactly as many `vn` as `v` lines. Per-corner normals are dropped.
    /// - Everything else (`vt`, `o`, `g`, `s`, `usemtl`, `mtllib`, `l`, `p`, comments...) is
    ///   ignored; no other file is opened.
    ///
    /// Errors: the file cannot be read ([`Error::Io`]); a malformed number or index, an index
    /// of 0 or out of range, a face with fewer than three corners or a repeated vertex, a
    /// non-finite coordinate, colours on only some vertices, or no vertices or no faces
    /// ([`Error::Format`] naming the path).
    pub fn read_obj(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let bytes = read_file(path)?;
        let text = String::from_utf8_lossy(&bytes);
        parse_obj(&text).map_err(|reason| Error::format(path, reason))
    }

    /// Writes a Wavefront OBJ file: `v x y z` lines (followed by ` r g b` when the mesh has
    /// colours), `vn` lines when it has normals, then `f a b c` lines (`f a//a b//b c//c`
    /// with normals) with 1-based indices. Numbers are written in Rust's shortest round-trip
    /// form, so [`TriMesh::read_obj`] gives back the same `f64` positions and normals and the
    /// same `f32` colours.
    ///
    /// Errors: an invalid mesh (see [`TriMesh::validate`]); a mesh without faces
    /// ([`Error::Empty`], as such a file could not be read back); a failed write
    /// ([`Error::Io`]).
    pub fn write_obj(&self, path: impl AsRef<Path>) -> Result<()> {
        let path = path.as_ref();
        self.check_writable()?;
        let io = |e| Error::io(path, e);
        let file = File::create(path).map_err(io)?;
        let mut out = BufWriter::new(file);
        self.write_obj_to(&mut out).map_err(io)?;
        out.flush().map_err(io)
    }

    fn write_obj_to(&self, out: &mut impl Write) -> std::io::Result<()> {
        writeln!(out, "# written by wscg-math")?;
        writeln!(
            out,
            "# {} vertices, {} faces",
            self.positions.len(),
            self.faces.len()
        )?;
        match &self.colors {
            Some(colors) => {
                for (p, c) in self.positions.iter().zip(colors) {
                    writeln!(
                        out,
                        "v {:?} {:?} {:?} {:?} {:?} {:?}",
                        p[0], p[1], p[2], c[0], c[1], c[2]
                    )?;
                }
            }
            None => {
                for p in &self.positions {
                    writeln!(out, "v {:?} {:?} {:?}", p[0], p[1], p[2])?;
                }
            }
        }
        if let Some(normals) = &self.normals {
            for n in normals {
                writeln!(out, "vn {:?} {:?} {:?}", n[0], n[1], n[2])?;
            }
            for f in &self.faces {
                let (a, b, c) = (f[0] + 1, f[1] + 1, f[2] + 1);
                writeln!(out, "f {a}//{a} {b}//{b} {c}//{c}")?;
            }
        } else {
            for f in &self.faces {
                writeln!(out, "f {} {} {}", f[0] + 1, f[1] + 1, f[2] + 1)?;
            }
        }
        Ok(())
    }

    /// Reads a Stanford PLY file (ASCII, binary little endian or binary big endian).
    ///
    /// - The `vertex` element must have scalar `x`, `y`, `z` properties (any numeric type).
    ///   Optional `nx`, `ny`, `nz` give normals; optional `red`, `green`, `blue` (or
    ///   `diffuse_red`, ...) give colours: `uchar` divided by 255, `ushort` by 65535, `float`
    ///   or `double` taken as `[0, 1]` values.
    /// - The `face` element must have an integer list property `vertex_indices` (or
    ///   `vertex_index`); polygons are split into a fan of triangles around their first corner.
    /// - Other elements and properties are skipped.
    ///
    /// Errors: the file cannot be read ([`Error::Io`]); a malformed header, element counts
    /// that the file is too small to hold, truncated or malformed data, missing `vertex` /
    /// `face` elements or `x`/`y`/`z`/`vertex_indices` properties, an index out of range, a
    /// face with fewer than three corners or a repeated vertex, a non-finite coordinate, a
    /// colour outside `[0, 1]`, or no vertices or no faces ([`Error::Format`] naming the
    /// path).
    pub fn read_ply(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let bytes = read_file(path)?;
        // `ply-rs` is fed only headers that passed `check_ply_header_numbers`; the
        // catch_unwind is a second line of defence against a panic inside the parser.
        let parsed = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| parse_ply(&bytes)))
            .unwrap_or_else(|_| Err("the PLY parser failed on malformed input".to_string()));
        parsed.map_err(|reason| Error::format(path, reason))
    }

    /// Writes a Stanford PLY file with the given encoding: a `vertex` element with `double`
    /// `x y z` (and `nx ny nz` with normals, `uchar` `red green blue` with colours, rounded to
    /// the nearest multiple of 1/255), and a `face` element with a `list uchar int
    /// vertex_indices` property.
    ///
    /// Errors: an invalid mesh (see [`TriMesh::validate`]); a mesh without faces
    /// ([`Error::Empty`], as such a file could not be read back); more than `i32::MAX`
    /// vertices ([`Error::LimitExceeded`]); a failed write ([`Error::Io`]).
    pub fn write_ply(&self, path: impl AsRef<Path>, encoding: PlyEncoding) -> Result<()> {
        let path = path.as_ref();
        self.check_writable()?;
        if self.positions.len() > i32::MAX as usize {
            return Err(Error::LimitExceeded(format!(
                "PLY `int` vertex indices hold at most {} vertices, the mesh has {}",
                i32::MAX,
                self.positions.len()
            )));
        }
        let io = |e| Error::io(path, e);
        let file = File::create(path).map_err(io)?;
        let mut out = BufWriter::new(file);
        self.write_ply_to(&mut out, encoding).map_err(io)?;
        out.flush().map_err(io)
    }

    fn write_ply_to(&self, out: &mut impl Write, encoding: PlyEncoding) -> std::io::Result<()> {
        let mut header = Header::new();
        header.encoding = match encoding {
            PlyEncoding::Ascii => Encoding::Ascii,
            PlyEncoding::BinaryLittleEndian => Encoding::BinaryLittleEndian,
        };
        header.comments.push("written by wscg-math".to_string());
        let scalar =
            |name: &str, t: ScalarType| PropertyDef::new(name.to_string(), PropertyType::Scalar(t));
        let mut vertex = ElementDef::new("vertex".to_string());
        vertex.count = self.positions.len();
        for name in ["x", "y", "z"] {
            vertex.properties.add(scalar(name, ScalarType::Double));
        }
        if self.normals.is_some() {
            for name in ["nx", "ny", "nz"] {
                vertex.properties.add(scalar(name, ScalarType::Double));
            }
        }
        if self.colors.is_some() {
            for name in ["red", "green", "blue"] {
                vertex.properties.add(scalar(name, ScalarType::UChar));
            }
        }
        header.elements.add(vertex);
        let mut face = ElementDef::new("face".to_string());
        face.count = self.faces.len();
        face.properties.add(PropertyDef::new(
            "vertex_indices".to_string(),
            PropertyType::List(ScalarType::UChar, ScalarType::Int),
        ));
        header.elements.add(face);
        PlyWriter::<PlySkip>::new().write_header(out, &header)?;

        let to_u8 = |c: f32| (c.clamp(0.0, 1.0) * 255.0).round() as u8;
        let normals = self.normals.as_deref();
        let colors = self.colors.as_deref();
        match encoding {
            PlyEncoding::Ascii => {
                for (i, p) in self.positions.iter().enumerate() {
                    write!(out, "{:?} {:?} {:?}", p[0], p[1], p[2])?;
                    if let Some(n) = normals {
                        let n = n[i];
                        write!(out, " {:?} {:?} {:?}", n[0], n[1], n[2])?;
                    }
                    if let Some(c) = colors {
                        let c = c[i];
                        write!(out, " {} {} {}", to_u8(c[0]), to_u8(c[1]), to_u8(c[2]))?;
                    }
                    writeln!(out)?;
                }
                for f in &self.faces {
                    writeln!(out, "3 {} {} {}", f[0], f[1], f[2])?;
                }
            }
            PlyEncoding::BinaryLittleEndian => {
                for (i, p) in self.positions.iter().enumerate() {
                    for v in p {
                        out.write_all(&v.to_le_bytes())?;
                    }
                    if let Some(n) = normals {
                        for v in n[i] {
                            out.write_all(&v.to_le_bytes())?;
                        }
                    }
                    if let Some(c) = colors {
                        let c = c[i];
                        out.write_all(&[to_u8(c[0]), to_u8(c[1]), to_u8(c[2])])?;
                    }
                }
                for f in &self.faces {
                    out.write_all(&[3u8])?;
                    for &i in f {
                        // Fits: the vertex count was checked against i32::MAX.
                        out.write_all(&(i as i32).to_le_bytes())?;
                    }
                }
            }
        }
        Ok(())
    }

    /// Validation shared by the writers.
    fn check_writable(&self) -> Result<()> {
        self.validate()?;
        if self.faces.is_empty() {
            return Err(Error::Empty("faces"));
        }
        Ok(())
    }
}

/// Payload encoding of a PLY file written by [`TriMesh::write_ply`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum PlyEncoding {
    /// Human-readable text.
    Ascii,
    /// Little-endian binary (compact and fast; the default).
    #[default]
    BinaryLittleEndian,
}

/// Mesh file formats known to [`TriMesh::read`] and [`TriMesh::write`].
enum MeshFormat {
    Obj,
    Ply,
}

impl MeshFormat {
    fn from_path(path: &Path) -> Result<Self> {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        match ext.as_deref() {
            Some("obj") => Ok(MeshFormat::Obj),
            Some("ply") => Ok(MeshFormat::Ply),
            Some(other) => Err(Error::UnsupportedFormat(format!(
                "mesh file extension `.{other}` of {}; supported: .obj, .ply",
                path.display()
            ))),
            None => Err(Error::UnsupportedFormat(format!(
                "mesh file {} has no extension; supported: .obj, .ply",
                path.display()
            ))),
        }
    }
}

// ------------------------------------------------------------------------------------------
// OBJ parsing
// ------------------------------------------------------------------------------------------

/// Resolves a 1-based or negative (relative to `count` items so far) OBJ index to 0-based.
fn obj_index(tok: &str, count: usize, what: &str, line: usize) -> std::result::Result<u32, String> {
    let i: i64 = tok
        .parse()
        .map_err(|_| format!("line {line}: `{tok}` is not a valid {what} index"))?;
    let r = match i {
        0 => {
            return Err(format!(
                "line {line}: {what} index 0 is invalid (OBJ indices start at 1)"
            ))
        }
        i if i > 0 => i - 1,
        i => count as i64 + i,
    };
    if r < 0 || r >= i64::from(u32::MAX) {
        return Err(format!(
            "line {line}: {what} index {i} is out of range ({count} defined so far)"
        ));
    }
    Ok(r as u32)
}

fn parse_f64(tok: &str, line: usize) -> std::result::Result<f64, String> {
    tok.parse()
        .map_err(|_| format!("line {line}: `{tok}` is not a number"))
}

/// Parses OBJ text into a mesh; errors are reasons without the path.
fn parse_obj(text: &str) -> std::result::Result<TriMesh, String> {
    let mut positions: Vec<[f64; 3]> = Vec::new();
    let mut colors: Vec<[f32; 3]> = Vec::new(); // aligned with positions, zero when absent
    let mut num_colored = 0usize;
    let mut normals: Vec<[f64; 3]> = Vec::new();
    let mut faces: Vec<[u32; 3]> = Vec::new();
    // (vertex, normal) for every face corner that names a normal.
    let mut corner_normals: Vec<(u32, u32)> = Vec::new();
    let mut corner_without_normal = false;
    let mut corners: Vec<(u32, Option<u32>)> = Vec::new();

    let mut joined = String::new();
    let mut line_no = 0usize;
    let mut lines = text.lines();
    loop {
        // Join lines ending in a backslash (line continuation).
        joined.clear();
        let Some(first) = lines.next() else { break };
        line_no += 1;
        let start_line = line_no;
        joined.push_str(first);
        while joined.ends_with('\\') {
            joined.pop();
            joined.push(' ');
            match lines.next() {
                Some(next) => {
                    line_no += 1;
                    joined.push_str(next);
                }
                None => break,
            }
        }
        let content = match joined.find('#') {
            Some(k) => &joined[..k],
            None => &joined[..],
        };
        let mut words = content.split_whitespace();
        let Some(keyword) = words.next() else {
            continue;
        };
        let line = start_line;
        match keyword {
            "v" => {
                let toks: Vec<&str> = words.collect();
                let xyz = |k: usize| parse_f64(toks[k], line);
                let (p, c) = match toks.len() {
                    3 => ([xyz(0)?, xyz(1)?, xyz(2)?], None),
                    4 => {
                        let w = xyz(3)?;
                        if w == 0.0 || !w.is_finite() {
                            return Err(format!("line {line}: vertex weight w = {w} is invalid"));
                        }
                        ([xyz(0)? / w, xyz(1)? / w, xyz(2)? / w], None)
                    }
                    6 => {
                        // Colours parse directly as f32, so written f32 values come back exactly.
                        let rgb = |k: usize| {
                            toks[k]
                                .parse::<f32>()
                                .map_err(|_| format!("line {line}: `{}` is not a number", toks[k]))
                        };
                        (
                            [xyz(0)?, xyz(1)?, xyz(2)?],
                            Some([rgb(3)?, rgb(4)?, rgb(5)?]),
                        )
                    }
                    n => {
                        return Err(format!(
                            "line {line}: a `v` line needs 3, 4 (x y z w) or 6 (x y z r g b) \
                             numbers, found {n}"
                        ))
                    }
                };
                if positions.len() >= u32::MAX as usize {
                    return Err(format!("more than {} vertices", u32::MAX));
                }
                positions.push(p);
                match c {
                    Some(c) => {
                        colors.push(c);
                        num_colored += 1;
                    }
                    None => colors.push([0.0; 3]),
                }
            }
            "vn" => {
                let vals = words
                    .map(|w| parse_f64(w, line))
                    .collect::<std::result::Result<Vec<f64>, String>>()?;
                if vals.len() != 3 {
                    return Err(format!(
                        "line {line}: a `vn` line needs 3 numbers, found {}",
                        vals.len()
                    ));
                }
                normals.push([vals[0], vals[1], vals[2]]);
            }
            "f" => {
                corners.clear();
                for w in words {
                    let mut parts = w.split('/');
                    let v = obj_index(parts.next().unwrap_or(""), positions.len(), "vertex", line)?;
                    let _texcoord = parts.next();
                    let n = match parts.next() {
                        Some(s) if !s.is_empty() => {
                            Some(obj_index(s, normals.len(), "normal", line)?)
                        }
                        _ => None,
                    };
                    if parts.next().is_some() {
                        return Err(format!("line {line}: malformed face corner `{w}`"));
                    }
                    corners.push((v, n));
                }
                if corners.len() < 3 {
                    return Err(format!(
                        "line {line}: a face needs at least 3 vertices, found {}",
                        corners.len()
                    ));
                }
                for &(v, n) in &corners {
                    match n {
                        Some(n) => corner_normals.push((v, n)),
                        None => corner_without_normal = true,
                    }
                }
                let a = corners[0].0;
                for k in 1..corners.len() - 1 {
                    faces.push([a, corners[k].0, corners[k + 1].0]);
                }
            }
            _ => {}
        }
    }

    if positions.is_empty() {
        return Err("the file has no vertices (`v` lines)".to_string());
    }
    if faces.is_empty() {
        return Err("the file has no faces (`f` lines)".to_string());
    }
    let nv = positions.len();

    if let Some(&(_, n)) = corner_normals
        .iter()
        .find(|&&(_, n)| n as usize >= normals.len())
    {
        return Err(format!(
            "a face refers to normal {} but the file has {} `vn` lines",
            u64::from(n) + 1,
            normals.len()
        ));
    }
    let vertex_normals = if !corner_normals.is_empty() && !corner_without_normal {
        const NONE: u32 = u32::MAX;
        let mut slot = vec![NONE; nv];
        let mut per_vertex = true;
        for &(v, n) in &corner_normals {
            // Out-of-range vertices are reported by TriMesh::new below.
            let Some(s) = slot.get_mut(v as usize) else {
                continue;
            };
            if *s == NONE {
                *s = n;
            } else if *s != n && normals[*s as usize] != normals[n as usize] {
                per_vertex = false;
                break;
            }
        }
        per_vertex.then(|| {
            slot.iter()
                .map(|&s| {
                    if s == NONE {
                        [0.0; 3]
                    } else {
                        normals[s as usize]
                    }
                })
                .collect::<Vec<_>>()
        })
    } else if corner_normals.is_empty() && normals.len() == nv {
        Some(normals)
    } else {
        None
    };

    let mut mesh = TriMesh::new(positions, faces).map_err(|e| e.to_string())?;
    if let Some(n) = vertex_normals {
        mesh = mesh.with_normals(n).map_err(|e| e.to_string())?;
    }
    if num_colored > 0 {
        if num_colored != nv {
            return Err(format!(
                "only {num_colored} of the {nv} vertices have a colour"
            ));
        }
        if colors.as_flattened().iter().any(|&c| c > 1.0) {
            for c in colors.as_flattened_mut() {
                *c /= 255.0;
            }
        }
        mesh = mesh.with_colors(colors).map_err(|e| e.to_string())?;
    }
    Ok(mesh)
}

// ------------------------------------------------------------------------------------------
// PLY parsing
// ------------------------------------------------------------------------------------------

/// Element type for PLY elements we skip (and for the header writer): stores nothing.
struct PlySkip;

impl PropertyAccess for PlySkip {
    fn new() -> Self {
        PlySkip
    }
}

/// Slots of [`PlyVertex::values`].
const PLY_VERTEX_SLOTS: [&[&str]; 9] = [
    &["x"],
    &["y"],
    &["z"],
    &["nx"],
    &["ny"],
    &["nz"],
    &["red", "diffuse_red"],
    &["green", "diffuse_green"],
    &["blue", "diffuse_blue"],
];

/// One PLY vertex: x y z nx ny nz r g b as read (colours not yet scaled).
struct PlyVertex {
    values: [f64; 9],
}

fn scalar_to_f64(p: &Property) -> Option<f64> {
    Some(match *p {
        Property::Char(v) => f64::from(v),
        Property::UChar(v) => f64::from(v),
        Property::Short(v) => f64::from(v),
        Property::UShort(v) => f64::from(v),
        Property::Int(v) => f64::from(v),
        Property::UInt(v) => f64::from(v),
        Property::Float(v) => f64::from(v),
        Property::Double(v) => v,
        _ => return None,
    })
}

impl PropertyAccess for PlyVertex {
    fn new() -> Self {
        PlyVertex { values: [0.0; 9] }
    }
    fn set_property(&mut self, name: String, property: Property) {
        if let Some(slot) = PLY_VERTEX_SLOTS
            .iter()
            .position(|names| names.contains(&name.as_str()))
        {
            if let Some(v) = scalar_to_f64(&property) {
                self.values[slot] = v;
            }
        }
    }
}

/// One PLY face: its index list as read.
struct PlyFace {
    indices: Option<Property>,
}

impl PropertyAccess for PlyFace {
    fn new() -> Self {
        PlyFace { indices: None }
    }
    fn set_property(&mut self, name: String, property: Property) {
        if name == "vertex_indices" || name == "vertex_index" {
            self.indices = Some(property);
        }
    }
}

/// Appends the integer list `p` to `out` as `i64`.
fn list_to_i64(p: &Property, out: &mut Vec<i64>) -> std::result::Result<(), String> {
    out.clear();
    match p {
        Property::ListChar(v) => out.extend(v.iter().map(|&x| i64::from(x))),
        Property::ListUChar(v) => out.extend(v.iter().map(|&x| i64::from(x))),
        Property::ListShort(v) => out.extend(v.iter().map(|&x| i64::from(x))),
        Property::ListUShort(v) => out.extend(v.iter().map(|&x| i64::from(x))),
        Property::ListInt(v) => out.extend(v.iter().map(|&x| i64::from(x))),
        Property::ListUInt(v) => out.extend(v.iter().map(|&x| i64::from(x))),
        _ => return Err("face vertex indices must be a list of integers".to_string()),
    }
    Ok(())
}

fn scalar_size(t: &ScalarType) -> usize {
    match t {
        ScalarType::Char | ScalarType::UChar => 1,
        ScalarType::Short | ScalarType::UShort => 2,
        ScalarType::Int | ScalarType::UInt | ScalarType::Float => 4,
        ScalarType::Double => 8,
    }
}

/// Checks the header lines of a PLY file (up to `end_header`) before `ply-rs` sees them:
/// the file must start with `ply`, and lines other than comments must not hold numbers of 20
/// or more digits (`ply-rs` 0.1.3 panics when an element count or version overflows `u64`).
fn check_ply_header_numbers(bytes: &[u8]) -> std::result::Result<(), String> {
    if !bytes.starts_with(b"ply") {
        return Err("not a PLY file (it does not start with `ply`)".to_string());
    }
    for line in bytes.split(|&b| b == b'\n') {
        let line = line.strip_suffix(b"\r").unwrap_or(line);
        if line.starts_with(b"end_header") {
            return Ok(());
        }
        if line.starts_with(b"comment") || line.starts_with(b"obj_info") {
            continue;
        }
        let longest_digit_run = line
            .split(|b| !b.is_ascii_digit())
            .map(<[u8]>::len)
            .max()
            .unwrap_or(0);
        if longest_digit_run >= 20 {
            return Err(format!(
                "header line `{}` holds a number too large for this reader",
                String::from_utf8_lossy(&line[..line.len().min(80)])
            ));
        }
    }
    Err("the PLY header has no `end_header` line".to_string())
}

/// Checks that `payload_len` bytes can hold the elements the header announces: every element
/// needs at least its fixed-size part (binary) or two characters per property (ASCII), and at
/// least one byte.
fn check_ply_counts(header: &Header, payload_len: usize) -> std::result::Result<(), String> {
    let mut need = 0usize;
    for (name, e) in &header.elements {
        let per = match header.encoding {
            Encoding::Ascii => 2 * e.properties.len(),
            _ => e
                .properties
                .values()
                .map(|p| match &p.data_type {
                    PropertyType::Scalar(t) => scalar_size(t),
                    PropertyType::List(count_type, _) => scalar_size(count_type),
                })
                .sum(),
        }
        .max(1);
        need = e
            .count
            .checked_mul(per)
            .and_then(|b| need.checked_add(b))
            .ok_or_else(|| format!("the header announces an absurd number of `{name}` elements"))?;
    }
    // An ASCII file may lack the final newline.
    let slack = usize::from(header.encoding == Encoding::Ascii);
    if need > payload_len + slack {
        let counts: Vec<String> = header
            .elements
            .values()
            .map(|e| format!("{} {}", e.count, e.name))
            .collect();
        return Err(format!(
            "the header announces {} needing at least {need} bytes, but only {payload_len} \
             bytes follow the header (truncated file or corrupt header)",
            counts.join(", ")
        ));
    }
    Ok(())
}

/// Scale of a colour property of type `t` to `[0, 1]`.
fn color_scale(t: &PropertyType, name: &str) -> std::result::Result<f64, String> {
    match t {
        PropertyType::Scalar(ScalarType::UChar) => Ok(1.0 / 255.0),
        PropertyType::Scalar(ScalarType::UShort) => Ok(1.0 / 65535.0),
        PropertyType::Scalar(ScalarType::Float | ScalarType::Double) => Ok(1.0),
        other => Err(format!(
            "vertex colour property `{name}` has unsupported type {other:?} (expected uchar, \
             ushort, float or double)"
        )),
    }
}

/// Parses a PLY file held in memory; errors are reasons without the path.
fn parse_ply(bytes: &[u8]) -> std::result::Result<TriMesh, String> {
    check_ply_header_numbers(bytes)?;
    let mut reader: &[u8] = bytes;
    let header = PlyParser::<PlySkip>::new()
        .read_header(&mut reader)
        .map_err(|e| format!("invalid PLY header: {e}"))?;
    check_ply_counts(&header, reader.len())?;

    let vdef = header
        .elements
        .get("vertex")
        .ok_or("the file has no `vertex` element")?;
    for axis in ["x", "y", "z"] {
        match vdef.properties.get(axis) {
            Some(p) if matches!(p.data_type, PropertyType::Scalar(_)) => {}
            Some(_) => return Err(format!("vertex property `{axis}` must be a scalar")),
            None => return Err(format!("the `vertex` element has no `{axis}` property")),
        }
    }
    let has_scalar = |name: &str| {
        matches!(
            vdef.properties.get(name).map(|p| &p.data_type),
            Some(PropertyType::Scalar(_))
        )
    };
    let has_normals = ["nx", "ny", "nz"].iter().all(|n| has_scalar(n));
    let mut color_scales = [0.0f64; 3];
    let mut has_colors = true;
    for (k, slot) in PLY_VERTEX_SLOTS[6..].iter().enumerate() {
        match slot.iter().find_map(|n| vdef.properties.get(*n)) {
            Some(p) => color_scales[k] = color_scale(&p.data_type, &p.name)?,
            None => has_colors = false,
        }
    }
    let fdef = header
        .elements
        .get("face")
        .ok_or("the file has no `face` element")?;
    match ["vertex_indices", "vertex_index"]
        .iter()
        .find_map(|n| fdef.properties.get(*n))
    {
        Some(p) if matches!(p.data_type, PropertyType::List(..)) => {}
        Some(p) => return Err(format!("face property `{}` must be a list", p.name)),
        None => return Err("the `face` element has no `vertex_indices` list property".to_string()),
    }
    if vdef.count == 0 {
        return Err("the file has no vertices".to_string());
    }
    if fdef.count == 0 {
        return Err("the file has no faces".to_string());
    }
    if vdef.count > u32::MAX as usize {
        return Err(format!("more than {} vertices", u32::MAX));
    }

    let mut vertices: Vec<PlyVertex> = Vec::new();
    let mut raw_faces: Vec<PlyFace> = Vec::new();
    for (name, def) in &header.elements {
        let what = |e: std::io::Error| format!("cannot read the `{name}` elements: {e}");
        match name.as_str() {
            "vertex" => {
                vertices = PlyParser::<PlyVertex>::new()
                    .read_payload_for_element(&mut reader, def, &header)
                    .map_err(what)?;
            }
            "face" => {
                raw_faces = PlyParser::<PlyFace>::new()
                    .read_payload_for_element(&mut reader, def, &header)
                    .map_err(what)?;
            }
            _ => {
                PlyParser::<PlySkip>::new()
                    .read_payload_for_element(&mut reader, def, &header)
                    .map_err(what)?;
            }
        }
    }

    let nv = vertices.len();
    let positions: Vec<[f64; 3]> = vertices
        .iter()
        .map(|v| [v.values[0], v.values[1], v.values[2]])
        .collect();
    let mut faces: Vec<[u32; 3]> = Vec::with_capacity(raw_faces.len());
    let mut list: Vec<i64> = Vec::new();
    for (k, f) in raw_faces.iter().enumerate() {
        let p = f
            .indices
            .as_ref()
            .ok_or_else(|| format!("face {k} has no vertex indices"))?;
        list_to_i64(p, &mut list)?;
        if list.len() < 3 {
            return Err(format!(
                "face {k} has {} vertices; a face needs at least 3",
                list.len()
            ));
        }
        if let Some(&i) = list.iter().find(|&&i| i < 0 || i >= nv as i64) {
            return Err(format!(
                "face {k} refers to vertex {i}, but the file has {nv} vertices"
            ));
        }
        let a = list[0] as u32;
        for w in list[1..].windows(2) {
            faces.push([a, w[0] as u32, w[1] as u32]);
        }
    }

    let mut mesh = TriMesh::new(positions, faces).map_err(|e| e.to_string())?;
    if has_normals {
        let normals = vertices
            .iter()
            .map(|v| [v.values[3], v.values[4], v.values[5]])
            .collect();
        mesh = mesh.with_normals(normals).map_err(|e| e.to_string())?;
    }
    if has_colors {
        let colors = vertices
            .iter()
            .map(|v| {
                let c = |k: usize| (v.values[6 + k] * color_scales[k]) as f32;
                [c(0), c(1), c(2)]
            })
            .collect();
        mesh = mesh.with_colors(colors).map_err(|e| e.to_string())?;
    }
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn angle(a: [f64; 3], b: [f64; 3]) -> f64 {
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

    /// Deterministic pseudo-random colours in [0, 1].
    fn colors_for(n: usize) -> Vec<[f32; 3]> {
        let mut s = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 40) as f32 / (1u64 << 24) as f32
        };
        (0..n).map(|_| [next(), next(), next()]).collect()
    }

    fn assert_positions_eq(a: &[[f64; 3]], b: &[[f64; 3]]) {
        assert_eq!(a.len(), b.len());
        for (p, q) in a.iter().zip(b) {
            assert_eq!(p, q);
        }
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

    #[test]
    fn icosphere_counts_topology_and_radius() {
        for k in 0..=3u32 {
            let m = TriMesh::icosphere(k, 2.0).unwrap();
            let p = 4usize.pow(k);
            assert_eq!(m.num_vertices(), 10 * p + 2, "k={k}");
            assert_eq!(m.num_faces(), 20 * p);
            assert_eq!(m.edges().len(), 30 * p);
            assert!(m.is_closed());
            assert!(m.boundary_edges().is_empty());
            assert_eq!(m.euler_characteristic(), 2);
            for q in &m.positions {
                assert!((norm(*q) - 2.0).abs() < 1e-12);
            }
            assert!(m.signed_volume() > 0.0, "outward oriented");
            // Every face normal points away from the centre.
            for (f, n) in m.faces.iter().zip(m.face_normals()) {
                let c = f
                    .iter()
                    .fold([0.0; 3], |a, &i| add(a, m.positions[i as usize]));
                assert!(dot(c, n) > 0.0);
            }
        }
        assert!(TriMesh::icosphere(1, 0.0).is_err());
        assert!(TriMesh::icosphere(1, f64::NAN).is_err());
        assert!(TriMesh::icosphere(MAX_ICOSPHERE_SUBDIVISIONS + 1, 1.0).is_err());
    }

    #[test]
    fn icosphere_area_and_volume_converge() {
        let r = 1.5;
        let area = 4.0 * PI * r * r;
        let vol = 4.0 / 3.0 * PI * r * r * r;
        let mut prev = (f64::INFINITY, f64::INFINITY);
        for k in 1..=4 {
            let m = TriMesh::icosphere(k, r).unwrap();
            let ea = (m.total_area() - area).abs() / area;
            let ev = (m.signed_volume() - vol).abs() / vol;
            // Inscribed polyhedron: both are underestimates that shrink about 4x per level.
            assert!(m.total_area() < area && m.signed_volume() < vol);
            assert!(ea < prev.0 / 3.0 && ev < prev.1 / 3.0, "k={k}: {ea} {ev}");
            prev = (ea, ev);
        }
        // Tolerance at subdivision 4: within 1% (measured: area 0.12%, volume 0.22%).
        assert!(prev.0 < 0.01 && prev.1 < 0.01, "{prev:?}");
    }

    #[test]
    fn icosphere_vertex_normals_are_radial() {
        // At subdivision 4 the area-weighted normals are within 1e-2 rad of the radial
        // direction (the largest deviation is about 6e-3 rad; about 1.2e-2 at level 3).
        let mut m = TriMesh::icosphere(4, 0.7).unwrap();
        m.compute_vertex_normals();
        let normals = m.normals.as_ref().unwrap();
        for (p, n) in m.positions.iter().zip(normals) {
            assert!((norm(*n) - 1.0).abs() < 1e-12);
            assert!(angle(*p, *n) < 1e-2, "{}", angle(*p, *n));
        }
        let c = m.area_centroid().unwrap();
        assert!(norm(c) < 1e-12);
        assert!(norm(m.centroid().unwrap()) < 1e-12);
    }

    #[test]
    fn cube_volume_area_and_orientation() {
        for size in [1.0, 2.5] {
            let m = TriMesh::cube(size).unwrap();
            assert_eq!(m.num_faces(), 12);
            assert_eq!(m.num_vertices(), 8);
            assert_eq!(m.edges().len(), 18);
            assert!((m.signed_volume() - size.powi(3)).abs() < 1e-12);
            assert!((m.total_area() - 6.0 * size * size).abs() < 1e-12);
            assert!(m.is_closed());
            assert_eq!(m.euler_characteristic(), 2);
            for (f, n) in m.faces.iter().zip(m.face_normals()) {
                let c = f
                    .iter()
                    .fold([0.0; 3], |a, &i| add(a, m.positions[i as usize]));
                // Outward and axis aligned.
                assert!(dot(c, n) > 0.0);
                assert_eq!(n.iter().filter(|v| v.abs() == 1.0).count(), 1);
            }
            let (lo, hi) = m.bounding_box().unwrap();
            assert_eq!(lo, [-size / 2.0; 3]);
            assert_eq!(hi, [size / 2.0; 3]);
        }
        assert!(TriMesh::cube(-1.0).is_err());
    }

    #[test]
    fn grid_is_an_open_flat_sheet() {
        let (nx, ny) = (4usize, 3usize);
        let m = TriMesh::grid(nx, ny, 2.0, 1.5).unwrap();
        assert_eq!(m.num_vertices(), (nx + 1) * (ny + 1));
        assert_eq!(m.num_faces(), 2 * nx * ny);
        assert_eq!(m.boundary_edges().len(), 2 * (nx + ny));
        assert!(!m.is_closed());
        assert_eq!(m.euler_characteristic(), 1);
        assert!((m.total_area() - 3.0).abs() < 1e-12);
        assert_eq!(m.signed_volume(), 0.0);
        for n in m.face_normals() {
            assert_eq!(n, [0.0, 0.0, 1.0]);
        }
        for n in m.vertex_normals() {
            assert_eq!(n, [0.0, 0.0, 1.0]);
        }
        assert_eq!(m.positions[nx + 1], [0.0, 0.5, 0.0]);
        assert_eq!(m.positions[(nx + 1) * (ny + 1) - 1], [2.0, 1.5, 0.0]);
        // Boundary vertices are exactly those on the rectangle's border.
        for e in m.boundary_edges() {
            for &v in &e {
                let p = m.positions[v as usize];
                assert!(p[0] == 0.0 || p[0] == 2.0 || p[1] == 0.0 || p[1] == 1.5);
            }
        }
        assert!(TriMesh::grid(0, 3, 1.0, 1.0).is_err());
        assert!(TriMesh::grid(3, 3, 1.0, 0.0).is_err());
        assert!(matches!(
            TriMesh::grid(usize::MAX / 2, 3, 1.0, 1.0).unwrap_err(),
            Error::LimitExceeded(_)
        ));
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

    #[test]
    fn obj_round_trip_preserves_everything() {
        let dir = tempfile::tempdir().unwrap();
        let mut m = TriMesh::icosphere(2, 1.3).unwrap();
        let n = m.num_vertices();
        m = m.with_colors(colors_for(n)).unwrap();
        m.compute_vertex_normals();
        let path = dir.path().join("sphere.obj");
        m.write_obj(&path).unwrap();
        let back = TriMesh::read_obj(&path).unwrap();
        assert_eq!(back, m);
        // Through the dispatcher, without normals or colours.
        let plain = TriMesh::cube(3.0).unwrap();
        let path = dir.path().join("cube.OBJ");
        plain.write(&path).unwrap();
        assert_eq!(TriMesh::read(&path).unwrap(), plain);
    }

    #[test]
    fn ply_round_trip_ascii_and_binary() {
        let dir = tempfile::tempdir().unwrap();
        let mut m = TriMesh::icosphere(2, 0.9).unwrap();
        let n = m.num_vertices();
        m = m.with_colors(colors_for(n)).unwrap();
        m.compute_vertex_normals();
        for enc in [PlyEncoding::Ascii, PlyEncoding::BinaryLittleEndian] {
            let path = dir.path().join(format!("sphere_{enc:?}.ply"));
            m.write_ply(&path, enc).unwrap();
            let back = TriMesh::read_ply(&path).unwrap();
            assert_positions_eq(&back.positions, &m.positions);
            assert_eq!(back.faces, m.faces);
            assert_eq!(back.normals, m.normals);
            let (c0, c1) = (m.colors.as_ref().unwrap(), back.colors.as_ref().unwrap());
            for (a, b) in c0.iter().zip(c1) {
                for k in 0..3 {
                    assert!((a[k] - b[k]).abs() <= 0.5 / 255.0 + 1e-6, "{a:?} {b:?}");
                }
            }
        }
        // Default write is binary; no normals or colours round trip as None.
        let plain = TriMesh::grid(3, 2, 1.0, 1.0).unwrap();
        let path = dir.path().join("grid.ply");
        plain.write(&path).unwrap();
        assert!(std::fs::read(&path)
            .unwrap()
            .windows(20)
            .any(|w| w == b"binary_little_endian"));
        assert_eq!(TriMesh::read(&path).unwrap(), plain);
    }

    #[test]
    fn obj_reader_handles_polygons_relative_indices_groups_and_normals() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("quad.obj");
        let text = "# a unit square as one quad\n\
                    mtllib nothing.mtl\n\
                    o square\n\
                    v 0 0 0\nv 1 0 0\nv 1 1 0\r\nv 0 1 0\n\
                    vt 0 0\n\
                    vn 0 0 1\n\
                    g half\n\
                    usemtl none\n\
                    f -4/1/1 -3/1/1 \\\n  -2/1/1 -1/1/1 # trailing comment\n";
        std::fs::write(&path, text).unwrap();
        let m = TriMesh::read_obj(&path).unwrap();
        assert_eq!(m.faces, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(m.normals, Some(vec![[0.0, 0.0, 1.0]; 4]));
        assert!((m.total_area() - 1.0).abs() < 1e-15);

        // A cube split over groups stays one closed mesh with shared vertices.
        let cube = TriMesh::cube(1.0).unwrap();
        let mut s = String::new();
        for p in &cube.positions {
            s += &format!("v {} {} {}\n", p[0], p[1], p[2]);
        }
        for (k, f) in cube.faces.iter().enumerate() {
            s += &format!(
                "g side{}\nf {} {} {}\n",
                k / 2,
                f[0] + 1,
                f[1] + 1,
                f[2] + 1
            );
        }
        std::fs::write(&path, s).unwrap();
        let back = TriMesh::read_obj(&path).unwrap();
        assert_eq!(back, cube);
        assert!(back.is_closed());

        // 0-255 vertex colours are scaled; per-corner normals are dropped.
        std::fs::write(
            &path,
            "v 0 0 0 255 0 0\nv 1 0 0 0 255 0\nv 0 1 0 0 0 51\nv 1 1 0 0 0 0\n\
             vn 0 0 1\nvn 0 0 -1\nf 1//1 2//1 3//1\nf 2//2 4//2 3//2\n",
        )
        .unwrap();
        let m = TriMesh::read_obj(&path).unwrap();
        assert_eq!(
            m.colors,
            Some(vec![
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 0.2],
                [0.0, 0.0, 0.0]
            ])
        );
        assert_eq!(m.normals, None);
        // Consistent per-vertex normal indices are kept; unused vertices get zero normals.
        std::fs::write(
            &path,
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 9 9 9\nvn 0 0 1\nvn 0 0 -1\nf 1//1 2//1 3//2\n",
        )
        .unwrap();
        let m = TriMesh::read_obj(&path).unwrap();
        assert_eq!(
            m.normals,
            Some(vec![
                [0.0, 0.0, 1.0],
                [0.0, 0.0, 1.0],
                [0.0, 0.0, -1.0],
                [0.0; 3]
            ])
        );
    }

    #[test]
    fn obj_reader_rejects_bad_files() {
        let dir = tempfile::tempdir().unwrap();
        let cases: &[(&str, &str)] = &[
            ("out_of_range", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n"),
            ("zero_index", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n"),
            (
                "relative_too_far",
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n",
            ),
            ("repeated", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 2\n"),
            ("two_corners", "v 0 0 0\nv 1 0 0\nf 1 2\n"),
            ("bad_number", "v 0 zero 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
            ("non_finite", "v 0 inf 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
            ("no_faces", "v 0 0 0\nv 1 0 0\nv 0 1 0\n"),
            ("no_vertices", "# nothing\n"),
            ("empty", ""),
            ("some_colours", "v 0 0 0 1 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
            (
                "bad_normal",
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//2\n",
            ),
            ("w_zero", "v 0 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
        ];
        for (name, text) in cases {
            let path = dir.path().join(format!("{name}.obj"));
            std::fs::write(&path, text).unwrap();
            let e = TriMesh::read_obj(&path).unwrap_err();
            match &e {
                Error::Format { path: p, .. } => assert_eq!(p, &path, "{name}"),
                other => panic!("{name}: unexpected {other:?}"),
            }
        }
        // Garbage bytes.
        let path = dir.path().join("garbage.obj");
        let garbage: Vec<u8> = (0..4096u32)
            .map(|i| (i.wrapping_mul(2654435761) >> 13) as u8)
            .collect();
        std::fs::write(&path, &garbage).unwrap();
        assert!(matches!(
            TriMesh::read_obj(&path),
            Err(Error::Format { .. })
        ));
        // Missing file.
        let e = TriMesh::read_obj(dir.path().join("missing.obj")).unwrap_err();
        assert!(matches!(e, Error::Io { .. }), "{e}");
    }

    #[test]
    fn ply_reader_handles_quads_floats_and_extra_elements() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("quad.ply");
        let text = "ply\n\
                    format ascii 1.0\n\
                    comment made by hand\n\
                    element vertex 4\n\
                    property float x\nproperty float y\nproperty float z\n\
                    property uchar red\nproperty uchar green\nproperty uchar blue\n\
                    property uchar alpha\n\
                    element face 1\n\
                    property list uchar uint vertex_index\n\
                    element edge 1\n\
                    property int vertex1\nproperty int vertex2\n\
                    end_header\n\
                    0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n1 1 0 0 0 255 255\n0 1 0 51 51 51 255\n\
                    4 0 1 2 3\n\
                    0 1";
        std::fs::write(&path, text).unwrap();
        let m = TriMesh::read_ply(&path).unwrap();
        assert_eq!(m.positions[2], [1.0, 1.0, 0.0]);
        assert_eq!(m.faces, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(m.normals, None);
        let c = m.colors.unwrap();
        assert_eq!(c[0], [1.0, 0.0, 0.0]);
        assert!((c[3][1] - 0.2).abs() < 1e-7);
    }

    #[test]
    fn ply_reader_reads_big_endian_binary() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("be.ply");
        let mut bytes = b"ply\nformat binary_big_endian 1.0\nelement vertex 3\n\
            property float x\nproperty float y\nproperty float z\n\
            property float nx\nproperty float ny\nproperty float nz\n\
            element face 1\nproperty list uchar short vertex_indices\nend_header\n"
            .to_vec();
        for p in [[0.0f32, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]] {
            for v in p.iter().chain(&[0.0, 0.0, 1.0]) {
                bytes.extend_from_slice(&v.to_be_bytes());
            }
        }
        bytes.push(3);
        for i in [0i16, 1, 2] {
            bytes.extend_from_slice(&i.to_be_bytes());
        }
        std::fs::write(&path, &bytes).unwrap();
        let m = TriMesh::read(&path).unwrap();
        assert_eq!(
            m.positions,
            vec![[0.0; 3], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]]
        );
        assert_eq!(m.faces, vec![[0, 1, 2]]);
        assert_eq!(m.normals, Some(vec![[0.0, 0.0, 1.0]; 3]));
        assert_eq!(m.colors, None);
        assert_eq!(m.total_area(), 2.0);
    }

    #[test]
    fn ply_reader_rejects_bad_files() {
        let dir = tempfile::tempdir().unwrap();
        let m = TriMesh::icosphere(1, 1.0)
            .unwrap()
            .with_colors(colors_for(42))
            .unwrap();
        for enc in [PlyEncoding::Ascii, PlyEncoding::BinaryLittleEndian] {
            let full = dir.path().join("full.ply");
            m.write_ply(&full, enc).unwrap();
            let bytes = std::fs::read(&full).unwrap();
            // Every truncation (in steps) fails cleanly with an error naming the path.
            let cut = dir.path().join("cut.ply");
            for len in (0..bytes.len() - 1).step_by(7) {
                std::fs::write(&cut, &bytes[..len]).unwrap();
                match TriMesh::read_ply(&cut) {
                    Err(Error::Format { path, .. }) => assert_eq!(path, cut),
                    other => panic!("{enc:?} truncated at {len}: {other:?}"),
                }
            }
            // Flipped bytes never panic.
            let mut s = 1u64;
            for _ in 0..200 {
                s = s
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                let mut b = bytes.clone();
                let k = (s >> 33) as usize % b.len();
                b[k] ^= (s >> 20) as u8 | 1;
                std::fs::write(&cut, &b).unwrap();
                let _ = TriMesh::read_ply(&cut);
            }
        }
        let header =
            |body: &str| format!("ply\nformat binary_little_endian 1.0\n{body}end_header\n");
        let cases: Vec<(&str, Vec<u8>)> =
            vec![
            // A hostile header announcing 10^12 vertices in a ~200-byte file.
            (
                "huge_count",
                header(
                    "element vertex 1000000000000\nproperty double x\nproperty double y\n\
                     property double z\nelement face 1\nproperty list uchar int vertex_indices\n",
                )
                .into_bytes(),
            ),
            // Elements without properties take no bytes each.
            (
                "empty_elements",
                header("element junk 1000000000000000\n").into_bytes(),
            ),
            // A count that overflows u64 (ply-rs itself would panic on it).
            (
                "overflow",
                header("element vertex 123456789012345678901234567890\nproperty float x\n")
                    .into_bytes(),
            ),
            ("garbage", (0..300u32).map(|i| (i * 7919 % 251) as u8).collect()),
            ("not_ply", b"hello world\n".to_vec()),
            ("no_end_header", b"ply\nformat ascii 1.0\nelement vertex 3\n".to_vec()),
            (
                "no_faces",
                b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                  property float z\nelement face 0\nproperty list uchar int vertex_indices\n\
                  end_header\n0 0 0\n1 0 0\n0 1 0\n"
                    .to_vec(),
            ),
            (
                "no_face_element",
                b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                  property float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n"
                    .to_vec(),
            ),
            (
                "index_out_of_range",
                b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                  property float z\nelement face 1\nproperty list uchar int vertex_indices\n\
                  end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n"
                    .to_vec(),
            ),
            (
                "negative_index",
                b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                  property float z\nelement face 1\nproperty list uchar int vertex_indices\n\
                  end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 -1\n"
                    .to_vec(),
            ),
            (
                "missing_z",
                b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                  element face 1\nproperty list uchar int vertex_indices\n\
                  end_header\n0 0\n1 0\n0 1\n3 0 1 2\n"
                    .to_vec(),
            ),
        ];
        for (name, bytes) in cases {
            let path = dir.path().join(format!("{name}.ply"));
            std::fs::write(&path, &bytes).unwrap();
            let start = std::time::Instant::now();
            let e = TriMesh::read_ply(&path).unwrap_err();
            assert!(matches!(e, Error::Format { .. }), "{name}: {e}");
            assert!(start.elapsed().as_secs_f64() < 5.0, "{name} took too long");
        }
        let e = TriMesh::read_ply(dir.path().join("missing.ply")).unwrap_err();
        assert!(matches!(e, Error::Io { .. }), "{e}");
    }

    #[test]
    fn dispatch_rejects_unknown_extensions_and_writers_reject_bad_meshes() {
        let dir = tempfile::tempdir().unwrap();
        let m = TriMesh::cube(1.0).unwrap();
        for name in ["mesh.stl", "mesh"] {
            let path = dir.path().join(name);
            assert!(matches!(m.write(&path), Err(Error::UnsupportedFormat(_))));
            std::fs::write(&path, b"solid").unwrap();
            let e = TriMesh::read(&path).unwrap_err();
            let names_ext = matches!(&e, Error::UnsupportedFormat(s) if s.contains("stl"));
            assert!(matches!(e, Error::UnsupportedFormat(_)), "{e}");
            assert_eq!(names_ext, name.ends_with("stl"), "{e}");
        }
        let empty = TriMesh::new(vec![[0.0; 3]], vec![]).unwrap();
        assert!(matches!(
            empty.write_obj(dir.path().join("e.obj")),
            Err(Error::Empty("faces"))
        ));
        assert!(matches!(
            empty.write_ply(dir.path().join("e.ply"), PlyEncoding::Ascii),
            Err(Error::Empty("faces"))
        ));
        let mut broken = m.clone();
        broken.faces[0] = [0, 1, 99];
        assert!(broken.write_obj(dir.path().join("b.obj")).is_err());
        assert!(matches!(
            m.write_obj(dir.path().join("no_such_dir").join("x.obj")),
            Err(Error::Io { .. })
        ));
    }
}
