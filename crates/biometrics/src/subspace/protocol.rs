//! The evaluation of the paper's section 6 for one method on one train/test split: the
//! accuracy-versus-dimension curve with its maximum (Table 1's "max accuracy at l", which
//! selects `l` on the test set) and, optionally, the validated variant that selects `l` by
//! cross-validation inside the training set.

use std::time::Instant;

use faer::MatRef;
use wscg_math::{Error, Result};

use super::{accuracy_curve, best_dimension, select_dimension_cv, Method, Metric, Projector};

wscg_math::params! {
    /// Options of [`evaluate`].
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct ProtocolParams {
        /// Largest dimension of the sweep (200 for the paper's finger-vein experiment).
        pub max_dim: usize,
        /// Folds of the validated protocol (`None` skips it).
        pub cv_folds: Option<usize>,
        /// Seed of the cross-validation folds.
        pub seed: u64,
        /// Nearest-neighbour distance.
        pub metric: Metric,
    }
}

impl Default for ProtocolParams {
    fn default() -> Self {
        Self {
            max_dim: 200,
            cv_folds: Some(5),
            seed: 0,
            metric: Metric::Euclidean,
        }
    }
}

impl ProtocolParams {
    /// Errors: `max_dim == 0`, fewer than 2 cross-validation folds. Whether the training set
    /// has as many rows as folds is checked by the cross-validation itself.
    pub fn validate(&self) -> Result<()> {
        if self.max_dim == 0 {
            return Err(Error::invalid("max_dim", "must be >= 1, got 0"));
        }
        if let Some(folds) = self.cv_folds {
            if folds < 2 {
                return Err(Error::invalid(
                    "cv_folds",
                    format!("must be at least 2, got {folds}"),
                ));
            }
        }
        Ok(())
    }
}

/// The outcome for one method.
#[derive(Clone, Debug, PartialEq)]
pub struct ProtocolResult {
    /// Method name ("FDKECA", "PCA", "KPCA", "KECA").
    pub method: &'static str,
    /// `(l, test accuracy)` for `l = 1 ..= min(max_dim, components)`.
    pub curve: Vec<(usize, f64)>,
    /// Maximum of the curve and the smallest `l` reaching it (the paper's protocol).
    pub best: (usize, f64),
    /// Dimension chosen by cross-validation and the test accuracy there.
    pub validated: Option<(usize, f64)>,
    /// Seconds to fit the method on the whole training set.
    pub fit_seconds: f64,
}

/// Runs the protocol for `method` on a split.
pub fn evaluate(
    method: &Method,
    xtr: MatRef<'_, f64>,
    ytr: &[u32],
    xte: MatRef<'_, f64>,
    yte: &[u32],
    opt: &ProtocolParams,
) -> Result<ProtocolResult> {
    opt.validate()?;
    let t = Instant::now();
    let model = method.fit(xtr)?;
    let fit_seconds = t.elapsed().as_secs_f64();
    let ztr = model.transform(xtr)?;
    let zte = model.transform(xte)?;
    let lmax = opt.max_dim.min(model.n_components()).max(1);
    let dims: Vec<usize> = (1..=lmax).collect();
    let curve = accuracy_curve(ztr.as_ref(), ytr, zte.as_ref(), yte, &dims, opt.metric)?;
    let best = best_dimension(&curve).expect("the sweep is not empty");
    let validated = match opt.cv_folds {
        None => None,
        Some(folds) => {
            let fit =
                |m: MatRef<'_, f64>| -> Result<Box<dyn Projector>> { Ok(Box::new(method.fit(m)?)) };
            let (l, _) = select_dimension_cv(xtr, ytr, &dims, folds, opt.seed, &fit, opt.metric)?;
            Some((l, curve[l - 1].1))
        }
    };
    Ok(ProtocolResult {
        method: method.name(),
        curve,
        best,
        validated,
        fit_seconds,
    })
}
