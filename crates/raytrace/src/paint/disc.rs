//! One flake of the binder: a disc with its centre, normal and radius, and what the tile, its
//! grid and the plate ask of it (tilt, extent, bounding box, ray hit).

use nalgebra::Vector3;

use crate::bvh::Aabb;

/// One flake: a disc of centre `c` (tile frame, µm), unit normal `n` (pointing up), radius
/// `r`, thickness `h`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Flake {
    /// Centre (µm): `x, y` in `[0, tile)`, `z` above the base.
    pub c: Vector3<f64>,
    /// Unit normal with `n.z > 0`.
    pub n: Vector3<f64>,
    /// Radius (µm).
    pub r: f64,
}

impl Flake {
    /// Tilt angle (radians).
    pub fn tilt(&self) -> f64 {
        self.n.z.clamp(-1.0, 1.0).acos()
    }

    /// Half of the flake's vertical extent: `r sin(tilt) + h/2 cos(tilt)`.
    pub fn half_height(&self, h: f64) -> f64 {
        let nz = self.n.z;
        let s = (1.0 - nz * nz).max(0.0).sqrt();
        self.r * s + 0.5 * h * nz
    }

    /// Bounding box of the disc (zero thickness).
    pub fn aabb(&self) -> Aabb {
        let e = self.n.map(|v| self.r * (1.0 - v * v).max(0.0).sqrt());
        Aabb {
            min: self.c - e,
            max: self.c + e,
        }
    }

    /// Ray parameter of the hit of `o + t d` with the disc's mid-plane inside its radius.
    #[inline]
    pub fn intersect(&self, o: &Vector3<f64>, d: &Vector3<f64>) -> Option<(f64, Vector3<f64>)> {
        let dn = d.dot(&self.n);
        if dn.abs() < 1e-12 {
            return None;
        }
        let t = (self.c - o).dot(&self.n) / dn;
        if t <= 1e-9 {
            return None;
        }
        let p = o + d * t;
        ((p - self.c).norm_squared() <= self.r * self.r).then_some((t, p))
    }
}
