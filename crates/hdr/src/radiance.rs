//! Radiance space (paper section 3, numerator of eq. 6): `E = f^-1(Z) / dt`, with Khan's
//! weight of every sample (eq. 7) and its normalised code `Z / z_max`.

use rayon::prelude::*;
use wscg_math::{Error, Image, Result};

pub use crate::crf::check_times;
use crate::crf::Crf;

/// Khan, Akyuz & Reinhard (2006) weight of code `z` (paper eq. 7):
/// `w(Z) = 1 - (2 Z / z_max - 1)^12`; exactly 0 at `0` and `z_max`, close to 1 in between.
#[inline]
pub fn khan_weight(z: f32, z_max: f32) -> f32 {
    let t = 2.0 * z / z_max - 1.0;
    let t2 = t * t;
    let t4 = t2 * t2;
    (1.0 - t4 * t4 * t4).max(0.0)
}

/// One view in radiance space: per pixel and channel the radiance `f^-1(Z) / dt`, the Khan
/// weight `w(Z)` and the normalised code `Z / z_max` (which side a clipped sample is on).
#[derive(Clone, Debug, PartialEq)]
pub struct ViewSamples {
    /// Radiance `E = f^-1(Z) / dt`.
    pub radiance: Image<f32>,
    /// Khan weight `w(Z)`.
    pub weight: Image<f32>,
    /// `Z / z_max` in `[0, 1]`.
    pub level: Image<f32>,
}

/// Weight added to every sample's weight by [`ViewSamples::stacked_weighted`]: small against
/// the Khan weight of any unclipped code, large enough to define pixels voted only from
/// clipped samples.
pub const WEIGHT_FLOOR: f32 = 1e-4;

impl ViewSamples {
    /// The three images as one image of `3 C` channels (radiance, weight, level), the form
    /// patch voting carries them in.
    pub fn stacked(&self) -> Image<f32> {
        let (h, w, c) = self.radiance.shape();
        let mut out = Vec::with_capacity(h * w * 3 * c);
        for i in 0..h * w {
            let s = i * c..(i + 1) * c;
            out.extend_from_slice(&self.radiance.data()[s.clone()]);
            out.extend_from_slice(&self.weight.data()[s.clone()]);
            out.extend_from_slice(&self.level.data()[s]);
        }
        Image::new(h, w, 3 * c, out).expect("shape of a stacked view")
    }

    /// [`ViewSamples::stacked`] with the radiance multiplied by `w + WEIGHT_FLOOR`, so that
    /// averaging (patch voting) gives the weighted mean radiance once
    /// [`ViewSamples::from_stacked_weighted`] divides by the averaged `w + WEIGHT_FLOOR`:
    /// clipped samples (weight 0) then barely enter a synthesised pixel that also receives
    /// valid ones, and a pixel receiving only clipped samples keeps their plain mean.
    pub fn stacked_weighted(&self) -> Image<f32> {
        let mut st = self.stacked();
        let c = self.radiance.shape().2;
        for px in st.data_mut().chunks_exact_mut(3 * c) {
            for k in 0..c {
                px[k] *= px[c + k] + WEIGHT_FLOOR;
            }
        }
        st
    }

    /// The inverse of [`ViewSamples::stacked_weighted`] (after voting or not).
    pub fn from_stacked_weighted(s: &Image<f32>) -> Result<Self> {
        let mut v = Self::from_stacked(s)?;
        for (e, &w) in v.radiance.data_mut().iter_mut().zip(v.weight.data()) {
            *e /= w + WEIGHT_FLOOR;
        }
        Ok(v)
    }

    /// The inverse of [`ViewSamples::stacked`].
    pub fn from_stacked(s: &Image<f32>) -> Result<Self> {
        let (h, w, c3) = s.shape();
        if c3 % 3 != 0 {
            return Err(Error::invalid(
                "stacked",
                format!("needs 3 C channels, got {c3}"),
            ));
        }
        let c = c3 / 3;
        let part = |k: usize| {
            let mut v = Vec::with_capacity(h * w * c);
            for px in s.data().chunks_exact(c3) {
                v.extend_from_slice(&px[k * c..(k + 1) * c]);
            }
            Image::new(h, w, c, v)
        };
        Ok(Self {
            radiance: part(0)?,
            weight: part(1)?,
            level: part(2)?,
        })
    }
}

/// Largest code of an image.
pub fn max_code(img: &Image<u16>) -> u16 {
    img.data().par_iter().copied().max().unwrap_or(0)
}

/// Converts a view of codes to radiance space with its response and exposure time `dt`.
///
/// Errors: `dt` not finite and positive; the response has another channel count or fewer
/// codes than the image uses.
pub fn to_samples(img: &Image<u16>, crf: &Crf, dt: f64) -> Result<ViewSamples> {
    check_times(&[dt], 1)?;
    let (h, w, c) = img.shape();
    crf.check_image(c, max_code(img))?;
    let zmax = crf.z_max() as f32;
    let inv_dt = (1.0 / dt) as f32;
    let n = h * w * c;
    let (mut e, mut wt, mut lv) = (vec![0f32; n], vec![0f32; n], vec![0f32; n]);
    e.par_chunks_mut(c)
        .zip(wt.par_chunks_mut(c))
        .zip(lv.par_chunks_mut(c))
        .zip(img.data().par_chunks(c))
        .for_each(|(((e, wt), lv), z)| {
            for k in 0..c {
                e[k] = crf.inv(z[k], k) * inv_dt;
                wt[k] = khan_weight(z[k] as f32, zmax);
                lv[k] = z[k] as f32 / zmax;
            }
        });
    Ok(ViewSamples {
        radiance: Image::new(h, w, c, e)?,
        weight: Image::new(h, w, c, wt)?,
        level: Image::new(h, w, c, lv)?,
    })
}

/// The radiance image `f^-1(Z) / dt` of a view.
pub fn to_radiance(img: &Image<u16>, crf: &Crf, dt: f64) -> Result<Image<f32>> {
    Ok(to_samples(img, crf, dt)?.radiance)
}

/// Converts a view given as signal levels in `[0, 1]` (unquantised or high-bit-depth
/// floats) to radiance space: `f^-1` interpolated linearly between the codes of `crf`,
/// weights `w(level * z_max)`.
///
/// Errors: levels outside `[0, 1]` or non-finite; channel mismatch; bad `dt`.
pub fn to_samples_float(levels: &Image<f32>, crf: &Crf, dt: f64) -> Result<ViewSamples> {
    check_times(&[dt], 1)?;
    let (h, w, c) = levels.shape();
    crf.check_image(c, 0)?;
    if let Some(v) = levels
        .data()
        .iter()
        .find(|v| !(v.is_finite() && (0.0..=1.0).contains(*v)))
    {
        return Err(Error::invalid(
            "levels",
            format!("must be finite and in [0, 1], got {v}"),
        ));
    }
    let zmax = crf.z_max() as f32;
    let inv_dt = (1.0 / dt) as f32;
    let interp = |v: f32, k: usize| {
        let z = v as f64 * zmax as f64;
        let z0 = (z.floor() as u16).min(crf.z_max().saturating_sub(1));
        let t = (z - z0 as f64) as f32;
        crf.inv(z0, k) * (1.0 - t) + crf.inv(z0 + 1, k) * t
    };
    let n = h * w * c;
    let mut e = vec![0f32; n];
    let mut wt = vec![0f32; n];
    for (i, &v) in levels.data().iter().enumerate() {
        e[i] = interp(v, i % c) * inv_dt;
        wt[i] = khan_weight(v * zmax, zmax);
    }
    Ok(ViewSamples {
        radiance: Image::new(h, w, c, e)?,
        weight: Image::new(h, w, c, wt)?,
        level: levels.clone(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Averaging weighted stacks (what patch voting does) gives the weighted mean radiance:
    /// a clipped sample (weight 0) next to a valid one barely counts, two clipped ones give
    /// their plain mean, and a stack that is not averaged comes back unchanged.
    #[test]
    fn weighted_stacks_average_to_the_weighted_mean_radiance() {
        let img = |v: [f32; 2]| Image::new(1, 2, 1, v.to_vec()).unwrap();
        let s = ViewSamples {
            radiance: img([5.0, 1.0]),
            weight: img([0.0, 0.5]),
            level: img([1.0, 0.4]),
        };
        let st = s.stacked_weighted();
        let back = ViewSamples::from_stacked_weighted(&st).unwrap();
        for (a, b) in back.radiance.data().iter().zip(s.radiance.data()) {
            assert!((a - b).abs() < 1e-6 * b, "{a} vs {b}");
        }
        let mean = |k: usize| (st.data()[k] + st.data()[3 + k]) / 2.0;
        let voted = Image::new(1, 1, 3, (0..3).map(mean).collect()).unwrap();
        let e = ViewSamples::from_stacked_weighted(&voted)
            .unwrap()
            .radiance
            .data()[0];
        let want = (5.0 * WEIGHT_FLOOR + 1.0 * (0.5 + WEIGHT_FLOOR)) / (0.5 + 2.0 * WEIGHT_FLOOR);
        assert!((e - want).abs() < 1e-6 && (e - 1.0).abs() < 1e-3, "{e}");
        let clipped = ViewSamples {
            radiance: img([5.0, 3.0]),
            weight: img([0.0, 0.0]),
            level: img([1.0, 1.0]),
        };
        let st = clipped.stacked_weighted();
        let voted = Image::new(
            1,
            1,
            3,
            (0..3)
                .map(|k| (st.data()[k] + st.data()[3 + k]) / 2.0)
                .collect(),
        )
        .unwrap();
        let e = ViewSamples::from_stacked_weighted(&voted)
            .unwrap()
            .radiance
            .data()[0];
        assert!((e - 4.0).abs() < 1e-5, "{e}");
    }
}
