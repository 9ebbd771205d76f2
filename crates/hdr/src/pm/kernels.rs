//! The sums of squared differences under the patch distance: portable kernels on lanes
//! of 4 and 8 floats, and the AVX2 rows used when the CPU has them (the same operations in
//! the same order as the portable 8-lane rows, so the same sums).

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
pub(super) fn sq_diff_lanes(a: &[f32], b: &[f32], acc: &mut Lanes) {
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
pub(super) fn sq_diff_row8(
    a: &[f32],
    b: &[f32],
    tail: &[f32; 8],
    a0: &mut [f32; 8],
    a1: &mut [f32; 8],
) {
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
pub(super) fn lanes8_sum(a0: &[f32; 8], a1: &[f32; 8]) -> f32 {
    let v: [f32; 8] = std::array::from_fn(|k| a0[k] + a1[k]);
    let t: [f32; 4] = std::array::from_fn(|k| v[k] + v[k + 4]);
    (t[0] + t[2]) + (t[1] + t[3])
}

/// The rows of [`Space::ssd_interior_unpadded`](super::cost::Space::ssd_interior_unpadded) with AVX intrinsics: the same operations in
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
pub(super) unsafe fn ssd_rows_avx2(
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
pub(super) unsafe fn ssd_rows_avx2_7x21(
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
pub(super) fn lanes_sum(acc: &Lanes) -> f32 {
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
pub(super) fn sq_diff(a: &[f32], b: &[f32]) -> f32 {
    let mut acc = [[0f32; 4]; 4];
    sq_diff_lanes(a, b, &mut acc);
    lanes_sum(&acc)
}

/// The samples of `img` with channels padded by zeros to a multiple of 4 (so a patch row is
/// whole SIMD registers); borrowed as they are when already a multiple.
pub(super) fn padded(data: &[f32], c: usize) -> std::borrow::Cow<'_, [f32]> {
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
pub(super) fn sq_diff_weighted(a: &[f32], b: &[f32], wa: &[f32], wb: &[f32]) -> f32 {
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

/// The lane mask of the last chunk of a row of `len` samples in [`sq_diff_row8`]: zero on
/// the lanes that chunk shares with the one before it.
pub(super) fn tail_mask(len: usize) -> [f32; 8] {
    std::array::from_fn(|k| {
        if len.is_multiple_of(8) || k >= 8 - len % 8 {
            1.0
        } else {
            0.0
        }
    })
}

/// Whether the CPU has AVX2 (detected at run time).
pub(super) fn avx2_available() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}
