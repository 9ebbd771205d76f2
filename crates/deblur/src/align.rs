//! Homography alignment of the single-frame estimates (paper section 5). The paper matches
//! SURF features with RANSAC; here the gyroscope predicts `K R K^-1` and the enhanced
//! correlation coefficient (ECC) maximisation of Evangelidis & Psarakis 2008 refines it on a
//! three-level pyramid. A frame whose final correlation is below a threshold, or whose
//! homography is degenerate, fails alignment and is dropped by the multi-frame solver.

use nalgebra::{Matrix3, SMatrix, SVector};
use rayon::prelude::*;
use wscg_math::{Error, Image, Result};

use crate::tiling::check_frame;
use crate::warp::{apply_h, bilinear};

wscg_math::params! {
    /// Options of [`align_homography`].
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct AlignParams {
        /// Pyramid levels (1 = full resolution only; default 3).
        pub levels: usize,
        /// ECC iterations per level, coarsest first; the last value repeats (default 30, 15, 5).
        pub iterations: [usize; 3],
        /// Stop a level when the parameter update is below this (default 1e-5).
        pub eps: f64,
    }
}

impl Default for AlignParams {
    fn default() -> Self {
        AlignParams {
            levels: 3,
            iterations: [30, 15, 5],
            eps: 1e-5,
        }
    }
}

impl AlignParams {
    /// Errors: `levels == 0`, a negative or non-finite `eps` (zero iterations at a level are
    /// allowed: that level keeps its starting homography).
    pub fn validate(&self) -> Result<()> {
        if self.levels == 0 {
            return Err(Error::invalid("levels", "must be >= 1"));
        }
        if !(self.eps.is_finite() && self.eps >= 0.0) {
            return Err(Error::invalid(
                "eps",
                format!("must be finite and >= 0, got {}", self.eps),
            ));
        }
        Ok(())
    }
}

/// Result of [`align_homography`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Alignment {
    /// Homography from source pixels to destination pixels.
    pub h_dst_src: Matrix3<f64>,
    /// Correlation coefficient (ECC) of the aligned images over their overlap, in `[-1, 1]`.
    pub ncc: f64,
    /// Fraction of destination pixels whose source lies inside the source image.
    pub overlap: f64,
}

struct Level {
    h: usize,
    w: usize,
    img: Vec<f32>,
}

fn downsample(l: &Level) -> Level {
    let (h, w) = (l.h / 2, l.w / 2);
    let mut img = vec![0f32; h * w];
    for y in 0..h {
        for x in 0..w {
            let i = 2 * y * l.w + 2 * x;
            img[y * w + x] = 0.25 * (l.img[i] + l.img[i + 1] + l.img[i + l.w] + l.img[i + l.w + 1]);
        }
    }
    Level { h, w, img }
}

fn gradients(l: &Level) -> (Vec<f32>, Vec<f32>) {
    let (h, w) = (l.h, l.w);
    let mut gx = vec![0f32; h * w];
    let mut gy = vec![0f32; h * w];
    for y in 0..h {
        for x in 0..w {
            let (xl, xr) = (x.saturating_sub(1), (x + 1).min(w - 1));
            let (yu, yd) = (y.saturating_sub(1), (y + 1).min(h - 1));
            gx[y * w + x] = (l.img[y * w + xr] - l.img[y * w + xl]) / (xr - xl).max(1) as f32;
            gy[y * w + x] = (l.img[yd * w + x] - l.img[yu * w + x]) / (yd - yu).max(1) as f32;
        }
    }
    (gx, gy)
}

/// Homography with parameters `p`: `[[1+p0, p2, p4], [p1, 1+p3, p5], [p6, p7, 1]]`.
fn to_matrix(p: &SVector<f64, 8>) -> Matrix3<f64> {
    Matrix3::new(
        1.0 + p[0],
        p[2],
        p[4],
        p[1],
        1.0 + p[3],
        p[5],
        p[6],
        p[7],
        1.0,
    )
}

fn from_matrix(m: &Matrix3<f64>) -> SVector<f64, 8> {
    let m = m / m[(2, 2)];
    SVector::<f64, 8>::from_column_slice(&[
        m[(0, 0)] - 1.0,
        m[(1, 0)],
        m[(0, 1)],
        m[(1, 1)] - 1.0,
        m[(0, 2)],
        m[(1, 2)],
        m[(2, 0)],
        m[(2, 1)],
    ])
}

/// Per-pixel sums of one ECC iteration.
#[derive(Clone, Copy)]
struct Sums {
    n: f64,
    si: f64,
    st: f64,
    sii: f64,
    stt: f64,
    sit: f64,
    hess: SMatrix<f64, 8, 8>,
    gi: SVector<f64, 8>,
    gt: SVector<f64, 8>,
    g1: SVector<f64, 8>,
}

impl Sums {
    fn zero() -> Self {
        Sums {
            n: 0.0,
            si: 0.0,
            st: 0.0,
            sii: 0.0,
            stt: 0.0,
            sit: 0.0,
            hess: SMatrix::zeros(),
            gi: SVector::zeros(),
            gt: SVector::zeros(),
            g1: SVector::zeros(),
        }
    }
    fn add(mut self, o: Sums) -> Self {
        self.n += o.n;
        self.si += o.si;
        self.st += o.st;
        self.sii += o.sii;
        self.stt += o.stt;
        self.sit += o.sit;
        self.hess += o.hess;
        self.gi += o.gi;
        self.gt += o.gt;
        self.g1 += o.g1;
        self
    }
}

/// Accumulates the ECC sums of `template` against `image` warped by `warp` (template pixels
/// to image pixels); `stride` subsamples the template.
fn accumulate(
    t: &Level,
    img: &Level,
    grads: &(Vec<f32>, Vec<f32>),
    warp: &Matrix3<f64>,
    stride: usize,
) -> Sums {
    (0..t.h)
        .into_par_iter()
        .step_by(stride)
        .map(|y| {
            let mut s = Sums::zero();
            for x in (0..t.w).step_by(stride) {
                let (xf, yf) = (x as f64, y as f64);
                let q = warp * nalgebra::Vector3::new(xf, yf, 1.0);
                if q.z.abs() < 1e-12 {
                    continue;
                }
                let (u, v) = (q.x / q.z, q.y / q.z);
                let Some(iv) = bilinear(&img.img, img.h, img.w, u, v) else {
                    continue;
                };
                let gx = bilinear(&grads.0, img.h, img.w, u, v).unwrap_or(0.0) as f64;
                let gy = bilinear(&grads.1, img.h, img.w, u, v).unwrap_or(0.0) as f64;
                let d = q.z;
                let jx = [
                    xf / d,
                    0.0,
                    yf / d,
                    0.0,
                    1.0 / d,
                    0.0,
                    -xf * u / d,
                    -yf * u / d,
                ];
                let jy = [
                    0.0,
                    xf / d,
                    0.0,
                    yf / d,
                    0.0,
                    1.0 / d,
                    -xf * v / d,
                    -yf * v / d,
                ];
                let g = SVector::<f64, 8>::from_fn(|k, _| gx * jx[k] + gy * jy[k]);
                let (iv, tv) = (iv as f64, t.img[y * t.w + x] as f64);
                s.n += 1.0;
                s.si += iv;
                s.st += tv;
                s.sii += iv * iv;
                s.stt += tv * tv;
                s.sit += iv * tv;
                s.hess += g * g.transpose();
                s.gi += g * iv;
                s.gt += g * tv;
                s.g1 += g;
            }
            s
        })
        .collect::<Vec<_>>()
        .into_iter()
        // Rows are added in order: the sums do not depend on the thread count.
        .fold(Sums::zero(), Sums::add)
}

/// ECC on one level from `warp` (template to image); returns the refined warp and the
/// final correlation and overlap.
fn ecc_level(
    t: &Level,
    img: &Level,
    mut warp: Matrix3<f64>,
    iters: usize,
    eps: f64,
) -> Result<(Matrix3<f64>, f64, f64)> {
    let grads = gradients(img);
    let stride = if t.h * t.w > 200_000 { 2 } else { 1 };
    let total = ((t.h.div_ceil(stride)) * (t.w.div_ceil(stride))) as f64;
    for _ in 0..iters {
        wscg_math::cancel::check()?;
        let s = accumulate(t, img, &grads, &warp, stride);
        if s.n < 64.0 {
            return Err(Error::Numerical(
                "ECC alignment: the images do not overlap".into(),
            ));
        }
        // Zero-mean projections: sum g (i - mean_i) = gi - g1 mean_i, likewise for t.
        let (mi, mt) = (s.si / s.n, s.st / s.n);
        let ii = s.sii - s.n * mi * mi;
        let it = s.sit - s.n * mi * mt;
        let gi = s.gi - s.g1 * mi;
        let gt = s.gt - s.g1 * mt;
        let hinv = s.hess.try_inverse().ok_or_else(|| {
            Error::Numerical("ECC alignment: singular Hessian (no texture)".into())
        })?;
        let hgi = hinv * gi;
        let lambda_n = ii - gi.dot(&hgi);
        let lambda_d = it - gt.dot(&hgi);
        if lambda_d <= 0.0 {
            return Err(Error::Numerical(
                "ECC alignment: the images are uncorrelated".into(),
            ));
        }
        let lambda = lambda_n / lambda_d;
        // error = lambda t - i (zero-mean); its projection on the Jacobian.
        let ge = gt * lambda - gi;
        let dp = hinv * ge;
        let p = from_matrix(&warp) + dp;
        warp = to_matrix(&p);
        if dp.norm() < eps {
            break;
        }
    }
    let s = accumulate(t, img, &grads, &warp, stride);
    let (mi, mt) = (s.si / s.n.max(1.0), s.st / s.n.max(1.0));
    let ii = s.sii - s.n * mi * mi;
    let tt = s.stt - s.n * mt * mt;
    let it = s.sit - s.n * mi * mt;
    let ncc = if ii > 0.0 && tt > 0.0 {
        it / (ii * tt).sqrt()
    } else {
        0.0
    };
    Ok((warp, ncc, s.n / total))
}

/// Aligns `src` to `dst`: returns the homography taking `src` pixels to `dst` pixels that
/// maximises the ECC of `dst` and the warped `src`, starting from `init` (identity if `None`),
/// coarse to fine.
///
/// Errors: multi-channel, empty or non-finite images; a singular initial homography; images
/// that do not overlap or carry no texture.
pub fn align_homography(
    src: &Image<f32>,
    dst: &Image<f32>,
    init: Option<Matrix3<f64>>,
    opts: &AlignParams,
) -> Result<Alignment> {
    opts.validate()?;
    check_frame(src, "src")?;
    check_frame(dst, "dst")?;
    let init = init.unwrap_or_else(Matrix3::identity);
    // ECC estimates the warp from dst (template) pixels to src (image) pixels.
    let mut warp = init
        .try_inverse()
        .ok_or_else(|| Error::invalid("init", "homography is singular"))?;
    let mut tp = vec![Level {
        h: dst.height(),
        w: dst.width(),
        img: dst.data().to_vec(),
    }];
    let mut ip = vec![Level {
        h: src.height(),
        w: src.width(),
        img: src.data().to_vec(),
    }];
    for _ in 1..opts.levels {
        let (t, i) = (tp.last().unwrap(), ip.last().unwrap());
        if t.h.min(t.w).min(i.h).min(i.w) < 32 {
            break;
        }
        let (t, i) = (downsample(t), downsample(i));
        tp.push(t);
        ip.push(i);
    }
    let nl = tp.len();
    // Level l coordinates: x_l = (x + 1/2) / 2^l - 1/2.
    let scale = |l: usize| {
        let s = 0.5f64.powi(l as i32);
        Matrix3::new(s, 0.0, 0.5 * s - 0.5, 0.0, s, 0.5 * s - 0.5, 0.0, 0.0, 1.0)
    };
    let mut result = (warp, 0.0, 0.0);
    for (step, l) in (0..nl).rev().enumerate() {
        let s = scale(l);
        let sinv = s.try_inverse().unwrap_or_else(Matrix3::identity);
        let level_warp = s * warp * sinv;
        let iters = opts.iterations[step.min(2)];
        let (w, ncc, ov) = ecc_level(&tp[l], &ip[l], level_warp, iters, opts.eps)?;
        warp = sinv * w * s;
        result = (warp, ncc, ov);
    }
    let h_dst_src = result
        .0
        .try_inverse()
        .ok_or_else(|| Error::Numerical("ECC alignment: degenerate homography".into()))?;
    Ok(Alignment {
        h_dst_src: h_dst_src / h_dst_src[(2, 2)],
        ncc: result.1,
        overlap: result.2,
    })
}

/// `true` when a homography is far from a plausible hand-shake motion (near-singular,
/// mirrored, or strongly projective within the frame).
pub fn degenerate(hm: &Matrix3<f64>, width: usize, height: usize) -> bool {
    let m = hm / hm[(2, 2)];
    let det = m.fixed_view::<2, 2>(0, 0).determinant();
    if !(0.2..5.0).contains(&det) {
        return true;
    }
    let corners = [
        (0.0, 0.0),
        (width as f64, 0.0),
        (0.0, height as f64),
        (width as f64, height as f64),
    ];
    corners.iter().any(|&(x, y)| {
        let d = m[(2, 0)] * x + m[(2, 1)] * y + 1.0;
        !(0.5..=2.0).contains(&d) || apply_h(&m, x, y).is_none()
    })
}

/// Correlation coefficient of `dst` and `src` warped by `h_dst_src` over their overlap, and
/// the overlap as a fraction of `dst`'s pixels (every second pixel on large images).
pub fn correlation(
    src: &Image<f32>,
    dst: &Image<f32>,
    h_dst_src: &Matrix3<f64>,
) -> Result<(f64, f64)> {
    check_frame(src, "src")?;
    check_frame(dst, "dst")?;
    let warp = h_dst_src
        .try_inverse()
        .ok_or_else(|| Error::invalid("homography", "is singular"))?;
    let t = Level {
        h: dst.height(),
        w: dst.width(),
        img: dst.data().to_vec(),
    };
    let i = Level {
        h: src.height(),
        w: src.width(),
        img: src.data().to_vec(),
    };
    let (_, ncc, ov) = ecc_level(&t, &i, warp, 0, 0.0)?;
    Ok((ncc, ov))
}
