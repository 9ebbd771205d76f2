//! Virtual point lights (instant radiosity, Keller 1997), generated as in the paper's
//! reference (Dachsbacher et al. 2014): light paths from the emitters, one VPL per vertex.

use nalgebra::Vector3;
use rand::Rng;
use rayon::prelude::*;
use wscg_math::{Error, Result};

use super::pmf::Pmf;
use super::scene::{luminance, Rgb, Scene};
use crate::frame::tangent_frame;

/// What a VPL is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum VplKind {
    /// On an emitter: radiates `power / pi` per unit projected solid angle.
    Emitter,
    /// On a diffuse surface hit by a light path: re-emits its incident flux with the
    /// surface's `albedo / pi`.
    Surface {
        /// The surface's albedo.
        albedo: Rgb,
    },
}

/// A virtual point light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vpl {
    /// Position.
    pub pos: [f64; 3],
    /// Unit normal of the side it radiates from.
    pub normal: [f64; 3],
    /// Power (emitter) or incident flux (surface VPL).
    pub power: Rgb,
    /// Emitter or surface VPL.
    pub kind: VplKind,
}

impl Vpl {
    /// `power * psi` with `psi = 1 / pi` (emitter) or `albedo / pi` (surface VPL): the
    /// factor of a VPL's contribution `L f_r G V` (eq. 1) that does not depend on the receiver.
    pub fn intensity(&self) -> Rgb {
        let pi = std::f64::consts::PI;
        match self.kind {
            VplKind::Emitter => self.power.map(|p| p / pi),
            VplKind::Surface { albedo } => [0, 1, 2].map(|c| self.power[c] * albedo[c] / pi),
        }
    }
}

wscg_math::params! {
    /// VPL generation parameters.
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct VplParams {
        /// Light paths traced (one emitter VPL each, plus one VPL per bounce); 1000.
        pub n_paths: usize,
        /// Bounces per light path (surface VPLs), 2.
        pub max_bounces: u32,
        /// Seed.
        pub seed: u64,
    }
}

impl Default for VplParams {
    fn default() -> Self {
        Self {
            n_paths: 1000,
            max_bounces: 2,
            seed: 0,
        }
    }
}

impl VplParams {
    /// Errors: `n_paths = 0` (any bounce count and seed is valid).
    pub fn validate(&self) -> Result<()> {
        if self.n_paths == 0 {
            return Err(Error::invalid(
                "n_paths",
                "at least one light path is needed, got 0",
            ));
        }
        Ok(())
    }
}

/// A direction from the cosine-weighted hemisphere around the unit normal `n`.
pub(crate) fn cosine_hemisphere(n: &Vector3<f64>, u1: f64, u2: f64) -> Vector3<f64> {
    let r = u1.sqrt();
    let phi = 2.0 * std::f64::consts::PI * u2;
    let (t, b) = tangent_frame(n);
    (t * (r * phi.cos()) + b * (r * phi.sin()) + n * (1.0 - u1).max(0.0).sqrt()).normalize()
}

/// Traces `n_paths` light paths: emitter `t` is chosen with probability proportional to its
/// luminance times its area, a uniform point on it gets an emitter VPL of power
/// `pi L_e A_t / (n_paths P_t)`; the path continues in a cosine-distributed direction, and
/// each surface it hits (up to `max_bounces`) gets a surface VPL carrying the incident flux,
/// which is then multiplied by the surface's albedo. The paths are traced in parallel with a
/// random stream each, so the result does not depend on the thread count.
///
/// Errors: no emitter in the scene, `n_paths = 0`; [`Error::OutOfMemory`] naming `n_paths`
/// when the VPLs cannot fit in memory.
pub fn generate_vpls(scene: &Scene, s: &VplParams) -> Result<Vec<Vpl>> {
    s.validate()?;
    let emitters = scene.emitters();
    if emitters.is_empty() {
        return Err(Error::invalid(
            "scene",
            "no emissive triangle: many-light rendering needs at least one emitter",
        ));
    }
    let tris = scene.triangles();
    let weights: Vec<f64> = emitters
        .iter()
        .map(|&i| luminance(&scene.emission(i)) * tris[i as usize].area)
        .collect();
    let pick = Pmf::new(&weights)
        .ok_or_else(|| Error::invalid("scene", "the emitters have no luminous power"))?;
    // At most 1 + max_bounces VPLs per path, held per path and then flattened (twice).
    let most = wscg_math::alloc::elements("n_paths", &[s.n_paths, 2 + s.max_bounces as usize])?;
    wscg_math::alloc::ensure::<Vpl>("n_paths", most)?;
    let eps = 1e-6 * scene.diagonal();
    let paths: Vec<Vec<Vpl>> = (0..s.n_paths)
        .into_par_iter()
        .map(|p| {
            if wscg_math::cancel::requested() {
                return Vec::new();
            }
            let mut rng = wscg_math::rng::stream(s.seed, p as u64);
            let k = pick.sample(rng.random());
            let tri = &tris[emitters[k] as usize];
            let prob = pick.pdf(k);
            let le = scene.emission(emitters[k]);
            let y = tri.sample(rng.random(), rng.random());
            let n = tri.normal;
            let scale = std::f64::consts::PI * tri.area / (s.n_paths as f64 * prob);
            let power = le.map(|l| l * scale);
            let mut out = vec![Vpl {
                pos: y,
                normal: n,
                power,
                kind: VplKind::Emitter,
            }];
            let mut beta = power;
            let (mut o, mut nrm) = (Vector3::from(y), Vector3::from(n));
            for _ in 0..s.max_bounces {
                let w = cosine_hemisphere(&nrm, rng.random(), rng.random());
                let Some(h) = scene.intersect((o + nrm * eps).into(), w.into(), f64::INFINITY)
                else {
                    break;
                };
                let hn = Vector3::from(h.normal);
                let hn = if hn.dot(&w) > 0.0 { -hn } else { hn };
                let albedo = scene.albedo(h.tri);
                if luminance(&albedo) <= 0.0 {
                    break;
                }
                out.push(Vpl {
                    pos: h.pos,
                    normal: hn.into(),
                    power: beta,
                    kind: VplKind::Surface { albedo },
                });
                beta = [0, 1, 2].map(|c| beta[c] * albedo[c]);
                o = h.pos.into();
                nrm = hn;
            }
            out
        })
        .collect();
    wscg_math::cancel::check()?;
    Ok(paths.into_iter().flatten().collect())
}
