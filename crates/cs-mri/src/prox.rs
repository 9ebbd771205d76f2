//! Proximal maps of paper 11, section 2.3: soft thresholding (the prox of eq. 8 for
//! `Phi = l1`) and the projection onto the data-fidelity ball (eq. 9).

use num_complex::Complex64;
use rayon::prelude::*;

use crate::sparsifier::CoeffVec;

/// Real soft threshold `sign(a) max(|a| - tau, 0)`.
pub fn soft(a: f64, tau: f64) -> f64 {
    a.signum() * (a.abs() - tau).max(0.0)
}

/// Complex (magnitude) soft threshold `a max(|a| - tau, 0) / |a|` (eq. 8 with `Phi = l1` on
/// complex coefficients: the magnitude shrinks, the phase is kept).
pub fn soft_complex(a: Complex64, tau: f64) -> Complex64 {
    let m = a.norm_sqr().sqrt();
    if m <= tau {
        Complex64::new(0.0, 0.0)
    } else {
        a * ((m - tau) / m)
    }
}

/// Soft-thresholds every coefficient in place (real ones by value, complex by magnitude).
pub fn soft_coeffs(c: &mut CoeffVec, tau: f64) {
    c.real.par_iter_mut().for_each(|v| *v = soft(*v, tau));
    c.complex
        .par_iter_mut()
        .for_each(|v| *v = soft_complex(*v, tau));
}

/// The fused l1 update of C-SALSA (eqs. 7-9): with `psi_x = Psi x`,
/// `a = psi_x - d`, `v = soft(a, tau)`, then `d <- v - a` and `next <- v + d` (what the next
/// x-update synthesises), element by element in one pass. Real and complex coefficients
/// flagged in `skip` (`[real, complex]`) are not shrunk.
pub fn admm_l1_step(
    psi_x: &CoeffVec,
    d: &mut CoeffVec,
    next: &mut CoeffVec,
    tau: f64,
    skip: [&[bool]; 2],
) {
    // A flag list shorter than its coefficients (empty: none skipped) reads as `false`.
    let kept = |flags: &[bool], i: usize| !flags.get(i).copied().unwrap_or(false);
    d.real
        .par_iter_mut()
        .zip(next.real.par_iter_mut())
        .zip(psi_x.real.par_iter())
        .enumerate()
        .for_each(|(i, ((d, n), &p))| {
            let a = p - *d;
            let v = if kept(skip[0], i) { soft(a, tau) } else { a };
            *d = v - a;
            *n = v + *d;
        });
    d.complex
        .par_iter_mut()
        .zip(next.complex.par_iter_mut())
        .zip(psi_x.complex.par_iter())
        .enumerate()
        .for_each(|(i, ((d, n), &p))| {
            let a = p - *d;
            let v = if kept(skip[1], i) {
                soft_complex(a, tau)
            } else {
                a
            };
            *d = v - a;
            *n = v + *d;
        });
}

/// Projection of `v` onto the ball `{u : ||u - y|| <= eps}` (eq. 9), in place.
/// With `eps = 0` this replaces `v` by `y`.
pub fn project_ball(v: &mut [Complex64], y: &[Complex64], eps: f64) {
    let d: f64 = v
        .iter()
        .zip(y)
        .map(|(a, b)| (a - b).norm_sqr())
        .sum::<f64>()
        .sqrt();
    if d <= eps {
        return;
    }
    let s = eps / d;
    v.iter_mut()
        .zip(y)
        .for_each(|(a, &b)| *a = b + (*a - b) * s);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thresholds_and_projection() {
        assert_eq!(soft(3.0, 1.0), 2.0);
        assert_eq!(soft(-3.0, 1.0), -2.0);
        assert_eq!(soft(0.5, 1.0), 0.0);
        let z = soft_complex(Complex64::new(3.0, 4.0), 1.0);
        assert!((z - Complex64::new(2.4, 3.2)).norm() < 1e-15);
        let y = vec![Complex64::new(1.0, 0.0); 4];
        let mut v = vec![Complex64::new(3.0, 0.0); 4];
        project_ball(&mut v, &y, 1.0);
        let d: f64 = v
            .iter()
            .zip(&y)
            .map(|(a, b)| (a - b).norm_sqr())
            .sum::<f64>()
            .sqrt();
        assert!((d - 1.0).abs() < 1e-12);
        project_ball(&mut v, &y, 0.0);
        assert_eq!(v, y);
        let mut c = CoeffVec {
            real: vec![2.0, -0.5],
            complex: vec![Complex64::new(0.0, 3.0)],
        };
        soft_coeffs(&mut c, 1.0);
        assert_eq!(c.real, vec![1.0, 0.0]);
        assert_eq!(c.complex, vec![Complex64::new(0.0, 2.0)]);
    }
}
