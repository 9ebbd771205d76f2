//! The slice renderer: instant convolution shadows and the paper's supersampled and
//! pre-integrated variants (paper §3, Fig. 2).
//!
//! One pass per slice over a 2-D light buffer and the eye buffers, rows in parallel, then one
//! convolution. Segment `n` runs from slice `n` to slice `n + 1`; its `m + 1` tissue samples
//! (or pre-integrated sub-segments) are lit by the linear interpolation (§3.2: sample `j` of
//! `m + 1` gets `(1 - a_j) L_n + a_j L_{n+1}`, `a_j = j / (m + 1)`) of `L_n` and
//! `L_{n+1}`. The shading `S(L) = k_a + (1 - k_a) L` is affine in the light, so a sample's
//! colour splits into `(1 - a_j) w_j c_j S(L_n)`, added at once, and `a_j w_j c_j S(L_{n+1})`,
//! whose light-free part `Q = sum a_j w_j c_j` waits in a per-pixel buffer until `L_{n+1}`
//! exists (the next pass): every sample is read once and only `O(W H)` floats are kept.
//!
//! Empty space costs little: along a row of a slice, a pixel whose samples (or segment fronts)
//! lie in the cube of empty cells around it starts a run of pixels that stay in that cube
//! ([`Sampler::transparent_run`]); the whole run only receives the deferred light of its
//! previous segment. On the frog with the skin transfer function, 96.5 % of the pixels of
//! a slice see only transparent samples (ICS at 0.2, 256 x 256). Exact: the images are the
//! same bits as without the runs.

use rayon::prelude::*;
use wscg_math::{Error, Result};

use super::camera::{Frame, Slicing};
use super::classify::{SampleLut, TransferFunction};
use super::field::ScalarField;
use super::kernel::{Kernel, StepKernel};
use super::method::{IlluminationParams, Light, LightAtten, LightBorder, Method};
use super::preintegration::PreIntegrationTable;
use super::sampler::Sampler;

/// Per-sample classification of a run.
enum Classifier {
    /// Post-classified samples; `slice_only` holds the slice-distance table of
    /// [`LightAtten::SliceOnly`].
    Samples {
        lut: SampleLut,
        slice_only: Option<SampleLut>,
    },
    /// Pre-integrated sub-segments.
    Table(PreIntegrationTable),
}

/// The light buffer's rectangle in image pixel coordinates.
#[derive(Clone, Copy, Debug)]
struct Rect {
    x0: i64,
    y0: i64,
    w: usize,
    h: usize,
}

/// What a slice render needs for one transfer function and method, whatever the camera:
/// the empty-space sampler and the classification tables (built once for many views).
pub(crate) struct Prepared<'a> {
    sampler: Sampler<'a>,
    classifier: Classifier,
    ds: f32,
    m: usize,
    delta: f32,
}

impl<'a> Prepared<'a> {
    /// Tables for a slice method (validated by `Method::check`). Errors: a ray caster
    /// (no light buffer), a bad pre-integration length.
    pub fn new(
        field: &'a ScalarField,
        tf: &TransferFunction,
        settings: &IlluminationParams,
        method: &Method,
    ) -> Result<Self> {
        let Method::Ics {
            slice: ds,
            subsamples: m,
            preintegrated,
            light_atten: atten,
        } = *method
        else {
            return Err(Error::invalid(
                "method",
                format!("{} has no light buffer; use a slice method", method.name()),
            ));
        };
        let m = m as usize;
        let delta = ds / (m as f32 + 1.0);
        let classifier = if preintegrated {
            Classifier::Table(PreIntegrationTable::build(tf, delta)?)
        } else {
            Classifier::Samples {
                lut: tf.sampled(delta),
                slice_only: (atten == LightAtten::SliceOnly && m > 0).then(|| tf.sampled(ds)),
            }
        };
        Ok(Self {
            sampler: Sampler::new(field, tf, settings.interp, preintegrated),
            classifier,
            ds,
            m,
            delta,
        })
    }
}

/// Most slices (or ray samples) of one render.
pub(crate) const MAX_SLICES: usize = 1 << 20;

/// Largest kernel reach per slice in pixels.
const MAX_REACH: f64 = 65536.0;

/// A slice render of one camera.
pub(crate) struct SliceRun<'a> {
    sampler: &'a Sampler<'a>,
    classifier: &'a Classifier,
    slicing: Slicing,
    m: usize,
    delta: f32,
    kernel: StepKernel,
    ka: f32,
    early_stop: f32,
    background: [f32; 3],
    skip_zero: bool,
    /// Skip runs of pixels whose samples (or pre-integrated segments) are all transparent
    /// (exact, see [`Sampler::transparent_run`]).
    skip_transparent: bool,
    /// Tissue segments no longer than an empty-space cell (so they can be skipped).
    short_segments: bool,
    rect: Rect,
    /// Per slice, the light-buffer pixels `[x0, x1) x [y0, y1)` whose segment can meet the
    /// volume (all pixels when the outside of the volume is not transparent).
    sections: Vec<Option<[usize; 4]>>,
    width: usize,
    height: usize,
    /// Voxel position of light-buffer pixel (0, 0) at depth 0, and per-pixel, per-row and
    /// per-unit-depth steps, all in voxel coordinates.
    org: [f32; 3],
    dx: [f32; 3],
    dy: [f32; 3],
    dz: [f32; 3],
    /// [`LightBorder::Closed`]: per axis, whether the outside beyond the box's low and high
    /// face is opaque to the light (the faces not turned towards it); `None` when open.
    walls: Option<[[bool; 2]; 3]>,
    /// The box's high faces, `n - 1/2` in voxel coordinates (the low ones are at `-1/2`).
    box_hi: [f32; 3],
}

/// What a run produced.
pub(crate) struct SliceOutput {
    /// RGBA image, `H x W x 4`, composited over the background.
    pub rgba: Vec<f32>,
    /// Slices processed.
    pub slices: usize,
    /// Floats held in 2-D buffers.
    pub buffer_floats: usize,
}

/// Mean and variance per axis of a step kernel (the larger axis).
fn kernel_spread(k: &StepKernel) -> (f64, f64) {
    match k {
        StepKernel::Separable { x, y } => {
            let (mx, vx) = x.moments();
            let (my, vy) = y.moments();
            (mx.hypot(my), vx.max(vy))
        }
        StepKernel::Stencil(t) => {
            let (mut mx, mut my) = (0f64, 0f64);
            for &(dx, dy, w) in t {
                mx += w as f64 * dx as f64;
                my += w as f64 * dy as f64;
            }
            let v = t
                .iter()
                .map(|&(dx, _, w)| w as f64 * (dx as f64 - mx).powi(2))
                .sum::<f64>();
            (mx.hypot(my), v)
        }
    }
}

impl<'a> SliceRun<'a> {
    /// Prepares the run of one camera. Errors: more than 2^20 slices, a light kernel
    /// reaching more than 65,536 pixels per slice, a bad light.
    pub fn new(
        field: &'a ScalarField,
        prep: &'a Prepared<'a>,
        frame: &Frame,
        light: &Light,
        settings: &IlluminationParams,
    ) -> Result<Self> {
        let l = light.unit_dir()?;
        let (ds, m, delta) = (prep.ds, prep.m, prep.delta);
        let slicing = Slicing::bounded(frame, field, ds as f64, MAX_SLICES, "slice_distance")?;
        let reach = match light.kernel {
            Kernel::Disk { tan_half } => ds as f64 * tan_half as f64 / frame.h,
            k => 3.0 * k.step_variance(ds as f64, frame.h).sqrt(),
        } + (ds as f64 * (l[0].hypot(l[1]) / l[2]) / frame.h);
        let limit = if matches!(light.kernel, Kernel::Disk { .. }) {
            1024.0
        } else {
            MAX_REACH
        };
        if reach.is_nan() || reach > limit {
            return Err(Error::invalid(
                "kernel",
                format!("reaches {reach:.0} pixels per slice (at most {limit}); lower the spread (tan_half for the disk) or the slice distance"),
            ));
        }
        // Source offset of the light per slice, in pixels (x right, y down).
        let h = frame.h;
        let shift = [ds as f64 * l[0] / l[2] / h, -(ds as f64) * l[1] / l[2] / h];
        let kernel = StepKernel::new(&light.kernel, ds as f64, h, shift);
        let (mean, var) = kernel_spread(&kernel);
        let n = slicing.n as f64;
        let (w, hh) = (frame.width as i64, frame.height as i64);
        let margin =
            ((3.0 * (var * n).sqrt() + mean * n).ceil() as i64 + kernel.reach() as i64 + 1)
                .min(2 * w.max(hh));
        let fp = frame.footprint(field);
        let skip_zero = prep.sampler.outside_transparent;
        let (x0, x1, y0, y1) = if skip_zero {
            (
                (-margin).max(fp[0] - margin),
                (w + margin).min(fp[1] + margin),
                (-margin).max(fp[2] - margin),
                (hh + margin).min(fp[3] + margin),
            )
        } else {
            (-margin, w + margin, -margin, hh + margin)
        };
        let rect = Rect {
            x0,
            y0,
            w: (x1 - x0).max(0) as usize,
            h: (y1 - y0).max(0) as usize,
        };
        let sections = (0..slicing.n)
            .map(|k| {
                if skip_zero {
                    section(frame, field, &rect, slicing.z(k), slicing.z(k) + ds as f64)
                } else {
                    (rect.w > 0 && rect.h > 0).then_some([0, rect.w, 0, rect.h])
                }
            })
            .collect();
        let [org, dx, dy, dz] = frame.voxel_steps(field, x0 as f64, y0 as f64);
        let short_segments = (delta as usize) < super::cells::CELL;
        // Direction towards the light in world (and, up to positive scales, voxel)
        // coordinates: the low face of axis `a` is turned towards the light when its
        // component is negative, the high face when it is positive.
        let walls = (settings.border == LightBorder::Closed).then(|| {
            let lw = frame.light_world(l);
            std::array::from_fn(|a| [lw[a] >= -1e-9, lw[a] <= 1e-9])
        });
        Ok(Self {
            sampler: &prep.sampler,
            classifier: &prep.classifier,
            slicing,
            m,
            delta,
            kernel,
            ka: light.ambient,
            early_stop: settings.early_stop,
            background: settings.background,
            skip_zero,
            // Pre-integrated segments are skipped only when they are short.
            skip_transparent: short_segments
                || matches!(prep.classifier, Classifier::Samples { .. }),
            short_segments,
            rect,
            sections,
            width: frame.width,
            height: frame.height,
            org,
            dx,
            dy,
            dz,
            walls,
            box_hi: field.dims().map(|n| n as f32 - 0.5),
        })
    }

    /// The slicing of this run.
    pub fn slicing(&self) -> Slicing {
        self.slicing
    }

    /// Runs every slice and returns the image.
    pub fn render(&self) -> SliceOutput {
        let mut st = State::new(self.rect.w * self.rect.h);
        // The slice loop runs on a worker of the thread pool: each slice's parallel passes
        // then split among the workers without a caller thread sleeping and waking per pass.
        rayon::scope(|_| {
            for n in 0..self.slicing.n {
                // Stops early on a cancellation request; the caller reports it.
                if wscg_math::cancel::requested() {
                    break;
                }
                self.step(&mut st, n);
            }
        });
        self.finish(st)
    }

    /// The light arriving at slice `k` (clamped to the last slice), as a `W x H` buffer
    /// (1 outside the light buffer).
    pub fn light_at(&self, k: usize) -> Vec<f32> {
        let mut st = State::new(self.rect.w * self.rect.h);
        for n in 0..k.min(self.slicing.n) {
            self.step(&mut st, n);
        }
        let mut out = vec![1f32; self.width * self.height];
        for (y, row) in out.chunks_mut(self.width).enumerate() {
            let ry = y as i64 - self.rect.y0;
            if ry < 0 || ry >= self.rect.h as i64 {
                continue;
            }
            for (x, o) in row.iter_mut().enumerate() {
                let rx = x as i64 - self.rect.x0;
                if rx >= 0 && rx < self.rect.w as i64 {
                    *o = st.l_cur[ry as usize * self.rect.w + rx as usize];
                }
            }
        }
        out
    }

    /// Segment `n`: sample, composite and attenuate the light in place (`L_n -> O_n`) over
    /// the pixels whose segment meets the volume (and those with light still to add from the
    /// previous segment), then convolve to `L_{n+1}` over the region where the light can
    /// differ from 1.
    fn step(&self, st: &mut State, n: usize) {
        let w = self.rect.w;
        if w == 0 || self.rect.h == 0 {
            return;
        }
        let z = self.slicing.z(n) as f32;
        let sec = self.sections[n];
        let prev = if n > 0 { self.sections[n - 1] } else { None };
        let State {
            l_cur,
            l_prev,
            tmp,
            eye,
            q,
            front,
            active,
        } = st;
        if let Some([x0, x1, y0, y1]) = union(sec, prev) {
            let rows = y0 * w..y1 * w;
            l_cur[rows.clone()]
                .par_chunks_mut(w)
                .zip(eye[rows.clone()].par_chunks_mut(w))
                .zip(q[rows.clone()].par_chunks_mut(w))
                .zip(front[rows].par_chunks_mut(w))
                .enumerate()
                .for_each(|(k, (((lrow, erow), qrow), frow))| {
                    self.pass_row(n, z, y0 + k, x0..x1, lrow, erow, qrow, frow);
                });
        }
        let Some(act) = union(*active, sec) else {
            // No light was blocked yet: L_{n+1} = 1 everywhere.
            return;
        };
        let r = self.kernel.reach();
        let out = [
            act[0].saturating_sub(r),
            (act[1] + r).min(w),
            act[2].saturating_sub(r),
            (act[3] + r).min(self.rect.h),
        ];
        if let Some(walls) = self.walls {
            // O_n lies at the next slice's depth.
            let z_next = (self.slicing.z(n) + self.slicing.ds) as f32;
            self.close_border(l_cur, out, z_next, walls);
        }
        self.kernel
            .apply_rect(l_cur, tmp, l_prev, w, self.rect.h, out);
        *active = Some(out);
        std::mem::swap(l_cur, l_prev);
    }

    /// [`LightBorder::Closed`]: sets the light to 0 at the pixels of `rect` (`[x0, x1) x
    /// [y0, y1)` of the light buffer) whose position at depth `z` lies beyond a wall of the
    /// box, before the convolution carries it on. Outside `rect` the light is 1 and more
    /// than the kernel's reach from every pixel whose light can change.
    fn close_border(&self, light: &mut [f32], rect: [usize; 4], z: f32, walls: [[bool; 2]; 3]) {
        let w = self.rect.w;
        let hi = self.box_hi;
        light[rect[2] * w..rect[3] * w]
            .par_chunks_mut(w)
            .enumerate()
            .for_each(|(k, row)| {
                let rf = (rect[2] + k) as f32;
                let row0: [f32; 3] =
                    std::array::from_fn(|a| self.org[a] + rf * self.dy[a] + z * self.dz[a]);
                for (i, v) in row.iter_mut().enumerate().take(rect[1]).skip(rect[0]) {
                    let fi = i as f32;
                    let beyond = (0..3).any(|a| {
                        let c = row0[a] + fi * self.dx[a];
                        (walls[a][0] && c < -0.5) || (walls[a][1] && c >= hi[a])
                    });
                    if beyond {
                        *v = 0.0;
                    }
                }
            });
    }

    /// Image-column range `[a, b)` of the light buffer row `r`, empty outside the image.
    fn image_span(&self, r: usize) -> (usize, usize) {
        let y = self.rect.y0 + r as i64;
        if y < 0 || y >= self.height as i64 {
            return (0, 0);
        }
        let a = (-self.rect.x0).clamp(0, self.rect.w as i64) as usize;
        let b = (self.width as i64 - self.rect.x0).clamp(0, self.rect.w as i64) as usize;
        (a, b.max(a))
    }

    #[allow(clippy::too_many_arguments)]
    fn pass_row(
        &self,
        n: usize,
        z: f32,
        r: usize,
        cols: std::ops::Range<usize>,
        lrow: &mut [f32],
        erow: &mut [[f32; 4]],
        qrow: &mut [[f32; 3]],
        frow: &mut [f32],
    ) {
        let (ia, ib) = self.image_span(r);
        let rf = r as f32;
        let row0: [f32; 3] =
            std::array::from_fn(|a| self.org[a] + rf * self.dy[a] + z * self.dz[a]);
        let step: [f32; 3] = self.dz.map(|c| c * self.delta);
        let m1 = self.m as f32 + 1.0;
        let ka = self.ka;
        // The sub-samples of a pixel span `m step` from its first one.
        let reach: [f32; 3] = step.map(|c| c * self.m as f32);
        let segments = matches!(self.classifier, Classifier::Table(_));
        let mut i = cols.start;
        while i < cols.end {
            let fi = i as f32;
            let p0: [f32; 3] = std::array::from_fn(|a| row0[a] + fi * self.dx[a]);
            if self.skip_transparent {
                // Pixels whose samples are all transparent change nothing but the deferred
                // light of their previous segment (`t = 1`, no colour): skipped as a run.
                let lo: [f32; 3] = std::array::from_fn(|a| p0[a] + reach[a].min(0.0));
                let hi: [f32; 3] = std::array::from_fn(|a| p0[a] + reach[a].max(0.0));
                let run = self.sampler.transparent_run(lo, hi, self.dx, segments);
                if run > 0 {
                    let end = cols.end.min(i.saturating_add(run));
                    if segments {
                        // No front value was read (as when each segment is skipped).
                        frow[i..end].fill(f32::NAN);
                    }
                    if n > 0 && self.m > 0 {
                        for k in i.max(ia)..end.min(ib) {
                            if qrow[k] != [0.0; 3] {
                                finalize(&mut erow[k], &mut qrow[k], ka, lrow[k]);
                            }
                        }
                    }
                    i = end;
                    continue;
                }
            }
            let lc = lrow[i];
            let in_img = i >= ia && i < ib;
            if in_img && n > 0 && self.m > 0 {
                finalize(&mut erow[i], &mut qrow[i], ka, lc);
            }
            let mut e = erow[i];
            let mut q = [0f32; 3];
            let s_n = ka + (1.0 - ka) * lc;
            let composite = in_img && e[3] < self.early_stop;
            let mut t = 1f32;
            let mut add = |j: usize, v: [f32; 4], e: &mut [f32; 4]| {
                t *= 1.0 - v[3];
                if composite {
                    let wgt = 1.0 - e[3];
                    let aj = j as f32 / m1;
                    let (wp, wq) = (wgt * (1.0 - aj) * s_n, wgt * aj);
                    for c in 0..3 {
                        e[c] += wp * v[c];
                        q[c] += wq * v[c];
                    }
                    e[3] += wgt * v[3];
                }
            };
            let at = |j: usize| -> [f32; 3] {
                let k = j as f32;
                std::array::from_fn(|a| p0[a] + k * step[a])
            };
            match self.classifier {
                Classifier::Samples { lut, slice_only } => {
                    let mut s0 = None;
                    for j in 0..=self.m {
                        let Some(s) = self.sampler.visible(at(j)) else {
                            continue;
                        };
                        if j == 0 {
                            s0 = Some(s);
                        }
                        add(j, lut.get(s), &mut e);
                    }
                    if let Some(so) = slice_only {
                        t = s0.map_or(1.0, |s| 1.0 - so.get(s)[3]);
                    }
                }
                Classifier::Table(table) => {
                    // A sub-segment whose front lies in the box reads its back sample clamped
                    // to the box (as a GPU slice's fragment reads an edge-clamped texture); one
                    // whose front lies outside is the value 0 throughout. Segments starting in
                    // empty space are skipped unread (NaN marks an unread front value).
                    let mut sf = if n == 0 { f32::NAN } else { frow[i] };
                    for j in 0..=self.m {
                        let pf = at(j);
                        if !self.sampler.contains(pf) {
                            if !self.skip_zero {
                                add(j, table.get(0.0, 0.0), &mut e);
                            }
                            sf = f32::NAN;
                            continue;
                        }
                        if self.short_segments && self.sampler.segment_empty(pf) {
                            sf = f32::NAN;
                            continue;
                        }
                        let front = if sf.is_nan() {
                            self.sampler.clamped(pf)
                        } else {
                            sf
                        };
                        let sb = self.sampler.clamped(at(j + 1));
                        add(j, table.get(front, sb), &mut e);
                        sf = sb;
                    }
                    frow[i] = sf;
                }
            }
            erow[i] = e;
            if composite && self.m > 0 {
                qrow[i] = q;
            }
            lrow[i] = lc * t;
            i += 1;
        }
    }

    /// Adds the last segment's light and the background; crops to the image.
    fn finish(&self, st: State) -> SliceOutput {
        let (w, hgt) = (self.width, self.height);
        let mut rgba = vec![0f32; w * hgt * 4];
        let bg = self.background;
        let floats = st.floats();
        let State {
            l_cur,
            mut eye,
            mut q,
            ..
        } = st;
        for (y, row) in rgba.chunks_mut(4 * w).enumerate() {
            let ry = y as i64 - self.rect.y0;
            for (x, px) in row.chunks_mut(4).enumerate() {
                let rx = x as i64 - self.rect.x0;
                let mut e = [0f32; 4];
                if ry >= 0 && ry < self.rect.h as i64 && rx >= 0 && rx < self.rect.w as i64 {
                    let k = ry as usize * self.rect.w + rx as usize;
                    if self.slicing.n > 0 && self.m > 0 {
                        finalize(&mut eye[k], &mut q[k], self.ka, l_cur[k]);
                    }
                    e = eye[k];
                }
                for c in 0..3 {
                    px[c] = e[c] + (1.0 - e[3]) * bg[c];
                }
                px[3] = e[3];
            }
        }
        SliceOutput {
            rgba,
            slices: self.slicing.n,
            buffer_floats: floats,
        }
    }
}

/// The 2-D buffers of a run (light-buffer rectangle).
struct State {
    l_cur: Vec<f32>,
    l_prev: Vec<f32>,
    tmp: Vec<f32>,
    eye: Vec<[f32; 4]>,
    q: Vec<[f32; 3]>,
    front: Vec<f32>,
    /// The region where the light buffer may differ from 1.
    active: Option<[usize; 4]>,
}

impl State {
    fn new(len: usize) -> Self {
        Self {
            l_cur: vec![1.0; len],
            l_prev: vec![1.0; len],
            tmp: vec![1.0; len],
            eye: vec![[0.0; 4]; len],
            q: vec![[0.0; 3]; len],
            front: vec![0.0; len],
            active: None,
        }
    }

    fn floats(&self) -> usize {
        4 * self.l_cur.len() + 4 * self.eye.len() + 3 * self.q.len()
    }
}

/// Adds the deferred part of a finished segment: `Q S(L_{n+1})`.
#[inline]
fn finalize(e: &mut [f32; 4], q: &mut [f32; 3], ka: f32, l_n1: f32) {
    let s = ka + (1.0 - ka) * l_n1;
    for c in 0..3 {
        e[c] += s * q[c];
    }
    *q = [0.0; 3];
}

/// The smallest rectangle holding both (`[x0, x1, y0, y1]`, half-open).
fn union(a: Option<[usize; 4]>, b: Option<[usize; 4]>) -> Option<[usize; 4]> {
    match (a, b) {
        (Some(a), Some(b)) => Some([
            a[0].min(b[0]),
            a[1].max(b[1]),
            a[2].min(b[2]),
            a[3].max(b[3]),
        ]),
        (a, None) => a,
        (None, b) => b,
    }
}

/// Light-buffer pixels (with a 2-pixel border) covering the part of the volume's box between
/// the depths `za` and `zb`: the box corners between them and the crossings of its edges
/// with both planes, projected.
fn section(
    frame: &Frame,
    field: &ScalarField,
    rect: &Rect,
    za: f64,
    zb: f64,
) -> Option<[usize; 4]> {
    use wscg_math::vec3::{dot, sub};
    let (lo, hi) = field.world_box();
    let corners: Vec<[f64; 3]> = super::camera::corners(lo, hi).collect();
    let depth = |p: [f64; 3]| dot(sub(p, frame.center), frame.d);
    let mut pts: Vec<[f64; 3]> = corners
        .iter()
        .copied()
        .filter(|&c| (za..=zb).contains(&depth(c)))
        .collect();
    for i in 0..8 {
        for a in 0..3 {
            let j = i | (1 << a);
            if j == i {
                continue;
            }
            let (p, q) = (corners[i], corners[j]);
            let (dp, dq) = (depth(p), depth(q));
            for zc in [za, zb] {
                if (dp - zc) * (dq - zc) <= 0.0 && dp != dq {
                    let t = (zc - dp) / (dq - dp);
                    pts.push(std::array::from_fn(|k| p[k] + t * (q[k] - p[k])));
                }
            }
        }
    }
    if pts.is_empty() {
        return None;
    }
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for p in pts {
        let q = sub(p, frame.center);
        let x = dot(q, frame.right) / frame.h + 0.5 * frame.width as f64 - 0.5 - rect.x0 as f64;
        let y = dot(q, frame.down) / frame.h + 0.5 * frame.height as f64 - 0.5 - rect.y0 as f64;
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    let clampx = |v: f64| v.clamp(0.0, rect.w as f64) as usize;
    let clampy = |v: f64| v.clamp(0.0, rect.h as f64) as usize;
    let r = [
        clampx(x0.floor() - 2.0),
        clampx(x1.ceil() + 3.0),
        clampy(y0.floor() - 2.0),
        clampy(y1.ceil() + 3.0),
    ];
    (r[0] < r[1] && r[2] < r[3]).then_some(r)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::illumination::{Kernel, SliceCamera};

    /// Two blobs in a corner of empty space, with their transfer function.
    fn sparse_scene() -> (ScalarField, TransferFunction) {
        use crate::illumination::scenes;
        let blobs = [([14.0, 20.0, 17.0], 7.0), ([33.0, 29.0, 32.0], 9.0)];
        let field = scenes::blobs([80; 3], [1.0, 1.0, 1.5], &blobs).unwrap();
        (field, scenes::blobs_tf())
    }

    /// Skipping runs of transparent pixels changes no bit of the image: ICS, SCS (with the
    /// deferred light of the sub-samples and with the slice-only light attenuation), PI-ICS
    /// and PI-SCS, soft and oblique light, views whose slices cross the empty space in every
    /// direction. The empty corner of the volume does start runs, for samples and for
    /// segment fronts alike, so the fast path is the one compared.
    #[test]
    fn skipping_transparent_runs_is_exact() {
        let (field, tf) = sparse_scene();
        let settings = IlluminationParams::default();
        let mut slice_only = Method::scs(1.2, 2);
        if let Method::Ics { light_atten, .. } = &mut slice_only {
            *light_atten = LightAtten::SliceOnly;
        }
        let lights = [
            Light::default(),
            Light {
                dir_view: [0.4, -0.3, 1.0],
                ambient: 0.2,
                kernel: Kernel::Gaussian { spread: 0.8 },
            },
        ];
        for dir in [[0.3, -0.5, 1.0], [-1.0, 0.2, -0.4], [0.0, 1.0, 0.0]] {
            let cam = SliceCamera::fit(&field, dir, [0.0, 0.0, 1.0], 56, 48).unwrap();
            let frame = cam.frame().unwrap();
            for light in &lights {
                for method in [
                    Method::ics(0.5),
                    Method::scs(1.0, 1),
                    Method::scs(1.3, 3),
                    // Segments longer than the blobs' edges: a pixel's colour deferred from
                    // a visible segment is added while its next segment is skipped.
                    Method::scs(6.0, 3),
                    slice_only,
                    Method::pi_scs(0.5, 0),
                    Method::pi_scs(1.3, 3),
                    Method::pi_scs(6.0, 3),
                ] {
                    let prep = Prepared::new(&field, &tf, &settings, &method).unwrap();
                    let segments = matches!(prep.classifier, Classifier::Table(_));
                    let corner = prep.sampler.transparent_run(
                        [70.0; 3],
                        [70.5; 3],
                        [-1.0, 0.0, 0.0],
                        segments,
                    );
                    assert!(corner > 1, "{method:?}: {corner}");
                    let mut run = SliceRun::new(&field, &prep, &frame, light, &settings).unwrap();
                    assert!(run.skip_transparent);
                    let fast = run.render();
                    run.skip_transparent = false;
                    let plain = run.render();
                    assert!(plain.rgba.iter().any(|&v| v > 0.05));
                    let same = fast
                        .rgba
                        .iter()
                        .zip(&plain.rgba)
                        .all(|(a, b)| a.to_bits() == b.to_bits());
                    assert!(same, "{dir:?} {method:?} {light:?}");
                }
            }
        }
    }
}
