//! The contribution of one VPL to a shading point (paper 08, eq. 1 and its terms).

use nalgebra::Vector3;
use wscg_math::vec3::add_scaled;
use wscg_math::{Error, Result};

use super::scene::{luminance, Rgb, Scene};
use super::vpl::Vpl;

/// A receiving point: position, unit normal (on the lit side), albedo.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Receiver {
    /// Position.
    pub pos: [f64; 3],
    /// Unit normal.
    pub normal: [f64; 3],
    /// Albedo.
    pub albedo: Rgb,
}

/// What every estimator shares: the VPLs, their intensities, the clamping distance and the
/// shadow-ray offset. The same clamped geometry term serves the reference and every
/// estimator, so the estimators are unbiased with respect to the reference.
pub struct Shading<'a> {
    /// The scene.
    pub scene: &'a Scene,
    /// The VPLs.
    pub vpls: &'a [Vpl],
    /// `power * psi` per VPL.
    pub intensity: Vec<Rgb>,
    /// Squared clamping distance.
    dc2: f64,
    /// Shadow-ray offset along the normals.
    eps: f64,
    /// Smallest distance of the bounded distribution without clamping.
    floor: f64,
}

impl<'a> Shading<'a> {
    /// The shading terms for `vpls` in `scene`; `clamp_dist`: the clamping distance `d_c`
    /// (`None`: 1 % of the scene's diagonal; 0: no clamping).
    ///
    /// Errors: no VPL, a VPL with a non-finite or negative power, a negative or non-finite
    /// clamping distance.
    pub fn new(scene: &'a Scene, vpls: &'a [Vpl], clamp_dist: Option<f64>) -> Result<Self> {
        if vpls.is_empty() {
            return Err(Error::Empty("vpls"));
        }
        for (i, v) in vpls.iter().enumerate() {
            let ok = v.power.iter().all(|p| p.is_finite() && *p >= 0.0)
                && v.pos.iter().chain(v.normal.iter()).all(|c| c.is_finite());
            if !ok {
                return Err(Error::NonFinite {
                    name: "vpls",
                    index: i,
                });
            }
        }
        let diag = scene.diagonal();
        let dc = clamp_dist.unwrap_or(0.01 * diag);
        if !(dc.is_finite() && dc >= 0.0) {
            return Err(Error::invalid(
                "clamp_dist",
                format!("must be finite and >= 0, got {dc}"),
            ));
        }
        Ok(Self {
            scene,
            vpls,
            intensity: vpls.iter().map(Vpl::intensity).collect(),
            dc2: dc * dc,
            eps: 1e-4 * diag,
            floor: (1e-6 * diag).max(f64::MIN_POSITIVE),
        })
    }

    /// Number of VPLs.
    pub fn len(&self) -> usize {
        self.vpls.len()
    }

    /// Whether there is no VPL (never true once built).
    pub fn is_empty(&self) -> bool {
        self.vpls.is_empty()
    }

    /// The clamped geometry term `G_c(x, y_j)` (the `G` of eq. 1 with the squared distance
    /// clamped at `d_c^2`, the usual many-light bound, which the paper does not specify): both
    /// cosines over the clamped squared distance; 0 behind either surface.
    #[inline]
    pub fn geometry(&self, r: &Receiver, j: usize) -> f64 {
        let v = &self.vpls[j];
        let d = Vector3::from(v.pos) - Vector3::from(r.pos);
        let d2 = d.norm_squared();
        if d2 == 0.0 {
            return 0.0;
        }
        let inv = 1.0 / d2.sqrt();
        let cx = Vector3::from(r.normal).dot(&d) * inv;
        let cy = -Vector3::from(v.normal).dot(&d) * inv;
        if cx <= 0.0 || cy <= 0.0 {
            return 0.0;
        }
        cx * cy / d2.max(self.dc2)
    }

    /// Whether VPL `j` is visible from `r` (one shadow ray between the offset points).
    #[inline]
    pub fn visible(&self, r: &Receiver, j: usize) -> bool {
        let v = &self.vpls[j];
        !self.scene.occluded(
            add_scaled(r.pos, self.eps, r.normal),
            add_scaled(v.pos, self.eps, v.normal),
        )
    }

    /// `I_j(x)` without visibility: `power psi (albedo / pi) G_c`.
    #[inline]
    pub fn unoccluded(&self, r: &Receiver, j: usize) -> Rgb {
        let g = self.geometry(r, j) / std::f64::consts::PI;
        let i = &self.intensity[j];
        [0, 1, 2].map(|c| i[c] * r.albedo[c] * g)
    }

    /// `I_j(x)`, the contribution `L f_r G V` of VPL `j` in eq. 1, visibility included.
    #[inline]
    pub fn contribution(&self, r: &Receiver, j: usize) -> Rgb {
        let u = self.unoccluded(r, j);
        if luminance(&u) > 0.0 && self.visible(r, j) {
            u
        } else {
            [0.0; 3]
        }
    }

    /// The share of `r`'s unoccluded luminance (summed over the VPLs) that reaches it, one
    /// shadow ray per VPL with a positive term; `None` when no VPL lights `r` even without
    /// occlusion. Strictly between 0 and 1 on the paper's "boundaries of shadows, where the
    /// visibilities between the VPLs and the cache points change" (section 4.2).
    pub fn visible_share(&self, r: &Receiver) -> Option<f64> {
        let (mut seen, mut all) = (0.0, 0.0);
        for j in 0..self.len() {
            let y = luminance(&self.unoccluded(r, j));
            if y > 0.0 {
                all += y;
                if self.visible(r, j) {
                    seen += y;
                }
            }
        }
        (all > 0.0).then(|| seen / all)
    }

    /// The exact sum over all VPLs at `r` (the reference).
    pub fn sum_all(&self, r: &Receiver) -> Rgb {
        (0..self.len()).fold([0.0; 3], |a, j| {
            let c = self.contribution(r, j);
            [a[0] + c[0], a[1] + c[1], a[2] + c[2]]
        })
    }

    /// An upper bound of the unoccluded luminance of VPL `j` over the disc of radius `rad`
    /// around `r` (the bounded distribution B): the VPL's cosine at the nearest angle the
    /// disc allows, the receiver's cosine bounded by 1, the distance shortened by `rad`.
    pub fn bound(&self, r: &Receiver, j: usize, rad: f64) -> f64 {
        let v = &self.vpls[j];
        let dv = Vector3::from(r.pos) - Vector3::from(v.pos);
        let d = dv.norm();
        let theta = if d > 0.0 {
            (Vector3::from(v.normal).dot(&dv) / d)
                .clamp(-1.0, 1.0)
                .acos()
        } else {
            0.0
        };
        let spread = if d > 0.0 {
            (rad / d).min(1.0).asin()
        } else {
            std::f64::consts::FRAC_PI_2
        };
        let cy = (theta - spread).max(0.0).cos().max(0.0);
        let dist = (d - rad).max(self.dc2.sqrt()).max(self.floor);
        let i = &self.intensity[j];
        let rgb = [0, 1, 2].map(|c| i[c] * r.albedo[c]);
        luminance(&rgb) * cy / (dist * dist) / std::f64::consts::PI
    }
}
