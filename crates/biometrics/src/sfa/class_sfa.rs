//! Class-wise slow feature analysis (paper 05, sections 2.2 and 3; eqs. 8-17): per class `C`,
//! `m` linear functions of the PCA-reduced, quadratically expanded input that vary little
//! inside `C` and much outside it; a sample goes to the class whose centred responses have
//! the smallest energy.
//!
//! With `S_C`, `S_not` the within-class scatters of `C` and of the other classes and
//! `d = mu_C - mu_not`, the paper's averaged pairwise differences are, for `y = w'z`,
//! - within the class (eq. 12): `<grad_C> = (1/N_C^2) sum_{el,n in C} (w'(z_n - z_el))^2
//!   = 2 w' S_C w`,
//! - across the class boundary (eq. 13): `(1/(N_C N_not)) sum_{el in C, n not in C}
//!   (w'(z_n - z_el))^2 = w'(S_C + S_not + d d')w`,
//!
//! and the objective (eq. 14) `O_C = <grad_C> - gamma <grad_C^o>` (`gamma = 1` in the paper)
//! is minimised under `w' B w = 1` and mutual `B`-orthogonality, `B` the covariance of all
//! training rows: the `m` smallest eigenpairs of `A_C w = lambda B w`.
//!
//! Choices where the paper is silent or inconsistent:
//! - eqs. 8-13 wrap the sums in a square root, which leaves no quadratic form and no
//!   eigen-solution; the root is dropped (as in Berkes 2005);
//! - the sums are mean-normalised by their pair counts (raw sums would weight the
//!   out-of-class term by `N_not / N_C`);
//! - section 3.2.2 says "largest eigenvalues", section 2.1 "smallest": minimising `O_C` is
//!   the smallest eigenvalues of `A_C`;
//! - the within-class scatter is shrunk towards its mean eigenvalue by `shrinkage` (in
//!   whitened coordinates), for classes with fewer rows than expanded dimensions.
//!
//! Classification (eqs. 15-17): `r_C(P) = W_C'(z(P) - mu_C)`, `Var_C(P) = |r_C(P)|^2`,
//! the class of smallest `Var_C` (ties to the smallest label).

use faer::{Mat, MatRef};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use wscg_math::{Error, Result};

use super::expansion::QuadraticExpansion;
use super::scatter::{project_blocks, symmetrized, ClassMoments, Whitening};
use crate::subspace::classify::check_labels;
use crate::subspace::{check_data, check_query, Pca, Projector};

/// The objective minimised per class.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum ClassObjective {
    /// Within-class slowness only (`A_C = 2 S_C`).
    WithinOnly,
    /// The paper's eq. 14: `A_C = 2 S_C - gamma (S_C + S_not + d d')`.
    WithinMinusOutOfClass {
        /// Weight of the out-of-class term (1 in the paper).
        gamma: f64,
    },
}

wscg_math::params! {
    /// Parameters of [`PerClassSfa`] (and of [`super::GlobalSfa`]).
    #[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
    pub struct ClassSfaParams {
        /// PCA dimensions before the expansion (35 in the paper).
        pub pca_dims: usize,
        /// The expansion (quadratic with linear terms by default; `None`: linear SFA).
        pub expansion: Option<QuadraticExpansion>,
        /// Slow functions per class (10 in the paper).
        pub m_per_class: usize,
        /// The objective (eq. 14 with `gamma = 1` by default).
        pub objective: ClassObjective,
        /// Shrinkage `alpha` of the within-class scatter: `S_C + alpha tr(S_C)/r I` (whitened).
        pub shrinkage: f64,
        /// Relative eigenvalue below which whitening drops a direction.
        pub rank_tol: f64,
    }
}

impl Default for ClassSfaParams {
    fn default() -> Self {
        Self {
            pca_dims: 35,
            expansion: Some(QuadraticExpansion::default()),
            m_per_class: 10,
            objective: ClassObjective::WithinMinusOutOfClass { gamma: 1.0 },
            shrinkage: 1e-6,
            rank_tol: 1e-10,
        }
    }
}

impl ClassSfaParams {
    /// Checks the numeric parameters. Errors: `pca_dims` or `m_per_class` zero, a negative
    /// or non-finite `shrinkage`, `rank_tol` or `gamma`.
    pub fn validate(&self) -> Result<()> {
        if self.pca_dims == 0 {
            return Err(Error::invalid("pca_dims", "must be at least 1"));
        }
        if self.m_per_class == 0 {
            return Err(Error::invalid(
                "m_per_class",
                "the number m of slow functions must be at least 1",
            ));
        }
        if !(self.shrinkage.is_finite() && self.shrinkage >= 0.0) {
            return Err(Error::invalid("shrinkage", "must be finite and >= 0"));
        }
        if !(self.rank_tol.is_finite() && self.rank_tol >= 0.0) {
            return Err(Error::invalid(
                "rank_tol",
                format!("must be finite and >= 0, got {}", self.rank_tol),
            ));
        }
        if let ClassObjective::WithinMinusOutOfClass { gamma } = self.objective {
            if !(gamma.is_finite() && gamma >= 0.0) {
                return Err(Error::invalid("gamma", "must be finite and >= 0"));
            }
        }
        Ok(())
    }
}

/// Validated training data: labels, classes with enough rows.
pub(crate) fn check_training(x: MatRef<'_, f64>, y: &[u32], min_per_class: usize) -> Result<()> {
    if x.nrows() == 0 {
        return Err(Error::Empty("x"));
    }
    check_data("x", x, 2)?;
    check_labels(x, y)?;
    let (classes, rows) = super::scatter::group_labels(y);
    if classes.len() < 2 {
        return Err(Error::invalid("y", "needs at least 2 classes"));
    }
    if let Some((c, r)) = classes
        .iter()
        .zip(&rows)
        .find(|(_, r)| r.len() < min_per_class)
    {
        return Err(Error::invalid(
            "y",
            format!(
                "class {c} has {} rows; at least {min_per_class} are needed",
                r.len()
            ),
        ));
    }
    Ok(())
}

/// PCA to `cfg.pca_dims` (checked against the data) and the projected rows.
pub(crate) fn fit_pca(x: MatRef<'_, f64>, pca_dims: usize) -> Result<(Pca, Mat<f64>)> {
    let limit = (x.nrows() - 1).min(x.ncols());
    if pca_dims > limit {
        return Err(Error::invalid(
            "pca_dims",
            format!(
                "{pca_dims} exceeds min(n - 1, n_features) = {limit} (n = {}, n_features = {})",
                x.nrows(),
                x.ncols()
            ),
        ));
    }
    let pca = Pca::fit(x, Some(pca_dims), false)?;
    let xp = pca.transform(x)?;
    Ok((pca, xp))
}

/// `A_C` of class `c` in whitened coordinates.
pub(crate) fn whitened_objective(
    mom: &ClassMoments,
    white: &Whitening,
    c: usize,
    objective: ClassObjective,
    shrinkage: f64,
) -> Mat<f64> {
    let t = mom.class_terms(c);
    let r = white.rank;
    let mut s_c = white.project(t.s_c.as_ref());
    if shrinkage > 0.0 {
        let tr: f64 = (0..r).map(|i| s_c[(i, i)]).sum();
        for i in 0..r {
            s_c[(i, i)] += shrinkage * tr / r as f64;
        }
    }
    match objective {
        ClassObjective::WithinOnly => s_c * faer::Scale(2.0),
        ClassObjective::WithinMinusOutOfClass { gamma } => {
            let s_not = white.project(t.s_not.as_ref());
            let dw: Vec<f64> = (0..r)
                .map(|k| (0..t.d.len()).map(|i| white.s[(i, k)] * t.d[i]).sum())
                .collect();
            symmetrized(Mat::from_fn(r, r, |i, j| {
                2.0 * s_c[(i, j)] - gamma * (s_c[(i, j)] + s_not[(i, j)] + dw[i] * dw[j])
            }))
        }
    }
}

/// A fitted class-wise SFA classifier.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PerClassSfa {
    /// The configuration it was fitted with.
    pub config: ClassSfaParams,
    /// The PCA before the expansion.
    pub pca: Pca,
    /// Class labels, ascending.
    pub classes: Vec<u32>,
    /// `[W_1 .. W_C]` (`D x C m`): class `c`'s functions are columns `c m .. (c + 1) m`.
    #[serde(with = "crate::subspace::serde_mat")]
    pub w: Mat<f64>,
    /// `W_c' mu_c` for every column of `w`.
    pub offsets: Vec<f64>,
    /// Per class: the eigenvalues `lambda` of its functions, ascending.
    pub lambdas: Vec<Vec<f64>>,
    /// Per class: the training mean `mu_C` of the expanded rows.
    pub means: Vec<Vec<f64>>,
    /// Rank of the expanded training covariance.
    pub rank: usize,
}

impl PerClassSfa {
    /// Fits the model to the rows of `x` (`n x p`, e.g. flattened images) with labels `y`
    /// (any `u32` values).
    ///
    /// Errors: empty or non-finite `x`, label count, fewer than 2 classes, a class with at
    /// most `m` rows, `pca_dims` above `min(n - 1, p)`, `m` above the expanded rank, rank-0
    /// data.
    pub fn fit(x: MatRef<'_, f64>, y: &[u32], cfg: &ClassSfaParams) -> Result<Self> {
        cfg.validate()?;
        check_training(x, y, cfg.m_per_class + 1)?;
        let (pca, xp) = fit_pca(x, cfg.pca_dims)?;
        let mom = ClassMoments::accumulate(xp.as_ref(), y, cfg.expansion);
        let white = Whitening::new(mom.total_covariance().as_ref(), cfg.rank_tol)?;
        let m = cfg.m_per_class;
        let per_class: Vec<(Vec<f64>, Mat<f64>)> = (0..mom.classes.len())
            .into_par_iter()
            .map(|c| {
                let a = whitened_objective(&mom, &white, c, cfg.objective, cfg.shrinkage);
                white.smallest(a.as_ref(), m)
            })
            .collect::<Result<_>>()?;
        let dim = mom.dim();
        let nc = mom.classes.len();
        let means: Vec<Vec<f64>> = (0..nc).map(|c| mom.class_mean(c)).collect();
        let w = Mat::from_fn(dim, nc * m, |i, j| per_class[j / m].1[(i, j % m)]);
        let offsets = (0..nc * m)
            .map(|j| (0..dim).map(|i| w[(i, j)] * means[j / m][i]).sum())
            .collect();
        Ok(Self {
            config: *cfg,
            pca,
            classes: mom.classes,
            w,
            offsets,
            lambdas: per_class.into_iter().map(|p| p.0).collect(),
            means,
            rank: white.rank,
        })
    }

    /// Input width the model expects.
    pub fn input_dim(&self) -> usize {
        self.pca.input_dim()
    }

    /// The centred responses `z W - offsets` of every row to the functions in columns
    /// `cols` of [`Self::w`], blocks of rows in parallel.
    fn responses_of(&self, x: MatRef<'_, f64>, cols: std::ops::Range<usize>) -> Result<Mat<f64>> {
        check_query(x, self.input_dim())?;
        let xp = self.pca.transform(x)?;
        let w = self.w.as_ref().subcols(cols.start, cols.len());
        let mut r = project_blocks(xp.as_ref(), self.config.expansion, w);
        for (j, o) in self.offsets[cols].iter().enumerate() {
            r.col_mut(j).iter_mut().for_each(|v| *v -= o);
        }
        Ok(r)
    }

    /// `Var_C` (eq. 16) of every row for every class (`n x C`, columns in [`Self::classes`]
    /// order); smaller is better.
    pub fn decision_scores(&self, x: MatRef<'_, f64>) -> Result<Mat<f64>> {
        let r = self.responses_of(x, 0..self.w.ncols())?;
        let m = self.config.m_per_class;
        Ok(Mat::from_fn(x.nrows(), self.classes.len(), |i, c| {
            (0..m).map(|k| r[(i, c * m + k)].powi(2)).sum()
        }))
    }

    /// The class of smallest `Var_C` for every row (eq. 17), ties to the smallest label.
    pub fn predict(&self, x: MatRef<'_, f64>) -> Result<Vec<u32>> {
        let s = self.decision_scores(x)?;
        Ok(argmin_rows(s.as_ref(), &self.classes))
    }

    /// The centred responses `r_C` (`n x m`) of `class`.
    ///
    /// Errors: an unknown class, bad rows.
    pub fn responses(&self, x: MatRef<'_, f64>, class: u32) -> Result<Mat<f64>> {
        let c = self
            .classes
            .binary_search(&class)
            .map_err(|_| Error::invalid("class", format!("{class} is not a trained class")))?;
        let m = self.config.m_per_class;
        self.responses_of(x, c * m..(c + 1) * m)
    }

    /// The model as JSON.
    pub fn to_json(&self) -> Result<String> {
        serde_json::to_string(self).map_err(|e| Error::invalid("model", e.to_string()))
    }

    /// A model from [`Self::to_json`] output, checked with [`Self::check_shapes`].
    pub fn from_json(s: &str) -> Result<Self> {
        crate::model_json::checked_from_json(s, "class-wise SFA model", Self::check_shapes)
    }

    /// Checks that a model read from a file is consistent (its parameters valid, every array
    /// of the size the others imply), so that scoring it cannot index out of bounds.
    pub fn check_shapes(&self) -> Result<()> {
        self.config.validate()?;
        let dim = checked_model_shapes(&self.pca, self.config.expansion, &self.w, &self.classes)?;
        let (nc, m) = (self.classes.len(), self.config.m_per_class);
        if nc.checked_mul(m) != Some(self.w.ncols()) {
            return Err(Error::invalid(
                "model",
                format!("{} functions for {nc} classes of {m}", self.w.ncols()),
            ));
        }
        lengths("offsets", [self.offsets.len()], self.w.ncols())?;
        lengths("lambdas", [self.lambdas.len(), self.means.len()], nc)?;
        lengths("means", self.means.iter().map(Vec::len), dim)
    }
}

/// The checks shared by the two SFA classifiers: a consistent PCA, functions `w` over the
/// expansion of its outputs, class labels ascending and distinct. Returns the expanded
/// dimension.
pub(crate) fn checked_model_shapes(
    pca: &Pca,
    expansion: Option<QuadraticExpansion>,
    w: &Mat<f64>,
    classes: &[u32],
) -> Result<usize> {
    pca.check_shapes()?;
    let p = pca.components.len();
    let dim = expansion.map_or(p, |e| e.out_dim(p));
    if w.nrows() != dim {
        return Err(Error::invalid(
            "model",
            format!("the functions have {} rows, the expansion {dim}", w.nrows()),
        ));
    }
    if classes.is_empty() || classes.windows(2).any(|c| c[0] >= c[1]) {
        return Err(Error::invalid(
            "model",
            "the class labels must be non-empty, ascending and distinct",
        ));
    }
    Ok(dim)
}

/// Checks that every length of `got` equals `want` (`what` names the field in the error).
pub(crate) fn lengths(what: &str, got: impl IntoIterator<Item = usize>, want: usize) -> Result<()> {
    match got.into_iter().find(|&n| n != want) {
        Some(n) => Err(Error::invalid(
            "model",
            format!("{what}: {n} values where {want} are expected"),
        )),
        None => Ok(()),
    }
}

/// For every row the label of the smallest entry (first on ties).
pub(crate) fn argmin_rows(s: MatRef<'_, f64>, classes: &[u32]) -> Vec<u32> {
    (0..s.nrows())
        .map(|i| {
            let mut best = 0;
            for c in 1..s.ncols() {
                if s[(i, c)] < s[(i, best)] {
                    best = c;
                }
            }
            classes[best]
        })
        .collect()
}
