//! Blending between consecutive actions at the leader's phase wrap (paper §2.4).
//!
//! The signed phase `φ` runs over `[−2π, 0]` in the previous action and `[0, 2π]` in the next;
//! the blend weight is `α(φ) = (1 + sin(πφ / 2β)) / 2` on `|φ| ≤ β` (0 before, 1 after), C¹ with
//! zero slope at `±β`. Periodic weights and means are blended linearly; the non-periodic weight
//! switches sign with `φ` so that `W₀ s₀` is continuous although `s₀ = cos(ψ/2)` jumps from −1
//! to 1 at the wrap, which puts the posture at the boundary at
//! `ξ_trans = (m_prev + m_post)/2 + (W₀,post − W₀,prev)/2`.

use std::f64::consts::PI;
use wscg_math::{Error, Result};

/// The paper's blend half-width `β = π/5`.
pub const DEFAULT_BETA: f64 = PI / 5.0;

/// Checks `β ∈ (0, π)`.
///
/// # Errors
/// [`Error::InvalidArgument`] otherwise.
pub fn check_beta(beta: f64) -> Result<()> {
    if beta.is_finite() && beta > 0.0 && beta < PI {
        Ok(())
    } else {
        Err(Error::invalid(
            "beta",
            format!("must be in (0, π), got {beta}"),
        ))
    }
}

/// Blend weight `α(φ)` (paper §2.4).
pub fn blend_alpha(phi: f64, beta: f64) -> f64 {
    if phi < -beta {
        0.0
    } else if phi > beta {
        1.0
    } else {
        0.5 * (1.0 + (PI * phi / (2.0 * beta)).sin())
    }
}

/// Signed phase to the nearest action boundary: `ψ − 2π` for `ψ ≥ π`, else `ψ`.
pub fn signed_phase(psi: f64) -> f64 {
    if psi >= PI {
        psi - 2.0 * PI
    } else {
        psi
    }
}

/// The non-periodic source `s₀ = cos(ψ/2)` at the raw phase `ψ ∈ [0, 2π)`.
pub fn nonperiodic_source(psi: f64) -> f64 {
    (0.5 * psi).cos()
}

/// Blended periodic weight or mean: `(1 − α) prev + α post`.
pub fn blend_linear(prev: f64, post: f64, alpha: f64) -> f64 {
    (1.0 - alpha) * prev + alpha * post
}

/// Blended non-periodic weight `W₀ = sign(φ) [(α − 1) W₀,prev + α W₀,post]` (sign(0) = +1).
pub fn blend_nonperiodic(prev: f64, post: f64, alpha: f64, phi: f64) -> f64 {
    let s = if phi < 0.0 { -1.0 } else { 1.0 };
    s * ((alpha - 1.0) * prev + alpha * post)
}
