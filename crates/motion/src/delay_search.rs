//! Search of one channel's delays, shared over trials, with the sources held: the polish that
//! [`crate::anechoic::fit_anechoic`] runs after its alternating least squares
//! ([`AnechoicParams::delay_search`](crate::anechoic::AnechoicParams::delay_search)).
//!
//! With the sources `c_j` fixed, channel `i`'s delays enter its fit only through the delayed
//! sources `d_p = e^{−2πikτ_p} c_p`. Taking every trial's weights at their least-squares
//! optimum (variable projection), the channel's squared in-band residual is
//!
//! ```text
//! f(τ) = Σ_r ‖x_r‖² − Σ_r b_rᵀ G⁻¹ b_r,    G_pq = Re⟨d_p, d_q⟩,    b_rp = Re⟨d_p, x_r⟩.
//! ```
//!
//! The ALS delay step moves one delay with the weights held. In a channel whose trial weights
//! are nearly proportional, two delayed sources can then only improve the fit by moving
//! together, and the ALS stops in a neighbouring optimum (one channel of the noisy synthetic
//! walker ends 0.41 periods off, its residual 19 % above that of the optimum next to the
//! generating delays). The search evaluates `f` on an `M × M` grid of every pair of delays
//! (the others held), keeps the deepest local minima of each pair's grid, and takes each to the
//! bottom of its basin by damped Newton steps on `f`.
//!
//! On the grid, `G_pq` depends only on `τ_q − τ_p` and `b_rp` only on `τ_p`, so both come from
//! tables of `M` entries per source, and adding source `q` to the others is a Schur
//! complement: a grid point costs one `R`-term sum plus `O(J²)`.

use std::cell::RefCell;

use num_complex::Complex64;

use crate::fourier::{delayed, re_dot, wrap_half};
use crate::linalg::solve_in_place;

/// Relative drop of a channel's residual that makes its new delays a better basin (smaller
/// drops are the ALS's own convergence, which the ALS finishes).
const BASIN_GAIN: f64 = 1e-3;
/// ... and by at least this share of the channel's data energy (the scale of the ALS's default
/// tolerance on `Q`).
const ENERGY_GAIN: f64 = 1e-9;
/// Smallest delay change (periods) that makes refined delays another basin than the current
/// one.
const BASIN_SHIFT: f64 = 0.01;
/// Local minima of each pair's grid that are refined.
const MINIMA_PER_PAIR: usize = 3;
/// Newton steps of a refinement at most.
const NEWTON_STEPS: usize = 100;
/// Central-difference step of the derivatives (periods).
const FD_STEP: f64 = 1e-5;

/// One channel's delay problem: the sources and the channel's data harmonics.
pub(crate) struct ChannelDelays<'a> {
    /// `J × K` source harmonics.
    c: &'a [Complex64],
    /// `R × K` data harmonics of the channel.
    x: Vec<Complex64>,
    j: usize,
    k: usize,
    r: usize,
    /// `Σ_r ‖x_r‖²`.
    energy: f64,
    /// Workspace of [`ChannelDelays::residual`]: the delayed sources (`J × K`), and `G`, `C`,
    /// one trial's projections and `G⁻¹` (`3 J² + J`).
    work_c: RefCell<Vec<Complex64>>,
    work_f: RefCell<Vec<f64>>,
}

impl<'a> ChannelDelays<'a> {
    /// The problem of sources `c` (`J × K`) and the channel's rows `rows` (`K` harmonics each).
    pub(crate) fn new<'r>(
        c: &'a [Complex64],
        k: usize,
        rows: impl Iterator<Item = &'r [Complex64]>,
    ) -> Self {
        let x: Vec<Complex64> = rows.flat_map(|row| row.iter().copied()).collect();
        let energy = x.iter().map(|v| v.norm_sqr()).sum();
        let j = c.len() / k;
        Self {
            c,
            work_c: RefCell::new(vec![Complex64::new(0.0, 0.0); j * k]),
            work_f: RefCell::new(vec![0.0; 3 * j * j + j]),
            j,
            k,
            r: x.len() / k,
            x,
            energy,
        }
    }

    fn source(&self, p: usize) -> &[Complex64] {
        &self.c[p * self.k..(p + 1) * self.k]
    }

    fn row(&self, r: usize) -> &[Complex64] {
        &self.x[r * self.k..(r + 1) * self.k]
    }

    /// `f(τ)`, the squared residual with least-squares weights (`+∞` when the delayed sources
    /// are linearly dependent).
    pub(crate) fn residual(&self, tau: &[f64]) -> f64 {
        let (j_n, k) = (self.j, self.k);
        let (mut d, mut ws) = (self.work_c.borrow_mut(), self.work_f.borrow_mut());
        for (p, dp) in d.chunks_exact_mut(k).enumerate() {
            delayed(tau[p], self.source(p), dp);
        }
        let (g, rest) = ws.split_at_mut(j_n * j_n);
        let (c, rest) = rest.split_at_mut(j_n * j_n);
        let (b, inv) = rest.split_at_mut(j_n);
        for p in 0..j_n {
            for q in 0..j_n {
                g[p * j_n + q] = re_dot(&d[p * k..(p + 1) * k], &d[q * k..(q + 1) * k]);
            }
        }
        c.fill(0.0);
        for r in 0..self.r {
            for (p, bp) in b.iter_mut().enumerate() {
                *bp = re_dot(&d[p * k..(p + 1) * k], self.row(r));
            }
            for p in 0..j_n {
                for q in 0..j_n {
                    c[p * j_n + q] += b[p] * b[q];
                }
            }
        }
        if spd_inverse(g, j_n, inv) {
            (self.energy - trace_product(inv, c)).max(0.0)
        } else {
            f64::INFINITY
        }
    }

    /// Searches delays with a lower [`ChannelDelays::residual`] than at `tau`, on `grid`
    /// points per period for each pair of delays. Returns the best delays found (wrapped to
    /// `[-0.5, 0.5)`) and their residual when some delay lies more than [`BASIN_SHIFT`] from
    /// `tau` and the residual at `tau` drops by more than [`BASIN_GAIN`] and [`ENERGY_GAIN`].
    pub(crate) fn search(&self, tau: &[f64], grid: usize) -> Option<(Vec<f64>, f64)> {
        let f0 = self.residual(tau);
        // Drops below the ALS tolerance (relative to the data energy) are not new basins; a
        // channel already fitted that well has none to find.
        let gain = (BASIN_GAIN * f0).max(ENERGY_GAIN * self.energy);
        if f0 <= gain {
            return None;
        }
        let mut best: Option<(Vec<f64>, f64)> = None;
        for p in 0..self.j {
            for q in p + 1..self.j {
                for mut t in self.pair_minima(tau, p, q, grid) {
                    let f = self.refine(&mut t);
                    // The current basin is the ALS's to finish: only delays elsewhere count.
                    let moved = t
                        .iter()
                        .zip(tau)
                        .any(|(a, b)| wrap_half(a - b).abs() > BASIN_SHIFT);
                    if moved && f < best.as_ref().map_or(f0, |b| b.1) {
                        best = Some((t, f));
                    }
                }
            }
        }
        best.filter(|b| b.1 < f0 - gain)
    }

    /// The deepest [`MINIMA_PER_PAIR`] local minima of [`ChannelDelays::pair_grid`] (the
    /// 8-neighbourhood wraps around), each as a full delay vector.
    fn pair_minima(&self, tau: &[f64], p: usize, q: usize, m: usize) -> Vec<Vec<f64>> {
        let values = self.pair_grid(tau, p, q, m);
        let mut minima: Vec<(f64, usize, usize)> = Vec::new();
        for a in 0..m {
            for b in 0..m {
                let v = values[a * m + b];
                let lowest = v.is_finite()
                    && (0..9).filter(|&n| n != 4).all(|n| {
                        let (da, db) = (n / 3 + m - 1, n % 3 + m - 1);
                        v < values[((a + da) % m) * m + (b + db) % m]
                    });
                if lowest {
                    minima.push((v, a, b));
                }
            }
        }
        minima.sort_by(|x, y| x.0.total_cmp(&y.0));
        minima
            .into_iter()
            .take(MINIMA_PER_PAIR)
            .map(|(_, a, b)| {
                let mut t = tau.to_vec();
                t[p] = a as f64 / m as f64;
                t[q] = b as f64 / m as f64;
                t
            })
            .collect()
    }

    /// `f` over the `m × m` grid of `(τ_p, τ_q) = (a / m, b / m)` (row `a`), the other delays
    /// as in `tau`; `+∞` where the delayed sources are dependent.
    ///
    /// For each grid value of `τ_p`, the "rest" (source `p` and the held ones) is projected out
    /// once: with `A` its Gram matrix, `β_r` its projections of trial `r` and `C_ββ = Σ_r β_r β_rᵀ`,
    /// adding source `q` lowers `f` by `Σ_r (b_rq − uᵀ β_r)² / γ` with `u = A⁻¹ g_q` (`g_q`: the
    /// Gram entries of `q` with the rest) and `γ = ‖c_q‖² − g_qᵀ u`; the numerator is
    /// `C_qq − 2 uᵀ c_q + uᵀ C_ββ u`, so a grid point costs one `R`-term sum and `O(J²)`.
    fn pair_grid(&self, tau: &[f64], p: usize, q: usize, m: usize) -> Vec<f64> {
        let (j_n, k, r_n) = (self.j, self.k, self.r);
        let held: Vec<usize> = (0..j_n).filter(|&o| o != p && o != q).collect();
        let n_h = held.len();
        // The rest: source p first, then the held sources.
        let n_b = n_h + 1;
        let zero = Complex64::new(0.0, 0.0);
        let grid_of = |s: usize| {
            let mut t = vec![zero; m * k];
            for (a, row) in t.chunks_exact_mut(k).enumerate() {
                delayed(a as f64 / m as f64, self.source(s), row);
            }
            t
        };
        let (dp, dq) = (grid_of(p), grid_of(q));
        let proj = |d: &[Complex64]| -> Vec<f64> {
            d.chunks_exact(k)
                .flat_map(|da| (0..r_n).map(move |r| re_dot(da, self.row(r))))
                .collect()
        };
        let (bp, bq) = (proj(&dp), proj(&dq));
        let d_h: Vec<Complex64> = held
            .iter()
            .flat_map(|&o| {
                let mut v = vec![zero; k];
                delayed(tau[o], self.source(o), &mut v);
                v
            })
            .collect();
        let b_h = proj(&d_h);
        let dot_r = |x: &[f64], y: &[f64]| -> f64 { x.iter().zip(y).map(|(a, b)| a * b).sum() };
        // Per grid value b of τ_q, stored as rows over b (so the loops over b vectorize): the
        // Gram and C entries of q with the rest (row 0, source p, is filled per τ_p; rows
        // 1.. are the held sources), and C_qq. `bq_t` is `R × m`.
        let mut g_row = vec![0.0; n_b * m];
        let mut c_row = vec![0.0; n_b * m];
        let mut c_qq = vec![0.0; m];
        let mut bq_t = vec![0.0; r_n * m];
        for b in 0..m {
            let (db, bb) = (&dq[b * k..(b + 1) * k], &bq[b * r_n..(b + 1) * r_n]);
            for hi in 0..n_h {
                g_row[(hi + 1) * m + b] = re_dot(db, &d_h[hi * k..(hi + 1) * k]);
                c_row[(hi + 1) * m + b] = dot_r(bb, &b_h[hi * r_n..(hi + 1) * r_n]);
            }
            c_qq[b] = dot_r(bb, bb);
            for (r, &v) in bb.iter().enumerate() {
                bq_t[r * m + b] = v;
            }
        }
        // G_pq as a function of τ_q − τ_p.
        let h: Vec<f64> = dq
            .chunks_exact(k)
            .map(|row| re_dot(self.source(p), row))
            .collect();
        let norm_q = re_dot(self.source(q), self.source(q));
        let mut values = vec![f64::INFINITY; m * m];
        let mut a_mat = vec![0.0; n_b * n_b];
        let mut c_bb = vec![0.0; n_b * n_b];
        let mut a_inv = vec![0.0; n_b * n_b];
        let mut a_copy = vec![0.0; n_b * n_b];
        // u = A⁻¹ g_q, and the numerator and γ of every b.
        let mut u = vec![0.0; n_b * m];
        let (mut num, mut gamma) = (vec![0.0; m], vec![0.0; m]);
        for a in 0..m {
            let (da, ba) = (&dp[a * k..(a + 1) * k], &bp[a * r_n..(a + 1) * r_n]);
            // The rest's Gram matrix and C block at this τ_p.
            let rest_d = |i: usize| if i == 0 { da } else { &d_h[(i - 1) * k..i * k] };
            let rest_b = |i: usize| {
                if i == 0 {
                    ba
                } else {
                    &b_h[(i - 1) * r_n..i * r_n]
                }
            };
            for i in 0..n_b {
                for j in 0..n_b {
                    a_mat[i * n_b + j] = re_dot(rest_d(i), rest_d(j));
                    c_bb[i * n_b + j] = dot_r(rest_b(i), rest_b(j));
                }
            }
            // A⁻¹, and the rest's own gain tr(A⁻¹ C_ββ).
            a_copy.copy_from_slice(&a_mat);
            if !spd_inverse(&mut a_copy, n_b, &mut a_inv) {
                continue;
            }
            let base = trace_product(&a_inv, &c_bb);
            // Row 0: G_pq(b − a) and C_pq(a, b) = Σ_r b_rp(a) b_rq(b).
            let (g0, c0) = (&mut g_row[..m], &mut c_row[..m]);
            // Entry b is h[(b − a) mod m].
            g0[a..].copy_from_slice(&h[..m - a]);
            g0[..a].copy_from_slice(&h[m - a..]);
            c0.fill(0.0);
            for (r, &w) in ba.iter().enumerate() {
                c0.iter_mut()
                    .zip(&bq_t[r * m..(r + 1) * m])
                    .for_each(|(c, &v)| *c += w * v);
            }
            u.fill(0.0);
            for i in 0..n_b {
                let ui = &mut u[i * m..(i + 1) * m];
                for j in 0..n_b {
                    let aij = a_inv[i * n_b + j];
                    ui.iter_mut()
                        .zip(&g_row[j * m..(j + 1) * m])
                        .for_each(|(x, &g)| *x += aij * g);
                }
            }
            gamma.fill(norm_q);
            num.copy_from_slice(&c_qq);
            for i in 0..n_b {
                let ui = &u[i * m..(i + 1) * m];
                let (gi, ci) = (&g_row[i * m..(i + 1) * m], &c_row[i * m..(i + 1) * m]);
                for b in 0..m {
                    gamma[b] -= gi[b] * ui[b];
                    num[b] -= 2.0 * ci[b] * ui[b];
                }
                for j in 0..n_b {
                    let cij = c_bb[i * n_b + j];
                    let uj = &u[j * m..(j + 1) * m];
                    for b in 0..m {
                        num[b] += cij * ui[b] * uj[b];
                    }
                }
            }
            let row = &mut values[a * m..(a + 1) * m];
            for b in 0..m {
                if gamma[b] > 1e-12 * norm_q {
                    row[b] = self.energy - base - num[b] / gamma[b];
                }
            }
        }
        values
    }

    /// Damped Newton descent (Levenberg-Marquardt) on [`ChannelDelays::residual`] from
    /// `tau`, with central-difference derivatives: `f` is a smooth function of the `J`
    /// delays, and its basins on ill-conditioned channels are long narrow valleys where
    /// single-delay steps crawl. Leaves the delays (wrapped) in `tau` and returns `f` there.
    fn refine(&self, tau: &mut [f64]) -> f64 {
        let j_n = self.j;
        let mut f = self.residual(tau);
        let mut lambda = 1e-3;
        let mut at = tau.to_vec();
        let mut eval = |t: &[f64], moves: &[(usize, f64)]| {
            at.copy_from_slice(t);
            for &(i, d) in moves {
                at[i] += d;
            }
            self.residual(&at)
        };
        for _ in 0..NEWTON_STEPS {
            if !f.is_finite() {
                break;
            }
            let (mut grad, mut hess) = (vec![0.0; j_n], vec![0.0; j_n * j_n]);
            for a in 0..j_n {
                let (fp, fm) = (eval(tau, &[(a, FD_STEP)]), eval(tau, &[(a, -FD_STEP)]));
                grad[a] = (fp - fm) / (2.0 * FD_STEP);
                hess[a * j_n + a] = (fp - 2.0 * f + fm) / (FD_STEP * FD_STEP);
                for b in 0..a {
                    let v = (eval(tau, &[(a, FD_STEP), (b, FD_STEP)])
                        - eval(tau, &[(a, FD_STEP), (b, -FD_STEP)])
                        - eval(tau, &[(a, -FD_STEP), (b, FD_STEP)])
                        + eval(tau, &[(a, -FD_STEP), (b, -FD_STEP)]))
                        / (4.0 * FD_STEP * FD_STEP);
                    hess[a * j_n + b] = v;
                    hess[b * j_n + a] = v;
                }
            }
            if !grad.iter().chain(&hess).all(|v| v.is_finite()) {
                break;
            }
            let scale = (0..j_n)
                .map(|a| hess[a * j_n + a].abs())
                .fold(0.0, f64::max)
                .max(f64::MIN_POSITIVE);
            // Raise the damping until a step lowers f.
            let mut moved = false;
            for _ in 0..40 {
                let mut a = hess.clone();
                for i in 0..j_n {
                    a[i * j_n + i] += lambda * scale;
                }
                let mut step: Vec<f64> = grad.iter().map(|g| -g).collect();
                if solve_in_place(&mut a, &mut step, j_n, 0.0).is_ok()
                    && step.iter().all(|v| v.is_finite())
                {
                    let moves: Vec<(usize, f64)> = step.iter().copied().enumerate().collect();
                    let fn_ = eval(tau, &moves);
                    if fn_ < f {
                        tau.iter_mut().zip(&step).for_each(|(t, d)| *t += d);
                        let small = step.iter().all(|d| d.abs() < 1e-10) || f - fn_ <= 1e-14 * f;
                        f = fn_;
                        lambda = (lambda * 0.25).max(1e-12);
                        moved = !small;
                        break;
                    }
                }
                lambda *= 8.0;
            }
            if !moved {
                break;
            }
        }
        tau.iter_mut().for_each(|t| *t = wrap_half(*t));
        self.residual(tau)
    }
}

/// The inverse of the symmetric positive definite `g` (`n × n`, overwritten by its Cholesky
/// factor) into `inv`; `false` when `g` is not numerically positive definite (a pivot below
/// 1e-12 of the largest diagonal entry: dependent delayed sources).
fn spd_inverse(g: &mut [f64], n: usize, inv: &mut [f64]) -> bool {
    let scale = (0..n).map(|i| g[i * n + i]).fold(0.0, f64::max);
    for col in 0..n {
        let mut v = g[col * n + col];
        for s in 0..col {
            v -= g[col * n + s] * g[col * n + s];
        }
        if v <= 1e-12 * scale || !v.is_finite() {
            return false;
        }
        let l = v.sqrt();
        g[col * n + col] = l;
        for row in col + 1..n {
            let mut u = g[row * n + col];
            for s in 0..col {
                u -= g[row * n + s] * g[col * n + s];
            }
            g[row * n + col] = u / l;
        }
    }
    // Column j of G⁻¹ solves L Lᵀ x = e_j (stored as row j: G⁻¹ is symmetric).
    for j in 0..n {
        let x = &mut inv[j * n..(j + 1) * n];
        for i in 0..n {
            let mut v = if i == j { 1.0 } else { 0.0 };
            for s in 0..i {
                v -= g[i * n + s] * x[s];
            }
            x[i] = v / g[i * n + i];
        }
        for i in (0..n).rev() {
            let mut v = x[i];
            for s in i + 1..n {
                v -= g[s * n + i] * x[s];
            }
            x[i] = v / g[i * n + i];
        }
    }
    true
}

/// `tr(A B)` of two `n × n` matrices, `B` symmetric.
fn trace_product(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// A channel of `j` random sources (`k` harmonics) mixed into `r` trials at delays `tau`
    /// with random weights; returns the sources and the rows.
    fn channel(
        j: usize,
        k: usize,
        r: usize,
        tau: &[f64],
        seed: u64,
    ) -> (Vec<Complex64>, Vec<Complex64>) {
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
        let c: Vec<Complex64> = (0..j * k)
            .map(|_| Complex64::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)))
            .collect();
        let mut x = vec![Complex64::new(0.0, 0.0); r * k];
        let mut d = vec![Complex64::new(0.0, 0.0); k];
        for row in x.chunks_exact_mut(k) {
            for p in 0..j {
                delayed(tau[p], &c[p * k..(p + 1) * k], &mut d);
                let w: f64 = rng.random_range(0.5..1.5);
                row.iter_mut().zip(&d).for_each(|(v, &dv)| *v += dv * w);
            }
        }
        (c, x)
    }

    #[test]
    fn pair_grid_equals_the_residual_at_its_points() {
        for (j, seed) in [(2, 1), (3, 2), (4, 3)] {
            let (k, r) = (6, 5);
            let truth: Vec<f64> = (0..j).map(|p| 0.1 + 0.2 * p as f64).collect();
            let (c, x) = channel(j, k, r, &truth, seed);
            let ch = ChannelDelays::new(&c, k, x.chunks_exact(k));
            let tau: Vec<f64> = (0..j).map(|p| -0.3 + 0.17 * p as f64).collect();
            let m = 16;
            let (p, q) = (0, j - 1);
            let grid = ch.pair_grid(&tau, p, q, m);
            for a in 0..m {
                for b in 0..m {
                    let mut t = tau.clone();
                    t[p] = a as f64 / m as f64;
                    t[q] = b as f64 / m as f64;
                    let want = ch.residual(&t);
                    let got = grid[a * m + b];
                    assert!(
                        (got - want).abs() <= 1e-9 * ch.energy,
                        "J = {j}, ({a}, {b}): grid {got} vs residual {want}"
                    );
                }
            }
        }
    }

    #[test]
    fn search_moves_two_delays_together_to_the_generating_ones() {
        // Noise-free channel: the generating delays give residual 0. Start with two delays
        // 0.3 periods off in opposite directions; the search must land on the truth.
        let (j, k, r) = (3, 8, 10);
        let truth = [0.21, -0.12, -0.37];
        let (c, x) = channel(j, k, r, &truth, 7);
        let ch = ChannelDelays::new(&c, k, x.chunks_exact(k));
        assert!(ch.residual(&truth) <= 1e-20 * ch.energy);
        let start = [
            wrap_half(truth[0] - 0.3),
            truth[1],
            wrap_half(truth[2] + 0.3),
        ];
        let f0 = ch.residual(&start);
        assert!(f0 > 1e-3 * ch.energy, "start residual {f0}");
        let (found, f) = ch.search(&start, 128).expect("a better basin");
        assert!(f <= 1e-12 * ch.energy, "residual {f} of {}", ch.energy);
        for (a, b) in found.iter().zip(&truth) {
            assert!(wrap_half(a - b).abs() < 1e-6, "{found:?} vs {truth:?}");
        }
        // Near the truth the best point is in the current basin: polishing it is the ALS's
        // job, so no move is reported although the residual can drop to 0.
        let near = [truth[0] + 0.003, truth[1], truth[2]];
        assert!(ch.residual(&near) > 1e-6 * ch.energy);
        assert!(ch.search(&near, 128).is_none());
    }

    #[test]
    fn spd_inverse_equals_the_dense_inverse() {
        let g0 = [4.0, 1.0, 0.5, 1.0, 3.0, 0.2, 0.5, 0.2, 2.0];
        let want = nalgebra::Matrix3::from_row_slice(&g0)
            .try_inverse()
            .unwrap();
        let (mut g, mut inv) = (g0, [0.0; 9]);
        assert!(spd_inverse(&mut g, 3, &mut inv));
        for i in 0..3 {
            for j in 0..3 {
                assert!((inv[i * 3 + j] - want[(i, j)]).abs() < 1e-12, "{inv:?}");
            }
        }
        let c = [2.0, 0.3, -0.1, 0.3, 1.0, 0.4, -0.1, 0.4, 5.0];
        let tr = (want * nalgebra::Matrix3::from_row_slice(&c)).trace();
        assert!((trace_product(&inv, &c) - tr).abs() < 1e-12);
        // Dependent columns, and a matrix that is not positive definite.
        assert!(!spd_inverse(&mut [1.0, 1.0, 1.0, 1.0], 2, &mut [0.0; 4]));
        assert!(!spd_inverse(&mut [1.0, 2.0, 2.0, 1.0], 2, &mut [0.0; 4]));
    }
}
