//! Exact Euclidean distance transforms (Felzenszwalb and Huttenlocher 2012): the squared
//! distance of every grid point to the nearest *feature* point, computed by one 1-D lower
//! envelope of parabolas per line along each axis in turn; `O(n)` per axis, exact (squared
//! integer distances are held exactly in `f64`).
//!
//! Used by the hand-pose features (paper 05, 2-D) and the onion-peel filling order of video
//! completion (paper 06, 3-D).

use rayon::prelude::*;

use crate::error::{Error, Result};

/// One-dimensional squared-distance transform: `d[q] = min_p w (q - p)^2 + f[p]`, the lower
/// envelope of parabolas rooted at the finite samples of `f` (infinite samples take no part;
/// all infinite gives all infinite). `v` and `z` are scratch buffers.
pub fn dt_1d(f: &[f64], d: &mut [f64], weight: f64, v: &mut Vec<usize>, z: &mut Vec<f64>) {
    v.clear();
    z.clear();
    for (q, &fq) in f.iter().enumerate() {
        if !fq.is_finite() {
            continue;
        }
        let qf = q as f64;
        let mut s = f64::NEG_INFINITY;
        while let Some(&p) = v.last() {
            let pf = p as f64;
            s = ((fq + weight * qf * qf) - (f[p] + weight * pf * pf)) / (2.0 * weight * (qf - pf));
            // z holds the left boundary of each parabola's interval.
            if s <= z[z.len() - 1] {
                v.pop();
                z.pop();
                s = f64::NEG_INFINITY;
            } else {
                break;
            }
        }
        v.push(q);
        z.push(s);
    }
    if v.is_empty() {
        d.fill(f64::INFINITY);
        return;
    }
    let mut k = 0;
    for (q, dq) in d.iter_mut().enumerate() {
        let qf = q as f64;
        while k + 1 < v.len() && z[k + 1] < qf {
            k += 1;
        }
        let p = v[k];
        let dp = qf - p as f64;
        *dq = weight * dp * dp + f[p];
    }
}

/// Squared Euclidean distance from every point of a grid of `shape` (row-major, last axis
/// fastest; 1 to 3 axes) to the nearest point where `feature` is true (0 there). Axis `a`
/// has spacing `sqrt(weights[a])` (`weights` of 1: voxel units). With `border_is_feature`
/// the points just outside the grid count as features (a point on the edge is at distance
/// 1 from them); otherwise the outside is ignored, and a grid without features gives
/// infinity everywhere.
///
/// Errors: `feature.len()` not the product of `shape`, no or more than 3 axes, a zero
/// extent, a weight that is not finite and positive.
pub fn squared_edt(
    feature: &[bool],
    shape: &[usize],
    weights: &[f64],
    border_is_feature: bool,
) -> Result<Vec<f64>> {
    if shape.is_empty() || shape.len() > 3 || weights.len() != shape.len() {
        return Err(Error::invalid(
            "shape",
            format!(
                "1 to 3 axes with one weight each, got shape {shape:?} and {} weights",
                weights.len()
            ),
        ));
    }
    if shape.contains(&0) {
        return Err(Error::Empty("feature"));
    }
    let n: usize = shape.iter().product();
    if feature.len() != n {
        return Err(Error::invalid(
            "feature",
            format!("{} values for a grid of shape {shape:?}", feature.len()),
        ));
    }
    if let Some(w) = weights.iter().find(|w| !(w.is_finite() && **w > 0.0)) {
        return Err(Error::invalid(
            "weights",
            format!("{w} is not finite and positive"),
        ));
    }
    let mut d: Vec<f64> = feature
        .iter()
        .map(|&f| if f { 0.0 } else { f64::INFINITY })
        .collect();
    for axis in 0..shape.len() {
        let len = shape[axis];
        let stride: usize = shape[axis + 1..].iter().product();
        let outer = n / (len * stride);
        let pad = usize::from(border_is_feature);
        // Lines along `axis`, in batches: computed in parallel into their own buffers, then
        // scattered (the batch bounds the extra memory).
        let lines = outer * stride;
        let batch = (1usize << 20).div_ceil(len).max(1);
        for first in (0..lines).step_by(batch) {
            let done: Vec<Vec<f64>> = (first..(first + batch).min(lines))
                .into_par_iter()
                .map_init(
                    || {
                        (
                            vec![0.0; len + 2 * pad],
                            vec![0.0; len + 2 * pad],
                            Vec::new(),
                            Vec::new(),
                        )
                    },
                    |(f, out, v, z), line| {
                        let base = (line / stride) * len * stride + line % stride;
                        if pad == 1 {
                            f[0] = 0.0;
                            f[len + 1] = 0.0;
                        }
                        for i in 0..len {
                            f[i + pad] = d[base + i * stride];
                        }
                        dt_1d(f, out, weights[axis], v, z);
                        out[pad..pad + len].to_vec()
                    },
                )
                .collect();
            for (k, vals) in done.into_iter().enumerate() {
                let line = first + k;
                let base = (line / stride) * len * stride + line % stride;
                for (i, v) in vals.into_iter().enumerate() {
                    d[base + i * stride] = v;
                }
            }
        }
    }
    Ok(d)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn brute(feature: &[bool], shape: [usize; 3], w: [f64; 3], border: bool) -> Vec<f64> {
        let [a, b, c] = shape;
        let mut out = vec![f64::INFINITY; a * b * c];
        for i in 0..a {
            for j in 0..b {
                for k in 0..c {
                    let o = &mut out[(i * b + j) * c + k];
                    for p in 0..a {
                        for q in 0..b {
                            for r in 0..c {
                                if feature[(p * b + q) * c + r] {
                                    let d = w[0] * (i as f64 - p as f64).powi(2)
                                        + w[1] * (j as f64 - q as f64).powi(2)
                                        + w[2] * (k as f64 - r as f64).powi(2);
                                    *o = o.min(d);
                                }
                            }
                        }
                    }
                    if border {
                        let edge = [
                            w[0] * ((i + 1).min(a - i) as f64).powi(2),
                            w[1] * ((j + 1).min(b - j) as f64).powi(2),
                            w[2] * ((k + 1).min(c - k) as f64).powi(2),
                        ];
                        *o = edge.iter().fold(*o, |m, &e| m.min(e));
                    }
                }
            }
        }
        out
    }

    #[test]
    fn matches_brute_force_in_3d() {
        let shape = [5, 7, 6];
        let n = 5 * 7 * 6;
        let feature: Vec<bool> = (0..n).map(|i| (i * 37 + 11) % 23 == 0).collect();
        for (w, border) in [([1.0, 1.0, 1.0], false), ([4.0, 1.0, 2.0], true)] {
            let d = squared_edt(&feature, &shape, &w, border).unwrap();
            let want = brute(&feature, shape, w, border);
            for (i, (a, b)) in d.iter().zip(&want).enumerate() {
                assert!((a - b).abs() < 1e-9, "{i}: {a} vs {b}");
            }
        }
        // No features and no border: infinite everywhere.
        let d = squared_edt(&vec![false; n], &shape, &[1.0; 3], false).unwrap();
        assert!(d.iter().all(|v| v.is_infinite()));
        assert!(squared_edt(&feature, &[5, 7], &[1.0, 1.0], false).is_err());
        assert!(squared_edt(&feature, &shape, &[1.0, 0.0, 1.0], false).is_err());
    }
}
