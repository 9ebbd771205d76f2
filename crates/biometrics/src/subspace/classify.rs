//! Recognition with a subspace (paper 01, sections 5 and 6).
//!
//! The paper's "spectral clustering algorithm" (section 5) is supervised: project training
//! and test images with the fitted transform and give each test image the label of its
//! nearest training image. Its evaluation (section 6, Table 1, Fig. 7) sweeps the number of
//! axes `l` and reports the maximum accuracy over `l`, which selects `l` on the test set;
//! [`select_dimension_cv`] chooses `l` by cross-validation inside the training set instead.

use faer::{Mat, MatRef};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use wscg_math::{rng, Error, Result};

use super::{check_query, Projector};

/// Distance of the nearest-neighbour rule.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Metric {
    /// Euclidean distance (the default, as in the authors' earlier PCA finger-vein work).
    #[default]
    Euclidean,
    /// `1 - cos(angle)`; a zero vector has cosine 0 to everything.
    Cosine,
}

/// Errors unless there is one label per row of `x` and at least one.
pub(crate) fn check_labels(x: MatRef<'_, f64>, labels: &[u32]) -> Result<()> {
    if labels.len() != x.nrows() {
        return Err(Error::ShapeMismatch(format!(
            "{} labels for {} rows",
            labels.len(),
            x.nrows()
        )));
    }
    if labels.is_empty() {
        return Err(Error::Empty("labels"));
    }
    Ok(())
}

/// The nearest training row of one query and its distance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Neighbour {
    /// Row index in the training set (ties go to the lowest index).
    pub index: usize,
    /// Euclidean distance, or cosine distance `1 - cos`.
    pub distance: f64,
}

/// For every test row and each `l` in the sorted `dims`, the nearest training row using the
/// first `l` columns. Distances are accumulated column by column, so the whole sweep costs
/// one pass over the `max(dims)` columns.
fn nearest_prefixes(
    train: MatRef<'_, f64>,
    test: MatRef<'_, f64>,
    dims: &[usize],
    metric: Metric,
) -> Vec<Vec<Neighbour>> {
    let n = train.nrows();
    let lmax = dims.last().copied().unwrap_or(0);
    (0..test.nrows())
        .into_par_iter()
        .map(|q| {
            let mut acc = vec![0.0f64; n];
            let mut tn = vec![0.0f64; n];
            let mut qn = 0.0;
            let mut out = Vec::with_capacity(dims.len());
            let mut next = 0;
            for c in 0..lmax {
                let v = test[(q, c)];
                match metric {
                    Metric::Euclidean => {
                        for (i, a) in acc.iter_mut().enumerate() {
                            let d = train[(i, c)] - v;
                            *a += d * d;
                        }
                    }
                    Metric::Cosine => {
                        qn += v * v;
                        for i in 0..n {
                            let t = train[(i, c)];
                            acc[i] += t * v;
                            tn[i] += t * t;
                        }
                    }
                }
                while next < dims.len() && dims[next] == c + 1 {
                    let score = |i: usize| match metric {
                        Metric::Euclidean => acc[i],
                        Metric::Cosine => {
                            let den = (tn[i] * qn).sqrt();
                            if den > 0.0 {
                                1.0 - acc[i] / den
                            } else {
                                1.0
                            }
                        }
                    };
                    let best = (0..n)
                        .min_by(|&a, &b| score(a).total_cmp(&score(b)).then(a.cmp(&b)))
                        .expect("training set is not empty");
                    let distance = match metric {
                        Metric::Euclidean => score(best).sqrt(),
                        Metric::Cosine => score(best),
                    };
                    out.push(Neighbour {
                        index: best,
                        distance,
                    });
                    next += 1;
                }
            }
            out
        })
        .collect()
}

fn check_dims(dims: &[usize], available: usize) -> Result<Vec<usize>> {
    let mut d = dims.to_vec();
    d.sort_unstable();
    d.dedup();
    match (d.first(), d.last()) {
        (Some(&0), _) => Err(Error::invalid("dims", "dimensions must be >= 1")),
        (_, Some(&m)) if m > available => Err(Error::invalid(
            "dims",
            format!("{m} exceeds the {available} projected components"),
        )),
        (None, _) => Err(Error::Empty("dims")),
        _ => Ok(d),
    }
}

/// The nearest row of `train` (same width) for every row of `test`.
///
/// Errors: width mismatch, empty training set, NaN.
pub fn nearest_neighbours(
    train: MatRef<'_, f64>,
    test: MatRef<'_, f64>,
    metric: Metric,
) -> Result<Vec<Neighbour>> {
    if train.nrows() == 0 {
        return Err(Error::Empty("train"));
    }
    if train.ncols() == 0 {
        return Err(Error::invalid("train", "has no columns"));
    }
    check_query(test, train.ncols())?;
    wscg_math::dense::check_matrix("train", train)?;
    Ok(nearest_prefixes(train, test, &[train.ncols()], metric)
        .into_iter()
        .map(|v| v[0])
        .collect())
}

/// 1-NN labels of the rows of `test` against `train` (same width).
///
/// Errors: width mismatch, label count, empty training set, NaN.
pub fn nn_classify(
    train: MatRef<'_, f64>,
    labels: &[u32],
    test: MatRef<'_, f64>,
    metric: Metric,
) -> Result<Vec<u32>> {
    check_labels(train, labels)?;
    Ok(nearest_neighbours(train, test, metric)?
        .into_iter()
        .map(|nb| labels[nb.index])
        .collect())
}

/// Fraction of `pred` equal to `truth`.
pub fn accuracy(pred: &[u32], truth: &[u32]) -> Result<f64> {
    if pred.len() != truth.len() || pred.is_empty() {
        return Err(Error::ShapeMismatch(format!(
            "{} predictions for {} labels",
            pred.len(),
            truth.len()
        )));
    }
    Ok(pred.iter().zip(truth).filter(|(a, b)| a == b).count() as f64 / pred.len() as f64)
}

/// The paper's protocol on projected data: 1-NN accuracy using the first `l` components,
/// for every `l` in `dims`. Returns `(l, accuracy)` sorted by `l`.
pub fn accuracy_curve(
    ztrain: MatRef<'_, f64>,
    ytrain: &[u32],
    ztest: MatRef<'_, f64>,
    ytest: &[u32],
    dims: &[usize],
    metric: Metric,
) -> Result<Vec<(usize, f64)>> {
    check_labels(ztrain, ytrain)?;
    check_labels(ztest, ytest)?;
    check_query(ztest, ztrain.ncols())?;
    let dims = check_dims(dims, ztrain.ncols())?;
    let nearest = nearest_prefixes(ztrain, ztest, &dims, metric);
    Ok(dims
        .iter()
        .enumerate()
        .map(|(k, &l)| {
            let correct = nearest
                .iter()
                .zip(ytest)
                .filter(|(p, &y)| ytrain[p[k].index] == y)
                .count();
            (l, correct as f64 / ytest.len() as f64)
        })
        .collect())
}

/// The maximum accuracy of a curve and the smallest `l` reaching it (Table 1's columns).
pub fn best_dimension(curve: &[(usize, f64)]) -> Option<(usize, f64)> {
    curve
        .iter()
        .copied()
        .fold(None, |best: Option<(usize, f64)>, (l, a)| match best {
            Some((_, b)) if b >= a => best,
            _ => Some((l, a)),
        })
}

/// Fits a projector on a matrix (for cross-validation).
pub type FitFn<'a> = dyn Fn(MatRef<'_, f64>) -> Result<Box<dyn Projector>> + Sync + 'a;

/// Chooses `l` by `folds`-fold cross-validation on the training set only: for each fold the
/// projector is refitted on the other folds, the validation fold is classified for every
/// `l` in `dims`, and the `l` with the best mean accuracy is returned with the mean curve.
pub fn select_dimension_cv(
    x: MatRef<'_, f64>,
    y: &[u32],
    dims: &[usize],
    folds: usize,
    seed: u64,
    fit: &FitFn<'_>,
    metric: Metric,
) -> Result<(usize, Vec<(usize, f64)>)> {
    check_labels(x, y)?;
    if folds < 2 || folds > x.nrows() {
        return Err(Error::invalid(
            "folds",
            format!(
                "must be between 2 and the number of rows {}, got {folds}",
                x.nrows()
            ),
        ));
    }
    let perm = rng::permutation(seed, x.nrows())?;
    let mut fold_of = vec![0usize; x.nrows()];
    for (k, &i) in perm.iter().enumerate() {
        fold_of[i] = k % folds;
    }
    let mut sum: Option<Vec<(usize, f64)>> = None;
    for f in 0..folds {
        let (tr, va): (Vec<usize>, Vec<usize>) = (0..x.nrows()).partition(|&i| fold_of[i] != f);
        let (xtr, xva) = (super::select_rows(x, &tr), super::select_rows(x, &va));
        let ytr: Vec<u32> = tr.iter().map(|&i| y[i]).collect();
        let yva: Vec<u32> = va.iter().map(|&i| y[i]).collect();
        let model = fit(xtr.as_ref())?;
        let ztr = model.transform(xtr.as_ref())?;
        let zva = model.transform(xva.as_ref())?;
        let usable: Vec<usize> = dims.iter().copied().filter(|&l| l <= ztr.ncols()).collect();
        let curve = accuracy_curve(ztr.as_ref(), &ytr, zva.as_ref(), &yva, &usable, metric)?;
        sum = Some(match sum {
            None => curve,
            Some(s) => s
                .into_iter()
                .filter_map(|(l, a)| curve.iter().find(|c| c.0 == l).map(|c| (l, a + c.1)))
                .collect(),
        });
    }
    let mean: Vec<(usize, f64)> = sum
        .unwrap_or_default()
        .into_iter()
        .map(|(l, a)| (l, a / folds as f64))
        .collect();
    let (l, _) = best_dimension(&mean).ok_or(Error::Empty("dims"))?;
    Ok((l, mean))
}

/// The section 5 pipeline: a fitted projection plus the projected, labelled training set.
/// Serialisable (with serde) when the projection is.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SubspaceClassifier<P: Projector> {
    /// The projection.
    pub projector: P,
    /// Projected training rows (`N x l`).
    #[serde(with = "super::serde_mat")]
    pub train: Mat<f64>,
    /// Their labels.
    pub labels: Vec<u32>,
    /// Nearest-neighbour distance.
    pub metric: Metric,
}

impl<P: Projector> SubspaceClassifier<P> {
    /// Projects the labelled training rows `x` with `projector`.
    pub fn new(projector: P, x: MatRef<'_, f64>, labels: &[u32], metric: Metric) -> Result<Self> {
        check_labels(x, labels)?;
        let train = projector.transform(x)?;
        Ok(Self {
            projector,
            train,
            labels: labels.to_vec(),
            metric,
        })
    }

    /// The nearest projected training row of every row of `x`.
    pub fn nearest(&self, x: MatRef<'_, f64>) -> Result<Vec<Neighbour>> {
        let z = self.projector.transform(x)?;
        nearest_neighbours(self.train.as_ref(), z.as_ref(), self.metric)
    }

    /// Labels of new rows (1-NN in the subspace).
    pub fn predict(&self, x: MatRef<'_, f64>) -> Result<Vec<u32>> {
        Ok(self
            .nearest(x)?
            .into_iter()
            .map(|nb| self.labels[nb.index])
            .collect())
    }
}
