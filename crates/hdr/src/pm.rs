//! PatchMatch on a scanline (paper section 3.1): the epipolar variant of the paper, with the
//! coherence-penalised cost `D = SSD / C` (eqs. 2-4) and the 1-D random search of eq. 1, and
//! the original 2-D PatchMatch of Barnes et al. (2009) it is compared against.
//!
//! Both run the classic sequential order: even iterations scan top-left to bottom-right and
//! propagate from the left and top neighbours, odd iterations scan back and propagate from
//! the right and bottom ones, so a good match travels across the whole image in one sweep.
//! The cost of a pixel's current match is recomputed before every comparison, because the
//! coherence term depends on neighbours that have moved since it was stored. The rows of a
//! sweep run on the pool's threads as a pipeline that shows every pixel exactly the
//! neighbours of the sequential scan (see `Run::sweep`), with one random stream per row and
//! sweep, so one field uses every core (the paper matches the pairs of views in parallel;
//! so does [`crate::multiscopic_hdr`]) and the result depends on the seed only.

use std::sync::atomic::{AtomicUsize, Ordering};

use rand::Rng as _;
use rayon::prelude::*;
use wscg_math::{rng, Error, Image, Result};

use crate::nnf::Nnf;

wscg_math::params! {
    /// Parameters of [`patchmatch`].
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct PatchMatchParams {
        /// Patch side `N` (odd, `>= 3`; the paper's figures use 7).
        pub patch: usize,
        /// Iterations (the paper: "two iterations were enough").
        pub iters: usize,
        /// Smallest horizontal offset searched (epipolar mode).
        pub d_min: i32,
        /// Largest horizontal offset searched (epipolar mode).
        pub d_max: i32,
        /// Vertical tolerance of the epipolar search (0: exact rectification).
        pub v_tol: i32,
        /// Ratio `alpha` of the random search radii (eq. 1; 1/2 as suggested).
        pub alpha: f32,
        /// Search on the epipolar line (the paper) or over the whole image (2-D).
        pub epipolar: bool,
        /// Divide the SSD by the coherence term `C` (eq. 2) or use the SSD alone.
        pub coherence: bool,
        /// Lower bound of `C` (the paper leaves `C <= 0` undefined).
        pub c_min: f32,
        /// Seed of the initialisation and the random search.
        pub seed: u64,
        /// Not in the paper (an ablation): weight each squared difference by the smaller Khan
        /// weight of the two samples, so clipped pixels do not drive the match (used by
        /// [`patchmatch_weighted`] and the multiscopic driver; plain [`patchmatch`] has no
        /// weights and ignores it).
        pub weighted_cost: bool,
    }
}

impl Default for PatchMatchParams {
    fn default() -> Self {
        Self {
            patch: 7,
            iters: 2,
            d_min: -64,
            d_max: 64,
            v_tol: 0,
            alpha: 0.5,
            epipolar: true,
            coherence: true,
            c_min: 0.05,
            seed: 0,
            weighted_cost: false,
        }
    }
}

impl PatchMatchParams {
    /// The original PatchMatch of Barnes et al. 2009: 2-D search over the whole source image,
    /// SSD cost without the coherence term.
    pub fn barnes(patch: usize, iters: usize, seed: u64) -> Self {
        Self {
            patch,
            iters,
            epipolar: false,
            coherence: false,
            seed,
            ..Self::default()
        }
    }

    /// The largest displacement `Max_disp` (eq. 4, and `w` of eq. 1) of the epipolar search.
    pub fn max_disp(&self) -> i32 {
        self.d_min
            .unsigned_abs()
            .max(self.d_max.unsigned_abs())
            .clamp(1, i32::MAX as u32) as i32
    }

    /// Checks the parameters for images of `(height, width)`.
    pub fn validate(&self, height: usize, width: usize) -> Result<()> {
        check_patch(self.patch, height, width)?;
        if self.epipolar {
            if self.d_min > self.d_max {
                return Err(Error::invalid(
                    "d_min",
                    format!("d_min = {} > d_max = {}", self.d_min, self.d_max),
                ));
            }
            if self.max_disp() as usize >= width {
                return Err(Error::invalid(
                    "max_disparity",
                    format!(
                        "|disparity| up to {} must be < the image width {width}",
                        self.max_disp()
                    ),
                ));
            }
            if self.v_tol < 0 || self.v_tol as usize >= height {
                return Err(Error::invalid(
                    "v_tol",
                    format!("must be in 0..{height}, got {}", self.v_tol),
                ));
            }
        }
        if !(self.alpha > 0.0 && self.alpha < 1.0) {
            return Err(Error::invalid(
                "alpha",
                format!("must be in (0, 1), got {}", self.alpha),
            ));
        }
        if !(self.c_min > 0.0 && self.c_min <= 1.0) {
            return Err(Error::invalid(
                "c_min",
                format!("must be in (0, 1], got {}", self.c_min),
            ));
        }
        Ok(())
    }
}

/// Checks a patch side: odd, `>= 3` and at most the smaller image side.
pub fn check_patch(patch: usize, height: usize, width: usize) -> Result<()> {
    if patch < 3 || patch.is_multiple_of(2) || patch > height.min(width) {
        return Err(Error::invalid(
            "patch",
            format!(
                "must be odd, >= 3 and <= min(height, width) = {}, got {patch}",
                height.min(width)
            ),
        ));
    }
    Ok(())
}

/// Checks that two images can be matched: same channel count, finite values.
pub fn check_pair(a: &Image<f32>, b: &Image<f32>) -> Result<()> {
    if a.channels() != b.channels() {
        return Err(Error::ShapeMismatch(format!(
            "images have {} and {} channels",
            a.channels(),
            b.channels()
        )));
    }
    if a.data().is_empty() || b.data().is_empty() {
        return Err(Error::invalid("image", "is empty"));
    }
    a.ensure_finite("a")?;
    b.ensure_finite("b")
}

/// Four independent 4-lane accumulators: one SIMD register per pixel of the 4-channel
/// padded layout, four of them so consecutive pixels do not wait on each other's additions.
type Lanes = [[f32; 4]; 4];

/// Adds `(x - y)^2` lane by lane to an `N`-lane accumulator (`x`, `y`: `N` samples).
#[inline(always)]
fn add_sq<const N: usize>(acc: &mut [f32; N], x: &[f32], y: &[f32]) {
    let x: &[f32; N] = x.try_into().expect("chunk of N");
    let y: &[f32; N] = y.try_into().expect("chunk of N");
    for k in 0..N {
        let d = x[k] - y[k];
        acc[k] += d * d;
    }
}

/// Adds the squared differences of two equal-length slices to the accumulators.
#[inline(always)]
fn sq_diff_lanes(a: &[f32], b: &[f32], acc: &mut Lanes) {
    let (ca, cb) = (a.chunks_exact(16), b.chunks_exact(16));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        add_sq(&mut acc[0], &x[0..4], &y[0..4]);
        add_sq(&mut acc[1], &x[4..8], &y[4..8]);
        add_sq(&mut acc[2], &x[8..12], &y[8..12]);
        add_sq(&mut acc[3], &x[12..16], &y[12..16]);
    }
    let (qa, qb) = (ra.chunks_exact(4), rb.chunks_exact(4));
    let (ta, tb) = (qa.remainder(), qb.remainder());
    for (k, (x, y)) in qa.zip(qb).enumerate() {
        add_sq(&mut acc[k], x, y);
    }
    for (k, (x, y)) in ta.iter().zip(tb).enumerate() {
        acc[3][k] += (x - y) * (x - y);
    }
}

/// [`add_sq`] with each difference multiplied by `mask` (0 or 1).
#[inline(always)]
fn add_sq8_masked(acc: &mut [f32; 8], x: &[f32], y: &[f32], mask: &[f32; 8]) {
    let x: &[f32; 8] = x.try_into().expect("chunk of 8");
    let y: &[f32; 8] = y.try_into().expect("chunk of 8");
    for k in 0..8 {
        let d = (x[k] - y[k]) * mask[k];
        acc[k] += d * d;
    }
}

/// Adds the squared differences of two rows of `len >= 8` unpadded samples to the two
/// accumulators, in chunks of 8 (alternate chunks to alternate accumulators, so consecutive
/// chunks do not wait on each other's additions). A row whose length is not a multiple of 8
/// ends with a chunk that overlaps the one before it; `tail` zeroes the lanes it shares with
/// it. Elementwise operations only, so the result does not depend on the vector width the
/// loop compiles to.
#[inline(always)]
fn sq_diff_row8(a: &[f32], b: &[f32], tail: &[f32; 8], a0: &mut [f32; 8], a1: &mut [f32; 8]) {
    let len = a.len();
    let full = len / 8;
    let mut i = 0;
    while i + 2 <= full {
        add_sq(a0, &a[8 * i..8 * i + 8], &b[8 * i..8 * i + 8]);
        add_sq(a1, &a[8 * i + 8..8 * i + 16], &b[8 * i + 8..8 * i + 16]);
        i += 2;
    }
    if i < full {
        add_sq(a0, &a[8 * i..8 * i + 8], &b[8 * i..8 * i + 8]);
    }
    if !len.is_multiple_of(8) {
        let acc = if full % 2 == 1 { &mut *a1 } else { &mut *a0 };
        add_sq8_masked(acc, &a[len - 8..], &b[len - 8..], tail);
    }
}

/// Sum of the lanes of two 8-lane accumulators, in the order of [`ssd_rows_avx2`]'s
/// reduction: `v = a0 + a1`, `t_k = v_k + v_(k+4)`, then `(t0 + t2) + (t1 + t3)`.
#[inline(always)]
fn lanes8_sum(a0: &[f32; 8], a1: &[f32; 8]) -> f32 {
    let v: [f32; 8] = std::array::from_fn(|k| a0[k] + a1[k]);
    let t: [f32; 4] = std::array::from_fn(|k| v[k] + v[k + 4]);
    (t[0] + t[2]) + (t[1] + t[3])
}

/// The rows of [`Space::ssd_interior_unpadded`] with AVX intrinsics: the same operations in
/// the same order as [`sq_diff_row8`] and [`lanes8_sum`], so the same sums. Returns the sum
/// of squared differences over `n`, or infinity as soon as a pair of rows takes the sum
/// above `lim` (no division on that path).
///
/// # Safety
/// The CPU must support AVX2, and rows `ra + k sa .. + len` of `ua` and `rb + k sb .. + len`
/// of `ub` (`k < side`) must lie inside the slices, with `len >= 8`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
unsafe fn ssd_rows_avx2(
    ua: &[f32],
    ub: &[f32],
    (mut ra, sa): (usize, usize),
    (mut rb, sb): (usize, usize),
    (side, len): (usize, usize),
    tail: &[f32; 8],
    (lim, n): (f32, f32),
) -> f32 {
    use std::arch::x86_64::*;
    debug_assert!(len >= 8);
    debug_assert!(ra + (side - 1) * sa + len <= ua.len() && rb + (side - 1) * sb + len <= ub.len());
    let full = len / 8;
    let m = _mm256_loadu_ps(tail.as_ptr());
    let (mut a0, mut a1) = (_mm256_setzero_ps(), _mm256_setzero_ps());
    let mut s = 0f32;
    for row in 0..side {
        // SAFETY (pointer arithmetic and loads): the rows lie inside the slices (caller).
        let (pa, pb) = (ua.as_ptr().add(ra), ub.as_ptr().add(rb));
        let sq = |k: usize| {
            let d = _mm256_sub_ps(_mm256_loadu_ps(pa.add(k)), _mm256_loadu_ps(pb.add(k)));
            _mm256_mul_ps(d, d)
        };
        let mut i = 0;
        while i + 2 <= full {
            a0 = _mm256_add_ps(a0, sq(8 * i));
            a1 = _mm256_add_ps(a1, sq(8 * i + 8));
            i += 2;
        }
        if i < full {
            a0 = _mm256_add_ps(a0, sq(8 * i));
        }
        if !len.is_multiple_of(8) {
            let d = _mm256_sub_ps(
                _mm256_loadu_ps(pa.add(len - 8)),
                _mm256_loadu_ps(pb.add(len - 8)),
            );
            let d = _mm256_mul_ps(d, m);
            if full % 2 == 1 {
                a1 = _mm256_add_ps(a1, _mm256_mul_ps(d, d));
            } else {
                a0 = _mm256_add_ps(a0, _mm256_mul_ps(d, d));
            }
        }
        ra += sa;
        rb += sb;
        if row % 2 == 1 || row + 1 == side {
            let v = _mm256_add_ps(a0, a1);
            let t = _mm_add_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps::<1>(v));
            let u = _mm_add_ps(t, _mm_movehl_ps(t, t));
            s = _mm_cvtss_f32(_mm_add_ss(u, _mm_shuffle_ps::<1>(u, u)));
            if s > lim {
                return f32::INFINITY;
            }
        }
    }
    s / n
}

/// [`ssd_rows_avx2`] for the paper's patches, 7 rows of 7 pixels of three channels: the same
/// operations with the row and chunk loops unrolled by their constant counts (about 6 %
/// faster fields).
///
/// # Safety
/// As [`ssd_rows_avx2`].
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline(never)]
unsafe fn ssd_rows_avx2_7x21(
    ua: &[f32],
    ub: &[f32],
    a: (usize, usize),
    b: (usize, usize),
    tail: &[f32; 8],
    bound: (f32, f32),
) -> f32 {
    ssd_rows_avx2(ua, ub, a, b, (7, 21), tail, bound)
}

/// Sum of all lanes.
#[inline(always)]
fn lanes_sum(acc: &Lanes) -> f32 {
    let mut v = [0f32; 4];
    for a in acc {
        for k in 0..4 {
            v[k] += a[k];
        }
    }
    (v[0] + v[1]) + (v[2] + v[3])
}

/// Sum of squared differences of two equal-length slices.
#[inline]
fn sq_diff(a: &[f32], b: &[f32]) -> f32 {
    let mut acc = [[0f32; 4]; 4];
    sq_diff_lanes(a, b, &mut acc);
    lanes_sum(&acc)
}

/// The samples of `img` with channels padded by zeros to a multiple of 4 (so a patch row is
/// whole SIMD registers); borrowed as they are when already a multiple.
fn padded(data: &[f32], c: usize) -> std::borrow::Cow<'_, [f32]> {
    let cp = c.div_ceil(4) * 4;
    if cp == c {
        return std::borrow::Cow::Borrowed(data);
    }
    let mut out = vec![0f32; data.len() / c * cp];
    for (o, p) in out.chunks_exact_mut(cp).zip(data.chunks_exact(c)) {
        o[..c].copy_from_slice(p);
    }
    std::borrow::Cow::Owned(out)
}

/// Weighted sum of squared differences, `sum min(wa, wb) (a - b)^2`.
#[inline]
fn sq_diff_weighted(a: &[f32], b: &[f32], wa: &[f32], wb: &[f32]) -> f32 {
    let mut acc = [0f32; 8];
    let n = a.len() / 8 * 8;
    for i in (0..n).step_by(8) {
        for k in 0..8 {
            let d = a[i + k] - b[i + k];
            acc[k] += wa[i + k].min(wb[i + k]) * d * d;
        }
    }
    let mut s: f32 = acc.iter().sum();
    for i in n..a.len() {
        let d = a[i] - b[i];
        s += wa[i].min(wb[i]) * d * d;
    }
    s
}

/// Added to weighted costs so that, where every sample is clipped (cost 0), the coherence
/// term still ranks the candidates.
const WEIGHTED_FLOOR: f32 = 1e-30;

/// The two images of a match and the patch half-size.
struct Space<'a> {
    /// The samples of `a` and `b` in the layout of `c` channels: padded to a multiple of 4
    /// for the weighted ablation and short patch rows, else the samples as they are.
    a: &'a [f32],
    b: &'a [f32],
    /// The samples of `a` and `b` without channel padding, for interior patches whose rows
    /// hold at least 8 samples.
    ua: &'a [f32],
    ub: &'a [f32],
    /// Lane mask of the last, overlapping chunk of such a row (see [`sq_diff_row8`]).
    tail: [f32; 8],
    /// Whether the CPU has AVX2 ([`ssd_rows_avx2`]).
    avx2: bool,
    /// Per-sample weights of `a` and `b` (the weighted-cost ablation).
    weights: Option<(&'a [f32], &'a [f32])>,
    wa: i32,
    ha: i32,
    wb: i32,
    hb: i32,
    /// Channels of the layout of `a` and `b` (padded or not).
    c: usize,
    /// Channels of the images (what a mean counts).
    c_real: usize,
    half: i32,
}

impl Space<'_> {
    /// Mean squared difference (eq. 3, per valid pixel and channel so border patches are
    /// comparable) between the patch of `A` at `(x, y)` and the patch of `B` at
    /// `(x + dx, y + dy)`, over the offsets inside both images. Stops early and returns
    /// infinity once the mean is certain to exceed `bound` (no division on that path);
    /// infinite without overlap.
    #[inline(always)]
    fn ssd(&self, x: i32, y: i32, d: [i32; 2], bound: f32) -> f32 {
        let h = self.half;
        if self.weights.is_none()
            && x >= h
            && y >= h
            && x + h < self.wa
            && y + h < self.ha
            && x + d[0] >= h
            && y + d[1] >= h
            && x + d[0] + h < self.wb
            && y + d[1] + h < self.hb
        {
            return self.ssd_interior(x, y, d, bound);
        }
        let oy0 = (-h).max(-y).max(-y - d[1]);
        let oy1 = h.min(self.ha - 1 - y).min(self.hb - 1 - y - d[1]);
        let ox0 = (-h).max(-x).max(-x - d[0]);
        let ox1 = h.min(self.wa - 1 - x).min(self.wb - 1 - x - d[0]);
        if oy0 > oy1 || ox0 > ox1 {
            return f32::INFINITY;
        }
        let len = (ox1 - ox0 + 1) as usize * self.c;
        let n = (oy1 - oy0 + 1) as f32 * ((ox1 - ox0 + 1) as usize * self.c_real) as f32;
        let lim = bound * n;
        let mut s = 0f32;
        for oy in oy0..=oy1 {
            let ra = ((y + oy) * self.wa + x + ox0) as usize * self.c;
            let rb = ((y + oy + d[1]) * self.wb + x + d[0] + ox0) as usize * self.c;
            let (xa, xb) = (&self.a[ra..ra + len], &self.b[rb..rb + len]);
            s += match self.weights {
                None => sq_diff(xa, xb),
                Some((wa, wb)) => sq_diff_weighted(xa, xb, &wa[ra..ra + len], &wb[rb..rb + len]),
            };
            if s > lim {
                return f32::INFINITY;
            }
        }
        if self.weights.is_some() {
            s / n + WEIGHTED_FLOOR
        } else {
            s / n
        }
    }
}

impl Space<'_> {
    /// [`Space::ssd`] of a patch inside both images: fixed row length, the lanes summed
    /// across two rows at a time between the early-termination checks. Rows of at least 8
    /// samples go to [`Space::ssd_interior_unpadded`]; shorter ones (a 3 x 3 patch of one or
    /// two channels, one-channel patches up to 7 wide) use the padded layout here.
    #[inline(always)]
    fn ssd_interior(&self, x: i32, y: i32, d: [i32; 2], bound: f32) -> f32 {
        let side = (2 * self.half + 1) as usize;
        if side * self.c_real >= 8 {
            return self.ssd_interior_unpadded(x, y, d, bound);
        }
        let len = side * self.c;
        let n = (side * side * self.c_real) as f32;
        let lim = bound * n;
        let (sa, sb) = (self.wa as usize * self.c, self.wb as usize * self.c);
        let mut ra =
            ((y - self.half) as usize * self.wa as usize + (x - self.half) as usize) * self.c;
        let mut rb = ((y + d[1] - self.half) as usize * self.wb as usize
            + (x + d[0] - self.half) as usize)
            * self.c;
        let mut acc = [[0f32; 4]; 4];
        let mut s = 0f32;
        for row in 0..side {
            sq_diff_lanes(&self.a[ra..ra + len], &self.b[rb..rb + len], &mut acc);
            ra += sa;
            rb += sb;
            if row % 2 == 1 || row + 1 == side {
                s = lanes_sum(&acc);
                if s > lim {
                    return f32::INFINITY;
                }
            }
        }
        s / n
    }
}

impl Space<'_> {
    /// [`Space::ssd_interior`] on the unpadded samples: each patch row is `side x channels`
    /// contiguous values, summed in 8-lane chunks ([`sq_diff_row8`]).
    #[inline(always)]
    fn ssd_interior_unpadded(&self, x: i32, y: i32, d: [i32; 2], bound: f32) -> f32 {
        let side = (2 * self.half + 1) as usize;
        let c = self.c_real;
        let len = side * c;
        let n = (side * side * c) as f32;
        let lim = bound * n;
        let (sa, sb) = (self.wa as usize * c, self.wb as usize * c);
        let mut ra = ((y - self.half) as usize * self.wa as usize + (x - self.half) as usize) * c;
        let mut rb = ((y + d[1] - self.half) as usize * self.wb as usize
            + (x + d[0] - self.half) as usize)
            * c;
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: AVX2 was detected; the patch lies inside both images (the caller's
            // interior test), so every row does, and `len >= 8` (`ssd_interior`'s test).
            return unsafe {
                if side == 7 && len == 21 {
                    ssd_rows_avx2_7x21(self.ua, self.ub, (ra, sa), (rb, sb), &self.tail, (lim, n))
                } else {
                    ssd_rows_avx2(
                        self.ua,
                        self.ub,
                        (ra, sa),
                        (rb, sb),
                        (side, len),
                        &self.tail,
                        (lim, n),
                    )
                }
            };
        }
        let (mut a0, mut a1) = ([0f32; 8], [0f32; 8]);
        let mut s = 0f32;
        for row in 0..side {
            let (xa, xb) = (&self.ua[ra..ra + len], &self.ub[rb..rb + len]);
            sq_diff_row8(xa, xb, &self.tail, &mut a0, &mut a1);
            ra += sa;
            rb += sb;
            if row % 2 == 1 || row + 1 == side {
                s = lanes8_sum(&a0, &a1);
                if s > lim {
                    return f32::INFINITY;
                }
            }
        }
        s / n
    }
}

/// The lane mask of the last chunk of a row of `len` samples in [`sq_diff_row8`]: zero on
/// the lanes that chunk shares with the one before it.
fn tail_mask(len: usize) -> [f32; 8] {
    std::array::from_fn(|k| {
        if len.is_multiple_of(8) || k >= 8 - len % 8 {
            1.0
        } else {
            0.0
        }
    })
}

/// Whether the CPU has AVX2 (detected at run time).
fn avx2_available() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Coherence `C = max(1 - d_c / Max_disp, c_min)` of eq. 4 for a squared distance
/// `d2 = d_c^2` to the closest neighbouring offset.
fn coherence_of(d2: i64, w: f32, c_min: f32) -> f32 {
    (1.0 - (d2 as f64).sqrt() as f32 / w).max(c_min)
}

/// [`coherence_of`] for `d2 = 0, 1, ...` up to the first value where it equals `c_min`
/// (every larger `d2` gives `c_min` too), at most 2^16 entries; empty without the coherence
/// term.
fn coherence_table(p: &PatchMatchParams, w: f32) -> Vec<f32> {
    if !p.coherence {
        return Vec::new();
    }
    let mut t = Vec::new();
    loop {
        let c = coherence_of(t.len() as i64, w, p.c_min);
        t.push(c);
        if c <= p.c_min || t.len() >= 1 << 16 {
            return t;
        }
    }
}

/// The current offsets of a pixel's 4-neighbours inside the image: `off[..n]`.
struct Neighbours {
    off: [[i32; 2]; 4],
    n: usize,
}

/// The state of one PatchMatch run.
struct Run<'a> {
    sp: Space<'a>,
    p: PatchMatchParams,
    off: Vec<[i32; 2]>,
    cost: Vec<f32>,
    /// The SSD of each pixel's current offset (NaN until first computed). A pixel's cost
    /// changes between visits only through its neighbours' offsets in the coherence term, so
    /// a visit recomputes `C` but not the SSD.
    ssd: Vec<f32>,
    /// `Max_disp` of the coherence term and `w` of the random search.
    w: f32,
    /// `C` of eq. 4 for the squared distances `d_c^2` of [`coherence_table`] (computed by
    /// [`coherence_of`] beyond it), so a candidate costs no square root.
    coh: Vec<f32>,
}

impl Run<'_> {
    /// Allowed horizontal offsets at column `x` (epipolar: the disparity range with the
    /// source centre inside `B`; 2-D: any source column).
    fn x_range(&self, x: i32) -> (i32, i32) {
        if !self.p.epipolar {
            return (-x, self.sp.wb - 1 - x);
        }
        let (lo, hi) = (self.p.d_min.max(-x), self.p.d_max.min(self.sp.wb - 1 - x));
        if lo <= hi {
            (lo, hi)
        } else {
            // No centre of the range lands in B: the nearest end of the range.
            let d = if self.p.d_min > self.sp.wb - 1 - x {
                self.p.d_min
            } else {
                self.p.d_max
            };
            (d, d)
        }
    }

    /// Allowed vertical offsets at row `y`.
    fn y_range(&self, y: i32) -> (i32, i32) {
        let (lo, hi) = (-y, self.sp.hb - 1 - y);
        if !self.p.epipolar {
            return (lo, hi);
        }
        let (l, h) = (lo.max(-self.p.v_tol), hi.min(self.p.v_tol));
        if l <= h {
            (l, h)
        } else {
            (0, 0)
        }
    }

    /// The current offsets of the 4-neighbours of `(x, y)` that lie inside the image (none
    /// without the coherence term). They stay fixed while the pixel is visited, so a visit
    /// reads them once for all candidates.
    #[inline(always)]
    fn neighbours(&self, x: i32, y: i32) -> Neighbours {
        // SAFETY: `off` is this run's own field of `wa * ha` offsets, not written meanwhile.
        unsafe { self.neighbours_in(self.off.as_ptr(), x, y) }
    }

    /// [`Run::neighbours`] read from the field at `off` (`wa * ha` offsets).
    ///
    /// # Safety
    /// `off` points to `wa * ha` offsets, and no other thread writes the four read here
    /// meanwhile (the row schedule of [`Run::sweep`]).
    #[inline(always)]
    unsafe fn neighbours_in(&self, off: *const [i32; 2], x: i32, y: i32) -> Neighbours {
        let mut nb = Neighbours {
            off: [[0; 2]; 4],
            n: 0,
        };
        if self.p.coherence {
            for (nx, ny) in [(x - 1, y), (x + 1, y), (x, y - 1), (x, y + 1)] {
                if nx < 0 || ny < 0 || nx >= self.sp.wa || ny >= self.sp.ha {
                    continue;
                }
                nb.off[nb.n] = *off.add((ny * self.sp.wa + nx) as usize);
                nb.n += 1;
            }
        }
        nb
    }

    /// Coherence term `C` (eq. 4) of offset `d` at a pixel with neighbours `nb`: `d_c` is the
    /// distance of `d` to the closest current offset of a 4-neighbour.
    #[inline(always)]
    fn coherence(&self, nb: &Neighbours, d: [i32; 2]) -> f32 {
        if nb.n == 0 {
            return 1.0;
        }
        // Smallest squared distance first, then eq. 4 from the table.
        let mut d2 = i64::MAX;
        for o in &nb.off[..nb.n] {
            let (ex, ey) = ((d[0] - o[0]) as i64, (d[1] - o[1]) as i64);
            d2 = d2.min(ex * ex + ey * ey);
        }
        match self.coh.get(d2 as usize) {
            Some(&c) => c,
            None => coherence_of(d2, self.w, self.p.c_min),
        }
    }

    /// Cost `D = SSD / C` (eq. 2), stopping early above `bound`.
    #[inline]
    fn cost_of(&self, x: i32, y: i32, d: [i32; 2], bound: f32) -> f32 {
        self.cost_and_ssd(&self.neighbours(x, y), x, y, d, bound).0
    }

    /// `(D, SSD)` of offset `d`; both infinite once `D` is certain to exceed `bound`.
    #[inline(always)]
    fn cost_and_ssd(&self, nb: &Neighbours, x: i32, y: i32, d: [i32; 2], bound: f32) -> (f32, f32) {
        let c = self.coherence(nb, d);
        let s = self.sp.ssd(x, y, d, bound * c);
        // A rejected candidate costs no division: the visit moves on as soon as it is known.
        if s == f32::INFINITY {
            (s, s)
        } else {
            (s / c, s)
        }
    }

    /// Uniformly random allowed offsets, each row from its own stream (rows in parallel).
    fn init(&mut self) {
        let mut off = std::mem::take(&mut self.off);
        let this = &*self;
        off.par_chunks_mut(this.sp.wa as usize)
            .enumerate()
            .for_each(|(y, row)| {
                let mut r = rng::stream(this.p.seed, y as u64);
                let y = y as i32;
                let (yl, yh) = this.y_range(y);
                for (x, d) in row.iter_mut().enumerate() {
                    let (xl, xh) = this.x_range(x as i32);
                    *d = [r.random_range(xl..=xh), r.random_range(yl..=yh)];
                }
            });
        self.off = off;
    }

    /// One sweep (number `it`: forward when even): propagation then random search at every
    /// pixel, in scan order. Rows run on the pool's threads as a pipeline: a row visits a
    /// column only once the row before it (in scan order) has left that column, so every
    /// pixel sees exactly the neighbours the sequential scan would show it, and each row
    /// draws its random search from its own stream. The field therefore depends on the seed
    /// only, never on the thread count, and the sweep runs about as many times faster as
    /// there are threads.
    fn sweep(&mut self, it: usize) {
        let forward = it.is_multiple_of(2);
        let ha = self.sp.ha as usize;
        let (mut off, mut cost, mut ssd) = (
            std::mem::take(&mut self.off),
            std::mem::take(&mut self.cost),
            std::mem::take(&mut self.ssd),
        );
        let cells = Cells {
            off: off.as_mut_ptr(),
            cost: cost.as_mut_ptr(),
            ssd: ssd.as_mut_ptr(),
        };
        // Columns of each row (in scan order) already visited, and the next row to take.
        let done: Vec<AtomicUsize> = (0..ha).map(|_| AtomicUsize::new(0)).collect();
        let next = AtomicUsize::new(0);
        let this = &*self;
        let workers = rayon::current_num_threads().clamp(1, ha);
        (0..workers).into_par_iter().for_each(|_| loop {
            // Rows are taken in scan order, so the row a worker waits for is being visited
            // by a running worker (a worker makes no rayon calls while it holds a row).
            let k = next.fetch_add(1, Ordering::Relaxed);
            if k >= ha {
                break;
            }
            let y = if forward { k } else { ha - 1 - k } as i32;
            let mut r = rng::stream(this.p.seed, ((it as u64 + 1) << 32) | y as u64);
            let ahead = k.checked_sub(1).map(|j| &done[j]);
            let row = RowTurn {
                y,
                forward,
                ahead,
                done: &done[k],
            };
            let _unblock = UnblockOnPanic(&done[k]);
            // SAFETY: `cells` holds this run's `wa * ha` pixels; row `k` is visited by this
            // worker alone, and `visit_row` reads other rows only where the schedule allows.
            unsafe { this.visit_row(cells, row, &mut r) };
        });
        self.off = off;
        self.cost = cost;
        self.ssd = ssd;
    }

    /// [`Run::visit_row_body`], compiled for AVX2 when the CPU has it (the same arithmetic
    /// in the same order either way, so the same field).
    ///
    /// # Safety
    /// As [`Run::visit_row_body`].
    unsafe fn visit_row(&self, cells: Cells, row: RowTurn, r: &mut rng::Rng) {
        #[cfg(target_arch = "x86_64")]
        if self.sp.avx2 {
            // SAFETY: the CPU supports the feature the function is compiled for.
            return self.visit_row_avx2(cells, row, r);
        }
        self.visit_row_body(cells, row, r);
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn visit_row_avx2(&self, cells: Cells, row: RowTurn, r: &mut rng::Rng) {
        self.visit_row_body(cells, row, r);
    }

    /// Visits row `row.y` of a sweep in scan order. Before column `x` (its `j`-th) it waits
    /// until the row before it in scan order (`row.ahead`, `None` for the first row) has
    /// visited `j + 1` columns, and it publishes its own count in `row.done` every
    /// [`PUBLISH`] columns and at the end.
    ///
    /// # Safety
    /// `cells` points to `wa * ha` pixels; no other thread touches row `y`; the rows before
    /// `y` in scan order are visited under the same schedule (so the row ahead has written
    /// column `x` before this row reads it, and the row behind has not yet written column
    /// `x` when this row reads it for the coherence term).
    #[inline(always)]
    unsafe fn visit_row_body(&self, cells: Cells, row: RowTurn, r: &mut rng::Rng) {
        let RowTurn {
            y,
            forward,
            ahead,
            done,
        } = row;
        let (wa, ha) = (self.sp.wa, self.sp.ha);
        let step = if forward { -1 } else { 1 };
        let radius0 = if self.p.epipolar {
            self.w
        } else {
            wa.max(ha).max(self.sp.wb).max(self.sp.hb) as f32
        };
        let (yl, yh) = self.y_range(y);
        let mut seen = 0usize;
        for j in 0..wa as usize {
            if let Some(a) = ahead {
                wait_past(a, j, &mut seen);
            }
            let x = if forward { j as i32 } else { wa - 1 - j as i32 };
            let i = (y * wa + x) as usize;
            let mut best = *cells.off.add(i);
            let nb = self.neighbours_in(cells.off, x, y);
            // The current offset's SSD is kept from the visit that chose it.
            let kept = *cells.ssd.add(i);
            let (mut dbest, mut sbest) = if kept.is_nan() {
                self.cost_and_ssd(&nb, x, y, best, f32::INFINITY)
            } else {
                (kept / self.coherence(&nb, best), kept)
            };
            // The offsets allowed at this pixel.
            let (xl, xh) = self.x_range(x);
            // Propagation from the neighbours already visited in this sweep.
            for (nx, ny) in [(x + step, y), (x, y + step)] {
                if nx < 0 || ny < 0 || nx >= wa || ny >= ha {
                    continue;
                }
                let cand = *cells.off.add((ny * wa + nx) as usize);
                let allowed = (xl..=xh).contains(&cand[0]) && (yl..=yh).contains(&cand[1]);
                if cand != best && allowed {
                    let (dc, sc) = self.cost_and_ssd(&nb, x, y, cand, dbest);
                    if dc < dbest {
                        (best, dbest, sbest) = (cand, dc, sc);
                    }
                }
            }
            // Random search, eq. 1: u_i = v0 + w alpha^i R_i while w alpha^i >= 1.
            let mut rad = radius0;
            while rad >= 1.0 {
                let rx: f32 = r.random_range(-1.0..=1.0);
                let cx = (best[0] + round_nearest(rad * rx)).clamp(xl, xh);
                let cy = if yl < yh {
                    let ry: f32 = r.random_range(-1.0..=1.0);
                    let rv = if self.p.epipolar {
                        rad.min(self.p.v_tol as f32)
                    } else {
                        rad
                    };
                    (best[1] + round_nearest(rv * ry)).clamp(yl, yh)
                } else {
                    yl
                };
                let cand = [cx, cy];
                if cand != best {
                    let (dc, sc) = self.cost_and_ssd(&nb, x, y, cand, dbest);
                    if dc < dbest {
                        (best, dbest, sbest) = (cand, dc, sc);
                    }
                }
                rad *= self.p.alpha;
            }
            *cells.off.add(i) = best;
            *cells.cost.add(i) = dbest;
            *cells.ssd.add(i) = sbest;
            if (j + 1) % PUBLISH == 0 {
                done.store(j + 1, Ordering::Release);
            }
        }
        done.store(wa as usize, Ordering::Release);
    }
}

/// `v` rounded to the nearest integer, halves to even, for `|v| < 2^31`: the `round` of eq. 1's
/// `w alpha^i R_i`. Inside the AVX2 visit it is one `roundss` and a conversion; `f32::round`
/// (halves away from zero) is a library call on x86-64, and rounding halves away by hand
/// took about 7 % of a field's time. The two differ only on exact halves, which `R_i`'s
/// 24-bit resolution makes rare.
#[inline(always)]
fn round_nearest(v: f32) -> i32 {
    v.round_ties_even() as i32
}

/// Waits until the row ahead has visited column `j` (its count `ahead` exceeds `j`), spinning
/// briefly, then yielding; `seen` caches the last count read, so a row reads the shared count
/// only when its cached value is not enough.
#[inline(always)]
fn wait_past(ahead: &AtomicUsize, j: usize, seen: &mut usize) {
    let mut spins = 0u32;
    while *seen <= j {
        *seen = ahead.load(Ordering::Acquire);
        if *seen <= j {
            spins += 1;
            if spins < 1 << 12 {
                std::hint::spin_loop();
            } else {
                std::thread::yield_now();
            }
        }
    }
}

/// How many columns a row visits between two publications of its progress (fewer
/// cross-core messages; the row behind trails by at most this many columns more).
const PUBLISH: usize = 16;

/// One row's turn in a sweep: the row, the scan direction, the visited-column count of the
/// row ahead of it in scan order (`None` for the first) and its own.
#[derive(Clone, Copy)]
struct RowTurn<'a> {
    y: i32,
    forward: bool,
    ahead: Option<&'a AtomicUsize>,
    done: &'a AtomicUsize,
}

/// Marks a row as finished if its visit unwinds, so the rows behind it stop waiting and the
/// panic reaches the caller instead of hanging the sweep.
struct UnblockOnPanic<'a>(&'a AtomicUsize);

impl Drop for UnblockOnPanic<'_> {
    fn drop(&mut self) {
        if std::thread::panicking() {
            self.0.store(usize::MAX, Ordering::Release);
        }
    }
}

/// The per-pixel state of a run (offsets, costs, kept SSDs) as raw pointers, shared by the
/// row workers of one sweep, each of which writes only its own row.
#[derive(Clone, Copy)]
struct Cells {
    off: *mut [i32; 2],
    cost: *mut f32,
    ssd: *mut f32,
}

// SAFETY: the row schedule of `Run::sweep` keeps every access of one pixel on one thread at a
// time, ordered by the release/acquire counts of the rows.
unsafe impl Send for Cells {}
unsafe impl Sync for Cells {}

/// The nearest-neighbour field from `a` to `b` (paper section 3.1), with [`PatchMatchParams`]
/// choosing the paper's epipolar, coherence-penalised search (the default) or the original
/// 2-D PatchMatch ([`PatchMatchParams::barnes`]). Images may differ in size but not in channels.
///
/// Epipolar mode: offsets `(d, dy)` with `d` in `[d_min, d_max]` and `|dy| <= v_tol`, every
/// source centre inside `b`; initialised uniformly in that range (the paper: "random
/// transformation values within a maximal disparity range on the same epipolar line").
/// 2-D mode: sources anywhere in `b`, initialised uniformly over `b`, random search from
/// radius `max(W, H)`.
///
/// Errors: channel counts differ; non-finite values; invalid parameters (see
/// [`PatchMatchParams::validate`]).
pub fn patchmatch(a: &Image<f32>, b: &Image<f32>, p: &PatchMatchParams) -> Result<Nnf> {
    run_patchmatch(a, b, None, p)
}

/// [`patchmatch`] with per-sample weights `wa`, `wb` (same shapes as `a`, `b`; Khan weights
/// in the multiscopic driver): with `p.weighted_cost` every squared difference is multiplied
/// by `min(wa, wb)`, so clipped samples (weight 0) do not drive the match. Not in the paper,
/// which reports failures in saturated areas; an ablation.
///
/// Errors: as [`patchmatch`]; weights of other shapes or not finite.
pub fn patchmatch_weighted(
    a: &Image<f32>,
    b: &Image<f32>,
    wa: &Image<f32>,
    wb: &Image<f32>,
    p: &PatchMatchParams,
) -> Result<Nnf> {
    if wa.shape() != a.shape() || wb.shape() != b.shape() {
        return Err(Error::ShapeMismatch(
            "the weights must have the shapes of their images".into(),
        ));
    }
    wa.ensure_finite("wa")?;
    wb.ensure_finite("wb")?;
    let weights = p.weighted_cost.then_some((wa.data(), wb.data()));
    run_patchmatch(a, b, weights, p)
}

fn run_patchmatch(
    a: &Image<f32>,
    b: &Image<f32>,
    weights: Option<(&[f32], &[f32])>,
    p: &PatchMatchParams,
) -> Result<Nnf> {
    check_pair(a, b)?;
    let (ha, wa, c) = a.shape();
    let (hb, wb, _) = b.shape();
    p.validate(ha.min(hb), wa.min(wb))?;
    let n = ha * wa;
    // The 4-lane padded layout serves the weighted ablation and patch rows of fewer than 8
    // samples; otherwise every path reads the samples as they are and nothing is copied.
    let side = p.patch / 2 * 2 + 1;
    let pad = weights.is_some() || side * c < 8;
    let lay = |data| {
        if pad {
            padded(data, c)
        } else {
            std::borrow::Cow::Borrowed(data)
        }
    };
    let (pa, pb) = (lay(a.data()), lay(b.data()));
    let pw = weights.map(|(x, y)| (padded(x, c), padded(y, c)));
    let w = if p.epipolar {
        p.max_disp() as f32
    } else {
        wa.max(ha) as f32
    };
    let mut run = Run {
        sp: Space {
            a: &pa,
            b: &pb,
            ua: a.data(),
            ub: b.data(),
            avx2: avx2_available(),
            tail: tail_mask(side * c),
            weights: pw.as_ref().map(|(x, y)| (&x[..], &y[..])),
            wa: wa as i32,
            ha: ha as i32,
            wb: wb as i32,
            hb: hb as i32,
            c: if pad { c.div_ceil(4) * 4 } else { c },
            c_real: c,
            half: (p.patch / 2) as i32,
        },
        p: *p,
        off: vec![[0, 0]; n],
        cost: vec![f32::INFINITY; n],
        ssd: vec![f32::NAN; n],
        w,
        coh: coherence_table(p, w),
    };
    run.init();
    for it in 0..p.iters {
        run.sweep(it);
    }
    if p.iters == 0 {
        for y in 0..ha as i32 {
            for x in 0..wa as i32 {
                let i = (y * wa as i32 + x) as usize;
                run.cost[i] = run.cost_of(x, y, run.off[i], f32::INFINITY);
            }
        }
    }
    Nnf::new(ha, wa, run.off, run.cost)
}

/// The original PatchMatch (Barnes et al. 2009) baseline: 2-D, SSD only.
pub fn patchmatch_2d(
    a: &Image<f32>,
    b: &Image<f32>,
    patch: usize,
    iters: usize,
    seed: u64,
) -> Result<Nnf> {
    patchmatch(a, b, &PatchMatchParams::barnes(patch, iters, seed))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A row waits for column `j` of the row ahead until that row has visited `j + 1`
    /// columns: a count of exactly `j` (column `j` not yet written) keeps it waiting, `j + 1`
    /// releases it. A wait that returned at `j` (an off-by-one the thread-count test cannot
    /// see reliably) fails here.
    #[test]
    fn a_row_waits_until_the_row_ahead_has_left_the_column() {
        use std::sync::atomic::AtomicBool;
        use std::time::Duration;
        let ahead = AtomicUsize::new(7);
        let released = AtomicBool::new(false);
        let early = std::thread::scope(|s| {
            s.spawn(|| {
                let mut seen = 0;
                wait_past(&ahead, 7, &mut seen);
                released.store(true, Ordering::SeqCst);
                assert!(seen >= 8, "{seen}");
            });
            std::thread::sleep(Duration::from_millis(100));
            let early = released.load(Ordering::SeqCst);
            // Released in any case, so a failing check cannot leave the waiter spinning.
            ahead.store(8, Ordering::Release);
            early
        });
        assert!(!early, "released at count 7 for column 7");
        assert!(released.load(Ordering::SeqCst));
        // A cached count that is already past the column does not read the shared one.
        let mut seen = 12;
        wait_past(&AtomicUsize::new(0), 11, &mut seen);
        assert_eq!(seen, 12);
    }

    /// A row whose visit unwinds marks itself finished (so the rows behind it stop waiting);
    /// a row that returns normally leaves its count to its own stores.
    #[test]
    fn an_unwinding_row_releases_the_rows_behind_it() {
        let done = AtomicUsize::new(3);
        let caught = std::panic::catch_unwind(|| {
            let _unblock = UnblockOnPanic(&done);
            panic!("visit failed");
        });
        assert!(caught.is_err());
        assert_eq!(done.load(Ordering::Acquire), usize::MAX);
        let done = AtomicUsize::new(3);
        {
            let _unblock = UnblockOnPanic(&done);
        }
        assert_eq!(done.load(Ordering::Acquire), 3);
    }

    /// The random search's rounding: integers and quarters to the nearest integer, exact
    /// halves to the even neighbour and their float neighbours to the nearer integer; random
    /// products of a radius and a draw in [-1, 1] within a half of their rounding.
    #[test]
    fn rounding_is_to_the_nearest_integer_halves_to_even() {
        let mut r = rng::seeded(11);
        for k in -200..=200 {
            let v = k as f32;
            assert_eq!(round_nearest(v), k);
            assert_eq!(round_nearest(v + 0.25), k);
            assert_eq!(round_nearest(v - 0.25), k);
            // Exact halves go to the even neighbour; just off a half, to the nearer one.
            let h = v + 0.5;
            assert_eq!(round_nearest(h), if k % 2 == 0 { k } else { k + 1 }, "{h}");
            assert_eq!(round_nearest(h.next_up()), k + 1, "{h}");
            assert_eq!(round_nearest(h.next_down()), k, "{h}");
        }
        for _ in 0..100_000 {
            let rad: f32 = r.random_range(1.0..2000.0);
            let v = rad * r.random_range(-1.0f32..=1.0);
            let k = round_nearest(v);
            assert!((v - k as f32).abs() <= 0.5, "{v} -> {k}");
        }
    }

    /// The coherence table holds eq. 4 for every squared distance up to where it reaches
    /// `c_min`, beyond which eq. 4 gives `c_min`; without the coherence term it is empty.
    #[test]
    fn coherence_table_is_eq_4_up_to_c_min() {
        for (d, c_min) in [(64, 0.05f32), (7, 0.3), (300, 0.2)] {
            let p = PatchMatchParams {
                d_min: -d,
                d_max: d,
                c_min,
                ..PatchMatchParams::default()
            };
            let w = p.max_disp() as f32;
            let t = coherence_table(&p, w);
            for (k, &c) in t.iter().enumerate() {
                assert_eq!(c.to_bits(), coherence_of(k as i64, w, c_min).to_bits());
            }
            assert_eq!(t[0], 1.0);
            assert_eq!(*t.last().unwrap(), c_min);
            assert!(t[t.len() - 2] > c_min);
            // Where 1 - sqrt(d2) / w first drops to c_min.
            let edge = (w * (1.0 - c_min)).powi(2);
            assert!(
                (t.len() as f32 - 1.0 - edge).abs() <= 2.0 + 1e-3 * edge,
                "{}",
                t.len()
            );
            for k in [t.len(), t.len() + 1, 4 * t.len()] {
                assert_eq!(coherence_of(k as i64, w, c_min), c_min);
            }
        }
        // A wide range: the table stops at 2^16 entries, short of c_min.
        let wide = PatchMatchParams {
            d_min: -1000,
            d_max: 1000,
            ..PatchMatchParams::default()
        };
        assert_eq!(coherence_table(&wide, 1000.0).len(), 1 << 16);
        let off = PatchMatchParams {
            coherence: false,
            ..PatchMatchParams::default()
        };
        assert!(coherence_table(&off, 64.0).is_empty());
    }

    /// The coherence term a visit computes (neighbours read once, eq. 4 from the table)
    /// equals eq. 4 evaluated directly: `max(1 - d_c / Max_disp, c_min)` with `d_c` the
    /// distance to the closest current offset of a 4-neighbour inside the image, 1 without
    /// neighbours. Offsets are random, 2-D (a vertical tolerance), and reach past the table.
    #[test]
    fn coherence_equals_eq_4_evaluated_directly() {
        let mut r = rng::seeded(5);
        let (h, w) = (9i32, 11i32);
        let zeros = vec![0f32; (h * w) as usize * 4];
        let p = PatchMatchParams {
            d_min: -40,
            d_max: 40,
            v_tol: 6,
            c_min: 0.05,
            ..PatchMatchParams::default()
        };
        let wmax = p.max_disp() as f32;
        let off: Vec<[i32; 2]> = (0..h * w)
            .map(|_| [r.random_range(-40..=40), r.random_range(-6..=6)])
            .collect();
        let run = Run {
            sp: Space {
                a: &zeros,
                b: &zeros,
                ua: &zeros,
                ub: &zeros,
                tail: tail_mask(28),
                avx2: false,
                weights: None,
                wa: w,
                ha: h,
                wb: w,
                hb: h,
                c: 4,
                c_real: 4,
                half: 3,
            },
            p,
            off: off.clone(),
            cost: vec![0.0; off.len()],
            ssd: vec![f32::NAN; off.len()],
            w: wmax,
            coh: coherence_table(&p, wmax),
        };
        for _ in 0..2000 {
            let (x, y) = (r.random_range(0..w), r.random_range(0..h));
            let d = [r.random_range(-80..=80), r.random_range(-12..=12)];
            let mut dc = f64::INFINITY;
            for (nx, ny) in [(x - 1, y), (x + 1, y), (x, y - 1), (x, y + 1)] {
                if (0..w).contains(&nx) && (0..h).contains(&ny) {
                    let o = off[(ny * w + nx) as usize];
                    dc = dc.min(f64::from(d[0] - o[0]).hypot(f64::from(d[1] - o[1])));
                }
            }
            let want = (1.0 - dc / f64::from(wmax)).max(0.05);
            let got = run.coherence(&run.neighbours(x, y), d);
            assert!(
                (f64::from(got) - want).abs() <= 1e-6,
                "({x}, {y}) {d:?}: {got} vs {want}"
            );
        }
        // A 1 x 1 image: no neighbours.
        let lone = Run {
            sp: Space {
                wa: 1,
                ha: 1,
                ..run.sp
            },
            off: vec![[3, 0]],
            coh: Vec::new(),
            ..run
        };
        assert_eq!(lone.coherence(&lone.neighbours(0, 0), [-30, 2]), 1.0);
        // Without the coherence term: no neighbours are read and every offset has C = 1.
        let plain = Run {
            sp: Space {
                wa: w,
                ha: h,
                ..lone.sp
            },
            p: PatchMatchParams {
                coherence: false,
                ..p
            },
            off,
            coh: Vec::new(),
            ..lone
        };
        assert_eq!(plain.neighbours(4, 4).n, 0);
        assert_eq!(plain.coherence(&plain.neighbours(4, 4), [-30, 2]), 1.0);
    }

    /// The unpadded interior distance gives the same sums with the portable rows and with
    /// the AVX2 rows (where the CPU has them), for every channel count and patch size, and
    /// equals the mean squared difference computed in `f64`; the early exit still returns a
    /// value above the bound.
    #[test]
    fn interior_kernels_agree_bit_for_bit() {
        let mut r = rng::seeded(7);
        for c in 1..=5usize {
            for patch in [3usize, 5, 7, 9] {
                let (h, w) = (17i32, 23i32);
                let n = (h * w) as usize * c;
                let a: Vec<f32> = (0..n).map(|_| r.random_range(0.0..4.0)).collect();
                let b: Vec<f32> = (0..n).map(|_| r.random_range(0.0..4.0)).collect();
                let (pa, pb) = (padded(&a, c), padded(&b, c));
                let half = (patch / 2) as i32;
                let space = |avx2: bool| Space {
                    a: &pa,
                    b: &pb,
                    ua: &a,
                    ub: &b,
                    tail: tail_mask(patch * c),
                    avx2,
                    weights: None,
                    wa: w,
                    ha: h,
                    wb: w,
                    hb: h,
                    c: c.div_ceil(4) * 4,
                    c_real: c,
                    half,
                };
                let (portable, simd) = (space(false), space(avx2_available()));
                for _ in 0..50 {
                    let (x, y) = (
                        r.random_range(half..w - half),
                        r.random_range(half..h - half),
                    );
                    let d = [
                        r.random_range(half - x..w - half - x),
                        r.random_range(half - y..h - half - y),
                    ];
                    let s0 = portable.ssd_interior(x, y, d, f32::INFINITY);
                    let s1 = simd.ssd_interior(x, y, d, f32::INFINITY);
                    assert_eq!(s0.to_bits(), s1.to_bits(), "c {c} patch {patch}");
                    let mut e = 0f64;
                    for oy in -half..=half {
                        for ox in -half..=half {
                            for k in 0..c {
                                let ia = ((y + oy) * w + x + ox) as usize * c + k;
                                let ib = ((y + oy + d[1]) * w + x + ox + d[0]) as usize * c + k;
                                e += (f64::from(a[ia]) - f64::from(b[ib])).powi(2);
                            }
                        }
                    }
                    let e = e / (patch * patch * c) as f64;
                    assert!((f64::from(s0) - e).abs() <= 1e-5 * e, "{s0} vs {e}");
                    let bound = 0.5 * s0;
                    let (t0, t1) = (
                        portable.ssd_interior(x, y, d, bound),
                        simd.ssd_interior(x, y, d, bound),
                    );
                    assert_eq!(t0.to_bits(), t1.to_bits());
                    assert!(t0 > bound);
                }
            }
        }
    }
}
