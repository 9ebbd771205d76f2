//! Top-down construction with early stop and bottom-up voxel attributes (paper §3
//! "Data Structure" and "Construction", Figs. 2-3).
//!
//! The GPU version splats the fragments level by level, caching up to two triangle ids per
//! node with atomic compare-and-swap and flagging a node for subdivision at the third distinct
//! id. Here the fragments are sorted by Morton code once, so every node owns a contiguous
//! fragment range; each level is one parallel pass that counts the distinct triangles of every
//! active node (stopping at three), turns nodes with at most two into leaves, and splits the
//! others into eight consecutive children whose ranges are found by binary search on the
//! octant bits. The result is deterministic.

use std::time::Instant;

use rayon::prelude::*;
use wscg_math::vec3::{cross, normalized_or_zero, sub};
use wscg_math::{Error, Result, TriMesh};

use crate::cube::{check_depth, child_octant, Cube};
use crate::node::{oct_encode, Node, Voxel, EMPTY, INDEX_MASK, LEAF_BIT};
use crate::octree::HybridOctree;
use crate::voxelize::{voxelize, Fragment};

wscg_math::params! {
    /// Construction parameters; `Default` gives the paper's values.
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct BuildParams {
        /// Deepest level `L` (the paper voxelizes at 512^3: `L = 9`). At most 21.
        pub max_depth: u8,
        /// A node with at most this many distinct triangles becomes a leaf (paper: 2).
        pub leaf_max_tris: u8,
        /// Stop early at small nodes (the paper's method); `false` builds the "full octree" of
        /// Table 2, split down to level `L` wherever there is geometry.
        pub early_stop: bool,
        /// Explicit cube domain (must hold every vertex); `None`: the mesh's bounding cube.
        pub domain: Option<Cube>,
        /// Bits of the node word that index children and triangle codes (30 in the paper's
        /// layout). Smaller values exist to test the overflow error on small meshes.
        pub index_bits: u8,
    }
}

impl Default for BuildParams {
    fn default() -> Self {
        Self {
            max_depth: 9,
            leaf_max_tris: 2,
            early_stop: true,
            domain: None,
            index_bits: 30,
        }
    }
}

impl BuildParams {
    /// Errors: `max_depth > 21`, `leaf_max_tris == 0`, `index_bits` outside 1..=30, a domain
    /// cube with a non-finite corner or a side that is not finite and positive. Whether the
    /// domain holds the mesh and the mesh fits the node word is checked by [`build`].
    pub fn validate(&self) -> Result<()> {
        check_depth(self.max_depth)?;
        if !(1..=30).contains(&self.index_bits) {
            return Err(Error::invalid(
                "index_bits",
                format!("must be in 1..=30, got {}", self.index_bits),
            ));
        }
        if self.leaf_max_tris == 0 {
            return Err(Error::invalid(
                "leaf_max_tris",
                "must be at least 1 (the paper uses 2)",
            ));
        }
        if let Some(c) = self.domain {
            Cube::new(c.min, c.size)?;
        }
        Ok(())
    }
}

/// What the construction did and how long each phase took.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BuildStats {
    /// Fragments (cell, triangle pairs) of the voxelization.
    pub fragments: usize,
    /// Zero-area triangles left out.
    pub degenerate_triangles: usize,
    /// Nodes, empty children included.
    pub nodes: usize,
    /// Non-empty nodes (one voxel each).
    pub voxels: usize,
    /// Leaves above the finest level (early stop).
    pub early_leaves: usize,
    /// Leaves at the finest level.
    pub finest_leaves: usize,
    /// Seconds spent voxelizing and sorting.
    pub voxelize_s: f64,
    /// Seconds spent building the node hierarchy.
    pub hierarchy_s: f64,
    /// Seconds spent on the bottom-up attributes.
    pub attributes_s: f64,
}

/// What one level's pass decides for an active node.
enum Decision {
    /// A leaf with these distinct triangles (sorted).
    Leaf(Vec<u32>),
    /// Split: the fragment ranges of the eight octants.
    Split([(u32, u32); 8]),
}

/// Up to `limit + 1` distinct triangles of a fragment range, or all of them when `all`.
fn distinct_prims(frags: &[Fragment], limit: usize, all: bool) -> Vec<u32> {
    let mut out: Vec<u32> = Vec::with_capacity(limit + 1);
    for f in frags {
        if !out.contains(&f.prim) {
            out.push(f.prim);
            if !all && out.len() > limit {
                break;
            }
            if all && out.len() > 16 {
                // Many triangles: finish with a sort instead of linear membership tests.
                let mut v: Vec<u32> = frags.iter().map(|f| f.prim).collect();
                v.sort_unstable();
                v.dedup();
                return v;
            }
        }
    }
    out.sort_unstable();
    out
}

/// Checks the mesh and the parameters, returning the cube domain.
fn check_input(mesh: &TriMesh, p: &BuildParams) -> Result<Cube> {
    p.validate()?;
    mesh.validate()?;
    if mesh.faces.is_empty() {
        return Err(Error::Empty("mesh faces"));
    }
    if mesh.faces.len() >= (1usize << p.index_bits) {
        return Err(Error::LimitExceeded(format!(
            "{} triangles do not fit the {}-bit triangle code of a leaf",
            mesh.faces.len(),
            p.index_bits
        )));
    }
    let (lo, hi) = mesh.bounding_box().ok_or(Error::Empty("mesh positions"))?;
    match p.domain {
        Some(c) => {
            if !c.contains_box(lo, hi) {
                return Err(Error::invalid(
                    "domain",
                    format!(
                        "the cube at {:?} with side {} does not contain the mesh's bounding box {lo:?}..{hi:?}",
                        c.min, c.size
                    ),
                ));
            }
            Ok(c)
        }
        None => Ok(Cube::around(lo, hi)),
    }
}

/// Builds the hybrid octree of `mesh` (per-vertex colours are used when present).
///
/// Errors: an empty or invalid mesh, `max_depth > 21`, a domain that does not contain the
/// mesh, a mesh of only zero-area triangles, or more nodes / triangle-index words than the
/// 30-bit node word can address ([`Error::LimitExceeded`]).
pub fn build(mesh: &TriMesh, p: &BuildParams) -> Result<(HybridOctree, BuildStats)> {
    let cube = check_input(mesh, p)?;
    let depth = p.max_depth;
    let limit = 1usize << p.index_bits;
    let t0 = Instant::now();
    let frags = voxelize(
        &mesh.positions,
        &mesh.faces,
        mesh.colors.as_deref(),
        &cube,
        depth,
    )?;
    if frags.list.is_empty() {
        return Err(Error::invalid(
            "mesh",
            format!(
                "all {} triangles have zero area; nothing to voxelize",
                mesh.faces.len()
            ),
        ));
    }
    let list = &frags.list;
    let mut stats = BuildStats {
        fragments: list.len(),
        degenerate_triangles: frags.degenerate,
        voxelize_s: t0.elapsed().as_secs_f64(),
        ..Default::default()
    };

    // Top-down, one pass per level.
    let t1 = Instant::now();
    let mut nodes = vec![Node {
        next: 0,
        payload: 0,
    }];
    let mut ranges: Vec<(u32, u32)> = vec![(0, list.len() as u32)];
    let mut level_start = vec![0usize];
    let mut leaves: Vec<(u32, Vec<u32>)> = Vec::new();
    let mut active: Vec<u32> = vec![0];
    let lmax = usize::from(p.leaf_max_tris);
    for l in 0..=depth {
        // Children made at this level start the next level.
        level_start.push(nodes.len());
        let decisions: Vec<Decision> = active
            .par_iter()
            .map(|&n| {
                let (lo, hi) = ranges[n as usize];
                let fr = &list[lo as usize..hi as usize];
                if l == depth {
                    return Decision::Leaf(distinct_prims(fr, lmax, true));
                }
                if p.early_stop {
                    let d = distinct_prims(fr, lmax, false);
                    if d.len() <= lmax {
                        return Decision::Leaf(d);
                    }
                }
                let mut sub = [(0u32, 0u32); 8];
                let mut start = 0usize;
                for (o, s) in sub.iter_mut().enumerate() {
                    let end = start
                        + fr[start..].partition_point(|f| child_octant(f.morton, l, depth) <= o);
                    *s = (lo + start as u32, lo + end as u32);
                    start = end;
                }
                Decision::Split(sub)
            })
            .collect();
        let mut next_active = Vec::new();
        for (&n, d) in active.iter().zip(decisions) {
            match d {
                Decision::Leaf(prims) => {
                    nodes[n as usize].next = LEAF_BIT;
                    leaves.push((n, prims));
                }
                Decision::Split(sub) => {
                    let first = nodes.len();
                    if first + 8 > limit {
                        return Err(Error::LimitExceeded(format!(
                            "more than 2^{} nodes: lower max_depth",
                            p.index_bits
                        )));
                    }
                    nodes[n as usize].next = first as u32;
                    for (o, r) in sub.into_iter().enumerate() {
                        if r.1 > r.0 {
                            nodes.push(Node {
                                next: 0,
                                payload: 0,
                            });
                            next_active.push((first + o) as u32);
                        } else {
                            nodes.push(Node::EMPTY_NODE);
                        }
                        ranges.push(r);
                    }
                }
            }
        }
        active = next_active;
        if active.is_empty() {
            break;
        }
    }
    while level_start.len() < usize::from(depth) + 3 {
        level_start.push(nodes.len());
    }

    // Leaf codes: singles are the triangle itself, pairs first in the index array, then lists
    // with their count as first word (the offsets of the paper's §3, Fig. 2; the count word is
    // our choice).
    let n_tris = mesh.faces.len() as u32;
    let n_pairs = leaves.iter().filter(|(_, t)| t.len() == 2).count();
    let n_pair_words = 2 * n_pairs as u32;
    let mut tri_index = vec![0u32; n_pair_words as usize];
    let mut pair_pos = 0usize;
    for (n, prims) in &leaves {
        let code = match prims.len() {
            1 => prims[0] as usize,
            2 => {
                tri_index[pair_pos..pair_pos + 2].copy_from_slice(prims);
                pair_pos += 2;
                n_tris as usize + pair_pos - 2
            }
            _ => {
                let at = tri_index.len();
                tri_index.push(prims.len() as u32);
                tri_index.extend_from_slice(prims);
                n_tris as usize + at
            }
        };
        if code >= limit.min(INDEX_MASK as usize + 1) {
            return Err(Error::LimitExceeded(format!(
                "leaf triangle code {code} exceeds the {}-bit index of a node",
                p.index_bits
            )));
        }
        nodes[*n as usize].next = LEAF_BIT | code as u32;
    }
    stats.hierarchy_s = t1.elapsed().as_secs_f64();

    // Bottom-up attributes.
    let t2 = Instant::now();
    let normals: Vec<[f32; 3]> = mesh
        .faces
        .par_iter()
        .map(|f| {
            let [a, b, c] = f.map(|i| mesh.positions[i as usize]);
            normalized_or_zero(cross(sub(b, a), sub(c, a))).map(|v| v as f32)
        })
        .collect();
    let mut color = vec![[0f32; 3]; nodes.len()];
    let mut normal = vec![[0f32; 3]; nodes.len()];
    for l in (0..=usize::from(depth)).rev() {
        let (s, e) = (level_start[l], level_start[l + 1]);
        if s == e {
            continue;
        }
        let (col_lo, col_hi) = color.split_at_mut(e);
        let (nrm_lo, nrm_hi) = normal.split_at_mut(e);
        col_lo[s..]
            .par_iter_mut()
            .zip(nrm_lo[s..].par_iter_mut())
            .enumerate()
            .for_each(|(i, (c, nn))| {
                let node = nodes[s + i];
                if node.is_empty() {
                    return;
                }
                if node.is_leaf() {
                    let (lo, hi) = ranges[s + i];
                    (*c, *nn) = leaf_attributes(&list[lo as usize..hi as usize], &normals);
                } else {
                    let first = node.index() as usize - e;
                    let kids = (first..first + 8).filter(|&k| !nodes[k + e].is_empty());
                    (*c, *nn) = inner_attributes(kids.map(|k| (col_hi[k], nrm_hi[k])));
                }
            });
    }
    let mut voxels = Vec::with_capacity(nodes.len());
    for (i, n) in nodes.iter_mut().enumerate() {
        if n.payload != EMPTY {
            n.payload = voxels.len() as u32;
            voxels.push(Voxel {
                rgba: [
                    quantize(color[i][0]),
                    quantize(color[i][1]),
                    quantize(color[i][2]),
                    255,
                ],
                normal_oct: oct_encode(normal[i]),
            });
        }
    }
    stats.attributes_s = t2.elapsed().as_secs_f64();
    stats.nodes = nodes.len();
    stats.voxels = voxels.len();
    let finest = level_start[usize::from(depth)];
    stats.early_leaves = leaves
        .iter()
        .filter(|(n, _)| (*n as usize) < finest)
        .count();
    stats.finest_leaves = leaves.len() - stats.early_leaves;
    let oct = HybridOctree::from_parts(
        nodes,
        voxels,
        tri_index,
        n_pair_words,
        cube,
        depth,
        p.early_stop,
        mesh.clone(),
    );
    Ok((oct, stats))
}

#[inline]
fn quantize(v: f32) -> u8 {
    (v.clamp(0.0, 1.0) * 255.0).round() as u8
}

/// Leaf attributes (paper §3, bottom-up phase): mean fragment colour; normalized sum of the
/// fragments' triangle normals, or the first fragment's normal when the sum vanishes
/// (opposite faces).
fn leaf_attributes(fr: &[Fragment], normals: &[[f32; 3]]) -> ([f32; 3], [f32; 3]) {
    let mut c = [0f32; 3];
    let mut n = [0f32; 3];
    for f in fr {
        for k in 0..3 {
            c[k] += f32::from(f.rgba[k]);
            n[k] += normals[f.prim as usize][k];
        }
    }
    let inv = 1.0 / (255.0 * fr.len() as f32);
    (c.map(|v| v * inv), unit_or(n, normals[fr[0].prim as usize]))
}

/// Inner-node attributes: mean of the children's colours, normalized sum of their unit
/// normals (first child's normal when the sum vanishes).
fn inner_attributes(kids: impl Iterator<Item = ([f32; 3], [f32; 3])>) -> ([f32; 3], [f32; 3]) {
    let mut c = [0f32; 3];
    let mut n = [0f32; 3];
    let mut first = None;
    let mut count = 0f32;
    for (kc, kn) in kids {
        first.get_or_insert(kn);
        count += 1.0;
        for k in 0..3 {
            c[k] += kc[k];
            n[k] += kn[k];
        }
    }
    (
        c.map(|v| v / count.max(1.0)),
        unit_or(n, first.unwrap_or([0.0, 0.0, 1.0])),
    )
}

/// `v / |v|`, or `fallback` when `|v| < 1e-6`.
fn unit_or(v: [f32; 3], fallback: [f32; 3]) -> [f32; 3] {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if l < 1e-6 {
        fallback
    } else {
        v.map(|x| x / l)
    }
}
