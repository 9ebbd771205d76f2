//! The search of one PatchMatch run: random initialisation, then per sweep and pixel the
//! propagation from the neighbours already visited and the random search of eq. 1, each
//! candidate ranked by the cost of eq. 2 ([`super::cost`]). The rows of a sweep are visited
//! under the pipeline of [`super::schedule`].

use std::sync::atomic::Ordering;

use rand::Rng as _;
use rayon::prelude::*;
use wscg_math::rng;

use super::cost::{coherence_of, Space};
use super::schedule::{self, wait_past, Cells, RowTurn, PUBLISH};
use super::PatchMatchParams;

/// The current offsets of a pixel's 4-neighbours inside the image: `off[..n]`.
struct Neighbours {
    off: [[i32; 2]; 4],
    n: usize,
}

/// The state of one PatchMatch run.
pub(super) struct Run<'a> {
    pub(super) sp: Space<'a>,
    pub(super) p: PatchMatchParams,
    pub(super) off: Vec<[i32; 2]>,
    pub(super) cost: Vec<f32>,
    /// The SSD of each pixel's current offset (NaN until first computed). A pixel's cost
    /// changes between visits only through its neighbours' offsets in the coherence term, so
    /// a visit recomputes `C` but not the SSD.
    pub(super) ssd: Vec<f32>,
    /// `Max_disp` of the coherence term and `w` of the random search.
    pub(super) w: f32,
    /// `C` of eq. 4 for the squared distances `d_c^2` of [`coherence_table`] (computed by
    /// [`coherence_of`] beyond it), so a candidate costs no square root.
    pub(super) coh: Vec<f32>,
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
    pub(super) fn cost_of(&self, x: i32, y: i32, d: [i32; 2], bound: f32) -> f32 {
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
    pub(super) fn init(&mut self) {
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
    /// pixel, in scan order. Rows run on the pool's threads as a pipeline
    /// ([`schedule::pipeline`]): a row visits a column only once the row before it (in scan
    /// order) has left that column, so every pixel sees exactly the neighbours the sequential
    /// scan would show it, and each row draws its random search from its own stream. The field therefore depends on the seed
    /// only, never on the thread count, and the sweep runs about as many times faster as
    /// there are threads.
    pub(super) fn sweep(&mut self, it: usize) {
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
        let this = &*self;
        schedule::pipeline(ha, forward, |row| {
            let mut r = rng::stream(this.p.seed, ((it as u64 + 1) << 32) | row.y as u64);
            // SAFETY: `cells` holds this run's `wa * ha` pixels; the row is visited by this
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

#[cfg(test)]
mod tests {
    use super::super::cost::coherence_table;
    use super::super::kernels::tail_mask;
    use super::*;

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
}
