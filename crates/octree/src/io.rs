//! The octree file: the structure and the mesh it references, little-endian, with a CRC-32
//! trailer, so a saved tree reloads bit-identically and a damaged file is an error.
//!
//! Layout: magic `WSCGOCT1`; `u32` flags (bit 0 early stop, bit 1 colours); `u32` depth;
//! cube corner and side (4 `f64`); counts `V, F, N, M, K` (`u64`) and `P` (`u32`); positions
//! (`3V f64`), faces (`3F u32`), colours (`3V f32`, when present), nodes (`2N u32`), voxels
//! (`M x` 4 colour bytes and 2 `i16`), the triangle-index array (`K u32`); CRC-32 of all of it.

use std::path::Path;

use wscg_math::{Error, Result, TriMesh};

use crate::cube::Cube;
use crate::node::{Node, Voxel};
use crate::octree::HybridOctree;

const MAGIC: &[u8; 8] = b"WSCGOCT1";

impl HybridOctree {
    /// Serializes the tree and its mesh.
    pub fn to_bytes(&self) -> Vec<u8> {
        let m = &self.mesh;
        let colors = m.colors.as_deref();
        let mut b = Vec::with_capacity(
            96 + 24 * m.positions.len()
                + 12 * m.faces.len()
                + 8 * self.nodes.len()
                + 8 * self.voxels.len()
                + 4 * self.tri_index.len(),
        );
        b.extend_from_slice(MAGIC);
        let flags = u32::from(self.early_stop) | (u32::from(colors.is_some()) << 1);
        b.extend_from_slice(&flags.to_le_bytes());
        b.extend_from_slice(&u32::from(self.max_depth).to_le_bytes());
        for v in self.cube.min.iter().chain([&self.cube.size]) {
            b.extend_from_slice(&v.to_le_bytes());
        }
        for n in [
            m.positions.len(),
            m.faces.len(),
            self.nodes.len(),
            self.voxels.len(),
            self.tri_index.len(),
        ] {
            b.extend_from_slice(&(n as u64).to_le_bytes());
        }
        b.extend_from_slice(&self.n_pair_words.to_le_bytes());
        m.positions
            .iter()
            .flatten()
            .for_each(|v| b.extend_from_slice(&v.to_le_bytes()));
        m.faces
            .iter()
            .flatten()
            .for_each(|v| b.extend_from_slice(&v.to_le_bytes()));
        if let Some(c) = colors {
            c.iter()
                .flatten()
                .for_each(|v| b.extend_from_slice(&v.to_le_bytes()));
        }
        for n in self.nodes.iter() {
            b.extend_from_slice(&n.next.to_le_bytes());
            b.extend_from_slice(&n.payload.to_le_bytes());
        }
        for v in &self.voxels {
            b.extend_from_slice(&v.rgba);
            b.extend_from_slice(&v.normal_oct[0].to_le_bytes());
            b.extend_from_slice(&v.normal_oct[1].to_le_bytes());
        }
        self.tri_index
            .iter()
            .for_each(|v| b.extend_from_slice(&v.to_le_bytes()));
        let crc = crc32fast::hash(&b);
        b.extend_from_slice(&crc.to_le_bytes());
        b
    }

    /// Reads a tree written by [`HybridOctree::to_bytes`]; `origin` names the source in
    /// errors. The checksum, the counts and the structure are all checked.
    pub fn from_bytes(bytes: &[u8], origin: &Path) -> Result<Self> {
        let bad = |why: &str| Error::format(origin, format!("not a valid octree file: {why}"));
        if bytes.len() < MAGIC.len() + 4 || &bytes[..8] != MAGIC {
            return Err(bad("missing WSCGOCT1 header"));
        }
        let (body, tail) = bytes.split_at(bytes.len() - 4);
        let crc = u32::from_le_bytes(tail.try_into().map_err(|_| bad("truncated"))?);
        if crc32fast::hash(body) != crc {
            return Err(bad("checksum mismatch (the file is damaged or truncated)"));
        }
        let mut r = Reader { b: body, at: 8 };
        let trunc = || bad("truncated");
        let flags = r.u32().ok_or_else(trunc)?;
        let depth = r.u32().ok_or_else(trunc)?;
        let mut c = [0f64; 4];
        for v in &mut c {
            *v = r.f64().ok_or_else(trunc)?;
        }
        let mut counts = [0usize; 5];
        for n in &mut counts {
            *n = usize::try_from(r.u64().ok_or_else(trunc)?).map_err(|_| bad("count too large"))?;
        }
        let [nv, nf, nn, nm, nk] = counts;
        let need = nv
            .checked_mul(24)
            .zip(nf.checked_mul(12))
            .zip(nn.checked_mul(8))
            .zip(nm.checked_mul(8))
            .zip(nk.checked_mul(4))
            .and_then(|((((a, b), c), d), e)| {
                a.checked_add(b)?
                    .checked_add(c)?
                    .checked_add(d)?
                    .checked_add(e)
            });
        if need.is_none_or(|n| n > body.len()) {
            return Err(bad("counts exceed the file size"));
        }
        let n_pair_words = r.u32().ok_or_else(trunc)?;
        let positions: Vec<[f64; 3]> = (0..nv)
            .map(|_| Some([r.f64()?, r.f64()?, r.f64()?]))
            .collect::<Option<_>>()
            .ok_or_else(trunc)?;
        let faces: Vec<[u32; 3]> = (0..nf)
            .map(|_| Some([r.u32()?, r.u32()?, r.u32()?]))
            .collect::<Option<_>>()
            .ok_or_else(trunc)?;
        let colors: Option<Vec<[f32; 3]>> = if flags & 2 != 0 {
            Some(
                (0..nv)
                    .map(|_| Some([r.f32()?, r.f32()?, r.f32()?]))
                    .collect::<Option<_>>()
                    .ok_or_else(trunc)?,
            )
        } else {
            None
        };
        let nodes: Vec<Node> = (0..nn)
            .map(|_| {
                Some(Node {
                    next: r.u32()?,
                    payload: r.u32()?,
                })
            })
            .collect::<Option<_>>()
            .ok_or_else(trunc)?;
        let voxels: Vec<Voxel> = (0..nm)
            .map(|_| {
                let c = r.take(4)?;
                Some(Voxel {
                    rgba: [c[0], c[1], c[2], c[3]],
                    normal_oct: [r.i16()?, r.i16()?],
                })
            })
            .collect::<Option<_>>()
            .ok_or_else(trunc)?;
        let tri_index: Vec<u32> = (0..nk)
            .map(|_| r.u32())
            .collect::<Option<_>>()
            .ok_or_else(trunc)?;
        if r.at != body.len() {
            return Err(bad("trailing bytes"));
        }
        let mut mesh = TriMesh::new(positions, faces).map_err(|e| bad(&e.to_string()))?;
        if let Some(c) = colors {
            mesh = mesh.with_colors(c).map_err(|e| bad(&e.to_string()))?;
        }
        let depth = u8::try_from(depth).map_err(|_| bad("depth out of range"))?;
        crate::cube::check_depth(depth).map_err(|e| bad(&e.to_string()))?;
        let cube = Cube::new([c[0], c[1], c[2]], c[3]).map_err(|e| bad(&e.to_string()))?;
        let oct = HybridOctree::from_parts(
            nodes,
            voxels,
            tri_index,
            n_pair_words,
            cube,
            depth,
            flags & 1 != 0,
            mesh,
        );
        oct.check().map_err(|e| bad(&e.to_string()))?;
        Ok(oct)
    }

    /// Writes the tree to `path`, atomically (a failed write leaves any previous file).
    pub fn save(&self, path: impl AsRef<Path>) -> Result<()> {
        wscg_math::io::atomic::write(path, self.to_bytes())
    }

    /// Reads a tree saved by [`HybridOctree::save`].
    pub fn load(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let bytes = wscg_math::error::read_file(path)?;
        Self::from_bytes(&bytes, path)
    }
}

/// A bounds-checked little-endian reader.
struct Reader<'a> {
    b: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn take(&mut self, n: usize) -> Option<&[u8]> {
        let s = self.b.get(self.at..self.at.checked_add(n)?)?;
        self.at += n;
        Some(s)
    }
    fn u32(&mut self) -> Option<u32> {
        Some(u32::from_le_bytes(self.take(4)?.try_into().ok()?))
    }
    fn i16(&mut self) -> Option<i16> {
        Some(i16::from_le_bytes(self.take(2)?.try_into().ok()?))
    }
    fn u64(&mut self) -> Option<u64> {
        Some(u64::from_le_bytes(self.take(8)?.try_into().ok()?))
    }
    fn f32(&mut self) -> Option<f32> {
        Some(f32::from_le_bytes(self.take(4)?.try_into().ok()?))
    }
    fn f64(&mut self) -> Option<f64> {
        Some(f64::from_le_bytes(self.take(8)?.try_into().ok()?))
    }
}
