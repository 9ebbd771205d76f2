//! The DTW kernel Δ of eq. 6 and dissimilarity matrices over sample sets.

use faer::Mat;
use rayon::prelude::*;
use wscg_math::{Error, Result};

use super::core::{check_seq, dtw_bounded, dtw_dependent_bounded, DtwParams, Frames, Multivariate};
use super::fused::{fused_sum, Interleaved};

/// A dissimilarity matrix (`queries x gallery`).
pub type DistMatrix = Mat<f64>;

/// Checks one multichannel sample: at least one channel, every channel non-empty and finite.
pub fn check_sample(name: &'static str, s: &[Vec<f64>]) -> Result<()> {
    if s.is_empty() {
        return Err(Error::Empty(name));
    }
    for ch in s {
        check_seq(name, ch)?;
    }
    Ok(())
}

/// Checks a set of samples that all have `channels` channels.
pub(crate) fn check_set(name: &'static str, set: &[Vec<Vec<f64>>], channels: usize) -> Result<()> {
    for (k, s) in set.iter().enumerate() {
        check_sample(name, s)?;
        if s.len() != channels {
            return Err(Error::ShapeMismatch(format!(
                "{name}[{k}] has {} channels, expected {channels} (samples must be built with the \
                 same pair list)",
                s.len()
            )));
        }
    }
    Ok(())
}

/// The DTW kernel of eq. 6: `Δ(θ, θ') = Σ_m DTW(θ_m, θ'_m)` over the channels (selected joint
/// pairs) of two samples; each channel warps separately (independent multivariate DTW). With
/// [`Multivariate::Dependent`] in `p`, the dependent DTW instead: one warp path for all
/// channels, the local cost between whole frames.
///
/// Errors: different channel counts, an empty or non-finite channel; for the dependent DTW,
/// channels of different lengths within a sample.
pub fn dtw_kernel(a: &[Vec<f64>], b: &[Vec<f64>], p: &DtwParams) -> Result<f64> {
    p.validate()?;
    check_sample("a", a)?;
    check_sample("b", b)?;
    if a.len() != b.len() {
        return Err(Error::ShapeMismatch(format!(
            "a has {} channels, b has {} (samples must be built with the same pair list)",
            a.len(),
            b.len()
        )));
    }
    let mut scratch = Vec::new();
    Ok(match p.multivariate {
        Multivariate::Independent => dtw_kernel_bounded(a, b, p, f64::INFINITY, &mut scratch),
        Multivariate::Dependent => {
            let (fa, fb) = (Frames::new("a", a)?, Frames::new("b", b)?);
            dtw_dependent_bounded(&fa, &fb, p, f64::INFINITY, &mut scratch)
        }
    })
}

/// The independent [`dtw_kernel`] (whatever `p.multivariate` says) without checks, abandoned (returns `+inf`) once the partial sum exceeds
/// `bound`; exact whenever the result is at most `bound`.
pub fn dtw_kernel_bounded(
    a: &[Vec<f64>],
    b: &[Vec<f64>],
    p: &DtwParams,
    bound: f64,
    scratch: &mut Vec<f64>,
) -> f64 {
    let mut sum = 0.0;
    for (x, y) in a.iter().zip(b) {
        sum += dtw_bounded(x, y, p, bound - sum, scratch);
        if sum > bound {
            return f64::INFINITY;
        }
    }
    sum
}

/// Interleaved copies of all samples when the channel-fused kernel applies (full grid, every
/// sample's channels of one length).
pub fn interleave_all(set: &[Vec<Vec<f64>>], p: &DtwParams) -> Option<Vec<Interleaved>> {
    if p.window.is_some() {
        return None;
    }
    set.iter().map(|s| Interleaved::new(s)).collect()
}

/// Copies of a sample set in the layout of the fastest kernel for `p`, made once per set so
/// that no pair allocates: frame-major for the dependent DTW, channel-interleaved for the
/// independent one when it applies, none otherwise.
pub(crate) enum Prepared {
    /// The samples as given (per-channel recursion).
    Plain,
    /// Channel-interleaved ([`Multivariate::Independent`], full grid, equal channel lengths).
    Fused(Vec<Interleaved>),
    /// Frame-major ([`Multivariate::Dependent`]).
    Frames(Vec<Frames>),
}

/// One sample's entry of a [`Prepared`] set.
#[derive(Clone, Copy)]
pub(crate) enum Layout<'a> {
    Plain,
    Fused(&'a Interleaved),
    Frames(&'a Frames),
}

impl<'a> From<Option<&'a Interleaved>> for Layout<'a> {
    fn from(f: Option<&'a Interleaved>) -> Self {
        f.map_or(Layout::Plain, Layout::Fused)
    }
}

impl Prepared {
    /// Errors: for the dependent DTW, a sample whose channels differ in length.
    pub(crate) fn new(name: &'static str, set: &[Vec<Vec<f64>>], p: &DtwParams) -> Result<Self> {
        Ok(match p.multivariate {
            Multivariate::Dependent => Prepared::Frames(
                set.iter()
                    .map(|s| Frames::new(name, s))
                    .collect::<Result<_>>()?,
            ),
            Multivariate::Independent => {
                interleave_all(set, p).map_or(Prepared::Plain, Prepared::Fused)
            }
        })
    }

    /// Entry `k`.
    pub(crate) fn get(&self, k: usize) -> Layout<'_> {
        match self {
            Prepared::Plain => Layout::Plain,
            Prepared::Fused(f) => Layout::Fused(&f[k]),
            Prepared::Frames(f) => Layout::Frames(&f[k]),
        }
    }
}

/// Δ between two samples with the kernel their layouts allow: channel-fused or per-channel
/// independent DTW, or the dependent DTW on frames.
pub(crate) fn pair_delta(
    sa: &[Vec<f64>],
    sb: &[Vec<f64>],
    la: Layout<'_>,
    lb: Layout<'_>,
    p: &DtwParams,
    scratch: &mut Vec<f64>,
    lanes: &mut Vec<[f64; super::fused::LANES]>,
) -> f64 {
    match (la, lb) {
        (Layout::Frames(x), Layout::Frames(y)) => {
            dtw_dependent_bounded(x, y, p, f64::INFINITY, scratch)
        }
        (Layout::Fused(x), Layout::Fused(y)) => {
            let d = fused_sum(x, y, p.cost, lanes);
            if p.normalize {
                d / (x.len() + y.len()) as f64
            } else {
                d
            }
        }
        _ => dtw_kernel_bounded(sa, sb, p, f64::INFINITY, scratch),
    }
}

/// Δ between every query (rows) and gallery sample (columns), in parallel over the rows.
/// Without a band, channels of equal length are processed [`super::fused::LANES`] at a time.
/// With [`Multivariate::Dependent`], the dependent DTW of every pair (each sample copied
/// frame-major once; no allocation per pair).
///
/// Errors: empty sets, samples with different channel counts, empty or non-finite channels;
/// for the dependent DTW, a sample whose channels differ in length.
pub fn dissimilarity_matrix(
    queries: &[Vec<Vec<f64>>],
    gallery: &[Vec<Vec<f64>>],
    p: &DtwParams,
) -> Result<DistMatrix> {
    p.validate()?;
    if queries.is_empty() {
        return Err(Error::Empty("queries"));
    }
    if gallery.is_empty() {
        return Err(Error::Empty("gallery"));
    }
    let channels = queries[0].len();
    check_set("queries", queries, channels)?;
    check_set("gallery", gallery, channels)?;
    let g = gallery.len();
    let (fq, fg) = (
        Prepared::new("queries", queries, p)?,
        Prepared::new("gallery", gallery, p)?,
    );
    let mut out = vec![0.0; queries.len() * g];
    out.par_chunks_mut(g).enumerate().for_each_init(
        || (Vec::new(), Vec::new()),
        |(scratch, lanes), (i, row)| {
            for (j, v) in row.iter_mut().enumerate() {
                *v = pair_delta(
                    &queries[i],
                    &gallery[j],
                    fq.get(i),
                    fg.get(j),
                    p,
                    scratch,
                    lanes,
                );
            }
        },
    );
    Ok(Mat::from_fn(queries.len(), g, |i, j| out[i * g + j]))
}

/// Δ between all pairs of one sample set (symmetric, zero diagonal): each pair is computed
/// once, in parallel over the pairs (channel-fused as in [`dissimilarity_matrix`]).
///
/// Errors as [`dissimilarity_matrix`].
pub fn self_dissimilarity(samples: &[Vec<Vec<f64>>], p: &DtwParams) -> Result<DistMatrix> {
    p.validate()?;
    if samples.is_empty() {
        return Err(Error::Empty("samples"));
    }
    check_set("samples", samples, samples[0].len())?;
    let n = samples.len();
    let pairs: Vec<(usize, usize)> = (0..n)
        .flat_map(|i| (i + 1..n).map(move |j| (i, j)))
        .collect();
    let fs = Prepared::new("samples", samples, p)?;
    let vals: Vec<f64> = pairs
        .par_iter()
        .map_init(
            || (Vec::new(), Vec::new()),
            |(scratch, lanes), &(i, j)| {
                pair_delta(
                    &samples[i],
                    &samples[j],
                    fs.get(i),
                    fs.get(j),
                    p,
                    scratch,
                    lanes,
                )
            },
        )
        .collect();
    let mut m = Mat::zeros(n, n);
    for (&(i, j), &v) in pairs.iter().zip(&vals) {
        m[(i, j)] = v;
        m[(j, i)] = v;
    }
    Ok(m)
}

/// The gallery sample nearest to `query` by Δ (or the dependent DTW, with
/// [`Multivariate::Dependent`]) and that distance (ties: the first index), using exact early
/// abandoning against the best distance so far.
///
/// Errors as [`dissimilarity_matrix`].
pub fn nearest(
    query: &[Vec<f64>],
    gallery: &[Vec<Vec<f64>>],
    p: &DtwParams,
) -> Result<(usize, f64)> {
    p.validate()?;
    check_sample("query", query)?;
    if gallery.is_empty() {
        return Err(Error::Empty("gallery"));
    }
    check_set("gallery", gallery, query.len())?;
    let mut scratch = Vec::new();
    let mut best = (0, f64::INFINITY);
    let frames = match p.multivariate {
        Multivariate::Independent => None,
        Multivariate::Dependent => Some((
            Frames::new("query", query)?,
            gallery
                .iter()
                .map(|s| Frames::new("gallery", s))
                .collect::<Result<Vec<_>>>()?,
        )),
    };
    for (k, s) in gallery.iter().enumerate() {
        let d = match &frames {
            None => dtw_kernel_bounded(query, s, p, best.1, &mut scratch),
            Some((q, g)) => dtw_dependent_bounded(q, &g[k], p, best.1, &mut scratch),
        };
        if d < best.1 {
            best = (k, d);
        }
    }
    Ok(best)
}
