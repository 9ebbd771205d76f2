//! Multi-frame blur removal (paper section 5, eq. 9): every frame is rectified and deblurred
//! region by region, the neighbours' estimates are aligned to the main frame, and each region
//! of the main frame is solved again with the neighbours' estimates as a quadratic prior,
//! weighted per region and per frame by the inverse spread of their kernels.

use nalgebra::Matrix3;
use wscg_math::progress::Progress;
use wscg_math::{Error, Image, Result};

use crate::align::{align_homography, correlation, degenerate, AlignParams};
use crate::camera::{to_display, Gamma, Intrinsics, Timing};
use crate::deconv::{self, HyperLaplacianParams};
use crate::gyro::GyroTrack;
use crate::kernel::{blurriness, kernel_grid, render_kernel, KernelGrid, KernelParams};
use crate::spectral::window;
use crate::tiling::{check_frame, deblur_piecewise, run_tiles, Method, Tiling};
use crate::warp::{apply_h, rectify_rolling_shutter, warp_homography};

/// One input frame: display values in `[0, 1]` (gamma-encoded as the camera delivers them)
/// and its time stamp on the frame clock.
#[derive(Clone, Debug)]
pub struct FrameInput {
    /// Grayscale display values in `[0, 1]`.
    pub image: Image<f32>,
    /// Frame time stamp `t_i` (s).
    pub t: f64,
}

/// How neighbour estimates are aligned to the main frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AlignMode {
    /// The gyroscope's rotation between the frames, `K R_main^T R_j K^-1`, as is.
    Gyro,
    /// The gyroscope's prediction refined by ECC (default).
    Ecc(AlignParams),
}

wscg_math::params! {
    /// Options of [`deblur_multiframe`].
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct MultiframeParams {
        /// Exposure time `t_e` (s).
        pub t_exposure: f64,
        /// Rolling-shutter readout `t_r` (s, 0 for a global shutter).
        pub t_readout: f64,
        /// Gyro-camera delay `t_d` (s).
        pub t_delay: f64,
        /// Camera response (default gamma 2.2, section 3.3); `None` treats values as linear.
        pub gamma: Option<Gamma>,
        /// Region layout (30 px regions).
        pub tiling: Tiling,
        /// Hyper-Laplacian solver parameters (default: the paper's, `lambda = 2000`; with
        /// `lambda: None` every frame's data weight comes from its own noise level, which
        /// lost 0.03-2.1 dB here on gyro-estimated kernels, whose errors the noise estimate
        /// does not see; BENCHMARKS.md).
        pub hl: HyperLaplacianParams,
        /// Weight `mu` of the multi-frame prior (eq. 9; default 250 = lambda / 8 for the
        /// paper's lambda 2000, tuned on the development image, benches/peers/_12_tune.py).
        pub mu: f32,
        /// Kernel rendering options.
        pub kernel: KernelParams,
        /// Alignment of the neighbours.
        pub align: AlignMode,
        /// A neighbour whose aligned correlation with the main estimate is below this is dropped
        /// (default 0.8).
        pub min_ncc: f64,
        /// Use at most this many frames on each side of the main frame (`None`: all).
        pub radius: Option<usize>,
    }
}

impl Default for MultiframeParams {
    fn default() -> Self {
        MultiframeParams {
            t_exposure: 0.03,
            t_readout: 0.0,
            t_delay: 0.0,
            gamma: Some(Gamma::default()),
            tiling: Tiling::default(),
            hl: HyperLaplacianParams::paper(),
            mu: 250.0,
            kernel: KernelParams::default(),
            align: AlignMode::Ecc(AlignParams::default()),
            min_ncc: 0.8,
            radius: None,
        }
    }
}

/// Result of [`deblur_multiframe`].
#[derive(Clone, Debug)]
pub struct DeblurResult {
    /// The deblurred main frame, display values in `[0, 1]` (KM).
    pub image: Image<f32>,
    /// The single-frame result of the main frame (KS), display values.
    pub single: Image<f32>,
    /// The main frame's region kernels.
    pub kernels: KernelGrid,
    /// Frame weights `nu_j` of eq. 9 per region: `rows x cols x frames`, row-major; 0 for the
    /// main frame (it enters through the data term) and for unused frames.
    pub weights: Vec<f32>,
    /// Number of frames (last axis of `weights`).
    pub frames: usize,
    /// Frames that contributed: the main frame and the aligned neighbours.
    pub used_frames: Vec<usize>,
    /// Neighbours dropped and why.
    pub warnings: Vec<String>,
}

impl MultiframeParams {
    /// Errors: invalid timing (`t_exposure <= 0`, `t_readout < 0`, non-finite times), gamma,
    /// tiling, solver, kernel or alignment parameters (the error names the field), a negative
    /// or non-finite `mu`, a non-finite `min_ncc`.
    pub fn validate(&self) -> Result<()> {
        Timing {
            t_frame: 0.0,
            t_exposure: self.t_exposure,
            t_readout: self.t_readout,
            t_delay: self.t_delay,
            height: 1,
        }
        .validate()?;
        if let Some(g) = self.gamma {
            g.validate()?;
        }
        self.tiling.validate()?;
        self.hl.validate()?;
        self.kernel.validate()?;
        if let AlignMode::Ecc(a) = self.align {
            a.validate()?;
        }
        if !(self.mu.is_finite() && self.mu >= 0.0) {
            return Err(Error::invalid(
                "mu",
                format!("must be finite and >= 0, got {}", self.mu),
            ));
        }
        if !self.min_ncc.is_finite() {
            return Err(Error::invalid("min_ncc", "must be finite"));
        }
        Ok(())
    }

    fn timing(&self, t: f64, height: usize) -> Timing {
        Timing {
            t_frame: t,
            t_exposure: self.t_exposure,
            t_readout: self.t_readout,
            t_delay: self.t_delay,
            height,
        }
    }
}

/// A frame after step 1: rectified linear frame, its kernels, its single-frame estimate.
type Estimate = (Image<f32>, KernelGrid, Image<f32>);

/// Per-region weights `nu_j = mu_j / sum mu_j` with `mu_j = 1 / max(sigma_j, 0.5)` of the
/// frames whose blurriness `sigma_j` is known (eq. 9): `None` marks a frame that does not
/// cover the region.
pub fn frame_weights(sigmas: &[Option<f64>]) -> Vec<f64> {
    let mu: Vec<f64> = sigmas
        .iter()
        .map(|s| s.map_or(0.0, |s| 1.0 / s.max(0.5)))
        .collect();
    let total: f64 = mu.iter().sum();
    mu.iter()
        .map(|m| if total > 0.0 { m / total } else { 0.0 })
        .collect()
}

/// Step 1 of the pipeline for one frame: linearise (gamma), rectify the rolling shutter and
/// render the region kernels. Returns the rectified linear frame and its kernels.
fn prepare(
    frame: &FrameInput,
    track: &GyroTrack,
    k: &Intrinsics,
    opts: &MultiframeParams,
) -> Result<(Image<f32>, KernelGrid)> {
    check_frame(&frame.image, "frame")?;
    let (h, w) = (frame.image.height(), frame.image.width());
    let mut lin = frame.image.clone();
    if let Some(g) = opts.gamma {
        g.linearise(lin.data_mut());
    }
    let timing = opts.timing(frame.t, h);
    let rect = rectify_rolling_shutter(&lin, track, &timing, k)?;
    let grid = kernel_grid(track, &timing, k, w, h, opts.tiling.tile, &opts.kernel)?;
    Ok((rect, grid))
}

/// Single-frame deblurring of one frame with any region method (Table 1's W, RL, KS or the
/// global kernel): linearise, rectify, render the region kernels, deblur, encode. Uses the
/// timing, camera response, tiling and kernel options of `opts`. Returns the display-valued
/// result and the kernels.
///
/// Errors: as [`deblur_multiframe`]; invalid method parameters.
pub fn deblur_frame(
    frame: &FrameInput,
    track: &GyroTrack,
    k: &Intrinsics,
    method: &Method,
    opts: &MultiframeParams,
) -> Result<(Image<f32>, KernelGrid)> {
    opts.validate()?;
    k.validate()?;
    let (rect, grid) = prepare(frame, track, k, opts)?;
    let mut d = deblur_piecewise(&rect, &grid, method, &opts.tiling)?.into_data();
    to_display(opts.gamma, &mut d);
    Ok((Image::new(rect.height(), rect.width(), 1, d)?, grid))
}

/// Multi-frame deblurring of `frames[main]` (paper section 5, Figs. 1-2).
///
/// 1. Every frame used is linearised (gamma), rolling-shutter rectified, and deblurred region
///    by region with its gyro kernels (KS).
/// 2. Every neighbour's estimate is aligned to the main estimate (gyro prediction, refined by
///    ECC unless [`AlignMode::Gyro`]); frames that fail (error, correlation below `min_ncc`,
///    degenerate homography) are dropped with a warning.
/// 3. For every region of the main frame, the neighbours covering it get weights from the
///    blurriness of their kernel at the corresponding point, and the region is solved with
///    the prior `sum_j nu_j I_j` of weight `mu` (KM, eq. 9).
///
/// With no usable neighbour the result is the single-frame KS result.
///
/// Errors: an empty frame list, `main` out of range, frames of different sizes, multi-channel
/// or non-finite frames, invalid options, gyroscope samples not covering an exposure, blur too
/// large for the tiling.
pub fn deblur_multiframe(
    frames: &[FrameInput],
    main: usize,
    track: &GyroTrack,
    k: &Intrinsics,
    opts: &MultiframeParams,
    progress: &dyn Progress,
) -> Result<DeblurResult> {
    opts.validate()?;
    if frames.is_empty() {
        return Err(Error::Empty("frames"));
    }
    if main >= frames.len() {
        return Err(Error::invalid(
            "main",
            format!("index {main} is out of range for {} frames", frames.len()),
        ));
    }
    k.validate()?;
    for f in frames {
        check_frame(&f.image, "frames")?;
        if !f.t.is_finite() {
            return Err(Error::invalid("frame_times", "must be finite"));
        }
    }
    let (h, w) = (frames[main].image.height(), frames[main].image.width());
    if let Some(f) = frames
        .iter()
        .find(|f| f.image.height() != h || f.image.width() != w)
    {
        return Err(Error::ShapeMismatch(format!(
            "frames differ in size: {}x{} and {}x{}",
            w,
            h,
            f.image.width(),
            f.image.height()
        )));
    }
    let radius = opts.radius.unwrap_or(frames.len());
    let chosen: Vec<usize> = (0..frames.len())
        .filter(|&j| j.abs_diff(main) <= radius)
        .collect();
    let method = Method::HyperLaplacian(opts.hl);
    let tile = opts.tiling.tile;
    progress.begin("deblurring frames", chosen.len() as u64 + 2);
    // 1. Rectify and deblur every chosen frame.
    let mut estimates: Vec<Option<Estimate>> = vec![None; frames.len()];
    for &j in &chosen {
        let (rect, grid) = prepare(&frames[j], track, k, opts)?;
        let est = deblur_piecewise(&rect, &grid, &method, &opts.tiling)?;
        estimates[j] = Some((rect, grid, est));
        progress.advance(1);
    }
    let Some((main_rect, main_grid, main_est)) = estimates[main].take() else {
        return Err(Error::Numerical("main frame was not processed".into()));
    };
    // 2. Align the neighbours to the main estimate.
    let t_main = opts.timing(frames[main].t, h).reference();
    let (km, kinv) = (
        k.matrix(),
        k.matrix()
            .try_inverse()
            .ok_or_else(|| Error::invalid("f", "singular intrinsics"))?,
    );
    let mut warnings = Vec::new();
    let mut aligned: Vec<(usize, Matrix3<f64>, Image<f32>)> = Vec::new();
    for &j in chosen.iter().filter(|&&j| j != main) {
        let Some((_, _, est)) = &estimates[j] else {
            continue;
        };
        let t_j = opts.timing(frames[j].t, h).reference();
        // Camera-at-j coordinates to camera-at-main coordinates.
        let pred = km * track.relative(t_main, t_j).matrix() * kinv;
        let result = match opts.align {
            AlignMode::Gyro => correlation(est, &main_est, &pred).map(|(ncc, _)| (pred, ncc)),
            AlignMode::Ecc(a) => {
                align_homography(est, &main_est, Some(pred), &a).map(|al| (al.h_dst_src, al.ncc))
            }
        };
        match result {
            Ok((hm, ncc)) if ncc >= opts.min_ncc && !degenerate(&hm, w, h) => {
                let (warped, mask) = warp_homography(est, &hm, h, w)?;
                // Pixels the neighbour does not see fall back to the main estimate.
                let mut data = warped.into_data();
                for (i, ok) in mask.iter().enumerate() {
                    if !ok {
                        data[i] = main_est.data()[i];
                    }
                }
                aligned.push((j, hm, Image::new(h, w, 1, data)?));
            }
            Ok((_, ncc)) => warnings.push(format!("frame {j} dropped: alignment correlation {ncc:.3} below {:.3} or degenerate homography", opts.min_ncc)),
            Err(e) => warnings.push(format!("frame {j} dropped: alignment failed ({e})")),
        }
    }
    progress.advance(1);
    // 3. Per-region weights (eq. 9) and the multi-frame solve.
    let nf = frames.len();
    let regions = main_grid.rows * main_grid.cols;
    let mut weights = vec![0f32; regions * nf];
    for r in 0..regions {
        let (row, col) = (r / main_grid.cols, r % main_grid.cols);
        let c = main_grid.centre(row, col);
        let (x0, y0) = ((col * tile) as f64, (row * tile) as f64);
        let (x1, y1) = (
            (((col + 1) * tile).min(w) - 1) as f64,
            (((row + 1) * tile).min(h) - 1) as f64,
        );
        let mut sigmas = Vec::with_capacity(aligned.len());
        for (j, hm, _) in &aligned {
            let inv = hm.try_inverse().unwrap_or_else(Matrix3::identity);
            let inside = [(x0, y0), (x1, y0), (x0, y1), (x1, y1)]
                .iter()
                .all(|&(x, y)| {
                    apply_h(&inv, x, y).is_some_and(|(u, v)| {
                        u >= 0.0 && v >= 0.0 && u <= (w - 1) as f64 && v <= (h - 1) as f64
                    })
                });
            let sigma = match (inside, apply_h(&inv, c.0, c.1)) {
                (true, Some(p)) => Some(blurriness(&render_kernel(
                    track,
                    &opts.timing(frames[*j].t, h),
                    k,
                    p,
                    &opts.kernel,
                )?)),
                _ => None,
            };
            sigmas.push(sigma);
        }
        for ((j, _, _), nu) in aligned.iter().zip(frame_weights(&sigmas)) {
            weights[r * nf + j] = nu as f32;
        }
    }
    // The main frame's data weight: `hl.lambda`, or from its own noise level when that is
    // `None` (each frame's single-frame pass above then estimated its own).
    let lambda = opts.hl.lambda_for(&main_rect)?;
    let luts = opts.hl.luts();
    let planes: Vec<(usize, &[f32])> = aligned.iter().map(|(j, _, img)| (*j, img.data())).collect();
    let multi = run_tiles(&main_rect, &main_grid, &opts.tiling, true, |job, work| {
        let nu = &weights[job.index * nf..][..nf];
        let (rows, cols) = (job.grid.rows, job.grid.cols);
        let mut prior = vec![0f32; rows * cols];
        let mut total = 0.0;
        for &(j, plane) in &planes {
            if nu[j] > 0.0 {
                total += nu[j];
                let win = window(plane, h, w, job.y0, job.x0, rows, cols);
                prior
                    .iter_mut()
                    .zip(&win)
                    .for_each(|(p, v)| *p += nu[j] * v);
            }
        }
        let mu = if total > 0.0 { opts.mu } else { 0.0 };
        deconv::hyper_laplacian(
            job.grid,
            job.window,
            job.otf,
            Some((&prior, mu)),
            lambda,
            &opts.hl,
            &luts,
            work,
        )
    })?;
    progress.advance(1);
    progress.finish();
    let encode = |img: Image<f32>| -> Result<Image<f32>> {
        let mut d = img.into_data();
        to_display(opts.gamma, &mut d);
        Image::new(h, w, 1, d)
    };
    let mut used_frames: Vec<usize> = std::iter::once(main)
        .chain(aligned.iter().map(|a| a.0))
        .collect();
    used_frames.sort_unstable();
    Ok(DeblurResult {
        image: encode(multi)?,
        single: encode(main_est)?,
        kernels: main_grid,
        weights,
        frames: nf,
        used_frames,
        warnings,
    })
}
