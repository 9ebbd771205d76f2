//! The Gradient Octree (paper 03, section 4; Campoalegre et al. 2013): a pointer-less octree
//! over the material-boundary voxels of a volume, 3 bytes a voxel (material + normal), whose
//! structure travels at one bit per node.
//!
//! - **Edge voxels.** A voxel is stored iff its material is not null and some 6-neighbour
//!   (outside the volume counts as null) has another material ([`EdgeRule::Boundary`], the
//!   reading consistent with the paper's sizes; [`EdgeRule::AllNonNull`] stores every
//!   non-null voxel).
//! - **Levels.** The volume is padded to a cube of side `R` (a power of two, at least 32).
//!   Level `l` in `32, 64, ..., R` has nodes covering `(R/l)^3` voxels; level-`R` nodes are
//!   voxels. A node is grey iff its cube holds an edge voxel.
//! - **Arrays.** `V_32[x + 32 (y + 32 z)]` is 1 + the rank of the grey level-32 cell in raster
//!   order (0: nil). The child of a level-`l` node in slot `s = 4 (X & 1) + 2 (Y & 1) + (Z & 1)`
//!   (x the high bit) is numbered parent-major, slot-minor from 1: `O_l[i][s]`. Leaf data
//!   `D_R[i]` holds the 3-byte code of leaf `i`. Index 0 is nil everywhere (row 0 unused).
//! - **Addressing** (eq. 1): `V_32` of the voxel's cell, then one `O_l` per level with the
//!   slot of the voxel's bits, then `D_R`: `log2(R) - 3` array reads.
//! - **Structure at one bit per node.** `V_32` as a 32^3 occupancy bitmask and, per level, one
//!   byte per grey node whose bit `s` says whether child `s` is grey; the client rebuilds every
//!   `O_l` by counting ([`GoStructure::from_occupancy`]).
//! - **ROI restriction.** A node is kept iff grey and its cube meets the ROI box (a leaf iff
//!   inside it); the kept nodes are renumbered in the same order, so the leaf data of a ROI
//!   travels without indices.
//!
//! Building sorts the edge voxels by the key (raster index of the level-32 cell, Morton code
//! inside it with x as each slot's high bit): that order is the leaf numbering, and every
//! `O_l` falls out of one pass over the sorted keys, without a per-voxel index volume.

use rayon::prelude::*;
use wscg_math::{Error, Result, Volume};

use crate::normal_code::encode_voxel;
use crate::tf::MaterialTable;

/// Which voxels the octree stores.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum EdgeRule {
    /// Non-null voxels with a 6-neighbour of another material (default).
    #[default]
    Boundary,
    /// Every non-null voxel.
    AllNonNull,
}

/// Cells per side of the first level.
pub const TOP: usize = 32;
const TOP_CELLS: usize = TOP * TOP * TOP;

/// A region of interest: a half-open voxel box `[min, max)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Roi {
    /// Lowest corner (inclusive).
    pub min: [u32; 3],
    /// Highest corner (exclusive).
    pub max: [u32; 3],
}

impl Roi {
    /// The box `[min, max)` snapped outward to multiples of 16 and clamped to `dims`.
    ///
    /// Errors: `min >= max` on some axis, or a box that is empty after clamping.
    pub fn snapped(min: [u32; 3], max: [u32; 3], dims: [usize; 3]) -> Result<Self> {
        let mut roi = Roi { min, max };
        for a in 0..3 {
            if min[a] >= max[a] {
                return Err(Error::invalid(
                    "roi",
                    format!("axis {a}: min {} >= max {}", min[a], max[a]),
                ));
            }
            roi.min[a] = min[a] / 16 * 16;
            // In u64: snapping a `max` near `u32::MAX` up to 16 would overflow `u32`.
            roi.max[a] = (u64::from(max[a]).div_ceil(16) * 16).min(dims[a] as u64) as u32;
            if roi.min[a] >= roi.max[a] {
                return Err(Error::invalid(
                    "roi",
                    format!(
                        "axis {a}: [{}, {}) lies outside the volume (size {})",
                        min[a], max[a], dims[a]
                    ),
                ));
            }
        }
        Ok(roi)
    }

    /// Whether the cube `[lo, lo + size)^3` meets the box.
    #[inline]
    pub fn meets_cube(&self, lo: [u32; 3], size: u32) -> bool {
        (0..3).all(|a| lo[a] < self.max[a] && lo[a] + size > self.min[a])
    }

    /// Whether voxel `p` lies in the box.
    #[inline]
    pub fn contains(&self, p: [u32; 3]) -> bool {
        (0..3).all(|a| p[a] >= self.min[a] && p[a] < self.max[a])
    }
}

/// The octree's structure: `V_32` and every `O_l` (no leaf data).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct GoStructure {
    /// Side of the padded cube (a power of two, >= 32).
    pub r: usize,
    /// `V_32`, x fastest; 0 is nil.
    pub v32: Vec<u32>,
    /// `O_l` for the levels 32, 64, ..., R/2 (`o[t]` is level `32 * 2^t`); row 0 unused.
    pub o: Vec<Vec<[u32; 8]>>,
}

/// `(i >> b) & 1` as the three bits of a slot, x high.
#[inline]
fn slot(p: [u32; 3], b: u32) -> usize {
    ((((p[0] >> b) & 1) << 2) | (((p[1] >> b) & 1) << 1) | ((p[2] >> b) & 1)) as usize
}

/// Raster index of the level-32 cell of voxel `p` in a cube of depth `depth`.
#[inline]
fn cell_index(p: [u32; 3], depth: u32) -> usize {
    let c = p.map(|v| (v >> depth) as usize);
    c[0] + TOP * (c[1] + TOP * c[2])
}

/// The cube side for a volume of `dims`: the next power of two >= the largest side, >= 32.
pub fn cube_side(dims: [usize; 3]) -> usize {
    dims.iter()
        .copied()
        .max()
        .unwrap_or(1)
        .next_power_of_two()
        .max(TOP)
}

/// The paper's eq. 1 addressing of voxel `ijk` in a cube of side `r` (a power of two >= 32):
/// its level-32 cell and the child slot taken at each level 32, 64, ..., r/2.
pub fn octree_address(ijk: [u32; 3], r: usize) -> ([u32; 3], Vec<u8>) {
    let depth = r.trailing_zeros().saturating_sub(5);
    let cell = ijk.map(|v| v >> depth);
    let slots = (0..depth).rev().map(|b| slot(ijk, b) as u8).collect();
    (cell, slots)
}

impl GoStructure {
    /// Number of levels below 32 (`log2(R) - 5`).
    pub fn depth(&self) -> usize {
        self.r.trailing_zeros() as usize - 5
    }

    /// Grey nodes per level 32, 64, ..., R.
    pub fn node_counts(&self) -> Vec<usize> {
        let mut n = vec![self.v32.iter().filter(|&&v| v != 0).count()];
        for o in &self.o {
            n.push(o[1..].iter().flatten().filter(|&&c| c != 0).count());
        }
        n
    }

    /// Leaf index of voxel `ijk` (0: nil or outside the cube) and the number of arrays read
    /// to find it (`V_32`, the `O_l` visited and, for a grey leaf, `D_R`).
    pub fn leaf(&self, ijk: [u32; 3]) -> (u32, usize) {
        if ijk.iter().any(|&v| v as usize >= self.r) {
            return (0, 0);
        }
        let depth = self.depth() as u32;
        let mut idx = self.v32[cell_index(ijk, depth)];
        let mut reads = 1;
        for (t, o) in self.o.iter().enumerate() {
            if idx == 0 {
                return (0, reads);
            }
            idx = o[idx as usize][slot(ijk, depth - 1 - t as u32)];
            reads += 1;
        }
        (idx, reads + usize::from(idx != 0))
    }

    /// The structure at one bit per node: the 32^3 occupancy bitmask of `V_32` (bit `c % 8`
    /// of byte `c / 8`) and, per level 32..R/2, one byte per grey node with bit `s` set iff
    /// child `s` is grey.
    pub fn occupancy(&self) -> (Vec<u8>, Vec<Vec<u8>>) {
        let mut bits = vec![0u8; TOP_CELLS / 8];
        for (c, &v) in self.v32.iter().enumerate() {
            if v != 0 {
                bits[c / 8] |= 1 << (c % 8);
            }
        }
        let b = self
            .o
            .iter()
            .map(|o| {
                o[1..]
                    .iter()
                    .map(|row| {
                        (0..8)
                            .filter(|&s| row[s] != 0)
                            .fold(0u8, |acc, s| acc | (1 << s))
                    })
                    .collect()
            })
            .collect();
        (bits, b)
    }

    /// The client's lossless rebuild from [`GoStructure::occupancy`].
    ///
    /// Errors: a bitmask that is not 4096 bytes, `r` not a power of two >= 32, a level whose
    /// byte count differs from the number of grey nodes the previous level announces.
    pub fn from_occupancy(r: usize, bits: &[u8], b: &[Vec<u8>]) -> Result<Self> {
        if !r.is_power_of_two() || r < TOP {
            return Err(Error::invalid(
                "r",
                format!("must be a power of two >= 32, got {r}"),
            ));
        }
        if bits.len() != TOP_CELLS / 8 {
            return Err(Error::invalid(
                "structure",
                format!(
                    "occupancy has {} bytes, expected {}",
                    bits.len(),
                    TOP_CELLS / 8
                ),
            ));
        }
        let depth = r.trailing_zeros() as usize - 5;
        if b.len() != depth {
            return Err(Error::invalid(
                "structure",
                format!("{} levels of child bytes for a depth of {depth}", b.len()),
            ));
        }
        let mut v32 = vec![0u32; TOP_CELLS];
        let mut n = 0u32;
        for (c, v) in v32.iter_mut().enumerate() {
            if bits[c / 8] >> (c % 8) & 1 == 1 {
                n += 1;
                *v = n;
            }
        }
        let mut o = Vec::with_capacity(depth);
        for (t, bl) in b.iter().enumerate() {
            if bl.len() != n as usize {
                return Err(Error::invalid(
                    "structure",
                    format!(
                        "level {} has {} child bytes for {n} grey nodes",
                        TOP << t,
                        bl.len()
                    ),
                ));
            }
            let mut rows = Vec::with_capacity(bl.len() + 1);
            rows.push([0u32; 8]);
            let mut next = 0u32;
            for &byte in bl {
                rows.push(std::array::from_fn(|s| {
                    if byte >> s & 1 == 1 {
                        next += 1;
                        next
                    } else {
                        0
                    }
                }));
            }
            o.push(rows);
            n = next;
        }
        Ok(Self { r, v32, o })
    }

    /// Number of leaves (grey level-R nodes).
    pub fn leaves(&self) -> usize {
        match self.o.last() {
            Some(o) => o[1..].iter().flatten().filter(|&&c| c != 0).count(),
            None => self.v32.iter().filter(|&&v| v != 0).count(),
        }
    }

    /// The structure restricted to `roi` (kept: grey nodes whose cube meets the box), with
    /// the full-tree leaf index of every kept leaf in the restricted numbering order.
    pub fn restrict(&self, roi: &Roi) -> (GoStructure, Vec<u32>) {
        let depth = self.depth();
        let mut v32 = vec![0u32; TOP_CELLS];
        let side = (self.r / TOP) as u32;
        // (full index, lowest voxel) of the kept nodes of the current level, in order.
        let mut kept: Vec<(u32, [u32; 3])> = Vec::new();
        for (c, &full) in self.v32.iter().enumerate() {
            let lo = [
                (c % TOP) as u32 * side,
                (c / TOP % TOP) as u32 * side,
                (c / (TOP * TOP)) as u32 * side,
            ];
            if full != 0 && roi.meets_cube(lo, side) {
                kept.push((full, lo));
                v32[c] = kept.len() as u32;
            }
        }
        let mut o = Vec::with_capacity(depth);
        let mut size = side;
        for full_o in &self.o {
            size /= 2;
            let mut rows = Vec::with_capacity(kept.len() + 1);
            rows.push([0u32; 8]);
            let mut next = Vec::new();
            for &(full, lo) in &kept {
                let row = &full_o[full as usize];
                let mut out = [0u32; 8];
                for s in 0..8 {
                    let child = row[s];
                    let clo = [
                        lo[0] + ((s >> 2) & 1) as u32 * size,
                        lo[1] + ((s >> 1) & 1) as u32 * size,
                        lo[2] + (s & 1) as u32 * size,
                    ];
                    if child != 0 && roi.meets_cube(clo, size) {
                        next.push((child, clo));
                        out[s] = next.len() as u32;
                    }
                }
                rows.push(out);
            }
            o.push(rows);
            kept = next;
        }
        let leaves = kept.into_iter().map(|(full, _)| full).collect();
        (GoStructure { r: self.r, v32, o }, leaves)
    }
}

/// A Gradient Octree: structure and leaf data.
#[derive(Clone, Debug, PartialEq)]
pub struct GradientOctree {
    /// Volume size (x, y, z).
    pub dims: [usize; 3],
    /// `V_32` and the `O_l`.
    pub structure: GoStructure,
    /// `D_R`: the 3-byte code of every leaf; row 0 unused.
    pub leaves: Vec<[u8; 3]>,
}

/// Unit normal the octree stores for voxel `(x, y, z)`: central differences of the density
/// (one-sided at the border); where they vanish, of the indicator of the voxel's material;
/// else +z. Panics if the voxel is outside the volume.
pub fn normal(v: &Volume<u8>, mats: &MaterialTable, p: [usize; 3]) -> [f32; 3] {
    let dims = v.dims();
    let m0 = mats.material(v.at(p[0], p[1], p[2]));
    let diff = |f: &dyn Fn(usize, usize, usize) -> f32| -> [f32; 3] {
        std::array::from_fn(|a| {
            let mut lo = p;
            let mut hi = p;
            lo[a] = p[a].saturating_sub(1);
            hi[a] = (p[a] + 1).min(dims[a] - 1);
            let span = (hi[a] - lo[a]).max(1) as f32;
            (f(hi[0], hi[1], hi[2]) - f(lo[0], lo[1], lo[2])) / span
        })
    };
    let unit = |g: [f32; 3]| {
        let l = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
        (l > 1e-12).then(|| g.map(|c| c / l))
    };
    unit(diff(&|x, y, z| v.at(x, y, z) as f32))
        .or_else(|| {
            unit(diff(&|x, y, z| {
                f32::from(mats.material(v.at(x, y, z)) == m0)
            }))
        })
        .unwrap_or([0.0, 0.0, 1.0])
}

/// Whether voxel `p` (material `m != 0`) has a 6-neighbour of another material.
fn on_boundary(v: &Volume<u8>, mats: &MaterialTable, p: [usize; 3], m: u8) -> bool {
    let dims = v.dims();
    (0..3).any(|a| {
        [-1isize, 1].iter().any(|&d| {
            let q = p[a] as isize + d;
            if q < 0 || q as usize >= dims[a] {
                return true;
            }
            let mut n = p;
            n[a] = q as usize;
            mats.material(v.at(n[0], n[1], n[2])) != m
        })
    })
}

impl GradientOctree {
    /// Builds the octree of `v` for the materials `mats`.
    ///
    /// Errors: an empty volume.
    pub fn build(v: &Volume<u8>, mats: &MaterialTable, rule: EdgeRule) -> Result<Self> {
        let dims = v.dims();
        if dims.contains(&0) {
            return Err(Error::Empty("volume"));
        }
        let r = cube_side(dims);
        let depth = r.trailing_zeros() - 5;
        // Sort key: cell raster index, then the Morton code of the low `depth` bits.
        let key = |p: [u32; 3]| {
            let code = (0..depth)
                .rev()
                .fold(0u64, |acc, b| (acc << 3) | slot(p, b) as u64);
            ((cell_index(p, depth) as u64) << (3 * depth)) | code
        };
        let mut voxels: Vec<(u64, [u8; 3])> = (0..dims[2])
            .into_par_iter()
            .flat_map_iter(|z| {
                let mut out = Vec::new();
                for y in 0..dims[1] {
                    for x in 0..dims[0] {
                        let m = mats.material(v.at(x, y, z));
                        if m == 0 {
                            continue;
                        }
                        let p = [x, y, z];
                        if rule == EdgeRule::Boundary && !on_boundary(v, mats, p, m) {
                            continue;
                        }
                        let code = encode_voxel(m, normal(v, mats, p));
                        out.push((key(p.map(|c| c as u32)), code));
                    }
                }
                out
            })
            .collect();
        voxels.par_sort_unstable_by_key(|e| e.0);
        let depth = depth as usize;
        let mut v32 = vec![0u32; TOP_CELLS];
        let mut o: Vec<Vec<[u32; 8]>> = (0..depth).map(|_| vec![[0u32; 8]]).collect();
        let mut leaves = vec![[0u8; 3]];
        let mut last = vec![u64::MAX; depth + 1];
        let mut idx = vec![0u32; depth + 1];
        for &(k, code) in &voxels {
            for t in 0..=depth {
                let prefix = k >> (3 * (depth - t));
                if prefix == last[t] {
                    continue;
                }
                last[t] = prefix;
                idx[t] = if t < depth {
                    o[t].push([0; 8]);
                    (o[t].len() - 1) as u32
                } else {
                    leaves.push(code);
                    (leaves.len() - 1) as u32
                };
                if t == 0 {
                    v32[(prefix) as usize] = idx[0];
                } else {
                    o[t - 1][idx[t - 1] as usize][(prefix & 7) as usize] = idx[t];
                }
            }
        }
        Ok(Self {
            dims,
            structure: GoStructure { r, v32, o },
            leaves,
        })
    }

    /// The 3-byte code of voxel `ijk`, `None` if it is not stored.
    pub fn lookup(&self, ijk: [u32; 3]) -> Option<[u8; 3]> {
        lookup(&self.structure, &self.leaves, ijk)
    }

    /// The leaf data of `roi` in the restricted order (what the server sends for a ROI).
    pub fn roi_leaves(&self, roi: &Roi) -> Vec<[u8; 3]> {
        let (_, full) = self.structure.restrict(roi);
        full.iter().map(|&i| self.leaves[i as usize]).collect()
    }
}

/// The code of voxel `ijk` in a (possibly restricted) structure with leaf data `leaves`
/// (row 0 unused).
pub fn lookup(s: &GoStructure, leaves: &[[u8; 3]], ijk: [u32; 3]) -> Option<[u8; 3]> {
    match s.leaf(ijk).0 {
        0 => None,
        i => leaves.get(i as usize).copied(),
    }
}
