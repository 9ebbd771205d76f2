//! The ray-casting baselines (paper §5.1): emission-absorption, Blinn-Phong local
//! illumination (the gradient of central differences at the voxels, interpolated trilinearly
//! from the value-and-gradient bricks of [`super::bricks`]) and the validation
//! renderer with a Beer-Lambert shadow ray per sample. Rays are orthographic and sample at
//! the same depths `z_start + (k + 1/2) step` as slices of distance `step` would, so a shadow
//! ray from a headlight crosses exactly the earlier samples of its own ray.

use rayon::prelude::*;
use wscg_math::vec3::{add, normalized_or_zero};
use wscg_math::Result;

use super::camera::{Frame, Slicing};
use super::classify::SampleLut;
use super::field::ScalarField;
use super::method::{IlluminationParams, Light, Phong};
use super::sampler::{Loc, Sampler};
use super::slicer::MAX_SLICES;

/// Shading of a ray caster.
#[derive(Clone, Copy, Debug)]
pub(crate) enum RayShading {
    /// Emission-absorption only.
    None,
    /// Blinn-Phong local illumination.
    Phong(Phong),
    /// Shadow rays towards the light, `S = k_a + (1 - k_a) T`.
    Shadow,
}

/// Renders `H x W x 4` RGBA with a ray per pixel; returns the image and the samples per ray.
#[allow(clippy::too_many_arguments)]
pub(crate) fn raycast(
    field: &ScalarField,
    sampler: &Sampler,
    lut: &SampleLut,
    frame: &Frame,
    light: &Light,
    settings: &IlluminationParams,
    step: f32,
    shading: RayShading,
) -> Result<(Vec<f32>, usize)> {
    let l = light.unit_dir()?;
    // `slice_distance` is the sample step of the ray casters in the Python and CLI options.
    let slicing = Slicing::bounded(
        frame,
        field,
        step as f64,
        MAX_SLICES,
        "step (slice_distance)",
    )?;
    let [org, dx, dy, dz] = frame.voxel_steps(field, 0.0, 0.0);
    let s = field.scale();
    let to_vox = |p: [f64; 3]| -> [f32; 3] { std::array::from_fn(|a| (p[a] / s[a]) as f32) };
    let lw = frame.light_world(l);
    // A shadow-ray step crosses the previous slice plane: length step / l_z towards the light.
    let shadow_step = to_vox(lw.map(|c| c * step as f64 / l[2]));
    let half = normalized_or_zero(add(lw, frame.d.map(|c| -c)));
    let (l32, h32) = (lw.map(|c| c as f32), half.map(|c| c as f32));
    let bricks = field.bricks();
    let vox = field.voxels();
    let (w, h) = (frame.width, frame.height);
    let bg = settings.background;
    let ka = light.ambient;
    let mut rgba = vec![0f32; w * h * 4];
    rgba.par_chunks_mut(4 * w).enumerate().for_each(|(y, row)| {
        // After a cancellation request the remaining rows are skipped (the caller reports it).
        if wscg_math::cancel::requested() {
            return;
        }
        for (x, px) in row.chunks_mut(4).enumerate() {
            let p0: [f32; 3] =
                std::array::from_fn(|a| org[a] + x as f32 * dx[a] + y as f32 * dy[a]);
            let at = |z: f32| -> [f32; 3] { std::array::from_fn(|a| p0[a] + z * dz[a]) };
            let mut e = [0f32; 4];
            // Only the samples inside the box matter when its outside is transparent.
            let (k0, k1) = if sampler.outside_transparent {
                match sampler.clip(p0, dz) {
                    // One sample of slack on each side against rounding at the faces.
                    Some((t0, t1)) => (
                        ((t0 as f64 - slicing.z_start) / slicing.ds - 1.5)
                            .ceil()
                            .max(0.0) as usize,
                        (((t1 as f64 - slicing.z_start) / slicing.ds + 0.5).floor() + 1.0)
                            .clamp(0.0, slicing.n as f64) as usize,
                    ),
                    None => (0, 0),
                }
            } else {
                (0, slicing.n)
            };
            let mut k = k0;
            while k < k1 && e[3] < settings.early_stop {
                let z = slicing.z(k) as f32;
                let p = at(z);
                let (sv, grad) = match sampler.locate(p) {
                    Loc::Outside if sampler.outside_transparent => {
                        k += 1;
                        continue;
                    }
                    // An empty cell: jump to the first sample beyond the empty cells around it.
                    Loc::Empty(c) => {
                        k = match sampler.empty_exit(p, dz, c) {
                            Some(t) => {
                                let next = ((z as f64 + t as f64 - slicing.z_start) / slicing.ds
                                    - 0.5)
                                    .ceil();
                                (next.max(0.0) as usize).max(k + 1)
                            }
                            None => k + 1,
                        };
                        continue;
                    }
                    Loc::Cell(c) => match shading {
                        RayShading::Phong(_) => {
                            let s4 = bricks.sample(vox, c, p, settings.interp);
                            (s4[0], [s4[1], s4[2], s4[3]])
                        }
                        _ => (sampler.value(p), [0.0; 3]),
                    },
                    // Outside the box (an opaque 0) the gradient is 0.
                    Loc::Outside => (0.0, [0.0; 3]),
                };
                k += 1;
                let v = lut.get(sv);
                if v[3] <= 0.0 {
                    continue;
                }
                let wgt = 1.0 - e[3];
                let (diffuse, spec) = match shading {
                    RayShading::None => (1.0, 0.0),
                    RayShading::Shadow => {
                        let mut t = 1f32;
                        for i in 1..=k {
                            let q: [f32; 3] =
                                std::array::from_fn(|a| p[a] + i as f32 * shadow_step[a]);
                            if let Some(sq) = sampler.visible(q) {
                                t *= 1.0 - lut.get(sq)[3];
                            }
                        }
                        (ka + (1.0 - ka) * t, 0.0)
                    }
                    RayShading::Phong(ph) => blinn_phong(&ph, grad, l32, h32),
                };
                for c in 0..3 {
                    e[c] += wgt * (v[c] * diffuse + v[3] * spec);
                }
                e[3] += wgt * v[3];
            }
            for c in 0..3 {
                px[c] = e[c] + (1.0 - e[3]) * bg[c];
            }
            px[3] = e[3];
        }
    });
    Ok((rgba, slicing.n))
}

/// Blinn-Phong weights `(diffuse, specular)` of a sample whose field gradient is `g`, lit from
/// `l` and seen along the half vector `h` (unit vectors): `k_a + k_d |n.l|` and
/// `k_s |n.h|^shininess` with `n = g / |g|`, two-sided (volume surfaces have no inside); a
/// vanishing gradient gives `k_a + k_d` and no highlight.
#[inline]
fn blinn_phong(ph: &Phong, g: [f32; 3], l: [f32; 3], h: [f32; 3]) -> (f32, f32) {
    let gn2 = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
    if gn2 < 1e-12 {
        return (ph.ka + ph.kd, 0.0);
    }
    let inv = 1.0 / gn2.sqrt();
    let dot = |v: [f32; 3]| {
        ((g[0] * v[0] + g[1] * v[1] + g[2] * v[2]) * inv)
            .abs()
            .min(1.0)
    };
    (ph.ka + ph.kd * dot(l), ph.ks * dot(h).powf(ph.shininess))
}
