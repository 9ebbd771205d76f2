//! Piecewise-uniform deblurring (paper section 3, Fig. 3): the frame is cut into regions of
//! `30 x 30` pixels; each region is deconvolved on an extended, edge-tapered window with its own
//! kernel, and the regions are reassembled with linear ramps over a small overlap (a partition
//! of unity, so no seams).

use num_complex::Complex32;
use rayon::prelude::*;
use wscg_math::{Error, Image, Result};

use crate::deconv::{self, HyperLaplacianParams, Work};
use crate::kernel::{Kernel, KernelGrid};
use crate::spectral::{smooth_size, window, Grid};

/// Region layout of [`deblur_piecewise`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Tiling {
    /// Region side in pixels (paper: 30).
    pub tile: usize,
    /// Half-width of the blending ramp across region borders (default 4 px).
    pub overlap: usize,
    /// Smallest margin around a region's core (default 8 px); the margin is at least the
    /// kernel radius + 4 and grows to the next fast FFT size.
    pub min_margin: usize,
}

impl Default for Tiling {
    fn default() -> Self {
        Tiling {
            tile: 30,
            overlap: 4,
            min_margin: 8,
        }
    }
}

impl Tiling {
    /// Errors: a zero tile, an overlap of half the tile or more.
    pub fn validate(&self) -> Result<()> {
        if self.tile == 0 {
            return Err(Error::invalid("tile", "region size must be > 0"));
        }
        if 2 * self.overlap >= self.tile.max(1) && self.overlap > 0 {
            return Err(Error::invalid(
                "overlap",
                format!(
                    "must be < tile / 2 = {}, got {}",
                    self.tile / 2,
                    self.overlap
                ),
            ));
        }
        Ok(())
    }
}

/// Deconvolution applied to every region.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Method {
    /// Wiener filter, `I^ = K^* B^ / (|K|^2 + nsr)` (Table 1 "W").
    Wiener {
        /// Noise-to-signal ratio (> 0).
        nsr: f32,
    },
    /// Richardson-Lucy (Table 1 "RL").
    RichardsonLucy {
        /// Iterations (>= 1).
        iters: usize,
    },
    /// Krishnan-Fergus hyper-Laplacian per region (Table 1 "KS").
    HyperLaplacian(HyperLaplacianParams),
    /// Krishnan-Fergus on the whole frame with the kernel of the frame centre: the uniform-blur
    /// assumption of blind tools such as the paper's Photoshop comparison ("GU").
    GlobalUniform(HyperLaplacianParams),
}

impl Method {
    /// Errors: out-of-range parameters.
    pub fn validate(&self) -> Result<()> {
        match self {
            Method::Wiener { nsr } if !(nsr.is_finite() && *nsr > 0.0) => Err(Error::invalid(
                "nsr",
                format!("must be finite and > 0, got {nsr}"),
            )),
            Method::RichardsonLucy { iters: 0 } => Err(Error::invalid("iters", "must be >= 1")),
            Method::HyperLaplacian(p) | Method::GlobalUniform(p) => p.validate(),
            _ => Ok(()),
        }
    }

    /// Parses `wiener`, `rl`, `krishnan` (or `ks`), `global`, with the parameters tuned on the
    /// development image (Wiener NSR 0.03, 20 Richardson-Lucy iterations; the paper gives
    /// neither for its Table 1 baselines) and the paper's `lambda = 2000` for Krishnan-Fergus
    /// (on gyro-estimated kernels the noise-aware weight loses, BENCHMARKS.md).
    pub fn by_name(name: &str) -> Result<Self> {
        Ok(match name {
            "wiener" | "w" => Method::Wiener { nsr: 0.03 },
            "rl" | "richardson-lucy" | "richardson_lucy" => Method::RichardsonLucy { iters: 20 },
            "krishnan" | "ks" | "hyper-laplacian" => Method::HyperLaplacian(HyperLaplacianParams::paper()),
            "global" | "gu" => Method::GlobalUniform(HyperLaplacianParams::paper()),
            other => {
                return Err(Error::invalid(
                    "method",
                    format!("{other:?} is not a valid method; valid methods are wiener, rl, krishnan, global"),
                ))
            }
        })
    }
}

/// One region's periodic solve: its index, the window's top-left in frame pixels, the planned
/// grid, the edge-tapered window, the kernel's transfer function, thread buffers.
pub(crate) struct TileJob<'a> {
    pub index: usize,
    pub y0: isize,
    pub x0: isize,
    pub grid: &'a Grid,
    pub window: &'a [f32],
    pub otf: &'a [Complex32],
}

/// Checks a single-channel, finite frame.
pub(crate) fn check_frame(frame: &Image<f32>, name: &'static str) -> Result<()> {
    if frame.channels() != 1 {
        return Err(Error::invalid(
            name,
            format!(
                "expected a single-channel (grayscale) image, got {} channels",
                frame.channels()
            ),
        ));
    }
    if frame.height() == 0 || frame.width() == 0 {
        return Err(Error::Empty(name));
    }
    frame.ensure_finite(name)
}

/// Runs `solve` on every region of `grid` and blends the cores (the paper's piecewise uniform
/// deblurring of section 3, Fig. 3, with overlapping regions blended by linear ramps).
pub(crate) fn run_tiles<F>(
    frame: &Image<f32>,
    kernels: &KernelGrid,
    tiling: &Tiling,
    taper: bool,
    solve: F,
) -> Result<Image<f32>>
where
    F: Fn(&TileJob, &mut Work) -> Vec<f32> + Sync,
{
    tiling.validate()?;
    check_frame(frame, "frame")?;
    let (h, w) = (frame.height(), frame.width());
    if kernels.width != w || kernels.height != h || kernels.tile != tiling.tile {
        return Err(Error::ShapeMismatch(format!(
            "kernel grid is for {}x{} frames with {} px regions, frame is {}x{} with {} px regions",
            kernels.width, kernels.height, kernels.tile, w, h, tiling.tile
        )));
    }
    let plane = frame.data();
    let t = tiling.tile;
    let results = (0..kernels.rows * kernels.cols)
        .into_par_iter()
        .map_init(Work::default, |work, index| -> Result<_> {
            let (r, c) = (index / kernels.cols, index % kernels.cols);
            let (cy0, cx0) = (r * t, c * t);
            let (ch, cw) = (((r + 1) * t).min(h) - cy0, ((c + 1) * t).min(w) - cx0);
            let k: &Kernel = kernels.get(r, c);
            let margin = tiling.min_margin.max(k.radius() + 4);
            let (rows, cols) = (smooth_size(ch + 2 * margin), smooth_size(cw + 2 * margin));
            let y0 = cy0 as isize - ((rows - ch) / 2) as isize;
            let x0 = cx0 as isize - ((cols - cw) / 2) as isize;
            let grid = Grid::shared(rows, cols)?;
            let mut win = window(plane, h, w, y0, x0, rows, cols);
            let otf = grid.otf(k, &mut work.scratch);
            if taper {
                grid.edgetaper(&mut win, k, &otf, &mut work.aux, &mut work.scratch);
            }
            let job = TileJob {
                index,
                y0,
                x0,
                grid: &grid,
                window: &win,
                otf: &otf,
            };
            Ok((index, y0, x0, cols, solve(&job, work)))
        })
        .collect::<Result<Vec<_>>>()?;
    // Blend: weight ramps of half-width `overlap` across inner region borders.
    let ov = tiling.overlap as isize;
    let ramp = |p: isize, a: isize, b: isize, n: isize| -> f32 {
        let mut wgt = 1.0f32;
        if a > 0 && ov > 0 && p < a + ov {
            wgt = wgt.min(((p - (a - ov)) as f32 + 0.5) / (2 * ov) as f32);
        }
        if b < n && ov > 0 && p >= b - ov {
            wgt = wgt.min((((b + ov) - p) as f32 - 0.5) / (2 * ov) as f32);
        }
        wgt.clamp(0.0, 1.0)
    };
    let mut acc = vec![0f32; h * w];
    let mut wsum = vec![0f32; h * w];
    for (index, y0, x0, cols, out) in results {
        let (r, c) = (index / kernels.cols, index % kernels.cols);
        let (a_y, a_x) = ((r * t) as isize, (c * t) as isize);
        let (b_y, b_x) = (
            (((r + 1) * t).min(h)) as isize,
            (((c + 1) * t).min(w)) as isize,
        );
        // The last region may be narrower than the ramp: clamp to the frame.
        let ylo = if r == 0 { 0 } else { (a_y - ov).max(0) };
        let yhi = if r + 1 == kernels.rows {
            h as isize
        } else {
            (b_y + ov).min(h as isize)
        };
        let xlo = if c == 0 { 0 } else { (a_x - ov).max(0) };
        let xhi = if c + 1 == kernels.cols {
            w as isize
        } else {
            (b_x + ov).min(w as isize)
        };
        let wxs: Vec<f32> = (xlo..xhi).map(|x| ramp(x, a_x, b_x, w as isize)).collect();
        for y in ylo..yhi {
            let wy = ramp(y, a_y, b_y, h as isize);
            let src = &out[((y - y0) as usize) * cols + (xlo - x0) as usize..][..wxs.len()];
            let row = y as usize * w + xlo as usize..y as usize * w + xhi as usize;
            for (((a, s), &wx), &v) in acc[row.clone()]
                .iter_mut()
                .zip(&mut wsum[row])
                .zip(&wxs)
                .zip(src)
            {
                *a += wy * wx * v;
                *s += wy * wx;
            }
        }
    }
    acc.iter_mut()
        .zip(&wsum)
        .for_each(|(a, s)| *a /= s.max(1e-12));
    // Iterative methods stop early on a cancellation request.
    wscg_math::cancel::check()?;
    Image::new(h, w, 1, acc)
}

/// Deblurs a linear-intensity grayscale frame region by region with the kernels of `kernels`
/// (paper section 4, Fig. 3). The frame should hold linear irradiance (see
/// [`crate::camera::Gamma`]); values are not clipped.
///
/// Errors: a multi-channel, empty or non-finite frame, a kernel grid for another frame size or
/// region size, invalid method parameters.
pub fn deblur_piecewise(
    frame: &Image<f32>,
    kernels: &KernelGrid,
    method: &Method,
    tiling: &Tiling,
) -> Result<Image<f32>> {
    method.validate()?;
    match *method {
        Method::Wiener { nsr } => run_tiles(frame, kernels, tiling, true, |j, w| {
            deconv::wiener(j.grid, j.window, j.otf, nsr, w)
        }),
        Method::RichardsonLucy { iters } => run_tiles(frame, kernels, tiling, true, |j, w| {
            deconv::richardson_lucy(j.grid, j.window, j.otf, iters, w)
        }),
        Method::HyperLaplacian(p) => {
            check_frame(frame, "frame")?;
            // One data weight for the whole frame: the noise is estimated on all of it.
            let lambda = p.lambda_for(frame)?;
            let luts = p.luts();
            run_tiles(frame, kernels, tiling, true, |j, w| {
                deconv::hyper_laplacian(j.grid, j.window, j.otf, None, lambda, &p, &luts, w)
            })
        }
        Method::GlobalUniform(p) => {
            check_frame(frame, "frame")?;
            let (cx, cy) = (frame.width() as f64 / 2.0, frame.height() as f64 / 2.0);
            let (r, c) = (
                ((cy / kernels.tile as f64) as usize).min(kernels.rows - 1),
                ((cx / kernels.tile as f64) as usize).min(kernels.cols - 1),
            );
            deconv_hl(frame, kernels.get(r, c), &p)
        }
    }
}

/// A one-region layout covering the whole frame with one kernel.
fn whole(frame: &Image<f32>, k: &Kernel) -> Result<(KernelGrid, Tiling)> {
    check_frame(frame, "image")?;
    let tile = frame.width().max(frame.height());
    let tiling = Tiling {
        tile,
        overlap: 0,
        min_margin: 8,
    };
    Ok((
        KernelGrid::uniform(k.clone(), frame.width(), frame.height(), tile)?,
        tiling,
    ))
}

/// Krishnan-Fergus deconvolution of a whole linear-intensity image with one uniform kernel
/// (paper eqs. 7-8): mirrored margin of the kernel radius + 4, edge taper, then the
/// half-quadratic continuation of [`HyperLaplacianParams`].
///
/// Errors: as [`deblur_piecewise`].
pub fn deconv_hl(image: &Image<f32>, k: &Kernel, p: &HyperLaplacianParams) -> Result<Image<f32>> {
    p.validate()?;
    let (grid, tiling) = whole(image, k)?;
    let lambda = p.lambda_for(image)?;
    let luts = p.luts();
    run_tiles(image, &grid, &tiling, true, |j, w| {
        deconv::hyper_laplacian(j.grid, j.window, j.otf, None, lambda, p, &luts, w)
    })
}

/// Multi-frame Krishnan-Fergus (paper eq. 9) on a whole image: the data term of `image` with
/// kernel `k`, the hyper-Laplacian prior, and `mu/2 ||I - prior||^2` where `prior` is the
/// weighted mean `sum_j nu_j I_j` of the aligned estimates of the other frames.
///
/// Errors: as [`deconv_hl`]; a prior of another shape; `mu < 0` or non-finite.
pub fn deconv_hl_multi(
    image: &Image<f32>,
    k: &Kernel,
    prior: &Image<f32>,
    mu: f32,
    p: &HyperLaplacianParams,
) -> Result<Image<f32>> {
    p.validate()?;
    check_frame(prior, "prior")?;
    image.ensure_same_shape(prior)?;
    if !(mu.is_finite() && mu >= 0.0) {
        return Err(Error::invalid(
            "mu",
            format!("must be finite and >= 0, got {mu}"),
        ));
    }
    let (grid, tiling) = whole(image, k)?;
    let lambda = p.lambda_for(image)?;
    let luts = p.luts();
    let (h, w) = (image.height(), image.width());
    run_tiles(image, &grid, &tiling, true, |j, wk| {
        let pw = window(prior.data(), h, w, j.y0, j.x0, j.grid.rows, j.grid.cols);
        deconv::hyper_laplacian(
            j.grid,
            j.window,
            j.otf,
            Some((&pw, mu)),
            lambda,
            p,
            &luts,
            wk,
        )
    })
}

/// Wiener deconvolution of a whole image with one kernel (mirrored margin, edge taper).
pub fn wiener(image: &Image<f32>, k: &Kernel, nsr: f32) -> Result<Image<f32>> {
    let (grid, tiling) = whole(image, k)?;
    deblur_piecewise(image, &grid, &Method::Wiener { nsr }, &tiling)
}

/// Richardson-Lucy deconvolution of a whole image with one kernel (mirrored margin, edge taper).
pub fn richardson_lucy(image: &Image<f32>, k: &Kernel, iters: usize) -> Result<Image<f32>> {
    let (grid, tiling) = whole(image, k)?;
    deblur_piecewise(image, &grid, &Method::RichardsonLucy { iters }, &tiling)
}

/// Periodic convolution `k * I` of a whole image (mirrored margin): the forward model the
/// solvers invert.
pub fn convolve(image: &Image<f32>, k: &Kernel) -> Result<Image<f32>> {
    let (grid, tiling) = whole(image, k)?;
    convolve_piecewise(image, &grid, &tiling)
}

/// Region-wise convolution with the kernels of `kernels`, blended as [`deblur_piecewise`]
/// blends: the piecewise-uniform forward model of eq. 1 (model-consistency check).
pub fn convolve_piecewise(
    image: &Image<f32>,
    kernels: &KernelGrid,
    tiling: &Tiling,
) -> Result<Image<f32>> {
    run_tiles(image, kernels, tiling, false, |j, w| {
        let mut out = vec![0f32; j.grid.len()];
        j.grid.convolve(
            j.window,
            j.otf,
            false,
            &mut out,
            &mut w.spec,
            &mut w.scratch,
        );
        out
    })
}
