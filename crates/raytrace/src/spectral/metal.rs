//! Optical constants of the flakes' metal (paper 07, section 2.3: "the optical constants n and
//! k of aluminium", with an absorption index "k = 6" found by a paired-comparison pre-study).

use num_complex::Complex64;
use wscg_math::{Error, Result};

/// eV times nm (photon energy of a wavelength: `E = 1239.84 / lambda_nm`).
const EV_NM: f64 = 1_239.841_984;

/// Complex index `n + i k` of aluminium at `lambda_nm` from the Lorentz-Drude model of Rakić
/// et al. (Appl. Opt. 37, 1998): `eps(w) = 1 - f0 wp^2 / (w (w + i G0)) + sum_j f_j wp^2 /
/// (w_j^2 - w^2 - i w G_j)`, `w` in eV, `n + i k = sqrt(eps)`.
pub fn aluminium_rakic_ld(lambda_nm: f64) -> Complex64 {
    const WP: f64 = 14.98;
    const F0: f64 = 0.523;
    const G0: f64 = 0.047;
    const OSC: [(f64, f64, f64); 4] = [
        (0.227, 0.333, 0.162),
        (0.050, 0.312, 1.544),
        (0.166, 1.351, 1.808),
        (0.030, 3.382, 3.473),
    ];
    let w = EV_NM / lambda_nm;
    let i = Complex64::i();
    let mut eps = Complex64::new(1.0, 0.0) - F0 * WP * WP / (w * (w + i * G0));
    for (f, g, wj) in OSC {
        eps += f * WP * WP / (wj * wj - w * w - i * w * g);
    }
    let nk = eps.sqrt();
    if nk.im < 0.0 {
        -nk
    } else {
        nk
    }
}

/// Where the flakes' `n` and `k` come from.
#[derive(Clone, Debug, PartialEq)]
pub enum MetalIor {
    /// Aluminium, Rakić Lorentz-Drude model (physics mode).
    AlRakicLd,
    /// Aluminium's `n` from the Rakić model with a constant absorption index `k` (the paper's
    /// mode: k = 6).
    AlRakicLdConstK {
        /// Absorption index.
        k: f64,
    },
    /// Constant `n` and `k`.
    Constant {
        /// Refractive index.
        n: f64,
        /// Absorption index.
        k: f64,
    },
    /// A table of `(lambda_nm, n, k)` rows in increasing wavelength, linearly interpolated
    /// (clamped at the ends).
    Table(Vec<(f64, f64, f64)>),
}

impl Default for MetalIor {
    fn default() -> Self {
        MetalIor::AlRakicLdConstK { k: 6.0 }
    }
}

impl MetalIor {
    /// Errors: negative or non-finite `k`, non-positive `n`, an empty or unsorted table.
    pub fn validate(&self) -> Result<()> {
        let check = |n: f64, k: f64| -> Result<()> {
            if !(n.is_finite() && n > 0.0) {
                return Err(Error::invalid(
                    "n",
                    format!("must be finite and positive, got {n}"),
                ));
            }
            if !(k.is_finite() && k >= 0.0) {
                return Err(Error::invalid(
                    "k",
                    format!("must be finite and >= 0, got {k}"),
                ));
            }
            Ok(())
        };
        match self {
            MetalIor::AlRakicLd => Ok(()),
            MetalIor::AlRakicLdConstK { k } => check(1.0, *k),
            MetalIor::Constant { n, k } => check(*n, *k),
            MetalIor::Table(rows) => {
                if rows.is_empty() {
                    return Err(Error::Empty("metal index table"));
                }
                for (i, &(l, n, k)) in rows.iter().enumerate() {
                    check(n, k)?;
                    if !l.is_finite() || (i > 0 && l <= rows[i - 1].0) {
                        return Err(Error::invalid(
                            "table",
                            "wavelengths must be finite and strictly increasing",
                        ));
                    }
                }
                Ok(())
            }
        }
    }

    /// `(n, k)` at `lambda_nm`.
    pub fn nk(&self, lambda_nm: f64) -> (f64, f64) {
        match self {
            MetalIor::AlRakicLd => {
                let c = aluminium_rakic_ld(lambda_nm);
                (c.re, c.im)
            }
            MetalIor::AlRakicLdConstK { k } => (aluminium_rakic_ld(lambda_nm).re, *k),
            MetalIor::Constant { n, k } => (*n, *k),
            MetalIor::Table(rows) => {
                let j = rows.partition_point(|r| r.0 < lambda_nm);
                if j == 0 {
                    return (rows[0].1, rows[0].2);
                }
                if j == rows.len() {
                    let r = rows[rows.len() - 1];
                    return (r.1, r.2);
                }
                let (a, b) = (rows[j - 1], rows[j]);
                let f = (lambda_nm - a.0) / (b.0 - a.0);
                (a.1 + f * (b.1 - a.1), a.2 + f * (b.2 - a.2))
            }
        }
    }
}
