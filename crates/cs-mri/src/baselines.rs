//! The baselines of paper 11 (section 3): FCSA (Huang, Zhang & Metaxas 2011), TVCMRI
//! (Ma, Yin, Zhang & Chakraborty 2008) and WaTMRI (Chen & Huang 2012), which all minimise the
//! unconstrained composite objective
//!
//! `(B1)  1/2 ||F_u x - y||^2 + a TV(x) + b ||Phi_w x||_1`
//!
//! with an orthonormal Daubechies wavelet `Phi_w` (WaTMRI adds a parent-child tree-sparsity
//! term), and a direct TV-constrained solver (Chambolle & Pock 2011) for checking that
//! UDCSMRI(TV) solves `min TV(x) s.t. ||F_u x - y|| <= eps`.
//!
//! As for C-SALSA, data are normalised by `s = max|x0|` so that `a` and `b` are meant for
//! images of unit peak; complex images get the wavelet on their real and imaginary parts
//! separately and a TV coupling both.
//!
//! TVCMRI: the original step rules of Ma et al. could not be checked against their paper
//! here, so (B1) is minimised by the Condat-Vu primal-dual algorithm (Condat 2013, Vu 2013)
//! with the same splitting (gradient step on the data term, wavelet shrinkage, TV handled
//! through projected dual variables); reports label it "TVCMRI (Condat-Vu)".

use num_complex::Complex64;
use rayon::prelude::*;
use wscg_math::progress::Progress;
use wscg_math::wavelet::Daubechies;
use wscg_math::{Error, Result};

use crate::csalsa::{check_inputs, mse, IterStat, Reconstruction};
use crate::fourier::Fourier;
use crate::kspace::KSpace;
use crate::prox::{project_ball, soft_coeffs};
use crate::sparsifier::{CoeffVec, Sparsifier, WaveletSparsifier};
use crate::tv::{divergence, gradient, tv_norm, TvProx};

wscg_math::params! {
    /// Parameters of the composite-objective baselines (B1).
    #[derive(Clone, Debug, PartialEq)]
    pub struct CompositeParams {
        /// TV weight `a` (for unit-peak images).
        pub a: f64,
        /// Wavelet l1 weight `b`.
        pub b: f64,
        /// WaTMRI's parent-child group weight `b_g`.
        pub group_weight: f64,
        /// WaTMRI's coupling `mu_g` of the replicated group variables.
        pub mu_g: f64,
        /// Iterations.
        pub max_iter: usize,
        /// Chambolle iterations per TV prox (FCSA, WaTMRI).
        pub tv_inner: usize,
        /// Daubechies order of `Phi_w`.
        pub order: usize,
        /// Wavelet levels.
        pub levels: usize,
        /// Record an [`IterStat`] per iteration (objective = (B1)).
        pub record_history: bool,
    }
}

impl Default for CompositeParams {
    fn default() -> Self {
        CompositeParams {
            a: 0.001,
            b: 0.035,
            group_weight: 0.035,
            mu_g: 0.001,
            max_iter: 70,
            tv_inner: 20,
            order: 4,
            levels: 4,
            record_history: false,
        }
    }
}

impl CompositeParams {
    /// Checks the ranges: negative or non-finite weights, a Daubechies order outside 1..=8,
    /// zero wavelet levels (whether the image sides are divisible by `2^levels` is checked
    /// when the wavelet is planned).
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [
            ("a", self.a),
            ("b", self.b),
            ("group_weight", self.group_weight),
            ("mu_g", self.mu_g),
        ] {
            if !(v >= 0.0 && v.is_finite()) {
                return Err(Error::invalid(name, format!("{v} must be finite and >= 0")));
            }
        }
        Daubechies::new(self.order)?;
        if self.levels == 0 {
            return Err(Error::invalid("levels", "must be at least 1"));
        }
        Ok(())
    }
}

/// Shared set-up of the composite solvers: normalised data, wavelet, Fourier.
struct Setup {
    rows: usize,
    cols: usize,
    s: f64,
    y: Vec<Complex64>,
    x0: Vec<Complex64>,
    wav: WaveletSparsifier,
}

impl Setup {
    fn new(data: &KSpace, p: &CompositeParams, reference: Option<&[Complex64]>) -> Result<Self> {
        p.validate()?;
        check_inputs(data, None, reference)?;
        let (rows, cols) = data.shape();
        let wav = WaveletSparsifier::new(rows, cols, p.order, p.levels)?;
        let x0 = data.zero_filled();
        let s = x0.iter().map(|v| v.norm()).fold(0.0, f64::max);
        let inv = if s > 0.0 { 1.0 / s } else { 1.0 };
        Ok(Setup {
            rows,
            cols,
            s: if s > 0.0 { s } else { 1.0 },
            y: data.values().iter().map(|v| v * inv).collect(),
            x0: x0.iter().map(|v| v * inv).collect(),
            wav,
        })
    }

    fn fourier(&self) -> &Fourier {
        self.wav.fourier()
    }

    /// The gradient step with unit step on the data term: `x - F_u^H (F_u x - y)`, i.e. the
    /// sampled Fourier bins of `x` replaced by `y`.
    fn data_step(&self, x: &[Complex64], idx: &[usize], out: &mut [Complex64]) {
        out.copy_from_slice(x);
        self.fourier().forward(out);
        for (&k, &v) in idx.iter().zip(&self.y) {
            out[k] = v;
        }
        self.fourier().inverse(out);
    }

    /// `1/2 ||F_u x - y||^2 + a TV(x) + b ||Phi x||_1` (plus the group term), image units.
    fn objective(&self, x: &[Complex64], idx: &[usize], p: &CompositeParams, groups: bool) -> f64 {
        let mut f = x.to_vec();
        self.fourier().forward(&mut f);
        let data: f64 = idx
            .iter()
            .zip(&self.y)
            .map(|(&k, &v)| (f[k] - v).norm_sqr())
            .sum();
        let mut c = self.wav.zeros();
        self.wav.analysis(x, &mut c);
        let mut obj = 0.5 * data + p.a * tv_norm(x, self.rows, self.cols) + p.b * c.l1();
        if groups {
            obj += p.group_weight * group_norm(&self.wav, &c);
        }
        obj
    }

    fn stat(
        &self,
        k: usize,
        (x, prev): (&[Complex64], &[Complex64]),
        idx: &[usize],
        p: &CompositeParams,
        groups: bool,
        reference: Option<&[Complex64]>,
    ) -> IterStat {
        let num: f64 = x.iter().zip(prev).map(|(a, b)| (a - b).norm_sqr()).sum();
        let den: f64 = prev.iter().map(|a| a.norm_sqr()).sum();
        let mut f = x.to_vec();
        self.fourier().forward(&mut f);
        let residual = idx
            .iter()
            .zip(&self.y)
            .map(|(&kk, &v)| (f[kk] - v).norm_sqr())
            .sum::<f64>()
            .sqrt()
            * self.s;
        let img: Vec<Complex64> = x.iter().map(|v| v * self.s).collect();
        IterStat {
            iter: k,
            rel_change: (num / den.max(f64::MIN_POSITIVE)).sqrt(),
            residual,
            objective: self.objective(x, idx, p, groups),
            mse: reference.map(|r| mse(&img, r)),
        }
    }

    fn finish(&self, x: Vec<Complex64>, iters: usize, history: Vec<IterStat>) -> Reconstruction {
        Reconstruction {
            image: x.into_iter().map(|v| v * self.s).collect(),
            shape: (self.rows, self.cols),
            iters,
            history,
        }
    }
}

/// The zero-filled reconstruction as a [`Reconstruction`].
pub fn zero_filled(data: &KSpace) -> Reconstruction {
    Reconstruction {
        image: data.zero_filled(),
        shape: data.shape(),
        iters: 0,
        history: Vec::new(),
    }
}

/// `x2 = Phi^H soft(Phi x, t)`.
fn wavelet_shrink(
    wav: &WaveletSparsifier,
    x: &[Complex64],
    t: f64,
    c: &mut CoeffVec,
    out: &mut [Complex64],
) {
    wav.analysis(x, c);
    soft_coeffs(c, t);
    wav.synthesis(c, out);
}

/// FISTA momentum: `t' = (1 + sqrt(1 + 4 t^2)) / 2`, `r = x + ((t - 1) / t') (x - x_prev)`.
fn momentum(t: &mut f64, x: &[Complex64], prev: &[Complex64], r: &mut [Complex64]) {
    let tn = (1.0 + (1.0 + 4.0 * *t * *t).sqrt()) / 2.0;
    let w = (*t - 1.0) / tn;
    r.par_iter_mut()
        .zip(x.par_iter().zip(prev))
        .for_each(|(r, (x, p))| *r = x + (x - p) * w);
    *t = tn;
}

/// FCSA (Huang, Zhang & Metaxas 2011): FISTA on (B1) where the proximal step averages the
/// TV prox and the wavelet shrinkage (composite splitting), step 1 (`L = 1`).
pub fn fcsa(
    data: &KSpace,
    p: &CompositeParams,
    reference: Option<&[Complex64]>,
    progress: &dyn Progress,
) -> Result<Reconstruction> {
    composite_fista(data, p, reference, progress, false)
}

/// WaTMRI (Chen & Huang 2012): FCSA plus tree sparsity, `b_g sum_g ||(Phi x)_g||_2` over the
/// overlapping groups {wavelet coefficient, its parent}, handled by replication: per
/// iteration `z = group_soft(G Phi r, b_g)` and a gradient step on
/// `mu_g / 2 ||G Phi x - z||^2` added to the data gradient.
pub fn watmri(
    data: &KSpace,
    p: &CompositeParams,
    reference: Option<&[Complex64]>,
    progress: &dyn Progress,
) -> Result<Reconstruction> {
    composite_fista(data, p, reference, progress, true)
}

/// The groups (child, parent) of the wavelet coefficients of both channels.
fn groups(wav: &WaveletSparsifier) -> Vec<(usize, usize)> {
    let (r, c) = wav.shape();
    let n = r * c;
    let w = wav.wavelet();
    (0..2)
        .flat_map(|ch| (0..n).filter_map(move |i| w.parent(i).map(|p| (ch * n + i, ch * n + p))))
        .collect()
}

/// `sum_g ||(Phi x)_g||_2` over the (child, parent) groups.
fn group_norm(wav: &WaveletSparsifier, c: &CoeffVec) -> f64 {
    groups(wav)
        .iter()
        .map(|&(a, b)| (c.real[a].powi(2) + c.real[b].powi(2)).sqrt())
        .sum()
}

fn composite_fista(
    data: &KSpace,
    p: &CompositeParams,
    reference: Option<&[Complex64]>,
    progress: &dyn Progress,
    tree: bool,
) -> Result<Reconstruction> {
    let st = Setup::new(data, p, reference)?;
    let idx = data.sampled();
    let n = st.rows * st.cols;
    let zero = Complex64::new(0.0, 0.0);
    let mut x = st.x0.clone();
    let mut prev = x.clone();
    let mut r = x.clone();
    let mut xg = vec![zero; n];
    let mut x1 = vec![zero; n];
    let mut x2 = vec![zero; n];
    let mut c = st.wav.zeros();
    let mut tv = TvProx::new(st.rows, st.cols);
    let grp = if tree { groups(&st.wav) } else { Vec::new() };
    let mut t = 1.0;
    let mut history = Vec::new();
    progress.begin(if tree { "WaTMRI" } else { "FCSA" }, p.max_iter as u64);
    for k in 0..p.max_iter {
        wscg_math::cancel::check()?;
        st.data_step(&r, idx, &mut xg);
        if tree {
            // xg -= mu_g Phi^H G^H (G Phi r - z), z = group_soft(G Phi r, b_g).
            st.wav.analysis(&r, &mut c);
            let mut g = CoeffVec::zeros(c.real.len(), 0);
            for &(a, b) in &grp {
                let (u, v) = (c.real[a], c.real[b]);
                let m = (u * u + v * v).sqrt();
                let keep = if m > p.group_weight {
                    (m - p.group_weight) / m
                } else {
                    0.0
                };
                // (G Phi r - z)_g = (1 - keep) (u, v), scattered back to both members.
                g.real[a] += (1.0 - keep) * u;
                g.real[b] += (1.0 - keep) * v;
            }
            let mut corr = vec![zero; n];
            st.wav.synthesis(&g, &mut corr);
            xg.par_iter_mut()
                .zip(&corr)
                .for_each(|(x, c)| *x -= c * p.mu_g);
        }
        tv.prox(&xg, 2.0 * p.a, p.tv_inner, &mut x1);
        wavelet_shrink(&st.wav, &xg, 2.0 * p.b, &mut c, &mut x2);
        prev.copy_from_slice(&x);
        x.par_iter_mut()
            .zip(x1.par_iter().zip(&x2))
            .for_each(|(x, (a, b))| *x = (a + b) * 0.5);
        momentum(&mut t, &x, &prev, &mut r);
        if p.record_history {
            history.push(st.stat(k + 1, (&x, &prev), idx, p, tree, reference));
        }
        progress.advance(1);
    }
    progress.finish();
    Ok(st.finish(x, p.max_iter, history))
}

/// TVCMRI's objective (B1) minimised by Condat-Vu: with `f` the data term (gradient
/// Lipschitz constant 1), `g = b ||Phi x||_1` and `h = a ||grad x||_{2,1}`,
///
/// `x' = prox_{tau g}(x - tau (grad f(x) - div p))`,
/// `p' = proj_{||.|| <= a}(p + sigma grad(2x' - x))`,
///
/// with `tau = 1`, `sigma = 1/16` (`1/tau - sigma ||grad||^2 >= 1/2`).
pub fn tvcmri(
    data: &KSpace,
    p: &CompositeParams,
    reference: Option<&[Complex64]>,
    progress: &dyn Progress,
) -> Result<Reconstruction> {
    let st = Setup::new(data, p, reference)?;
    let idx = data.sampled();
    let (rows, cols) = (st.rows, st.cols);
    let n = rows * cols;
    let zero = Complex64::new(0.0, 0.0);
    let (tau, sigma) = (1.0, 1.0 / 16.0);
    let mut x = st.x0.clone();
    let mut prev = x.clone();
    let mut py = vec![zero; n];
    let mut px = vec![zero; n];
    let mut div = vec![zero; n];
    let mut step = vec![zero; n];
    let mut gy = vec![zero; n];
    let mut gx = vec![zero; n];
    let mut c = st.wav.zeros();
    let mut history = Vec::new();
    progress.begin("TVCMRI", p.max_iter as u64);
    for k in 0..p.max_iter {
        wscg_math::cancel::check()?;
        // x - tau grad f(x) = data_step(x) for tau = 1; then + tau div p.
        st.data_step(&x, idx, &mut step);
        divergence(&py, &px, rows, cols, &mut div);
        step.par_iter_mut()
            .zip(&div)
            .for_each(|(s, d)| *s += d * tau);
        prev.copy_from_slice(&x);
        wavelet_shrink(&st.wav, &step, tau * p.b, &mut c, &mut x);
        // Dual ascent on the extrapolated point, projected onto the a-ball per pixel.
        step.par_iter_mut()
            .zip(x.par_iter().zip(&prev))
            .for_each(|(s, (x, q))| *s = x * 2.0 - q);
        gradient(&step, rows, cols, &mut gy, &mut gx);
        py.par_iter_mut()
            .zip(px.par_iter_mut())
            .zip(gy.par_iter().zip(gx.par_iter()))
            .for_each(|((py, px), (&gy, &gx))| {
                let (ny, nx) = (*py + gy * sigma, *px + gx * sigma);
                let m = (ny.norm_sqr() + nx.norm_sqr()).sqrt();
                let sc = if m > p.a { p.a / m } else { 1.0 };
                *py = ny * sc;
                *px = nx * sc;
            });
        if p.record_history {
            history.push(st.stat(k + 1, (&x, &prev), idx, p, false, reference));
        }
        progress.advance(1);
    }
    progress.finish();
    Ok(st.finish(x, p.max_iter, history))
}

/// The (B1) objective of an image (data units), as the baselines define it; `tree` adds
/// WaTMRI's group term.
pub fn composite_objective(
    data: &KSpace,
    x: &[Complex64],
    p: &CompositeParams,
    tree: bool,
) -> Result<f64> {
    let st = Setup::new(data, p, Some(x))?;
    let xn: Vec<Complex64> = x.iter().map(|v| v / st.s).collect();
    Ok(st.objective(&xn, data.sampled(), p, tree))
}

/// Direct solver of `min TV(x) s.t. ||F_u x - y|| <= eps` by Chambolle-Pock (2011, Alg. 1)
/// with `K = grad`: `p' = proj_{|.|<=1}(p + sigma grad xbar)`, `x' = proj_C(x + tau div p')`,
/// `xbar = 2x' - x`, `tau = sigma = 0.99 / sqrt(8)`; `proj_C` projects the sampled Fourier
/// bins onto the data ball. Used to check UDCSMRI(TV), which solves the same problem.
pub fn tv_constrained(
    data: &KSpace,
    epsilon: f64,
    max_iter: usize,
    reference: Option<&[Complex64]>,
) -> Result<Reconstruction> {
    if !(epsilon >= 0.0 && epsilon.is_finite()) {
        return Err(Error::invalid(
            "epsilon",
            format!("{epsilon} must be finite and >= 0"),
        ));
    }
    check_inputs(data, None, reference)?;
    let (rows, cols) = data.shape();
    let n = rows * cols;
    let fourier = Fourier::new(rows, cols)?;
    let x0 = data.zero_filled();
    let s = x0
        .iter()
        .map(|v| v.norm())
        .fold(0.0, f64::max)
        .max(f64::MIN_POSITIVE);
    let y: Vec<Complex64> = data.values().iter().map(|v| v / s).collect();
    let eps = epsilon / s;
    let idx = data.sampled();
    let zero = Complex64::new(0.0, 0.0);
    let (tau, sigma) = (0.99 / 8f64.sqrt(), 0.99 / 8f64.sqrt());
    let mut x: Vec<Complex64> = x0.iter().map(|v| v / s).collect();
    let mut xbar = x.clone();
    let (mut py, mut px) = (vec![zero; n], vec![zero; n]);
    let (mut gy, mut gx, mut div) = (vec![zero; n], vec![zero; n], vec![zero; n]);
    let mut b = vec![zero; idx.len()];
    let mut history = Vec::new();
    for k in 0..max_iter {
        wscg_math::cancel::check()?;
        gradient(&xbar, rows, cols, &mut gy, &mut gx);
        py.par_iter_mut()
            .zip(px.par_iter_mut())
            .zip(gy.par_iter().zip(gx.par_iter()))
            .for_each(|((py, px), (&gy, &gx))| {
                let (ny, nx) = (*py + gy * sigma, *px + gx * sigma);
                let m = (ny.norm_sqr() + nx.norm_sqr()).sqrt().max(1.0);
                *py = ny / m;
                *px = nx / m;
            });
        divergence(&py, &px, rows, cols, &mut div);
        let prev = x.clone();
        x.par_iter_mut().zip(&div).for_each(|(x, d)| *x += d * tau);
        fourier.forward(&mut x);
        for (i, &kk) in idx.iter().enumerate() {
            b[i] = x[kk];
        }
        project_ball(&mut b, &y, eps);
        for (i, &kk) in idx.iter().enumerate() {
            x[kk] = b[i];
        }
        fourier.inverse(&mut x);
        xbar.par_iter_mut()
            .zip(x.par_iter().zip(&prev))
            .for_each(|(xb, (x, p))| *xb = x * 2.0 - p);
        if let Some(r) = reference {
            if (k + 1) % 50 == 0 || k + 1 == max_iter {
                let img: Vec<Complex64> = x.iter().map(|v| v * s).collect();
                history.push(IterStat {
                    iter: k + 1,
                    rel_change: 0.0,
                    residual: data.residual(&img)?,
                    objective: tv_norm(&img, rows, cols),
                    mse: Some(mse(&img, r)),
                });
            }
        }
    }
    Ok(Reconstruction {
        image: x.into_iter().map(|v| v * s).collect(),
        shape: (rows, cols),
        iters: max_iter,
        history,
    })
}
