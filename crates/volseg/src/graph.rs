//! The bone-only graph (paper section 2.4): nodes are the voxels at or above the bone
//! threshold, edges join 6-adjacent bone voxels, weights follow eq. 1.

use wscg_math::{Error, Result, Volume};

use crate::params::{IntensityNorm, RandomWalkParams};

/// Marks a missing neighbour.
pub const NONE: u32 = u32::MAX;

/// A 6-connected weighted graph on the bone voxels of a volume.
///
/// It serialises with `serde` without the voxel-to-node map, which deserialising rebuilds
/// after checking that the parts agree (sizes, node and voxel indices in range).
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
#[serde(try_from = "GraphParts")]
pub struct BoneGraph {
    dims: [usize; 3],
    spacing: [f64; 3],
    /// Node id of every voxel, [`NONE`] for non-bone voxels.
    #[serde(skip_serializing)]
    node_of_voxel: Vec<u32>,
    /// Voxel index of every node (raster order).
    voxel_of_node: Vec<u32>,
    /// Neighbours of every node: −x, +x, −y, +y, −z, +z ([`NONE`] if absent).
    nbr: Vec<[u32; 6]>,
    /// Edge weights in the same order (0 where there is no edge), `f32` like the solver's
    /// vectors (48 bytes of neighbours and weights per node).
    w: Vec<[f32; 6]>,
}

/// The serialised fields of a [`BoneGraph`], in its field order.
#[derive(serde::Deserialize)]
struct GraphParts {
    dims: [usize; 3],
    spacing: [f64; 3],
    voxel_of_node: Vec<u32>,
    nbr: Vec<[u32; 6]>,
    w: Vec<[f32; 6]>,
}

impl TryFrom<GraphParts> for BoneGraph {
    type Error = Error;

    /// Rebuilds the voxel-to-node map; errors when the parts disagree.
    fn try_from(p: GraphParts) -> Result<Self> {
        let voxels = p
            .dims
            .iter()
            .try_fold(1usize, |a, &d| a.checked_mul(d))
            .filter(|&v| v < NONE as usize)
            .ok_or_else(|| Error::invalid("graph", format!("dims {:?} too large", p.dims)))?;
        let n = p.voxel_of_node.len();
        let bad = |what: &str| Err(Error::invalid("graph", format!("inconsistent {what}")));
        if p.nbr.len() != n || p.w.len() != n {
            return bad("neighbour or weight count");
        }
        if p.nbr
            .iter()
            .flatten()
            .any(|&m| m != NONE && m as usize >= n)
        {
            return bad("neighbour ids");
        }
        let mut node_of_voxel = vec![NONE; voxels];
        for (i, &v) in p.voxel_of_node.iter().enumerate() {
            match node_of_voxel.get_mut(v as usize) {
                Some(slot) if *slot == NONE => *slot = i as u32,
                _ => return bad("voxel ids"),
            }
        }
        Ok(Self {
            dims: p.dims,
            spacing: p.spacing,
            node_of_voxel,
            voxel_of_node: p.voxel_of_node,
            nbr: p.nbr,
            w: p.w,
        })
    }
}

/// The map `I ↦ g` of `norm` (the paper does not say how intensities are scaled before `β`
/// applies): a window clamps to [0, 1], `MinMax` uses
/// the extremes of the voxels in `mask`.
pub(crate) fn intensity_map(
    ct: &Volume<f32>,
    mask: &[bool],
    norm: IntensityNorm,
) -> impl Fn(f32) -> f64 + Sync {
    let (off, scale) = match norm {
        IntensityNorm::Window { lo, hi } => (lo, hi - lo),
        IntensityNorm::None => (0.0, 1.0),
        IntensityNorm::MinMax => {
            let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
            for (v, &m) in ct.data().iter().zip(mask) {
                if m {
                    lo = lo.min(*v as f64);
                    hi = hi.max(*v as f64);
                }
            }
            (lo, if hi > lo { hi - lo } else { 1.0 })
        }
    };
    let clamp = matches!(norm, IntensityNorm::Window { .. });
    move |v: f32| {
        let g = (v as f64 - off) / scale;
        if clamp {
            g.clamp(0.0, 1.0)
        } else {
            g
        }
    }
}

impl BoneGraph {
    /// Thresholds `ct` (HU) at `p.t_bone` and builds the graph with the weights of eq. 1,
    /// `w_ij = exp(−β (g_i − g_j)²) + ε`, `g` the normalised intensity (divided by the voxel
    /// spacing along the edge when `p.spacing_in_weights`, as scikit-image does).
    ///
    /// Errors: NaN or infinite CT values, invalid parameters, more than 2^32 − 1 bone voxels.
    pub fn build(ct: &Volume<f32>, p: &RandomWalkParams) -> Result<Self> {
        Self::from_mask(ct, &crate::preprocess::threshold(ct, p.t_bone), p)
    }

    /// Builds the graph on the voxels of `mask` (same size as `ct`).
    ///
    /// Errors: as [`Self::build`], and a mask of another size.
    pub fn from_mask(ct: &Volume<f32>, mask: &[bool], p: &RandomWalkParams) -> Result<Self> {
        p.validate()?;
        if let Some(index) = ct.data().iter().position(|v| !v.is_finite()) {
            return Err(Error::NonFinite { name: "ct", index });
        }
        if mask.len() != ct.len() {
            return Err(Error::ShapeMismatch(format!(
                "mask has {} voxels, the CT {}",
                mask.len(),
                ct.len()
            )));
        }
        let n = mask.iter().filter(|&&m| m).count();
        if n >= NONE as usize {
            return Err(Error::LimitExceeded(format!(
                "{n} bone voxels (at most 2^32 - 2)"
            )));
        }
        let dims = ct.dims();
        let map = intensity_map(ct, mask, p.norm);
        let g = |i: usize| map(ct.data()[i]);
        let mut node_of_voxel = vec![NONE; mask.len()];
        let mut voxel_of_node = Vec::with_capacity(n);
        for (i, &m) in mask.iter().enumerate() {
            if m {
                node_of_voxel[i] = voxel_of_node.len() as u32;
                voxel_of_node.push(i as u32);
            }
        }
        let [nx, ny, nz] = dims;
        let strides = [1isize, nx as isize, (nx * ny) as isize];
        let size = [nx, ny, nz];
        let mut nbr = vec![[NONE; 6]; n];
        let mut w = vec![[0.0f32; 6]; n];
        let inv_h: [f64; 3] = if p.spacing_in_weights {
            let h = ct.spacing();
            [1.0 / h[0], 1.0 / h[1], 1.0 / h[2]]
        } else {
            [1.0; 3]
        };
        for (node, &vox) in voxel_of_node.iter().enumerate() {
            let v = vox as usize;
            let c = [v % nx, (v / nx) % ny, v / (nx * ny)];
            for axis in 0..3 {
                for (s, dir) in [(0usize, -1isize), (1, 1)] {
                    let inside = if dir < 0 {
                        c[axis] > 0
                    } else {
                        c[axis] + 1 < size[axis]
                    };
                    if !inside {
                        continue;
                    }
                    let u = (v as isize + dir * strides[axis]) as usize;
                    let m = node_of_voxel[u];
                    if m != NONE {
                        let d = (g(v) - g(u)) * inv_h[axis];
                        nbr[node][2 * axis + s] = m;
                        w[node][2 * axis + s] = ((-p.beta * d * d).exp() + p.eps) as f32;
                    }
                }
            }
        }
        Ok(Self {
            dims,
            spacing: ct.spacing(),
            node_of_voxel,
            voxel_of_node,
            nbr,
            w,
        })
    }

    /// Volume dimensions.
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    /// Voxel spacing of the CT the graph was built from.
    pub fn spacing(&self) -> [f64; 3] {
        self.spacing
    }

    /// Number of nodes (bone voxels).
    pub fn len(&self) -> usize {
        self.voxel_of_node.len()
    }

    /// Whether the graph has no node.
    pub fn is_empty(&self) -> bool {
        self.voxel_of_node.is_empty()
    }

    /// Number of undirected edges.
    pub fn edges(&self) -> usize {
        self.nbr.iter().flatten().filter(|&&m| m != NONE).count() / 2
    }

    /// Node id of voxel `v`, if it is bone.
    pub fn node(&self, v: usize) -> Option<usize> {
        self.node_of_voxel
            .get(v)
            .copied()
            .filter(|&m| m != NONE)
            .map(|m| m as usize)
    }

    /// Voxel index of node `i`.
    pub fn voxel(&self, i: usize) -> usize {
        self.voxel_of_node[i] as usize
    }

    /// Neighbour ids of node `i` (−x, +x, −y, +y, −z, +z; [`NONE`] if absent).
    pub fn neighbours(&self, i: usize) -> &[u32; 6] {
        &self.nbr[i]
    }

    /// Edge weights of node `i`, same order as [`Self::neighbours`].
    pub fn weights(&self, i: usize) -> &[f32; 6] {
        &self.w[i]
    }

    /// Weighted degree `Σ_j w_ij` of node `i`.
    pub fn degree(&self, i: usize) -> f64 {
        self.w[i].iter().map(|&w| f64::from(w)).sum()
    }

    /// Approximate memory of the graph in bytes.
    pub fn memory_bytes(&self) -> usize {
        self.node_of_voxel.len() * 4 + self.voxel_of_node.len() * (4 + 24 + 24)
    }
}
