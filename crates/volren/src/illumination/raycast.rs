//! The ray-casting baselines (spec section 2.6): emission-absorption, Blinn-Phong local
//! illumination (gradient by central differences of trilinear samples) and the validation
//! renderer with a Beer-Lambert shadow ray per sample. Rays are orthographic and sample at
//! the same depths `z_start + (k + 1/2) step` as slices of distance `step` would, so a shadow
//! ray from a headlight crosses exactly the earlier samples of its own ray.

use rayon::prelude::*;
use wscg_math::vec3::{add, dot, normalized_or_zero};
use wscg_math::Result;

use super::camera::{Frame, Slicing};
use super::classify::SampleLut;
use super::field::ScalarField;
use super::method::{Light, Phong, RenderSettings};
use super::sampler::Sampler;
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
    settings: &RenderSettings,
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
    let (w, h) = (frame.width, frame.height);
    let bg = settings.background;
    let ka = light.ambient;
    let mut rgba = vec![0f32; w * h * 4];
    rgba.par_chunks_mut(4 * w).enumerate().for_each(|(y, row)| {
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
            while k < k1 {
                if e[3] >= settings.early_stop {
                    break;
                }
                let z = slicing.z(k) as f32;
                let p = at(z);
                // An empty cell: jump to the first sample beyond it.
                if let Some(t) = sampler.empty_exit(p, dz) {
                    let next = ((z as f64 + t as f64 - slicing.z_start) / slicing.ds - 0.5).ceil();
                    k = (next.max(0.0) as usize).max(k + 1);
                    continue;
                }
                k += 1;
                let Some(sv) = sampler.visible(p) else {
                    continue;
                };
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
                    RayShading::Phong(ph) => {
                        let g = field.gradient(p, settings.interp);
                        let gn = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
                        if gn < 1e-6 {
                            (ph.ka + ph.kd, 0.0)
                        } else {
                            let n = [
                                -(g[0] / gn) as f64,
                                -(g[1] / gn) as f64,
                                -(g[2] / gn) as f64,
                            ];
                            let ndl = dot(n, lw).abs() as f32;
                            let ndh = dot(n, half).abs() as f32;
                            (ph.ka + ph.kd * ndl, ph.ks * ndh.powf(ph.shininess))
                        }
                    }
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
