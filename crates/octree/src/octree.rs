//! The hybrid octree: nodes, voxel payloads, the triangle-index array and the mesh whose
//! triangles the leaves reference (paper §3, Fig. 2-3).

use wscg_math::{Error, Result, TriMesh};

use crate::cube::Cube;
use crate::node::{LeafTris, Node, NodeArray, Voxel};

/// A triangle prepared for ray intersection: first vertex and two edges, in `f32`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tri {
    /// First vertex.
    pub v0: [f32; 3],
    /// `v1 - v0`.
    pub e1: [f32; 3],
    /// `v2 - v0`.
    pub e2: [f32; 3],
}

/// One sparse voxel octree with pre-filtered attributes in every non-empty node and triangle
/// references in its leaves.
#[derive(Clone, Debug, PartialEq)]
pub struct HybridOctree {
    /// Nodes in level order; the root is node 0; the 8 children of an inner node are
    /// consecutive, in Morton (octant) order, and share one cache line.
    pub nodes: NodeArray,
    /// One voxel per non-empty node.
    pub voxels: Vec<Voxel>,
    /// Pair words (`2 x` pair leaves), then the lists (a count, then the triangle indices).
    pub tri_index: Vec<u32>,
    /// `T`: the number of triangles, offset of the pair codes.
    pub n_tris: u32,
    /// `P`: words holding pairs, offset of the list codes past `T`.
    pub n_pair_words: u32,
    /// The root cell.
    pub cube: Cube,
    /// Deepest level `L`.
    pub max_depth: u8,
    /// Whether the tree was built with early stop (otherwise: the full-octree baseline).
    pub early_stop: bool,
    /// The triangles the leaves refer to.
    pub mesh: TriMesh,
    tris: Vec<Tri>,
    /// `v_w(l)` for every level, in `f32`, for the traversal.
    pub(crate) cell_sizes: [f32; 22],
    /// The mesh's bounding box in `f32`, widened by `1e-5` of the cube side: rays in triangle
    /// mode that miss it cannot hit anything.
    pub(crate) bounds: [[f32; 3]; 2],
}

/// Sizes in bytes of the parts of the structure (the columns of the paper's Table 2).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MemoryReport {
    /// 8 bytes per node, empty children included.
    pub nodes: usize,
    /// Mesh storage: three `f32` positions and three `u32` indices per triangle (48 bytes);
    /// the same for every variant of the tree.
    pub triangles: usize,
    /// 4 bytes per word of the triangle-index array.
    pub tri_index: usize,
    /// 8 bytes per voxel (non-empty node).
    pub voxels: usize,
    /// The sum.
    pub total: usize,
}

impl MemoryReport {
    /// `1 - self.total / full.total`: the fraction saved against a full octree.
    pub fn saving_against(&self, full: &MemoryReport) -> f64 {
        1.0 - self.total as f64 / full.total as f64
    }
}

pub(crate) fn prepare(mesh: &TriMesh) -> Vec<Tri> {
    let p = |i: u32| mesh.positions[i as usize].map(|v| v as f32);
    mesh.faces
        .iter()
        .map(|f| {
            let (a, b, c) = (p(f[0]), p(f[1]), p(f[2]));
            Tri {
                v0: a,
                e1: [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
                e2: [c[0] - a[0], c[1] - a[1], c[2] - a[2]],
            }
        })
        .collect()
}

/// The mesh's bounding box widened by `pad` on every side and rounded outwards to `f32`; an
/// inverted (empty) box for a mesh without vertices.
fn mesh_bounds(mesh: &TriMesh, pad: f64) -> [[f32; 3]; 2] {
    match mesh.bounding_box() {
        Some((lo, hi)) => [
            lo.map(|v| ((v - pad) as f32).next_down()),
            hi.map(|v| ((v + pad) as f32).next_up()),
        ],
        None => [[f32::INFINITY; 3], [f32::NEG_INFINITY; 3]],
    }
}

impl HybridOctree {
    /// Assembles a tree from its parts (used by the builder and the file reader).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn from_parts(
        nodes: Vec<Node>,
        voxels: Vec<Voxel>,
        tri_index: Vec<u32>,
        n_pair_words: u32,
        cube: Cube,
        max_depth: u8,
        early_stop: bool,
        mesh: TriMesh,
    ) -> Self {
        let tris = prepare(&mesh);
        let cell_sizes = std::array::from_fn(|l| cube.cell_size(l as u8) as f32);
        let bounds = mesh_bounds(&mesh, 1e-5 * cube.size);
        Self {
            nodes: NodeArray::from(&nodes[..]),
            voxels,
            tri_index,
            n_tris: mesh.faces.len() as u32,
            n_pair_words,
            cube,
            max_depth,
            early_stop,
            mesh,
            tris,
            cell_sizes,
            bounds,
        }
    }

    /// The triangles prepared for intersection.
    #[inline]
    pub fn tris(&self) -> &[Tri] {
        &self.tris
    }

    /// The triangles of leaf node `node` (single / pair / list, paper §3, Fig. 2). Panics if
    /// `node` is not a non-empty leaf of this tree.
    #[inline]
    pub fn decode_leaf(&self, node: u32) -> LeafTris<'_> {
        self.decode_code(self.nodes[node as usize].index())
    }

    /// Decodes a leaf's triangle code.
    #[inline]
    pub(crate) fn decode_code(&self, v: u32) -> LeafTris<'_> {
        let t = self.n_tris;
        if v < t {
            LeafTris::Single(v)
        } else if v < t + self.n_pair_words {
            let i = (v - t) as usize;
            LeafTris::Pair(self.tri_index[i], self.tri_index[i + 1])
        } else {
            let i = (v - t) as usize;
            let n = self.tri_index[i] as usize;
            LeafTris::List(&self.tri_index[i + 1..i + 1 + n])
        }
    }

    /// Memory of each part in bytes (Table 2's columns).
    pub fn memory_report(&self) -> MemoryReport {
        let nodes = 8 * self.nodes.len();
        let triangles = 48 * self.mesh.faces.len();
        let tri_index = 4 * self.tri_index.len();
        let voxels = 8 * self.voxels.len();
        MemoryReport {
            nodes,
            triangles,
            tri_index,
            voxels,
            total: nodes + triangles + tri_index + voxels,
        }
    }

    /// Calls `f(node, level, cell)` for every non-empty node, depth first, children in
    /// octant order; `cell` is the node's integer position at its level.
    pub fn visit(&self, mut f: impl FnMut(u32, u8, [u32; 3])) {
        let mut stack = vec![(0u32, 0u8, [0u32; 3])];
        while let Some((n, l, c)) = stack.pop() {
            let node = self.nodes[n as usize];
            if node.is_empty() {
                continue;
            }
            f(n, l, c);
            if !node.is_leaf() {
                let first = node.index();
                for o in (0..8u32).rev() {
                    let cc = [
                        2 * c[0] + (o & 1),
                        2 * c[1] + ((o >> 1) & 1),
                        2 * c[2] + ((o >> 2) & 1),
                    ];
                    stack.push((first + o, l + 1, cc));
                }
            }
        }
    }

    /// Cells `(x, y, z)` of the non-empty nodes at `level` (leaves that stopped above it are
    /// not expanded).
    pub fn occupancy(&self, level: u8) -> Vec<[u32; 3]> {
        let mut out = Vec::new();
        self.visit(|_, l, c| {
            if l == level {
                out.push(c);
            }
        });
        out
    }

    /// The level of every node (empty children included), in node order.
    pub fn node_levels(&self) -> Vec<u8> {
        let mut levels = vec![0u8; self.nodes.len()];
        for (i, n) in self.nodes.iter().enumerate() {
            if !n.is_empty() && !n.is_leaf() {
                let l = levels[i] + 1;
                let first = n.index() as usize;
                levels[first..first + 8].fill(l);
            }
        }
        levels
    }

    /// Checks the internal consistency of the structure: child and triangle indices in range,
    /// children after their parent, one voxel per non-empty node in order. Used on trees read
    /// from files, so a corrupted file is an error instead of a wrong answer or a panic.
    pub fn check(&self) -> Result<()> {
        let bad = |why: String| Err(Error::invalid("octree", why));
        if self.nodes.is_empty() {
            return bad("no root node".into());
        }
        if self.n_tris as usize != self.mesh.faces.len() {
            return bad(format!(
                "{} triangles declared, {} in the mesh",
                self.n_tris,
                self.mesh.faces.len()
            ));
        }
        if self.n_pair_words as usize > self.tri_index.len() || !self.n_pair_words.is_multiple_of(2)
        {
            return bad(format!("pair words {} invalid", self.n_pair_words));
        }
        if self.max_depth > crate::cube::MAX_DEPTH {
            return bad(format!("depth {} exceeds 21", self.max_depth));
        }
        if self.tri_index[..self.n_pair_words as usize]
            .iter()
            .any(|&t| t >= self.n_tris)
        {
            return bad("a pair refers to a triangle out of range".into());
        }
        let mut next_voxel = 0u32;
        // Child blocks follow one another in the order of their parents (level order), so
        // every node but the root has exactly one parent and one level.
        let mut next_block = 1usize;
        let mut levels = vec![0u8; self.nodes.len()];
        for (i, n) in self.nodes.iter().enumerate() {
            if n.is_empty() {
                continue;
            }
            if n.payload != next_voxel || n.payload as usize >= self.voxels.len() {
                return bad(format!("node {i}: voxel payloads out of order"));
            }
            next_voxel += 1;
            let v = n.index();
            if n.is_leaf() {
                if v >= self.n_tris + self.n_pair_words {
                    let at = (v - self.n_tris) as usize;
                    let Some(&count) = self.tri_index.get(at) else {
                        return bad(format!("node {i}: list offset out of range"));
                    };
                    let Some(list) = self.tri_index.get(at + 1..at + 1 + count as usize) else {
                        return bad(format!("node {i}: list length out of range"));
                    };
                    if list.iter().any(|&t| t >= self.n_tris) {
                        return bad(format!("node {i}: triangle out of range"));
                    }
                }
            } else if v as usize != next_block
                || v as usize + 8 > self.nodes.len()
                || levels[i] >= self.max_depth
            {
                return bad(format!("node {i}: child index {v} out of place"));
            } else {
                let l = levels[i] + 1;
                levels[v as usize..v as usize + 8].fill(l);
                next_block += 8;
            }
        }
        if next_block != self.nodes.len() {
            return bad(format!(
                "{} nodes, but the child blocks end at {next_block}",
                self.nodes.len()
            ));
        }
        if next_voxel as usize != self.voxels.len() {
            return bad("more voxels than non-empty nodes".into());
        }
        Ok(())
    }
}
