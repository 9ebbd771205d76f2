//! `wscg biometrics fdkeca ...`: paper 01 on the user's own data.
//!
//! Data: a gallery folder with one sub-folder of PNG/JPEG images per identity, or a `.npy`
//! matrix (`(n, d)` or an `(n, h, w)` image stack) with a `.npy` label vector.

mod ear;
mod gait;
mod sfa;

use std::path::PathBuf;

use clap::{Args, Subcommand, ValueEnum};
use faer::Mat;
use wscg_biometrics::data::files::{
    image_files, load_identity_folder, load_images, read_npy_dataset, read_npy_matrix,
};
use wscg_biometrics::data::{split_per_subject, IdentityImages};
use wscg_biometrics::subspace::{
    evaluate, select_rows, FdkecaParams, Gamma, Kernel, Method, Metric as NnMetric, Model,
    Ordering, ProtocolParams, Recognizer, Sigma,
};
use wscg_math::progress::Progress;
use wscg_math::{Error, Result};

use crate::progress::Bars;

#[derive(Subcommand, Debug)]
pub enum BiometricsCommand {
    /// Paper 01: FDKECA and its baselines (PCA, KPCA, KECA) with 1-NN recognition.
    #[command(subcommand)]
    Fdkeca(FdkecaCommand),
    /// Paper 05: class-wise slow feature analysis of silhouettes (hand poses) and its
    /// baselines; the synthetic hand-pose generator.
    #[command(subcommand)]
    Sfa(sfa::SfaCommand),
    /// Paper 14: ear occlusion detection and index-based recognition (enrol, identify,
    /// detect, simulate).
    #[command(subcommand)]
    Ear(ear::EarCommand),
    /// Paper 17: Kinect gait recognition with joint relative angles and a DTW kernel
    /// (enroll, identify, cycle, ucr, simulate).
    #[command(subcommand)]
    Gait(gait::GaitCommand),
}

#[derive(Subcommand, Debug)]
pub enum FdkecaCommand {
    /// Fit a model on a labelled gallery and save it (JSON) for `identify`.
    Fit {
        #[command(flatten)]
        data: DataArgs,
        #[command(flatten)]
        model: ModelArgs,
        /// Where to write the model.
        #[arg(long)]
        out: PathBuf,
    },
    /// Identify query images (files, or folders of images) or the rows of a .npy file.
    Identify {
        /// Model written by `fit`.
        #[arg(long)]
        model: PathBuf,
        /// Query image files or folders.
        queries: Vec<PathBuf>,
        /// Query matrix (.npy) instead of images.
        #[arg(long, conflicts_with = "queries")]
        npy: Option<PathBuf>,
    },
    /// The paper's protocol on a labelled data set: per identity, K samples train and the
    /// rest test; maximum accuracy over l and the cross-validated choice of l, for each
    /// method.
    Evaluate {
        #[command(flatten)]
        data: DataArgs,
        #[command(flatten)]
        model: ModelArgs,
        /// Training samples per identity.
        #[arg(long, default_value_t = 5)]
        train_per_identity: usize,
        /// Largest number of axes swept.
        #[arg(long, default_value_t = 200)]
        max_dim: usize,
        /// Folds of the validated protocol (0 skips it).
        #[arg(long, default_value_t = 5)]
        folds: usize,
        /// Seed of the split and the folds.
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Methods to compare (default all four).
        #[arg(long, value_enum, num_args = 1.., default_values_t = [MethodName::Fdkeca, MethodName::Pca, MethodName::Kpca, MethodName::Keca])]
        methods: Vec<MethodName>,
    },
    /// Write the first axes of an FDKECA or PCA model as PNG images (the eigenface view).
    Axes {
        /// Model written by `fit`.
        #[arg(long)]
        model: PathBuf,
        /// Output folder.
        #[arg(long)]
        out: PathBuf,
        /// Number of axes (default all).
        #[arg(long)]
        count: Option<usize>,
    },
}

#[derive(Args, Debug)]
pub struct DataArgs {
    /// Gallery folder: one sub-folder of PNG/JPEG images per identity (class).
    #[arg(long, required_unless_present = "npy")]
    pub(super) gallery: Option<PathBuf>,
    /// Data (.npy): rows (n, d) or an image stack (n, h, w), instead of a gallery folder.
    #[arg(long, requires = "labels", conflicts_with = "gallery")]
    pub(super) npy: Option<PathBuf>,
    /// Labels (.npy, 1-D integers) for --npy.
    #[arg(long)]
    pub(super) labels: Option<PathBuf>,
    /// Resize gallery images to HxW (e.g. 10x20; default: the first image's size).
    #[arg(long, value_parser = parse_size)]
    pub(super) size: Option<(usize, usize)>,
}

#[derive(Args, Debug)]
pub struct ModelArgs {
    /// Method (for `fit`).
    #[arg(long, value_enum, default_value_t = MethodName::Fdkeca)]
    method: MethodName,
    /// Kernel of FDKECA, KPCA and KECA.
    #[arg(long, value_enum, default_value_t = KernelName::Rbf)]
    kernel: KernelName,
    /// Gaussian sigma (default: median distance times --sigma-scale).
    #[arg(long)]
    sigma: Option<f64>,
    /// Multiplier of the median distance.
    #[arg(long, default_value_t = 1.0)]
    sigma_scale: f64,
    /// Polynomial degree.
    #[arg(long, default_value_t = 2)]
    degree: u32,
    /// Polynomial gamma (default: 1 / length of the vectors compared).
    #[arg(long)]
    gamma: Option<f64>,
    /// Polynomial constant.
    #[arg(long, default_value_t = 1.0)]
    coef0: f64,
    /// Number of components kept (default: all available).
    #[arg(long)]
    components: Option<usize>,
    /// FDKECA axis ranking.
    #[arg(long, value_enum, default_value_t = OrderName::Entropy)]
    ordering: OrderName,
    /// Whiten PCA.
    #[arg(long)]
    whiten: bool,
    /// Nearest-neighbour distance.
    #[arg(long, value_enum, default_value_t = MetricName::Euclidean)]
    metric: MetricName,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum MethodName {
    Fdkeca,
    Pca,
    Kpca,
    Keca,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum KernelName {
    Rbf,
    Poly,
    Linear,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum OrderName {
    Entropy,
    Eigenvalue,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum MetricName {
    Euclidean,
    Cosine,
}

fn parse_size(s: &str) -> std::result::Result<(usize, usize), String> {
    let (h, w) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("expected HxW, e.g. 10x20, got {s:?}"))?;
    let p = |v: &str| {
        v.trim()
            .parse::<usize>()
            .ok()
            .filter(|&n| n > 0)
            .ok_or_else(|| format!("{v:?} is not a positive integer"))
    };
    Ok((p(h)?, p(w)?))
}

impl ModelArgs {
    fn kernel(&self) -> Kernel {
        match self.kernel {
            KernelName::Linear => Kernel::Linear,
            KernelName::Poly => Kernel::Polynomial {
                degree: self.degree,
                gamma: self.gamma.map_or(Gamma::InvDim, Gamma::Fixed),
                coef0: self.coef0,
            },
            KernelName::Rbf => Kernel::Gaussian {
                sigma: self.sigma.map_or(
                    Sigma::Median {
                        scale: self.sigma_scale,
                    },
                    Sigma::Fixed,
                ),
            },
        }
    }

    fn method(&self, name: MethodName) -> Method {
        let n_components = self.components;
        match name {
            MethodName::Fdkeca => Method::Fdkeca(
                FdkecaParams::default()
                    .kernel(self.kernel())
                    .n_components(n_components)
                    .ordering(match self.ordering {
                        OrderName::Entropy => Ordering::Entropy,
                        OrderName::Eigenvalue => Ordering::Eigenvalue,
                    })
                    .center(true),
            ),
            MethodName::Pca => Method::Pca {
                n_components,
                whiten: self.whiten,
            },
            MethodName::Kpca => Method::KernelPca {
                kernel: self.kernel(),
                n_components,
            },
            MethodName::Keca => Method::Keca {
                kernel: self.kernel(),
                n_components,
            },
        }
    }

    fn metric(&self) -> NnMetric {
        match self.metric {
            MetricName::Euclidean => NnMetric::Euclidean,
            MetricName::Cosine => NnMetric::Cosine,
        }
    }
}

fn load(data: &DataArgs) -> Result<IdentityImages> {
    match (&data.gallery, &data.npy, &data.labels) {
        (Some(dir), None, _) => load_identity_folder(dir, data.size),
        (None, Some(x), Some(y)) => read_npy_dataset(x, y),
        _ => Err(Error::invalid(
            "data",
            "give --gallery DIR, or --npy X.npy with --labels Y.npy",
        )),
    }
}

/// Runs a `wscg biometrics` command.
pub fn run(cmd: BiometricsCommand) -> Result<()> {
    let cmd = match cmd {
        BiometricsCommand::Fdkeca(cmd) => cmd,
        BiometricsCommand::Sfa(cmd) => return sfa::run(cmd),
        BiometricsCommand::Ear(cmd) => return ear::run(cmd),
        BiometricsCommand::Gait(cmd) => return gait::run(cmd),
    };
    match cmd {
        FdkecaCommand::Fit { data, model, out } => {
            let inputs = [&data.gallery, &data.npy, &data.labels];
            crate::commands::overwrite::check_file("out", &out, inputs.into_iter().flatten())?;
            let ds = load(&data)?;
            let img = &ds.images;
            let method = model.method(model.method);
            let bars = Bars::new("fit");
            bars.begin(
                &format!("{} on {} samples", method.name(), img.x.nrows()),
                1,
            );
            let rec = Recognizer::fit(
                &method,
                img.x.as_ref(),
                &img.labels,
                ds.names.clone(),
                (img.height, img.width),
                model.metric(),
            )?;
            bars.finish();
            rec.save(&out)?;
            println!(
                "{} fitted on {} samples of {} identities ({} x {} = {} values each), {} \
                 components; model written to {}",
                method.name(),
                img.x.nrows(),
                ds.names.len(),
                img.height,
                img.width,
                img.x.ncols(),
                rec.classifier.train.ncols(),
                out.display()
            );
            Ok(())
        }
        FdkecaCommand::Identify {
            model,
            queries,
            npy,
        } => {
            let rec = Recognizer::load(&model)?;
            let (x, labels): (Mat<f64>, Vec<String>) = match npy {
                Some(p) => {
                    let (x, _) = read_npy_matrix(&p)?;
                    let names = (0..x.nrows())
                        .map(|i| format!("{}[{i}]", p.display()))
                        .collect();
                    (x, names)
                }
                None => {
                    let files = expand_queries(&queries)?;
                    let (x, _) = load_images(&files, Some(rec.image_shape))?;
                    (x, files.iter().map(|f| f.display().to_string()).collect())
                }
            };
            let ids = rec.identify(x.as_ref())?;
            println!("query\tidentity\tdistance");
            for (q, id) in labels.iter().zip(&ids) {
                println!("{q}\t{}\t{:.6}", id.name, id.distance);
            }
            Ok(())
        }
        FdkecaCommand::Evaluate {
            data,
            model,
            train_per_identity,
            max_dim,
            folds,
            seed,
            methods,
        } => {
            let ds = load(&data)?;
            let img = &ds.images;
            let (tr, te) = split_per_subject(&img.labels, train_per_identity, seed)?;
            let (xtr, xte) = (
                select_rows(img.x.as_ref(), &tr),
                select_rows(img.x.as_ref(), &te),
            );
            let ytr: Vec<u32> = tr.iter().map(|&i| img.labels[i]).collect();
            let yte: Vec<u32> = te.iter().map(|&i| img.labels[i]).collect();
            let opt = ProtocolParams::default()
                .max_dim(max_dim)
                .cv_folds((folds > 0).then_some(folds))
                .seed(seed)
                .metric(model.metric());
            let bars = Bars::new("evaluate");
            bars.begin("methods", methods.len() as u64);
            println!(
                "{} identities, {} train / {} test samples, d = {}",
                ds.names.len(),
                tr.len(),
                te.len(),
                img.x.ncols()
            );
            println!("method   max acc %   at l   validated %   at l   fit s");
            for name in methods {
                let r = evaluate(
                    &model.method(name),
                    xtr.as_ref(),
                    &ytr,
                    xte.as_ref(),
                    &yte,
                    &opt,
                )?;
                bars.advance(1);
                let (vl, va) = r.validated.map_or(("-".into(), "-".into()), |(l, a)| {
                    (l.to_string(), format!("{:.1}", 100.0 * a))
                });
                println!(
                    "{:<8} {:>9.1} {:>6} {:>13} {:>6} {:>7.3}",
                    r.method,
                    100.0 * r.best.1,
                    r.best.0,
                    va,
                    vl,
                    r.fit_seconds
                );
            }
            bars.finish();
            Ok(())
        }
        FdkecaCommand::Axes { model, out, count } => {
            crate::commands::overwrite::check_folder("out", &out, [&model])?;
            let rec = Recognizer::load(&model)?;
            let (h, w) = rec.image_shape;
            let imgs = match &rec.classifier.projector {
                Model::Fdkeca(m) => m.axis_images(count.unwrap_or(m.axes.len()), h, w),
                Model::Pca(m) => m.axis_images(count.unwrap_or(m.components.len()), h, w),
                other => Err(Error::invalid(
                    "model",
                    format!(
                        "{} has no image-space axes; use FDKECA or PCA",
                        other.name()
                    ),
                )),
            }?;
            std::fs::create_dir_all(&out).map_err(|e| Error::io(&out, e))?;
            for (k, im) in imgs.iter().enumerate() {
                im.save(out.join(format!("axis_{:03}.png", k + 1)))?;
            }
            println!("{} axes written to {}", imgs.len(), out.display());
            Ok(())
        }
    }
}

/// Query paths: files as given, folders expanded to their images (sorted).
pub(super) fn expand_queries(queries: &[PathBuf]) -> Result<Vec<PathBuf>> {
    if queries.is_empty() {
        return Err(Error::Empty("queries"));
    }
    let mut files = Vec::new();
    for q in queries {
        if q.is_dir() {
            files.extend(image_files(q)?);
        } else {
            files.push(q.clone());
        }
    }
    if files.is_empty() {
        return Err(Error::invalid(
            "queries",
            "the given folders hold no PNG/JPEG images",
        ));
    }
    Ok(files)
}
