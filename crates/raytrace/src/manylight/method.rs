//! One entry point for every method of the comparison (paper 08, section 5): the paper's
//! adaptive importance caching, its ablation with uniform weights, importance caching
//! (Georgiev 2012), power sampling and the all-VPL reference.

use std::time::Instant;

use wscg_math::image::Image;
use wscg_math::progress::Progress;
use wscg_math::{Error, Result};

use super::cache::Record;
use super::camera::Camera;
use super::gbuffer::{trace_primary, GBuffer};
use super::placement::{AdaptiveParams, Placement};
use super::render::{
    build_cache, render, render_power, render_reference_filtered, CacheStats,
    ImportanceCachingParams,
};
use super::scene::Scene;
use super::vpl::{generate_vpls, Vpl, VplParams};
use super::weights::Interp;
use crate::spectral::srgb_oetf;

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
    /// Every VPL at every pixel sample (`ic.filter`, `ic.pixel_samples`).
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

wscg_math::params! {
    /// Everything a run needs.
    #[derive(Clone, Copy, Debug, Default, PartialEq)]
    pub struct ManyLightParams {
        /// VPL generation.
        pub vpl: VplParams,
        /// Cache and sampling.
        pub ic: ImportanceCachingParams,
        /// The paper's placement.
        pub adaptive: AdaptiveParams,
        /// The paper's weights (the ablation and the baseline use uniform weights).
        pub weights: Interp,
    }
}

impl ManyLightParams {
    /// Checks every part: [`VplParams::validate`], [`ImportanceCachingParams::validate`],
    /// [`AdaptiveParams::validate`] and [`Interp::validate`].
    pub fn validate(&self) -> Result<()> {
        self.vpl.validate()?;
        self.ic.validate()?;
        self.adaptive.validate()?;
        self.weights.validate()
    }
}

/// What a run produced.
#[derive(Clone, Debug)]
pub struct ManyLightResult {
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
    s: &ManyLightParams,
    progress: &dyn Progress,
) -> Result<ManyLightResult> {
    s.validate()?;
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
    g: &GBuffer,
    vpls: &[Vpl],
    method: Method,
    s: &ManyLightParams,
    progress: &dyn Progress,
    setup_seconds: f64,
) -> Result<ManyLightResult> {
    s.validate()?;
    let t = Instant::now();
    let (image, records, cache, cache_seconds) = match method.cache_setup(&s.adaptive, s.weights) {
        Some((placement, interp)) => {
            let (cache, stats) = build_cache(scene, g, vpls, &placement, interp, &s.ic)?;
            let cache_seconds = t.elapsed().as_secs_f64();
            let img = render(scene, g, vpls, &cache, &s.ic, progress)?;
            (img, cache.records, Some(stats), cache_seconds)
        }
        None if method == Method::Power => (
            render_power(scene, g, vpls, &s.ic, progress)?,
            Vec::new(),
            None,
            0.0,
        ),
        None => (
            render_reference_filtered(scene, g, vpls, &s.ic, progress)?,
            Vec::new(),
            None,
            0.0,
        ),
    };
    Ok(ManyLightResult {
        image,
        records,
        cache,
        n_vpls: vpls.len(),
        setup_seconds,
        cache_seconds,
        render_seconds: t.elapsed().as_secs_f64() - cache_seconds,
    })
}

/// The comparison of the paper's section 5: every method of `methods` on the same VPLs and
/// shading points, in that order; importance caching gets the final record count of the
/// adaptive run when `methods` holds both (the paper: "the same numbers of cache points").
pub fn compare(
    scene: &Scene,
    g: &GBuffer,
    vpls: &[Vpl],
    methods: &[Method],
    s: &ManyLightParams,
    progress: &dyn Progress,
) -> Result<Vec<(Method, ManyLightResult)>> {
    s.validate()?;
    let mut done: Vec<Option<ManyLightResult>> = vec![None; methods.len()];
    let mut st = *s;
    if let Some(i) = methods.iter().position(|m| *m == Method::Adaptive) {
        let o = run_with(scene, g, vpls, Method::Adaptive, s, progress, 0.0)?;
        st.ic.n_cache = o.records.len().max(1);
        done[i] = Some(o);
    }
    for (i, m) in methods.iter().enumerate() {
        if done[i].is_none() {
            let p = if *m == Method::Ic { &st } else { s };
            done[i] = Some(run_with(scene, g, vpls, *m, p, progress, 0.0)?);
        }
    }
    Ok(methods
        .iter()
        .copied()
        .zip(done.into_iter().flatten())
        .collect())
}

/// Display sRGB (IEC 61966-2-1 curve) of linear radiance times `exposure`, clipped to
/// `[0, 1]`.
pub fn to_display(img: &Image<f32>, exposure: f64) -> Image<f32> {
    img.map(|v| srgb_oetf((v as f64 * exposure).clamp(0.0, 1.0)) as f32)
}
