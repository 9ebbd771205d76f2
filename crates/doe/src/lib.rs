//! # wscg-doe
//!
//! Design-of-experiments statistics of paper 07 of the Journal of WSCG vol. 23: F. da Graça,
//! A. Paljic, E. Diaz, "Evaluating stereoscopic visualization for predictive rendering"
//! (WSCG 2015). The paper compares virtual metallic-paint plates with a photograph of a real
//! one: 13 plates drawn from a central composite design over flake radius and flake density,
//! 26 observers, similarity scores 0 (identical) … 10 (different), a monoscopic and a
//! stereoscopic condition, a quadratic response surface per condition (Tables 2–3), a
//! repeated-measures ANOVA and Fisher's LSD.
//!
//! Modules (generic, usable for any small perceptual study):
//!
//! - [`mod@ccd`]: central composite designs (circumscribed, inscribed, faced; rotatable or orthogonal
//!   α), pyDOE3-compatible, and the coded ↔ physical maps.
//! - [`williams`]: Williams Latin squares, presentation orders balanced for carry-over.
//! - [`rsm`]: second-order response surfaces by OLS with standard errors, t-tests, R², adjusted
//!   and predicted R², PRESS, leverages, stationary point and canonical analysis; on panel
//!   means or on all scores with subjects as blocks.
//! - [`anova`]: two-way repeated-measures ANOVA with Greenhouse–Geisser correction, one-way
//!   repeated-measures ANOVA, Fisher's LSD.
//! - [`panel`]: PCA of the standardised panel (observer agreement).
//! - [`dist`]: Student-t and F tails and the t quantile.
//!
//! All functions return [`wscg_math::Result`]; bad input (wrong shapes, NaN, too few runs, a
//! singular design, out-of-range parameters) is an error naming the argument, never a panic.
//!
//! ```
//! use wscg_doe::ccd::{ccd, decode, CcdAlpha, CcdFace};
//! use wscg_doe::rsm::fit_quadratic;
//!
//! // The paper's 13-run inscribed rotatable design, in physical units.
//! let x = ccd(2, CcdFace::Inscribed, CcdAlpha::Rotatable, 5).unwrap();
//! let runs = decode(&x, &[15.0, 3.5], &[45.0, 9.5]).unwrap();
//! assert!((runs[(0, 0)] - 19.393).abs() < 1e-3);
//!
//! // A response with a minimum at (0.1, -0.2) plus a little noise.
//! let y: Vec<f64> = x
//!     .row_iter()
//!     .enumerate()
//!     .map(|(i, r)| 2.0 + 6.0 * (r[0] - 0.1).powi(2) + 2.0 * (r[1] + 0.2).powi(2) + 0.01 * (i % 3) as f64)
//!     .collect();
//! let fit = fit_quadratic(&x, &y, false).unwrap();
//! assert!(fit.canonical_eigs.iter().all(|&l| l > 0.0)); // a minimum: the best match
//! let xs = fit.stationary.unwrap();
//! assert!((xs[0] - 0.1).abs() < 0.01 && (xs[1] + 0.2).abs() < 0.01);
//! ```
#![warn(missing_docs)]

pub mod anova;
pub mod ccd;
pub mod io;
/// Student-t and F tails, shared with other papers through wscg-math.
pub use wscg_math::dist;
pub mod panel;
pub mod rsm;
pub mod williams;

pub use anova::{
    lsd_pairs, rm_anova, rm_anova_oneway, AnovaEffect, AnovaTable, LeastSignificantDifference,
};
pub use ccd::{ccd, ccd_blocks, decode, encode, CcdAlpha, CcdFace};
pub use io::{
    parse_design, parse_runs, parse_study, read_design, read_runs, read_study, write_runs,
    write_study, Study,
};
pub use panel::panel_pca;
pub use rsm::{fit_quadratic, fit_quadratic_blocked, predict, RsmFit};
pub use williams::williams_square;
pub use wscg_math::{Error, Result};
