//! The matching cost of eq. 2, `D = SSD / C`: the mean squared difference of two patches
//! (eq. 3) over the images of a match, stopping early above a bound, and the coherence term
//! `C` of eq. 4 tabulated over the integer squared distances.

use super::kernels::{
    lanes8_sum, lanes_sum, sq_diff, sq_diff_lanes, sq_diff_row8, sq_diff_weighted,
};
#[cfg(target_arch = "x86_64")]
use super::kernels::{ssd_rows_avx2, ssd_rows_avx2_7x21};
use super::PatchMatchParams;

/// Added to weighted costs so that, where every sample is clipped (cost 0), the coherence
/// term still ranks the candidates.
const WEIGHTED_FLOOR: f32 = 1e-30;

/// The two images of a match and the patch half-size.
pub(super) struct Space<'a> {
    /// The samples of `a` and `b` in the layout of `c` channels: padded to a multiple of 4
    /// for the weighted ablation and short patch rows, else the samples as they are.
    pub(super) a: &'a [f32],
    pub(super) b: &'a [f32],
    /// The samples of `a` and `b` without channel padding, for interior patches whose rows
    /// hold at least 8 samples.
    pub(super) ua: &'a [f32],
    pub(super) ub: &'a [f32],
    /// Lane mask of the last, overlapping chunk of such a row (see [`sq_diff_row8`]).
    pub(super) tail: [f32; 8],
    /// Whether the CPU has AVX2 ([`ssd_rows_avx2`]).
    pub(super) avx2: bool,
    /// Per-sample weights of `a` and `b` (the weighted-cost ablation).
    pub(super) weights: Option<(&'a [f32], &'a [f32])>,
    pub(super) wa: i32,
    pub(super) ha: i32,
    pub(super) wb: i32,
    pub(super) hb: i32,
    /// Channels of the layout of `a` and `b` (padded or not).
    pub(super) c: usize,
    /// Channels of the images (what a mean counts).
    pub(super) c_real: usize,
    pub(super) half: i32,
}

impl Space<'_> {
    /// Mean squared difference (eq. 3, per valid pixel and channel so border patches are
    /// comparable) between the patch of `A` at `(x, y)` and the patch of `B` at
    /// `(x + dx, y + dy)`, over the offsets inside both images. Stops early and returns
    /// infinity once the mean is certain to exceed `bound` (no division on that path);
    /// infinite without overlap.
    #[inline(always)]
    pub(super) fn ssd(&self, x: i32, y: i32, d: [i32; 2], bound: f32) -> f32 {
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
    pub(super) fn ssd_interior(&self, x: i32, y: i32, d: [i32; 2], bound: f32) -> f32 {
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

/// Coherence `C = max(1 - d_c / Max_disp, c_min)` of eq. 4 for a squared distance
/// `d2 = d_c^2` to the closest neighbouring offset.
pub(super) fn coherence_of(d2: i64, w: f32, c_min: f32) -> f32 {
    (1.0 - (d2 as f64).sqrt() as f32 / w).max(c_min)
}

/// [`coherence_of`] for `d2 = 0, 1, ...` up to the first value where it equals `c_min`
/// (every larger `d2` gives `c_min` too), at most 2^16 entries; empty without the coherence
/// term.
pub(super) fn coherence_table(p: &PatchMatchParams, w: f32) -> Vec<f32> {
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

#[cfg(test)]
mod tests {
    use rand::Rng as _;
    use wscg_math::rng;

    use super::super::kernels::{avx2_available, padded, tail_mask};
    use super::*;

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
