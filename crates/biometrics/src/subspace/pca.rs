//! PCA baseline (paper 01, section 2.1).
//!
//! The covariance `C = Xc' Xc / N` (eq. 1, with the paper's `1/N`) is decomposed as
//! `V Delta V'`; the projection is `y = V_l' (x - mean)`, or the paper's whitened
//! `Delta_l^{-1/2} V_l' (x - mean)` when `whiten` is set (off by default: classic
//! eigenfaces, whose nearest-neighbour distances whitening would change). When `N < d` the
//! SVD of `Xc` is used instead (at most `min(N, d)` components).

use faer::{Mat, MatRef};
use serde::{Deserialize, Serialize};
use wscg_math::image::Image;
use wscg_math::{dense, Error, Result};

use super::{
    check_components, check_data, check_query, column_means, columns, from_columns, subtract_mean,
    Projector,
};

/// A fitted PCA.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Pca {
    /// Mean of the training rows.
    pub mean: Vec<f64>,
    /// Principal axes (unit vectors of length `d`), by decreasing variance.
    pub components: Vec<Vec<f64>>,
    /// Variances `delta_i` (eigenvalues of `Xc' Xc / N`) of the kept axes.
    pub variances: Vec<f64>,
    /// Whether [`Projector::transform`] divides by `sqrt(delta_i)`.
    pub whiten: bool,
}

impl Pca {
    /// Checks that a model read from a file is consistent: a non-empty mean, every axis of
    /// its length, one variance per axis. [`Projector::transform`] indexes by these sizes.
    pub fn check_shapes(&self) -> Result<()> {
        let d = self.mean.len();
        if d == 0 {
            return Err(Error::invalid("pca", "the mean is empty"));
        }
        if let Some((i, c)) = self
            .components
            .iter()
            .enumerate()
            .find(|(_, c)| c.len() != d)
        {
            return Err(Error::invalid(
                "pca",
                format!("axis {i} has {} values, the mean {d}", c.len()),
            ));
        }
        if self.variances.len() != self.components.len() {
            return Err(Error::invalid(
                "pca",
                format!(
                    "{} variances for {} axes",
                    self.variances.len(),
                    self.components.len()
                ),
            ));
        }
        Ok(())
    }

    /// Fits PCA to the `N x d` matrix `x`, keeping `n_components` axes (default all
    /// available: `d`, or `min(N, d)` when `N < d`).
    pub fn fit(x: MatRef<'_, f64>, n_components: Option<usize>, whiten: bool) -> Result<Self> {
        check_data("x", x, 2)?;
        let (n, d) = (x.nrows(), x.ncols());
        let mean = column_means(x);
        let (components, variances): (Vec<Vec<f64>>, Vec<f64>) = if n >= d {
            let l = check_components(n_components, d)?;
            covariance_axes(x, &mean, l)?
        } else {
            let s = dense::svd(subtract_mean(x, &mean).as_ref())?;
            let l = check_components(n_components, s.s.len())?;
            let idx: Vec<usize> = (0..l).collect();
            (
                columns(s.v.as_ref(), &idx),
                s.s[..l].iter().map(|v| v * v / n as f64).collect(),
            )
        };
        if whiten {
            if let Some(i) = variances.iter().position(|&v| v <= 1e-12 * variances[0]) {
                return Err(Error::invalid(
                    "n_components",
                    format!("component {i} has zero variance and cannot be whitened"),
                ));
            }
        }
        Ok(Self {
            mean,
            components,
            variances,
            whiten,
        })
    }

    /// The same model with the first `l` axes.
    pub fn truncated(&self, l: usize) -> Result<Self> {
        let l = check_components(Some(l), self.components.len())?;
        let mut m = self.clone();
        m.components.truncate(l);
        m.variances.truncate(l);
        Ok(m)
    }

    /// Reconstructs rows from projections `y` (`m x l`): `x = mean + V_l y` (eigenface
    /// reconstruction; undoes the whitening when set).
    pub fn inverse_transform(&self, y: MatRef<'_, f64>) -> Result<Mat<f64>> {
        let scale: Option<Vec<f64>> = self
            .whiten
            .then(|| self.variances.iter().map(|v| v.sqrt()).collect());
        super::reconstruct(&self.mean, &self.components, scale.as_deref(), y)
    }

    /// The first `k` axes as min-max scaled `height x width` images (eigenfaces).
    pub fn axis_images(&self, k: usize, height: usize, width: usize) -> Result<Vec<Image>> {
        super::fdkeca::axis_images(&self.components, k, height, width)
    }
}

/// The `l` leading eigenpairs of the covariance of `x` (`n >= d`). Constant columns (image
/// borders that are background in every sample, say) have zero rows and columns in the
/// covariance: the eigenproblem is solved on the other columns only and the axes are padded
/// with zeros there, which is exact and saves the quadratic cost of those columns. When
/// `l` exceeds the number of varying columns, unit axes of constant columns (variance 0)
/// complete the set.
fn covariance_axes(
    x: MatRef<'_, f64>,
    mean: &[f64],
    l: usize,
) -> Result<(Vec<Vec<f64>>, Vec<f64>)> {
    let (n, d) = (x.nrows(), x.ncols());
    let (varying, constant): (Vec<usize>, Vec<usize>) =
        (0..d).partition(|&j| x.col(j).iter().any(|&v| v != x[(0, j)]));
    let mut axes = Vec::with_capacity(l);
    let mut variances = Vec::with_capacity(l);
    let q = varying.len().min(l);
    if q > 0 {
        let sub_mean: Vec<f64> = varying.iter().map(|&j| mean[j]).collect();
        let c = dense::centered_gram_of(x, &varying, &sub_mean, 1.0 / n as f64);
        let e = dense::eigh_largest(c.as_ref(), q)?;
        for k in 0..q {
            let mut axis = vec![0.0; d];
            for (r, &j) in varying.iter().enumerate() {
                axis[j] = e.vectors[(r, k)];
            }
            axes.push(axis);
            variances.push(e.values[k].max(0.0));
        }
    }
    for &j in constant.iter().take(l - q) {
        let mut axis = vec![0.0; d];
        axis[j] = 1.0;
        axes.push(axis);
        variances.push(0.0);
    }
    Ok((axes, variances))
}

impl Projector for Pca {
    fn transform(&self, x: MatRef<'_, f64>) -> Result<Mat<f64>> {
        check_query(x, self.mean.len())?;
        // (x - 1 mean') V computed as x V - 1 (mean' V): no centred copy of x.
        let v = from_columns(self.mean.len(), &self.components);
        let mut y = x * &v;
        let shift: Vec<f64> = (0..v.ncols())
            .map(|j| v.col(j).iter().zip(&self.mean).map(|(a, b)| a * b).sum())
            .collect();
        for (j, s) in shift.iter().enumerate() {
            for i in 0..y.nrows() {
                y[(i, j)] -= s;
            }
        }
        if self.whiten {
            for j in 0..y.ncols() {
                let s = self.variances[j].sqrt();
                for i in 0..y.nrows() {
                    y[(i, j)] /= s;
                }
            }
        }
        Ok(y)
    }
    fn n_components(&self) -> usize {
        self.components.len()
    }
    fn input_dim(&self) -> usize {
        self.mean.len()
    }
}
