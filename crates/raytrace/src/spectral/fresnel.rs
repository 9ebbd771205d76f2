//! Fresnel reflectance of smooth interfaces (paper 07, section 2.3: aluminium flakes in a
//! dielectric binder under a clear coat). Unpolarised light: the mean of the s and p
//! reflectances.

use num_complex::Complex64;

/// Unpolarised reflectance of a smooth conductor (or absorbing dielectric) for light arriving
/// from a dielectric medium: `cos_i` is the cosine of the incidence angle (its absolute value
/// is used), `n_rel + i k_rel` the conductor's index divided by the incident medium's (for a
/// flake inside a binder of index `n_b`: `(n + i k) / n_b`).
///
/// Exact for any complex index: `cos_t = sqrt(1 - sin_i^2 / eta^2)` (the decaying branch),
/// `r_s = (cos_i - eta cos_t) / (cos_i + eta cos_t)`, `r_p = (eta cos_i - cos_t) / (eta cos_i +
/// cos_t)`, `R = (|r_s|^2 + |r_p|^2) / 2`. With `k_rel = 0` and `n_rel < 1` it gives total
/// internal reflection (R = 1) beyond the critical angle.
pub fn fresnel_conductor(cos_i: f64, n_rel: f64, k_rel: f64) -> f64 {
    let c = cos_i.abs().min(1.0);
    let eta = Complex64::new(n_rel, k_rel);
    let s2 = 1.0 - c * c;
    let mut cos_t = (Complex64::new(1.0, 0.0) - s2 / (eta * eta)).sqrt();
    // The transmitted wave must decay away from the interface.
    if (eta * cos_t).im < 0.0 {
        cos_t = -cos_t;
    }
    let rs = (c - eta * cos_t) / (c + eta * cos_t);
    let rp = (eta * c - cos_t) / (eta * c + cos_t);
    (0.5 * (rs.norm_sqr() + rp.norm_sqr())).min(1.0)
}

/// Unpolarised reflectance of a smooth interface between two dielectrics, `eta = n_t / n_i`
/// (e.g. 1.5 from air into the clear coat, 1 / 1.5 from the coat back into air); 1 under
/// total internal reflection. `cos_i` as in [`fresnel_conductor`].
pub fn fresnel_dielectric(cos_i: f64, eta: f64) -> f64 {
    let c = cos_i.abs().min(1.0);
    let s2t = (1.0 - c * c) / (eta * eta);
    if s2t >= 1.0 {
        return 1.0;
    }
    let ct = (1.0 - s2t).sqrt();
    let rs = (c - eta * ct) / (c + eta * ct);
    let rp = (eta * c - ct) / (eta * c + ct);
    0.5 * (rs * rs + rp * rp)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_incidence_and_limits() {
        // ((n - 1) / (n + 1))^2 at normal incidence, grazing -> 1.
        assert!((fresnel_dielectric(1.0, 1.5) - 0.04).abs() < 1e-15);
        assert!((fresnel_dielectric(1e-9, 1.5) - 1.0).abs() < 1e-6);
        let (n, k) = (1.2, 7.0);
        let r0 = ((n - 1.0) * (n - 1.0) + k * k) / ((n + 1.0) * (n + 1.0) + k * k);
        assert!((fresnel_conductor(1.0, n, k) - r0).abs() < 1e-14);
        // A conductor with k = 0 is a dielectric.
        for c in [0.1, 0.5, 0.9] {
            assert!((fresnel_conductor(c, 1.5, 0.0) - fresnel_dielectric(c, 1.5)).abs() < 1e-14);
        }
        // Critical angle from the coat into air: sin = 1 / 1.5.
        let cc = (1.0f64 - 1.0 / 2.25).sqrt();
        assert_eq!(fresnel_dielectric(cc - 1e-6, 1.0 / 1.5), 1.0);
        assert!(fresnel_dielectric(cc + 1e-3, 1.0 / 1.5) < 1.0);
    }
}
