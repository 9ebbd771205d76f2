//! A layered multi-view scene with ground truth, standing in for the paper's camera-array
//! datasets: fronto-parallel textured planes at fractional disparities composited back to
//! front (exact occlusions), lit by a field with a bright emitter (about `10^4` dynamic
//! range), seen by `n` cameras on a horizontal baseline, each with its own exposure time,
//! a camera response and sensor noise before 8-bit quantisation.
//!
//! Geometry: a layer of disparity `d` (pixels per camera step) seen by camera `k` at column
//! `x` shows its point `u = x + (k - c) d`, `c` the central camera; so a point at column
//! `x` of view `r` is at `x + (r - s) d` in view `s` (a camera on the right sees it further
//! left). Textures are continuous functions of `u`, so fractional shifts are exact.

use rand_distr::{Distribution, Normal};
use rayon::prelude::*;
use wscg_math::{rng, Error, Image, Result};

use crate::crf::{levels_of, Crf};

/// A camera response `v = f(X)` mapping exposure `X` in `[0, 1]` to a signal in `[0, 1]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Response {
    /// `f(X) = X^(1/gamma)`.
    Gamma(f64),
    /// An S-shaped response: a gamma-2.2 curve through a `tanh` of steepness `a`,
    /// normalised to `f(0) = 0`, `f(1) = 1`.
    SCurve(f64),
    /// The response whose inverse is the cubic `f^-1(v) = a_1 v + a_2 v^2 + a_3 v^3`
    /// (Mitsunaga & Nayar's polynomial model; the coefficients should sum to 1 and keep it
    /// increasing on `[0, 1]`).
    Cubic([f64; 3]),
}

impl Response {
    /// `f(X)`.
    pub fn forward(&self, x: f64) -> f64 {
        let x = x.clamp(0.0, 1.0);
        match *self {
            Self::Gamma(g) => x.powf(1.0 / g),
            Self::SCurve(a) => {
                let t = (a / 2.0).tanh();
                ((a * (x.powf(1.0 / 2.2) - 0.5)).tanh() + t) / (2.0 * t)
            }
            Self::Cubic(_) => {
                // Bisection on the increasing inverse.
                let (mut lo, mut hi) = (0.0, 1.0);
                for _ in 0..60 {
                    let mid = 0.5 * (lo + hi);
                    if self.inverse(mid) < x {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                0.5 * (lo + hi)
            }
        }
    }

    /// `f^-1(v)`.
    pub fn inverse(&self, v: f64) -> f64 {
        let v = v.clamp(0.0, 1.0);
        match *self {
            Self::Gamma(g) => v.powf(g),
            Self::SCurve(a) => {
                let t = (a / 2.0).tanh();
                let s = (v * 2.0 * t - t).clamp(-1.0 + 1e-15, 1.0 - 1e-15);
                (0.5 + s.atanh() / a).clamp(0.0, 1.0).powf(2.2)
            }
            Self::Cubic([a1, a2, a3]) => v * (a1 + v * (a2 + v * a3)),
        }
    }

    /// The inverse response table of a `bits`-bit camera (codes at `Z / z_max`).
    pub fn crf(&self, bits: u8, channels: usize) -> Result<Crf> {
        let levels = levels_of(bits)?;
        let zmax = (levels - 1) as f64;
        let t: Vec<f32> = (0..levels)
            .flat_map(|z| std::iter::repeat_n(self.inverse(z as f64 / zmax) as f32, channels))
            .collect();
        Crf::from_table(&t, levels, channels)
    }
}

/// One plane of the scene ([`Layer::new`], then the setters).
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct Layer {
    /// Disparity between neighbouring cameras, pixels (fractional).
    pub disparity: f64,
    /// Extent in the central view `(y0, y1, x0, x1)` as fractions of the image; a disk when
    /// `disk` (centre and radius from the box).
    pub rect: [f64; 4],
    /// Elliptic instead of rectangular outline.
    pub disk: bool,
    /// Texture seed.
    pub seed: u64,
    /// Radiance factor of the layer (1: the base light; a bright object clipped in the
    /// long exposures takes a few tens).
    pub gain: f64,
}

impl Layer {
    /// A layer of disparity `disparity` over `rect` (see [`Layer::rect`]), rectangular,
    /// texture seed `seed`, gain 1.
    pub fn new(disparity: f64, rect: [f64; 4], seed: u64) -> Self {
        Self {
            disparity,
            rect,
            disk: false,
            seed,
            gain: 1.0,
        }
    }

    /// The layer with an elliptic (`true`) or rectangular outline.
    pub fn disk(self, disk: bool) -> Self {
        Self { disk, ..self }
    }

    /// The layer with radiance factor `gain`.
    pub fn gain(self, gain: f64) -> Self {
        Self { gain, ..self }
    }

    /// Checks the layer `k` of a scene: finite disparity, `0 <= y0 < y1 <= 1` and `0 <= x0 <
    /// x1 <= 1`, finite gain `> 0`.
    pub fn validate(&self, k: usize) -> Result<()> {
        if !self.disparity.is_finite() {
            return Err(Error::invalid(
                "layers",
                format!(
                    "layer {k}: disparity must be finite, got {}",
                    self.disparity
                ),
            ));
        }
        let [y0, y1, x0, x1] = self.rect;
        let ok = |a: f64, b: f64| (0.0..=1.0).contains(&a) && (0.0..=1.0).contains(&b) && a < b;
        if !(ok(y0, y1) && ok(x0, x1)) {
            return Err(Error::invalid(
                "layers",
                format!(
                    "layer {k}: rect (y0, y1, x0, x1) needs 0 <= y0 < y1 <= 1 and 0 <= x0 < x1 \
                     <= 1, got {:?}",
                    self.rect
                ),
            ));
        }
        if !(self.gain.is_finite() && self.gain > 0.0) {
            return Err(Error::invalid(
                "layers",
                format!("layer {k}: gain must be finite and > 0, got {}", self.gain),
            ));
        }
        Ok(())
    }
}

wscg_math::params! {
    /// Configuration of [`layered_scene`].
    #[derive(Clone, Debug, PartialEq)]
    pub struct SceneParams {
        /// Image height.
        pub height: usize,
        /// Image width.
        pub width: usize,
        /// Exposure time of each camera, seconds (the number of cameras).
        pub times: Vec<f64>,
        /// Planes, back to front (the first one should cover the image; where no layer
        /// covers a pixel the first one is seen). The emitter lights the first one.
        pub layers: Vec<Layer>,
        /// Peak of the emitter relative to the base illumination.
        pub emitter_peak: f64,
        /// Response of the cameras.
        pub response: Response,
        /// Sensor noise, standard deviation of the signal in `[0, 1]` before quantisation.
        pub noise: f64,
        /// Bit depth of the views.
        pub bits: u8,
    }
}

impl Default for SceneParams {
    /// Five cameras with the exposures of the IIS Jumble set (5, 30, 61, 122, 280 ms),
    /// three planes at 7.5, 18.3 and 33.7 px, an emitter 300 times the base light, gamma
    /// 2.2, noise 0.002, 8 bits.
    fn default() -> Self {
        Self {
            height: 160,
            width: 256,
            times: vec![0.005, 0.030, 0.061, 0.122, 0.280],
            layers: vec![
                Layer::new(7.5, [0.0, 1.0, 0.0, 1.0], 11),
                Layer::new(18.3, [0.18, 0.78, 0.12, 0.47], 23),
                Layer::new(33.7, [0.35, 0.85, 0.52, 0.78], 37).disk(true),
            ],
            emitter_peak: 300.0,
            response: Response::Gamma(2.2),
            noise: 0.002,
            bits: 8,
        }
    }
}

/// The scene with its ground truth.
#[derive(Clone, Debug)]
pub struct SynthScene {
    /// Views (codes), left to right.
    pub views: Vec<Image<u16>>,
    /// Exposure times.
    pub times: Vec<f64>,
    /// The cameras' response.
    pub crf: Crf,
    /// True radiance of every view (3 channels).
    pub radiance: Vec<Image<f32>>,
    /// True disparity of every view's pixels (of the visible layer, per camera step).
    pub disparity: Vec<Image<f32>>,
    /// The cameras' response (for noiseless codes of the truth).
    pub response: Response,
    /// Per view and pixel, the views that see its surface point (bit `j` for view `j`,
    /// itself included).
    pub seen_by: Vec<Vec<u32>>,
}

/// Hash of a lattice point to `[0, 1)`.
fn lattice(seed: u64, i: i64, j: i64) -> f64 {
    let mut z = seed
        .wrapping_mul(0x9E37_79B9_7F4A_7C15)
        .wrapping_add((i as u64).wrapping_mul(0xBF58_476D_1CE4_E5B9))
        .wrapping_add((j as u64).wrapping_mul(0x94D0_49BB_1331_11EB));
    z ^= z >> 30;
    z = z.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z ^= z >> 27;
    z = z.wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64
}

/// Smooth value noise at `(y, u)` with lattice period `period`.
fn value_noise(seed: u64, y: f64, u: f64, period: f64) -> f64 {
    let (fy, fu) = (y / period, u / period);
    let (iy, iu) = (fy.floor(), fu.floor());
    let s = |t: f64| t * t * (3.0 - 2.0 * t);
    let (ty, tu) = (s(fy - iy), s(fu - iu));
    let (iy, iu) = (iy as i64, iu as i64);
    let v = |a: i64, b: i64| lattice(seed, a, b);
    let top = v(iy, iu) * (1.0 - tu) + v(iy, iu + 1) * tu;
    let bot = v(iy + 1, iu) * (1.0 - tu) + v(iy + 1, iu + 1) * tu;
    top * (1.0 - ty) + bot * ty
}

/// Albedo of a layer texture at `(y, u)`, channel `ch`: fractal value noise (periods 32 to
/// 2 px, amplitude proportional to the period: the `1/f` spectrum of natural images) with a
/// colour per layer, in `[0.05, 1]`.
pub fn albedo(seed: u64, y: f64, u: f64, ch: usize) -> f64 {
    let mut v = 0.0;
    let mut norm = 0.0;
    for (k, period) in [32.0, 16.0, 8.0, 4.0, 2.0].into_iter().enumerate() {
        let a = period / 32.0;
        v += a * value_noise(seed.wrapping_add(k as u64 * 101), y, u, period);
        norm += a;
    }
    let v = v / norm;
    let tint = 0.55 + 0.45 * lattice(seed ^ 0xC0FFEE, ch as i64, 7);
    let contrast = (v - 0.5) * 2.6 + 0.5;
    (0.05 + 0.95 * contrast.clamp(0.0, 1.0) * tint).clamp(0.05, 1.0)
}

/// Whether layer `l` covers `(y, u)` (layer coordinates in pixels).
fn covers(l: &Layer, y: f64, u: f64, h: usize, w: usize) -> bool {
    let (y0, y1) = (l.rect[0] * h as f64, l.rect[1] * h as f64);
    let (x0, x1) = (l.rect[2] * w as f64, l.rect[3] * w as f64);
    if l.disk {
        let (cy, cx) = ((y0 + y1) / 2.0, (x0 + x1) / 2.0);
        let (ry, rx) = ((y1 - y0) / 2.0, (x1 - x0) / 2.0);
        ((y - cy) / ry).powi(2) + ((u - cx) / rx).powi(2) <= 1.0
    } else if l.rect == [0.0, 1.0, 0.0, 1.0] {
        true
    } else {
        (y0..y1).contains(&y) && (x0..x1).contains(&u)
    }
}

impl SceneParams {
    /// Checks the ranges: 2 to 32 finite, positive `times`, at least one layer, each valid
    /// ([`Layer::validate`]), `height`
    /// and `width` at least 8, `noise` finite and `>= 0`, `emitter_peak` finite and `>= 1`,
    /// `bits` a supported depth.
    pub fn validate(&self) -> Result<()> {
        if !(2..=32).contains(&self.times.len()) {
            return Err(Error::invalid(
                "times",
                format!("needs 2 to 32 cameras, got {}", self.times.len()),
            ));
        }
        crate::radiance::check_times(&self.times, self.times.len())?;
        if self.layers.is_empty() {
            return Err(Error::invalid("layers", "needs at least one layer"));
        }
        for (k, l) in self.layers.iter().enumerate() {
            l.validate(k)?;
        }
        for (name, v) in [("height", self.height), ("width", self.width)] {
            if v < 8 {
                return Err(Error::invalid(
                    name,
                    format!("images must be at least 8 x 8, got {name} {v}"),
                ));
            }
        }
        // Per camera and pixel: radiance, disparity, visibility, the view and its copies.
        wscg_math::alloc::ensure_shape::<[f32; 8]>(
            "height, width",
            &[self.height, self.width, self.times.len()],
        )?;
        if !(self.noise.is_finite() && self.noise >= 0.0) {
            return Err(Error::invalid(
                "noise",
                format!("must be finite and >= 0, got {}", self.noise),
            ));
        }
        if !(self.emitter_peak.is_finite() && self.emitter_peak >= 1.0) {
            return Err(Error::invalid(
                "emitter_peak",
                format!("must be finite and >= 1, got {}", self.emitter_peak),
            ));
        }
        levels_of(self.bits).map(|_| ())
    }

    /// Index of the camera in the middle of the baseline.
    fn centre(&self) -> f64 {
        (self.times.len() - 1) as f64 / 2.0
    }

    /// The front-most layer seen by camera `k` at `(y, x)`, and its point `u`.
    fn visible(&self, k: usize, y: f64, x: f64) -> (usize, f64) {
        let c = self.centre();
        for (li, l) in self.layers.iter().enumerate().rev() {
            let u = x + (k as f64 - c) * l.disparity;
            if covers(l, y, u, self.height, self.width) {
                return (li, u);
            }
        }
        (0, x + (k as f64 - c) * self.layers[0].disparity)
    }

    /// Radiance of layer `li` at `(y, u)`, channel `ch`: albedo times light times the
    /// layer's gain, scaled so that the brightest possible point of a layer of gain 1 fills
    /// 90% of the shortest exposure.
    fn radiance(&self, li: usize, y: f64, u: f64, ch: usize) -> f64 {
        let (h, w) = (self.height as f64, self.width as f64);
        let tmin = self.times.iter().cloned().fold(f64::INFINITY, f64::min);
        let scale = 0.9 / (tmin * self.emitter_peak);
        let light = if li == 0 {
            let (ey, eu, s) = (0.14 * h, 0.9 * w, 0.03 * w);
            let g = (-((y - ey).powi(2) + (u - eu).powi(2)) / (2.0 * s * s)).exp();
            1.0 + (self.emitter_peak - 1.0) * g
        } else {
            1.0
        };
        scale * albedo(self.layers[li].seed, y, u, ch) * light * self.layers[li].gain
    }
}

/// Encodes radiance `e` with exposure `t` through `response`, adding Gaussian noise of
/// standard deviation `noise` to the signal and quantising to `bits` bits.
pub fn encode(
    e: &Image<f32>,
    t: f64,
    response: Response,
    noise: f64,
    bits: u8,
    seed: u64,
) -> Result<Image<u16>> {
    let zmax = (levels_of(bits)? - 1) as f64;
    let normal =
        Normal::new(0.0, noise.max(0.0)).map_err(|err| Error::invalid("noise", err.to_string()))?;
    let (h, w, c) = e.shape();
    let mut out = vec![0u16; h * w * c];
    out.par_chunks_mut(w * c).enumerate().for_each(|(y, row)| {
        let mut r = rng::stream(seed, y as u64);
        for (o, &v) in row.iter_mut().zip(&e.data()[y * w * c..(y + 1) * w * c]) {
            let mut s = response.forward(v as f64 * t);
            if noise > 0.0 {
                s += normal.sample(&mut r);
            }
            *o = (s.clamp(0.0, 1.0) * zmax).round() as u16;
        }
    });
    Image::new(h, w, c, out)
}

/// A calibration target of `height x width` pixels: radiance rising over 3.5 decades along
/// the rows (`10^(-1 + 3.5 u)`, `u` from 0 to 1 through the image in reading order), the
/// three channels 10 % apart, so that exposures one stop apart cover every code.
pub fn gradient_target(height: usize, width: usize) -> Result<Image<f32>> {
    let n = wscg_math::alloc::elements("height, width", &[height, width, 3])?;
    let mut d = wscg_math::alloc::try_with_capacity("height, width", n)?;
    for y in 0..height {
        for x in 0..width {
            let u = (x as f64 + y as f64 / height as f64) / width as f64;
            let e = 10f64.powf(-1.0 + 3.5 * u);
            d.extend((0..3).map(|k| (e * (1.0 - 0.1 * k as f64)) as f32));
        }
    }
    Image::new(height, width, 3, d)
}

/// The layered multi-view scene of `cfg` with noise seed `seed`.
pub fn layered_scene(cfg: &SceneParams, seed: u64) -> Result<SynthScene> {
    cfg.validate()?;
    let (h, w, n) = (cfg.height, cfg.width, cfg.times.len());
    let c = cfg.centre();
    let mut radiance = Vec::with_capacity(n);
    let mut disparity = Vec::with_capacity(n);
    let mut seen_by = Vec::with_capacity(n);
    for k in 0..n {
        let mut e = vec![0f32; h * w * 3];
        let mut d = vec![0f32; h * w];
        let mut seen = vec![0u32; h * w];
        e.par_chunks_mut(w * 3)
            .zip(d.par_chunks_mut(w))
            .zip(seen.par_chunks_mut(w))
            .enumerate()
            .for_each(|(y, ((er, dr), sr))| {
                let yf = y as f64 + 0.5;
                for x in 0..w {
                    let (li, u) = cfg.visible(k, yf, x as f64 + 0.5);
                    let l = &cfg.layers[li];
                    for ch in 0..3 {
                        er[x * 3 + ch] = cfg.radiance(li, yf, u, ch) as f32;
                    }
                    dr[x] = l.disparity as f32;
                    // Seen by camera j where the same layer is in front at its column.
                    sr[x] = (0..n)
                        .filter(|&j| {
                            let xj = u - (j as f64 - c) * l.disparity;
                            (0.0..w as f64).contains(&xj) && cfg.visible(j, yf, xj).0 == li
                        })
                        .fold(0u32, |m, j| m | (1 << j));
                }
            });
        radiance.push(Image::new(h, w, 3, e)?);
        disparity.push(Image::new(h, w, 1, d)?);
        seen_by.push(seen);
    }
    let views = radiance
        .iter()
        .enumerate()
        .map(|(k, e)| {
            encode(
                e,
                cfg.times[k],
                cfg.response,
                cfg.noise,
                cfg.bits,
                seed.wrapping_add(k as u64),
            )
        })
        .collect::<Result<_>>()?;
    Ok(SynthScene {
        views,
        times: cfg.times.clone(),
        crf: cfg.response.crf(cfg.bits, 1)?,
        response: cfg.response,
        radiance,
        disparity,
        seen_by,
    })
}
