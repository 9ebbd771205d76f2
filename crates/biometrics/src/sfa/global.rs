//! SFA learned once on the whole data set (paper 05, section 2.2, "Full dataset" row of
//! Table 1; Berkes 2005): one shared set of `K` functions minimising the class-weighted sum
//! of the per-class objectives, `A = sum_C pi_C A_C`, `A w = lambda B w`.
//!
//! With `gamma = 0` this is Berkes' SFA for pattern recognition, which equals Fisher
//! discriminant analysis (only `C - 1` functions are informative). The paper does not say
//! how the shared functions classify; two rules are offered: the nearest class mean in the
//! paper's variance sense (`Var_C = |W'(z - mu_C)|^2`, the default) and Berkes' class-wise
//! Gaussians with full covariance on the outputs and equal priors.

use faer::{Mat, MatRef};
use serde::{Deserialize, Serialize};
use wscg_math::{dense, Error, Result};

use super::class_sfa::{
    argmin_rows, check_training, checked_model_shapes, fit_pca, lengths, whitened_objective,
    ClassSfaParams,
};
use super::scatter::{project_blocks, ClassMoments, Whitening};
use crate::subspace::{check_query, Pca, Projector};

/// How [`GlobalSfa`] turns its outputs into a class.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum GlobalRule {
    /// Smallest `|W'(z - mu_C)|^2`.
    #[default]
    NearestMeanVariance,
    /// Largest class-conditional Gaussian likelihood of `W'z` (Berkes 2005).
    Gaussian,
}

/// A fitted full-data-set SFA classifier.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct GlobalSfa {
    /// Configuration (`m_per_class` is the number `K` of shared functions).
    pub config: ClassSfaParams,
    /// The decision rule.
    pub rule: GlobalRule,
    /// PCA before the expansion.
    pub pca: Pca,
    /// Class labels, ascending.
    pub classes: Vec<u32>,
    /// Shared functions `W` (`D x K`).
    #[serde(with = "crate::subspace::serde_mat")]
    pub w: Mat<f64>,
    /// Eigenvalues of the functions, ascending.
    pub lambdas: Vec<f64>,
    /// Per class: `W' mu_C`.
    pub class_means: Vec<Vec<f64>>,
    /// Per class: the inverse of `W' S_C W` and half its log-determinant (Gaussian rule).
    pub gaussians: Vec<(Vec<f64>, f64)>,
}

impl GlobalSfa {
    /// Fits `cfg.m_per_class` shared functions. Errors as [`super::PerClassSfa::fit`].
    pub fn fit(
        x: MatRef<'_, f64>,
        y: &[u32],
        cfg: &ClassSfaParams,
        rule: GlobalRule,
    ) -> Result<Self> {
        cfg.validate()?;
        check_training(x, y, 2)?;
        let (pca, xp) = fit_pca(x, cfg.pca_dims)?;
        let mom = ClassMoments::accumulate(xp.as_ref(), y, cfg.expansion);
        let white = Whitening::new(mom.total_covariance().as_ref(), cfg.rank_tol)?;
        let r = white.rank;
        let n = mom.total() as f64;
        let mut a = Mat::<f64>::zeros(r, r);
        for c in 0..mom.classes.len() {
            let pi = mom.counts[c] as f64 / n;
            a +=
                whitened_objective(&mom, &white, c, cfg.objective, cfg.shrinkage) * faer::Scale(pi);
        }
        let (lambdas, w) = white.smallest(a.as_ref(), cfg.m_per_class)?;
        let k = w.ncols();
        let mut class_means = Vec::new();
        let mut gaussians = Vec::new();
        for c in 0..mom.classes.len() {
            let mu = mom.class_mean(c);
            class_means.push(
                (0..k)
                    .map(|j| (0..mu.len()).map(|i| w[(i, j)] * mu[i]).sum())
                    .collect(),
            );
            let cov = w.transpose() * mom.class_terms(c).s_c * &w;
            let e = dense::eigh(super::scatter::symmetrized(cov).as_ref())?;
            let floor = 1e-12 * e.values.last().copied().unwrap_or(1.0).max(1e-300);
            let vals: Vec<f64> = e.values.iter().map(|v| v.max(floor)).collect();
            let inv = Mat::from_fn(k, k, |i, j| {
                (0..k)
                    .map(|t| e.vectors[(i, t)] * e.vectors[(j, t)] / vals[t])
                    .sum()
            });
            let half_logdet = 0.5 * vals.iter().map(|v| v.ln()).sum::<f64>();
            gaussians.push((
                (0..k * k).map(|t| inv[(t / k, t % k)]).collect(),
                half_logdet,
            ));
        }
        Ok(Self {
            config: *cfg,
            rule,
            pca,
            classes: mom.classes,
            w,
            lambdas,
            class_means,
            gaussians,
        })
    }

    /// The shared outputs `W' z` of the rows of `x` (`n x K`).
    pub fn transform(&self, x: MatRef<'_, f64>) -> Result<Mat<f64>> {
        check_query(x, self.pca.input_dim())?;
        let xp = self.pca.transform(x)?;
        Ok(project_blocks(
            xp.as_ref(),
            self.config.expansion,
            self.w.as_ref(),
        ))
    }

    /// Per row and class the rule's score, smaller is better: `Var_C`, or the negative
    /// Gaussian log-likelihood up to a constant.
    pub fn decision_scores(&self, x: MatRef<'_, f64>) -> Result<Mat<f64>> {
        let y = self.transform(x)?;
        let k = self.w.ncols();
        Ok(Mat::from_fn(y.nrows(), self.classes.len(), |i, c| {
            let d: Vec<f64> = (0..k).map(|j| y[(i, j)] - self.class_means[c][j]).collect();
            match self.rule {
                GlobalRule::NearestMeanVariance => d.iter().map(|v| v * v).sum(),
                GlobalRule::Gaussian => {
                    let (inv, half_logdet) = &self.gaussians[c];
                    let q: f64 = (0..k)
                        .map(|a| d[a] * (0..k).map(|b| inv[a * k + b] * d[b]).sum::<f64>())
                        .sum();
                    0.5 * q + half_logdet
                }
            }
        }))
    }

    /// The class of smallest score for every row, ties to the smallest label.
    pub fn predict(&self, x: MatRef<'_, f64>) -> Result<Vec<u32>> {
        Ok(argmin_rows(
            self.decision_scores(x)?.as_ref(),
            &self.classes,
        ))
    }

    /// The model as JSON.
    pub fn to_json(&self) -> Result<String> {
        serde_json::to_string(self).map_err(|e| Error::invalid("model", e.to_string()))
    }

    /// A model from [`Self::to_json`] output, checked with [`Self::check_shapes`].
    pub fn from_json(s: &str) -> Result<Self> {
        crate::model_json::checked_from_json(s, "global SFA model", Self::check_shapes)
    }

    /// Checks that a model read from a file is consistent (its parameters valid, every array
    /// of the size the others imply), so that scoring it cannot index out of bounds.
    pub fn check_shapes(&self) -> Result<()> {
        self.config.validate()?;
        checked_model_shapes(&self.pca, self.config.expansion, &self.w, &self.classes)?;
        let (nc, k) = (self.classes.len(), self.w.ncols());
        lengths("lambdas", [self.lambdas.len()], k)?;
        lengths("class_means", [self.class_means.len()], nc)?;
        lengths("class_means", self.class_means.iter().map(Vec::len), k)?;
        if self.rule == GlobalRule::Gaussian {
            lengths("gaussians", [self.gaussians.len()], nc)?;
            lengths("gaussians", self.gaussians.iter().map(|g| g.0.len()), k * k)?;
        }
        Ok(())
    }
}

/// Rejects an unknown rule name.
pub fn parse_rule(name: &str) -> Result<GlobalRule> {
    match name {
        "variance" => Ok(GlobalRule::NearestMeanVariance),
        "gaussian" => Ok(GlobalRule::Gaussian),
        other => Err(Error::invalid(
            "rule",
            format!("{other:?}: use variance or gaussian"),
        )),
    }
}
