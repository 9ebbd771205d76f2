//! The light-propagation kernel of instant convolution shadows (paper §3: the light of slice
//! `n` "is first attenuated by the opacity of the samples on slice n, and then this outgoing
//! light is convolved with a kernel k(x)"): the light that
//! left slice `n` (attenuated) is convolved with `K` to give the light arriving at slice
//! `n + 1`. Outside the light buffer the light is unoccluded (value 1).
//!
//! The Gaussian kernel has the **exact** discrete variance `2 D ds / h^2` pixels^2 per step, so
//! variances add up to `2 D z` after any depth `z` whatever the slice distance (the semigroup
//! property the paper's slice-distance study relies on). An oblique light shifts the kernel's
//! mean by `ds (l_x, l_y) / l_z`; the fractional part of the shift is realised exactly inside
//! the same variance budget when the budget allows (`var >= f (1 - f)`), otherwise the
//! minimal bilinear spread `f (1 - f)` is used.

use rayon::prelude::*;
use wscg_math::{Error, Result};

/// The kernel family (the paper does not give its kernel; the variance-additive Gaussian is
/// our default, for the semigroup property above).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Kernel {
    /// No blur: hard shadows, equal to shadow rays for a headlight.
    Delta,
    /// Variance-additive Gaussian: variance `2 spread ds` (world units^2) per slice.
    Gaussian {
        /// Diffusion constant `D >= 0` (world units).
        spread: f32,
    },
    /// The cone of directional occlusion shading (Schott et al. 2009): a disk of radius
    /// `ds tan_half` per slice, so the total blur grows with the slice distance.
    Disk {
        /// Tangent of the cone's half angle, `>= 0`.
        tan_half: f32,
    },
}

impl Default for Kernel {
    fn default() -> Self {
        Kernel::Gaussian { spread: 0.5 }
    }
}

impl Kernel {
    /// Errors: negative or non-finite parameter.
    pub fn check(&self) -> Result<()> {
        match *self {
            Kernel::Delta => Ok(()),
            Kernel::Gaussian { spread } if spread.is_finite() && spread >= 0.0 => Ok(()),
            Kernel::Disk { tan_half } if tan_half.is_finite() && tan_half >= 0.0 => Ok(()),
            k => Err(Error::invalid(
                "kernel",
                format!("{k:?}: the spread must be finite and >= 0"),
            )),
        }
    }

    /// Variance per slice in pixels^2 (Gaussian), 0 otherwise.
    pub fn step_variance(&self, ds: f64, pixel: f64) -> f64 {
        match *self {
            Kernel::Gaussian { spread } => 2.0 * spread as f64 * ds / (pixel * pixel),
            _ => 0.0,
        }
    }
}

/// A 1-D discrete kernel: weights at the offsets `first, first + 1, ...`.
#[derive(Clone, Debug, PartialEq)]
pub struct Taps {
    /// Offset of the first weight.
    pub first: isize,
    /// Weights (sum 1).
    pub w: Vec<f32>,
}

impl Taps {
    /// Mean and variance of the weights.
    pub fn moments(&self) -> (f64, f64) {
        let m: f64 = self
            .w
            .iter()
            .enumerate()
            .map(|(i, &w)| w as f64 * (self.first + i as isize) as f64)
            .sum();
        let v: f64 = self
            .w
            .iter()
            .enumerate()
            .map(|(i, &w)| w as f64 * ((self.first + i as isize) as f64 - m).powi(2))
            .sum();
        (m, v)
    }

    /// Largest absolute offset.
    fn reach(&self) -> usize {
        let last = self.first + self.w.len() as isize - 1;
        self.first.unsigned_abs().max(last.unsigned_abs())
    }
}

/// Discrete 1-D kernel with mean `mean` and variance `var` (pixels): three taps when
/// `var <= 1/2`, else a sampled Gaussian whose width is solved so the discrete variance is
/// `var` exactly.
pub fn discrete_gaussian(var: f64, mean: f64) -> Taps {
    let k0 = mean.round();
    let f = mean - k0;
    let base = k0 as isize;
    if var <= 0.5 {
        let var = var.max(f.abs() * (1.0 - f.abs()));
        let wp = 0.5 * (var + f * f + f);
        let wm = 0.5 * (var + f * f - f);
        let w = vec![
            wm.max(0.0) as f32,
            (1.0 - var - f * f) as f32,
            wp.max(0.0) as f32,
        ];
        return Taps { first: base - 1, w };
    }
    let sigma = var.sqrt();
    let r = (3.0 * sigma).ceil() as isize + 1;
    // Weights of a Gaussian of width `s` centred at `c`, and their mean and variance.
    let make = |c: f64, s: f64| -> Vec<f64> {
        let w: Vec<f64> = (-r..=r)
            .map(|k| (-(k as f64 - c).powi(2) / (2.0 * s * s)).exp())
            .collect();
        let z: f64 = w.iter().sum();
        w.into_iter().map(|x| x / z).collect()
    };
    let moments = |w: &[f64]| {
        let m: f64 = w
            .iter()
            .enumerate()
            .map(|(i, x)| x * (i as isize - r) as f64)
            .sum();
        let v = w
            .iter()
            .enumerate()
            .map(|(i, x)| x * ((i as isize - r) as f64 - m).powi(2))
            .sum::<f64>();
        (m, v)
    };
    // Solve for the centre (mean f) and the width (variance var) by alternating a secant
    // step on the centre with a bisection on the width.
    let (mut c, mut s) = (f, sigma);
    for _ in 0..6 {
        let (mut lo, mut hi) = (0.3 * sigma, 1.5 * sigma);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if moments(&make(c, mid)).1 < var {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        s = 0.5 * (lo + hi);
        c += f - moments(&make(c, s)).0;
    }
    let w = make(c, s).into_iter().map(|x| x as f32).collect();
    Taps { first: base - r, w }
}

/// One slice's light kernel, ready to apply.
#[derive(Clone, Debug, PartialEq)]
pub enum StepKernel {
    /// Separable: `x` along rows, `y` along columns.
    Separable {
        /// Horizontal taps.
        x: Taps,
        /// Vertical taps.
        y: Taps,
    },
    /// A 2-D stencil of `(dx, dy, weight)`.
    Stencil(Vec<(isize, isize, f32)>),
}

impl StepKernel {
    /// The kernel of one slice of distance `ds` for pixel size `pixel` (world units) and a
    /// per-slice light shift `shift` in pixels (source offset, `x` right, `y` down).
    pub fn new(kernel: &Kernel, ds: f64, pixel: f64, shift: [f64; 2]) -> Self {
        match *kernel {
            Kernel::Delta | Kernel::Gaussian { .. } => {
                let var = kernel.step_variance(ds, pixel);
                StepKernel::Separable {
                    x: discrete_gaussian(var, shift[0]),
                    y: discrete_gaussian(var, shift[1]),
                }
            }
            Kernel::Disk { tan_half } => {
                let r = ds * tan_half as f64 / pixel;
                let (sx, sy) = (shift[0].round() as isize, shift[1].round() as isize);
                let ri = r.floor() as isize;
                let mut taps = Vec::new();
                for dy in -ri..=ri {
                    for dx in -ri..=ri {
                        if ((dx * dx + dy * dy) as f64) <= r * r {
                            taps.push((dx + sx, dy + sy, 1.0));
                        }
                    }
                }
                if taps.is_empty() {
                    taps.push((sx, sy, 1.0));
                }
                let n = taps.len() as f32;
                taps.iter_mut().for_each(|t| t.2 = 1.0 / n);
                StepKernel::Stencil(taps)
            }
        }
    }

    /// Largest offset in pixels along either axis.
    pub fn reach(&self) -> usize {
        match self {
            StepKernel::Separable { x, y } => x.reach().max(y.reach()),
            StepKernel::Stencil(t) => t
                .iter()
                .map(|&(dx, dy, _)| dx.unsigned_abs().max(dy.unsigned_abs()))
                .max()
                .unwrap_or(0),
        }
    }

    /// Sum of the weights (1 up to rounding).
    pub fn weight_sum(&self) -> f64 {
        match self {
            StepKernel::Separable { x, y } => {
                x.w.iter().map(|&v| v as f64).sum::<f64>()
                    * y.w.iter().map(|&v| v as f64).sum::<f64>()
            }
            StepKernel::Stencil(t) => t.iter().map(|&(_, _, w)| w as f64).sum(),
        }
    }

    /// `dst = K * src` on a `w x h` buffer whose outside is 1 (`tmp` is scratch of the same
    /// size, rows in parallel), computing only the pixels `[x0, x1) x [y0, y1)` of `dst`
    /// (`out = [x0, x1, y0, y1]`); the rest of `dst` is left untouched.
    pub(crate) fn apply_rect(
        &self,
        src: &[f32],
        tmp: &mut [f32],
        dst: &mut [f32],
        w: usize,
        h: usize,
        out: [usize; 4],
    ) {
        let [x0, x1, y0, y1] = out;
        if x0 >= x1 || y0 >= y1 {
            return;
        }
        match self {
            StepKernel::Separable { x, y } => {
                // Rows of the horizontal pass the vertical pass reads.
                let last = y.first + y.w.len() as isize - 1;
                let r0 = (y0 as isize + y.first).clamp(0, h as isize) as usize;
                let r1 =
                    ((y1 as isize - 1 + last).min(h as isize - 1) + 1).max(r0 as isize) as usize;
                tmp[r0 * w..r1 * w]
                    .par_chunks_mut(w)
                    .zip(src[r0 * w..r1 * w].par_chunks(w))
                    .for_each(|(out, row)| convolve_row(row, &mut out[x0..x1], x0, x));
                dst[y0 * w..y1 * w]
                    .par_chunks_mut(w)
                    .enumerate()
                    .for_each(|(k, out)| {
                        let j = y0 + k;
                        let out = &mut out[x0..x1];
                        out.fill(0.0);
                        let mut outside = 0f32;
                        for (t, &wk) in y.w.iter().enumerate() {
                            let r = j as isize + y.first + t as isize;
                            if r < 0 || r >= h as isize {
                                outside += wk;
                                continue;
                            }
                            let row = &tmp[r as usize * w + x0..r as usize * w + x1];
                            for (o, &v) in out.iter_mut().zip(row) {
                                *o += wk * v;
                            }
                        }
                        if outside > 0.0 {
                            out.iter_mut().for_each(|o| *o += outside);
                        }
                    });
            }
            StepKernel::Stencil(taps) => {
                dst[y0 * w..y1 * w]
                    .par_chunks_mut(w)
                    .enumerate()
                    .for_each(|(k, out)| {
                        let j = y0 + k;
                        for (i, o) in out.iter_mut().enumerate().take(x1).skip(x0) {
                            let mut acc = 0f32;
                            for &(dx, dy, wk) in taps {
                                let (x, y) = (i as isize + dx, j as isize + dy);
                                acc += wk
                                    * if x < 0 || y < 0 || x >= w as isize || y >= h as isize {
                                        1.0
                                    } else {
                                        src[y as usize * w + x as usize]
                                    };
                            }
                            *o = acc;
                        }
                    });
            }
        }
    }
}

/// Pixels `x0..x0 + out.len()` of one row of the horizontal pass, border value 1.
fn convolve_row(row: &[f32], out: &mut [f32], x0: usize, t: &Taps) {
    let n = row.len() as isize;
    let len = t.w.len() as isize;
    let edge = |i: isize| -> f32 {
        let mut acc = 0f32;
        for (k, &wk) in t.w.iter().enumerate() {
            let x = i + t.first + k as isize;
            acc += wk
                * if x < 0 || x >= n {
                    1.0
                } else {
                    row[x as usize]
                };
        }
        acc
    };
    // Outputs whose whole window lies in the row, `[k_lo, k_hi)`: accumulated tap by tap over
    // shifted slices (vectorised; the same summation order as a per-pixel dot product).
    let x0i = x0 as isize;
    let k_lo = (-t.first - x0i).clamp(0, out.len() as isize) as usize;
    let k_hi = (n - len - t.first - x0i + 1).clamp(k_lo as isize, out.len() as isize) as usize;
    let inner = &mut out[k_lo..k_hi];
    inner.fill(0.0);
    if !inner.is_empty() {
        let base = x0i + k_lo as isize + t.first;
        for (k, &wk) in t.w.iter().enumerate() {
            let src = &row[(base + k as isize) as usize..];
            for (o, &v) in inner.iter_mut().zip(src) {
                *o += wk * v;
            }
        }
    }
    for k in (0..k_lo).chain(k_hi..out.len()) {
        out[k] = edge((x0 + k) as isize);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tap-major row pass equals the per-pixel dot product with border value 1, bit for
    /// bit, for windows before, inside, beyond and wider than the row.
    #[test]
    fn row_pass_equals_the_per_pixel_dot_product() {
        let row: Vec<f32> = (0..23).map(|i| ((i * 37 % 11) as f32) / 10.0).collect();
        let n = row.len() as isize;
        for (first, len) in [(-1isize, 3usize), (-4, 9), (2, 3), (-30, 5), (-2, 40)] {
            let w: Vec<f32> = (0..len).map(|k| 0.1 + 0.05 * k as f32).collect();
            let t = Taps { first, w };
            for (x0, m) in [(0usize, 23usize), (5, 10), (20, 3), (0, 1)] {
                let mut out = vec![f32::NAN; m];
                convolve_row(&row, &mut out, x0, &t);
                for (k, &o) in out.iter().enumerate() {
                    let mut want = 0f32;
                    for (j, &wk) in t.w.iter().enumerate() {
                        let x = (x0 + k) as isize + first + j as isize;
                        want += wk
                            * if x < 0 || x >= n {
                                1.0
                            } else {
                                row[x as usize]
                            };
                    }
                    assert_eq!(o, want, "first {first} len {len} x0 {x0} k {k}");
                }
            }
        }
    }
}
