//! The client's two-level ray caster (paper 03, section 5) and the comparison renderers.
//!
//! A ray is cut into the parts outside and inside the ROI box. Outside, the low-resolution
//! volume `V_W` is sampled trilinearly every `context_step` voxels and coloured by the
//! canonical transfer function without lighting (as the paper's figures). Inside, the ray
//! steps `step` voxels through the restricted Gradient Octree: a nil voxel adds nothing, a
//! stored one is coloured by the ROI transfer function at its material's representative
//! density and shaded with its decoded normal, `c (k_a + k_d |n.l|) + k_s |n.l|^32` under a
//! headlight. Samples composite front to back with the opacity corrected to the step,
//! `alpha = 1 - (1 - a)^(step / 1 voxel)`, and the ray stops at 98 % opacity.
//!
//! Coordinates are continuous voxel coordinates: voxel `(i, j, k)` covers `[i, i + 1) x ...`.
//! [`render_reference`] is the full-resolution counterpart (trilinear densities, gradients by
//! central differences) that the comparisons measure against.

use rayon::prelude::*;
use wscg_math::vec3::{add_scaled, cross, normalized_or_zero, sub, try_normalize};
use wscg_math::{Error, Image, Result, Volume};

use crate::gradient_octree::{lookup, GoStructure, Roi};
use crate::normal_code::decode_voxel;
use crate::tf::{MaterialTable, PiecewiseTransferFunction};

type V3 = [f64; 3];

/// The RGB channels of an RGBA rendering (for saving or encoding).
pub fn rgb(img: &Image<f32>) -> Result<Image<f32>> {
    let data = img
        .data()
        .chunks_exact(4)
        .flat_map(|c| [c[0], c[1], c[2]])
        .collect();
    Image::new(img.height(), img.width(), 3, data)
}

/// Side of an empty-space cell, in voxels of the sampled volume.
pub const CELL: usize = 4;

/// Empty-space cells of a volume for one transfer function: cell `c` covers the voxels
/// `[c CELL, (c + 1) CELL)` and is empty when the transfer function is transparent over the
/// range of the voxels `[c CELL - 1, (c + 1) CELL]` (all a trilinear sample in the cell
/// reads). Skipping a sample in an empty cell changes no pixel.
#[derive(Clone, Debug, Default)]
pub struct EmptyCells {
    dims: [usize; 3],
    empty: Vec<bool>,
}

impl EmptyCells {
    /// The cells of `v` under `tf`.
    pub fn new(v: &Volume<f32>, tf: &PiecewiseTransferFunction) -> Self {
        let vd = v.dims();
        let dims = vd.map(|d| d.div_ceil(CELL));
        let empty = (0..dims[0] * dims[1] * dims[2])
            .into_par_iter()
            .map(|c| {
                let cell = [c % dims[0], c / dims[0] % dims[1], c / (dims[0] * dims[1])];
                let lo = cell.map(|x| (x * CELL).saturating_sub(1));
                let hi: Vec<usize> = (0..3)
                    .map(|a| ((cell[a] + 1) * CELL).min(vd[a] - 1))
                    .collect();
                let (mut mn, mut mx) = (f32::MAX, f32::MIN);
                for z in lo[2]..=hi[2] {
                    for y in lo[1]..=hi[1] {
                        for x in lo[0]..=hi[0] {
                            let d = v.at(x, y, z);
                            mn = mn.min(d);
                            mx = mx.max(d);
                        }
                    }
                }
                tf.max_opacity(mn, mx) <= 0.0
            })
            .collect();
        Self { dims, empty }
    }

    /// Whether the sample at voxel coordinate `q` (the trilinear argument) lies in an empty
    /// cell.
    #[inline]
    fn skip(&self, q: V3) -> bool {
        if self.empty.is_empty() {
            return false;
        }
        let c: [usize; 3] =
            std::array::from_fn(|a| ((q[a].max(0.0) as usize) / CELL).min(self.dims[a] - 1));
        self.empty[c[0] + self.dims[0] * (c[1] + self.dims[1] * c[2])]
    }
}

/// A perspective pinhole camera in voxel coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position.
    pub eye: V3,
    /// Point looked at.
    pub target: V3,
    /// Up direction.
    pub up: V3,
    /// Vertical field of view (degrees, in (0, 180)).
    pub fov_deg: f64,
    /// Image width (pixels).
    pub width: usize,
    /// Image height (pixels).
    pub height: usize,
}

impl Camera {
    /// A camera looking at the centre of a `dims` volume from the direction given by
    /// `azimuth` and `elevation` (degrees), far enough for the volume to fill about 80 % of a
    /// `size x size` image at a 30 degree field of view; `z` is up.
    pub fn orbit(dims: [usize; 3], azimuth: f64, elevation: f64, size: usize) -> Self {
        let c = dims.map(|d| d as f64 / 2.0);
        let radius = 0.5 * dims.iter().map(|&d| (d * d) as f64).sum::<f64>().sqrt();
        let dist = radius / (15f64.to_radians().tan() * 0.8);
        let (a, e) = (azimuth.to_radians(), elevation.to_radians());
        let dir = [e.cos() * a.cos(), e.cos() * a.sin(), e.sin()];
        Self {
            eye: [
                c[0] + dist * dir[0],
                c[1] + dist * dir[1],
                c[2] + dist * dir[2],
            ],
            target: c,
            up: [0.0, 0.0, 1.0],
            fov_deg: 30.0,
            width: size,
            height: size,
        }
    }

    fn validate(&self) -> Result<()> {
        let finite = |v: V3| v.iter().all(|c| c.is_finite());
        if self.width == 0 || self.height == 0 || self.width * self.height > 1 << 26 {
            return Err(Error::invalid(
                "camera",
                format!("image size {}x{}", self.width, self.height),
            ));
        }
        let fov_ok = self.fov_deg > 0.0 && self.fov_deg < 180.0;
        if !(finite(self.eye) && finite(self.target) && finite(self.up) && fov_ok) {
            return Err(Error::invalid(
                "camera",
                "needs finite vectors and a fov in (0, 180)",
            ));
        }
        Ok(())
    }

    /// The view frame, computed once per image. Errors: invalid camera.
    fn frame(&self) -> Result<Frame> {
        self.validate()?;
        let f = try_normalize(sub(self.target, self.eye), 1e-12)
            .ok_or_else(|| Error::invalid("camera", "eye and target coincide"))?;
        let r = try_normalize(cross(f, self.up), 1e-12)
            .ok_or_else(|| Error::invalid("camera", "up is parallel to the view direction"))?;
        let t = (0.5 * self.fov_deg).to_radians().tan();
        Ok(Frame {
            f,
            r: r.map(|c| c * t * self.width as f64 / self.height as f64),
            u: cross(r, f).map(|c| c * t),
            width: self.width as f64,
            height: self.height as f64,
        })
    }
}

/// A camera's forward direction and its right and up vectors scaled to the image plane at
/// unit distance.
struct Frame {
    f: V3,
    r: V3,
    u: V3,
    width: f64,
    height: f64,
}

impl Frame {
    /// Unit direction of the ray through the centre of pixel `(px, py)`.
    #[inline]
    fn ray(&self, px: usize, py: usize) -> V3 {
        let sx = 2.0 * (px as f64 + 0.5) / self.width - 1.0;
        let sy = 1.0 - 2.0 * (py as f64 + 0.5) / self.height;
        normalized_or_zero(add_scaled(add_scaled(self.f, sx, self.r), sy, self.u))
    }
}

wscg_math::params! {
    /// Ray-casting parameters (the paper's choices where it gives them).
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct RenderParams {
        /// Step inside the ROI and of the reference renderer (voxels).
        pub step: f64,
        /// Step through the low-resolution context (voxels; half a `V_W` voxel at `w_l = 2`).
        pub context_step: f64,
        /// Opacity at which a ray stops.
        pub early_stop: f32,
        /// Background colour.
        pub background: [f32; 3],
        /// Ambient, diffuse and specular weights of the shading.
        pub ka: f32,
        /// Diffuse weight.
        pub kd: f32,
        /// Specular weight (exponent 32).
        pub ks: f32,
    }
}

impl Default for RenderParams {
    fn default() -> Self {
        Self {
            step: 0.5,
            context_step: 2.0,
            early_stop: 0.98,
            background: [0.0; 3],
            ka: 0.3,
            kd: 0.7,
            ks: 0.2,
        }
    }
}

impl RenderParams {
    /// Errors: `step` or `context_step` outside `(0, 64]` voxels, `early_stop` outside
    /// `(0, 1]`, a background colour outside `[0, 1]`, `ka`, `kd` or `ks` negative or not
    /// finite.
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [("step", self.step), ("context_step", self.context_step)] {
            if !(v.is_finite() && v > 0.0 && v <= 64.0) {
                return Err(Error::invalid(
                    name,
                    format!("steps must be in (0, 64] voxels, got {v}"),
                ));
            }
        }
        if !(self.early_stop > 0.0 && self.early_stop <= 1.0) {
            return Err(Error::invalid(
                "early_stop",
                format!("must be in (0, 1], got {}", self.early_stop),
            ));
        }
        if !self.background.iter().all(|v| (0.0..=1.0).contains(v)) {
            return Err(Error::invalid(
                "background",
                format!("must be in [0, 1], got {:?}", self.background),
            ));
        }
        for (name, v) in [("ka", self.ka), ("kd", self.kd), ("ks", self.ks)] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::invalid(
                    name,
                    format!("must be finite and >= 0, got {v}"),
                ));
            }
        }
        Ok(())
    }
}

/// Entry and exit of a ray through the box `[lo, hi]`.
fn slab(o: V3, d: V3, lo: V3, hi: V3) -> Option<(f64, f64)> {
    let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
    for a in 0..3 {
        if d[a].abs() < 1e-15 {
            if o[a] < lo[a] || o[a] > hi[a] {
                return None;
            }
            continue;
        }
        let (mut ta, mut tb) = ((lo[a] - o[a]) / d[a], (hi[a] - o[a]) / d[a]);
        if ta > tb {
            std::mem::swap(&mut ta, &mut tb);
        }
        t0 = t0.max(ta);
        t1 = t1.min(tb);
    }
    (t0 < t1).then_some((t0, t1))
}

/// Front-to-back accumulation.
struct Accum {
    c: [f32; 3],
    a: f32,
}

/// `t^step` with the common steps in closed form (no `powf`).
#[inline]
fn pow_step(t: f32, step: f64) -> f32 {
    if step == 0.5 {
        t.sqrt()
    } else if step == 1.0 {
        t
    } else if step == 2.0 {
        t * t
    } else {
        t.powf(step as f32)
    }
}

impl Accum {
    fn add(&mut self, rgba: [f32; 4], step: f64) {
        let alpha = 1.0 - pow_step(1.0 - rgba[3].clamp(0.0, 1.0), step);
        let w = (1.0 - self.a) * alpha;
        for (c, v) in self.c.iter_mut().zip(rgba) {
            *c += w * v;
        }
        self.a += w;
    }
}

/// Shading of a colour with normal `n` under a headlight along `-d`.
fn shade(rgba: [f32; 4], n: [f32; 3], d: V3, o: &RenderParams) -> [f32; 4] {
    let ndl = (n[0] as f64 * d[0] + n[1] as f64 * d[1] + n[2] as f64 * d[2]).abs() as f32;
    let diffuse = o.ka + o.kd * ndl;
    let spec = o.ks * ndl.powi(32);
    [
        rgba[0] * diffuse + spec,
        rgba[1] * diffuse + spec,
        rgba[2] * diffuse + spec,
        rgba[3],
    ]
}

/// What a ray samples in a segment.
#[derive(Clone, Copy)]
pub(crate) enum Source<'a> {
    /// The low-resolution volume (`factor` voxels per `V_W` voxel) under `tf`, unlit.
    Context {
        lowres: &'a Volume<f32>,
        factor: f64,
        tf: &'a PiecewiseTransferFunction,
        empty: &'a EmptyCells,
    },
    /// A (restricted) Gradient Octree under `tf`, shaded with the stored normals, or with
    /// the unquantised normals of `exact` (the volume the octree was built from).
    Octree {
        structure: &'a GoStructure,
        leaves: &'a [[u8; 3]],
        mats: &'a MaterialTable,
        tf: &'a PiecewiseTransferFunction,
        exact: Option<&'a Volume<u8>>,
    },
    /// The full-resolution volume under `tf`, shaded with its gradient when `lit`.
    Full {
        v: &'a Volume<f32>,
        tf: &'a PiecewiseTransferFunction,
        lit: bool,
    },
}

impl Source<'_> {
    fn sample(&self, p: V3, d: V3, o: &RenderParams) -> Option<[f32; 4]> {
        match *self {
            Source::Context {
                lowres,
                factor,
                tf,
                empty,
            } => {
                let q = p.map(|c| c / factor - 0.5);
                if empty.skip(q) {
                    return None;
                }
                Some(tf.eval(lowres.trilinear(q)))
            }
            Source::Octree {
                structure,
                leaves,
                mats,
                tf,
                exact,
            } => {
                let v = p.map(|c| c.max(0.0).floor() as u32);
                let (m, mut n) = decode_voxel(lookup(structure, leaves, v)?);
                if let Some(vol) = exact {
                    n = crate::gradient_octree::normal(vol, mats, v.map(|c| c as usize));
                }
                let rgba = tf.eval(mats.representative(m)?);
                Some(shade(rgba, n, d, o))
            }
            Source::Full { v, tf, lit } => {
                let q = p.map(|c| c - 0.5);
                let rgba = tf.eval(v.trilinear(q));
                if rgba[3] <= 0.0 {
                    return None;
                }
                if !lit {
                    return Some(rgba);
                }
                let g = v.gradient_trilinear(q);
                let l = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
                let n = if l > 1e-6 { g.map(|c| c / l) } else { [0.0; 3] };
                Some(shade(rgba, n, d, o))
            }
        }
    }
}

/// Casts every pixel: the volume box `dims`, with `inside` sampled in the ROI box and
/// `outside` elsewhere (`roi = None`: `outside` everywhere).
pub(crate) fn cast(
    dims: [usize; 3],
    cam: &Camera,
    opts: &RenderParams,
    roi: Option<(&Roi, Source, f64)>,
    outside: (Source, f64),
) -> Result<Image<f32>> {
    let frame = cam.frame()?;
    let hi = dims.map(|d| d as f64);
    let (w, h) = (cam.width, cam.height);
    let mut data = vec![0.0f32; w * h * 4];
    data.par_chunks_mut(w * 4)
        .enumerate()
        .for_each(|(py, row)| {
            // After a cancellation request the remaining rows are skipped (and reported).
            if wscg_math::cancel::requested() {
                return;
            }
            for px in 0..w {
                let d = frame.ray(px, py);
                let mut acc = Accum {
                    c: [0.0; 3],
                    a: 0.0,
                };
                if let Some((t0, t1)) = slab(cam.eye, d, [0.0; 3], hi) {
                    // At most three segments: before, inside and after the ROI box.
                    let mut segments = [(t0, t1, outside), (t1, t1, outside), (t1, t1, outside)];
                    if let Some((r, inside, step)) = &roi {
                        let lo = r.min.map(|c| c as f64);
                        let up = r.max.map(|c| c as f64);
                        if let Some((r0, r1)) = slab(cam.eye, d, lo, up) {
                            let (r0, r1) = (r0.max(t0), r1.min(t1));
                            if r0 < r1 {
                                segments = [
                                    (t0, r0, outside),
                                    (r0, r1, (*inside, *step)),
                                    (r1, t1, outside),
                                ];
                            }
                        }
                    }
                    'ray: for (s0, s1, (src, step)) in segments {
                        let n = ((s1 - s0) / step).ceil().max(0.0) as usize;
                        for k in 0..n {
                            let t = s0 + (k as f64 + 0.5) * step;
                            if t >= s1 {
                                break;
                            }
                            let p = [0, 1, 2].map(|i| cam.eye[i] + t * d[i]);
                            if let Some(rgba) = src.sample(p, d, opts) {
                                acc.add(rgba, step);
                                if acc.a >= opts.early_stop {
                                    break 'ray;
                                }
                            }
                        }
                    }
                }
                for k in 0..3 {
                    row[4 * px + k] = acc.c[k] + (1.0 - acc.a) * opts.background[k];
                }
                row[4 * px + 3] = acc.a;
            }
        });
    wscg_math::cancel::check()?;
    Image::new(h, w, 4, data)
}

/// The full-resolution reference ("VrMed"): trilinear densities and central-difference
/// gradients. With `roi = None`, `tf` everywhere, shaded. With `roi = Some((box, roi_tf))`,
/// the full-resolution counterpart of the hybrid image: `tf` unlit outside the box (as the
/// hybrid's context) and `roi_tf` shaded inside.
///
/// Errors: empty volume, bad camera or options.
pub fn render_reference(
    v: &Volume<u8>,
    tf: &PiecewiseTransferFunction,
    roi: Option<(&Roi, &PiecewiseTransferFunction)>,
    cam: &Camera,
    opts: &RenderParams,
) -> Result<Image<f32>> {
    opts.validate()?;
    if v.dims().contains(&0) {
        return Err(Error::Empty("volume"));
    }
    let f = v.map(|d| d as f32);
    let inside = roi.map(|(r, t)| {
        let src = Source::Full {
            v: &f,
            tf: t,
            lit: true,
        };
        (r, src, opts.step)
    });
    let outside = Source::Full {
        v: &f,
        tf,
        lit: roi.is_none(),
    };
    cast(v.dims(), cam, opts, inside, (outside, opts.step))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn empty_cells_never_skip_a_visible_sample() {
        let u = wscg_math::rng::uniform_vec(21, 20 * 18 * 14, 0.0, 1.0).unwrap();
        // Mostly dark with bright islands, so that some cells are empty and some are not.
        let v = Volume::from_fn([20, 18, 14], [1.0; 3], |x, y, z| {
            let r = u[x + 20 * (y + 18 * z)];
            if r > 0.97 {
                200.0
            } else {
                10.0 * r as f32
            }
        })
        .unwrap();
        let tf = PiecewiseTransferFunction::new(vec![
            (50.0, [1.0, 1.0, 1.0, 0.0]),
            (60.0, [1.0, 1.0, 1.0, 0.5]),
        ])
        .unwrap();
        let cells = EmptyCells::new(&v, &tf);
        let q = wscg_math::rng::uniform_vec(22, 3 * 20000, -1.0, 21.0).unwrap();
        let (mut skipped, mut visible) = (0, 0);
        for p in q.chunks(3) {
            let p = [p[0], p[1], p[2]];
            let a = tf.eval(v.trilinear(p))[3];
            if cells.skip(p) {
                skipped += 1;
                assert_eq!(a, 0.0, "skipped a visible sample at {p:?}");
            }
            visible += usize::from(a > 0.0);
        }
        assert!(
            skipped > 200 && visible > 100,
            "{skipped} skipped, {visible} visible"
        );
    }
}
