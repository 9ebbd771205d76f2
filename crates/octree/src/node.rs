//! The compact node layout (paper §3 "Data Structure", Figs. 2-3): two 32-bit words per node,
//! an 8-byte voxel payload per non-empty node, and the single / pair / list encoding of a
//! leaf's triangles.

/// Payload of an empty node.
pub const EMPTY: u32 = u32::MAX;
/// `Node::next` bit 31: the node is a leaf.
pub const LEAF_BIT: u32 = 1 << 31;
/// `Node::next` bit 30: split flag, used during construction only.
pub const SPLIT_BIT: u32 = 1 << 30;
/// `Node::next` bits 0-29: first child (inner) or triangle code (leaf).
pub const INDEX_MASK: u32 = SPLIT_BIT - 1;

/// One octree node: exactly 8 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Node {
    /// Bit 31 leaf, bit 30 split (construction), bits 0-29 first child or triangle code.
    pub next: u32,
    /// Index into the voxel array, or [`EMPTY`].
    pub payload: u32,
}

impl Node {
    /// An empty node.
    pub const EMPTY_NODE: Node = Node {
        next: 0,
        payload: EMPTY,
    };

    /// Whether the node holds no geometry.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.payload == EMPTY
    }

    /// Whether the node is a leaf (its `index` is a triangle code).
    #[inline]
    pub fn is_leaf(&self) -> bool {
        self.next & LEAF_BIT != 0
    }

    /// First child (inner node) or triangle code (leaf).
    #[inline]
    pub fn index(&self) -> u32 {
        self.next & INDEX_MASK
    }
}

/// Eight nodes, one 64-byte cache line.
#[repr(C, align(64))]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
struct NodeLine([Node; 8]);

/// Nodes not stored before node 0, so that every block of 8 children (which starts at a node
/// index `1 + 8 k`) fills exactly one cache line.
const LEAD: usize = 7;

/// The node array, stored so that the 8 children of an inner node share one cache line: the
/// traversal reads them with one memory access instead of two. Dereferences to `[Node]`; the
/// node indices are those of the paper's layout (root 0, children blocks at `1 + 8 k`).
#[derive(Clone)]
pub struct NodeArray {
    lines: Vec<NodeLine>,
    len: usize,
}

impl From<&[Node]> for NodeArray {
    fn from(nodes: &[Node]) -> Self {
        let mut lines = vec![NodeLine::default(); (LEAD + nodes.len()).div_ceil(8)];
        for (i, &n) in nodes.iter().enumerate() {
            let j = LEAD + i;
            lines[j / 8].0[j % 8] = n;
        }
        Self {
            lines,
            len: nodes.len(),
        }
    }
}

impl std::ops::Deref for NodeArray {
    type Target = [Node];
    #[inline]
    fn deref(&self) -> &[Node] {
        // SAFETY: `NodeLine` is `repr(C)` around `[Node; 8]` with size 64 = 8 * size_of::<Node>()
        // (no padding), so the lines hold `8 * lines.len() >= LEAD + len` contiguous nodes
        // (`From` allocates at least that many, and at least one line).
        unsafe {
            std::slice::from_raw_parts(self.lines.as_ptr().cast::<Node>().add(LEAD), self.len)
        }
    }
}

impl std::fmt::Debug for NodeArray {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_list().entries(self.iter()).finish()
    }
}

impl PartialEq for NodeArray {
    fn eq(&self, other: &Self) -> bool {
        **self == **other
    }
}

/// Pre-filtered voxel attributes of a node: RGBA8 colour and an octahedral normal, 8 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Voxel {
    /// Mean colour of the node's surface.
    pub rgba: [u8; 4],
    /// Mean unit normal, octahedral-encoded (Cigolle et al. 2014) in signed 16-bit.
    pub normal_oct: [i16; 2],
}

impl Voxel {
    /// Colour as RGB in `[0, 1]`.
    #[inline]
    pub fn color(&self) -> [f32; 3] {
        [0, 1, 2].map(|k| f32::from(self.rgba[k]) / 255.0)
    }

    /// Decoded unit normal.
    #[inline]
    pub fn normal(&self) -> [f32; 3] {
        oct_decode(self.normal_oct)
    }
}

/// Octahedral encoding of a unit vector.
pub fn oct_encode(n: [f32; 3]) -> [i16; 2] {
    let l1 = n[0].abs() + n[1].abs() + n[2].abs();
    if l1.is_nan() || l1 <= 0.0 || !l1.is_finite() {
        return [0, 0];
    }
    let (mut x, mut y) = (n[0] / l1, n[1] / l1);
    if n[2] < 0.0 {
        let (ox, oy) = (x, y);
        x = (1.0 - oy.abs()) * if ox >= 0.0 { 1.0 } else { -1.0 };
        y = (1.0 - ox.abs()) * if oy >= 0.0 { 1.0 } else { -1.0 };
    }
    [x, y].map(|v| (v.clamp(-1.0, 1.0) * 32767.0).round() as i16)
}

/// Decodes [`oct_encode`].
pub fn oct_decode(e: [i16; 2]) -> [f32; 3] {
    let mut x = f32::from(e[0]) / 32767.0;
    let mut y = f32::from(e[1]) / 32767.0;
    let z = 1.0 - x.abs() - y.abs();
    if z < 0.0 {
        let (ox, oy) = (x, y);
        x = (1.0 - oy.abs()) * if ox >= 0.0 { 1.0 } else { -1.0 };
        y = (1.0 - ox.abs()) * if oy >= 0.0 { 1.0 } else { -1.0 };
    }
    let l = (x * x + y * y + z * z).sqrt();
    [x / l, y / l, z / l]
}

/// The triangles of a leaf, decoded from its code (paper §3, Fig. 2).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LeafTris<'a> {
    /// One triangle: code `v < T`.
    Single(u32),
    /// Two triangles: `T <= v < T + P`, stored at `tri_index[v - T]` and the next word.
    Pair(u32, u32),
    /// Three or more (finest level only): `v >= T + P`, a count followed by the indices.
    List(&'a [u32]),
}

impl LeafTris<'_> {
    /// Number of triangles.
    pub fn len(&self) -> usize {
        match self {
            LeafTris::Single(_) => 1,
            LeafTris::Pair(..) => 2,
            LeafTris::List(l) => l.len(),
        }
    }

    /// Whether the leaf holds no triangle (never for a non-empty node).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Calls `f` on every triangle.
    #[inline]
    pub fn for_each(&self, mut f: impl FnMut(u32)) {
        match *self {
            LeafTris::Single(a) => f(a),
            LeafTris::Pair(a, b) => {
                f(a);
                f(b)
            }
            LeafTris::List(l) => l.iter().copied().for_each(f),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn child_blocks_fill_whole_cache_lines() {
        let nodes: Vec<Node> = (0..1 + 8 * 5)
            .map(|i| Node {
                next: i,
                payload: 2 * i,
            })
            .collect();
        let a = NodeArray::from(&nodes[..]);
        assert_eq!(&a[..], &nodes[..]);
        for k in 0..5 {
            assert_eq!(a[1 + 8 * k..].as_ptr() as usize % 64, 0);
        }
        assert!(NodeArray::from(&[][..]).is_empty());
    }

    #[test]
    fn node_is_eight_bytes_and_octahedral_normals_round_trip() {
        assert_eq!(std::mem::size_of::<Node>(), 8);
        assert_eq!(std::mem::size_of::<Voxel>(), 8);
        for n in [
            [0.0f32, 0.0, 1.0],
            [0.0, 0.0, -1.0],
            [0.6, -0.8, 0.0],
            [-0.48, 0.6, -0.64],
            [0.577, 0.577, 0.577],
        ] {
            let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            let n = n.map(|v: f32| v / l);
            let d = oct_decode(oct_encode(n));
            let dot = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
            // Within 1e-3 rad: 1 - cos(1e-3) = 5e-7.
            assert!(dot > 1.0 - 5e-7, "{n:?} -> {d:?}");
        }
    }
}
