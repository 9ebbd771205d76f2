//! Light at the plate's horizontal interfaces, shared by the camera chains and the photons:
//! mirror reflection, Snell refraction, and the Fresnel choice between them at the
//! coat-binder interface.

use nalgebra::Vector3;
use rand::Rng;

use crate::spectral::fresnel_dielectric;

/// Mirror reflection of `d` about the unit normal `n`.
pub(crate) fn reflect(d: &Vector3<f64>, n: &Vector3<f64>) -> Vector3<f64> {
    d - n * (2.0 * d.dot(n))
}

/// The ray parameter at which a ray at height `z` in the binder `[0, t_bind]`, with vertical
/// direction component `dz`, leaves it: through the base (`z = 0`) going down, through the
/// binder's top going up.
pub(crate) fn binder_exit(z: f64, dz: f64, t_bind: f64) -> f64 {
    if dz < 0.0 {
        z / -dz
    } else {
        (t_bind - z) / dz
    }
}

/// Refraction through the horizontal interface: `d` crosses from index `n1` to `n2`; the
/// horizontal components scale by `n1 / n2` (Snell). `None` under total internal reflection.
pub(crate) fn refract_horizontal(d: &Vector3<f64>, n1: f64, n2: f64) -> Option<Vector3<f64>> {
    let eta = n1 / n2;
    let (x, y) = (d.x * eta, d.y * eta);
    let s2 = x * x + y * y;
    if s2 >= 1.0 {
        return None;
    }
    Some(Vector3::new(x, y, (1.0 - s2).sqrt().copysign(d.z)))
}

/// What a ray does at the coat-binder interface.
pub(crate) enum Crossing {
    /// Reflected back (chosen with the Fresnel probability); `dir.z` is flipped.
    Reflected,
    /// Refracted through (or no interface: equal indices); `dir` is the new direction.
    Refracted,
    /// Totally reflected where the deterministic refraction has no solution.
    Lost,
}

/// Crossing of the horizontal interface from index `n1` to `n2` by `dir`.
pub(crate) fn cross_interface(
    dir: &mut Vector3<f64>,
    n1: f64,
    n2: f64,
    rng: &mut impl Rng,
) -> Crossing {
    if n1 == n2 {
        return Crossing::Refracted;
    }
    if rng.random::<f64>() < fresnel_dielectric(dir.z.abs(), n2 / n1) {
        dir.z = -dir.z;
        return Crossing::Reflected;
    }
    match refract_horizontal(dir, n1, n2) {
        Some(r) => {
            *dir = r;
            Crossing::Refracted
        }
        None => Crossing::Lost,
    }
}
