//! Synthetic gyro blur with exact ground truth, standing in for the recorded hand shake of the
//! paper's section 6.2 (its images and gyroscope logs are not public): Ornstein-Uhlenbeck hand
//! shake, gyroscope noise, and frames rendered densely (per row, per time sub-step, a full
//! homography warp of the sharp image) so that the tests never blur with the kernels they
//! deblur with.

use nalgebra::Vector3;
use rand::Rng;
use rand_distr::{Distribution, Normal, StandardNormal};
use rayon::prelude::*;
use wscg_math::vec3::add;
use wscg_math::{rng, Error, Image, Result};

use crate::camera::{to_display, Gamma, Intrinsics, Timing};
use crate::gyro::{GyroSample, GyroTrack};
use crate::tiling::check_frame;
use crate::warp::bicubic;

wscg_math::params! {
    /// Hand-shake model: an Ornstein-Uhlenbeck process per camera axis.
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct ShakeParams {
        /// Sampling rate in Hz (default 200, the paper's phone gyroscope).
        pub rate: f64,
        /// Correlation time in seconds (default 0.05).
        pub tau: f64,
        /// Stationary standard deviation of the rate about x (pitch), y (yaw), z (roll), rad/s
        /// (default 0.35, 0.35, 0.10).
        pub std: [f64; 3],
        /// Start time of the trace (s).
        pub t0: f64,
        /// Duration (s).
        pub duration: f64,
    }
}

impl Default for ShakeParams {
    fn default() -> Self {
        ShakeParams {
            rate: 200.0,
            tau: 0.05,
            std: [0.35, 0.35, 0.10],
            t0: 0.0,
            duration: 1.0,
        }
    }
}

impl ShakeParams {
    /// Errors: a non-positive or non-finite `rate`, `tau` or `duration`, a negative or
    /// non-finite deviation, a non-finite `t0`.
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [
            ("rate", self.rate),
            ("tau", self.tau),
            ("duration", self.duration),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::invalid(
                    name,
                    format!("must be finite and > 0, got {v}"),
                ));
            }
        }
        if let Some(s) = self.std.iter().find(|s| !(s.is_finite() && **s >= 0.0)) {
            return Err(Error::invalid(
                "std",
                format!("rate deviations must be finite and >= 0, got {s}"),
            ));
        }
        if !self.t0.is_finite() {
            return Err(Error::invalid(
                "t0",
                format!("must be finite, got {}", self.t0),
            ));
        }
        Ok(())
    }
}

/// Samples an Ornstein-Uhlenbeck angular-rate trace (exact discretisation, started from the
/// stationary distribution), in camera axes, noise-free.
///
/// Errors: non-positive rate, correlation time or duration; negative deviations.
pub fn ou_gyro(p: &ShakeParams, seed: u64) -> Result<Vec<GyroSample>> {
    p.validate()?;
    let n = (p.duration * p.rate).ceil() as usize + 1;
    if n > 100_000_000 {
        return Err(Error::LimitExceeded(format!("{n} gyroscope samples")));
    }
    let dt = 1.0 / p.rate;
    let a = (-dt / p.tau).exp();
    let b = (1.0 - a * a).sqrt();
    let mut r = rng::seeded(seed);
    let mut w: [f64; 3] = std::array::from_fn(|k| p.std[k] * r.sample::<f64, _>(StandardNormal));
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        out.push(GyroSample {
            t: p.t0 + i as f64 * dt,
            w,
        });
        for (k, wk) in w.iter_mut().enumerate() {
            *wk = a * *wk + b * p.std[k] * r.sample::<f64, _>(StandardNormal);
        }
    }
    Ok(out)
}

/// Adds white noise of standard deviation `sigma` (rad/s) to every rate.
pub fn add_gyro_noise(samples: &[GyroSample], sigma: f64, seed: u64) -> Result<Vec<GyroSample>> {
    let n =
        Normal::new(0.0, sigma).map_err(|_| Error::invalid("sigma", "must be finite and >= 0"))?;
    let mut r = rng::seeded(seed);
    Ok(samples
        .iter()
        .map(|s| GyroSample {
            t: s.t,
            w: add(s.w, std::array::from_fn(|_| n.sample(&mut r))),
        })
        .collect())
}

wscg_math::params! {
    /// Options of [`render_blurred`].
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct BlurRenderParams {
        /// Fewest time sub-steps per row (default 64); more are used so that consecutive
        /// sub-steps move the image by at most half a pixel.
        pub min_steps: usize,
        /// Standard deviation of the Gaussian noise added to the linear image (default 0.005).
        pub noise_sigma: f32,
        /// Camera response applied after the noise (default gamma 2.2); `None` keeps linear values.
        pub gamma: Option<Gamma>,
        /// Quantise the display values to 8 bits (default true).
        pub quantise: bool,
    }
}

impl Default for BlurRenderParams {
    fn default() -> Self {
        BlurRenderParams {
            min_steps: 64,
            noise_sigma: 0.005,
            gamma: Some(Gamma::default()),
            quantise: true,
        }
    }
}

impl BlurRenderParams {
    /// Errors: `min_steps == 0`, a negative or non-finite `noise_sigma`, an invalid gamma.
    pub fn validate(&self) -> Result<()> {
        if self.min_steps == 0 {
            return Err(Error::invalid("min_steps", "must be >= 1"));
        }
        if !(self.noise_sigma.is_finite() && self.noise_sigma >= 0.0) {
            return Err(Error::invalid(
                "noise_sigma",
                format!("must be finite and >= 0, got {}", self.noise_sigma),
            ));
        }
        if let Some(g) = self.gamma {
            g.validate()?;
        }
        Ok(())
    }
}

/// Renders a blurred frame of a planar scene densely (eq. 2 with the rotation-only homography
/// of eq. 5): `sharp` holds the linear image seen in the pose at `t_world` (ground truth); row
/// `y` of the frame averages, over the sub-steps `tau` of its exposure (eq. 6), the sharp image
/// warped by `K R(t_world)^T R(tau) K^-1` (bicubic, borders replicated). Noise, gamma and 8-bit
/// quantisation follow `opts`; the result is in display values `[0, 1]` (or linear when
/// `opts.gamma` is `None`).
///
/// Errors: invalid timing or intrinsics, gyroscope samples not covering the frame, a frame
/// height different from `timing.height`, a multi-channel or non-finite image.
pub fn render_blurred(
    sharp: &Image<f32>,
    track: &GyroTrack,
    timing: &Timing,
    k: &Intrinsics,
    t_world: f64,
    opts: &BlurRenderParams,
    seed: u64,
) -> Result<Image<f32>> {
    opts.validate()?;
    check_frame(sharp, "sharp")?;
    timing.validate()?;
    k.validate()?;
    let (h, w) = (sharp.height(), sharp.width());
    if timing.height != h {
        return Err(Error::ShapeMismatch(format!(
            "timing.height = {} but the image has {h} rows",
            timing.height
        )));
    }
    track.ensure_covers(
        timing.open(0.0),
        timing.open((h - 1) as f64) + timing.t_exposure,
    )?;
    track.ensure_covers(t_world, t_world)?;
    let q_world_inv = track.orientation(t_world).inverse();
    let km = k.matrix();
    let kinv = km
        .try_inverse()
        .ok_or_else(|| Error::invalid("f", "singular intrinsics"))?;
    // Sub-steps: enough that the corners move by < 0.5 px between consecutive ones.
    let corners = [
        (0.0, 0.0),
        ((w - 1) as f64, 0.0),
        (0.0, (h - 1) as f64),
        ((w - 1) as f64, (h - 1) as f64),
    ];
    let t0 = timing.open(0.0);
    let probe = 256;
    let mut longest = 0f64;
    for s in 0..probe {
        let (ta, tb) = (
            t0 + timing.t_exposure * s as f64 / probe as f64,
            t0 + timing.t_exposure * (s + 1) as f64 / probe as f64,
        );
        let r = track.relative(ta, tb);
        for &(x, y) in &corners {
            let p = r.inverse_transform_vector(&Vector3::from(k.ray(x, y)));
            if let Some((px, py)) = k.project(p.into()) {
                longest = longest.max((px - x).hypot(py - y) * probe as f64);
            }
        }
    }
    let steps = opts
        .min_steps
        .max((longest / 0.5).ceil() as usize)
        .min(16384);
    let plane = sharp.data();
    let mut out = vec![0f32; h * w];
    out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        let t_open = timing.open(y as f64);
        let mut acc = vec![0f64; w];
        for s in 0..steps {
            let tau = t_open + (s as f64 + 0.5) * timing.t_exposure / steps as f64;
            // Frame pixel x sees the ray R(t_world)^T R(tau) K^-1 x of the world (sharp) pose.
            let hm = km
                * (q_world_inv * track.orientation(tau))
                    .to_rotation_matrix()
                    .matrix()
                * kinv;
            for (x, a) in acc.iter_mut().enumerate() {
                let p = hm * Vector3::new(x as f64, y as f64, 1.0);
                *a += bicubic(plane, h, w, p.x / p.z, p.y / p.z) as f64;
            }
        }
        for (o, a) in row.iter_mut().zip(&acc) {
            *o = (*a / steps as f64) as f32;
        }
    });
    finish(&mut out, opts, seed)?;
    Image::new(h, w, 1, out)
}

/// Noise, camera response and quantisation of a rendered linear frame.
fn finish(data: &mut [f32], opts: &BlurRenderParams, seed: u64) -> Result<()> {
    if opts.noise_sigma > 0.0 {
        rng::par_fill(seed, data.len(), |r| r.sample::<f32, _>(StandardNormal))?
            .iter()
            .zip(data.iter_mut())
            .for_each(|(n, v)| *v += opts.noise_sigma * n);
    }
    to_display(opts.gamma, data);
    if opts.quantise {
        data.iter_mut()
            .for_each(|v| *v = (*v * 255.0).round() / 255.0);
    }
    Ok(())
}

/// A textured test scene of `height x width` linear intensities in `[0.02, 0.98]`: smooth
/// blobs, sharp-edged discs and bars, and fine stripes, from a seed (Rust tests and demos use
/// it where the Python tests use scikit-image's photographs).
pub fn scene(height: usize, width: usize, seed: u64) -> Result<Image<f32>> {
    if height == 0 || width == 0 {
        return Err(Error::Empty("scene"));
    }
    let mut r = rng::seeded(seed);
    let blobs: Vec<(f64, f64, f64, f64)> = (0..24)
        .map(|_| {
            (
                r.random::<f64>() * width as f64,
                r.random::<f64>() * height as f64,
                4.0 + 20.0 * r.random::<f64>(),
                r.random::<f64>() - 0.5,
            )
        })
        .collect();
    let discs: Vec<(f64, f64, f64, f64)> = (0..40)
        .map(|_| {
            (
                r.random::<f64>() * width as f64,
                r.random::<f64>() * height as f64,
                2.0 + 10.0 * r.random::<f64>(),
                r.random::<f64>() - 0.5,
            )
        })
        .collect();
    let bars: Vec<(f64, f64, f64, f64, f64)> = (0..20)
        .map(|_| {
            (
                r.random::<f64>() * width as f64,
                r.random::<f64>() * height as f64,
                r.random::<f64>() * std::f64::consts::PI,
                3.0 + 20.0 * r.random::<f64>(),
                r.random::<f64>() - 0.5,
            )
        })
        .collect();
    let (f1, f2) = (0.3 + 0.4 * r.random::<f64>(), 0.2 + 0.5 * r.random::<f64>());
    Image::from_fn(height, width, |y, x| {
        let (xf, yf) = (x as f64, y as f64);
        let mut v = 0.45 + 0.08 * (xf * 0.05 * f1).sin() * (yf * 0.043 * f2).cos();
        for &(cx, cy, s, a) in &blobs {
            v += 0.25 * a * (-((xf - cx).powi(2) + (yf - cy).powi(2)) / (2.0 * s * s)).exp();
        }
        for &(cx, cy, rad, a) in &discs {
            if (xf - cx).hypot(yf - cy) < rad {
                v += 0.35 * a;
            }
        }
        for &(cx, cy, th, len, a) in &bars {
            let (dx, dy) = (xf - cx, yf - cy);
            let (u, n) = (
                dx * th.cos() + dy * th.sin(),
                -dx * th.sin() + dy * th.cos(),
            );
            if u.abs() < len && n.abs() < 1.5 {
                v += 0.4 * a;
            }
        }
        if x * 4 > 3 * width && y * 4 > 3 * height {
            v += 0.15 * ((xf * 1.3).sin() + (yf * 0.9).sin());
        }
        v.clamp(0.02, 0.98) as f32
    })
}

/// Frame timing and shake of a synthetic burst: `frames` frames at `fps` starting at `t0`,
/// exposure `t_e`, readout `t_r`, gyro delay `t_d`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Burst {
    /// Number of frames.
    pub frames: usize,
    /// Frame rate (Hz, default 30).
    pub fps: f64,
    /// Time stamp of the first frame (s, default 0.1 so the gyro trace starts earlier).
    pub t0: f64,
    /// Exposure (s, default 0.03).
    pub t_exposure: f64,
    /// Readout (s, default 0).
    pub t_readout: f64,
    /// Gyro-camera delay (s, default 0.015).
    pub t_delay: f64,
    /// Focal length in pixels (default 600); the principal point is the frame centre.
    pub f: f64,
}

impl Default for Burst {
    fn default() -> Self {
        Burst {
            frames: 5,
            fps: 30.0,
            t0: 0.1,
            t_exposure: 0.03,
            t_readout: 0.0,
            t_delay: 0.015,
            f: 600.0,
        }
    }
}

impl Burst {
    /// Frame time stamps.
    pub fn times(&self) -> Vec<f64> {
        (0..self.frames)
            .map(|i| self.t0 + i as f64 / self.fps)
            .collect()
    }

    /// Timing of frame `i` for frames of `height` rows.
    pub fn timing(&self, i: usize, height: usize) -> Timing {
        Timing {
            t_frame: self.t0 + i as f64 / self.fps,
            t_exposure: self.t_exposure,
            t_readout: self.t_readout,
            t_delay: self.t_delay,
            height,
        }
    }

    /// Gyro trace duration covering every frame with margin (s).
    pub fn duration(&self) -> f64 {
        self.t0
            + self.frames as f64 / self.fps
            + self.t_delay.abs()
            + self.t_exposure
            + self.t_readout
            + 0.1
    }
}

/// A synthetic burst: the frames (display values), the true and the measured (noisy)
/// gyroscope samples, and the ground truth (the sharp image in display values, in the pose of
/// the main frame's virtual global shutter).
#[derive(Clone, Debug)]
pub struct SyntheticBurst {
    /// Rendered frames with their time stamps.
    pub frames: Vec<crate::multiframe::FrameInput>,
    /// Noise-free gyroscope samples used for rendering.
    pub truth: Vec<GyroSample>,
    /// Gyroscope samples with white noise, as a phone would report them.
    pub measured: Vec<GyroSample>,
    /// Ground truth in display values.
    pub sharp_display: Image<f32>,
}

/// Renders `burst.frames` frames of the linear image `sharp` under Ornstein-Uhlenbeck shake
/// (`ou`, its duration extended to cover the burst) for the camera of `burst`, world = the pose of frame `main`'s virtual
/// global shutter; the measured gyro has white noise `gyro_noise` (rad/s).
///
/// Errors: those of [`ou_gyro`] and [`render_blurred`]; `main` out of range.
pub fn make_burst(
    sharp: &Image<f32>,
    burst: &Burst,
    ou: &ShakeParams,
    main: usize,
    gyro_noise: f64,
    render: &BlurRenderParams,
    seed: u64,
) -> Result<SyntheticBurst> {
    render.validate()?;
    if main >= burst.frames {
        return Err(Error::invalid(
            "main",
            format!("index {main} is out of range for {} frames", burst.frames),
        ));
    }
    let ou = ShakeParams {
        duration: ou.duration.max(burst.duration() - ou.t0),
        ..*ou
    };
    let truth = ou_gyro(&ou, seed)?;
    let measured = add_gyro_noise(&truth, gyro_noise, seed ^ 0x9e37_79b9)?;
    let track = GyroTrack::from_camera_rates(&truth)?;
    let h = sharp.height();
    let k = Intrinsics::centred(burst.f, sharp.width(), h);
    let world = burst.timing(main, h).reference();
    let frames = (0..burst.frames)
        .map(|i| {
            let timing = burst.timing(i, h);
            let image = render_blurred(
                sharp,
                &track,
                &timing,
                &k,
                world,
                render,
                seed.wrapping_mul(31).wrapping_add(i as u64),
            )?;
            Ok(crate::multiframe::FrameInput {
                image,
                t: timing.t_frame,
            })
        })
        .collect::<Result<Vec<_>>>()?;
    let mut d = sharp.data().to_vec();
    to_display(render.gamma, &mut d);
    Ok(SyntheticBurst {
        frames,
        truth,
        measured,
        sharp_display: Image::new(h, sharp.width(), 1, d)?,
    })
}
