//! `wscg biometrics sfa ...`: paper 05 (class-wise slow feature analysis) on the user's own
//! silhouettes, and the synthetic hand-pose generator.
//!
//! Data: a gallery folder with one sub-folder of PNG/JPEG silhouettes per class, or a `.npy`
//! stack `(n, h, w)` of masks (or an `(n, d)` matrix of feature rows for `fit`/`predict`) with
//! a `.npy` label vector. Image inputs are binarised at half their maximum and downscaled by
//! `--downscale` (3, the paper's pre-processing) before the PCA.

use std::path::{Path, PathBuf};

use clap::{Args, Subcommand, ValueEnum};
use faer::Mat;
use wscg_biometrics::data::files::{load_identity_folder, read_npy_labels};
use wscg_biometrics::sfa::handpose::protocol::{compare_masks, rows_to_mat};
use wscg_biometrics::sfa::handpose::{
    downscale, generate_with, rotation_robustness, split_masks, CompareParams, HandposeSynthParams,
    Jitter, Method, CLASS_NAMES,
};
use wscg_biometrics::sfa::{
    ClassObjective, ClassSfaParams, FittedSfa, GlobalRule, GlobalSfa, PerClassSfa,
    QuadraticExpansion, SfaModelFile,
};
use wscg_math::image::Image;
use wscg_math::progress::Progress;
use wscg_math::{npy, Error, ImageStackView, Result};

use super::DataArgs;
use crate::progress::Bars;

#[derive(Subcommand, Debug)]
pub enum SfaCommand {
    /// Write the synthetic hand-pose set (FIST, FLAT, INDEX, OPEN, GRAB): masks.npy (uint8,
    /// n x h x w), depth.npy (float32, mm), labels.npy, subjects.npy, and a few PNGs per class.
    Generate {
        /// Output folder.
        #[arg(long)]
        out: PathBuf,
        /// Frames per class.
        #[arg(long, default_value_t = 3000)]
        n_per_class: usize,
        /// Subjects (hand sizes).
        #[arg(long, default_value_t = 3)]
        subjects: usize,
        /// Seed.
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Translation jitter of the hand, px (25; the tight preset's 8 gives easily separable
        /// poses).
        #[arg(long, default_value_t = 25.0)]
        translation: f64,
        /// PNG files written per class under OUT/png/CLASS/.
        #[arg(long, default_value_t = 5)]
        png: usize,
    },
    /// Fit class-wise SFA (or full-data-set SFA with --global) and save it as JSON.
    Fit {
        #[command(flatten)]
        data: SfaData,
        #[command(flatten)]
        model: SfaArgs,
        /// Where to write the model.
        #[arg(long)]
        out: PathBuf,
    },
    /// Classify silhouettes (files or folders) or the rows of a .npy file with a fitted model.
    Predict {
        /// Model written by `fit`.
        #[arg(long)]
        model: PathBuf,
        /// Query image files or folders.
        queries: Vec<PathBuf>,
        /// Query stack (n, h, w) or rows (n, d) in a .npy file instead of images.
        #[arg(long, conflicts_with = "queries")]
        npy: Option<PathBuf>,
        /// Also write every score (n x classes, float64, smaller is better) to this .npy.
        #[arg(long)]
        scores: Option<PathBuf>,
    },
    /// The paper's protocol on labelled silhouettes: per class a random test set, rotated
    /// copies of training frames appended, class-wise SFA against KNN on physical features,
    /// PCA and Isomap and full-data-set SFA (the layout of Tables 3-6); rotated test frames.
    Evaluate {
        #[command(flatten)]
        data: SfaData,
        #[command(flatten)]
        model: SfaArgs,
        /// Depth maps (.npy, float, the shape of the masks) for the azimuth feature.
        #[arg(long)]
        depth: Option<PathBuf>,
        /// Test frames per class.
        #[arg(long, default_value_t = 300)]
        test_per_class: usize,
        /// Rotated training copies per class (0: no augmentation).
        #[arg(long, default_value_t = 1000)]
        augment_per_class: usize,
        /// KNN neighbours.
        #[arg(long, default_value_t = 5)]
        k: usize,
        /// Seed of the split and the subsets.
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Methods (default all five).
        #[arg(long, value_enum, num_args = 1.., default_values_t = [MethodArg::Sfa, MethodArg::Physical, MethodArg::Pca, MethodArg::Isomap, MethodArg::Global])]
        methods: Vec<MethodArg>,
        /// Also score the class-wise SFA on test frames rotated by +-U(10, 20) degrees.
        #[arg(long)]
        rotated: bool,
    },
}

#[derive(Args, Debug)]
pub struct SfaData {
    #[command(flatten)]
    src: DataArgs,
    /// Downscaling factor of image inputs (fit / predict; evaluate always uses the paper's 3).
    #[arg(long, default_value_t = 3)]
    downscale: usize,
}

#[derive(Args, Debug)]
pub struct SfaArgs {
    /// PCA dimensions before the expansion.
    #[arg(long, default_value_t = 35)]
    pca_dims: usize,
    /// Slow functions per class (shared functions with --global).
    #[arg(long, default_value_t = 10)]
    m: usize,
    /// 1: linear SFA, 2: quadratic expansion.
    #[arg(long, default_value_t = 2)]
    degree: usize,
    /// Weight of the out-of-class term (eq. 14); 0 keeps only within-class slowness.
    #[arg(long, default_value_t = 1.0)]
    gamma: f64,
    /// Shrinkage of the within-class scatter (for classes with few samples).
    #[arg(long, default_value_t = 1e-6)]
    shrinkage: f64,
    /// Fit SFA once on all classes (Berkes 2005) with this decision rule.
    #[arg(long, value_enum)]
    global: Option<RuleArg>,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum RuleArg {
    Variance,
    Gaussian,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum MethodArg {
    Sfa,
    Physical,
    Pca,
    Isomap,
    Global,
}

impl SfaArgs {
    fn config(&self) -> Result<ClassSfaParams> {
        let expansion = match self.degree {
            1 => None,
            2 => Some(QuadraticExpansion::default()),
            d => return Err(Error::invalid("degree", format!("must be 1 or 2, got {d}"))),
        };
        let cfg = ClassSfaParams::default()
            .pca_dims(self.pca_dims)
            .expansion(expansion)
            .m_per_class(self.m)
            .objective(if self.gamma == 0.0 {
                ClassObjective::WithinOnly
            } else {
                ClassObjective::WithinMinusOutOfClass { gamma: self.gamma }
            })
            .shrinkage(self.shrinkage);
        cfg.validate()?;
        Ok(cfg)
    }

    /// Warns when a class has fewer rows than expanded dimensions (its within-class scatter
    /// is singular and the slowest functions lie in its null space).
    fn warn_small_classes(&self, labels: &[u32], names: &[String]) {
        let p = self.pca_dims;
        let dim = if self.degree == 2 { p * (p + 3) / 2 } else { p };
        let mut counts = vec![0usize; names.len()];
        for &l in labels {
            if let Some(c) = counts.get_mut(l as usize) {
                *c += 1;
            }
        }
        if let Some((i, c)) = counts.iter().enumerate().find(|(_, &c)| c < dim) {
            eprintln!(
                "warning: class {} has {c} training samples for {dim} expanded dimensions; \
                 its slow functions will not generalise. Use more samples, fewer --pca-dims \
                 or --shrinkage 1e-3.",
                names[i]
            );
        }
    }
}

/// Image stack or rows as loaded: values, shape of one sample, labels and names.
struct Loaded {
    /// `n x (h w)` values (images) or `n x d` rows.
    values: Vec<f32>,
    n: usize,
    /// `Some((h, w))` for images.
    shape: Option<(usize, usize)>,
    labels: Vec<u32>,
    names: Vec<String>,
}

/// The rows of `x`, row-major, as `f32`.
fn row_values(x: &Mat<f64>) -> Vec<f32> {
    (0..x.nrows())
        .flat_map(|i| (0..x.ncols()).map(move |j| x[(i, j)] as f32))
        .collect()
}

fn load(data: &SfaData) -> Result<Loaded> {
    let src = &data.src;
    match (&src.gallery, &src.npy, &src.labels) {
        (Some(dir), None, _) => {
            let ds = load_identity_folder(dir, src.size)?;
            let img = &ds.images;
            Ok(Loaded {
                values: row_values(&img.x),
                n: img.x.nrows(),
                shape: Some((img.height, img.width)),
                labels: img.labels.clone(),
                names: ds.names,
            })
        }
        (None, Some(x), Some(y)) => {
            let (values, n, shape) = read_stack(x)?;
            let (labels, names) = read_npy_labels(y)?;
            if labels.len() != n {
                return Err(Error::ShapeMismatch(format!(
                    "{} labels for {n} samples of {}",
                    labels.len(),
                    x.display()
                )));
            }
            Ok(Loaded {
                values,
                n,
                shape,
                labels,
                names,
            })
        }
        _ => Err(Error::invalid(
            "data",
            "give --gallery DIR, or --npy X.npy with --labels Y.npy",
        )),
    }
}

/// Values, sample count and image shape (`None` for rows) of a `.npy` input.
type Stack = (Vec<f32>, usize, Option<(usize, usize)>);

/// A `.npy` stack `(n, h, w)` (images) or matrix `(n, d)` (rows).
fn read_stack(path: &Path) -> Result<Stack> {
    let a = npy::read::<f32>(path)?;
    match a.shape[..] {
        [n, h, w] => Ok((a.data, n, Some((h, w)))),
        [n, _] => Ok((a.data, n, None)),
        _ => Err(Error::format(
            path,
            format!(
                "expected a 3-D (n, h, w) mask stack or a 2-D (n, d) matrix, found shape {:?}",
                a.shape
            ),
        )),
    }
}

/// Binary masks (foreground above half the stack's maximum).
fn binarise(values: &[f32]) -> Result<Vec<u8>> {
    if let Some(v) = values.iter().find(|v| !v.is_finite()) {
        return Err(Error::invalid("images", format!("non-finite value {v}")));
    }
    let max = values.iter().copied().fold(0.0f32, f32::max);
    if max <= 0.0 {
        return Err(Error::invalid(
            "images",
            "no foreground: every value is <= 0",
        ));
    }
    Ok(values.iter().map(|&v| u8::from(v > 0.5 * max)).collect())
}

/// Model input rows: images binarised and downscaled, rows as they are.
fn rows(
    values: &[f32],
    n: usize,
    shape: Option<(usize, usize)>,
    factor: usize,
) -> Result<Mat<f64>> {
    match shape {
        None => {
            let d = values.len() / n.max(1);
            Ok(Mat::from_fn(n, d, |i, j| f64::from(values[i * d + j])))
        }
        Some((h, w)) => {
            let masks = binarise(values)?;
            let mut out = Vec::new();
            for mask in ImageStackView::new(n, h, w, &masks)?.iter() {
                out.extend_from_slice(downscale(mask, factor)?.data());
            }
            let d = out.len() / n.max(1);
            Ok(rows_to_mat(&out, d))
        }
    }
}

/// Runs a `wscg biometrics sfa` command.
pub fn run(cmd: SfaCommand) -> Result<()> {
    match cmd {
        SfaCommand::Generate {
            out,
            n_per_class,
            subjects,
            seed,
            translation,
            png,
        } => {
            let bars = Bars::new("generate");
            bars.begin("frames", 1);
            let data = generate_with(
                &HandposeSynthParams::default()
                    .n_per_class(n_per_class)
                    .subjects(subjects)
                    .seed(seed),
                &Jitter {
                    translation_px: translation,
                    ..Jitter::default()
                },
            )?;
            bars.finish();
            std::fs::create_dir_all(&out).map_err(|e| Error::io(&out, e))?;
            let (n, h, w) = (data.len(), data.height, data.width);
            npy::write(out.join("masks.npy"), &[n, h, w], &data.masks)?;
            npy::write(out.join("depth.npy"), &[n, h, w], &data.depth)?;
            let labels: Vec<i64> = data.labels.iter().map(|&l| i64::from(l)).collect();
            npy::write(out.join("labels.npy"), &[n], &labels)?;
            let subj: Vec<i64> = data.subjects.iter().map(|&l| i64::from(l)).collect();
            npy::write(out.join("subjects.npy"), &[n], &subj)?;
            for (c, name) in CLASS_NAMES.iter().enumerate() {
                let dir = out.join("png").join(name);
                if png > 0 {
                    std::fs::create_dir_all(&dir).map_err(|e| Error::io(&dir, e))?;
                }
                for k in 0..png.min(n_per_class) {
                    let i = c * n_per_class + k;
                    let m = data.mask(i).ok_or(Error::Empty("frame"))?;
                    let img =
                        Image::new(h, w, 1, m.data().iter().map(|&v| f32::from(v)).collect())?;
                    img.save(dir.join(format!("frame_{i:05}.png")))?;
                }
            }
            println!(
                "{n} frames of {h} x {w} ({n_per_class} per class, {subjects} subjects, seed \
                 {seed}) written to {}",
                out.display()
            );
            Ok(())
        }
        SfaCommand::Fit { data, model, out } => {
            let inputs = [&data.src.gallery, &data.src.npy, &data.src.labels];
            crate::commands::overwrite::check_file("out", &out, inputs.into_iter().flatten())?;
            let cfg = model.config()?;
            let ds = load(&data)?;
            let x = rows(&ds.values, ds.n, ds.shape, data.downscale)?;
            model.warn_small_classes(&ds.labels, &ds.names);
            let bars = Bars::new("fit");
            bars.begin(&format!("SFA on {} samples", x.nrows()), 1);
            let fitted = match model.global {
                None => FittedSfa::Class(PerClassSfa::fit(x.as_ref(), &ds.labels, &cfg)?),
                Some(r) => {
                    let rule = match r {
                        RuleArg::Variance => GlobalRule::NearestMeanVariance,
                        RuleArg::Gaussian => GlobalRule::Gaussian,
                    };
                    FittedSfa::Global(GlobalSfa::fit(x.as_ref(), &ds.labels, &cfg, rule)?)
                }
            };
            let kind = match fitted {
                FittedSfa::Class(_) => "class",
                FittedSfa::Global(_) => "global",
            };
            bars.finish();
            SfaModelFile::new(fitted, ds.names.clone(), ds.shape, data.downscale).write(&out)?;
            println!(
                "{kind} SFA fitted on {} samples of {} classes ({} values each); model written \
                 to {}",
                x.nrows(),
                ds.names.len(),
                x.ncols(),
                out.display()
            );
            Ok(())
        }
        SfaCommand::Predict {
            model,
            queries,
            npy: npy_path,
            scores: scores_out,
        } => {
            if let Some(out) = &scores_out {
                let inputs = queries.iter().chain(npy_path.as_ref()).chain([&model]);
                crate::commands::overwrite::check_file("scores", out, inputs)?;
            }
            let file = SfaModelFile::read(&model)?;
            let (values, n, shape, names) = match npy_path {
                Some(p) => {
                    let (v, n, s) = read_stack(&p)?;
                    let names: Vec<String> =
                        (0..n).map(|i| format!("{}[{i}]", p.display())).collect();
                    (v, n, s, names)
                }
                None => {
                    let files = super::expand_queries(&queries)?;
                    let (x, _) =
                        wscg_biometrics::data::files::load_images(&files, file.image_shape)?;
                    let v = row_values(&x);
                    let names = files.iter().map(|f| f.display().to_string()).collect();
                    (v, x.nrows(), file.image_shape, names)
                }
            };
            if shape.is_some() != file.image_shape.is_some() {
                return Err(Error::invalid(
                    "queries",
                    "the model was fitted on images and these are rows, or the reverse",
                ));
            }
            if let (Some(s), Some(m)) = (shape, file.image_shape) {
                if s != m {
                    return Err(Error::ShapeMismatch(format!(
                        "queries are {} x {}, the model takes {} x {}",
                        s.0, s.1, m.0, m.1
                    )));
                }
            }
            let x = rows(&values, n, shape, file.downscale)?;
            let (pred, scores) = file.model.predict_scores(x.as_ref())?;
            if let Some(p) = scores_out {
                let (r, c) = (scores.nrows(), scores.ncols());
                let v: Vec<f64> = (0..r * c).map(|t| scores[(t / c, t % c)]).collect();
                npy::write(&p, &[r, c], &v)?;
            }
            println!("query\tclass\tscore");
            for (i, (q, &p)) in names.iter().zip(&pred).enumerate() {
                let name = file.names.get(p as usize).map_or("?", String::as_str);
                let best = (0..scores.ncols())
                    .map(|j| scores[(i, j)])
                    .fold(f64::INFINITY, f64::min);
                println!("{q}\t{name}\t{best:.6e}");
            }
            Ok(())
        }
        SfaCommand::Evaluate {
            data,
            model,
            depth,
            test_per_class,
            augment_per_class,
            k,
            seed,
            methods,
            rotated,
        } => {
            let ds = load(&data)?;
            let (h, w) = ds.shape.ok_or_else(|| {
                Error::invalid(
                    "npy",
                    "evaluate needs silhouettes: an (n, h, w) stack or a gallery",
                )
            })?;
            let masks = binarise(&ds.values)?;
            let depth = match depth {
                Some(p) => {
                    let a = npy::read::<f32>(&p)?;
                    if a.data.len() != masks.len() {
                        return Err(Error::format(
                            &p,
                            format!(
                                "shape {:?} is not that of the masks ({}, {h}, {w})",
                                a.shape, ds.n
                            ),
                        ));
                    }
                    Some(a.data)
                }
                None => None,
            };
            let stack = ImageStackView::new(ds.n, h, w, &masks)?;
            let depth = depth
                .as_deref()
                .map(|d| ImageStackView::new(ds.n, h, w, d))
                .transpose()?;
            let split = split_masks(stack, &ds.labels, test_per_class, augment_per_class, seed)?;
            model.warn_small_classes(&split.train_y, &ds.names);
            let cfg = CompareParams::default()
                .sfa(model.config()?)
                .k(k)
                .seed(seed);
            let methods: Vec<Method> = methods
                .iter()
                .map(|m| match m {
                    MethodArg::Sfa => Method::ClassSfa,
                    MethodArg::Physical => Method::KnnPhysical,
                    MethodArg::Pca => Method::KnnPca,
                    MethodArg::Isomap => Method::KnnIsomap,
                    MethodArg::Global => Method::GlobalSfa,
                })
                .collect();
            println!(
                "{} classes, {} training rows ({} rotated copies), {} test rows",
                ds.names.len(),
                split.train_y.len(),
                split.train_rotation.iter().filter(|&&a| a != 0.0).count(),
                split.test_y.len()
            );
            let bars = Bars::new("evaluate");
            bars.begin("methods", methods.len() as u64);
            let res = compare_masks(stack, depth, &split, &cfg, &methods, |_| bars.advance(1))?;
            bars.finish();
            print!("{}", res.format_tables_with(&ds.names));
            if rotated {
                let rot = rotation_robustness(
                    stack,
                    &split,
                    &cfg.sfa,
                    res.class_sfa.as_ref(),
                    false,
                    seed.wrapping_add(1),
                )?;
                println!(
                    "class-wise SFA on test frames rotated by +-U(10, 20) degrees: {:.2} % \
                     (unrotated {:.2} %)",
                    rot.augmented.1, rot.augmented.0
                );
            }
            Ok(())
        }
    }
}
