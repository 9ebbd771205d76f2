//! Image sampling and warps: bilinear and bicubic interpolation, homography warps and the
//! gyro-driven rolling-shutter rectification of Karpenko et al. 2011 (paper section 5).

use nalgebra::{Matrix3, Vector3};
use rayon::prelude::*;
use wscg_math::{Error, Image, Result};

use crate::camera::{Intrinsics, Timing};
use crate::gyro::GyroTrack;
use crate::tiling::check_frame;

/// Bilinear sample of a `h x w` plane at `(x, y)` (pixel centres at integers), `None` outside
/// `[0, w-1] x [0, h-1]`.
#[inline]
pub(crate) fn bilinear(plane: &[f32], h: usize, w: usize, x: f64, y: f64) -> Option<f32> {
    if !(x >= 0.0 && y >= 0.0 && x <= (w - 1) as f64 && y <= (h - 1) as f64) {
        return None;
    }
    let (x0, y0) = (x.floor() as usize, y.floor() as usize);
    let (x1, y1) = ((x0 + 1).min(w - 1), (y0 + 1).min(h - 1));
    let (fx, fy) = ((x - x0 as f64) as f32, (y - y0 as f64) as f32);
    let top = plane[y0 * w + x0] * (1.0 - fx) + plane[y0 * w + x1] * fx;
    let bot = plane[y1 * w + x0] * (1.0 - fx) + plane[y1 * w + x1] * fx;
    Some(top * (1.0 - fy) + bot * fy)
}

/// Keys cubic weights (`a = -1/2`) of the four taps around fraction `t`.
#[inline]
fn cubic_weights(t: f64) -> [f64; 4] {
    let a = -0.5;
    let w = |d: f64| {
        let d = d.abs();
        if d <= 1.0 {
            (a + 2.0) * d * d * d - (a + 3.0) * d * d + 1.0
        } else if d < 2.0 {
            a * d * d * d - 5.0 * a * d * d + 8.0 * a * d - 4.0 * a
        } else {
            0.0
        }
    };
    [w(1.0 + t), w(t), w(1.0 - t), w(2.0 - t)]
}

/// Bicubic (Keys) sample at `(x, y)`, borders replicated.
#[inline]
pub(crate) fn bicubic(plane: &[f32], h: usize, w: usize, x: f64, y: f64) -> f32 {
    let (xf, yf) = (x.floor(), y.floor());
    let (wx, wy) = (cubic_weights(x - xf), cubic_weights(y - yf));
    let (xi, yi) = (xf as isize, yf as isize);
    let mut s = 0.0;
    for (m, wyv) in wy.iter().enumerate() {
        let row = (yi - 1 + m as isize).clamp(0, h as isize - 1) as usize * w;
        let mut r = 0.0;
        for (n, wxv) in wx.iter().enumerate() {
            let c = (xi - 1 + n as isize).clamp(0, w as isize - 1) as usize;
            r += wxv * plane[row + c] as f64;
        }
        s += wyv * r;
    }
    s as f32
}

/// Applies a homography to a pixel; `None` at infinity.
#[inline]
pub fn apply_h(hm: &Matrix3<f64>, x: f64, y: f64) -> Option<(f64, f64)> {
    let p = hm * Vector3::new(x, y, 1.0);
    (p.z.abs() > 1e-12).then(|| (p.x / p.z, p.y / p.z))
}

/// Warps `src` into a `height x width` frame with the homography `h_dst_src` (source pixels to
/// destination pixels): `dst(p) = src(H^-1 p)`, bilinear. Returns the image and the mask of
/// pixels whose source lies inside `src` (outside pixels are 0).
///
/// Errors: a singular homography, a multi-channel or empty source.
pub fn warp_homography(
    src: &Image<f32>,
    h_dst_src: &Matrix3<f64>,
    height: usize,
    width: usize,
) -> Result<(Image<f32>, Vec<bool>)> {
    check_frame(src, "src")?;
    let inv = h_dst_src
        .try_inverse()
        .ok_or_else(|| Error::invalid("homography", "is singular"))?;
    let (sh, sw) = (src.height(), src.width());
    let plane = src.data();
    let mut out = vec![0f32; height * width];
    let mut mask = vec![false; height * width];
    out.par_chunks_mut(width)
        .zip(mask.par_chunks_mut(width))
        .enumerate()
        .for_each(|(y, (row, m))| {
            for x in 0..width {
                if let Some(v) = apply_h(&inv, x as f64, y as f64)
                    .and_then(|(sx, sy)| bilinear(plane, sh, sw, sx, sy))
                {
                    row[x] = v;
                    m[x] = true;
                }
            }
        });
    Ok((Image::new(height, width, 1, out)?, mask))
}

/// Rolling-shutter rectification (Karpenko et al. 2011, paper section 5): warps a frame to a
/// virtual global shutter at the opening of its middle row. Output pixel `p` samples the frame
/// at `q = pi(K R(t(y))^T R(t_ref) K^-1 p)` where `y` is found by three fixed-point steps
/// `y <- q_y` (the row of `q` decides its time, eq. 6). Pixels mapping outside are replicated
/// from the border.
///
/// Errors: invalid intrinsics or timing, gyroscope samples not covering the frame's readout,
/// a frame height different from `timing.height`.
pub fn rectify_rolling_shutter(
    frame: &Image<f32>,
    track: &GyroTrack,
    timing: &Timing,
    k: &Intrinsics,
) -> Result<Image<f32>> {
    check_frame(frame, "frame")?;
    timing.validate()?;
    k.validate()?;
    let (h, w) = (frame.height(), frame.width());
    if timing.height != h {
        return Err(Error::ShapeMismatch(format!(
            "timing.height = {} but the frame has {h} rows",
            timing.height
        )));
    }
    if timing.t_readout == 0.0 {
        return Ok(frame.clone());
    }
    track.ensure_covers(timing.open(0.0), timing.open((h - 1) as f64))?;
    let t_ref = timing.reference();
    let (km, kinv) = (
        k.matrix(),
        k.matrix()
            .try_inverse()
            .ok_or_else(|| Error::invalid("f", "singular intrinsics"))?,
    );
    // Homographies of every row time, interpolated linearly for fractional rows.
    let rows: Vec<Matrix3<f64>> = (0..h)
        .map(|y| km * track.relative(timing.open(y as f64), t_ref).matrix() * kinv)
        .collect();
    let at = |y: f64| -> Matrix3<f64> {
        let yc = y.clamp(0.0, (h - 1) as f64);
        let y0 = yc.floor() as usize;
        let y1 = (y0 + 1).min(h - 1);
        let f = yc - y0 as f64;
        rows[y0] * (1.0 - f) + rows[y1] * f
    };
    let plane = frame.data();
    let mut out = vec![0f32; h * w];
    out.par_chunks_mut(w).enumerate().for_each(|(py, row)| {
        for (px, o) in row.iter_mut().enumerate() {
            let (mut qx, mut qy) = (px as f64, py as f64);
            for _ in 0..3 {
                if let Some(q) = apply_h(&at(qy), px as f64, py as f64) {
                    (qx, qy) = q;
                }
            }
            let (cx, cy) = (qx.clamp(0.0, (w - 1) as f64), qy.clamp(0.0, (h - 1) as f64));
            *o = bilinear(plane, h, w, cx, cy).unwrap_or(0.0);
        }
    });
    Image::new(h, w, 1, out)
}
