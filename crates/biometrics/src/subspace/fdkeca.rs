//! FDKECA: feature-dependent kernel entropy component analysis (paper 01, section 3).
//!
//! With `X` the `N x d` training matrix and `Xc` its centred copy (mean image removed, as in
//! the paper's section 4), the feature vector `f_t` is column `t` of `Xc`: pixel `t` across
//! all `N` images. FDKECA
//! 1. builds the `d x d` kernel `K_tt' = k(f_t, f_t')` (eq. 10; the paper's "(N x N)" in
//!    section 3.1 is a typo: its Fig. 2 and complexity argument make `K` `d x d`), from one
//!    GEMM `G = Xc' Xc`;
//! 2. eigendecomposes `K = E L E'` (negative round-off eigenvalues clipped to 0);
//! 3. scores each eigenpair by its contribution to the Renyi entropy estimate,
//!    `psi_i = lambda_i (1' e_i)^2` (eq. 9 applied in the feature space), with
//!    `V = (1/d^2) sum_i psi_i = (1/d^2) 1' K 1` (eq. 8);
//! 4. keeps the `l` eigenvectors of largest `psi` as axes `A` (`d x l`) and projects
//!    `y = A' (x - mean)`.
//!
//! The cost depends on `d`, not on `N` (beyond the `O(N d^2)` GEMM): the paper's main claim.
//! `K` itself is not centred (a centred kernel has `K 1 = 0` and all `psi = 0`).

use faer::{Mat, MatRef};
use serde::{Deserialize, Serialize};
use wscg_math::image::Image;
use wscg_math::{dense, Error, Result};

use super::kernel::{kernel_from_gram, resolve, Kernel, ResolvedKernel};
use super::{
    check_components, check_data, check_query, column_means, columns, from_columns, order_desc,
    subtract_mean, Projector,
};

/// How eigenpairs are ranked.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Ordering {
    /// By entropy contribution `psi_i = lambda_i (1' e_i)^2` (the paper; ties by eigenvalue).
    #[default]
    Entropy,
    /// By eigenvalue (kernel-Gram PCA; with the linear kernel this is PCA).
    Eigenvalue,
}

wscg_math::params! {
    /// Parameters of [`Fdkeca::fit`].
    #[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
    pub struct FdkecaParams {
        /// Kernel between feature vectors (default: Gaussian, sigma = median distance).
        pub kernel: Kernel,
        /// Number of axes kept (default: all `d`).
        pub n_components: Option<usize>,
        /// Ranking of the eigenpairs (default: entropy).
        pub ordering: Ordering,
        /// Subtract the mean image before building the kernel (default: true, section 4).
        pub center: bool,
    }
}

impl Default for FdkecaParams {
    fn default() -> Self {
        Self {
            kernel: Kernel::default(),
            n_components: None,
            ordering: Ordering::Entropy,
            center: true,
        }
    }
}

impl FdkecaParams {
    /// Errors: bad fixed kernel parameters (the error names the kernel parameter: `degree`,
    /// `gamma`, `coef0`, `sigma` or `sigma_scale`), `n_components == Some(0)`. Whether
    /// `n_components` exceeds the feature count `d` is checked by [`Fdkeca::fit`].
    pub fn validate(&self) -> Result<()> {
        super::kernel::validate(&self.kernel)?;
        if self.n_components == Some(0) {
            return Err(Error::invalid("n_components", "must be >= 1, got 0"));
        }
        Ok(())
    }
}

/// A fitted FDKECA model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Fdkeca {
    /// Mean training image (zeros when not centring), length `d`.
    pub mean: Vec<f64>,
    /// The axes `e_pi(1), ..., e_pi(l)`, each of length `d`, in ranking order.
    pub axes: Vec<Vec<f64>>,
    /// Eigenvalues `lambda` of the kept axes, in ranking order.
    pub eigenvalues: Vec<f64>,
    /// Entropy terms `psi` of the kept axes, in ranking order.
    pub entropy_terms: Vec<f64>,
    /// `1' K 1 = sum of psi over all d eigenpairs`.
    pub kernel_sum: f64,
    /// The kernel with its data-dependent parameters resolved (`sigma_used` for Gaussian).
    pub kernel: ResolvedKernel,
    /// Ranking used.
    pub ordering: Ordering,
    /// Number of training images `N`.
    pub n_train: usize,
}

impl Fdkeca {
    /// Fits FDKECA to the `N x d` matrix `x` (one image per row).
    ///
    /// Errors: `N < 2`, `d = 0`, NaN/inf, bad kernel parameters, `n_components` 0 or > d,
    /// all feature vectors identical under the median heuristic.
    pub fn fit(x: MatRef<'_, f64>, p: &FdkecaParams) -> Result<Self> {
        p.validate()?;
        let (n, d) = (x.nrows(), x.ncols());
        let fk = feature_kernel(x, &p.kernel, p.center)?;
        let l = check_components(p.n_components, d)?;
        let (mean, k, kernel) = (fk.mean, fk.k, fk.kernel);
        let e = dense::eigh(k.as_ref())?;
        let (lambda, psi) = super::entropy_terms(&e);
        let order = match p.ordering {
            Ordering::Entropy => order_desc(&psi, &lambda),
            Ordering::Eigenvalue => order_desc(&lambda, &psi),
        };
        let keep = &order[..l];
        let ones_k: f64 = (0..d).map(|i| (0..d).map(|j| k[(i, j)]).sum::<f64>()).sum();
        Ok(Self {
            mean,
            axes: columns(e.vectors.as_ref(), keep),
            eigenvalues: keep.iter().map(|&i| lambda[i]).collect(),
            entropy_terms: keep.iter().map(|&i| psi[i]).collect(),
            kernel_sum: ones_k,
            kernel,
            ordering: p.ordering,
            n_train: n,
        })
    }

    /// The axes as a `d x l` matrix.
    pub fn axes_matrix(&self) -> Mat<f64> {
        from_columns(self.mean.len(), &self.axes)
    }

    /// The Renyi quadratic entropy estimate `V = 1' K 1 / d^2` (eq. 8; `H = -log V`).
    pub fn renyi_entropy_estimate(&self) -> f64 {
        let d = self.mean.len() as f64;
        self.kernel_sum / (d * d)
    }

    /// The same model with only the first `l` axes (no refit).
    pub fn truncated(&self, l: usize) -> Result<Self> {
        let l = check_components(Some(l), self.axes.len())?;
        let mut m = self.clone();
        m.axes.truncate(l);
        m.eigenvalues.truncate(l);
        m.entropy_terms.truncate(l);
        Ok(m)
    }

    /// Reconstructs images from projections `y` (`m x l`): `x = mean + A y` (the axes are
    /// orthonormal, so this is the least-squares pre-image; exact at `l = d`).
    pub fn inverse_transform(&self, y: MatRef<'_, f64>) -> Result<Mat<f64>> {
        super::reconstruct(&self.mean, &self.axes, None, y)
    }

    /// The first `k` axes as `height x width` images, each min-max scaled to `[0, 1]` (the
    /// paper's eigenface view, section 4). Errors when `height * width != d` or `k` is out
    /// of range.
    pub fn axis_images(&self, k: usize, height: usize, width: usize) -> Result<Vec<Image>> {
        axis_images(&self.axes, k, height, width)
    }

    /// Serialises the fitted model to JSON.
    pub fn to_json(&self) -> Result<String> {
        serde_json::to_string(self).map_err(|e| Error::invalid("model", e.to_string()))
    }

    /// Reads a model written by [`Fdkeca::to_json`].
    pub fn from_json(s: &str) -> Result<Self> {
        serde_json::from_str(s).map_err(|e| Error::invalid("json", e.to_string()))
    }
}

/// The feature-space kernel of a data matrix (step 1 of section 3.1).
#[derive(Clone, Debug)]
pub struct FeatureKernel {
    /// Column means subtracted (zeros when not centring).
    pub mean: Vec<f64>,
    /// `K_tt' = k(f_t, f_t')`, `d x d` (eq. 10).
    pub k: Mat<f64>,
    /// The kernel with data-dependent parameters resolved.
    pub kernel: ResolvedKernel,
}

/// Builds FDKECA's `d x d` kernel between the feature vectors (columns of the centred `x`)
/// from one GEMM `G = Xc' Xc`.
///
/// Errors: `N < 2`, `d = 0`, NaN/inf, bad kernel parameters, all feature vectors identical
/// under the median heuristic.
pub fn feature_kernel(x: MatRef<'_, f64>, kernel: &Kernel, center: bool) -> Result<FeatureKernel> {
    check_data("x", x, 2)?;
    let (n, d) = (x.nrows(), x.ncols());
    let mean = if center {
        column_means(x)
    } else {
        vec![0.0; d]
    };
    let g = wscg_math::dense::centered_gram(x, &mean, 1.0);
    let kernel = resolve(kernel, g.as_ref(), n, "features")?;
    let k = kernel_from_gram(g.as_ref(), &kernel);
    Ok(FeatureKernel { mean, k, kernel })
}

/// Axes (each of length `height * width`) as min-max scaled images.
pub fn axis_images(axes: &[Vec<f64>], k: usize, height: usize, width: usize) -> Result<Vec<Image>> {
    let k = check_components(Some(k), axes.len())?;
    let d = axes.first().map_or(0, |a| a.len());
    if height * width != d {
        return Err(Error::ShapeMismatch(format!(
            "axes have {d} values, not {height} x {width}"
        )));
    }
    axes[..k]
        .iter()
        .map(|a| {
            let (lo, hi) = a
                .iter()
                .fold((f64::MAX, f64::MIN), |(l, h), &v| (l.min(v), h.max(v)));
            let span = if hi > lo { hi - lo } else { 1.0 };
            Image::new(
                height,
                width,
                1,
                a.iter().map(|&v| ((v - lo) / span) as f32).collect(),
            )
        })
        .collect()
}

impl Projector for Fdkeca {
    /// `y = A' (x - mean)` for every row (section 3).
    fn transform(&self, x: MatRef<'_, f64>) -> Result<Mat<f64>> {
        check_query(x, self.mean.len())?;
        Ok(subtract_mean(x, &self.mean) * self.axes_matrix())
    }
    fn n_components(&self) -> usize {
        self.axes.len()
    }
    fn input_dim(&self) -> usize {
        self.mean.len()
    }
}
