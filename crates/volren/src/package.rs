//! The hybrid scheme's packages and its two ends (paper 03, sections 4-5): the server sends a
//! *static* package once (transfer functions, the low-resolution wavelet volume `V_W`, the
//! Gradient Octree structure at one bit per node) and a *dynamic* package per region of
//! interest (the 3-byte data of the ROI's leaves, in the restricted order both ends derive,
//! so no index travels).
//!
//! # Wire format (version 1, little-endian)
//!
//! Every package: magic `WSCG03` (6 bytes), version (u8 = 1), kind (u8: 1 static, 2 ROI),
//! payload length (u64), CRC-32 of the payload (u32), payload.
//!
//! - Static payload: volume id (u64), dims (3 x u32), canonical TF index (u8), TF count (u8),
//!   per TF its point count (u16) and points (density f32, RGBA 4 x f32); wavelet steps sent
//!   (u8), quantisation steps (4 x f32), block stream length (u64) and bytes; octree side `R`
//!   (u32), the 32^3 occupancy bitmask (4096 bytes) and the child bytes of every level
//!   32..R/2 (their counts follow from the previous level's bits).
//! - ROI payload: volume id (u64), ROI min and max (6 x u32), leaf count (u64), 3 bytes a leaf.
//!
//! The volume id is an FNV-1a hash of the dims, voxels and transfer functions, so a ROI
//! package built for another volume is refused; a client also checks the leaf count against
//! the one it derives from the structure and the ROI before reading the leaves.

use wscg_math::{Error, Result, Volume};

use crate::bytes::{Reader, Writer};
use crate::gradient_octree::{EdgeRule, GoStructure, GradientOctree, Roi};
use crate::tf::{MaterialTable, PiecewiseTransferFunction};
use crate::wavelet::{decode_lowres, encode_blocks, HaarQuant, WaveletPackage};

const MAGIC: &[u8; 6] = b"WSCG03";
/// Wire format version.
pub const VERSION: u8 = 1;
const KIND_STATIC: u8 = 1;
const KIND_ROI: u8 = 2;
const HEADER: usize = 6 + 1 + 1 + 8 + 4;

wscg_math::params! {
    /// Server parameters.
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct ServerParams {
        /// Wavelet steps sent in the static package (1..=4; 2 gives the paper's 1/64 volume).
        pub steps_sent: u8,
        /// Quantisation of the wavelet details.
        pub quant: HaarQuant,
        /// Which voxels the octree stores.
        pub edge_rule: EdgeRule,
    }
}

impl Default for ServerParams {
    fn default() -> Self {
        Self {
            steps_sent: 2,
            quant: HaarQuant::default(),
            edge_rule: EdgeRule::Boundary,
        }
    }
}

impl ServerParams {
    /// Errors: `steps_sent` outside `1..=4`, a quantisation step of `quant` not finite and
    /// positive (`edge_rule` is a choice, each valid).
    pub fn validate(&self) -> Result<()> {
        if !(1..=4).contains(&self.steps_sent) {
            return Err(Error::invalid(
                "steps_sent",
                format!("must be in 1..=4, got {}", self.steps_sent),
            ));
        }
        if self
            .quant
            .delta
            .iter()
            .any(|d| !(d.is_finite() && *d > 0.0))
        {
            return Err(Error::invalid(
                "quant",
                format!(
                    "quantisation steps must be finite and > 0, got {:?}",
                    self.quant.delta
                ),
            ));
        }
        Ok(())
    }
}

fn frame(kind: u8, payload: Vec<u8>) -> Vec<u8> {
    let mut out = Vec::with_capacity(HEADER + payload.len());
    out.extend_from_slice(MAGIC);
    out.push(VERSION);
    out.push(kind);
    out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    out.extend_from_slice(&crc32fast::hash(&payload).to_le_bytes());
    out.extend_from_slice(&payload);
    out
}

fn bad(msg: impl Into<String>) -> Error {
    Error::invalid("package", msg.into())
}

/// Checks the header of a package of `kind` and returns its payload.
fn unframe(bytes: &[u8], kind: u8) -> Result<&[u8]> {
    if bytes.len() < HEADER {
        return Err(bad(format!(
            "{} bytes, shorter than the header",
            bytes.len()
        )));
    }
    if &bytes[..6] != MAGIC {
        return Err(bad("not a wscg paper-03 package (bad magic)"));
    }
    if bytes[6] != VERSION {
        return Err(bad(format!(
            "version {} (this build reads {VERSION})",
            bytes[6]
        )));
    }
    if bytes[7] != kind {
        return Err(bad(format!(
            "package kind {} where {kind} was expected",
            bytes[7]
        )));
    }
    let len = u64::from_le_bytes(bytes[8..16].try_into().expect("8 bytes"));
    let payload = &bytes[HEADER..];
    if payload.len() as u64 != len {
        return Err(bad(format!(
            "payload of {} bytes, header says {len} (truncated or padded)",
            payload.len()
        )));
    }
    let crc = u32::from_le_bytes(bytes[16..20].try_into().expect("4 bytes"));
    if crc32fast::hash(payload) != crc {
        return Err(bad("CRC mismatch (corrupted package)"));
    }
    Ok(payload)
}

/// FNV-1a over byte slices.
fn fnv1a<'a>(parts: impl IntoIterator<Item = &'a [u8]>) -> u64 {
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    for p in parts {
        for &b in p {
            h ^= b as u64;
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
    }
    h
}

fn write_tfs(w: &mut Writer, tfs: &[PiecewiseTransferFunction]) {
    w.u8(tfs.len() as u8);
    for t in tfs {
        w.u16(t.points().len() as u16);
        for (d, c) in t.points() {
            w.f32(*d);
            c.iter().for_each(|&v| w.f32(v));
        }
    }
}

fn read_tfs(r: &mut Reader) -> Result<Vec<PiecewiseTransferFunction>> {
    let n = r.u8()?;
    (0..n)
        .map(|_| {
            let k = r.u16()?;
            let pts = (0..k)
                .map(|_| Ok((r.f32()?, [r.f32()?, r.f32()?, r.f32()?, r.f32()?])))
                .collect::<Result<Vec<_>>>()?;
            PiecewiseTransferFunction::new(pts)
        })
        .collect()
}

/// The server: the volume, its transfer functions, wavelet package and Gradient Octree.
#[derive(Clone, Debug)]
pub struct HybridServer {
    volume: Volume<u8>,
    tfs: Vec<PiecewiseTransferFunction>,
    canonical: usize,
    wavelet: WaveletPackage,
    octree: GradientOctree,
    id: u64,
    opts: ServerParams,
}

/// Bytes each scheme sends (paper 03, Tables 1 and 2), all measured on serialized buffers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SizeReport {
    /// The raw volume (Volume Viewer [5]): one byte a voxel.
    pub raw: usize,
    /// The wavelet scheme [1]: the block stream with all 4 steps for the whole volume.
    pub wavelets: usize,
    /// The Gradient Octree [2]: its structure and every leaf.
    pub gradient_octree: usize,
    /// The hybrid static package.
    pub hybrid_static: usize,
    /// The hybrid ROI package.
    pub hybrid_roi: usize,
    /// One JPEG frame (quality 85) of a thin client [6], if a viewport was given.
    pub thin_client_frame: Option<usize>,
}

impl SizeReport {
    /// Hybrid bytes: static plus ROI package.
    pub fn hybrid(&self) -> usize {
        self.hybrid_static + self.hybrid_roi
    }

    /// `bytes / raw`.
    pub fn rate(&self, bytes: usize) -> f64 {
        bytes as f64 / self.raw as f64
    }

    /// Frames of the thin client that cost as much as `bytes` (`None` without a frame size).
    pub fn break_even(&self, bytes: usize) -> Option<f64> {
        self.thin_client_frame.map(|f| bytes as f64 / f as f64)
    }
}

impl HybridServer {
    /// Prepares `v` for the transfer functions `tfs` (`canonical` selects the one of the
    /// low-resolution context).
    ///
    /// Errors: empty volume, no transfer function or more than 255, more than 63 materials,
    /// `canonical` out of range, bad options.
    pub fn new(
        v: &Volume<u8>,
        tfs: Vec<PiecewiseTransferFunction>,
        canonical: usize,
        opts: ServerParams,
    ) -> Result<Self> {
        opts.validate()?;
        if v.dims().contains(&0) {
            return Err(Error::Empty("volume"));
        }
        if tfs.is_empty() || tfs.len() > 255 {
            return Err(Error::invalid(
                "tfs",
                format!("need 1 to 255 transfer functions, got {}", tfs.len()),
            ));
        }
        if canonical >= tfs.len() {
            return Err(Error::invalid(
                "canonical",
                format!("index {canonical} for {} transfer functions", tfs.len()),
            ));
        }
        if tfs.iter().any(|t| t.points().len() > u16::MAX as usize) {
            return Err(Error::invalid("tfs", "too many control points"));
        }
        let mats = MaterialTable::from_tfs(&tfs)?;
        let wavelet = encode_blocks(v, &tfs[canonical], &opts.quant, opts.steps_sent)?;
        let octree = GradientOctree::build(v, &mats, opts.edge_rule)?;
        let mut tf_bytes = Writer::default();
        write_tfs(&mut tf_bytes, &tfs);
        let dims_bytes: Vec<u8> = v
            .dims()
            .iter()
            .flat_map(|&d| (d as u32).to_le_bytes())
            .collect();
        let id = fnv1a([dims_bytes.as_slice(), v.data(), tf_bytes.0.as_slice()]);
        Ok(Self {
            volume: v.clone(),
            tfs,
            canonical,
            wavelet,
            octree,
            id,
            opts,
        })
    }

    /// The Gradient Octree.
    pub fn octree(&self) -> &GradientOctree {
        &self.octree
    }

    /// The volume the server was built from.
    pub fn volume(&self) -> &Volume<u8> {
        &self.volume
    }

    /// The transfer functions the clients may choose.
    pub fn tfs(&self) -> &[PiecewiseTransferFunction] {
        &self.tfs
    }

    /// The index of the canonical transfer function (the low-resolution context's).
    pub fn canonical(&self) -> usize {
        self.canonical
    }

    /// The server parameters. [`HybridServer::new`] of [`Self::volume`], [`Self::tfs`],
    /// [`Self::canonical`] and these rebuilds the same server (the same packages).
    pub fn params(&self) -> &ServerParams {
        &self.opts
    }

    /// The static package (sent once).
    pub fn static_package(&self) -> Vec<u8> {
        let mut w = Writer::default();
        w.u64(self.id);
        self.volume.dims().iter().for_each(|&d| w.u32(d as u32));
        w.u8(self.canonical as u8);
        write_tfs(&mut w, &self.tfs);
        let p = &self.wavelet;
        w.u8(p.steps_sent);
        p.quant.delta.iter().for_each(|&d| w.f32(d));
        w.u64(p.blocks.len() as u64);
        w.bytes(&p.blocks);
        let s = &self.octree.structure;
        w.u32(s.r as u32);
        let (bits, b) = s.occupancy();
        w.bytes(&bits);
        b.iter().for_each(|l| w.bytes(l));
        frame(KIND_STATIC, w.0)
    }

    /// The bytes of every scheme for `roi` and, with `thin_client = Some(camera)`, the JPEG
    /// size of one full-resolution frame (canonical transfer function outside the ROI,
    /// `roi_tf` inside) at the camera's viewport.
    ///
    /// Errors: a bad ROI, camera or `roi_tf`.
    pub fn size_report(
        &self,
        min: [u32; 3],
        max: [u32; 3],
        roi_tf: usize,
        thin_client: Option<&crate::render::Camera>,
    ) -> Result<SizeReport> {
        let roi = Roi::snapped(min, max, self.volume.dims())?;
        let tf = self.tfs.get(roi_tf).ok_or_else(|| {
            Error::invalid(
                "roi_tf",
                format!("{roi_tf} of {} transfer functions", self.tfs.len()),
            )
        })?;
        let full = encode_blocks(&self.volume, &self.tfs[self.canonical], &self.opts.quant, 4)?;
        let (bits, b) = self.octree.structure.occupancy();
        let go = bits.len()
            + b.iter().map(Vec::len).sum::<usize>()
            + self
                .roi_package([0; 3], self.volume.dims().map(|d| d as u32))?
                .len();
        let thin = match thin_client {
            Some(cam) => {
                let img = crate::render::render_reference(
                    &self.volume,
                    &self.tfs[self.canonical],
                    Some((&roi, tf)),
                    cam,
                    &crate::render::RenderParams::default(),
                )?;
                Some(crate::render::rgb(&img)?.encode_jpeg(85)?.len())
            }
            None => None,
        };
        Ok(SizeReport {
            raw: self.volume.len(),
            wavelets: full.blocks.len(),
            gradient_octree: go,
            hybrid_static: self.static_package().len(),
            hybrid_roi: self.roi_package(min, max)?.len(),
            thin_client_frame: thin,
        })
    }

    /// The dynamic package of `roi` (snapped outward to multiples of 16 and clamped).
    ///
    /// Errors: an inverted ROI or one outside the volume.
    pub fn roi_package(&self, min: [u32; 3], max: [u32; 3]) -> Result<Vec<u8>> {
        let roi = Roi::snapped(min, max, self.volume.dims())?;
        let leaves = self.octree.roi_leaves(&roi);
        let mut w = Writer::default();
        w.u64(self.id);
        roi.min.iter().chain(&roi.max).for_each(|&c| w.u32(c));
        w.u64(leaves.len() as u64);
        leaves.iter().for_each(|l| w.bytes(l));
        Ok(frame(KIND_ROI, w.0))
    }
}

/// What a client holds: the static information and, after [`HybridClient::set_roi`], the
/// restricted structure and leaf data of one ROI.
#[derive(Clone, Debug)]
pub struct HybridClient {
    /// Volume size.
    pub dims: [usize; 3],
    /// Transfer functions (index `canonical` colours the context).
    pub tfs: Vec<PiecewiseTransferFunction>,
    /// Canonical transfer function index.
    pub canonical: usize,
    /// Materials of the transfer functions.
    pub materials: MaterialTable,
    /// The decoded low-resolution volume `V_W`.
    pub lowres: Volume<f32>,
    /// Voxels per `V_W` voxel along each axis.
    pub lowres_factor: usize,
    /// The full octree structure rebuilt from the static package.
    pub structure: GoStructure,
    /// The current ROI: box, restricted structure and leaf data (row 0 unused).
    pub roi: Option<(Roi, GoStructure, Vec<[u8; 3]>)>,
    /// Empty-space cells of the context: `CONTEXT_CELL^3` voxels of `V_W` each, true where
    /// the canonical transfer function is transparent over every density a trilinear sample
    /// inside the cell can take.
    pub(crate) context_empty: crate::render::EmptyCells,
    id: u64,
}

impl HybridClient {
    /// Reads a static package.
    ///
    /// Errors: any malformed, truncated or corrupted package.
    pub fn from_static(bytes: &[u8]) -> Result<Self> {
        let mut r = Reader::new(unframe(bytes, KIND_STATIC)?, "package");
        let id = r.u64()?;
        let dims = [r.u32()?, r.u32()?, r.u32()?].map(|d| d as usize);
        if dims.contains(&0) || dims.iter().any(|&d| d > 1 << 16) {
            return Err(bad(format!("volume dims {dims:?}")));
        }
        let canonical = r.u8()? as usize;
        let tfs = read_tfs(&mut r)?;
        if canonical >= tfs.len() {
            return Err(bad("canonical transfer function out of range"));
        }
        let materials = MaterialTable::from_tfs(&tfs)?;
        let steps_sent = r.u8()?;
        let quant = HaarQuant {
            delta: [r.f32()?, r.f32()?, r.f32()?, r.f32()?],
        };
        let n = r.u64()?;
        let blocks = r.take(usize::try_from(n).map_err(|_| bad("block stream length"))?)?;
        let wavelet = WaveletPackage {
            dims,
            steps_sent,
            quant,
            blocks: blocks.to_vec(),
        };
        let lowres = decode_lowres(&wavelet, steps_sent)?;
        let side = r.u32()? as usize;
        if side != crate::gradient_octree::cube_side(dims) {
            return Err(bad(format!("octree side {side} for dims {dims:?}")));
        }
        let bits = r.take(4096)?;
        let depth = side.trailing_zeros() as usize - 5;
        let mut n_nodes = bits.iter().map(|b| b.count_ones() as usize).sum::<usize>();
        let mut levels = Vec::with_capacity(depth);
        for _ in 0..depth {
            let l = r.take(n_nodes)?;
            n_nodes = l.iter().map(|b| b.count_ones() as usize).sum();
            levels.push(l.to_vec());
        }
        r.done()?;
        let structure = GoStructure::from_occupancy(side, bits, &levels)?;
        let context_empty = crate::render::EmptyCells::new(&lowres, &tfs[canonical]);
        Ok(Self {
            dims,
            tfs,
            canonical,
            materials,
            lowres,
            lowres_factor: 1 << (4 - steps_sent as usize),
            structure,
            roi: None,
            context_empty,
            id,
        })
    }

    /// Reads a ROI package: checks it belongs to this volume and that its leaf count is the
    /// one the structure and the ROI imply, then keeps the restricted structure and leaves.
    ///
    /// Errors: malformed, truncated or corrupted package, another volume's package, a ROI
    /// outside the volume, a leaf count that does not match.
    pub fn set_roi(&mut self, bytes: &[u8]) -> Result<()> {
        let mut r = Reader::new(unframe(bytes, KIND_ROI)?, "package");
        if r.u64()? != self.id {
            return Err(bad("ROI package of another volume (volume id mismatch)"));
        }
        let min = [r.u32()?, r.u32()?, r.u32()?];
        let max = [r.u32()?, r.u32()?, r.u32()?];
        let roi = Roi::snapped(min, max, self.dims)?;
        if roi.min != min || roi.max != max {
            return Err(bad("ROI not snapped to the volume's 16-voxel grid"));
        }
        let (restricted, full) = self.structure.restrict(&roi);
        let count = r.u64()?;
        if count != full.len() as u64 {
            return Err(bad(format!(
                "{count} leaves in the package, the structure and ROI imply {}",
                full.len()
            )));
        }
        let data = r.take(3 * full.len())?;
        r.done()?;
        let mut leaves = Vec::with_capacity(full.len() + 1);
        leaves.push([0u8; 3]);
        leaves.extend(data.chunks_exact(3).map(|c| [c[0], c[1], c[2]]));
        self.roi = Some((roi, restricted, leaves));
        Ok(())
    }

    /// Drops the ROI (render the context only).
    pub fn clear_roi(&mut self) {
        self.roi = None;
    }
}
