//! The parameter sweep of paper 04's comparisons: the paper tunes every method by a grid
//! search and plots its "optimal parameters and iterations". [`sweep`] runs every setting of
//! a baseline for a number of iterations and keeps the one reaching the lowest error at any
//! iteration.

use wscg_math::{Result, TriMesh};

use crate::bmd::{bmd_trace, BmdParams};
use crate::smoothing::{laplacian_trace, taubin_trace};

/// One setting of a baseline.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Setting {
    /// Uniform Laplacian smoothing with this factor.
    Laplacian {
        /// Factor `lambda_L`.
        lambda: f64,
    },
    /// Taubin smoothing, one `lambda` and one `mu` step per iteration.
    Taubin {
        /// Shrinking factor `lambda`.
        lambda: f64,
        /// Inflating factor `mu` (`mu < -lambda`).
        mu: f64,
    },
    /// Bilateral mesh denoising (its `iterations` field is replaced by the sweep's).
    Bmd(BmdParams),
}

impl Setting {
    /// The Laplacian grid of the sweep (the paper tunes every method by a grid search,
    /// section 4, but lists no grid; this one is ours): `lambda_L` in 0.1, 0.2, ..., 1.
    pub fn laplacian_grid() -> Vec<Setting> {
        (1..=10)
            .map(|l| Setting::Laplacian {
                lambda: l as f64 / 10.0,
            })
            .collect()
    }

    /// The Taubin grid of the sweep (ours): `lambda` in 0.3, 0.4, ..., 0.7, with `mu` from
    /// Taubin's (1995) pass-band frequency `k_PB = 1/lambda + 1/mu = 0.1`.
    pub fn taubin_grid() -> Vec<Setting> {
        (3..=7)
            .map(|l| {
                let lambda = l as f64 / 10.0;
                Setting::Taubin {
                    lambda,
                    mu: 1.0 / (0.1 - 1.0 / lambda),
                }
            })
            .collect()
    }

    /// The bilateral grid of the sweep (ours, as the Laplacian one) for mean vertex distance
    /// `mvd`:
    /// `sigma_c` in {1, 2} mvd, `sigma_s` in {0.25, 0.5, 1} mvd, with and without volume
    /// preservation.
    pub fn bmd_grid(mvd: f64) -> Vec<Setting> {
        let mut out = Vec::new();
        for sc in [1.0, 2.0] {
            for ss in [0.25, 0.5, 1.0] {
                for volume_preserve in [false, true] {
                    out.push(Setting::Bmd(BmdParams {
                        sigma_c: sc * mvd,
                        sigma_s: ss * mvd,
                        iterations: 0,
                        volume_preserve,
                    }));
                }
            }
        }
        out
    }
}

/// The best setting of a sweep.
#[derive(Clone, Debug, PartialEq)]
pub struct SweepBest {
    /// The setting.
    pub setting: Setting,
    /// The iteration (1-based) at which its error was lowest.
    pub iteration: usize,
    /// That error.
    pub error: f64,
    /// The positions at that iteration.
    pub positions: Vec<[f64; 3]>,
    /// The setting's error after every iteration.
    pub curve: Vec<f64>,
}

/// Runs every setting for `iterations` iterations on `noisy` and returns the one with the
/// lowest `error(positions)` at any iteration.
///
/// Errors: an invalid mesh or setting.
pub fn sweep(
    noisy: &TriMesh,
    settings: &[Setting],
    iterations: usize,
    error: impl Fn(&[[f64; 3]]) -> f64,
) -> Result<Option<SweepBest>> {
    let mut best: Option<SweepBest> = None;
    for &setting in settings {
        let mut curve = Vec::with_capacity(iterations);
        let mut here: Option<(usize, f64, Vec<[f64; 3]>)> = None;
        let mut observe = |it: usize, x: &[[f64; 3]]| {
            let e = error(x);
            curve.push(e);
            if here.as_ref().is_none_or(|h| e < h.1) {
                here = Some((it, e, x.to_vec()));
            }
        };
        match setting {
            Setting::Laplacian { lambda } => {
                laplacian_trace(noisy, lambda, iterations, &mut observe)?;
            }
            Setting::Taubin { lambda, mu } => {
                taubin_trace(noisy, lambda, mu, iterations, &mut observe)?;
            }
            Setting::Bmd(p) => {
                let p = BmdParams { iterations, ..p };
                bmd_trace(noisy, &p, &mut observe)?;
            }
        }
        if let Some((iteration, e, positions)) = here {
            if best.as_ref().is_none_or(|b| e < b.error) {
                best = Some(SweepBest {
                    setting,
                    iteration,
                    error: e,
                    positions,
                    curve,
                });
            }
        }
    }
    Ok(best)
}
