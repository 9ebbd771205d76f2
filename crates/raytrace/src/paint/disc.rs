//! One flake of the binder: a disc with its centre, normal and radius, and what the tile, its
//! grid and the plate ask of it (tilt, extent, bounding box, ray hit).

use nalgebra::Vector3;
use wscg_math::vec3::{add, sub};

use crate::bvh::Aabb;

/// One flake: a disc of centre `c` (tile frame, µm), unit normal `n` (pointing up), radius
/// `r`, thickness `h`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Flake {
    /// Centre (µm): `x, y` in `[0, tile)`, `z` above the base.
    pub c: [f64; 3],
    /// Unit normal with `n.z > 0`.
    pub n: [f64; 3],
    /// Radius (µm).
    pub r: f64,
}

impl Flake {
    /// Tilt angle (radians).
    pub fn tilt(&self) -> f64 {
        self.n[2].clamp(-1.0, 1.0).acos()
    }

    /// Half of the flake's vertical extent: `r sin(tilt) + h/2 cos(tilt)`.
    pub fn half_height(&self, h: f64) -> f64 {
        let nz = self.n[2];
        let s = (1.0 - nz * nz).max(0.0).sqrt();
        self.r * s + 0.5 * h * nz
    }

    /// Bounding box of the disc (zero thickness).
    pub fn aabb(&self) -> Aabb {
        let e = self.n.map(|v| self.r * (1.0 - v * v).max(0.0).sqrt());
        Aabb {
            min: sub(self.c, e),
            max: add(self.c, e),
        }
    }

    /// Ray parameter of the hit of `o + t d` with the disc's mid-plane inside its radius.
    #[inline]
    pub fn intersect(&self, o: [f64; 3], d: [f64; 3]) -> Option<(f64, [f64; 3])> {
        self.intersect_v(&o.into(), &d.into())
            .map(|(t, p)| (t, p.into()))
    }

    /// [`Flake::intersect`] for a ray converted once, before the loop over the discs.
    #[inline]
    pub(crate) fn intersect_v(
        &self,
        o: &Vector3<f64>,
        d: &Vector3<f64>,
    ) -> Option<(f64, Vector3<f64>)> {
        let (c, n) = (Vector3::from(self.c), Vector3::from(self.n));
        let dn = d.dot(&n);
        if dn.abs() < 1e-12 {
            return None;
        }
        let t = (c - o).dot(&n) / dn;
        if t <= 1e-9 {
            return None;
        }
        let p = o + d * t;
        ((p - c).norm_squared() <= self.r * self.r).then_some((t, p))
    }
}
