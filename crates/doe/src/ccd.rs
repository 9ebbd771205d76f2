//! Central composite designs (Box–Wilson) in coded units, and the coded ↔ physical maps.
//!
//! Paper 07 (§2.3, Table 1, Fig. 5c) draws its 13 virtual plates from "a central composite design
//! with replicated centred points" over two factors, flake radius (15–45 µm) and flake density
//! (3.5–9.5). The variant consistent with the paper's reported mean scores is the **inscribed**
//! (CCI), **rotatable** design with 5 centre points:
//!
//! ```text
//! factorial (±1/√2, ±1/√2) x 4,  axial (±1, 0), (0, ±1),  centre (0, 0) x 5
//! ```
//!
//! which [`decode`] maps to radius {19.39, 40.61} x density {4.379, 8.621}, (15, 6.5), (45, 6.5),
//! (30, 3.5), (30, 9.5) and 5 x (30, 6.5).
//!
//! The generator follows pyDOE3's `ccdesign(k, center=(c1, c2), alpha, face)` exactly, rows in
//! the same order:
//!
//! 1. the 2^k factorial points, the first factor varying slowest (`itertools.product`);
//! 2. `c1` centre points;
//! 3. the 2k axial points `(-α, 0, ..)`, `(+α, 0, ..)`, `(0, -α, ..)`, ...;
//! 4. `c2` centre points.
//!
//! Axial distance α (for the circumscribed design):
//!
//! ```text
//! rotatable:   α = (2^k)^(1/4)
//! orthogonal:  α = sqrt( k (1 + c2 / (2k)) / (1 + c1 / 2^k) )
//! ```
//!
//! Faces: **circumscribed** (CCC) puts factorial points at ±1 and axial points at ±α;
//! **inscribed** (CCI) divides the CCC design by α so the axial points sit at ±1 and the factorial
//! points at ±1/α; **faced** (CCF) uses α = 1.

use std::str::FromStr;

use nalgebra::DMatrix;
use wscg_math::{Error, Result};

/// Largest number of factors accepted by [`ccd`] (2^20 factorial runs).
pub const MAX_FACTORS: usize = 20;

/// Largest number of centre points accepted by [`ccd`] and [`ccd_blocks`].
pub const MAX_CENTER: usize = 1_000_000;

/// Where the axial ("star") points sit relative to the factorial cube.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CcdFace {
    /// CCC: factorial points at ±1, axial points at ±α (outside the cube for α > 1).
    Circumscribed,
    /// CCI: the CCC design divided by α: axial points at ±1, factorial points at ±1/α.
    /// Use it when the factor ranges are hard limits (paper 07's design).
    Inscribed,
    /// CCF: axial points on the faces of the cube (α = 1); three levels per factor.
    Faced,
}

impl FromStr for CcdFace {
    type Err = Error;

    /// Parses pyDOE3's names: `circumscribed`/`ccc`, `inscribed`/`cci`, `faced`/`ccf`
    /// (case-insensitive).
    fn from_str(s: &str) -> Result<Self> {
        match s.to_ascii_lowercase().as_str() {
            "circumscribed" | "ccc" => Ok(CcdFace::Circumscribed),
            "inscribed" | "cci" => Ok(CcdFace::Inscribed),
            "faced" | "ccf" => Ok(CcdFace::Faced),
            _ => Err(Error::invalid(
                "face",
                format!(
                    "`{s}` is not a valid face. Valid faces are `circumscribed` (`ccc`), \
                     `inscribed` (`cci`) and `faced` (`ccf`)"
                ),
            )),
        }
    }
}

/// How the axial distance α is chosen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CcdAlpha {
    /// α = (2^k)^(1/4): the prediction variance depends only on the distance to the centre.
    Rotatable,
    /// α making the quadratic columns orthogonal, from pyDOE3's formula (depends on the split of
    /// the centre points between the factorial and axial blocks).
    Orthogonal,
    /// A user-chosen α > 0 (≥ 1 for the inscribed face, = 1 for the faced one).
    Value(f64),
}

impl FromStr for CcdAlpha {
    type Err = Error;

    /// Parses pyDOE3's names `rotatable`/`r` and `orthogonal`/`o` (case-insensitive), or a
    /// number.
    fn from_str(s: &str) -> Result<Self> {
        match s.to_ascii_lowercase().as_str() {
            "rotatable" | "r" => Ok(CcdAlpha::Rotatable),
            "orthogonal" | "o" => Ok(CcdAlpha::Orthogonal),
            other => other.parse::<f64>().map(CcdAlpha::Value).map_err(|_| {
                Error::invalid(
                    "alpha",
                    format!(
                        "`{s}` is not a valid alpha. Valid values are `rotatable` (`r`), \
                         `orthogonal` (`o`) or a number"
                    ),
                )
            }),
        }
    }
}

/// Central composite design with `n_center` centre points in total, as coded runs (rows).
///
/// pyDOE3 places centre points in two blocks (after the factorial points and after the axial
/// points); this function splits `n_center` as `(ceil(n/2), floor(n/2))`, so `n_center = 5`
/// is pyDOE3's `center=(3, 2)`. Use [`ccd_blocks`] to choose the split (it matters for
/// [`CcdAlpha::Orthogonal`]).
///
/// * `k`: number of factors, 2 ≤ k ≤ [`MAX_FACTORS`].
/// * Returns a `(2^k + 2k + n_center) x k` matrix of coded levels.
///
/// Paper 07's design is `ccd(2, CcdFace::Inscribed, CcdAlpha::Rotatable, 5)` (13 runs).
///
/// # Errors
/// [`Error::InvalidArgument`] for `k < 2`, a non-finite or non-positive α, α < 1 with the
/// inscribed face, α ≠ 1 with the faced one; [`Error::LimitExceeded`] for `k > MAX_FACTORS` or
/// more than [`MAX_CENTER`] centre points.
pub fn ccd(k: usize, face: CcdFace, alpha: CcdAlpha, n_center: usize) -> Result<DMatrix<f64>> {
    let c1 = n_center.div_ceil(2);
    ccd_blocks(k, face, alpha, (c1, n_center - c1))
}

/// Central composite design with pyDOE3's centre blocks `center = (c1, c2)`: `c1` centre points
/// follow the factorial block and `c2` the axial block. Same as
/// `pyDOE3.ccdesign(k, center=center, alpha=..., face=...)`, row for row.
///
/// # Errors
/// As [`ccd`].
pub fn ccd_blocks(
    k: usize,
    face: CcdFace,
    alpha: CcdAlpha,
    center: (usize, usize),
) -> Result<DMatrix<f64>> {
    let a = axial_alpha(k, alpha, center)?;
    let (fact_level, axial_level) = match face {
        CcdFace::Circumscribed => (1.0, a),
        CcdFace::Inscribed => {
            if a < 1.0 {
                return Err(Error::invalid(
                    "alpha",
                    format!("must be >= 1 for an inscribed design, got {a}"),
                ));
            }
            (1.0 / a, 1.0)
        }
        CcdFace::Faced => {
            if let CcdAlpha::Value(v) = alpha {
                if v != 1.0 {
                    return Err(Error::invalid(
                        "alpha",
                        format!("a faced design has alpha = 1, got {v}"),
                    ));
                }
            }
            (1.0, 1.0)
        }
    };
    let n_fact = 1usize << k;
    let rows = n_fact + center.0 + 2 * k + center.1;
    let mut h = DMatrix::<f64>::zeros(rows, k);
    // Factorial block, first factor slowest (pyDOE3 ff2n = itertools.product([-1, 1], repeat=k)).
    for r in 0..n_fact {
        for j in 0..k {
            let bit = (r >> (k - 1 - j)) & 1;
            h[(r, j)] = if bit == 1 { fact_level } else { -fact_level };
        }
    }
    // Axial block after the first centre block.
    let base = n_fact + center.0;
    for i in 0..k {
        h[(base + 2 * i, i)] = -axial_level;
        h[(base + 2 * i + 1, i)] = axial_level;
    }
    Ok(h)
}

/// Axial distance α of the circumscribed design (pyDOE3's `star(..)` value): the inscribed design
/// divides the factorial points by it, the faced design ignores it.
///
/// # Errors
/// As [`ccd`] (`k` range, centre counts, α finite and > 0).
pub fn axial_alpha(k: usize, alpha: CcdAlpha, center: (usize, usize)) -> Result<f64> {
    if k < 2 {
        return Err(Error::invalid(
            "k",
            format!("a central composite design needs at least 2 factors, got {k}"),
        ));
    }
    if k > MAX_FACTORS {
        return Err(Error::LimitExceeded(format!(
            "k = {k} factors gives 2^{k} factorial runs; at most {MAX_FACTORS} factors are supported"
        )));
    }
    if center.0 > MAX_CENTER || center.1 > MAX_CENTER {
        return Err(Error::LimitExceeded(format!(
            "at most {MAX_CENTER} centre points per block, got {center:?}"
        )));
    }
    let nc = (1usize << k) as f64;
    Ok(match alpha {
        CcdAlpha::Rotatable => nc.powf(0.25),
        CcdAlpha::Orthogonal => {
            let na = (2 * k) as f64;
            ((k as f64) * (1.0 + center.1 as f64 / na) / (1.0 + center.0 as f64 / nc)).sqrt()
        }
        CcdAlpha::Value(v) => {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::invalid(
                    "alpha",
                    format!("must be a finite number > 0, got {v}"),
                ));
            }
            v
        }
    })
}

/// Maps coded levels to physical units, factor by factor ("reduced and centred" coding of the
/// paper, Fig. 5): `physical = (low + high)/2 + coded · (high − low)/2`, so −1 ↦ `low`,
/// +1 ↦ `high`.
///
/// * `coded`: runs x k.
/// * `low`, `high`: length k, physical bounds with `low < high` (paper 07: radius 15–45 µm,
///   density 3.5–9.5).
///
/// # Errors
/// [`Error::ShapeMismatch`] when `low`/`high` do not have one entry per column;
/// [`Error::NonFinite`] for NaN/∞ in any input; [`Error::InvalidArgument`] when `low >= high`
/// for a factor.
pub fn decode(coded: &DMatrix<f64>, low: &[f64], high: &[f64]) -> Result<DMatrix<f64>> {
    let (centre, half) = ranges(coded, low, high, "coded")?;
    let mut out = coded.clone();
    for (j, mut col) in out.column_iter_mut().enumerate() {
        col.apply(|v| *v = centre[j] + *v * half[j]);
    }
    Ok(out)
}

/// Inverse of [`decode`]: `coded = (physical − (low + high)/2) / ((high − low)/2)`.
///
/// # Errors
/// As [`decode`].
pub fn encode(physical: &DMatrix<f64>, low: &[f64], high: &[f64]) -> Result<DMatrix<f64>> {
    let (centre, half) = ranges(physical, low, high, "physical")?;
    let mut out = physical.clone();
    for (j, mut col) in out.column_iter_mut().enumerate() {
        col.apply(|v| *v = (*v - centre[j]) / half[j]);
    }
    Ok(out)
}

fn ranges(
    m: &DMatrix<f64>,
    low: &[f64],
    high: &[f64],
    name: &'static str,
) -> Result<(Vec<f64>, Vec<f64>)> {
    let k = m.ncols();
    if low.len() != k || high.len() != k {
        return Err(Error::ShapeMismatch(format!(
            "`{name}` has {k} columns (factors) but `low` has {} and `high` {} entries",
            low.len(),
            high.len()
        )));
    }
    wscg_math::error::ensure_finite(name, m.as_slice())?;
    wscg_math::error::ensure_finite("low", low)?;
    wscg_math::error::ensure_finite("high", high)?;
    if let Some(j) = (0..k).find(|&j| low[j] >= high[j]) {
        return Err(Error::invalid(
            "high",
            format!("factor {j}: low = {} must be < high = {}", low[j], high[j]),
        ));
    }
    let centre = (0..k).map(|j| 0.5 * (low[j] + high[j])).collect();
    let half = (0..k).map(|j| 0.5 * (high[j] - low[j])).collect();
    Ok((centre, half))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_design_has_the_expected_levels() {
        let h = ccd(2, CcdFace::Inscribed, CcdAlpha::Rotatable, 5).unwrap();
        assert_eq!(h.shape(), (13, 2));
        let f = std::f64::consts::FRAC_1_SQRT_2;
        // Factorial rows first, first factor slowest.
        let want_fact = [[-f, -f], [-f, f], [f, -f], [f, f]];
        for (r, w) in want_fact.iter().enumerate() {
            assert!((h[(r, 0)] - w[0]).abs() < 1e-15 && (h[(r, 1)] - w[1]).abs() < 1e-15);
        }
        // 3 centre rows, 4 axial rows, 2 centre rows.
        for r in [4, 5, 6, 11, 12] {
            assert_eq!((h[(r, 0)], h[(r, 1)]), (0.0, 0.0));
        }
        let axial = [[-1.0, 0.0], [1.0, 0.0], [0.0, -1.0], [0.0, 1.0]];
        for (i, w) in axial.iter().enumerate() {
            assert_eq!((h[(7 + i, 0)], h[(7 + i, 1)]), (w[0], w[1]));
        }
    }

    #[test]
    fn faces_scale_as_documented() {
        let a = 8f64.powf(0.25);
        let ccc = ccd(3, CcdFace::Circumscribed, CcdAlpha::Rotatable, 2).unwrap();
        let cci = ccd(3, CcdFace::Inscribed, CcdAlpha::Rotatable, 2).unwrap();
        let ccf = ccd(3, CcdFace::Faced, CcdAlpha::Rotatable, 2).unwrap();
        assert!((&ccc / a - &cci).abs().max() < 1e-15);
        assert_eq!(ccf.abs().max(), 1.0);
        assert!((ccc.abs().max() - a).abs() < 1e-15);
        assert_eq!(ccc.nrows(), 8 + 6 + 2);
    }

    #[test]
    fn orthogonal_alpha_formula() {
        // k = 2, centre (4, 4): alpha = sqrt(2 (1 + 4/4) / (1 + 4/4)) = sqrt(2).
        let a = axial_alpha(2, CcdAlpha::Orthogonal, (4, 4)).unwrap();
        assert!((a - 2f64.sqrt()).abs() < 1e-15);
        // k = 3, centre (0, 0): alpha = sqrt(3).
        let a = axial_alpha(3, CcdAlpha::Orthogonal, (0, 0)).unwrap();
        assert!((a - 3f64.sqrt()).abs() < 1e-15);
    }

    #[test]
    fn names_parse_like_pydoe3() {
        assert_eq!("CCI".parse::<CcdFace>().unwrap(), CcdFace::Inscribed);
        assert_eq!("faced".parse::<CcdFace>().unwrap(), CcdFace::Faced);
        assert_eq!("r".parse::<CcdAlpha>().unwrap(), CcdAlpha::Rotatable);
        assert_eq!("1.5".parse::<CcdAlpha>().unwrap(), CcdAlpha::Value(1.5));
        let e = "cube".parse::<CcdFace>().unwrap_err().to_string();
        assert!(e.contains("face") && e.contains("inscribed"), "{e}");
        assert!("fast".parse::<CcdAlpha>().is_err());
    }

    #[test]
    fn bad_arguments_are_errors() {
        for k in [0, 1] {
            assert!(ccd(k, CcdFace::Inscribed, CcdAlpha::Rotatable, 5).is_err());
        }
        assert!(matches!(
            ccd(MAX_FACTORS + 1, CcdFace::Faced, CcdAlpha::Rotatable, 1),
            Err(Error::LimitExceeded(_))
        ));
        for v in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(ccd(2, CcdFace::Circumscribed, CcdAlpha::Value(v), 1).is_err());
        }
        assert!(ccd(2, CcdFace::Inscribed, CcdAlpha::Value(0.5), 1).is_err());
        assert!(ccd(2, CcdFace::Faced, CcdAlpha::Value(2.0), 1).is_err());
        assert!(ccd(2, CcdFace::Faced, CcdAlpha::Value(1.0), 1).is_ok());
    }

    #[test]
    fn decode_and_encode_round_trip() {
        let h = ccd(2, CcdFace::Inscribed, CcdAlpha::Rotatable, 5).unwrap();
        let p = decode(&h, &[15.0, 3.5], &[45.0, 9.5]).unwrap();
        let back = encode(&p, &[15.0, 3.5], &[45.0, 9.5]).unwrap();
        assert!((back - &h).abs().max() < 1e-14);
        assert!(decode(&h, &[15.0], &[45.0, 9.5]).is_err());
        assert!(decode(&h, &[15.0, 9.5], &[45.0, 3.5]).is_err());
        assert!(decode(&h, &[15.0, f64::NAN], &[45.0, 9.5]).is_err());
    }
}
