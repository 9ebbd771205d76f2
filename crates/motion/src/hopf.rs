//! Dynamic primitives (paper §2.2): Hopf limit-cycle oscillators in a star network, one leader
//! and one follower per periodic source.
//!
//! ```text
//! ẋ = (1 − x² − y²) x − ω y + k (x_p − x)
//! ẏ = (1 − x² − y²) y + ω x + k (y_p − y)
//! ```
//!
//! For `k = 0` the circle of radius 1 is a stable limit cycle traversed at angular frequency
//! `ω`; from radius `r₀` the radius follows `r(t) = (1 + (r₀⁻² − 1) e^{−2t})^{−1/2}`. The
//! followers receive the leader's state as `(x_p, y_p)` (unilateral coupling). The symmetric
//! part of the Hopf Jacobian has eigenvalues ≤ 1, so by contraction analysis (Lohmiller and
//! Slotine; Pham and Slotine) any `k > 1` makes each follower converge to the leader at a rate
//! of at least `k − 1`.

use std::f64::consts::TAU;
use wscg_math::{Error, Result};

/// Largest `ω·dt` of one RK4 step; longer frames are split into sub-steps.
pub const MAX_PHASE_STEP: f64 = 0.2;

/// Right-hand side of one (possibly coupled) Hopf oscillator.
pub fn hopf_rhs(s: [f64; 2], omega: f64, k: f64, input: [f64; 2]) -> [f64; 2] {
    let [x, y] = s;
    let g = 1.0 - x * x - y * y;
    [
        g * x - omega * y + k * (input[0] - x),
        g * y + omega * x + k * (input[1] - y),
    ]
}

/// Analytic radius of an uncoupled oscillator started at radius `r0 > 0`, after time `t`.
pub fn hopf_radius(r0: f64, t: f64) -> f64 {
    (1.0 + (r0.powi(-2) - 1.0) * (-2.0 * t).exp()).powf(-0.5)
}

/// Phase `atan2(y, x)` wrapped to `[0, 2π)` (the paper writes `arctan(y/x)`, which is wrong in
/// two quadrants).
pub fn phase(s: [f64; 2]) -> f64 {
    let a = s[1].atan2(s[0]);
    // `atan2` is in [−π, π]; a tiny negative angle plus 2π rounds up to exactly 2π.
    let p = if a < 0.0 { a + TAU } else { a };
    if p >= TAU {
        0.0
    } else {
        p
    }
}

/// A leader oscillator with followers coupled to it in a star.
#[derive(Clone, Debug, PartialEq)]
pub struct StarNetwork {
    /// Angular frequency (rad/s).
    pub omega: f64,
    /// Coupling strength of the followers.
    pub k: f64,
    /// Leader state.
    pub leader: [f64; 2],
    /// Follower states.
    pub followers: Vec<[f64; 2]>,
}

impl StarNetwork {
    /// A network with every oscillator at `(1, 0)` (phase 0, on the limit cycle).
    ///
    /// # Errors
    /// `omega` not finite and > 0, `k` negative or not finite.
    pub fn new(omega: f64, k: f64, n_followers: usize) -> Result<Self> {
        check_omega(omega)?;
        if !(k.is_finite() && k >= 0.0) {
            return Err(Error::invalid(
                "k",
                format!("coupling must be finite and >= 0, got {k}"),
            ));
        }
        Ok(Self {
            omega,
            k,
            leader: [1.0, 0.0],
            followers: vec![[1.0, 0.0]; n_followers],
        })
    }

    /// Leader phase in `[0, 2π)`.
    pub fn phase(&self) -> f64 {
        phase(self.leader)
    }

    /// Changes the frequency (done at the leader's phase wrap so that no source shifts).
    ///
    /// # Errors
    /// `omega` not finite and > 0.
    pub fn set_omega(&mut self, omega: f64) -> Result<()> {
        check_omega(omega)?;
        self.omega = omega;
        Ok(())
    }

    /// Advances by `dt` with classical RK4, split into sub-steps of `ω·h ≤ 0.2`.
    ///
    /// # Errors
    /// `dt` not finite and > 0.
    pub fn step_rk4(&mut self, dt: f64) -> Result<()> {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(Error::invalid(
                "dt",
                format!("must be finite and > 0, got {dt}"),
            ));
        }
        let n = (self.omega * dt / MAX_PHASE_STEP).ceil().max(1.0) as usize;
        let h = dt / n as f64;
        for _ in 0..n {
            self.rk4(h);
        }
        Ok(())
    }

    fn rk4(&mut self, h: f64) {
        let (w, k) = (self.omega, self.k);
        let add = |s: [f64; 2], d: [f64; 2], f: f64| [s[0] + f * d[0], s[1] + f * d[1]];
        let l0 = self.leader;
        let free = [0.0, 0.0];
        let lk1 = hopf_rhs(l0, w, 0.0, free);
        let l1 = add(l0, lk1, 0.5 * h);
        let lk2 = hopf_rhs(l1, w, 0.0, free);
        let l2 = add(l0, lk2, 0.5 * h);
        let lk3 = hopf_rhs(l2, w, 0.0, free);
        let l3 = add(l0, lk3, h);
        let lk4 = hopf_rhs(l3, w, 0.0, free);
        // The followers see the leader at the same RK stages.
        for f in &mut self.followers {
            let f0 = *f;
            let k1 = hopf_rhs(f0, w, k, l0);
            let k2 = hopf_rhs(add(f0, k1, 0.5 * h), w, k, l1);
            let k3 = hopf_rhs(add(f0, k2, 0.5 * h), w, k, l2);
            let k4 = hopf_rhs(add(f0, k3, h), w, k, l3);
            *f = [
                f0[0] + h / 6.0 * (k1[0] + 2.0 * k2[0] + 2.0 * k3[0] + k4[0]),
                f0[1] + h / 6.0 * (k1[1] + 2.0 * k2[1] + 2.0 * k3[1] + k4[1]),
            ];
        }
        self.leader = [
            l0[0] + h / 6.0 * (lk1[0] + 2.0 * lk2[0] + 2.0 * lk3[0] + lk4[0]),
            l0[1] + h / 6.0 * (lk1[1] + 2.0 * lk2[1] + 2.0 * lk3[1] + lk4[1]),
        ];
    }
}

fn check_omega(omega: f64) -> Result<()> {
    if omega.is_finite() && omega > 0.0 {
        Ok(())
    } else {
        Err(Error::invalid(
            "omega",
            format!("must be finite and > 0, got {omega}"),
        ))
    }
}

/// Rotates a state by `angle` (radians): the delayed source `s(t − τ)` of a follower is its map
/// evaluated at `R(−ωτ)·state` (paper §2.2), so delays need no buffers.
pub fn rotate(s: [f64; 2], angle: f64) -> [f64; 2] {
    let (sn, cs) = angle.sin_cos();
    [cs * s[0] - sn * s[1], sn * s[0] + cs * s[1]]
}
