//! The painted plate's layers and the lamp (paper 07, section 2.3): air, a clear coat
//! (dielectric), the binder holding the aluminium flakes, and a base ("a black surface to
//! minimise the back-surface reflection"); a lamp of small angular size.

use nalgebra::Vector3;
use wscg_math::vec3::dot;
use wscg_math::{Error, Result};

use crate::spectral::{daylight_d, MetalIor, Spectrum};

/// The clear coat on top of the binder.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coat {
    /// Refractive index (> 1); 1.5 by default (not given in the paper).
    pub ior: f64,
    /// Thickness (µm); 40 by default (not given in the paper).
    pub thickness_um: f64,
}

impl Default for Coat {
    fn default() -> Self {
        Self {
            ior: 1.5,
            thickness_um: 40.0,
        }
    }
}

/// The layers of the plate, top to bottom: optional clear coat, binder (with the flakes),
/// base.
#[derive(Clone, Debug, PartialEq)]
pub struct PlateStack {
    /// Plate size (mm): 150 x 100 in the paper.
    pub size_mm: (f64, f64),
    /// The clear coat (`None`: the binder meets the air).
    pub coat: Option<Coat>,
    /// Binder refractive index (>= 1; 1.5 by default, the same as the coat, so that the two
    /// have no optical interface; 1 makes the binder optically air, for a bare base).
    pub binder_ior: f64,
    /// Binder thickness (µm): the flake layer, 20.24 in the paper.
    pub binder_um: f64,
    /// Binder absorption coefficient (1/mm); 0 by default.
    pub binder_sigma_a_per_mm: f64,
    /// Lambertian albedo of the base (0: the paper's black base).
    pub base_albedo: f64,
    /// The flakes' metal.
    pub metal: MetalIor,
}

impl Default for PlateStack {
    fn default() -> Self {
        Self {
            size_mm: (150.0, 100.0),
            coat: Some(Coat::default()),
            binder_ior: 1.5,
            binder_um: 20.24,
            binder_sigma_a_per_mm: 0.0,
            base_albedo: 0.0,
            metal: MetalIor::default(),
        }
    }
}

impl PlateStack {
    /// Errors: a coat index <= 1, a binder index < 1, non-positive sizes or thicknesses, an
    /// albedo outside [0, 1], a negative absorption, a bad metal index.
    pub fn validate(&self) -> Result<()> {
        let pos = wscg_math::error::ensure_positive;
        pos("size_mm", self.size_mm.0)?;
        pos("size_mm", self.size_mm.1)?;
        pos("binder_um", self.binder_um)?;
        if let Some(c) = self.coat {
            if !(c.ior.is_finite() && c.ior > 1.0) {
                return Err(Error::invalid(
                    "coat_ior",
                    format!(
                        "a clear coat's refractive index must exceed 1, got {}",
                        c.ior
                    ),
                ));
            }
            pos("coat_um", c.thickness_um)?;
        }
        if !(self.binder_ior.is_finite() && self.binder_ior >= 1.0) {
            return Err(Error::invalid(
                "binder_ior",
                format!("must be >= 1, got {}", self.binder_ior),
            ));
        }
        if !(self.binder_sigma_a_per_mm.is_finite() && self.binder_sigma_a_per_mm >= 0.0) {
            return Err(Error::invalid(
                "binder_sigma_a_per_mm",
                format!(
                    "must be finite and >= 0, got {}",
                    self.binder_sigma_a_per_mm
                ),
            ));
        }
        if !(0.0..=1.0).contains(&self.base_albedo) {
            return Err(Error::invalid(
                "base_albedo",
                format!("must lie in [0, 1], got {}", self.base_albedo),
            ));
        }
        self.metal.validate()
    }

    /// Index of the medium right under the top surface.
    pub fn top_ior(&self) -> f64 {
        self.coat.map_or(self.binder_ior, |c| c.ior)
    }

    /// Height of the top surface above the base (µm).
    pub fn top_um(&self) -> f64 {
        self.binder_um + self.coat.map_or(0.0, |c| c.thickness_um)
    }

    /// The indices and heights that the ray walkers (camera chains, photons, the base's
    /// return) step through.
    pub(crate) fn walk(&self) -> Walk {
        let coat = self.coat.map_or(0.0, |c| c.thickness_um);
        Walk {
            n_top: self.top_ior(),
            nb: self.binder_ior,
            t_bind: self.binder_um,
            coat,
            z_top: self.binder_um + coat,
            sigma: self.binder_sigma_a_per_mm * 1e-3,
        }
    }
}

/// [`PlateStack::walk`]: the stack as a ray walker sees it (lengths in µm).
pub(crate) struct Walk {
    /// Index under the top surface (the coat's, else the binder's).
    pub n_top: f64,
    /// The binder's index.
    pub nb: f64,
    /// The binder's thickness: the height of the binder's top above the base.
    pub t_bind: f64,
    /// The coat's thickness (0 without a coat).
    pub coat: f64,
    /// Height of the top surface above the base.
    pub z_top: f64,
    /// The binder's absorption coefficient per µm.
    pub sigma: f64,
}

/// A lamp of angular radius `angular_radius_deg` seen from the plate, of constant radiance
/// over its disc: with mirror flakes a point (delta) light would never produce a glint. The
/// paper's lamp is a SOLUX 4700K "directional light emitted from the top"; its geometry is not
/// given: by default 45 degrees above the plate, from its top edge, and the CIE daylight
/// spectrum of 4700 K (SOLUX is sold as a daylight simulator).
#[derive(Clone, Debug, PartialEq)]
pub struct DiscLight {
    /// Unit direction from the plate to the lamp's centre, in the plate frame (x right, y
    /// towards the plate's top edge, z out of the plate); [`DiscLight::validate`] refuses a
    /// vector whose length is not 1.
    pub dir_to_light: [f64; 3],
    /// Angular radius (degrees), 1 by default.
    pub angular_radius_deg: f64,
    /// Relative spectral radiance.
    pub spectrum: Spectrum,
    /// Factor on `spectrum`.
    pub radiance_scale: f64,
}

impl Default for DiscLight {
    fn default() -> Self {
        let e = 45f64.to_radians();
        Self {
            dir_to_light: towards_top_edge(e),
            angular_radius_deg: 1.0,
            spectrum: daylight_d(4700.0).expect("4700 K lies on the daylight locus"),
            radiance_scale: 1.0,
        }
    }
}

impl DiscLight {
    /// A lamp at `elevation_deg` above the plate, towards its top edge.
    pub fn from_elevation(elevation_deg: f64, angular_radius_deg: f64) -> Self {
        let e = elevation_deg.to_radians();
        Self {
            dir_to_light: towards_top_edge(e),
            angular_radius_deg,
            ..Self::default()
        }
    }

    /// Errors: a direction that is not a finite unit vector, an angular radius outside
    /// (0, 90) degrees, a lamp whose disc reaches below the plate's horizon, a negative or
    /// non-finite scale or spectrum.
    pub fn validate(&self) -> Result<()> {
        let d = self.dir_to_light;
        let len = Vector3::from(d).norm();
        if !(len.is_finite() && (len - 1.0).abs() <= 1e-9) {
            return Err(Error::invalid(
                "dir_to_light",
                format!("must be a unit vector, got {d:?} of length {len}"),
            ));
        }
        let r = self.angular_radius_deg;
        if !(r.is_finite() && r > 0.0 && r < 90.0) {
            return Err(Error::invalid(
                "angular_radius_deg",
                format!("must lie in (0, 90), got {r}"),
            ));
        }
        let elev = self.dir_to_light[2].clamp(-1.0, 1.0).asin().to_degrees();
        if elev - r <= 0.0 {
            return Err(Error::invalid(
                "dir_to_light",
                format!("the lamp's disc must lie above the plate: elevation {elev:.2} deg, radius {r} deg"),
            ));
        }
        if !(self.radiance_scale.is_finite() && self.radiance_scale >= 0.0) {
            return Err(Error::invalid("radiance_scale", "must be finite and >= 0"));
        }
        if let Some(index) = self
            .spectrum
            .v
            .iter()
            .position(|v| !(v.is_finite() && *v >= 0.0))
        {
            return Err(Error::NonFinite {
                name: "light spectrum",
                index,
            });
        }
        Ok(())
    }

    /// Cosine of the angular radius.
    pub fn cos_radius(&self) -> f64 {
        self.angular_radius_deg.to_radians().cos()
    }

    /// A direction towards the lamp, uniform in its disc's solid angle, from two uniform
    /// numbers in `[0, 1)`.
    pub fn sample_direction(&self, u1: f64, u2: f64) -> [f64; 3] {
        let cos_r = self.cos_radius();
        let ct = 1.0 - u1 * (1.0 - cos_r);
        let phi = 2.0 * std::f64::consts::PI * u2;
        let st = (1.0 - ct * ct).max(0.0).sqrt();
        let a = Vector3::from(self.dir_to_light);
        let (u, v) = crate::frame::tangent_frame(&a);
        (a * ct + (u * phi.cos() + v * phi.sin()) * st).into()
    }

    /// Solid angle of the lamp's disc (sr).
    pub fn solid_angle(&self) -> f64 {
        2.0 * std::f64::consts::PI * (1.0 - self.cos_radius())
    }

    /// Whether direction `d` (unit, plate frame) points into the lamp's disc.
    pub fn contains(&self, d: [f64; 3]) -> bool {
        dot(d, self.dir_to_light) >= self.cos_radius()
    }

    /// Projected solid angle of the lamp divided by pi: `sin^2(r) cos(theta_c)` (exact for a
    /// disc fully above the horizon). A white Lambertian surface under the lamp has radiance
    /// `L * white_factor()`.
    pub fn white_factor(&self) -> f64 {
        let s = self.angular_radius_deg.to_radians().sin();
        s * s * self.dir_to_light[2]
    }
}

/// The unit vector `elevation` (radians) above the plate, towards its top edge.
fn towards_top_edge(elevation: f64) -> [f64; 3] {
    Vector3::new(0.0, elevation.cos(), elevation.sin())
        .normalize()
        .into()
}
