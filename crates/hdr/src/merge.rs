//! The HDR merge of one view (paper eqs. 6-7): per pixel and channel the Khan-weighted mean
//! of the radiance samples, with a defined result where every weight vanishes.

use rayon::prelude::*;
use wscg_math::{Error, Image, Result};

use crate::crf::Crf;
use crate::radiance::{check_times, khan_weight, max_code, ViewSamples};

/// Below this total weight a pixel takes the fallback value.
pub const MIN_WEIGHT_SUM: f32 = 1e-6;

/// One input of the merge: radiance samples (own view, or synthesised and aligned to the
/// reference) with their weights and levels, and the exposure time they were taken with.
#[derive(Clone, Copy, Debug)]
pub struct MergeInput<'a> {
    /// Radiance, weight and level images.
    pub samples: &'a ViewSamples,
    /// Exposure time (orders the fallback).
    pub time: f64,
}

/// A merged HDR image and how many pixels took the fallback.
#[derive(Clone, Debug, PartialEq)]
pub struct Merged {
    /// HDR radiance, `(H, W, C)`.
    pub hdr: Image<f32>,
    /// Pixels where some channel had total weight `< 1e-6`.
    pub fallback_pixels: usize,
}

/// Merges aligned radiance samples (eq. 6): `E = sum_n w_n E_n / sum_n w_n` per channel.
///
/// Where `sum_n w_n < 1e-6` (every sample clipped; the paper leaves this undefined) the pixel
/// takes the radiance of the shortest exposure when the samples are clipped high (mean level
/// `>= 0.5`: a lower bound of the true radiance) and of the longest exposure when they are
/// clipped low, and is counted in `fallback_pixels`. The result is never NaN or infinite for
/// finite inputs.
///
/// Errors: no inputs; inputs of different shapes; non-finite or non-positive times.
pub fn merge(inputs: &[MergeInput]) -> Result<Merged> {
    let first = inputs
        .first()
        .ok_or_else(|| Error::invalid("inputs", "nothing to merge"))?;
    let shape = first.samples.radiance.shape();
    check_times(
        &inputs.iter().map(|i| i.time).collect::<Vec<_>>(),
        inputs.len(),
    )?;
    for (k, i) in inputs.iter().enumerate() {
        let s = i.samples;
        if s.radiance.shape() != shape || s.weight.shape() != shape || s.level.shape() != shape {
            return Err(Error::ShapeMismatch(format!(
                "merge input {k} is not {shape:?} in all of radiance, weight and level"
            )));
        }
    }
    let (short, long) = extreme_times(&inputs.iter().map(|i| i.time).collect::<Vec<_>>());
    merge_with(shape, inputs.len(), short, long, |k, i| {
        let s = inputs[k].samples;
        (s.radiance.data()[i], s.weight.data()[i], s.level.data()[i])
    })
}

/// Eq. 6 with the fallback over `n` inputs whose sample `k` at pixel-channel `i` is
/// `sample(k, i) = (radiance, weight, level)`; `short`, `long` index the shortest and the
/// longest exposure.
fn merge_with(
    (h, w, c): (usize, usize, usize),
    n: usize,
    short: usize,
    long: usize,
    sample: impl Fn(usize, usize) -> (f32, f32, f32) + Sync,
) -> Result<Merged> {
    let mut out = vec![0f32; h * w * c];
    let fallback: usize = out
        .par_chunks_mut(c)
        .enumerate()
        .map(|(p, px)| {
            let mut fell = false;
            for (ch, o) in px.iter_mut().enumerate() {
                let i = p * c + ch;
                let (mut num, mut den, mut lev) = (0f64, 0f64, 0f64);
                for k in 0..n {
                    let (e, wt, lv) = sample(k, i);
                    num += wt as f64 * e as f64;
                    den += wt as f64;
                    lev += lv as f64;
                }
                *o = if den >= MIN_WEIGHT_SUM as f64 {
                    (num / den) as f32
                } else {
                    fell = true;
                    let k = if lev / n as f64 >= 0.5 { short } else { long };
                    sample(k, i).0
                };
            }
            usize::from(fell)
        })
        .sum();
    Ok(Merged {
        hdr: Image::new(h, w, c, out)?,
        fallback_pixels: fallback,
    })
}

/// Indices of the shortest and the longest exposure (the first of equal times).
fn extreme_times(times: &[f64]) -> (usize, usize) {
    let pick = |longest: bool| {
        (0..times.len())
            .reduce(|a, b| {
                let (ta, tb) = (times[a], times[b]);
                if (longest && tb > ta) || (!longest && tb < ta) {
                    b
                } else {
                    a
                }
            })
            .unwrap_or(0)
    };
    (pick(false), pick(true))
}

/// Merges an aligned exposure stack of one view (no matching): the same result as
/// converting every image with [`crate::radiance::to_samples`] and calling [`merge`], bit
/// for bit, computed straight from the codes through per-exposure tables of radiance,
/// weight and level. `crfs`: one response for all images or one per image.
///
/// Errors: no images; shapes differ; wrong number of times or responses; codes beyond a
/// response table.
pub fn merge_stack(images: &[Image<u16>], times: &[f64], crfs: &[Crf]) -> Result<Merged> {
    let first = images
        .first()
        .ok_or_else(|| Error::invalid("images", "nothing to merge"))?;
    check_times(times, images.len())?;
    if crfs.len() != 1 && crfs.len() != images.len() {
        return Err(Error::invalid(
            "crfs",
            format!("give one response or one per image, got {}", crfs.len()),
        ));
    }
    let shape = first.shape();
    let c = shape.2;
    // Per exposure, per code and channel: (radiance, weight, level).
    let mut luts = Vec::with_capacity(images.len());
    for (k, im) in images.iter().enumerate() {
        if im.shape() != shape {
            return Err(Error::ShapeMismatch(format!(
                "image {k} is {:?}, image 0 is {shape:?}",
                im.shape()
            )));
        }
        let crf = &crfs[k.min(crfs.len() - 1)];
        crf.check_image(c, max_code(im))?;
        let zmax = crf.z_max() as f32;
        let inv_dt = (1.0 / times[k]) as f32;
        let lut: Vec<(f32, f32, f32)> = (0..crf.levels())
            .flat_map(|z| {
                (0..c).map(move |ch| {
                    let z16 = z as u16;
                    (
                        crf.inv(z16, ch) * inv_dt,
                        khan_weight(z as f32, zmax),
                        z as f32 / zmax,
                    )
                })
            })
            .collect();
        luts.push(lut);
    }
    let (short, long) = extreme_times(times);
    merge_with(shape, images.len(), short, long, |k, i| {
        luts[k][images[k].data()[i] as usize * c + i % c]
    })
}
