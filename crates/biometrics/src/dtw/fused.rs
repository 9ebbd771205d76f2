//! Channel-fused DTW: the recursion of eq. 5 run on `LANES` channels of one pair of samples at
//! once. The channels of a gait sample share their length (one cycle), so their dynamic
//! programmes have the same shape; interleaving them turns the serial dependency of each
//! programme (every cell waits for its left neighbour) into independent SIMD lanes. Results
//! are identical to the per-channel recursion.

use super::core::{fmin, LocalCost};

/// Channels processed together.
pub const LANES: usize = 8;

type Lane = [f64; LANES];

/// A sample stored time-major with its channels interleaved in groups of [`LANES`] (missing
/// lanes of the last group are zero in every sample, so they add nothing).
#[derive(Clone, Debug)]
pub struct Interleaved {
    len: usize,
    channels: usize,
    groups: Vec<Vec<Lane>>,
}

impl Interleaved {
    /// The interleaved copy of `sample`, or `None` when its channels differ in length (or it
    /// has none).
    pub fn new(sample: &[Vec<f64>]) -> Option<Self> {
        let len = sample.first()?.len();
        if len == 0 || sample.iter().any(|c| c.len() != len) {
            return None;
        }
        let groups = sample
            .chunks(LANES)
            .map(|g| {
                (0..len)
                    .map(|t| std::array::from_fn(|l| g.get(l).map_or(0.0, |c| c[t])))
                    .collect()
            })
            .collect();
        Some(Self {
            len,
            channels: sample.len(),
            groups,
        })
    }

    /// Number of channels.
    pub fn channels(&self) -> usize {
        self.channels
    }

    /// Number of samples per channel.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the sample is empty (never, for a constructed value).
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}

/// One group's full-grid recursion; writes the `LANES` distances into `out`.
#[inline(always)]
fn group<const SQ: bool>(a: &[Lane], b: &[Lane], scratch: &mut Vec<Lane>, out: &mut Lane) {
    let m = b.len();
    scratch.clear();
    scratch.resize(2 * (m + 1), [f64::INFINITY; LANES]);
    let (prev, cur) = scratch.split_at_mut(m + 1);
    let (mut prev, mut cur) = (prev, cur);
    prev[0] = [0.0; LANES];
    for ai in a {
        cur[0] = [f64::INFINITY; LANES];
        let mut left = [f64::INFINITY; LANES];
        let mut diag = prev[0];
        for j in 1..=m {
            let up = prev[j];
            let bj = &b[j - 1];
            let mut v = [0.0; LANES];
            for l in 0..LANES {
                let d = ai[l] - bj[l];
                let c = if SQ { d * d } else { d.abs() };
                v[l] = c + fmin(fmin(diag[l], up[l]), left[l]);
            }
            cur[j] = v;
            left = v;
            diag = up;
        }
        std::mem::swap(&mut prev, &mut cur);
    }
    *out = prev[m];
}

/// The DTW distance of every channel of `a` and `b` (same channel count), written to `out`
/// (length at least the channel count). Full grid, no normalisation.
pub fn fused_channels(
    a: &Interleaved,
    b: &Interleaved,
    cost: LocalCost,
    scratch: &mut Vec<[f64; LANES]>,
    out: &mut [f64],
) {
    let mut lanes = [0.0; LANES];
    for (g, (ga, gb)) in a.groups.iter().zip(&b.groups).enumerate() {
        match cost {
            LocalCost::Abs => group::<false>(ga, gb, scratch, &mut lanes),
            LocalCost::Squared => group::<true>(ga, gb, scratch, &mut lanes),
        }
        let k0 = g * LANES;
        let n = (a.channels - k0).min(LANES);
        out[k0..k0 + n].copy_from_slice(&lanes[..n]);
    }
}

/// Δ of eq. 6 (sum over the channels) of two interleaved samples.
pub fn fused_sum(
    a: &Interleaved,
    b: &Interleaved,
    cost: LocalCost,
    scratch: &mut Vec<[f64; LANES]>,
) -> f64 {
    let mut lanes = [0.0; LANES];
    let mut sum = 0.0;
    for (ga, gb) in a.groups.iter().zip(&b.groups) {
        match cost {
            LocalCost::Abs => group::<false>(ga, gb, scratch, &mut lanes),
            LocalCost::Squared => group::<true>(ga, gb, scratch, &mut lanes),
        }
        sum += lanes.iter().sum::<f64>();
    }
    sum
}
