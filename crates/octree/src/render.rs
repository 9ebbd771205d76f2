//! The renderer of the paper's timings (§5, Table 3): one primary ray per pixel, Phong
//! shading with one point light and one shadow ray, in any [`TraceMode`].

use std::time::Instant;

use rayon::prelude::*;
use wscg_math::{Error, Image, Result};

use crate::octree::HybridOctree;
use crate::traverse::{cross, dot, Footprint, Hit, HitKind, Ray, TraceMode};

/// A pinhole camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position.
    pub eye: [f32; 3],
    /// Point looked at.
    pub target: [f32; 3],
    /// Up direction (need not be orthogonal to the view direction).
    pub up: [f32; 3],
    /// Vertical field of view in degrees.
    pub fov_y_deg: f32,
    /// Image width in pixels.
    pub width: usize,
    /// Image height in pixels.
    pub height: usize,
}

fn sub(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn unit(a: [f32; 3]) -> [f32; 3] {
    let l = dot(a, a).sqrt();
    a.map(|x| x / l)
}

/// The camera's orthonormal frame `(right, up, forward)`.
type Frame = ([f32; 3], [f32; 3], [f32; 3]);

impl Camera {
    /// Checks the camera and returns its frame.
    pub fn frame(&self) -> Result<Frame> {
        let vals = self.eye.iter().chain(&self.target).chain(&self.up);
        if vals.clone().any(|v| !v.is_finite()) {
            return Err(Error::invalid(
                "camera",
                "eye, target and up must be finite",
            ));
        }
        if !(self.fov_y_deg > 0.0 && self.fov_y_deg < 180.0) {
            return Err(Error::invalid(
                "fov_y_deg",
                format!("must be in (0, 180), got {}", self.fov_y_deg),
            ));
        }
        if self.width == 0 || self.height == 0 || self.width * self.height > 1 << 28 {
            return Err(Error::invalid(
                "camera",
                format!(
                    "image size {}x{} must be positive and at most 2^28 pixels",
                    self.width, self.height
                ),
            ));
        }
        let f = sub(self.target, self.eye);
        let r = cross(f, self.up);
        if dot(f, f) == 0.0 || dot(r, r) <= 1e-12 * dot(f, f) * dot(self.up, self.up) {
            return Err(Error::invalid(
                "camera",
                "target must differ from eye and up must not be parallel to the view direction",
            ));
        }
        let fw = unit(f);
        let rt = unit(r);
        Ok((rt, cross(rt, fw), fw))
    }

    /// Primary ray through the centre of pixel `(x, y)` (row 0 at the top), unit direction.
    pub fn ray(&self, frame: &Frame, x: usize, y: usize) -> Ray {
        self.ray_gen(frame).ray(x, y)
    }

    /// The per-camera constants of [`Camera::ray`], for generating many rays.
    pub fn ray_gen(&self, frame: &Frame) -> RayGen {
        let (r, u, f) = frame;
        let h = (0.5 * self.fov_y_deg.to_radians()).tan();
        let aspect = self.width as f32 / self.height as f32;
        let dx: [f32; 3] = std::array::from_fn(|k| 2.0 * h * aspect / self.width as f32 * r[k]);
        let dy: [f32; 3] = std::array::from_fn(|k| -2.0 * h / self.height as f32 * u[k]);
        // Direction through the top-left corner of the image plane at distance 1.
        let corner = std::array::from_fn(|k| f[k] - h * aspect * r[k] + h * u[k]);
        RayGen {
            eye: self.eye,
            corner,
            dx,
            dy,
        }
    }

    /// The pixels whose primary rays can enter `cube`, as half-open column and row ranges:
    /// the bounding rectangle of the cube's projected corners, widened by one pixel against
    /// rounding. Every ray outside it misses the cube, so a renderer can fill those pixels
    /// with the background without tracing them (in a far view most of the image). The whole
    /// image when a corner lies on or behind the eye plane (the projection is then unbounded),
    /// empty when the cube lies wholly behind the eye.
    pub fn cube_pixels(&self, frame: &Frame, cube: &crate::Cube) -> PixelRect {
        let (r, u, f) = (
            frame.0.map(f64::from),
            frame.1.map(f64::from),
            frame.2.map(f64::from),
        );
        let eye = self.eye.map(f64::from);
        let (w, h) = (self.width, self.height);
        let th = (0.5 * f64::from(self.fov_y_deg)).to_radians().tan();
        let ta = th * w as f64 / h as f64;
        let full = PixelRect { x: 0..w, y: 0..h };
        let (mut x0, mut y0) = (f64::INFINITY, f64::INFINITY);
        let (mut x1, mut y1) = (f64::NEG_INFINITY, f64::NEG_INFINITY);
        let mut behind = 0;
        for corner in 0..8 {
            let p: [f64; 3] = std::array::from_fn(|k| {
                cube.min[k] + if corner >> k & 1 == 1 { cube.size } else { 0.0 } - eye[k]
            });
            let z = p[0] * f[0] + p[1] * f[1] + p[2] * f[2];
            if z <= 0.0 {
                behind += 1;
                continue;
            }
            let a = (p[0] * r[0] + p[1] * r[1] + p[2] * r[2]) / z;
            let b = (p[0] * u[0] + p[1] * u[1] + p[2] * u[2]) / z;
            // Continuous pixel coordinates: pixel `x`'s centre is at `x + 1/2`.
            let fx = (a + ta) * w as f64 / (2.0 * ta);
            let fy = (th - b) * h as f64 / (2.0 * th);
            x0 = x0.min(fx);
            x1 = x1.max(fx);
            y0 = y0.min(fy);
            y1 = y1.max(fy);
        }
        if behind == 8 {
            return PixelRect { x: 0..0, y: 0..0 };
        }
        if behind > 0 || ![x0, x1, y0, y1].iter().all(|v| v.is_finite()) {
            return full;
        }
        // Centres `c + 1/2` in `[lo, hi]`, one pixel more on each side.
        let span = |lo: f64, hi: f64, n: usize| {
            let a = ((lo - 0.5).ceil() - 1.0).clamp(0.0, n as f64) as usize;
            let b = ((hi - 0.5).floor() + 2.0).clamp(0.0, n as f64) as usize;
            a..b.max(a)
        };
        PixelRect {
            x: span(x0, x1, w),
            y: span(y0, y1, h),
        }
    }

    /// Pixel footprint of primary rays (Igehy 1999): `f(t) = t 2 tan(fov_y / 2) / H`.
    pub fn footprint(&self) -> Footprint {
        Footprint {
            width0: 0.0,
            spread: 2.0 * (0.5 * self.fov_y_deg.to_radians()).tan() / self.height as f32,
        }
    }
}

/// A rectangle of pixels: columns `x`, rows `y` (half-open).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PixelRect {
    /// Columns.
    pub x: std::ops::Range<usize>,
    /// Rows.
    pub y: std::ops::Range<usize>,
}

/// Generates the primary rays of a camera: `dir = corner + (x + 1/2) dx + (y + 1/2) dy`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayGen {
    eye: [f32; 3],
    corner: [f32; 3],
    dx: [f32; 3],
    dy: [f32; 3],
}

impl RayGen {
    /// Primary ray through the centre of pixel `(x, y)`, unit direction.
    #[inline]
    pub fn ray(&self, x: usize, y: usize) -> Ray {
        let (fx, fy) = (x as f32 + 0.5, y as f32 + 0.5);
        let d = std::array::from_fn(|k| self.corner[k] + fx * self.dx[k] + fy * self.dy[k]);
        Ray::new(self.eye, unit(d))
    }
}

/// A point light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointLight {
    /// Position.
    pub position: [f32; 3],
    /// Intensity (1 = unit radiance scale, no falloff).
    pub intensity: f32,
}

/// Phong parameters (the paper, Table 3, names Phong lighting without coefficients; the
/// defaults are ours).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shading {
    /// Ambient coefficient.
    pub ka: f32,
    /// Diffuse coefficient.
    pub kd: f32,
    /// Specular coefficient.
    pub ks: f32,
    /// Specular exponent.
    pub shininess: f32,
    /// Cast a shadow ray per hit.
    pub shadows: bool,
    /// Background colour.
    pub background: [f32; 3],
    /// Ambient-occlusion rays per hit (0: none). The ambient term is scaled by the fraction
    /// of unoccluded rays (cosine-distributed over the hemisphere, traced in the same mode,
    /// so far hits are occluded by voxels: the paper's shadows/AO application).
    pub ao_samples: u32,
    /// Length of the ambient-occlusion rays as a fraction of the cube side.
    pub ao_radius: f32,
    /// View-dependent detail (the paper's display-wall application): full triangle detail
    /// inside a screen ellipse, coarser voxels with the distance outside it.
    pub focus: Option<Focus>,
}

/// A focus region in the image (the paper's display wall: the tracked user's central field of
/// view). Pixels inside the ellipse trace triangles; outside, the hybrid mode's LoD scale is
/// doubled for every `falloff` pixels of distance from the ellipse, so detail drops away from
/// the focus. The paper's image-space blur of the transitions is not applied.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Focus {
    /// Centre `(x, y)` in pixels.
    pub centre: [f32; 2],
    /// Semi-axes `(a, b)` in pixels.
    pub radii: [f32; 2],
    /// Pixels of distance per doubling of the LoD scale.
    pub falloff: f32,
}

impl Focus {
    /// The trace mode of pixel `(x, y)` for a base `mode` (only the hybrid mode changes).
    pub fn mode_at(&self, mode: &TraceMode, x: usize, y: usize) -> TraceMode {
        let TraceMode::Hybrid {
            lod_scale,
            blend,
            small_leaves_as_voxels,
        } = *mode
        else {
            return *mode;
        };
        let dx = (x as f32 + 0.5 - self.centre[0]) / self.radii[0].max(1e-6);
        let dy = (y as f32 + 0.5 - self.centre[1]) / self.radii[1].max(1e-6);
        let e = (dx * dx + dy * dy).sqrt();
        if e <= 1.0 {
            return TraceMode::Triangles;
        }
        // Distance outside the ellipse, in pixels, along the ray from its centre.
        let d = (e - 1.0) / e * (dx * self.radii[0]).hypot(dy * self.radii[1]);
        TraceMode::Hybrid {
            lod_scale: lod_scale * (d / self.falloff.max(1e-6)).exp2(),
            blend,
            small_leaves_as_voxels,
        }
    }

    fn check(&self) -> Result<()> {
        let ok = self.centre.iter().all(|v| v.is_finite())
            && self.radii.iter().all(|v| v.is_finite() && *v > 0.0)
            && self.falloff.is_finite()
            && self.falloff > 0.0;
        if ok {
            Ok(())
        } else {
            Err(Error::invalid(
                "focus",
                format!("centre must be finite, radii and falloff positive: {self:?}"),
            ))
        }
    }
}

impl Default for Shading {
    fn default() -> Self {
        Self {
            ka: 0.1,
            kd: 0.8,
            ks: 0.2,
            shininess: 32.0,
            shadows: true,
            background: [0.05, 0.05, 0.08],
            ao_samples: 0,
            ao_radius: 0.05,
            focus: None,
        }
    }
}

/// Counts of a rendered frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RenderStats {
    /// Primary rays that hit a triangle.
    pub triangle_hits: usize,
    /// Primary rays that stopped at a voxel.
    pub voxel_hits: usize,
    /// Primary rays that hit nothing.
    pub misses: usize,
    /// Smallest voxel blend factor seen (1 when there were no voxel hits).
    pub blend_min: f32,
    /// Largest voxel blend factor seen.
    pub blend_max: f32,
    /// Seconds for the frame.
    pub seconds: f64,
}

impl RenderStats {
    /// Fraction of hit pixels that are voxel hits.
    pub fn voxel_fraction(&self) -> f64 {
        let hits = self.triangle_hits + self.voxel_hits;
        if hits == 0 {
            0.0
        } else {
            self.voxel_hits as f64 / hits as f64
        }
    }

    fn merge(mut self, o: RenderStats) -> RenderStats {
        self.triangle_hits += o.triangle_hits;
        self.voxel_hits += o.voxel_hits;
        self.misses += o.misses;
        self.blend_min = self.blend_min.min(o.blend_min);
        self.blend_max = self.blend_max.max(o.blend_max);
        self
    }
}

/// Shades one primary hit: Phong with one shadow ray offset from the surface (by 1.5 sides of
/// the voxel hit, or for a triangle hit in the hybrid mode of the largest voxel the shadow
/// ray may stop at, against self-shadowing by the surface's own voxels), and the optional
/// ambient occlusion.
#[allow(clippy::too_many_arguments)]
fn shade(
    oct: &HybridOctree,
    ray: &Ray,
    hit: &Hit,
    light: &PointLight,
    mode: &TraceMode,
    fp: Footprint,
    s: &Shading,
    seed: u64,
) -> [f32; 3] {
    let p: [f32; 3] = std::array::from_fn(|k| ray.origin[k] + hit.t * ray.dir[k]);
    let mut n = hit.normal;
    if dot(n, ray.dir) > 0.0 {
        n = n.map(|x| -x);
    }
    let to_l = sub(light.position, p);
    let dist = dot(to_l, to_l).sqrt();
    let l = to_l.map(|x| x / dist.max(1e-20));
    let ndl = dot(n, l);
    let c = hit.color;
    let sfp = Footprint {
        width0: fp.width0 + fp.spread * hit.t,
        spread: fp.spread,
    };
    let offset = match hit.kind {
        HitKind::Voxel { level, .. } => 1.5 * oct.cube.size as f32 / (1u32 << level) as f32,
        // A secondary ray from a triangle may stop at the voxels of the same surface, as
        // large as the footprint it is traced at allows (`v_w <= lod_scale * w`, paper
        // section 4): it leaves them first, as from a voxel hit.
        HitKind::Triangle { .. } => {
            let vw = match *mode {
                TraceMode::Hybrid { lod_scale, .. } => {
                    let max = lod_scale * sfp.width0;
                    // The side of the largest cell no larger than the footprint.
                    (0..=oct.max_depth)
                        .map(|l| oct.cube.cell_size(l) as f32)
                        .find(|&w| w <= max)
                        .unwrap_or(0.0)
                }
                _ => 0.0,
            };
            (1.5 * vw).max(1e-4 * oct.cube.size as f32)
        }
    };
    let origin: [f32; 3] = std::array::from_fn(|k| p[k] + offset * n[k]);
    let ao = if s.ao_samples > 0 {
        ambient_occlusion(oct, origin, n, mode, sfp, s, seed)
    } else {
        1.0
    };
    let mut out = c.map(|x| ao * s.ka * x);
    if ndl <= 0.0 {
        return out;
    }
    if s.shadows {
        let shadow = Ray {
            origin,
            dir: l,
            t_min: 0.0,
            t_max: dist - offset,
        };
        if shadow.t_max > 0.0 && oct.occluded(&shadow, mode, Some(sfp)) {
            return out;
        }
    }
    let v = ray.dir.map(|x| -x);
    let rfl: [f32; 3] = std::array::from_fn(|k| 2.0 * ndl * n[k] - l[k]);
    let spec = s.ks * dot(rfl, v).max(0.0).powf(s.shininess);
    for k in 0..3 {
        out[k] += light.intensity * (s.kd * ndl * c[k] + spec);
    }
    out
}

/// A uniform number in `[0, 1)` from a 64-bit hash of `k` (SplitMix64's finalizer).
fn hash01(k: u64) -> f32 {
    let mut z = k.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
}

/// Fraction of `s.ao_samples` cosine-distributed rays from `origin` around `n` that travel
/// `s.ao_radius` cube sides without a hit (deterministic per pixel through `seed`).
#[allow(clippy::too_many_arguments)]
fn ambient_occlusion(
    oct: &HybridOctree,
    origin: [f32; 3],
    n: [f32; 3],
    mode: &TraceMode,
    fp: Footprint,
    s: &Shading,
    seed: u64,
) -> f32 {
    let helper = if n[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let u = unit(cross(n, helper));
    let v = cross(n, u);
    let reach = s.ao_radius * oct.cube.size as f32;
    let mut open = 0u32;
    for i in 0..s.ao_samples {
        // A huge sample count stays interruptible: the caller reports the cancellation.
        if i % 1024 == 1023 && wscg_math::cancel::requested() {
            break;
        }
        let k = seed.wrapping_mul(0x2545_f491_4f6c_dd1d) ^ u64::from(i) << 40;
        let (r1, r2) = (hash01(k.wrapping_mul(2)), hash01(k.wrapping_mul(2) | 1));
        let (r, phi) = (r1.sqrt(), std::f32::consts::TAU * r2);
        let (a, b, c) = (r * phi.cos(), r * phi.sin(), (1.0 - r1).max(0.0).sqrt());
        let dir = std::array::from_fn(|j| a * u[j] + b * v[j] + c * n[j]);
        let ray = Ray {
            origin,
            dir,
            t_min: 0.0,
            t_max: reach,
        };
        if !oct.occluded(&ray, mode, Some(fp)) {
            open += 1;
        }
    }
    open as f32 / s.ao_samples as f32
}

/// Renders `oct` from `cam` in `mode`: an `H x W x 3` linear RGB image and hit counts.
/// Only the pixels of [`Camera::cube_pixels`] are traced; the rest are background (and
/// counted as misses) without a ray.
pub fn render(
    oct: &HybridOctree,
    cam: &Camera,
    light: &PointLight,
    mode: &TraceMode,
    shading: &Shading,
) -> Result<(Image<f32>, RenderStats)> {
    let frame = cam.frame()?;
    if light.position.iter().any(|v| !v.is_finite()) || !light.intensity.is_finite() {
        return Err(Error::invalid(
            "light",
            "position and intensity must be finite",
        ));
    }
    if let Some(f) = &shading.focus {
        f.check()?;
    }
    if !(shading.ao_radius.is_finite() && shading.ao_radius > 0.0) {
        return Err(Error::invalid(
            "ao_radius",
            format!("must be positive, got {}", shading.ao_radius),
        ));
    }
    let t0 = Instant::now();
    let fp = cam.footprint();
    let rays = cam.ray_gen(&frame);
    let (w, h) = (cam.width, cam.height);
    let mut data = vec![0f32; w * h * 3];
    // Pixels outside the cube's projection miss everything: background, not traced.
    let inside = cam.cube_pixels(&frame, &oct.cube);
    let empty = RenderStats {
        blend_min: 1.0,
        blend_max: 0.0,
        ..Default::default()
    };
    let mut stats = data
        .par_chunks_mut(w * 3)
        .enumerate()
        .map(|(y, row)| {
            let mut st = empty;
            if wscg_math::cancel::requested() {
                return st;
            }
            let xs = if inside.y.contains(&y) {
                inside.x.clone()
            } else {
                0..0
            };
            st.misses += w - xs.len();
            for x in (0..xs.start).chain(xs.end..w) {
                row[3 * x..3 * x + 3].copy_from_slice(&shading.background);
            }
            for x in xs {
                let ray = rays.ray(x, y);
                let pm = match &shading.focus {
                    Some(f) => f.mode_at(mode, x, y),
                    None => *mode,
                };
                let mode = &pm;
                let px = match oct.intersect(&ray, mode, Some(fp)) {
                    Some(hit) => {
                        match hit.kind {
                            HitKind::Triangle { .. } => st.triangle_hits += 1,
                            HitKind::Voxel { blend, .. } => {
                                st.voxel_hits += 1;
                                st.blend_min = st.blend_min.min(blend);
                                st.blend_max = st.blend_max.max(blend);
                            }
                        }
                        shade(
                            oct,
                            &ray,
                            &hit,
                            light,
                            mode,
                            fp,
                            shading,
                            (y * w + x) as u64,
                        )
                    }
                    None => {
                        st.misses += 1;
                        shading.background
                    }
                };
                row[3 * x..3 * x + 3].copy_from_slice(&px);
            }
            st
        })
        .reduce(|| empty, RenderStats::merge);
    // Rows skipped (and sample loops cut short) after a cancellation request.
    wscg_math::cancel::check()?;
    if stats.voxel_hits == 0 {
        stats.blend_min = 1.0;
        stats.blend_max = 1.0;
    }
    stats.seconds = t0.elapsed().as_secs_f64();
    Ok((Image::new(h, w, 3, data)?, stats))
}

/// A false-colour map of what each primary ray stops at in `mode`: triangle hits white-grey,
/// voxel hits coloured by level (blue for coarse, through green, to red for the finest),
/// misses black. Shows where the LoD criterion switches between representations.
/// With `focus`, the mode of each pixel follows [`Focus::mode_at`].
pub fn lod_map(
    oct: &HybridOctree,
    cam: &Camera,
    mode: &TraceMode,
    focus: Option<&Focus>,
) -> Result<Image<f32>> {
    let frame = cam.frame()?;
    if let Some(f) = focus {
        f.check()?;
    }
    let rays = cam.ray_gen(&frame);
    let fp = cam.footprint();
    let depth = f32::from(oct.max_depth.max(1));
    let inside = cam.cube_pixels(&frame, &oct.cube);
    let mut data = vec![0f32; cam.width * cam.height * 3];
    data.par_chunks_mut(cam.width * 3)
        .enumerate()
        .filter(|(y, _)| inside.y.contains(y))
        .for_each(|(y, row)| {
            for x in inside.x.clone() {
                let pm = focus.map_or(*mode, |f| f.mode_at(mode, x, y));
                let c = match oct.intersect(&rays.ray(x, y), &pm, Some(fp)) {
                    None => [0.0; 3],
                    Some(h) => match h.kind {
                        HitKind::Triangle { .. } => [0.85; 3],
                        HitKind::Voxel { level, .. } => {
                            let s = f32::from(level) / depth;
                            [s, 1.0 - (2.0 * s - 1.0).abs(), 1.0 - s]
                        }
                    },
                };
                row[3 * x..3 * x + 3].copy_from_slice(&c);
            }
        });
    Image::new(cam.height, cam.width, 3, data)
}
