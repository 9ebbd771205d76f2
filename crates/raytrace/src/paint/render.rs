//! Spectral rendering of the painted plate (paper 07, section 2.3: spectral ray tracing over
//! 380-780 nm in 5 nm steps, aluminium flakes in a dielectric binder under a clear coat, a
//! black base, a lamp of known spectrum).
//!
//! Every surface of the paint is specular (coat, flakes), so a camera ray follows one chain of
//! mirror reflections and refractions; it gathers the lamp's radiance each time it leaves the
//! plate in a direction inside the lamp's disc. The lamp's radiance is constant over its
//! disc, so this test is exact: the only variance is the pixel footprint's sampling. The
//! coat's internal reflection is followed deterministically (the escaping part is gathered,
//! the reflected part continues with its Fresnel weight), the 81 wavelengths travel together
//! (the geometry does not depend on the wavelength) and the flakes' spectral Fresnel factors
//! are evaluated only for the chains that reach the lamp. The radiance factors `n^2` of
//! entering and leaving the coat cancel for such chains.
//!
//! A base with a Lambertian albedo gets the lamp's light through the coat (the refracted
//! disc, shadowed by the flakes) by light sampling, seen by the eye through the same chains;
//! the light that reaches it after flake reflections (caustics) comes from a photon map
//! ([`super::photons`]). The light the base sends back up and the plate reflects down again
//! (the top surface's Fresnel reflection and total internal reflection, the flakes) makes
//! round trips summed in closed form, `B = a E / (1 - a rho)` with `rho` traced through the
//! plate ([`super::photons::base_return`]), so that a white base under a clear coat keeps
//! the energy the coat lets in.

use nalgebra::Vector3;
use num_complex::Complex64;
use rand::Rng;
use rayon::prelude::*;
use wscg_math::image::Image;
use wscg_math::progress::{NoProgress, Progress};
use wscg_math::{Error, Result};

use super::interface::{binder_exit, cross_interface, reflect, refract_horizontal, Crossing};
use super::layers::{DiscLight, Walk};
pub use super::microstructure::{FlakeHit, Microstructure, NoFlakes, Plate};
use super::photons::{base_return, trace_photons, PhotonMap, PhotonParams, BASE_RETURN_RAYS};
use crate::spectral::{
    fresnel_conductor, fresnel_dielectric, tables, xyz_to_rgb, SpectralGrid, XYZ_TO_SRGB,
};
use crate::stereo::{Eye, StereoRig};

/// How colour is carried along a chain.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ColourMode {
    /// 81 wavelengths, 380-780 nm in 5 nm steps (the paper's renderer).
    #[default]
    Spectral,
    /// The non-spectral baseline: three bands at the sRGB primaries' dominant wavelengths
    /// (612, 549, 465 nm) weighted by the lamp's linear sRGB colour, as an RGB renderer
    /// computes. Equal to the spectral render for a grey reflector; it differs where the
    /// flakes' reflectance varies with the wavelength.
    Rgb,
}

/// Wavelengths of the RGB baseline's bands (nm).
pub const RGB_BAND_NM: [f64; 3] = [612.0, 549.0, 465.0];

/// One band of the colour computation: the flakes' relative index there and the band's
/// lamp weight in normalised XYZ.
struct Band {
    rel: Complex64,
    xyz: [f64; 3],
    /// The lamp's normalised spectral radiance in the band (the spectral output's unit).
    rad: f64,
}

/// What a pixel's samples add up: normalised XYZ and, when kept, the radiance per band.
struct Acc<'s> {
    xyz: [f64; 3],
    spectrum: &'s mut [f64],
    /// Per-band scratch space (base irradiance).
    scratch: Vec<f64>,
}

/// The bands of `mode` and the lamp's own luminance, normalised so that a white Lambertian
/// plate under the lamp has `Y = 1`.
fn bands(plate: &Plate, light: &DiscLight, mode: ColourMode) -> (Vec<Band>, f64) {
    let (w, lamp_y, norm) = lamp_weights(light);
    match mode {
        ColourMode::Spectral => {
            let b = w
                .into_iter()
                .enumerate()
                .map(|(i, xyz)| {
                    let l = SpectralGrid::VISIBLE.wavelength(i);
                    Band {
                        rel: plate.relative_index(l),
                        xyz,
                        rad: light.spectrum.at(l) * light.radiance_scale * norm,
                    }
                })
                .collect();
            (b, lamp_y)
        }
        ColourMode::Rgb => {
            let lamp_xyz = w
                .iter()
                .fold([0.0; 3], |a, x| [a[0] + x[0], a[1] + x[1], a[2] + x[2]]);
            let rgb = xyz_to_rgb(lamp_xyz, &XYZ_TO_SRGB);
            let to_xyz = nalgebra::Matrix3::from_fn(|r, c| XYZ_TO_SRGB[r][c])
                .try_inverse()
                .expect("the sRGB matrix is invertible");
            let b = (0..3)
                .map(|k| Band {
                    rel: plate.relative_index(RGB_BAND_NM[k]),
                    xyz: [
                        to_xyz[(0, k)] * rgb[k],
                        to_xyz[(1, k)] * rgb[k],
                        to_xyz[(2, k)] * rgb[k],
                    ],
                    rad: rgb[k],
                })
                .collect();
            (b, lamp_y)
        }
    }
}

/// A rectangle of the plate (mm, plate centre at the origin, y up).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rect {
    /// Left.
    pub x0: f64,
    /// Bottom.
    pub y0: f64,
    /// Right.
    pub x1: f64,
    /// Top.
    pub y1: f64,
}

impl Rect {
    /// The rectangle of size `w x h` centred at `(cx, cy)`.
    pub fn centred(cx: f64, cy: f64, w: f64, h: f64) -> Self {
        Self {
            x0: cx - 0.5 * w,
            y0: cy - 0.5 * h,
            x1: cx + 0.5 * w,
            y1: cy + 0.5 * h,
        }
    }
}

wscg_math::params! {
    /// Rendering parameters.
    #[derive(Clone, Debug, PartialEq)]
    pub struct PaintRenderParams {
        /// Samples per pixel (jittered over the pixel's footprint on the plate), 64.
        pub spp: u32,
        /// Most scattering events (flake reflections, internal reflections) per chain, 8.
        pub max_depth: u32,
        /// Seed of the pixel sampling (the microstructure has its own).
        pub seed: u64,
        /// Part of the plate to render (mm); `None`: the whole plate.
        pub region_mm: Option<Rect>,
        /// Magnification: 1 renders at the rig's screen pixel size (the plate at 1:1 scale on the
        /// study's screen); 4 renders pixels four times smaller.
        pub magnification: f64,
        /// Draw the samples of a pixel independently instead of jittered on a grid (the grid is
        /// used when `spp` is a square number and this is false).
        pub independent_samples: bool,
        /// Spectral (the paper) or the RGB baseline.
        pub colour: ColourMode,
        /// Keep each pixel's radiance per band ([`XyzImage::spectrum`]).
        pub keep_spectrum: bool,
        /// Photon map of the caustics on a diffuse base (used only when the stack's
        /// `base_albedo > 0`; `None` leaves them out).
        pub photons: Option<PhotonParams>,
    }
}

impl Default for PaintRenderParams {
    fn default() -> Self {
        Self {
            spp: 64,
            max_depth: 8,
            seed: 0,
            region_mm: None,
            magnification: 1.0,
            independent_samples: false,
            colour: ColourMode::Spectral,
            keep_spectrum: false,
            photons: Some(PhotonParams::default()),
        }
    }
}

impl PaintRenderParams {
    /// Errors: `spp = 0`, `max_depth` outside `1..=`[`MAX_DEPTH`], a non-positive or
    /// non-finite magnification, an empty or non-finite `region_mm`, invalid `photons` (see
    /// [`PhotonParams::validate`]). Whether the region lies on the plate is checked by
    /// [`render`].
    pub fn validate(&self) -> Result<()> {
        if self.spp == 0 {
            return Err(Error::invalid(
                "spp",
                "at least one sample per pixel is needed, got 0",
            ));
        }
        if !(1..=MAX_DEPTH).contains(&self.max_depth) {
            return Err(Error::invalid(
                "max_depth",
                format!("must lie in 1..={MAX_DEPTH}, got {}", self.max_depth),
            ));
        }
        if !(self.magnification.is_finite() && self.magnification > 0.0) {
            return Err(Error::invalid(
                "magnification",
                format!("must be finite and positive, got {}", self.magnification),
            ));
        }
        if let Some(region) = self.region_mm {
            let ok = [region.x0, region.y0, region.x1, region.y1]
                .iter()
                .all(|v| v.is_finite());
            if !ok || region.x1 <= region.x0 || region.y1 <= region.y0 {
                return Err(Error::invalid("region_mm", format!("{region:?} is empty")));
            }
        }
        if let Some(ps) = &self.photons {
            ps.validate()?;
        }
        Ok(())
    }
}

/// Marks a pixel without a glint in [`XyzImage::flake_id`].
pub const NO_FLAKE: u64 = u64::MAX;

/// A rendered view: CIE XYZ per pixel, normalised so that a perfect white Lambertian plate
/// under the same lamp has `Y = 1`.
#[derive(Clone, Debug, PartialEq)]
pub struct XyzImage {
    /// Width (pixels).
    pub width: usize,
    /// Height (pixels).
    pub height: usize,
    /// `X, Y, Z` per pixel, row-major, top row first.
    pub xyz: Vec<f32>,
    /// Per pixel, the first flake seen glinting directly ([`NO_FLAKE`] if none): a flake whose
    /// single mirror reflection, between entering and leaving the plate, sends the camera
    /// ray into the lamp (no other flake, no internal reflection in the chain).
    pub flake_id: Vec<u64>,
    /// Every flake seen glinting directly in the image, sorted.
    pub glint_ids: Vec<u64>,
    /// Pixel size on the plate (mm).
    pub mm_per_px: f64,
    /// The rendered region (mm).
    pub region: Rect,
    /// Luminance of the lamp itself in the same units (the largest `Y` a pixel can have).
    pub lamp_y: f64,
    /// Wavelengths of the bands of [`XyzImage::spectrum`] (nm); empty unless kept.
    pub bands_nm: Vec<f64>,
    /// Radiance per pixel and band (pixel-major), relative to the lamp's radiance scaled
    /// like XYZ (a white Lambertian plate has the lamp's relative spectrum times
    /// `1 / Y_white`); empty unless [`PaintRenderParams::keep_spectrum`].
    pub spectrum: Vec<f32>,
}

impl XyzImage {
    /// The `Y` channel, a single-channel image.
    pub fn luminance(&self) -> Image<f32> {
        let y = self.xyz.chunks_exact(3).map(|p| p[1]).collect();
        Image::new(self.height, self.width, 1, y).expect("xyz holds 3 values per pixel")
    }

    /// Mean `X, Y, Z` over the image.
    pub fn mean_xyz(&self) -> [f64; 3] {
        let n = (self.width * self.height).max(1) as f64;
        self.xyz.chunks_exact(3).fold([0.0; 3], |a, p| {
            [
                a[0] + p[0] as f64 / n,
                a[1] + p[1] as f64 / n,
                a[2] + p[2] as f64 / n,
            ]
        })
    }

    /// Display sRGB in `[0, 1]` (IEC 61966-2-1 matrix and transfer curve) of the XYZ values
    /// times `exposure`; brighter values clip. The matrix `m` maps XYZ to the display's
    /// linear RGB ([`XYZ_TO_SRGB`], or a display's calibration matrix as in the paper).
    pub fn to_display(&self, exposure: f64, m: &[[f64; 3]; 3]) -> Result<Image<f32>> {
        let data = self
            .xyz
            .chunks_exact(3)
            .flat_map(|p| {
                let rgb = xyz_to_rgb([p[0] as f64, p[1] as f64, p[2] as f64], m);
                rgb.map(|v| crate::spectral::srgb_oetf((v * exposure).clamp(0.0, 1.0)) as f32)
            })
            .collect();
        Image::new(self.height, self.width, 3, data)
    }
}

/// Per-wavelength lamp weights `L(l) cmf(l) dl / Y_white`, the lamp's own `Y`, and the
/// normalisation `1 / Y_white`.
fn lamp_weights(light: &DiscLight) -> (Vec<[f64; 3]>, f64, f64) {
    let step = SpectralGrid::VISIBLE.step_nm;
    let l: Vec<f64> = (0..81)
        .map(|i| light.spectrum.at(SpectralGrid::VISIBLE.wavelength(i)) * light.radiance_scale)
        .collect();
    let y_lamp: f64 = (0..81).map(|i| l[i] * tables::CMF_Y[i] * step).sum();
    let y_white = y_lamp * light.white_factor();
    let norm = if y_white > 0.0 { 1.0 / y_white } else { 1.0 };
    let w = (0..81)
        .map(|i| {
            let s = l[i] * step * norm;
            [
                tables::CMF_X[i] * s,
                tables::CMF_Y[i] * s,
                tables::CMF_Z[i] * s,
            ]
        })
        .collect();
    (w, y_lamp * norm, norm)
}

/// Chain weight (at 560 nm) below which Russian roulette may end a chain: the part of a
/// camera ray reflected back into the plate by the top surface (4 % near normal incidence)
/// is followed only now and then, with a weight that keeps the estimate unbiased.
const ROULETTE_BELOW: f64 = 0.5;

/// One pixel's result: mean XYZ, first directly glinting flake, every directly glinting
/// flake, radiance per band (when kept).
type PixelResult = ([f32; 3], u64, Vec<u64>, Vec<f32>);

/// Most scattering events per chain ([`PaintRenderParams::max_depth`]).
pub const MAX_DEPTH: u32 = 16;

/// One chain's scratch state: the flakes met so far.
struct Chain {
    cosines: [f64; MAX_DEPTH as usize + 1],
    n: usize,
    first_id: Option<u64>,
    /// Internal reflections at the plate's interfaces so far.
    bounces: u32,
    /// Scattering events (flake and internal reflections) so far.
    events: u32,
}

impl Chain {
    /// Counts an internal reflection; false once the chain has more than `max_depth` events.
    fn internal_reflection(&mut self, max_depth: u32) -> bool {
        self.bounces += 1;
        self.events += 1;
        self.events <= max_depth
    }
}

struct Ctx<'a> {
    plate: &'a Plate,
    light: &'a DiscLight,
    bands: Vec<Band>,
    max_depth: u32,
    /// Caustics on a diffuse base.
    caustics: Option<PhotonMap>,
    /// Per band, `1 / (1 - a rho)`: the light's round trips between a diffuse base of albedo
    /// `a` and the plate above it ([`base_return`]); empty for a black base.
    base_boost: Vec<f64>,
    /// Relative index at 560 nm, for the Russian-roulette estimate of a chain's weight.
    mid: Complex64,
}

impl Ctx<'_> {
    /// `weight * sum_l prod_k R(cos_k, l) lamp(l)`.
    fn gather(&self, chain: &Chain, weight: f64, out: &mut Acc) {
        if weight != 0.0 {
            self.gather_bands(chain, weight, None, out);
        }
    }

    /// [`Ctx::gather`] with an extra factor per band.
    fn gather_bands(&self, chain: &Chain, weight: f64, per_band: Option<&[f64]>, out: &mut Acc) {
        for (k, b) in self.bands.iter().enumerate() {
            let mut t = weight * per_band.map_or(1.0, |f| f[k]);
            for &c in &chain.cosines[..chain.n] {
                t *= fresnel_conductor(c, b.rel.re, b.rel.im);
            }
            for (o, x) in out.xyz.iter_mut().zip(&b.xyz) {
                *o += t * x;
            }
            if let Some(sp) = out.spectrum.get_mut(k) {
                *sp += t * b.rad;
            }
        }
    }

    /// Adds to `out` the radiance along one camera ray entering the plate at `(x, y)` (µm)
    /// with direction `d` (plate frame, going down); returns the flake glinting directly.
    fn trace(
        &self,
        x: f64,
        y: f64,
        d: Vector3<f64>,
        rng: &mut impl Rng,
        out: &mut Acc,
    ) -> Option<u64> {
        let st = &self.plate.stack;
        let mut glint: Option<u64> = None;
        let mut chain = Chain {
            cosines: [0.0; MAX_DEPTH as usize + 1],
            n: 0,
            first_id: None,
            bounces: 0,
            events: 0,
        };
        let Walk {
            n_top,
            nb,
            t_bind,
            coat,
            z_top,
            sigma,
        } = st.walk();
        // Top surface: specular reflection of the lamp, then refraction into the plate.
        let cos_i = -d.z;
        let f = if n_top > 1.0 {
            fresnel_dielectric(cos_i, n_top)
        } else {
            0.0
        };
        if f > 0.0 && self.light.contains([d.x, d.y, -d.z]) {
            self.gather(&chain, f, out);
        }
        let mut w = 1.0 - f;
        let mut dir = refract_horizontal(&d, 1.0, n_top)?;
        let mut pos = Vector3::new(x, y, z_top);
        let mut proxy = 1.0;
        loop {
            // Through the coat (no flakes) down to the binder, or up to the top surface.
            if pos.z > t_bind && dir.z < 0.0 {
                let t = (pos.z - t_bind) / -dir.z;
                pos += dir * t;
                pos.z = t_bind;
                match cross_interface(&mut dir, n_top, nb, rng) {
                    Crossing::Reflected if chain.internal_reflection(self.max_depth) => continue,
                    Crossing::Refracted => {}
                    _ => break,
                }
            }
            if pos.z >= z_top - 1e-9 && dir.z > 0.0 {
                // Leaving through the top: gather if the escaping direction meets the lamp.
                let ft = fresnel_dielectric(dir.z, 1.0 / n_top);
                if ft < 1.0 {
                    if let Some(out_dir) = refract_horizontal(&dir, n_top, 1.0) {
                        if self.light.contains(out_dir.into()) {
                            self.gather(&chain, w * (1.0 - ft), out);
                            if glint.is_none() && chain.n == 1 && chain.bounces == 0 {
                                glint = chain.first_id;
                            }
                        }
                    }
                }
                if n_top == 1.0 {
                    break;
                }
                w *= ft;
                dir.z = -dir.z;
                if !chain.internal_reflection(self.max_depth) {
                    break;
                }
            } else if pos.z > t_bind + 1e-9 && dir.z > 0.0 {
                // In the coat going up.
                let t = (z_top - pos.z) / dir.z;
                pos += dir * t;
                pos.z = z_top;
                continue;
            } else {
                // In the binder: the nearest flake, else the base or the binder's top.
                let t_exit = binder_exit(pos.z, dir.z, t_bind);
                match self.plate.hit(pos.into(), dir.into(), t_exit) {
                    Some(h) => {
                        let normal = Vector3::from(h.normal);
                        pos += dir * h.t;
                        w *= (-sigma * h.t).exp();
                        let c = dir.dot(&normal).abs();
                        if chain.n < chain.cosines.len() {
                            chain.cosines[chain.n] = c;
                            chain.n += 1;
                        }
                        if chain.first_id.is_none() {
                            chain.first_id = Some(h.id);
                        }
                        proxy *= fresnel_conductor(c, self.mid.re, self.mid.im);
                        dir = reflect(&dir, &normal);
                        chain.events += 1;
                        if chain.events > self.max_depth {
                            break;
                        }
                    }
                    None => {
                        pos += dir * t_exit;
                        w *= (-sigma * t_exit).exp();
                        if dir.z < 0.0 {
                            pos.z = 0.0;
                            if st.base_albedo > 0.0 {
                                self.gather_base(&chain, w, &pos, rng, out);
                            }
                            break;
                        }
                        pos.z = t_bind;
                        // Binder to coat.
                        match cross_interface(&mut dir, nb, n_top, rng) {
                            Crossing::Reflected if chain.internal_reflection(self.max_depth) => {
                                continue
                            }
                            Crossing::Refracted => {}
                            _ => break,
                        }
                        if coat == 0.0 {
                            pos.z = z_top;
                        } else {
                            pos.z = t_bind + 1e-7;
                        }
                    }
                }
            }
            // Russian roulette on weak chains (unbiased: survivors carry 1 / q).
            let tw = w * proxy;
            if tw < ROULETTE_BELOW {
                let q = (tw / ROULETTE_BELOW).max(0.05);
                if rng.random::<f64>() >= q {
                    break;
                }
                w /= q;
            }
        }
        glint
    }

    /// Adds the base's radiance seen by `chain` (weight `w`) at base point `p`: the direct
    /// light by light sampling, plus the caustics from the photon map when there is one,
    /// times the round trips of the light between the base and the plate above it (the
    /// light the base sends up and the top surface or the flakes reflect back down: without
    /// them a white base under a coat of index 1.5 renders at `Y = 0.41`).
    fn gather_base(
        &self,
        chain: &Chain,
        w: f64,
        p: &Vector3<f64>,
        rng: &mut impl Rng,
        out: &mut Acc,
    ) {
        let (direct, _) = self.base_direct(p, rng);
        let mut e = std::mem::take(&mut out.scratch);
        e.resize(self.bands.len(), 0.0);
        if let Some(map) = &self.caustics {
            map.band_irradiance(p.x, p.y, &mut e);
        } else {
            e.iter_mut().for_each(|v| *v = 0.0);
        }
        let st = &self.plate.stack;
        let to_radiance = st.base_albedo / std::f64::consts::PI / (st.binder_ior * st.binder_ior);
        for (v, b) in e.iter_mut().zip(&self.base_boost) {
            *v = (direct + to_radiance * *v) * b;
        }
        self.gather_bands(chain, w, Some(&e), out);
        out.scratch = e;
    }

    /// Light sampling of the lamp from a base point (µm): the achromatic factor of
    /// `albedo / pi * E / n_base^2`, where `E` is the irradiance through the top surface
    /// (and the coat-binder interface), shadowed by the flakes; one direction of the lamp's
    /// disc, uniformly.
    fn base_direct(&self, p: &Vector3<f64>, rng: &mut impl Rng) -> (f64, bool) {
        let st = &self.plate.stack;
        let light = self.light;
        let omega = light.solid_angle();
        let wdir = Vector3::from(light.sample_direction(rng.random(), rng.random()));
        if wdir.z <= 0.0 {
            return (0.0, false);
        }
        let n_top = st.top_ior();
        let nb = st.binder_ior;
        let mut tr = 1.0;
        if n_top > 1.0 {
            tr *= 1.0 - fresnel_dielectric(wdir.z, n_top);
        }
        // Direction towards the lamp inside the coat and the binder (Snell invariant).
        let Some(in_coat) = refract_horizontal(&wdir, 1.0, n_top) else {
            return (0.0, false);
        };
        if n_top != nb {
            tr *= 1.0 - fresnel_dielectric(in_coat.z, nb / n_top);
        }
        let Some(in_binder) = refract_horizontal(&wdir, 1.0, nb) else {
            return (0.0, false);
        };
        let t_exit = st.binder_um / in_binder.z;
        if self
            .plate
            .hit((*p).into(), in_binder.into(), t_exit)
            .is_some()
        {
            return (0.0, true);
        }
        let sigma = st.binder_sigma_a_per_mm * 1e-3;
        tr *= (-sigma * t_exit).exp();
        let e = omega * wdir.z * tr;
        (st.base_albedo / std::f64::consts::PI * e / (nb * nb), false)
    }
}

/// Renders `plate` under `light` for one eye of `rig`: the region's pixels (the rig's screen
/// pixels divided by the magnification) each take `spp` jittered rays from the eye through
/// their footprint on the plate, which lies in the zero-parallax plane at 1:1 scale. Pixels
/// are computed in parallel with a random stream per pixel, so the image does not depend on
/// the thread count.
///
/// Errors: invalid parameters (see [`PaintRenderParams::validate`]), lamp or rig, a region
/// outside the plate.
pub fn render(
    plate: &Plate,
    light: &DiscLight,
    rig: &StereoRig,
    eye: Eye,
    s: &PaintRenderParams,
) -> Result<XyzImage> {
    render_with_progress(plate, light, rig, eye, s, &NoProgress)
}

/// The photon map of the caustics on the base for rendering `region` (mm), with the
/// bands' flux evaluated: none with a black base or without photon settings. Photons are
/// shot over the region widened by the margin, within the plate.
fn caustic_map(
    plate: &Plate,
    light: &DiscLight,
    region: Rect,
    s: &PaintRenderParams,
    bands: &[Band],
) -> Result<Option<PhotonMap>> {
    let Some(ps) = s.photons.filter(|_| plate.stack.base_albedo > 0.0) else {
        return Ok(None);
    };
    let m = ps.margin_um;
    let (pw, ph) = plate.stack.size_mm;
    let half = [500.0 * pw, 500.0 * ph];
    let area = [
        (region.x0 * 1e3 - m).max(-half[0]),
        (region.y0 * 1e3 - m).max(-half[1]),
        (region.x1 * 1e3 + m).min(half[0]),
        (region.y1 * 1e3 + m).min(half[1]),
    ];
    let mut map = trace_photons(plate, light, area, &ps, true)?;
    let rel: Vec<Complex64> = bands.iter().map(|b| b.rel).collect();
    map.set_bands(&rel);
    Ok(Some(map))
}

/// Per band, `1 / (1 - a rho)` for a diffuse base of albedo `a` under the plate: the sum of
/// the light's round trips between the base and the plate (`rho` from [`base_return`] over
/// `region`, mm); empty for a black base.
fn base_round_trips(plate: &Plate, region: Rect, seed: u64, bands: &[Band]) -> Result<Vec<f64>> {
    let a = plate.stack.base_albedo;
    if a == 0.0 {
        return Ok(Vec::new());
    }
    let rel: Vec<Complex64> = bands.iter().map(|b| b.rel).collect();
    let area = [region.x0, region.y0, region.x1, region.y1].map(|v| v * 1e3);
    let rho = base_return(plate, &rel, area, BASE_RETURN_RAYS, seed)?;
    Ok(rho
        .into_iter()
        .map(|r| 1.0 / (1.0 - a * r).max(1e-6))
        .collect())
}

/// [`render`], reporting the rows done to `progress`.
pub fn render_with_progress(
    plate: &Plate,
    light: &DiscLight,
    rig: &StereoRig,
    eye: Eye,
    s: &PaintRenderParams,
    progress: &dyn Progress,
) -> Result<XyzImage> {
    s.validate()?;
    light.validate()?;
    rig.validate()?;
    let (pw, ph) = plate.stack.size_mm;
    let full = Rect::centred(0.0, 0.0, pw, ph);
    let region = s.region_mm.unwrap_or(full);
    let eps = 1e-9;
    if region.x0 < full.x0 - eps
        || region.x1 > full.x1 + eps
        || region.y0 < full.y0 - eps
        || region.y1 > full.y1 + eps
    {
        return Err(Error::invalid(
            "region_mm",
            format!("{region:?} leaves the {pw} x {ph} mm plate"),
        ));
    }
    let pitch = rig.pixel_pitch_m().0 * 1e3 / s.magnification;
    let width = ((region.x1 - region.x0) / pitch).round().max(1.0) as usize;
    let height = ((region.y1 - region.y0) / pitch).round().max(1.0) as usize;
    let (bands, lamp_y) = bands(plate, light, s.colour);
    let n_bands = bands.len();
    let band_nm: Vec<f64> = match s.colour {
        ColourMode::Spectral => SpectralGrid::VISIBLE.wavelengths().collect(),
        ColourMode::Rgb => RGB_BAND_NM.to_vec(),
    };
    let caustics = caustic_map(plate, light, region, s, &bands)?;
    let base_boost = base_round_trips(plate, region, s.seed, &bands)?;
    let ctx = Ctx {
        plate,
        light,
        bands,
        max_depth: s.max_depth,
        caustics,
        base_boost,
        mid: plate.relative_index(560.0),
    };
    let e = Vector3::from(rig.eye(eye));
    let a = rig.dist_m;
    let (px_w, px_h) = (
        (region.x1 - region.x0) / width as f64,
        (region.y1 - region.y0) / height as f64,
    );
    let side = (s.spp as f64).sqrt().round() as u32;
    let stratified = side * side == s.spp && !s.independent_samples;
    progress.begin("rendering rows", height as u64);
    let pixel = |idx: usize| {
        let (i, j) = (idx % width, idx / width);
        let mut rng = wscg_math::rng::stream(s.seed, idx as u64);
        let mut spectrum = vec![0.0f64; if s.keep_spectrum { n_bands } else { 0 }];
        let mut acc = Acc {
            xyz: [0.0; 3],
            spectrum: &mut spectrum,
            scratch: Vec::new(),
        };
        let mut first = NO_FLAKE;
        let mut ids = Vec::new();
        for k in 0..s.spp {
            if k % 1024 == 1023 {
                // A huge sample count stays interruptible (the caller reports it) and keeps
                // its flake list bounded by the distinct flakes seen.
                if wscg_math::cancel::requested() {
                    break;
                }
                if ids.len() > 1 << 16 {
                    ids.sort_unstable();
                    ids.dedup();
                }
            }
            let (u, v) = if stratified {
                (
                    ((k % side) as f64 + rng.random::<f64>()) / side as f64,
                    ((k / side) as f64 + rng.random::<f64>()) / side as f64,
                )
            } else {
                (rng.random::<f64>(), rng.random::<f64>())
            };
            let x_mm = region.x0 + (i as f64 + u) * px_w;
            let y_mm = region.y1 - (j as f64 + v) * px_h;
            let p = Vector3::new(x_mm * 1e-3, y_mm * 1e-3, a);
            let de = (p - e).normalize();
            let d = Vector3::new(de.x, de.y, -de.z);
            if let Some(id) = ctx.trace(x_mm * 1e3, y_mm * 1e3, d, &mut rng, &mut acc) {
                if first == NO_FLAKE {
                    first = id;
                }
                ids.push(id);
            }
        }
        ids.sort_unstable();
        ids.dedup();
        let n = s.spp as f64;
        let xyz = acc.xyz.map(|v| (v / n) as f32);
        let spectrum = spectrum.iter().map(|v| (v / n) as f32).collect();
        (xyz, first, ids, spectrum)
    };
    let rows: Vec<Vec<PixelResult>> = (0..height)
        .into_par_iter()
        .map(|j| {
            if wscg_math::cancel::requested() {
                return Vec::new();
            }
            let row = (j * width..(j + 1) * width).map(pixel).collect();
            progress.advance(1);
            row
        })
        .collect();
    progress.finish();
    wscg_math::cancel::check()?;
    let pixels = rows.into_iter().flatten();
    let mut xyz = Vec::with_capacity(3 * width * height);
    let mut flake_id = Vec::with_capacity(width * height);
    let mut glint_ids = Vec::new();
    let mut spectrum = Vec::with_capacity(if s.keep_spectrum {
        n_bands * width * height
    } else {
        0
    });
    for (c, f, ids, sp) in pixels {
        xyz.extend_from_slice(&c);
        flake_id.push(f);
        glint_ids.extend(ids);
        spectrum.extend(sp);
    }
    glint_ids.sort_unstable();
    glint_ids.dedup();
    Ok(XyzImage {
        width,
        height,
        xyz,
        flake_id,
        glint_ids,
        mm_per_px: px_w,
        region,
        lamp_y,
        bands_nm: if s.keep_spectrum { band_nm } else { Vec::new() },
        spectrum,
    })
}
