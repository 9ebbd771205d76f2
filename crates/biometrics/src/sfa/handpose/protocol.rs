//! The paper's hand-pose comparison (§3.2 and §4, Tables 3-6) on a [`SynthData`] set split by
//! [`split_protocol`]: the class-wise SFA and its four baselines trained on the same frames and
//! scored on the same test frames, each as a confusion matrix in the tables' layout.
//!
//! | method | table | input | classifier |
//! |---|---|---|---|
//! | [`Method::ClassSfa`] | 3 | downscaled masks (2200 values) | [`PerClassSfa`] (PCA-35, quadratic, m = 10, gamma = 1) |
//! | [`Method::KnnPhysical`] | 4 | 9 physical features of the full-size mask and depth | KNN, k = 5, z-scored features |
//! | [`Method::KnnPca`] | 5 | the same downscaled masks, PCA-35 | KNN, k = 5 |
//! | [`Method::KnnIsomap`] | 6 | the same downscaled masks, 9-D Isomap | KNN, k = 5 |
//! | [`Method::GlobalSfa`] | 1, row 2 | as class SFA | [`GlobalSfa`], 10 shared functions, variance rule |
//!
//! Choices where the paper is silent:
//! - **Physical features** are computed on the original (unrotated) training frames, of which
//!   `physical_per_class` per class (1500, the paper's "1500 samples from each class") are
//!   drawn at random; each feature is z-scored with the training mean and standard deviation
//!   (pixel coordinates, ratios and angles mix scales). Test frames are the split's.
//! - **PCA-35 for KNN** is the PCA of the class-wise SFA's training rows, the same 35 axes.
//! - **Isomap** (n_neighbors 8, 9 components) is fitted to `isomap_per_class` training rows per
//!   class drawn at random (all of them when `None`), exact up to [`MAX_EXACT_POINTS`] points
//!   and Landmark Isomap with `isomap_landmarks` landmarks above; the test rows are placed by
//!   [`Isomap::transform`], and the KNN is trained on the embedded training rows.
//! - The KNN votes break ties by the nearest neighbour ([`KnnTie::Nearest`]).
//!
//! [`MAX_EXACT_POINTS`]: crate::sfa::isomap::MAX_EXACT_POINTS

use std::time::Instant;

use faer::{Mat, MatRef};
use rayon::prelude::*;
use wscg_math::rng;
use wscg_math::{Error, ImageStackView, Result};

use super::features::physical_features;
use super::generate::{rotated_rows, Split, SynthData, CLASS_NAMES, DOWNSCALE};
use crate::sfa::isomap::{Isomap, IsomapParams, MAX_EXACT_POINTS};
use crate::sfa::scatter::group_labels;
use crate::sfa::{
    confusion_matrix, ClassSfaParams, GlobalRule, GlobalSfa, Knn, KnnTie, PerClassSfa,
};
use crate::subspace::classify::accuracy;
use crate::subspace::{column_means, select_rows, Pca, Projector};

/// One of the compared classifiers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Method {
    /// The paper's class-wise SFA (Table 3).
    ClassSfa,
    /// KNN on the physical features (Table 4).
    KnnPhysical,
    /// KNN on PCA-35 (Table 5).
    KnnPca,
    /// KNN on 9-D Isomap (Table 6).
    KnnIsomap,
    /// SFA fitted once on all classes (Berkes 2005; Table 1, row 2).
    GlobalSfa,
}

impl Method {
    /// All five, in the order of the paper's tables.
    pub const ALL: [Method; 5] = [
        Method::ClassSfa,
        Method::KnnPhysical,
        Method::KnnPca,
        Method::KnnIsomap,
        Method::GlobalSfa,
    ];

    /// Title as printed above its table.
    pub fn title(self) -> &'static str {
        match self {
            Method::ClassSfa => "Table 3: class-wise SFA",
            Method::KnnPhysical => "Table 4: KNN on physical features",
            Method::KnnPca => "Table 5: KNN on PCA-35",
            Method::KnnIsomap => "Table 6: KNN on 9-D Isomap",
            Method::GlobalSfa => "Full-dataset SFA (Berkes 2005)",
        }
    }

    /// Short name (command line, Python): `sfa`, `physical`, `pca`, `isomap`, `global`.
    pub fn name(self) -> &'static str {
        match self {
            Method::ClassSfa => "sfa",
            Method::KnnPhysical => "physical",
            Method::KnnPca => "pca",
            Method::KnnIsomap => "isomap",
            Method::GlobalSfa => "global",
        }
    }

    /// The method called `name` (see [`Method::name`]).
    pub fn parse(name: &str) -> Result<Self> {
        Self::ALL
            .into_iter()
            .find(|m| m.name() == name)
            .ok_or_else(|| {
                Error::invalid(
                    "method",
                    format!("unknown {name:?}; expected sfa, physical, pca, isomap or global"),
                )
            })
    }
}

wscg_math::params! {
    /// Parameters of [`compare`]; the defaults are the paper's (§3.2.2, §4) with our choices
    /// where it is silent (see the module docs).
    #[derive(Clone, Debug, PartialEq)]
    pub struct CompareParams {
        /// The class-wise and full-data-set SFA (PCA-35, quadratic, 10 functions, gamma = 1).
        pub sfa: ClassSfaParams,
        /// Neighbours of every KNN (5).
        pub k: usize,
        /// Training frames per class for the physical-feature KNN (1500).
        pub physical_per_class: usize,
        /// Isomap parameters (8 neighbours, 9 components; `n_landmarks` is set by
        /// `isomap_landmarks` when the training set exceeds the exact limit).
        pub isomap: IsomapParams,
        /// Training rows per class for Isomap (`None`: all).
        pub isomap_per_class: Option<usize>,
        /// Landmarks of Landmark Isomap above the exact limit (2000).
        pub isomap_landmarks: usize,
        /// Decision rule of the full-data-set SFA (the paper-style variance rule).
        pub global_rule: GlobalRule,
        /// Seed of the random subsets (physical features, Isomap).
        pub seed: u64,
    }
}

impl Default for CompareParams {
    fn default() -> Self {
        Self {
            sfa: ClassSfaParams::default(),
            k: 5,
            physical_per_class: 1500,
            isomap: IsomapParams::default(),
            isomap_per_class: None,
            isomap_landmarks: 2000,
            global_rule: GlobalRule::NearestMeanVariance,
            seed: 0,
        }
    }
}

impl CompareParams {
    /// Errors: invalid SFA or Isomap parameters (the error names the field), `k`,
    /// `physical_per_class` or `isomap_per_class` zero, fewer than 2 `isomap_landmarks`.
    pub fn validate(&self) -> Result<()> {
        self.sfa.validate()?;
        if self.k == 0 {
            return Err(Error::invalid("k", "must be at least 1"));
        }
        if self.physical_per_class == 0 {
            return Err(Error::invalid("physical_per_class", "must be at least 1"));
        }
        self.isomap.validate()?;
        if self.isomap_per_class == Some(0) {
            return Err(Error::invalid("isomap_per_class", "must be at least 1"));
        }
        if self.isomap_landmarks < 2 {
            return Err(Error::invalid(
                "isomap_landmarks",
                format!(
                    "Landmark Isomap needs at least 2 landmarks, got {}",
                    self.isomap_landmarks
                ),
            ));
        }
        Ok(())
    }
}

/// The result of one method.
#[derive(Clone, Debug)]
pub struct MethodResult {
    /// Which method.
    pub method: Method,
    /// Confusion matrix in percent (row = true class, column = predicted), classes ascending.
    pub confusion: Mat<f64>,
    /// Predicted label of every test row.
    pub predictions: Vec<u32>,
    /// Seconds spent fitting (features and embedding included).
    pub fit_seconds: f64,
    /// Seconds spent predicting the test rows (features and embedding included).
    pub predict_seconds: f64,
}

impl MethodResult {
    /// Per-class accuracy in percent (the diagonal).
    pub fn per_class(&self) -> Vec<f64> {
        (0..self.confusion.nrows())
            .map(|i| self.confusion[(i, i)])
            .collect()
    }

    /// Mean of the per-class accuracies, percent (the paper's "diagonal mean").
    pub fn mean(&self) -> f64 {
        let d = self.per_class();
        d.iter().sum::<f64>() / d.len().max(1) as f64
    }
}

/// All results of [`compare`].
#[derive(Clone, Debug)]
pub struct Comparison {
    /// Class labels, ascending (row / column order of every matrix).
    pub classes: Vec<u32>,
    /// Training rows (original + rotated).
    pub n_train: usize,
    /// Test rows.
    pub n_test: usize,
    /// One entry per method asked for, in the order asked.
    pub results: Vec<MethodResult>,
    /// The fitted class-wise SFA, when [`Method::ClassSfa`] was run.
    pub class_sfa: Option<PerClassSfa>,
}

impl Comparison {
    /// The result of `method`, when it was run.
    pub fn get(&self, method: Method) -> Option<&MethodResult> {
        self.results.iter().find(|r| r.method == method)
    }

    /// Every matrix in the layout of the paper's Tables 3-6 (row = true class, % per
    /// predicted class, then the diagonal mean), class names from [`CLASS_NAMES`] where the
    /// labels are `0..5`.
    pub fn format_tables(&self) -> String {
        let names: Vec<String> = self
            .classes
            .iter()
            .map(|&c| {
                CLASS_NAMES
                    .get(c as usize)
                    .map_or_else(|| c.to_string(), |s| (*s).to_string())
            })
            .collect();
        self.format_tables_with(&names)
    }

    /// [`Comparison::format_tables`] with the given class names (one per class, in the order
    /// of [`Comparison::classes`]; missing names print as the label).
    pub fn format_tables_with(&self, names: &[String]) -> String {
        use std::fmt::Write;
        let names: Vec<String> = (0..self.classes.len())
            .map(|i| {
                names
                    .get(i)
                    .cloned()
                    .unwrap_or_else(|| self.classes[i].to_string())
            })
            .collect();
        let width = names.iter().map(String::len).max().unwrap_or(0).max(7) + 1;
        let mut s = String::new();
        for r in &self.results {
            let _ = writeln!(s, "{}", r.method.title());
            let _ = write!(s, "{:>width$}", "");
            for n in &names {
                let _ = write!(s, "{n:>width$}");
            }
            s.push('\n');
            for (i, n) in names.iter().enumerate() {
                let _ = write!(s, "{n:>width$}");
                for j in 0..names.len() {
                    let _ = write!(s, "{:>width$.1}", r.confusion[(i, j)]);
                }
                s.push('\n');
            }
            let _ = writeln!(
                s,
                "  diagonal mean {:.2} %  (fit {:.2} s, predict {:.3} s)\n",
                r.mean(),
                r.fit_seconds,
                r.predict_seconds
            );
        }
        s
    }
}

/// `n` row-major rows of `dim` values (e.g. [`Split::train_x`]) as an `n x dim` matrix.
pub fn rows_to_mat(v: &[f64], dim: usize) -> Mat<f64> {
    let n = v.len() / dim.max(1);
    wscg_math::dense::from_row_major(&v[..n * dim], n, dim)
}

/// At most `per_class` row indices of each class of `y` (all when `None`), drawn at random
/// without replacement and returned in increasing order.
fn subset_per_class(y: &[u32], per_class: Option<usize>, seed: u64) -> Vec<usize> {
    let (_, groups) = group_labels(y);
    let mut r = rng::seeded(seed);
    let mut out = Vec::new();
    for mut g in groups {
        if let Some(k) = per_class.filter(|&k| k < g.len()) {
            rng::shuffle(&mut g, &mut r);
            g.truncate(k);
        }
        out.extend(g);
    }
    out.sort_unstable();
    out
}

/// Physical features of the given frames of a mask stack (with depth maps when given),
/// `frames.len() x 9` (8 without depth).
fn frame_features(
    masks: ImageStackView<'_, u8>,
    depth: Option<ImageStackView<'_, f32>>,
    frames: &[usize],
) -> Result<Mat<f64>> {
    let rows: Vec<Vec<f64>> = frames
        .par_iter()
        .map(|&f| {
            let m = masks.frame(f).ok_or(Error::Empty("frame"))?;
            let d = depth.and_then(|d| d.frame(f));
            physical_features(m, d)
        })
        .collect::<Result<_>>()?;
    let d = rows.first().map_or(0, Vec::len);
    Ok(Mat::from_fn(rows.len(), d, |i, j| rows[i][j]))
}

/// Column means and standard deviations (1 where a column is constant).
fn zscore_params(x: MatRef<'_, f64>) -> (Vec<f64>, Vec<f64>) {
    let n = x.nrows() as f64;
    let mean = column_means(x);
    let sd = mean
        .iter()
        .enumerate()
        .map(|(j, m)| {
            let var = x.col(j).iter().map(|v| (v - m).powi(2)).sum::<f64>() / n;
            if var > 0.0 {
                var.sqrt()
            } else {
                1.0
            }
        })
        .collect();
    (mean, sd)
}

fn zscore(x: MatRef<'_, f64>, p: &(Vec<f64>, Vec<f64>)) -> Mat<f64> {
    Mat::from_fn(x.nrows(), x.ncols(), |i, j| (x[(i, j)] - p.0[j]) / p.1[j])
}

/// Runs `f`, returning its value and the seconds it took.
fn timed<T>(f: impl FnOnce() -> Result<T>) -> Result<(T, f64)> {
    let t = Instant::now();
    let v = f()?;
    Ok((v, t.elapsed().as_secs_f64()))
}

/// Physical features for the Table 4 baseline, computed outside [`compare_rows`] (they need
/// the full-size masks, not the downscaled rows).
#[derive(Clone, Debug)]
pub struct FeatureSets {
    /// Training features (`n_train x f`).
    pub train: Mat<f64>,
    /// Labels of the training features.
    pub train_y: Vec<u32>,
    /// Features of the test rows, in test-row order (`n_test x f`).
    pub test: Mat<f64>,
    /// Seconds spent extracting the training features (added to the fit time).
    pub train_seconds: f64,
    /// Seconds spent extracting the test features (added to the predict time).
    pub test_seconds: f64,
}

/// Trains every method of `methods` on the training rows of `split` and scores it on the test
/// rows (see the module docs). `data` must be the set `split` was made from (the physical
/// features need the full-size masks and depth maps).
///
/// `progress` is called with each method before it runs.
///
/// Errors: an empty `methods`, `k == 0`, a `split` that does not belong to `data`, and the
/// errors of the classifiers (e.g. too few training rows for the PCA or Isomap).
pub fn compare(
    data: &SynthData,
    split: &Split,
    cfg: &CompareParams,
    methods: &[Method],
    progress: impl FnMut(Method),
) -> Result<Comparison> {
    compare_masks(
        data.mask_stack()?,
        Some(data.depth_stack()?),
        split,
        cfg,
        methods,
        progress,
    )
}

/// [`compare`] on any mask stack (non-zero = foreground; depth maps optional: without them
/// the physical features have 8 values) that `split` was made from by
/// [`super::split_masks`].
///
/// Errors: as [`compare`]; `depth` not the shape of `masks`.
pub fn compare_masks(
    masks: ImageStackView<'_, u8>,
    depth: Option<ImageStackView<'_, f32>>,
    split: &Split,
    cfg: &CompareParams,
    methods: &[Method],
    progress: impl FnMut(Method),
) -> Result<Comparison> {
    cfg.validate()?;
    let (n, h, w) = (masks.frames(), masks.height(), masks.width());
    if split.shape != (h.div_ceil(DOWNSCALE), w.div_ceil(DOWNSCALE))
        || split
            .train_index
            .iter()
            .chain(&split.test_index)
            .any(|&f| f >= n)
    {
        return Err(Error::ShapeMismatch(
            "the split was not made from these frames".into(),
        ));
    }
    if let Some(d) = depth {
        masks.ensure_same_shape(&d, "depth")?;
    }
    let physical = if methods.contains(&Method::KnnPhysical) {
        let ytr = &split.train_y;
        let originals: Vec<usize> = (0..ytr.len())
            .filter(|&i| split.train_rotation[i] == 0.0)
            .collect();
        let y_orig: Vec<u32> = originals.iter().map(|&i| ytr[i]).collect();
        let chosen: Vec<usize> = subset_per_class(&y_orig, Some(cfg.physical_per_class), cfg.seed)
            .into_iter()
            .map(|i| originals[i])
            .collect();
        let frames: Vec<usize> = chosen.iter().map(|&i| split.train_index[i]).collect();
        let (train, train_seconds) = timed(|| frame_features(masks, depth, &frames))?;
        let (test, test_seconds) = timed(|| frame_features(masks, depth, &split.test_index))?;
        Some(FeatureSets {
            train,
            train_y: chosen.iter().map(|&i| ytr[i]).collect(),
            test,
            train_seconds,
            test_seconds,
        })
    } else {
        None
    };
    compare_rows(
        rows_to_mat(&split.train_x, split.dim).as_ref(),
        &split.train_y,
        rows_to_mat(&split.test_x, split.dim).as_ref(),
        &split.test_y,
        cfg,
        methods,
        physical.as_ref(),
        progress,
    )
}

/// [`compare`] on any training and test rows (e.g. the user's own flattened silhouettes):
/// `physical` supplies the features of [`Method::KnnPhysical`], which is refused without them.
///
/// Errors: an empty `methods`, `k == 0`, label counts, [`Method::KnnPhysical`] without
/// `physical` (or with features whose rows do not match the labels), and the errors of the
/// classifiers.
#[allow(clippy::too_many_arguments)]
pub fn compare_rows(
    xtr: MatRef<'_, f64>,
    ytr: &[u32],
    xte: MatRef<'_, f64>,
    yte: &[u32],
    cfg: &CompareParams,
    methods: &[Method],
    physical: Option<&FeatureSets>,
    mut progress: impl FnMut(Method),
) -> Result<Comparison> {
    cfg.validate()?;
    if methods.is_empty() {
        return Err(Error::Empty("methods"));
    }
    if yte.len() != xte.nrows() {
        return Err(Error::ShapeMismatch(format!(
            "{} test labels for {} test rows",
            yte.len(),
            xte.nrows()
        )));
    }
    let (classes, _) = group_labels(ytr);
    let mut results = Vec::new();
    // The class-wise SFA's PCA is reused by the PCA-KNN.
    let mut sfa_model: Option<PerClassSfa> = None;
    for &method in methods {
        progress(method);
        let (pred, fit_seconds, predict_seconds) = match method {
            Method::ClassSfa => {
                let (model, tf) = timed(|| PerClassSfa::fit(xtr, ytr, &cfg.sfa))?;
                let (p, tp) = timed(|| model.predict(xte))?;
                sfa_model = Some(model);
                (p, tf, tp)
            }
            Method::GlobalSfa => {
                let (model, tf) = timed(|| GlobalSfa::fit(xtr, ytr, &cfg.sfa, cfg.global_rule))?;
                let (p, tp) = timed(|| model.predict(xte))?;
                (p, tf, tp)
            }
            Method::KnnPca => {
                let ((pca, knn), tf) = timed(|| {
                    let pca = match &sfa_model {
                        Some(m) => m.pca.clone(),
                        None => Pca::fit(xtr, Some(cfg.sfa.pca_dims), false)?,
                    };
                    let knn = Knn::fit(pca.transform(xtr)?.as_ref(), ytr, cfg.k, KnnTie::Nearest)?;
                    Ok((pca, knn))
                })?;
                let (p, tp) = timed(|| knn.predict(pca.transform(xte)?.as_ref()))?;
                (p, tf, tp)
            }
            Method::KnnPhysical => {
                let f = physical.ok_or_else(|| {
                    Error::invalid(
                        "methods",
                        "the physical-feature KNN needs the masks (features not given)",
                    )
                })?;
                if f.test.nrows() != yte.len() {
                    return Err(Error::ShapeMismatch(format!(
                        "{} test feature rows for {} test labels",
                        f.test.nrows(),
                        yte.len()
                    )));
                }
                let ((zp, knn), tf) = timed(|| {
                    let zp = zscore_params(f.train.as_ref());
                    let z = zscore(f.train.as_ref(), &zp);
                    let knn = Knn::fit(z.as_ref(), &f.train_y, cfg.k, KnnTie::Nearest)?;
                    Ok((zp, knn))
                })?;
                let (p, tp) = timed(|| knn.predict(zscore(f.test.as_ref(), &zp).as_ref()))?;
                (p, tf + f.train_seconds, tp + f.test_seconds)
            }
            Method::KnnIsomap => {
                let chosen = subset_per_class(ytr, cfg.isomap_per_class, cfg.seed.wrapping_add(1));
                let ((iso, knn), tf) = timed(|| {
                    let x = select_rows(xtr, &chosen);
                    let mut params = cfg.isomap.clone();
                    if x.nrows() > MAX_EXACT_POINTS && params.n_landmarks.is_none() {
                        params.n_landmarks = Some(cfg.isomap_landmarks);
                    }
                    let iso = Isomap::fit(x.as_ref(), &params)?;
                    let y: Vec<u32> = chosen.iter().map(|&i| ytr[i]).collect();
                    let knn = Knn::fit(iso.embedding(), &y, cfg.k, KnnTie::Nearest)?;
                    Ok((iso, knn))
                })?;
                let (p, tp) = timed(|| knn.predict(iso.transform(xte)?.as_ref()))?;
                (p, tf, tp)
            }
        };
        results.push(MethodResult {
            method,
            confusion: confusion_matrix(yte, &pred, &classes)?,
            predictions: pred,
            fit_seconds,
            predict_seconds,
        });
    }
    Ok(Comparison {
        classes,
        n_train: ytr.len(),
        n_test: yte.len(),
        results,
        class_sfa: sfa_model,
    })
}

/// Accuracies (%) of the rotation-robustness check: class-wise SFA on the unrotated test rows
/// and on the same test frames rotated by `+-U(10, 20)` degrees ([`rotated_rows`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RotationCheck {
    /// `(unrotated, rotated)` for the model trained with the rotated copies.
    pub augmented: (f64, f64),
    /// `(unrotated, rotated)` for the model trained on the original frames only, when asked.
    pub unaugmented: Option<(f64, f64)>,
}

impl RotationCheck {
    /// Accuracy lost on rotated frames by the augmented model, percentage points.
    pub fn augmented_drop(&self) -> f64 {
        self.augmented.0 - self.augmented.1
    }

    /// The same for the unaugmented model.
    pub fn unaugmented_drop(&self) -> Option<f64> {
        self.unaugmented.map(|(a, b)| a - b)
    }
}

/// The test of the paper's invariance claim (§3.2.1: the rotated copies "train the SFA for
/// rotational invariances"): the class-wise SFA trained on `split` (pass the model [`compare`]
/// fitted, [`Comparison::class_sfa`], to skip refitting it) scored on the test frames of the
/// mask stack `masks` rotated by `+-U(10, 20)` degrees; with `unaugmented`, also a model
/// trained without the rotated copies.
///
/// Errors: as [`rotated_rows`] and [`PerClassSfa::fit`].
pub fn rotation_robustness(
    masks: ImageStackView<'_, u8>,
    split: &Split,
    sfa: &ClassSfaParams,
    fitted: Option<&PerClassSfa>,
    unaugmented: bool,
    seed: u64,
) -> Result<RotationCheck> {
    let rotated = rows_to_mat(
        &rotated_rows(masks, &split.test_index, 10.0, 20.0, seed)?,
        split.dim,
    );
    let plain = rows_to_mat(&split.test_x, split.dim);
    let score = |m: &PerClassSfa| -> Result<(f64, f64)> {
        Ok((
            100.0 * accuracy(&m.predict(plain.as_ref())?, &split.test_y)?,
            100.0 * accuracy(&m.predict(rotated.as_ref())?, &split.test_y)?,
        ))
    };
    let augmented = match fitted {
        Some(m) => score(m)?,
        None => score(&PerClassSfa::fit(
            rows_to_mat(&split.train_x, split.dim).as_ref(),
            &split.train_y,
            sfa,
        )?)?,
    };
    let unaugmented = if unaugmented {
        let keep: Vec<usize> = (0..split.train_y.len())
            .filter(|&i| split.train_rotation[i] == 0.0)
            .collect();
        let all = MatRef::from_row_major_slice(&split.train_x, split.train_y.len(), split.dim);
        let x = select_rows(all, &keep);
        let y: Vec<u32> = keep.iter().map(|&i| split.train_y[i]).collect();
        Some(score(&PerClassSfa::fit(x.as_ref(), &y, sfa)?)?)
    } else {
        None
    };
    Ok(RotationCheck {
        augmented,
        unaugmented,
    })
}
