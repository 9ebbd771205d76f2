//! Filters on [`Volume`]s: separable Gaussian smoothing along x, y and z, as
//! `scipy.ndimage.gaussian_filter` computes it.

use rayon::prelude::*;

use super::{Real, Volume};
use crate::error::{Error, Result};
use crate::filter::{gaussian_kernel, Border};

impl<T: Real> Volume<T> {
    /// Separable Gaussian smoothing with standard deviation `sigma` (voxels, per axis x, y, z;
    /// 0 leaves an axis alone), as `scipy.ndimage.gaussian_filter(arr_zyx, sigma[::-1],
    /// truncate=truncate, mode=...)`: kernel radius `int(truncate * sigma + 0.5)`, sums in f64,
    /// lines in parallel.
    ///
    /// Errors: negative or non-finite `sigma`, `truncate` not > 0.
    pub fn gaussian_filter(&self, sigma: [f64; 3], truncate: f64, border: Border) -> Result<Self> {
        let mut out = self.clone();
        for (axis, &s) in sigma.iter().enumerate() {
            if !(s.is_finite() && s >= 0.0) {
                return Err(Error::invalid(
                    "sigma",
                    format!("must be finite and >= 0, got {s}"),
                ));
            }
            if s == 0.0 {
                continue;
            }
            let k = gaussian_kernel(s, truncate)?;
            out = out.correlate_axis(axis, &k, border);
        }
        Ok(out)
    }

    /// Correlates every line along `axis` with the centred odd kernel `k`.
    fn correlate_axis(&self, axis: usize, k: &[f64], border: Border) -> Self {
        let d = self.dims;
        let n = d[axis];
        let stride = [1, d[0], d[0] * d[1]][axis];
        let r = (k.len() / 2) as isize;
        let src = &self.data;
        // One task per line along `axis`.
        let starts: Vec<usize> = (0..self.data.len())
            .filter(|&i| (i / stride).is_multiple_of(n))
            .collect();
        let lines: Vec<(usize, Vec<T>)> = starts
            .par_iter()
            .map(|&s| {
                let line: Vec<T> = (0..n as isize)
                    .map(|i| {
                        let mut acc = 0.0f64;
                        for (t, &w) in k.iter().enumerate() {
                            let j = i + t as isize - r;
                            let v = match border.map(j, n) {
                                Some(j) => src[s + j * stride].to_f64(),
                                None => border.cval(),
                            };
                            acc += w * v;
                        }
                        T::from_f64(acc)
                    })
                    .collect();
                (s, line)
            })
            .collect();
        let mut out = self.clone();
        for (s, line) in lines {
            for (i, v) in line.into_iter().enumerate() {
                out.data[s + i * stride] = v;
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gaussian_filter_of_a_delta_is_the_kernel_product() {
        let n = 15;
        let mut v = Volume::filled([n, n + 2, n + 4], [1.0; 3], 0.0f32).unwrap();
        v.set(7, 8, 9, 1.0);
        let g = v
            .gaussian_filter([1.0, 2.0, 0.0], 4.0, Border::Reflect)
            .unwrap();
        let (kx, ky) = (
            gaussian_kernel(1.0, 4.0).unwrap(),
            gaussian_kernel(2.0, 4.0).unwrap(),
        );
        for z in 0..n + 4 {
            for y in 0..n + 2 {
                for x in 0..n {
                    let dx = x as isize - 7 + 4;
                    let dy = y as isize - 8 + 8;
                    let want = if z == 9 && (0..9).contains(&dx) && (0..17).contains(&dy) {
                        kx[dx as usize] * ky[dy as usize]
                    } else {
                        0.0
                    };
                    assert!(
                        (g.at(x, y, z) as f64 - want).abs() < 1e-7,
                        "({x}, {y}, {z})"
                    );
                }
            }
        }
        let c = Volume::filled([5, 6, 7], [1.0; 3], 3.0f32).unwrap();
        let gc = c
            .gaussian_filter([1.5, 1.5, 1.5], 4.0, Border::Reflect)
            .unwrap();
        assert!(gc.data().iter().all(|&x| (x - 3.0).abs() < 1e-6));
        assert!(c
            .gaussian_filter([-1.0, 0.0, 0.0], 4.0, Border::Reflect)
            .is_err());
    }
}
