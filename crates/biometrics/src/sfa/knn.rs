//! The k-nearest-neighbour classifier of paper 05's baselines (Tables 4-6): Euclidean
//! distance, majority vote, and the confusion matrix in the layout of the paper's tables.

use faer::{Mat, MatRef};
use serde::{Deserialize, Serialize};
use wscg_math::{Error, Result};

use super::neighbours::k_nearest;
use crate::subspace::classify::check_labels;
use crate::subspace::{check_data, check_query};

/// How a tied vote is decided.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum KnnTie {
    /// The tied class with the nearest member (the default; the paper does not say how ties
    /// are broken).
    #[default]
    Nearest,
    /// The smallest tied label (scikit-learn's `KNeighborsClassifier`).
    SmallestLabel,
}

/// A fitted k-NN classifier (stores the training rows).
#[derive(Clone, Debug)]
pub struct Knn {
    k: usize,
    tie: KnnTie,
    train: Mat<f64>,
    labels: Vec<u32>,
}

impl Knn {
    /// Stores the training set. Errors: `k == 0` or above the row count, label count,
    /// empty or non-finite rows.
    pub fn fit(x: MatRef<'_, f64>, y: &[u32], k: usize, tie: KnnTie) -> Result<Self> {
        check_data("x", x, 1)?;
        check_labels(x, y)?;
        if k == 0 || k > x.nrows() {
            return Err(Error::invalid(
                "k",
                format!("must be in 1..={}, got {k}", x.nrows()),
            ));
        }
        Ok(Self {
            k,
            tie,
            train: x.to_owned(),
            labels: y.to_vec(),
        })
    }

    /// The labels of the rows of `x`: the majority among the `k` nearest training rows
    /// (distance ties by training index).
    pub fn predict(&self, x: MatRef<'_, f64>) -> Result<Vec<u32>> {
        check_query(x, self.train.ncols())?;
        let nb = k_nearest(x, self.train.as_ref(), self.k, false);
        Ok(nb.idx.chunks(self.k).map(|near| self.vote(near)).collect())
    }

    /// The vote of the training rows `near`, nearest first.
    fn vote(&self, near: &[usize]) -> u32 {
        let mut counts: Vec<(u32, usize, usize)> = Vec::new(); // (label, votes, first rank)
        for (rank, &i) in near.iter().enumerate() {
            let l = self.labels[i];
            match counts.iter_mut().find(|c| c.0 == l) {
                Some(c) => c.1 += 1,
                None => counts.push((l, 1, rank)),
            }
        }
        let top = counts.iter().map(|c| c.1).max().unwrap_or(0);
        let tied = counts.iter().filter(|c| c.1 == top);
        match self.tie {
            KnnTie::Nearest => tied.min_by_key(|c| c.2).map_or(0, |c| c.0),
            KnnTie::SmallestLabel => tied.map(|c| c.0).min().unwrap_or(0),
        }
    }
}

/// Row-normalised confusion matrix in percent: row = true class, column = predicted, in the
/// order of `classes` (the layout of the paper's Tables 3-6).
///
/// Errors: length mismatch, a label not in `classes`.
pub fn confusion_matrix(y_true: &[u32], y_pred: &[u32], classes: &[u32]) -> Result<Mat<f64>> {
    if y_true.len() != y_pred.len() {
        return Err(Error::ShapeMismatch(format!(
            "{} true labels, {} predictions",
            y_true.len(),
            y_pred.len()
        )));
    }
    let pos = |l: u32| {
        classes
            .iter()
            .position(|&c| c == l)
            .ok_or_else(|| Error::invalid("labels", format!("{l} is not among the classes")))
    };
    let c = classes.len();
    let mut m = Mat::<f64>::zeros(c, c);
    for (&t, &p) in y_true.iter().zip(y_pred) {
        m[(pos(t)?, pos(p)?)] += 1.0;
    }
    for i in 0..c {
        let row: f64 = (0..c).map(|j| m[(i, j)]).sum();
        if row > 0.0 {
            for j in 0..c {
                m[(i, j)] *= 100.0 / row;
            }
        }
    }
    Ok(m)
}
