//! The DTW recursion of eq. 5 on two sequences of scalars (one channel) or of frames (all
//! channels at one instant, the dependent multivariate DTW). One recursion serves both: it
//! is generic over [`Rows`], the element access of a sequence.

use serde::{Deserialize, Serialize};
use wscg_math::{Error, Result};

/// The local cost `c(a_i, b_j)` between two samples.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum LocalCost {
    /// `|a_i - b_j|`: the paper's "Euclidean distance" between two scalar angles (default).
    #[default]
    Abs,
    /// `(a_i - b_j)^2`: the cost of the UCR/UEA archive's published DTW error rates (and of
    /// dtaidistance, which returns the square root of the accumulated squared cost).
    Squared,
}

impl LocalCost {
    /// Parses `"abs"` or `"squared"`.
    pub fn parse(s: &str) -> Result<Self> {
        match s {
            "abs" => Ok(Self::Abs),
            "squared" | "sq" => Ok(Self::Squared),
            other => Err(Error::invalid(
                "cost",
                format!("`{other}` is not a valid cost. Valid costs are \"abs\" and \"squared\""),
            )),
        }
    }
}

/// How a multichannel sample is warped.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Multivariate {
    /// Each channel warps on its own and the channel distances are summed: the DTW kernel Δ
    /// of eq. 6 (`DTW_I`, Shokoohi-Yekta et al. 2017; default, the paper's).
    #[default]
    Independent,
    /// One warp path for all channels, the local cost taken between whole frames: the
    /// Euclidean norm `||a_i - b_j||` ([`LocalCost::Abs`]) or its square
    /// ([`LocalCost::Squared`]). This is `DTW_D` of the UEA multivariate archive's published
    /// 1-NN results (Bagnall et al. 2018) and dtaidistance's `dtw_ndim.distance` (which
    /// returns the square root of the squared-cost distance). Every channel of a sample must
    /// have the same length.
    Dependent,
}

impl Multivariate {
    /// Parses `"independent"` or `"dependent"`.
    pub fn parse(s: &str) -> Result<Self> {
        match s {
            "independent" => Ok(Self::Independent),
            "dependent" => Ok(Self::Dependent),
            other => Err(Error::invalid(
                "multivariate",
                format!(
                    "`{other}` is not a valid mode. Valid modes are \"independent\" and \
                     \"dependent\""
                ),
            )),
        }
    }
}

wscg_math::params! {
    /// Parameters of [`dtw`].
    #[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
    pub struct DtwParams {
        /// Local cost (default [`LocalCost::Abs`], the paper's).
        pub cost: LocalCost,
        /// Optional Sakoe-Chiba band half-width `r` in samples of the second sequence: cell
        /// `(i, j)` (0-based) is allowed when `|j - i (m-1)/(n-1)| <= r`. For equal lengths this
        /// is the usual `|i - j| <= r` (`r = 0`: the lock-step Euclidean sum); for different
        /// lengths `r` is raised to `ceil((m-1)/(n-1))` when needed so that a warp path exists.
        /// `None` (default, the paper's) is the full grid.
        pub window: Option<usize>,
        /// Divide the accumulated cost by `n + m` (a path-length normalisation the paper does not
        /// use; default `false`).
        pub normalize: bool,
        /// How multichannel samples are compared by [`super::dtw_kernel`],
        /// [`super::dissimilarity_matrix`] and [`super::nearest`] (default
        /// [`Multivariate::Independent`], eq. 6). Scalar sequences are unaffected.
        #[serde(default)]
        pub multivariate: Multivariate,
    }
}

impl DtwParams {
    /// Every value of every field is valid (a band `r = 0` is the lock-step sum, a band
    /// narrower than the length ratio is widened), so this never fails; it is here so that
    /// every parameter struct is checked the same way.
    pub fn validate(&self) -> Result<()> {
        Ok(())
    }

    /// The paper's DTW with the given local cost.
    pub fn with_cost(cost: LocalCost) -> Self {
        Self {
            cost,
            ..Self::default()
        }
    }
}

/// Checks that a sequence is non-empty and finite.
pub(crate) fn check_seq(name: &'static str, a: &[f64]) -> Result<()> {
    if a.is_empty() {
        return Err(Error::Empty(name));
    }
    if let Some(index) = a.iter().position(|v| !v.is_finite()) {
        return Err(Error::NonFinite { name, index });
    }
    Ok(())
}

/// DTW distance between `a` (length `n`) and `b` (length `m`), eq. 5:
/// `D(0,0) = 0`, `D(i,0) = D(0,j) = inf`,
/// `D(i,j) = c(a_i, b_j) + min{D(i-1,j), D(i,j-1), D(i-1,j-1)}`, result `D(n,m)`.
///
/// Two rows of memory (`O(min(n, m))`). Errors: an empty or non-finite sequence.
pub fn dtw(a: &[f64], b: &[f64], p: &DtwParams) -> Result<f64> {
    p.validate()?;
    check_seq("a", a)?;
    check_seq("b", b)?;
    let mut scratch = Vec::new();
    Ok(dtw_bounded(a, b, p, f64::INFINITY, &mut scratch))
}

/// Element access of a sequence the recursion runs on: scalars (`&[f64]`) or frames
/// ([`Frames`]).
pub(crate) trait Rows: Copy {
    /// One element: a scalar or a frame.
    type Row: Copy;
    /// Number of elements.
    fn len(self) -> usize;
    /// Element `i` (`i < len`).
    fn row(self, i: usize) -> Self::Row;
}

impl Rows for &[f64] {
    type Row = f64;
    #[inline(always)]
    fn len(self) -> usize {
        <[f64]>::len(self)
    }
    #[inline(always)]
    fn row(self, i: usize) -> f64 {
        self[i]
    }
}

/// A multichannel sample stored frame-major (`time x channels`, the channels of one instant
/// adjacent): the layout of the dependent DTW ([`Multivariate::Dependent`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Frames {
    data: Vec<f64>,
    channels: usize,
}

impl Frames {
    /// The frame-major copy of a sample given as channels (`channels x time`).
    ///
    /// Errors: no channel, an empty or non-finite channel, channels of different lengths.
    pub fn new(name: &'static str, sample: &[Vec<f64>]) -> Result<Self> {
        if sample.is_empty() {
            return Err(Error::Empty(name));
        }
        let len = sample[0].len();
        for ch in sample {
            check_seq(name, ch)?;
            if ch.len() != len {
                return Err(Error::ShapeMismatch(format!(
                    "{name} has channels of lengths {len} and {}: dependent DTW compares whole \
                     frames, so every channel of a sample needs the same length",
                    ch.len()
                )));
            }
        }
        let channels = sample.len();
        // The same size as the sample itself, which is already in memory.
        let mut data = vec![0.0; len * channels];
        for (k, ch) in sample.iter().enumerate() {
            for (t, &v) in ch.iter().enumerate() {
                data[t * channels + k] = v;
            }
        }
        Ok(Self { data, channels })
    }

    /// Number of channels.
    pub fn channels(&self) -> usize {
        self.channels
    }

    /// Number of frames.
    pub fn len(&self) -> usize {
        self.data.len() / self.channels
    }

    /// Whether there is no frame (never, for a constructed value).
    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }
}

impl<'a> Rows for &'a Frames {
    type Row = &'a [f64];
    #[inline(always)]
    fn len(self) -> usize {
        Frames::len(self)
    }
    #[inline(always)]
    fn row(self, i: usize) -> &'a [f64] {
        &self.data[i * self.channels..(i + 1) * self.channels]
    }
}

/// Squared Euclidean distance between two frames of equal length. Eight partial sums, so that
/// a long frame is not one chain of dependent additions but two SIMD vectors' worth of them
/// (the order of the additions differs from a left-to-right sum only by rounding).
#[inline(always)]
fn frame_sq(x: &[f64], y: &[f64]) -> f64 {
    const W: usize = 8;
    let (xc, yc) = (x.chunks_exact(W), y.chunks_exact(W));
    let tail: f64 = xc
        .remainder()
        .iter()
        .zip(yc.remainder())
        .map(|(u, v)| (u - v) * (u - v))
        .sum();
    let mut acc = [0.0; W];
    for (u, v) in xc.zip(yc) {
        for l in 0..W {
            let d = u[l] - v[l];
            acc[l] += d * d;
        }
    }
    ((acc[0] + acc[1]) + (acc[2] + acc[3])) + ((acc[4] + acc[5]) + (acc[6] + acc[7])) + tail
}

/// [`dtw`] without input checks, with early abandoning: returns `+inf` as soon as every cell
/// of a row exceeds `bound` (the distance is then known to exceed `bound`; exact otherwise).
/// `scratch` is reused between calls to avoid allocation. Inputs must be non-empty.
pub fn dtw_bounded(a: &[f64], b: &[f64], p: &DtwParams, bound: f64, scratch: &mut Vec<f64>) -> f64 {
    match p.cost {
        LocalCost::Abs => run(a, b, p, bound, scratch, |x, y| (x - y).abs()),
        LocalCost::Squared => run(a, b, p, bound, scratch, |x, y| (x - y) * (x - y)),
    }
}

/// The dependent DTW ([`Multivariate::Dependent`]) of two samples with the same channel
/// count: eq. 5 on frames, local cost `||a_i - b_j||` or `||a_i - b_j||^2`. Early abandoning
/// and `scratch` as in [`dtw_bounded`]; no allocation once `scratch` has grown.
pub fn dtw_dependent_bounded(
    a: &Frames,
    b: &Frames,
    p: &DtwParams,
    bound: f64,
    scratch: &mut Vec<f64>,
) -> f64 {
    debug_assert_eq!(a.channels, b.channels);
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports the feature the function is compiled for.
        return unsafe { dependent_avx2(a, b, p, bound, scratch) };
    }
    dependent(a, b, p, bound, scratch)
}

/// [`dependent`] compiled for AVX2 (the frame cost in 256-bit vectors); the same operations
/// in the same order, so the same result.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn dependent_avx2(
    a: &Frames,
    b: &Frames,
    p: &DtwParams,
    bound: f64,
    scratch: &mut Vec<f64>,
) -> f64 {
    dependent(a, b, p, bound, scratch)
}

#[inline(always)]
fn dependent(a: &Frames, b: &Frames, p: &DtwParams, bound: f64, scratch: &mut Vec<f64>) -> f64 {
    match p.cost {
        LocalCost::Abs => run(a, b, p, bound, scratch, |x, y| frame_sq(x, y).sqrt()),
        LocalCost::Squared => run(a, b, p, bound, scratch, frame_sq),
    }
}

/// The band / normalisation dispatch shared by scalars and frames.
#[inline(always)]
fn run<S: Rows>(
    a: S,
    b: S,
    p: &DtwParams,
    bound: f64,
    scratch: &mut Vec<f64>,
    c: impl Fn(S::Row, S::Row) -> f64,
) -> f64 {
    let (n, m) = (a.len(), b.len());
    let scale = if p.normalize { (n + m) as f64 } else { 1.0 };
    let raw_bound = bound * scale;
    let raw = match p.window.filter(|_| n > 1 && m > 1) {
        None => full(a, b, raw_bound, scratch, c),
        Some(r) => band(a, b, r, raw_bound, scratch, c),
    };
    raw / scale
}

/// Minimum of two finite-or-infinite values (no NaN reaches the recursion): a plain comparison,
/// which compiles to one `minsd`, where `f64::min` adds NaN handling to the critical path.
#[inline(always)]
pub(crate) fn fmin(a: f64, b: f64) -> f64 {
    if a < b {
        a
    } else {
        b
    }
}

/// Full-grid recursion; the shorter sequence indexes the rows of memory. Always inlined, so
/// that it is compiled with the target features of its caller.
#[inline(always)]
fn full<S: Rows>(
    a: S,
    b: S,
    bound: f64,
    scratch: &mut Vec<f64>,
    c: impl Fn(S::Row, S::Row) -> f64,
) -> f64 {
    // DTW is symmetric for symmetric costs: keep the row buffer short.
    let (a, b) = if b.len() > a.len() { (b, a) } else { (a, b) };
    let (n, m) = (a.len(), b.len());
    scratch.clear();
    scratch.resize(2 * (m + 1), f64::INFINITY);
    let (prev, cur) = scratch.split_at_mut(m + 1);
    let (mut prev, mut cur) = (prev, cur);
    prev[0] = 0.0;
    let check = bound.is_finite();
    for i in 0..n {
        let ai = a.row(i);
        cur[0] = f64::INFINITY;
        let mut left = f64::INFINITY;
        let mut diag = prev[0];
        let mut row_min = f64::INFINITY;
        for j in 1..=m {
            let up = prev[j];
            let v = c(ai, b.row(j - 1)) + fmin(fmin(diag, up), left);
            cur[j] = v;
            left = v;
            diag = up;
            row_min = fmin(row_min, v);
        }
        if check && row_min > bound {
            return f64::INFINITY;
        }
        std::mem::swap(&mut prev, &mut cur);
    }
    prev[m]
}

/// Slope `(m-1)/(n-1)` of the band's centre line and its effective half-width: `r` itself for
/// equal lengths, else at least `ceil(slope)` so that a warp path exists.
fn band_radius(r: usize, n: usize, m: usize) -> (f64, f64) {
    if n == m {
        return (1.0, r as f64);
    }
    let slope = (m - 1) as f64 / (n - 1) as f64;
    (slope, (r as f64).max(slope.ceil()))
}

/// The allowed column range `lo..=hi` (0-based) of row `i` in the Sakoe-Chiba band.
#[inline]
fn band_range(i: usize, slope: f64, r: f64, m: usize) -> (usize, usize) {
    let centre = i as f64 * slope;
    let lo = (centre - r).ceil().max(0.0) as usize;
    let hi = ((centre + r).floor() as usize).min(m - 1);
    (lo, hi)
}

/// Banded recursion (`n, m >= 2`), always inlined as [`full`].
#[inline(always)]
fn band<S: Rows>(
    a: S,
    b: S,
    r: usize,
    bound: f64,
    scratch: &mut Vec<f64>,
    c: impl Fn(S::Row, S::Row) -> f64,
) -> f64 {
    let (n, m) = (a.len(), b.len());
    let (slope, r) = band_radius(r, n, m);
    scratch.clear();
    scratch.resize(2 * (m + 1), f64::INFINITY);
    let (prev, cur) = scratch.split_at_mut(m + 1);
    let (mut prev, mut cur) = (prev, cur);
    prev[0] = 0.0;
    // Range written into `cur` two rows ago (1-based columns), to be reset.
    let mut stale = (1usize, 0usize);
    let check = bound.is_finite();
    for i in 0..n {
        let ai = a.row(i);
        for v in &mut cur[stale.0..=stale.1] {
            *v = f64::INFINITY;
        }
        cur[0] = f64::INFINITY;
        let (lo, hi) = band_range(i, slope, r, m);
        let mut left = f64::INFINITY;
        let mut row_min = f64::INFINITY;
        for j in lo + 1..=hi + 1 {
            let v = c(ai, b.row(j - 1)) + fmin(fmin(prev[j - 1], prev[j]), left);
            cur[j] = v;
            left = v;
            row_min = fmin(row_min, v);
        }
        if check && row_min > bound {
            return f64::INFINITY;
        }
        std::mem::swap(&mut prev, &mut cur);
        // `cur` now holds the row before; its written range is the previous row's.
        stale = if i == 0 {
            (0, 0)
        } else {
            stale_of(i - 1, slope, r, m)
        };
    }
    prev[m]
}

/// 1-based written range of row `i`.
fn stale_of(i: usize, slope: f64, r: f64, m: usize) -> (usize, usize) {
    let (lo, hi) = band_range(i, slope, r, m);
    (lo + 1, hi + 1)
}

/// DTW distance and an optimal warp path `[(0,0), ..., (n-1,m-1)]` (0-based index pairs,
/// monotone, steps (1,0), (0,1), (1,1)); ties prefer the diagonal step. Full `(n+1) x (m+1)`
/// table. Errors as [`dtw`].
pub fn dtw_path(a: &[f64], b: &[f64], p: &DtwParams) -> Result<(f64, Vec<(usize, usize)>)> {
    p.validate()?;
    check_seq("a", a)?;
    check_seq("b", b)?;
    let (n, m) = (a.len(), b.len());
    let w = m + 1;
    let mut d = vec![f64::INFINITY; (n + 1) * w];
    d[0] = 0.0;
    let (slope, r) = match p.window.filter(|_| n > 1 && m > 1) {
        Some(r) => band_radius(r, n, m),
        None => (0.0, f64::INFINITY),
    };
    for i in 1..=n {
        let (lo, hi) = if r.is_finite() {
            band_range(i - 1, slope, r, m)
        } else {
            (0, m - 1)
        };
        for j in lo + 1..=hi + 1 {
            let diff = a[i - 1] - b[j - 1];
            let c = match p.cost {
                LocalCost::Abs => diff.abs(),
                LocalCost::Squared => diff * diff,
            };
            let best = d[(i - 1) * w + j - 1]
                .min(d[(i - 1) * w + j])
                .min(d[i * w + j - 1]);
            d[i * w + j] = c + best;
        }
    }
    let mut path = vec![(n - 1, m - 1)];
    let (mut i, mut j) = (n, m);
    while (i, j) != (1, 1) {
        let diag = d[(i - 1) * w + j - 1];
        let up = d[(i - 1) * w + j];
        let left = d[i * w + j - 1];
        if diag <= up && diag <= left {
            i -= 1;
            j -= 1;
        } else if up <= left {
            i -= 1;
        } else {
            j -= 1;
        }
        path.push((i - 1, j - 1));
    }
    path.reverse();
    let scale = if p.normalize { (n + m) as f64 } else { 1.0 };
    Ok((d[n * w + m] / scale, path))
}
