//! Blur kernels rendered from the gyroscope (paper section 3.2, Fig. 1a): a virtual point light
//! at pixel `u` is followed through the exposure under the rotation-only homography
//! `H_t = K R_t K^-1` (eq. 5) and splatted bilinearly; piecewise-uniform kernel grids and the
//! kernel spread ("blurriness") that weights the frames of section 5.

use nalgebra::Vector3;
use rayon::prelude::*;
use wscg_math::{Error, Result};

use crate::camera::{Intrinsics, Timing};
use crate::gyro::GyroTrack;

/// A blur kernel: a `size x size` row-major array of non-negative weights summing to 1, and
/// the array index of zero displacement. A latent point at pixel `u` spreads to
/// `u + (col - origin.1, row - origin.0)`, so the blurred image is `B(x) = sum_d k(d) I(x - d)`.
#[derive(Clone, Debug, PartialEq)]
pub struct Kernel {
    /// Side length (odd).
    pub size: usize,
    /// Row-major weights.
    pub data: Vec<f32>,
    /// `(row, col)` of zero displacement; the centre for gyro kernels.
    pub origin: (usize, usize),
}

impl Kernel {
    /// The identity kernel (no blur).
    pub fn delta() -> Self {
        Kernel {
            size: 1,
            data: vec![1.0],
            origin: (0, 0),
        }
    }

    /// A kernel from a `size x size` array whose zero displacement is at its centre
    /// (`size` odd). The weights are normalised to sum 1.
    ///
    /// Errors: even or zero size, wrong length, negative or non-finite weights, zero sum.
    pub fn centred(size: usize, data: Vec<f32>) -> Result<Self> {
        if size == 0 || size.is_multiple_of(2) {
            return Err(Error::invalid(
                "kernel",
                format!("side must be odd, got {size}"),
            ));
        }
        Self::with_origin(size, size, data, (size / 2, size / 2))
    }

    /// A kernel from an `h x w` array with zero displacement at `origin`; it is embedded in the
    /// smallest odd square centred on the origin and normalised to sum 1.
    ///
    /// Errors: empty, wrong length, origin outside, negative or non-finite weights, zero sum.
    pub fn with_origin(h: usize, w: usize, data: Vec<f32>, origin: (usize, usize)) -> Result<Self> {
        if h == 0 || w == 0 || data.len() != h * w {
            return Err(Error::invalid(
                "kernel",
                format!("expected {h}x{w} = {} weights, got {}", h * w, data.len()),
            ));
        }
        if origin.0 >= h || origin.1 >= w {
            return Err(Error::invalid(
                "origin",
                format!("{origin:?} lies outside the {h}x{w} kernel"),
            ));
        }
        if let Some(i) = data.iter().position(|v| !v.is_finite() || *v < 0.0) {
            return Err(Error::invalid(
                "kernel",
                format!("weights must be finite and >= 0 (index {i})"),
            ));
        }
        let sum: f64 = data.iter().map(|&v| v as f64).sum();
        if sum <= 0.0 {
            return Err(Error::invalid("kernel", "weights sum to zero"));
        }
        let r = origin
            .0
            .max(h - 1 - origin.0)
            .max(origin.1)
            .max(w - 1 - origin.1);
        let size = 2 * r + 1;
        let mut out = vec![0f32; size * size];
        for i in 0..h {
            for j in 0..w {
                out[(i + r - origin.0) * size + j + r - origin.1] =
                    (data[i * w + j] as f64 / sum) as f32;
            }
        }
        Ok(Kernel {
            size,
            data: out,
            origin: (r, r),
        })
    }

    /// A uniform line kernel of `length` pixels through the origin at `angle` radians
    /// (0 = along +x), sampled with 8 points per pixel and splatted bilinearly.
    pub fn line(length: f64, angle: f64) -> Result<Self> {
        if !(length.is_finite() && length >= 0.0) {
            return Err(Error::invalid(
                "length",
                format!("must be finite and >= 0, got {length}"),
            ));
        }
        let n = ((length * 8.0).ceil() as usize).max(1);
        let pts: Vec<(f64, f64)> = (0..n)
            .map(|s| {
                let t = ((s as f64 + 0.5) / n as f64 - 0.5) * length;
                (t * angle.cos(), t * angle.sin())
            })
            .collect();
        splat(&pts, 1e-4, usize::MAX)
    }

    /// Largest displacement from the origin covered by the array, in pixels.
    pub fn radius(&self) -> usize {
        self.origin
            .0
            .max(self.size - 1 - self.origin.0)
            .max(self.origin.1)
            .max(self.size - 1 - self.origin.1)
    }

    /// Mass-weighted mean displacement `(dx, dy)` from the origin.
    pub fn centroid(&self) -> (f64, f64) {
        let (mut sx, mut sy) = (0.0, 0.0);
        for (i, &v) in self.data.iter().enumerate() {
            let (dy, dx) = self.displacement(i);
            sx += v as f64 * dx;
            sy += v as f64 * dy;
        }
        (sx, sy)
    }

    /// Second central moments `(var_x, var_y, cov_xy)` of the kernel mass.
    pub fn moments(&self) -> (f64, f64, f64) {
        let (mx, my) = self.centroid();
        let (mut vx, mut vy, mut cxy) = (0.0, 0.0, 0.0);
        for (i, &v) in self.data.iter().enumerate() {
            let (dy, dx) = self.displacement(i);
            let (ex, ey) = (dx - mx, dy - my);
            vx += v as f64 * ex * ex;
            vy += v as f64 * ey * ey;
            cxy += v as f64 * ex * ey;
        }
        (vx, vy, cxy)
    }

    /// `(dy, dx)` of flat index `i`.
    fn displacement(&self, i: usize) -> (f64, f64) {
        (
            (i / self.size) as f64 - self.origin.0 as f64,
            (i % self.size) as f64 - self.origin.1 as f64,
        )
    }

    /// The kernel mirrored through its origin (`k(-d)`): the correlation partner of a
    /// convolution, and the wrong-sign kernel of the model-consistency check.
    pub fn flipped(&self) -> Self {
        let n = self.size;
        let mut data = vec![0f32; n * n];
        for i in 0..n {
            for j in 0..n {
                data[(n - 1 - i) * n + (n - 1 - j)] = self.data[i * n + j];
            }
        }
        Kernel {
            size: n,
            data,
            origin: (n - 1 - self.origin.0, n - 1 - self.origin.1),
        }
    }

    /// L1 distance between two kernels aligned at their origins.
    pub fn l1_distance(&self, other: &Kernel) -> f64 {
        let r = self.radius().max(other.radius()) as isize;
        let get = |k: &Kernel, dy: isize, dx: isize| {
            let (i, j) = (dy + k.origin.0 as isize, dx + k.origin.1 as isize);
            if i < 0 || j < 0 || i >= k.size as isize || j >= k.size as isize {
                0.0
            } else {
                k.data[i as usize * k.size + j as usize] as f64
            }
        };
        let mut d = 0.0;
        for dy in -r..=r {
            for dx in -r..=r {
                d += (get(self, dy, dx) - get(other, dy, dx)).abs();
            }
        }
        d
    }
}

/// Blurriness of section 5: the spatial standard deviation of the kernel mass,
/// `sqrt(sum_d k(d) |d - mean|^2)` in pixels.
pub fn blurriness(k: &Kernel) -> f64 {
    let (vx, vy, _) = k.moments();
    (vx + vy).sqrt()
}

wscg_math::params! {
    /// Options of [`render_kernel`].
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct KernelParams {
        /// Fewest time sub-steps over the exposure (default 32).
        pub min_steps: usize,
        /// Sub-steps are refined until consecutive projections are closer than this (px, 0.25).
        pub max_step_px: f64,
        /// Most sub-steps (default 4096).
        pub max_steps: usize,
        /// Crop threshold relative to the peak weight (default 1e-4).
        pub threshold: f64,
        /// Largest allowed kernel side in pixels (default 128); larger blur is an error.
        pub max_size: usize,
    }
}

impl Default for KernelParams {
    fn default() -> Self {
        KernelParams {
            min_steps: 32,
            max_step_px: 0.25,
            max_steps: 4096,
            threshold: 1e-4,
            max_size: 128,
        }
    }
}

impl KernelParams {
    /// A fixed number of sub-steps (no refinement).
    pub fn fixed(steps: usize) -> Self {
        KernelParams {
            min_steps: steps,
            max_steps: steps,
            ..Default::default()
        }
    }

    /// Errors: `min_steps == 0`, `max_steps < min_steps`, a non-positive or non-finite
    /// `max_step_px`, `threshold` outside `[0, 1)`, `max_size == 0`.
    pub fn validate(&self) -> Result<()> {
        if self.min_steps == 0 {
            return Err(Error::invalid(
                "min_steps",
                "need 1 <= min_steps <= max_steps, got 0",
            ));
        }
        if self.max_steps < self.min_steps {
            return Err(Error::invalid(
                "max_steps",
                format!(
                    "need 1 <= min_steps <= max_steps, got min_steps {} and max_steps {}",
                    self.min_steps, self.max_steps
                ),
            ));
        }
        if !(self.max_step_px.is_finite() && self.max_step_px > 0.0) {
            return Err(Error::invalid(
                "max_step_px",
                format!("must be finite and > 0, got {}", self.max_step_px),
            ));
        }
        if !(self.threshold >= 0.0 && self.threshold < 1.0) {
            return Err(Error::invalid(
                "threshold",
                format!("must lie in [0, 1), got {}", self.threshold),
            ));
        }
        if self.max_size == 0 {
            return Err(Error::invalid("max_size", "must be > 0"));
        }
        Ok(())
    }
}

/// Displacements of the image of a latent point at `pixel` at `steps` instants
/// `t_open + (s + 1/2) t_e / steps`, relative to the shutter-open pose.
fn path(
    track: &GyroTrack,
    k: &Intrinsics,
    pixel: (f64, f64),
    t_open: f64,
    t_e: f64,
    steps: usize,
) -> Result<Vec<(f64, f64)>> {
    let ray = Vector3::from(k.ray(pixel.0, pixel.1));
    let q_open_inv = track.orientation(t_open).inverse();
    (0..steps)
        .map(|s| {
            let tau = t_open + (s as f64 + 0.5) * t_e / steps as f64;
            // R_rel maps camera-at-tau to camera-at-open; the latent point X (open frame) is
            // R_rel^T X in camera-at-tau coordinates.
            let r_rel = q_open_inv * track.orientation(tau);
            let p: Vector3<f64> = r_rel.inverse_transform_vector(&ray);
            k.project(p.into())
                .map(|(x, y)| (x - pixel.0, y - pixel.1))
                .ok_or_else(|| {
                    Error::invalid(
                        "gyro",
                        "the camera turned by more than 90 degrees during the exposure",
                    )
                })
        })
        .collect()
}

/// Splats points with equal weight bilinearly around the origin, crops to the smallest odd
/// square centred on the origin that holds all mass above `threshold * peak`, renormalises.
fn splat(pts: &[(f64, f64)], threshold: f64, max_size: usize) -> Result<Kernel> {
    let r = pts
        .iter()
        .fold(0f64, |m, p| m.max(p.0.abs()).max(p.1.abs()))
        .ceil() as usize
        + 1;
    let n = 2 * r + 1;
    if n > 8192 {
        return Err(Error::LimitExceeded(format!(
            "blur of {} px is too large for tiling",
            n
        )));
    }
    let mut acc = vec![0f64; n * n];
    let w = 1.0 / pts.len() as f64;
    for &(dx, dy) in pts {
        let (x, y) = (dx + r as f64, dy + r as f64);
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as usize, y0 as usize);
        acc[y0 * n + x0] += w * (1.0 - fx) * (1.0 - fy);
        acc[y0 * n + x0 + 1] += w * fx * (1.0 - fy);
        acc[(y0 + 1) * n + x0] += w * (1.0 - fx) * fy;
        acc[(y0 + 1) * n + x0 + 1] += w * fx * fy;
    }
    let peak = acc.iter().cloned().fold(0.0, f64::max);
    let cut = threshold * peak;
    let mut keep = 0usize;
    for (i, &v) in acc.iter().enumerate() {
        if v > cut {
            let (dy, dx) = ((i / n) as isize - r as isize, (i % n) as isize - r as isize);
            keep = keep.max(dy.unsigned_abs()).max(dx.unsigned_abs());
        }
    }
    let size = 2 * keep + 1;
    if size > max_size {
        return Err(Error::LimitExceeded(format!(
            "blur too large for tiling: the kernel needs {size} px, at most {max_size} px are allowed"
        )));
    }
    let mut data = vec![0f32; size * size];
    let mut sum = 0.0;
    for i in 0..size {
        for j in 0..size {
            let v = acc[(i + r - keep) * n + j + r - keep];
            let v = if v > cut { v } else { 0.0 };
            sum += v;
            data[i * size + j] = v as f32;
        }
    }
    data.iter_mut().for_each(|v| *v = (*v as f64 / sum) as f32);
    Ok(Kernel {
        size,
        data,
        origin: (keep, keep),
    })
}

/// Renders the blur kernel at `pixel = (x, y)` of a frame (paper section 3.2): the exposure of
/// the pixel's row (eq. 6) is cut into sub-steps (at least `opts.min_steps`, refined until
/// consecutive projections are closer than `opts.max_step_px`), the latent point's image under
/// `R(t_open)^T R(tau)` is splatted bilinearly with weight `1/S` each, and the kernel is
/// cropped around its origin (the shutter-open pose) and normalised.
///
/// Convention: a positive rate about the camera's `+y` axis (yaw) moves the kernel towards `-x`.
///
/// Errors: invalid timing or intrinsics, gyroscope samples not covering the exposure, blur
/// wider than `opts.max_size` ("blur too large for tiling").
pub fn render_kernel(
    track: &GyroTrack,
    timing: &Timing,
    k: &Intrinsics,
    pixel: (f64, f64),
    opts: &KernelParams,
) -> Result<Kernel> {
    timing.validate()?;
    k.validate()?;
    opts.validate()?;
    if !(pixel.0.is_finite() && pixel.1.is_finite()) {
        return Err(Error::invalid("pixel", "must be finite"));
    }
    let t_open = timing.open(pixel.1);
    let t_e = timing.t_exposure;
    track.ensure_covers(t_open, t_open + t_e)?;
    let mut steps = opts.min_steps;
    let mut pts = path(track, k, pixel, t_open, t_e, steps)?;
    while steps < opts.max_steps {
        let longest = pts
            .windows(2)
            .fold(0f64, |m, p| m.max((p[1].0 - p[0].0).hypot(p[1].1 - p[0].1)));
        if longest < opts.max_step_px {
            break;
        }
        steps = ((steps as f64 * longest / opts.max_step_px * 1.1).ceil() as usize)
            .clamp(steps + 1, opts.max_steps);
        pts = path(track, k, pixel, t_open, t_e, steps)?;
    }
    splat(&pts, opts.threshold, opts.max_size)
}

/// Piecewise-uniform kernels of a frame (paper section 3, Fig. 3): one kernel per
/// `tile x tile` region, rendered at the region centre with the centre row's timing.
#[derive(Clone, Debug)]
pub struct KernelGrid {
    /// Region side in pixels.
    pub tile: usize,
    /// Frame width and height in pixels.
    pub width: usize,
    /// Frame height.
    pub height: usize,
    /// Region rows.
    pub rows: usize,
    /// Region columns.
    pub cols: usize,
    /// Row-major kernels, `rows * cols`.
    pub kernels: Vec<Kernel>,
}

impl KernelGrid {
    /// The same kernel for every region (uniform blur).
    pub fn uniform(kernel: Kernel, width: usize, height: usize, tile: usize) -> Result<Self> {
        let (rows, cols) = grid_shape(width, height, tile)?;
        Ok(KernelGrid {
            tile,
            width,
            height,
            rows,
            cols,
            kernels: vec![kernel; rows * cols],
        })
    }

    /// Kernel of region `(row, col)`.
    pub fn get(&self, row: usize, col: usize) -> &Kernel {
        &self.kernels[row * self.cols + col]
    }

    /// Centre `(x, y)` of region `(row, col)` in pixels.
    pub fn centre(&self, row: usize, col: usize) -> (f64, f64) {
        region_centre(self.tile, self.width, self.height, row, col)
    }

    /// Largest kernel radius of the grid.
    pub fn max_radius(&self) -> usize {
        self.kernels.iter().map(Kernel::radius).max().unwrap_or(0)
    }
}

/// `(rows, cols)` of the region grid of a `width x height` frame.
pub(crate) fn grid_shape(width: usize, height: usize, tile: usize) -> Result<(usize, usize)> {
    if width == 0 || height == 0 {
        return Err(Error::Empty("frame"));
    }
    if tile == 0 {
        return Err(Error::invalid("tile", "region size must be > 0"));
    }
    Ok((height.div_ceil(tile), width.div_ceil(tile)))
}

/// Centre `(x, y)` of region `(row, col)`; the last row and column may be narrower.
pub(crate) fn region_centre(
    tile: usize,
    width: usize,
    height: usize,
    row: usize,
    col: usize,
) -> (f64, f64) {
    let x1 = ((col + 1) * tile).min(width);
    let y1 = ((row + 1) * tile).min(height);
    (
        (col * tile + x1 - 1) as f64 / 2.0,
        (row * tile + y1 - 1) as f64 / 2.0,
    )
}

/// Renders the kernel of every `tile x tile` region of a `width x height` frame at the region
/// centre (in parallel). Errors: those of [`render_kernel`], a zero size or tile.
pub fn kernel_grid(
    track: &GyroTrack,
    timing: &Timing,
    k: &Intrinsics,
    width: usize,
    height: usize,
    tile: usize,
    opts: &KernelParams,
) -> Result<KernelGrid> {
    opts.validate()?;
    let (rows, cols) = grid_shape(width, height, tile)?;
    let kernels = (0..rows * cols)
        .into_par_iter()
        .map(|i| {
            render_kernel(
                track,
                timing,
                k,
                region_centre(tile, width, height, i / cols, i % cols),
                opts,
            )
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(KernelGrid {
        tile,
        width,
        height,
        rows,
        cols,
        kernels,
    })
}
