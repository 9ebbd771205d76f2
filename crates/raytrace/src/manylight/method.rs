//! One entry point for every method of the comparison (paper 08, section 5): the paper's
//! adaptive importance caching, its ablation with uniform weights, importance caching
//! (Georgiev 2012), power sampling and the all-VPL reference.

use std::time::Instant;

use wscg_math::image::Image;
use wscg_math::progress::Progress;
use wscg_math::{Error, Result};

use super::cache::Record;
use super::camera::Camera;
use super::gbuffer::trace_primary;
use super::placement::{AdaptiveParams, Placement};
use super::render::{build_cache, render, render_power, render_reference, CacheStats, IcParams};
use super::scene::Scene;
use super::vpl::{generate_vpls, Vpl, VplSettings};
use super::weights::Interp;

/// A rendering method.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// The paper: clustering, adaptive insertion, similarity weights.
    Adaptive,
    /// The paper's ablation: clustering and insertion with uniform weights.
    AdaptiveUniform,
    /// Importance caching (Georgiev et al. 2012): screen-grid records, uniform weights.
    Ic,
    /// VPLs drawn in proportion to their power, no cache.
    Power,
    /// Every VPL at every pixel.
    Reference,
}

impl Method {
    /// All methods.
    pub const ALL: [Method; 5] = [
        Method::Adaptive,
        Method::AdaptiveUniform,
        Method::Ic,
        Method::Power,
        Method::Reference,
    ];

    /// Its name: `adaptive`, `adaptive_uniform`, `ic`, `power`, `reference`.
    pub fn name(&self) -> &'static str {
        match self {
            Method::Adaptive => "adaptive",
            Method::AdaptiveUniform => "adaptive_uniform",
            Method::Ic => "ic",
            Method::Power => "power",
            Method::Reference => "reference",
        }
    }

    /// The method of a name.
    ///
    /// Errors: an unknown name (the message lists the valid ones).
    pub fn parse(name: &str) -> Result<Self> {
        Self::ALL
            .into_iter()
            .find(|m| m.name() == name)
            .ok_or_else(|| {
                Error::invalid(
                    "method",
                    format!(
                        "{name:?} is not a method; valid methods are {}",
                        Self::ALL.map(|m| m.name()).join(", ")
                    ),
                )
            })
    }

    /// Placement and interpolation of a cached method; `None` for the others.
    pub fn cache_setup(&self, a: &AdaptiveParams, weights: Interp) -> Option<(Placement, Interp)> {
        match self {
            Method::Adaptive => Some((Placement::Adaptive(*a), weights)),
            Method::AdaptiveUniform => Some((Placement::Adaptive(*a), Interp::Uniform)),
            Method::Ic => Some((Placement::RandomScreen, Interp::Uniform)),
            Method::Power | Method::Reference => None,
        }
    }
}

/// Everything a run needs.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Settings {
    /// VPL generation.
    pub vpl: VplSettings,
    /// Cache and sampling.
    pub ic: IcParams,
    /// The paper's placement.
    pub adaptive: AdaptiveParams,
    /// The paper's weights (the ablation and the baseline use uniform weights).
    pub weights: Interp,
}

/// What a run produced.
#[derive(Clone, Debug)]
pub struct Output {
    /// Linear RGB radiance, `height x width x 3`.
    pub image: Image<f32>,
    /// The records (cached methods).
    pub records: Vec<Record>,
    /// Cache statistics (cached methods).
    pub cache: Option<CacheStats>,
    /// Number of VPLs.
    pub n_vpls: usize,
    /// Seconds spent generating VPLs and shading points.
    pub setup_seconds: f64,
    /// Seconds spent building the cache.
    pub cache_seconds: f64,
    /// Seconds spent rendering.
    pub render_seconds: f64,
}

/// Renders `scene` from `cam` with `method`: VPLs, shading points, cache (for the cached
/// methods), image.
///
/// Errors: any of the steps' (no emitter, invalid camera or parameters, ...).
pub fn run(
    scene: &Scene,
    cam: &Camera,
    method: Method,
    s: &Settings,
    progress: &dyn Progress,
) -> Result<Output> {
    let t0 = Instant::now();
    let vpls = generate_vpls(scene, &s.vpl)?;
    let g = trace_primary(scene, cam)?;
    run_with(
        scene,
        &g,
        &vpls,
        method,
        s,
        progress,
        t0.elapsed().as_secs_f64(),
    )
}

/// [`run`] on given VPLs and shading points (so that several methods share them).
pub fn run_with(
    scene: &Scene,
    g: &super::gbuffer::GBuffer,
    vpls: &[Vpl],
    method: Method,
    s: &Settings,
    progress: &dyn Progress,
    setup_seconds: f64,
) -> Result<Output> {
    let mut out = Output {
        image: Image::filled(1, 1, 3, 0.0)?,
        records: Vec::new(),
        cache: None,
        n_vpls: vpls.len(),
        setup_seconds,
        cache_seconds: 0.0,
        render_seconds: 0.0,
    };
    let t = Instant::now();
    out.image = match method.cache_setup(&s.adaptive, s.weights) {
        Some((placement, interp)) => {
            let (cache, stats) = build_cache(scene, g, vpls, &placement, interp, &s.ic)?;
            out.cache_seconds = t.elapsed().as_secs_f64();
            let t = Instant::now();
            let img = render(scene, g, vpls, &cache, &s.ic, progress)?;
            out.render_seconds = t.elapsed().as_secs_f64();
            out.records = cache.records;
            out.cache = Some(stats);
            return Ok(Output { image: img, ..out });
        }
        None if method == Method::Power => render_power(scene, g, vpls, &s.ic, progress)?,
        None => render_reference(scene, g, vpls, s.ic.clamp_dist, progress)?,
    };
    out.render_seconds = t.elapsed().as_secs_f64();
    Ok(out)
}
