//! The orbit-subspace start of the anechoic demixing (an initialisation for the ALS of
//! [`crate::anechoic`], not in the paper, which cites its demixing without details).
//!
//! With delays shared over trials, channel `i` of trial `r` has the harmonics
//! `X_ri = Σ_j w_rij R(τ_ij) c_j`, where `R(τ)` delays a source by `τ` (harmonic `k` turned by
//! `−2πkτ`). Over the trials only the weights change, so the `R × 2K` real matrix of a
//! channel (re and im of each harmonic, one row per trial) has rank `J`, and its row space
//! `V_i` is spanned by the delayed sources `R(τ_ij) c_j`. A true source is therefore a vector
//! whose delay orbit `{R(τ) c}` meets every channel's `V_i`: the fit
//! `Σ_i max_τ ‖V_iᵀ R(τ) c‖² / ‖c‖²` reaches its bound `I` exactly there. The sources are
//! found one at a time by alternating the channels' delays and the source (a top
//! eigenvector), from a few random starts; each found source is taken out of the channels'
//! subspaces before the next (the next fit measures the part of a delayed candidate off the
//! known sources). Finally each channel keeps, of these delays and of each source's best
//! delay into its whole subspace, the set with the better least-squares fit of its trials.
//!
//! No weight enters the search, so the ALS starts next to the generating sources and delays
//! instead of in the basin of whichever delays a start happened to have. On data whose sources
//! share their harmonic amplitudes, such a basin is often a neighbouring optimum: random and
//! PCA starts end there, at a slightly lower `Q` with sources off by several percent.
//! The subspaces need trial weights that vary independently; where a channel's weights are
//! nearly proportional over the trials its subspace is ill-conditioned, and with noise its
//! delays may stay ambiguous.

use std::f64::consts::TAU;

use num_complex::Complex64;
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;
use wscg_math::{Error, Result};

use crate::fourier::{delayed, re_dot, trig_argmax, trig_eval, wrap_half};
use faer::MatRef;
use wscg_math::dense::{eigh_largest, from_row_major, gram};

/// The top-`d` eigenvectors of the symmetric `a` (`m × m`), as an `m × d` row-major basis.
fn top_eigenvectors(a: MatRef<'_, f64>, d: usize) -> Result<Vec<f64>> {
    let m = a.nrows();
    let e = eigh_largest(a, d)?;
    Ok((0..m)
        .flat_map(|r| (0..d).map(move |l| (r, l)))
        .map(|(r, l)| e.vectors[(r, l)])
        .collect())
}

/// The top-`d` right singular vectors of the row-major `rows × m` matrix `a` (the top
/// eigenvectors of `AᵀA`), as an `m × d` row-major basis.
fn top_row_space(a: &[f64], rows: usize, m: usize, d: usize) -> Result<Vec<f64>> {
    top_eigenvectors(gram(from_row_major(a, rows, m).as_ref(), 1.0).as_ref(), d)
}

/// Harmonics as a real vector: `(re, im)` of each.
fn real_of(z: &[Complex64]) -> Vec<f64> {
    z.iter().flat_map(|v| [v.re, v.im]).collect()
}

/// A real vector of `(re, im)` pairs as harmonics.
fn complex_of(v: &[f64]) -> Vec<Complex64> {
    v.chunks_exact(2)
        .map(|p| Complex64::new(p[0], p[1]))
        .collect()
}

/// `Σ_l (Re Σ_k b_lk e^{−2πikτ})²` as `const + Re Σ_{m=1}^{2K} h_m e^{−2πimτ}` (`y² = (|z|² +
/// Re z²) / 2`): accumulates the coefficients of one `z = Σ_k a_k e^{−2πikτ}` into `h`
/// (length `2K`; `a[n]` is harmonic `n + 1`).
fn add_squared_real_part(a: &[Complex64], h: &mut [Complex64]) {
    let k = a.len();
    for m in 1..k {
        for l in 0..k - m {
            h[m - 1] += a[l + m] * a[l].conj();
        }
    }
    for (n1, &a1) in a.iter().enumerate() {
        for (n2, &a2) in a.iter().enumerate() {
            h[n1 + n2 + 1] += a1 * a2 * 0.5;
        }
    }
}

/// Rows `(2k, 2k + 1)` of the `m × d` row-major `v` rotated by `θ_k = 2π(k + 1)τ`:
/// `R(τ)ᵀ v`, so that `(R(τ)ᵀ v)ᵀ c = vᵀ R(τ) c` with `R(τ) c` the source delayed by `τ`.
fn rotate_rows(v: &[f64], d: usize, k: usize, tau: f64, out: &mut [f64]) {
    for kk in 0..k {
        let (s, co) = (TAU * (kk + 1) as f64 * tau).sin_cos();
        for l in 0..d {
            let (p, q) = (v[2 * kk * d + l], v[(2 * kk + 1) * d + l]);
            out[2 * kk * d + l] = p * co - q * s;
            out[(2 * kk + 1) * d + l] = p * s + q * co;
        }
    }
}

/// `Σ_l (vᵀ R(τ) c)_l²` as a trigonometric polynomial: its constant and coefficients `h`.
fn projection_poly(v: &[f64], d: usize, k: usize, c: &[f64], h: &mut [Complex64]) -> f64 {
    let zero = Complex64::new(0.0, 0.0);
    h.fill(zero);
    let mut a = vec![zero; k];
    let mut constant = 0.0;
    for l in 0..d {
        for (kk, av) in a.iter_mut().enumerate() {
            let (p, q) = (v[2 * kk * d + l], v[(2 * kk + 1) * d + l]);
            *av = Complex64::new(p, -q) * Complex64::new(c[2 * kk], c[2 * kk + 1]);
        }
        constant += 0.5 * a.iter().map(|z| z.norm_sqr()).sum::<f64>();
        add_squared_real_part(&a, h);
    }
    constant
}

/// Points of the grid search of [`orbit_delay`].
const ORBIT_GRID: usize = 64;

/// Random starts per source.
const STARTS: usize = 4;

/// Channel `i`'s step of [`orbit_fit`]: the delay `τ` maximising the fit of the delayed
/// source, `ρ(τ) = ‖Vᵀ R c‖² / (1 − ‖Kᵀ R c‖²)`, and the channel's term of the `c` step's
/// matrix, `(W Wᵀ − ρ (I − K' K'ᵀ)) / n` with `W = R(τ)ᵀ V`, `K' = R(τ)ᵀ K` and `n` the
/// denominator (added into `big`). Without known sources `ρ` is a trigonometric polynomial,
/// maximised exactly; otherwise by a grid search refined by golden sections.
fn orbit_delay(
    (v, d): (&[f64], usize),
    (kn, nk): (&[f64], usize),
    k: usize,
    c: &[f64],
    table: &[Complex64],
    big: &mut [f64],
) -> (f64, f64) {
    let m = 2 * k;
    let zero = Complex64::new(0.0, 0.0);
    let (mut hv, mut hk) = (vec![zero; m], vec![zero; m]);
    let cv = projection_poly(v, d, k, c, &mut hv);
    let ck = if nk > 0 {
        projection_poly(kn, nk, k, c, &mut hk)
    } else {
        0.0
    };
    // The fit's numerator and denominator at `τ` (the known part is zero without known
    // sources: `hk` stays zero).
    let parts = |t: f64| {
        let num = cv + trig_eval(&hv, t).0;
        let den = (1.0 - ck - trig_eval(&hk, t).0).max(1e-12);
        (num, den)
    };
    let ratio = |t: f64| {
        let (num, den) = parts(t);
        num / den
    };
    let tau = if nk == 0 {
        wrap_half(trig_argmax(&hv).0)
    } else {
        let (mut bt, mut br) = (0.0, f64::NEG_INFINITY);
        for (g, row) in table.chunks_exact(m).enumerate() {
            let at = |h: &[Complex64]| -> f64 { h.iter().zip(row).map(|(a, b)| (a * b).re).sum() };
            let r = (cv + at(&hv)) / (1.0 - ck - at(&hk)).max(1e-12);
            if r > br {
                (bt, br) = (g as f64 / ORBIT_GRID as f64 - 0.5, r);
            }
        }
        let step = 1.0 / ORBIT_GRID as f64;
        let (mut lo, mut hi) = (bt - step, bt + step);
        for _ in 0..20 {
            let (x1, x2) = (hi - 0.618 * (hi - lo), lo + 0.618 * (hi - lo));
            if ratio(x1) > ratio(x2) {
                hi = x2;
            } else {
                lo = x1;
            }
        }
        let t = 0.5 * (lo + hi);
        wrap_half(if ratio(t) > br { t } else { bt })
    };
    let (num, den) = parts(tau);
    let rho = num / den;
    let mut w = vec![0.0; m * d];
    rotate_rows(v, d, k, tau, &mut w);
    let mut kr = vec![0.0; m * nk];
    rotate_rows(kn, nk, k, tau, &mut kr);
    for r in 0..m {
        big[r * m + r] -= rho / den;
        for s2 in 0..m {
            let ww: f64 = (0..d).map(|l| w[r * d + l] * w[s2 * d + l]).sum();
            let kk: f64 = (0..nk).map(|l| kr[r * nk + l] * kr[s2 * nk + l]).sum();
            big[r * m + s2] += (ww + rho * kk) / den;
        }
    }
    (tau, rho)
}

/// One source of the orbit start: the unit `c` (real `2K`: re, im per harmonic) whose
/// delayed copies best fit every channel's subspace. Channel `i` has `bases[i]` (`2K × d`,
/// orthonormal) and `known[i]` (`2K × nk`, orthonormal: the sources found before, delayed);
/// the fit of `c` delayed by `τ` is `‖V_iᵀ R c‖² / ‖(I − K_i K_iᵀ) R c‖²`, 1 when the delayed
/// source lies in `span(V_i, K_i)`. Alternates the delays ([`orbit_delay`]) and `c` (a
/// Dinkelbach step for the sum of ratios: the top eigenvector of the summed channel terms).
/// Returns `c`, the delays and the summed fit.
fn orbit_fit(
    (bases, d): (&[Vec<f64>], usize),
    (known, nk): (&[Vec<f64>], usize),
    k: usize,
    c0: &[f64],
    table: &[Complex64],
) -> Result<(Vec<f64>, Vec<f64>, f64)> {
    let m = 2 * k;
    let nrm = c0.iter().map(|x| x * x).sum::<f64>().sqrt();
    let mut c: Vec<f64> = c0.iter().map(|x| x / nrm).collect();
    let mut taus = vec![0.0; bases.len()];
    let mut f_old = f64::NEG_INFINITY;
    for _ in 0..60 {
        // Each channel's term in parallel, summed in channel order (the result does not
        // depend on the number of threads).
        let terms: Vec<(f64, Vec<f64>)> = bases
            .par_iter()
            .zip(known)
            .zip(taus.par_iter_mut())
            .map(|((v, kn), tau)| {
                let mut term = vec![0.0; m * m];
                let (t, rho) = orbit_delay((v, d), (kn, nk), k, &c, table, &mut term);
                *tau = t;
                (rho, term)
            })
            .collect();
        let mut big = vec![0.0; m * m];
        let mut f = 0.0;
        for (rho, term) in &terms {
            f += rho;
            big.iter_mut().zip(term).for_each(|(x, y)| *x += y);
        }
        c = top_eigenvectors(from_row_major(&big, m, m).as_ref(), 1)?;
        let done = (f - f_old).abs() <= 1e-10 * f.abs().max(1e-300);
        f_old = f;
        if done {
            break;
        }
    }
    Ok((c, taus, f_old))
}

/// Sources (`J × K` harmonics `k = 1..=K`) and delays shared over trials (`I × J`, in
/// periods) whose delayed copies span every channel's row space of the data, found one
/// source at a time; `rows(r, i)` are the `K` harmonics of trial `r`, channel `i`, of an
/// `R × I` set. Needs `J <= R` and `J < 2K`.
///
/// # Errors
/// A failed eigendecomposition.
pub(crate) fn orbit_sources<'a, F>(
    rows: &F,
    (r_n, i_n, k): (usize, usize, usize),
    j_n: usize,
    seed: u64,
) -> Result<(Vec<Complex64>, Vec<f64>)>
where
    F: Fn(usize, usize) -> &'a [Complex64] + Sync,
{
    let m = 2 * k;
    // Each channel's row space: the top-J right singular vectors of its R × 2K matrix
    // (re, im of every harmonic in every trial).
    let mut bases: Vec<Vec<f64>> = (0..i_n)
        .into_par_iter()
        .map(|i| {
            let a: Vec<f64> = (0..r_n).flat_map(|r| real_of(rows(r, i))).collect();
            top_row_space(&a, r_n, m, j_n)
        })
        .collect::<Result<_>>()?;
    let full = bases.clone();
    let mut rng = wscg_math::rng::stream(seed, 0x0b17);
    // e^{−2πimτ_g} on the grid τ_g = g / G − 1/2, m = 1..2K.
    let table: Vec<Complex64> = (0..ORBIT_GRID)
        .flat_map(|g| {
            let t = g as f64 / ORBIT_GRID as f64 - 0.5;
            (1..=m).map(move |mm| Complex64::from_polar(1.0, -TAU * mm as f64 * t))
        })
        .collect();
    let mut known: Vec<Vec<f64>> = vec![Vec::new(); i_n];
    let mut c_all = Vec::with_capacity(j_n * k);
    let mut tau_all = vec![0.0; i_n * j_n];
    for j in 0..j_n {
        let (d, nk) = (j_n - j, j);
        // The best of a few random starts (smooth: harmonic k scaled by 1/k).
        let mut best: Option<(Vec<f64>, Vec<f64>, f64)> = None;
        for _ in 0..STARTS {
            let c0: Vec<f64> = (0..m)
                .map(|r| {
                    let g: f64 = StandardNormal.sample(&mut rng);
                    g / (r / 2 + 1) as f64
                })
                .collect();
            let fit = orbit_fit((&bases, d), (&known, nk), k, &c0, &table)?;
            if best.as_ref().is_none_or(|b| fit.2 > b.2) {
                best = Some(fit);
            }
        }
        let (c, taus, _) = best.ok_or_else(|| Error::Numerical("no orbit start".into()))?;
        let cz = complex_of(&c);
        c_all.extend_from_slice(&cz);
        for (i, &t) in taus.iter().enumerate() {
            tau_all[i * j_n + j] = t;
        }
        if d == 1 {
            break;
        }
        // Each channel: the delayed source joins the known span (Gram-Schmidt), and the
        // channel's subspace is projected off the known span (the rest, d − 1 dimensions).
        let mut dz = vec![Complex64::new(0.0, 0.0); k];
        for ((v, kn), &tau) in bases.iter_mut().zip(known.iter_mut()).zip(&taus) {
            delayed(tau, &cz, &mut dz);
            let mut u = real_of(&dz);
            for l in 0..nk {
                let p: f64 = (0..m).map(|r| kn[r * nk + l] * u[r]).sum();
                for r in 0..m {
                    u[r] -= p * kn[r * nk + l];
                }
            }
            let nu = u.iter().map(|x| x * x).sum::<f64>().sqrt().max(1e-300);
            u.iter_mut().for_each(|x| *x /= nu);
            let mut kn2 = vec![0.0; m * (nk + 1)];
            for r in 0..m {
                kn2[r * (nk + 1)..r * (nk + 1) + nk].copy_from_slice(&kn[r * nk..r * nk + nk]);
                kn2[r * (nk + 1) + nk] = u[r];
            }
            *kn = kn2;
            let mut vp = v.clone();
            for l in 0..d {
                let p: f64 = (0..m).map(|r| u[r] * v[r * d + l]).sum();
                for r in 0..m {
                    vp[r * d + l] -= p * u[r];
                }
            }
            // The rest's basis: the top left singular vectors of `vp` (`m × d`).
            let vpt: Vec<f64> = (0..d)
                .flat_map(|l| (0..m).map(move |r| (r, l)))
                .map(|(r, l)| vp[r * d + l])
                .collect();
            *v = top_row_space(&vpt, d, m, d - 1)?;
        }
    }
    // The stages fit each source in what the sources before it left of a channel's subspace,
    // which in a channel whose trial weights are nearly proportional is ill-conditioned; each
    // source's delay into the whole subspace is the other candidate. Each channel keeps the
    // set of delays with the better least-squares fit of its trials.
    tau_all
        .par_chunks_mut(j_n)
        .zip(&full)
        .enumerate()
        .try_for_each(|(i, (t, v))| -> Result<()> {
            let mut h = vec![Complex64::new(0.0, 0.0); m];
            let whole: Vec<f64> = c_all
                .chunks_exact(k)
                .map(|cj| {
                    projection_poly(v, j_n, k, &real_of(cj), &mut h);
                    wrap_half(trig_argmax(&h).0)
                })
                .collect();
            let fit = |d: &[f64]| channel_fit(&|r| rows(r, i), r_n, &c_all, k, d);
            if fit(&whole)? > fit(t)? {
                t.copy_from_slice(&whole);
            }
            Ok(())
        })?;
    Ok((c_all, tau_all))
}

/// The least-squares fit `Σ_r b_rᵀ G⁻¹ b_r` of a channel's trials `rows(r)` (`K` harmonics
/// each) by the sources `c` (`J × K`) delayed by `taus`, every trial's weights refitted:
/// `G_pq = Re⟨R(τ_p) c_p, R(τ_q) c_q⟩`, `b_rj = Re⟨X_r, R(τ_j) c_j⟩`. The channel's residual
/// is its energy minus this.
fn channel_fit<'a>(
    rows: &dyn Fn(usize) -> &'a [Complex64],
    r_n: usize,
    c: &[Complex64],
    k: usize,
    taus: &[f64],
) -> Result<f64> {
    let j_n = taus.len();
    let mut d = vec![Complex64::new(0.0, 0.0); j_n * k];
    for ((dj, cj), &t) in d.chunks_exact_mut(k).zip(c.chunks_exact(k)).zip(taus) {
        delayed(t, cj, dj);
    }
    let mut g = vec![0.0; j_n * j_n];
    for (p, dp) in d.chunks_exact(k).enumerate() {
        for (q, dq) in d.chunks_exact(k).enumerate() {
            g[p * j_n + q] = re_dot(dp, dq);
        }
    }
    let b: Vec<f64> = (0..r_n)
        .flat_map(|r| d.chunks_exact(k).map(move |dj| re_dot(rows(r), dj)))
        .collect();
    let mut sol = b.clone();
    crate::linalg::solve_many_in_place(&mut g, &mut sol, j_n, 1e-12)?;
    Ok(b.iter().zip(&sol).map(|(u, v)| u * v).sum())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fourier::PeriodicSource;
    use crate::matching::align;

    /// Exact data `X_ri = Σ_j w_rij R(τ_ij) c_j` of random sources (`J × K`), delays and
    /// independently varying weights; returns the rows (`R × I × K`) and the sources.
    fn exact_data(
        (r_n, i_n, k, j_n): (usize, usize, usize, usize),
        seed: u64,
    ) -> (Vec<Complex64>, Vec<Complex64>) {
        let mut rng = wscg_math::rng::stream(seed, 7);
        let mut normal = || -> f64 { StandardNormal.sample(&mut rng) };
        let c: Vec<Complex64> = (0..j_n * k)
            .map(|n| Complex64::new(normal(), normal()) / (n % k + 1) as f64)
            .collect();
        let taus: Vec<f64> = (0..i_n * j_n).map(|_| 0.3 * normal()).collect();
        let mut x = vec![Complex64::new(0.0, 0.0); r_n * i_n * k];
        for r in 0..r_n {
            for i in 0..i_n {
                for j in 0..j_n {
                    let w = 1.0 + 0.5 * normal();
                    for kk in 0..k {
                        let z =
                            Complex64::from_polar(1.0, -TAU * (kk + 1) as f64 * taus[i * j_n + j]);
                        x[(r * i_n + i) * k + kk] += c[j * k + kk] * z * w;
                    }
                }
            }
        }
        (x, c)
    }

    /// The start depends on the seed only, not on the number of threads.
    #[test]
    fn orbit_start_does_not_depend_on_the_thread_count() {
        let (r_n, i_n, k, j_n) = (8, 16, 4, 2);
        let (x, _) = exact_data((r_n, i_n, k, j_n), 5);
        let rows = |r: usize, i: usize| &x[(r * i_n + i) * k..(r * i_n + i + 1) * k];
        let with = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| orbit_sources(&rows, (r_n, i_n, k), j_n, 3).unwrap())
        };
        assert_eq!(with(1), with(3));
    }

    /// On exact data the start fits every channel exactly (its least-squares residual is
    /// zero) and every true source is one of the found ones up to delay, sign and scale.
    #[test]
    fn orbit_start_recovers_exact_sources_and_delays() {
        for (dims, seed) in [((10, 20, 5, 2), 1), ((12, 30, 6, 3), 2)] {
            let (r_n, i_n, k, j_n) = dims;
            let (x, truth) = exact_data(dims, seed);
            let rows = |r: usize, i: usize| &x[(r * i_n + i) * k..(r * i_n + i + 1) * k];
            let (c, taus) = orbit_sources(&rows, (r_n, i_n, k), j_n, 0).unwrap();
            for i in 0..i_n {
                let energy: f64 = (0..r_n)
                    .map(|r| rows(r, i).iter().map(|v| v.norm_sqr()).sum::<f64>())
                    .sum();
                let fit = channel_fit(&|r| rows(r, i), r_n, &c, k, &taus[i * j_n..(i + 1) * j_n])
                    .unwrap();
                assert!(
                    (energy - fit).abs() < 1e-8 * energy,
                    "channel {i}: {fit} of {energy}"
                );
            }
            for t in truth.chunks_exact(k) {
                let t = PeriodicSource::new(t.to_vec());
                let best = c
                    .chunks_exact(k)
                    .map(|e| align(&PeriodicSource::new(e.to_vec()), &t).0)
                    .fold(0.0, f64::max);
                assert!(best > 1.0 - 1e-8, "a true source matched at {best}");
            }
        }
    }
}
