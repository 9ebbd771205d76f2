//! Photon mapping of the plate's base (paper 07, section 2.3: "raytracing with photon
//! mapping"; Jensen 1996). With the paper's black base nothing reaches the eye this way;
//! with a diffuse base (`base_albedo > 0`) the lamp's light also arrives at the base after
//! mirror reflections on the flakes (caustics), which light sampling from the base cannot
//! find through specular surfaces. Photons are shot from the lamp through the coat over the
//! rendered area, followed through the flakes and interfaces, and those that reach the base
//! after at least one flake are stored; a camera chain that reaches the base adds the
//! density estimate of its `k` nearest photons, while the direct light (no flake on the way)
//! stays with light sampling.
//!
//! Flux units: a photon carries `cos * solid angle * area / N` (µm²) of the lamp's radiance,
//! times its Fresnel transmissions and the binder's absorption, so that the flux per µm²
//! of the base is its irradiance per unit lamp radiance. The flakes' spectral reflectances
//! are kept as the incidence cosines of the photon's flake hits and evaluated per band once
//! the renderer's bands are known ([`PhotonMap::set_bands`]).

use nalgebra::Vector3;
use num_complex::Complex64;
use rand::Rng;
use rayon::prelude::*;
use wscg_math::knn::KdTree;
use wscg_math::{Error, Result};

use super::interface::{binder_exit, cross_interface, reflect, refract_horizontal, Crossing};
use super::layers::{DiscLight, Walk};
use super::microstructure::Plate;
use crate::spectral::{fresnel_conductor, fresnel_dielectric};

/// Most flake reflections a stored photon remembers; longer paths are dropped (their flux
/// is below `R^5`, under 0.1 % of the caustics for aluminium).
pub const PHOTON_FLAKES: usize = 4;

/// Most scattering events followed per photon.
const MAX_EVENTS: usize = 32;

wscg_math::params! {
    /// Photon-mapping parameters.
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct PhotonParams {
        /// Photons shot from the lamp over the rendered area (2 000 000).
        pub count: usize,
        /// Photons in a density estimate (50).
        pub k: usize,
        /// Largest gather radius (µm, 250): photons farther away are not used.
        pub max_radius_um: f64,
        /// How far around the rendered region photons are shot (µm, 1500): light entering there
        /// can reach the region's base after travelling sideways in the plate.
        pub margin_um: f64,
        /// Seed of the photon paths.
        pub seed: u64,
    }
}

impl Default for PhotonParams {
    fn default() -> Self {
        Self {
            count: 2_000_000,
            k: 50,
            max_radius_um: 250.0,
            margin_um: 1500.0,
            seed: 0,
        }
    }
}

impl PhotonParams {
    /// Errors: no photons, more than 500 million, `k = 0`, a non-positive radius, a negative
    /// margin.
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [("count", self.count), ("k", self.k)] {
            if v == 0 {
                return Err(Error::invalid(name, "must be at least 1, got 0"));
            }
        }
        if self.count > 500_000_000 {
            return Err(Error::LimitExceeded(format!(
                "{} photons (at most 500 million)",
                self.count
            )));
        }
        wscg_math::error::ensure_positive("max_radius_um", self.max_radius_um)?;
        if !(self.margin_um.is_finite() && self.margin_um >= 0.0) {
            return Err(Error::invalid(
                "margin_um",
                format!("must be finite and >= 0, got {}", self.margin_um),
            ));
        }
        Ok(())
    }
}

/// A photon stored on the base.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Photon {
    /// Position on the base (µm, plate frame).
    pub x: f64,
    /// Position on the base (µm, plate frame).
    pub y: f64,
    /// Achromatic flux (see the module documentation).
    pub flux: f64,
    /// Incidence cosines of its flake reflections.
    pub cosines: [f32; PHOTON_FLAKES],
    /// Number of valid entries in `cosines`.
    pub n: u8,
}

/// The photons on the base and their 2-D search tree.
pub struct PhotonMap {
    /// The stored photons.
    pub photons: Vec<Photon>,
    /// Photons shot.
    pub shot: usize,
    tree: Option<KdTree>,
    /// Per photon and band: flux times the product of its flakes' reflectances.
    band_flux: Vec<f32>,
    n_bands: usize,
    /// Gathering parameters.
    pub settings: PhotonParams,
}

impl PhotonMap {
    /// The indices of the `k` nearest photons of `(x, y)` within the largest radius and the
    /// radius of the disc they fill (µm): the largest radius when fewer than `k` lie in it.
    pub fn nearest(&self, x: f64, y: f64) -> (Vec<usize>, f64) {
        let Some(tree) = &self.tree else {
            return (Vec::new(), self.settings.max_radius_um);
        };
        let mut found = tree.knn(&[x, y, 0.0], self.settings.k, None);
        found.retain(|&(_, d)| d <= self.settings.max_radius_um);
        let r = if found.len() < self.settings.k {
            self.settings.max_radius_um
        } else {
            found.last().map_or(0.0, |&(_, d)| d)
        };
        (found.into_iter().map(|(i, _)| i).collect(), r)
    }

    /// Achromatic irradiance estimate at `(x, y)` (per unit lamp radiance): the flux of the
    /// nearest photons over the area of their disc, the flakes' reflectances left out.
    pub fn irradiance(&self, x: f64, y: f64) -> f64 {
        let (idx, r) = self.nearest(x, y);
        idx.iter().map(|&i| self.photons[i].flux).sum::<f64>() / (std::f64::consts::PI * r * r)
    }

    /// Evaluates each photon's flux per band: the flakes' relative indices per band.
    pub fn set_bands(&mut self, rel: &[Complex64]) {
        self.n_bands = rel.len();
        self.band_flux = self
            .photons
            .par_iter()
            .flat_map_iter(|p| {
                rel.iter().map(move |r| {
                    let f = p.cosines[..p.n as usize]
                        .iter()
                        .fold(p.flux, |a, &c| a * fresnel_conductor(c as f64, r.re, r.im));
                    f as f32
                })
            })
            .collect();
    }

    /// Irradiance per band at `(x, y)` into `out` (one entry per band of
    /// [`PhotonMap::set_bands`]); false when no photon is near.
    pub fn band_irradiance(&self, x: f64, y: f64, out: &mut [f64]) -> bool {
        out.iter_mut().for_each(|o| *o = 0.0);
        let (idx, r) = self.nearest(x, y);
        if idx.is_empty() || self.n_bands != out.len() {
            return false;
        }
        let inv_area = 1.0 / (std::f64::consts::PI * r * r);
        for i in idx {
            let f = &self.band_flux[i * self.n_bands..(i + 1) * self.n_bands];
            for (o, v) in out.iter_mut().zip(f) {
                *o += *v as f64 * inv_area;
            }
        }
        true
    }
}

/// Shoots `settings.count` photons from `light` onto the rectangle `[x0, x1] x [y0, y1]` (µm,
/// plate frame) of the top surface and keeps those that reach the base: after at least one
/// flake (`caustic_only`), or all of them.
///
/// Errors: an empty area, invalid settings or lamp.
pub fn trace_photons(
    plate: &Plate,
    light: &DiscLight,
    area_um: [f64; 4],
    settings: &PhotonParams,
    caustic_only: bool,
) -> Result<PhotonMap> {
    light.validate()?;
    settings.validate()?;
    let [x0, y0, x1, y1] = area_um;
    let (w, h) = (x1 - x0, y1 - y0);
    if !(w > 0.0 && h > 0.0 && w.is_finite() && h.is_finite()) {
        return Err(Error::invalid("area", format!("{area_um:?} is empty")));
    }
    let n = settings.count;
    let base = light.solid_angle() * w * h / n as f64;
    const BLOCK: usize = 4096;
    let photons: Vec<Photon> = (0..n.div_ceil(BLOCK))
        .into_par_iter()
        .flat_map_iter(|b| {
            let mut rng = wscg_math::rng::stream(settings.seed, b as u64);
            let mut out = Vec::new();
            for _ in b * BLOCK..((b + 1) * BLOCK).min(n) {
                let x = x0 + rng.random::<f64>() * w;
                let y = y0 + rng.random::<f64>() * h;
                let to_lamp = Vector3::from(light.sample_direction(rng.random(), rng.random()));
                if to_lamp.z <= 0.0 {
                    continue;
                }
                if let Some(p) = follow(plate, x, y, -to_lamp, base * to_lamp.z, &mut rng) {
                    if p.n > 0 || !caustic_only {
                        out.push(p);
                    }
                }
            }
            out.into_iter()
        })
        .collect();
    let tree = if photons.is_empty() {
        None
    } else {
        let pts: Vec<[f64; 3]> = photons.iter().map(|p| [p.x, p.y, 0.0]).collect();
        Some(KdTree::new(&pts)?)
    };
    Ok(PhotonMap {
        photons,
        shot: n,
        tree,
        band_flux: Vec::new(),
        n_bands: 0,
        settings: *settings,
    })
}

/// Follows one photon arriving at the top surface at `(x, y)` (µm) with direction `d`
/// (going down) and flux `flux`; the photon where it reaches the base, if it does. The
/// part reflected by the top surface on entry is not followed; inside, every interface
/// reflects or transmits with the Fresnel probability.
fn follow(
    plate: &Plate,
    x: f64,
    y: f64,
    d: Vector3<f64>,
    flux: f64,
    rng: &mut impl Rng,
) -> Option<Photon> {
    let Walk {
        n_top,
        nb,
        t_bind,
        coat,
        z_top,
        sigma,
    } = plate.stack.walk();
    let mut ph = Photon {
        x,
        y,
        flux: flux * (1.0 - fresnel_dielectric(-d.z, n_top)),
        cosines: [0.0; PHOTON_FLAKES],
        n: 0,
    };
    let mut dir = refract_horizontal(&d, 1.0, n_top)?;
    let mut pos = Vector3::new(x, y, z_top);
    let mut in_coat = coat > 0.0;
    for _ in 0..MAX_EVENTS {
        if in_coat {
            // Crossing the coat: down to the binder or up to the top surface.
            let (z, n_other) = if dir.z < 0.0 {
                (t_bind, nb)
            } else {
                (z_top, 1.0)
            };
            pos += dir * ((z - pos.z) / dir.z);
            pos.z = z;
            match cross_interface(&mut dir, n_top, n_other, rng) {
                Crossing::Reflected => {}
                Crossing::Refracted if n_other == nb => in_coat = false,
                _ => return None,
            }
            continue;
        }
        let t_exit = binder_exit(pos.z, dir.z, t_bind);
        if let Some(h) = plate.hit(pos.into(), dir.into(), t_exit) {
            let normal = Vector3::from(h.normal);
            pos += dir * h.t;
            ph.flux *= (-sigma * h.t).exp();
            if ph.n as usize == PHOTON_FLAKES {
                return None;
            }
            ph.cosines[ph.n as usize] = dir.dot(&normal).abs() as f32;
            ph.n += 1;
            dir = reflect(&dir, &normal);
            continue;
        }
        pos += dir * t_exit;
        ph.flux *= (-sigma * t_exit).exp();
        if dir.z < 0.0 {
            ph.x = pos.x;
            ph.y = pos.y;
            return Some(ph);
        }
        pos.z = t_bind;
        let n_other = if coat > 0.0 { n_top } else { 1.0 };
        match cross_interface(&mut dir, nb, n_other, rng) {
            Crossing::Reflected => {}
            Crossing::Refracted if coat > 0.0 => in_coat = true,
            _ => return None,
        }
    }
    None
}

/// Rays traced from the base by [`base_return`] in the renderer (a 256 x 256 grid of
/// jittered cosine-weighted directions).
pub const BASE_RETURN_RAYS: usize = 65_536;

/// Most flake reflections a ray of [`base_return`] remembers; longer paths are dropped.
const RETURN_FLAKES: usize = 8;

/// The fraction of the light leaving a Lambertian base that the plate sends back down to the
/// base, per band: `rho = E[prod R]` over cosine-weighted rays leaving the base at random
/// points of `area_um` (µm, plate frame), reflected by the flakes (their relative indices
/// `rel` per band), by the coat-binder interface and by the top surface (Fresnel, total
/// internal reflection beyond the critical angle), absorbed by the binder.
///
/// A base of albedo `a` under the plate then has the radiosity `B = a E / (1 - a rho)` for
/// the irradiance `E` arriving from the lamp (the sum of the light's round trips between the
/// base and the plate: Kubelka-Munk's multiple reflection, or Saunderson's correction; paper
/// 07's black base has `a = 0`). Without flakes and with one interface of relative index
/// `n`, `rho` is the hemispherical (diffuse) Fresnel reflectance seen from inside,
/// `F_dr,in = 1 - (1 - F_dr,out) / n^2`: 0.596 at n = 1.5. The directions are stratified,
/// so that estimate converges quickly; `rays` are rounded up to a square grid.
///
/// Errors: an empty area, no rays.
pub fn base_return(
    plate: &Plate,
    rel: &[Complex64],
    area_um: [f64; 4],
    rays: usize,
    seed: u64,
) -> Result<Vec<f64>> {
    let [x0, y0, x1, y1] = area_um;
    let (w, h) = (x1 - x0, y1 - y0);
    if !(w > 0.0 && h > 0.0 && w.is_finite() && h.is_finite()) {
        return Err(Error::invalid("area", format!("{area_um:?} is empty")));
    }
    if rays == 0 {
        return Err(Error::invalid("rays", "must be at least 1, got 0"));
    }
    let side = (rays as f64).sqrt().ceil() as usize;
    let n = (side * side) as f64;
    let sums = (0..side)
        .into_par_iter()
        .map(|i| {
            let mut rng = wscg_math::rng::stream(seed, i as u64);
            let mut acc = vec![0.0; rel.len()];
            for j in 0..side {
                // Cosine-weighted: sin^2(theta) uniform in the stratum.
                let s2 = (i as f64 + rng.random::<f64>()) / side as f64;
                let phi =
                    2.0 * std::f64::consts::PI * (j as f64 + rng.random::<f64>()) / side as f64;
                let s = s2.sqrt();
                let dir = Vector3::new(s * phi.cos(), s * phi.sin(), (1.0 - s2).max(0.0).sqrt());
                let x = x0 + rng.random::<f64>() * w;
                let y = y0 + rng.random::<f64>() * h;
                let Some((wt, cosines, k)) = follow_up(plate, x, y, dir, &mut rng) else {
                    continue;
                };
                for (a, r) in acc.iter_mut().zip(rel) {
                    *a += cosines[..k]
                        .iter()
                        .fold(wt, |v, &c| v * fresnel_conductor(c, r.re, r.im));
                }
            }
            acc
        })
        .reduce(
            || vec![0.0; rel.len()],
            |mut a, b| {
                a.iter_mut().zip(&b).for_each(|(x, y)| *x += y);
                a
            },
        );
    Ok(sums.into_iter().map(|v| v / n).collect())
}

/// Follows a ray leaving the base at `(x, y)` with direction `dir` (going up) until it comes
/// back down to the base: its weight (the top surface's Fresnel reflectances, the binder's
/// absorption; the coat-binder interface chosen with its Fresnel probability) and the
/// incidence cosines of its flake reflections. `None` when it leaves the plate.
fn follow_up(
    plate: &Plate,
    x: f64,
    y: f64,
    mut dir: Vector3<f64>,
    rng: &mut impl Rng,
) -> Option<(f64, [f64; RETURN_FLAKES], usize)> {
    let Walk {
        n_top,
        nb,
        t_bind,
        coat,
        z_top,
        sigma,
    } = plate.stack.walk();
    let mut pos = Vector3::new(x, y, 0.0);
    let mut w = 1.0;
    let mut cosines = [0.0; RETURN_FLAKES];
    let mut k = 0;
    let mut in_coat = false;
    for _ in 0..MAX_EVENTS {
        if in_coat {
            if dir.z > 0.0 {
                // Up to the top surface: the reflected part comes back down.
                pos += dir * ((z_top - pos.z) / dir.z);
                pos.z = z_top;
                w *= fresnel_dielectric(dir.z, 1.0 / n_top);
                dir.z = -dir.z;
                if w == 0.0 {
                    return None;
                }
                continue;
            }
            pos += dir * ((t_bind - pos.z) / dir.z);
            pos.z = t_bind;
            match cross_interface(&mut dir, n_top, nb, rng) {
                Crossing::Reflected => {}
                Crossing::Refracted => in_coat = false,
                Crossing::Lost => return None,
            }
            continue;
        }
        let t_exit = binder_exit(pos.z, dir.z, t_bind);
        if let Some(hit) = plate.hit(pos.into(), dir.into(), t_exit) {
            let normal = Vector3::from(hit.normal);
            pos += dir * hit.t;
            w *= (-sigma * hit.t).exp();
            if k == RETURN_FLAKES {
                return None;
            }
            cosines[k] = dir.dot(&normal).abs();
            k += 1;
            dir = reflect(&dir, &normal);
            continue;
        }
        pos += dir * t_exit;
        w *= (-sigma * t_exit).exp();
        if dir.z < 0.0 {
            return Some((w, cosines, k));
        }
        pos.z = t_bind;
        if coat == 0.0 {
            // The binder meets the air.
            if nb == 1.0 {
                return None;
            }
            w *= fresnel_dielectric(dir.z, 1.0 / nb);
            dir.z = -dir.z;
            continue;
        }
        match cross_interface(&mut dir, nb, n_top, rng) {
            Crossing::Reflected => {}
            Crossing::Refracted => in_coat = true,
            Crossing::Lost => return None,
        }
    }
    None
}
