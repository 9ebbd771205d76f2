//! One type for the four fitted projections, so that a model of any method can be stored,
//! loaded, swept and used by the recognition pipeline.

use faer::{Mat, MatRef};
use serde::{Deserialize, Serialize};
use wscg_math::{Error, Result};

use super::{Fdkeca, FdkecaParams, Keca, Kernel, KernelPca, Pca, Projector};

/// A method with its parameters, ready to fit.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Method {
    /// FDKECA (the paper's method).
    Fdkeca(FdkecaParams),
    /// PCA, optionally whitened.
    Pca {
        /// Number of axes (default all).
        n_components: Option<usize>,
        /// Divide by the square root of the variances.
        whiten: bool,
    },
    /// Kernel PCA.
    KernelPca {
        /// Kernel between samples.
        kernel: Kernel,
        /// Number of components (default: the numerical rank of the centred kernel).
        n_components: Option<usize>,
    },
    /// KECA.
    Keca {
        /// Kernel between samples.
        kernel: Kernel,
        /// Number of components (default: those with a positive entropy term).
        n_components: Option<usize>,
    },
}

impl Method {
    /// Short name as in the paper's tables: "FDKECA", "PCA", "KPCA", "KECA".
    pub fn name(&self) -> &'static str {
        match self {
            Method::Fdkeca(_) => "FDKECA",
            Method::Pca { .. } => "PCA",
            Method::KernelPca { .. } => "KPCA",
            Method::Keca { .. } => "KECA",
        }
    }

    /// The four methods of the paper's Table 1 with their default parameters (Gaussian
    /// kernels with the median heuristic), FDKECA first; KPCA and KECA keep
    /// `kernel_components` components (the paper uses the first 200).
    pub fn table1(kernel_components: Option<usize>) -> [Method; 4] {
        let kernel = Kernel::default();
        [
            Method::Fdkeca(FdkecaParams::default()),
            Method::Pca {
                n_components: None,
                whiten: false,
            },
            Method::KernelPca {
                kernel,
                n_components: kernel_components,
            },
            Method::Keca {
                kernel,
                n_components: kernel_components,
            },
        ]
    }

    /// Fits the method to the rows of `x`.
    pub fn fit(&self, x: MatRef<'_, f64>) -> Result<Model> {
        Ok(match *self {
            Method::Fdkeca(p) => Model::Fdkeca(Fdkeca::fit(x, &p)?),
            Method::Pca {
                n_components,
                whiten,
            } => Model::Pca(Pca::fit(x, n_components, whiten)?),
            Method::KernelPca {
                kernel,
                n_components,
            } => Model::KernelPca(KernelPca::fit(x, &kernel, n_components)?),
            Method::Keca {
                kernel,
                n_components,
            } => Model::Keca(Keca::fit(x, &kernel, n_components)?),
        })
    }
}

/// A fitted FDKECA, PCA, KPCA or KECA.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Model {
    /// FDKECA.
    Fdkeca(Fdkeca),
    /// PCA.
    Pca(Pca),
    /// Kernel PCA.
    KernelPca(KernelPca),
    /// KECA.
    Keca(Keca),
}

impl Model {
    /// Short name: "FDKECA", "PCA", "KPCA", "KECA".
    pub fn name(&self) -> &'static str {
        match self {
            Model::Fdkeca(_) => "FDKECA",
            Model::Pca(_) => "PCA",
            Model::KernelPca(_) => "KPCA",
            Model::Keca(_) => "KECA",
        }
    }

    fn projector(&self) -> &dyn Projector {
        match self {
            Model::Fdkeca(m) => m,
            Model::Pca(m) => m,
            Model::KernelPca(m) => m,
            Model::Keca(m) => m,
        }
    }

    /// The same model with its first `l` components (no refit).
    pub fn truncated(&self, l: usize) -> Result<Self> {
        Ok(match self {
            Model::Fdkeca(m) => Model::Fdkeca(m.truncated(l)?),
            Model::Pca(m) => Model::Pca(m.truncated(l)?),
            Model::KernelPca(m) => Model::KernelPca(m.truncated(l)?),
            Model::Keca(m) => Model::Keca(m.truncated(l)?),
        })
    }

    /// Maps projected rows back to image space (FDKECA and PCA, whose axes are orthonormal:
    /// `x = mean + A y`); kernel methods have no linear pre-image and return an error.
    pub fn inverse_transform(&self, y: MatRef<'_, f64>) -> Result<Mat<f64>> {
        match self {
            Model::Fdkeca(m) => m.inverse_transform(y),
            Model::Pca(m) => m.inverse_transform(y),
            Model::KernelPca(_) | Model::Keca(_) => Err(Error::invalid(
                "model",
                format!(
                    "{} has no linear pre-image; reconstruction needs FDKECA or PCA",
                    self.name()
                ),
            )),
        }
    }

    /// Serialises the model to JSON.
    pub fn to_json(&self) -> Result<String> {
        serde_json::to_string(self).map_err(|e| Error::invalid("model", e.to_string()))
    }

    /// Reads a model written by [`Model::to_json`].
    pub fn from_json(s: &str) -> Result<Self> {
        serde_json::from_str(s).map_err(|e| Error::invalid("json", e.to_string()))
    }
}

impl Projector for Model {
    fn transform(&self, x: MatRef<'_, f64>) -> Result<Mat<f64>> {
        self.projector().transform(x)
    }
    fn n_components(&self) -> usize {
        self.projector().n_components()
    }
    fn input_dim(&self) -> usize {
        self.projector().input_dim()
    }
}
