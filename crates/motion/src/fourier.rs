//! Band-limited periodic signals (paper §2.3 as specified: each source is a Fourier series with
//! `K` harmonics and no mean).
//!
//! Time is normalised to one period, `t ∈ [0, 1)`, so a delay `τ` is a fraction of the period
//! and a shift is circular. A source is
//!
//! ```text
//! s(t) = Σ_{k=-K..K, k≠0} c_k e^{2πikt} = 2 Re Σ_{k=1..K} c_k e^{2πikt},   c_{-k} = conj(c_k)
//! ```
//!
//! and a delayed copy `s(t − τ)` has coefficients `c_k e^{−2πikτ}`: delays act on the
//! coefficients, which is what makes the demixing linear in the sources for fixed delays.

use num_complex::Complex64;
use std::f64::consts::TAU;

/// A real, zero-mean, 1-periodic Fourier series stored by its positive harmonics `c_1..c_K`.
#[derive(Clone, Debug, PartialEq)]
pub struct PeriodicSource {
    /// `c_k` for `k = 1..=K` (index `k − 1`).
    pub coeffs: Vec<Complex64>,
}

impl PeriodicSource {
    /// A source from its positive harmonics.
    pub fn new(coeffs: Vec<Complex64>) -> Self {
        Self { coeffs }
    }

    /// Number of harmonics `K`.
    pub fn n_harmonics(&self) -> usize {
        self.coeffs.len()
    }

    /// `s(t − τ)` at normalised time `t` (periods).
    pub fn eval(&self, t: f64, tau: f64) -> f64 {
        let z = Complex64::from_polar(1.0, TAU * (t - tau));
        let mut p = z;
        let mut acc = 0.0;
        for c in &self.coeffs {
            acc += (c * p).re;
            p *= z;
        }
        2.0 * acc
    }

    /// `s` at the phase angle `θ` (radians), i.e. `s(θ / 2π)`.
    pub fn eval_angle(&self, theta: f64) -> f64 {
        self.eval(theta / TAU, 0.0)
    }

    /// `n` samples of `s(t − τ)` at `t = m / n`, `m = 0..n`.
    pub fn sample(&self, n: usize, tau: f64) -> Vec<f64> {
        (0..n)
            .map(|m| self.eval(m as f64 / n as f64, tau))
            .collect()
    }

    /// Root mean square over one period: `sqrt(2 Σ |c_k|²)` (Parseval).
    pub fn rms(&self) -> f64 {
        (2.0 * self.coeffs.iter().map(|c| c.norm_sqr()).sum::<f64>()).sqrt()
    }

    /// The source shifted in time, `s'(t) = s(t − μ)`.
    pub fn shifted(&self, mu: f64) -> Self {
        let coeffs = self
            .coeffs
            .iter()
            .enumerate()
            .map(|(k, c)| c * Complex64::from_polar(1.0, -TAU * (k + 1) as f64 * mu))
            .collect();
        Self { coeffs }
    }

    /// Harmonics `1..=k` of `n` equispaced samples (the source whose samples they are, when the
    /// samples are band-limited to `k < n / 2`).
    pub fn from_samples(x: &[f64], k: usize) -> Self {
        Self {
            coeffs: harmonics(x, k),
        }
    }
}

/// Normalised DFT coefficients `X_k = (1/N) Σ_n x_n e^{−2πikn/N}` for `k = 1..=K`.
pub fn harmonics(x: &[f64], k: usize) -> Vec<Complex64> {
    let n = x.len();
    let mut out = vec![Complex64::new(0.0, 0.0); k];
    if n == 0 {
        return out;
    }
    let inv = 1.0 / n as f64;
    for (kk, o) in out.iter_mut().enumerate() {
        let w = Complex64::from_polar(1.0, -TAU * (kk + 1) as f64 / n as f64);
        let mut p = Complex64::new(1.0, 0.0);
        let mut acc = Complex64::new(0.0, 0.0);
        for &v in x {
            acc += p * v;
            p *= w;
        }
        *o = acc * inv;
    }
    out
}

/// Wrap a delay (periods) into `[-0.5, 0.5)`.
pub fn wrap_half(t: f64) -> f64 {
    t - (t + 0.5).floor()
}

/// The global maximum over `τ ∈ [0, 1)` of the real trigonometric polynomial
/// `F(τ) = Re Σ_{k=1..K} g_k e^{−2πikτ}`: a grid of `32 K` points (at least 64) brackets every
/// local maximum (there are at most `K`), and Newton steps on the analytic derivatives refine
/// the best one. Returns `(τ, F(τ))`.
pub fn trig_argmax(g: &[Complex64]) -> (f64, f64) {
    let k = g.len().max(1);
    let m = (32 * k).max(64);
    // F(m'/M) = Σ_k a_k cos(2πkm'/M) + b_k sin(2πkm'/M) for g_k = a_k + i b_k: with the
    // cosines and sines of the grid tabulated once per (K, M), the grid is 2K contiguous
    // multiply-adds over M points, which vectorize.
    let best = GRID.with(|cache| {
        let mut cache = cache.borrow_mut();
        if cache.k != k || cache.m != m {
            *cache = GridTable::new(k, m);
        }
        cache.argmax(g)
    });
    let (mut tau, mut f) = (best.0 as f64 / m as f64, best.1);
    for _ in 0..8 {
        let (_, d1, d2) = trig_eval(g, tau);
        if d2 >= 0.0 {
            break;
        }
        let cand = tau - d1 / d2;
        let fc = trig_eval(g, cand).0;
        if fc >= f {
            let moved = (cand - tau).abs();
            tau = cand;
            f = fc;
            if moved < 1e-14 {
                break;
            }
        } else {
            break;
        }
    }
    (tau.rem_euclid(1.0), f)
}

thread_local! {
    /// The grid table of the last `(K, M)` used on this thread.
    static GRID: std::cell::RefCell<GridTable> = std::cell::RefCell::new(GridTable::new(0, 0));
}

/// `cos(2πkm/M)` and `sin(2πkm/M)` for `k = 1..=K` and `m = 0..M` (row per harmonic), and a
/// scratch row for the grid values.
struct GridTable {
    k: usize,
    m: usize,
    cos: Vec<f64>,
    sin: Vec<f64>,
    values: Vec<f64>,
}

impl GridTable {
    fn new(k: usize, m: usize) -> Self {
        let angle = |i: usize| {
            let (h, t) = (i / m.max(1) + 1, i % m.max(1));
            // Reduce h·t mod M first so that the angle stays in [0, 2π).
            TAU * ((h * t) % m.max(1)) as f64 / m as f64
        };
        Self {
            k,
            m,
            cos: (0..k * m).map(|i| angle(i).cos()).collect(),
            sin: (0..k * m).map(|i| angle(i).sin()).collect(),
            values: vec![0.0; m],
        }
    }

    /// Index and value of the largest `Re Σ_k g_k e^{−2πikm'/M}` over the grid.
    fn argmax(&mut self, g: &[Complex64]) -> (usize, f64) {
        let m = self.m;
        self.values.fill(0.0);
        let rows = self.cos.chunks_exact(m).zip(self.sin.chunks_exact(m));
        for (gk, (c, s)) in g.iter().zip(rows) {
            for ((v, &cv), &sv) in self.values.iter_mut().zip(c).zip(s) {
                *v += gk.re * cv + gk.im * sv;
            }
        }
        let mut best = (0usize, f64::NEG_INFINITY);
        for (step, &f) in self.values.iter().enumerate() {
            if f > best.1 {
                best = (step, f);
            }
        }
        best
    }
}

/// `F(τ)`, `F'(τ)` and `F''(τ)` of [`trig_argmax`]'s polynomial.
pub fn trig_eval(g: &[Complex64], tau: f64) -> (f64, f64, f64) {
    let z = Complex64::from_polar(1.0, -TAU * tau);
    let mut p = z;
    let (mut f, mut d1, mut d2) = (0.0, 0.0, 0.0);
    for (i, gk) in g.iter().enumerate() {
        let k = (i + 1) as f64;
        let v = gk * p;
        f += v.re;
        // d/dτ e^{−2πikτ} = −2πik e^{−2πikτ}
        d1 += (v * Complex64::new(0.0, -TAU * k)).re;
        d2 -= v.re * (TAU * k) * (TAU * k);
        p *= z;
    }
    (f, d1, d2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn harmonics_invert_sampling() {
        let s = PeriodicSource::new(vec![Complex64::new(0.3, -0.2), Complex64::new(0.0, 0.1)]);
        let x = s.sample(50, 0.17);
        let back = PeriodicSource::from_samples(&x, 2);
        let want = s.shifted(0.17);
        for (a, b) in back.coeffs.iter().zip(&want.coeffs) {
            assert!((a - b).norm() < 1e-12);
        }
        let rms = (x.iter().map(|v| v * v).sum::<f64>() / 50.0).sqrt();
        assert!((rms - s.rms()).abs() < 1e-12);
    }

    #[test]
    fn argmax_finds_shift_of_cosine() {
        // F(τ) = cos(2π(τ − 0.3)) = Re(e^{2πi·0.3} e^{−2πiτ})
        let g = [Complex64::from_polar(1.0, TAU * 0.3)];
        let (tau, f) = trig_argmax(&g);
        assert!((tau - 0.3).abs() < 1e-12 && (f - 1.0).abs() < 1e-12);
    }

    #[test]
    fn argmax_is_the_global_maximum_of_a_multi_harmonic_polynomial() {
        // Several harmonics of comparable size, so that F has competing local maxima and
        // every row of the grid table (harmonic k) matters.
        for seed in 0..20 {
            let g: Vec<Complex64> = (0..6)
                .map(|k| {
                    let a = (seed * 7 + k) as f64;
                    Complex64::new((a * 1.37).sin(), (a * 2.11).cos()) / (1.0 + 0.3 * k as f64)
                })
                .collect();
            let (tau, f) = trig_argmax(&g);
            assert!((trig_eval(&g, tau).0 - f).abs() < 1e-12);
            // Dense brute force with the independent evaluator.
            let best = (0..20_000)
                .map(|m| trig_eval(&g, m as f64 / 20_000.0).0)
                .fold(f64::NEG_INFINITY, f64::max);
            assert!(
                f >= best - 1e-12,
                "seed {seed}: {f} below the brute-force {best}"
            );
        }
    }
}
