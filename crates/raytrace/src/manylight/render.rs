//! The estimators (paper 08, eq. 1): importance-cache sampling with four strategies combined
//! by the alpha-max heuristic (Georgiev et al. 2012, section 5), the all-VPL reference, and
//! sampling by VPL power.

use std::time::Instant;

use rand::Rng;
use rayon::prelude::*;
use wscg_math::image::Image;
use wscg_math::progress::Progress;
use wscg_math::{Error, Result};

use super::cache::{ImportanceCache, Lookup, CONSERVATIVE, UNOCCLUDED};
use super::gbuffer::{shade_point, GBuffer, ShadingPoint};
use super::near::NearVpls;
use super::placement::{adaptive, random_screen, AdaptiveStats, Placement};
use super::pmf::{sample_list, Pmf};
use super::scene::{luminance, Rgb, Scene};
use super::shading::Shading;
use super::vpl::Vpl;
use super::weights::Interp;

/// How a pixel's value is sampled: the film's pixel filter.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PixelFilter {
    /// One primary ray through the pixel centre, the shading point of the G-buffer (the
    /// paper's section 5 setting; what an all-VPL reference at pixel centres shows).
    Center,
    /// Sub-pixel positions uniform over the pixel (the box filter of a film renderer's
    /// pixel), the default.
    #[default]
    Box,
    /// Sub-pixel positions drawn from the tent filter `(1 - |dx|) (1 - |dy|)` of radius one
    /// pixel around the centre.
    Tent,
}

impl PixelFilter {
    /// All filters.
    pub const ALL: [PixelFilter; 3] = [PixelFilter::Center, PixelFilter::Box, PixelFilter::Tent];

    /// Its name: `center`, `box`, `tent`.
    pub fn name(&self) -> &'static str {
        match self {
            PixelFilter::Center => "center",
            PixelFilter::Box => "box",
            PixelFilter::Tent => "tent",
        }
    }

    /// The filter of a name.
    ///
    /// Errors: an unknown name (the message lists the valid ones).
    pub fn parse(name: &str) -> Result<Self> {
        Self::ALL
            .into_iter()
            .find(|f| f.name() == name)
            .ok_or_else(|| {
                Error::invalid(
                    "filter",
                    format!(
                        "{name:?} is not a pixel filter; valid filters are {}",
                        Self::ALL.map(|f| f.name()).join(", ")
                    ),
                )
            })
    }

    /// Offsets from the pixel centre (pixels) of `n` sub-pixel samples: a randomly shifted
    /// two-dimensional additive recurrence (Roberts' R2 sequence, so that the samples
    /// stratify the pixel), each sample marginally distributed as the filter (uniform over
    /// the pixel for the box; the tent by inverting its distribution per axis). Because each
    /// sample follows the filter, the plain average of the samples' radiance estimates the
    /// filtered pixel without bias. The centre filter gives `n` zero offsets.
    pub fn offsets(&self, n: u32, shift: [f64; 2]) -> Vec<[f64; 2]> {
        // 1 / g and 1 / g^2, g the plastic number (the R2 sequence).
        const A: [f64; 2] = [0.754_877_666_246_692_7, 0.569_840_290_998_053_3];
        (0..n)
            .map(|k| {
                let u = [0, 1].map(|c| (shift[c] + k as f64 * A[c]).fract());
                match self {
                    PixelFilter::Center => [0.0; 2],
                    PixelFilter::Box => u.map(|v| v - 0.5),
                    PixelFilter::Tent => u.map(|v| {
                        if v < 0.5 {
                            (2.0 * v).sqrt() - 1.0
                        } else {
                            1.0 - (2.0 - 2.0 * v).sqrt()
                        }
                    }),
                }
            })
            .collect()
    }
}

/// The default share of the unoccluded strategy's samples drawn from the pixel's own
/// nearest VPLs ([`ImportanceCachingParams::near_share`]).
pub const DEFAULT_NEAR_SHARE: f64 = 0.25;
/// The default number of those VPLs ([`ImportanceCachingParams::near_vpls`]).
pub const DEFAULT_NEAR_VPLS: usize = 32;

wscg_math::params! {
    /// Importance-caching parameters.
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct ImportanceCachingParams {
        /// Records (cache points): the budget of the adaptive placement, the count of the screen
        /// grid; 1 % of the pixels in the paper's scenes.
        pub n_cache: usize,
        /// Records mixed at a shading point (`M`), 3.
        pub m_nearest: usize,
        /// VPL samples per pixel (`N_s` of eq. 1), 16: shared out equally among the pixel
        /// samples and, at each, among the strategies available there.
        pub spp: u32,
        /// The pixel filter: box (default), tent, or one ray through the pixel centre (the
        /// paper's setting).
        pub filter: PixelFilter,
        /// Sub-pixel positions (primary rays) per pixel under the box and tent filters, 4;
        /// each gets `max(1, round(spp / pixel_samples))` VPL samples. The centre filter
        /// ignores it.
        pub pixel_samples: u32,
        /// Which of the four strategies (full, unoccluded, bounded, conservative) are used; the
        /// conservative one keeps the estimator unbiased.
        pub strategies: [bool; 4],
        /// Weights of the alpha-max heuristic, 1 each.
        pub alpha: [f64; 4],
        /// Beyond the paper: the share of the unoccluded strategy's samples drawn from the
        /// pixel's own distribution over the `near_vpls` VPLs nearest its first shading point,
        /// proportional to their contributions without visibility there (0.25; 0: the
        /// paper's strategy). A VPL close to a shading point but far from every record gets
        /// a tiny probability from the records' distributions, all computed farther away,
        /// while the geometry term makes its contribution there large: single bright pixels
        /// behind hard, repeated shadows. The share bounds those samples' weights, keeps the
        /// estimator unbiased, and costs a nearest-VPL search and `near_vpls` contribution
        /// evaluations per pixel (20-30 % more render time at the defaults).
        pub near_share: f64,
        /// VPLs of the pixel's own distribution (32).
        pub near_vpls: usize,
        /// Clamping distance of the geometry term (`None`: 1 % of the scene's diagonal; 0: none).
        pub clamp_dist: Option<f64>,
        /// Seed of the placement and the sampling.
        pub seed: u64,
        /// Largest memory for the distributions (bytes), 4 GiB.
        pub max_cache_bytes: usize,
    }
}

impl Default for ImportanceCachingParams {
    fn default() -> Self {
        Self {
            n_cache: 1000,
            m_nearest: 3,
            spp: 16,
            filter: PixelFilter::Box,
            pixel_samples: 4,
            strategies: [true; 4],
            alpha: [1.0; 4],
            near_share: DEFAULT_NEAR_SHARE,
            near_vpls: DEFAULT_NEAR_VPLS,
            clamp_dist: None,
            seed: 0,
            max_cache_bytes: 4 << 30,
        }
    }
}

impl ImportanceCachingParams {
    /// Errors: `n_cache = 0`, `m_nearest = 0`, `spp = 0`, `pixel_samples = 0`, no strategy, a negative or
    /// non-finite alpha, `near_share` outside `[0, 1)`, `near_vpls = 0`, a given `clamp_dist`
    /// negative or not finite.
    pub fn validate(&self) -> Result<()> {
        if self.n_cache == 0 {
            return Err(Error::invalid("n_cache", "at least one record is needed"));
        }
        if self.m_nearest == 0 {
            return Err(Error::invalid(
                "m_nearest",
                "at least one record per lookup",
            ));
        }
        if self.spp == 0 {
            return Err(Error::invalid(
                "spp",
                "at least one sample per pixel is needed",
            ));
        }
        if self.pixel_samples == 0 {
            return Err(Error::invalid(
                "pixel_samples",
                "at least one sample per pixel is needed",
            ));
        }
        if !self.strategies.iter().any(|s| *s) {
            return Err(Error::invalid(
                "strategies",
                "at least one strategy is needed",
            ));
        }
        if self.alpha.iter().any(|a| !(a.is_finite() && *a > 0.0)) {
            return Err(Error::invalid(
                "alpha",
                format!("must be finite and positive, got {:?}", self.alpha),
            ));
        }
        if !(0.0..1.0).contains(&self.near_share) {
            return Err(Error::invalid(
                "near_share",
                format!("must lie in [0, 1), got {}", self.near_share),
            ));
        }
        if self.near_vpls == 0 {
            return Err(Error::invalid(
                "near_vpls",
                "at least one VPL is needed for the pixel's own distribution",
            ));
        }
        if let Some(dc) = self.clamp_dist {
            if !(dc.is_finite() && dc >= 0.0) {
                return Err(Error::invalid(
                    "clamp_dist",
                    format!("must be finite and >= 0, got {dc}"),
                ));
            }
        }
        Ok(())
    }
}

/// What building a cache did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CacheStats {
    /// Final number of records.
    pub records: usize,
    /// Records of the initial placement.
    pub initial: usize,
    /// Records added by the adaptive insertion.
    pub inserted: usize,
    /// Insertion passes.
    pub passes: u32,
    /// Shadow rays traced for the full distributions.
    pub shadow_rays: u64,
    /// Bytes of the distributions.
    pub bytes: usize,
    /// Wall time (s).
    pub seconds: f64,
}

/// Builds the records of `placement` and their distributions.
///
/// Errors: invalid parameters, more records than valid pixels (adaptive placement), no
/// valid pixel, a cache larger than `max_cache_bytes`, invalid VPLs.
pub fn build_cache(
    scene: &Scene,
    g: &GBuffer,
    vpls: &[Vpl],
    placement: &Placement,
    interp: Interp,
    p: &ImportanceCachingParams,
) -> Result<(ImportanceCache, CacheStats)> {
    p.validate()?;
    interp.validate()?;
    let sh = Shading::new(scene, vpls, p.clamp_dist)?;
    let valid = g.valid();
    if valid == 0 {
        return Err(Error::invalid("gbuffer", "no pixel sees the scene"));
    }
    let bytes = p.n_cache as u128 * vpls.len() as u128 * 24;
    if bytes > p.max_cache_bytes as u128 {
        return Err(Error::LimitExceeded(format!(
            "{} records x {} VPLs need {:.2} GiB of distributions (limit {:.2} GiB)",
            p.n_cache,
            vpls.len(),
            bytes as f64 / (1u64 << 30) as f64,
            p.max_cache_bytes as f64 / (1u64 << 30) as f64
        )));
    }
    let t0 = Instant::now();
    let (cache, a) = match placement {
        Placement::RandomScreen => {
            let recs = random_screen(scene, g, p.n_cache, p.seed);
            if recs.is_empty() {
                return Err(Error::invalid("n_cache", "no record hit the scene"));
            }
            let n = recs.len();
            let c = ImportanceCache::build(&sh, recs, interp, p.m_nearest)?;
            (
                c,
                AdaptiveStats {
                    clusters: n,
                    ..AdaptiveStats::default()
                },
            )
        }
        Placement::Adaptive(a) => {
            if p.n_cache > valid {
                return Err(Error::invalid(
                    "n_cache",
                    format!(
                        "{} records but only {valid} pixels see the scene",
                        p.n_cache
                    ),
                ));
            }
            adaptive(&sh, g, p.n_cache, interp, p.m_nearest, a, p.seed)?
        }
    };
    let records = cache.records.len();
    let stats = CacheStats {
        records,
        initial: a.clusters.min(records),
        inserted: a.inserted,
        passes: a.passes,
        shadow_rays: (records * vpls.len()) as u64,
        bytes: cache.bytes(),
        seconds: t0.elapsed().as_secs_f64(),
    };
    Ok((cache, stats))
}

/// Rendered image (linear RGB, f32) of per-pixel values.
fn image(g: &GBuffer, px: Vec<Rgb>) -> Result<Image<f32>> {
    let data = px.into_iter().flat_map(|c| c.map(|v| v as f32)).collect();
    Image::new(g.height, g.width, 3, data)
}

fn add(a: &mut Rgb, b: &Rgb, s: f64) {
    for c in 0..3 {
        a[c] += b[c] * s;
    }
}

/// The estimate of eq. (1) at one shading point: for each available strategy `s`, `n_s`
/// VPLs drawn from its mixture over the records found; a sample counts (weight 1) when
/// `alpha_s p_s` is the largest of the strategies' mixture probabilities for that VPL (ties
/// to the first strategy), and adds `I / (n_s p_s)`. Every VPL of positive power is won by
/// exactly one strategy of positive probability, so the estimate is unbiased. With
/// `p.near_share = b > 0` and a non-empty `near` the unoccluded strategy's probability is
/// `(1 - b) p_unoccluded + b p_near`, `p_near` the distribution `near` over the VPLs nearest
/// the pixel ([`NearVpls::distribution`], sorted by VPL); it is still one
/// strategy's probability, sampled as the mixture it is.
pub fn estimate(
    sh: &Shading,
    cache: &ImportanceCache,
    x: &ShadingPoint,
    p: &ImportanceCachingParams,
    near: &[(usize, f64)],
    rng: &mut impl Rng,
) -> Rgb {
    let mut out = x.emitted;
    let r = x.receiver();
    let found = cache.lookup(r.pos, r.normal, None);
    let mut mix: [Lookup; 4] = Default::default();
    let mut avail = [false; 4];
    for s in 0..4 {
        if !p.strategies[s] {
            continue;
        }
        if s == CONSERVATIVE {
            avail[s] = cache.n_positive > 0;
        } else {
            mix[s] = cache.mixture(&found, s);
            avail[s] = !mix[s].is_empty();
        }
    }
    let n_avail = avail.iter().filter(|a| **a).count();
    if n_avail == 0 {
        return out;
    }
    let n_s = ((p.spp as f64 / n_avail as f64).round() as u32).max(1);
    let beta = if near.is_empty() || !avail[UNOCCLUDED] {
        0.0
    } else {
        p.near_share
    };
    let pdf = |t: usize, j: usize| {
        let q = cache.pdf(&mix[t], t, j);
        if t == UNOCCLUDED && beta > 0.0 {
            let own = near
                .binary_search_by_key(&j, |e| e.0)
                .map_or(0.0, |i| near[i].1);
            (1.0 - beta) * q + beta * own
        } else {
            q
        }
    };
    for s in 0..4 {
        if !avail[s] {
            continue;
        }
        for k in 0..n_s {
            if k % 1024 == 1023 && wscg_math::cancel::requested() {
                break;
            }
            let (u1, u2): (f64, f64) = (rng.random(), rng.random());
            let drawn = if s == UNOCCLUDED && u1 < beta {
                sample_list(near, u2)
            } else if s == UNOCCLUDED && beta > 0.0 {
                cache.sample(&mix[s], s, (u1 - beta) / (1.0 - beta), u2)
            } else {
                cache.sample(&mix[s], s, u1, u2)
            };
            let Some(j) = drawn else {
                continue;
            };
            let ps = p.alpha[s] * pdf(s, j);
            if ps <= 0.0 {
                continue;
            }
            let wins = (0..4).filter(|&t| t != s && avail[t]).all(|t| {
                let pt = p.alpha[t] * pdf(t, j);
                if t < s {
                    pt < ps
                } else {
                    pt <= ps
                }
            });
            if wins {
                let i = sh.contribution(&r, j);
                add(&mut out, &i, p.alpha[s] / (n_s as f64 * ps));
            }
        }
    }
    out
}

/// Renders with the importance cache: [`estimate`] at every pixel sample of `p.filter`
/// (`max(1, round(spp / pixel_samples))` VPL samples at each of `pixel_samples` sub-pixel
/// shading points for the box and tent filters, `spp` at the G-buffer's pixel centre for the
/// centre filter), a random stream per pixel, so the image does not depend on the thread
/// count. The cache itself is built at the pixel centres.
///
/// Errors: invalid parameters or VPLs.
pub fn render(
    scene: &Scene,
    g: &GBuffer,
    vpls: &[Vpl],
    cache: &ImportanceCache,
    p: &ImportanceCachingParams,
    progress: &dyn Progress,
) -> Result<Image<f32>> {
    p.validate()?;
    let sh = Shading::new(scene, vpls, p.clamp_dist)?;
    if cache.positive.len() != vpls.len() {
        return Err(Error::ShapeMismatch(format!(
            "the cache was built for {} VPLs, not {}",
            cache.positive.len(),
            vpls.len()
        )));
    }
    let sub = sub_params(p);
    let nearest = (p.near_share > 0.0 && p.strategies[UNOCCLUDED])
        .then(|| NearVpls::new(&sh))
        .transpose()?;
    // The near-VPL distribution of a pixel is computed at its first shading point and shared
    // by the others (a fixed distribution per pixel keeps each estimate unbiased).
    filtered(scene, g, p, 0x1c_0000_0000, progress, |x, near, rng| {
        let near = near.get_or_insert_with(|| {
            nearest.as_ref().map_or_else(Vec::new, |n| {
                n.distribution(&sh, &x.receiver(), sub.near_vpls)
            })
        });
        estimate(&sh, cache, x, &sub, near, rng)
    })
}

/// The parameters of one pixel sample: `spp` shared out among the pixel samples.
fn sub_params(p: &ImportanceCachingParams) -> ImportanceCachingParams {
    let mut q = *p;
    if p.filter != PixelFilter::Center {
        q.spp = ((p.spp as f64 / p.pixel_samples as f64).round() as u32).max(1);
    }
    q
}

/// Runs `f` at every pixel's samples under `p.filter` (a random stream per pixel from
/// `p.seed ^ salt`, so the image does not depend on the thread count): the centre filter at
/// the G-buffer's valid pixels; the box and tent filters at `p.pixel_samples` sub-pixel
/// shading points ([`PixelFilter::offsets`]), averaged, a primary ray that misses counting
/// as black. `f` gets a state per pixel (`None` at the pixel's first shading point).
fn filtered<S>(
    scene: &Scene,
    g: &GBuffer,
    p: &ImportanceCachingParams,
    salt: u64,
    progress: &dyn Progress,
    f: impl Fn(&ShadingPoint, &mut Option<S>, &mut wscg_math::rng::Rng) -> Rgb + Sync,
) -> Result<Image<f32>> {
    let stream = |i: usize| wscg_math::rng::stream(p.seed ^ salt, i as u64);
    if p.filter == PixelFilter::Center {
        return per_pixel(g, progress, true, |i| {
            g.points[i].map_or([0.0; 3], |x| f(&x, &mut None, &mut stream(i)))
        });
    }
    per_pixel(g, progress, false, |i| {
        let mut rng = stream(i);
        let shift = [rng.random(), rng.random()];
        let (cx, cy) = ((i % g.width) as f64 + 0.5, (i / g.width) as f64 + 0.5);
        let mut out = [0.0; 3];
        let mut state = None;
        let n = p.pixel_samples;
        for [dx, dy] in p.filter.offsets(n, shift) {
            if let Some(x) = shade_point(scene, &g.frame, cx + dx, cy + dy, 1.0) {
                add(&mut out, &f(&x, &mut state, &mut rng), 1.0 / n as f64);
            }
        }
        out
    })
}

/// Runs `f` on every pixel (`valid_only`: those of the G-buffer with a shading point) in
/// parallel, rows reported to `progress`.
fn per_pixel(
    g: &GBuffer,
    progress: &dyn Progress,
    valid_only: bool,
    f: impl Fn(usize) -> Rgb + Sync,
) -> Result<Image<f32>> {
    progress.begin("rendering rows", g.height as u64);
    let rows: Vec<Vec<Rgb>> = (0..g.height)
        .into_par_iter()
        .map(|y| {
            // After a cancellation request the remaining pixels are skipped (and reported).
            let row = (y * g.width..(y + 1) * g.width)
                .map(|i| {
                    let skip = valid_only && g.points[i].is_none();
                    if skip || wscg_math::cancel::requested() {
                        [0.0; 3]
                    } else {
                        f(i)
                    }
                })
                .collect();
            progress.advance(1);
            row
        })
        .collect();
    progress.finish();
    wscg_math::cancel::check()?;
    image(g, rows.into_iter().flatten().collect())
}

/// The all-VPL reference at the pixel centres: emitted radiance plus every VPL's
/// contribution (one shadow ray per VPL and pixel).
///
/// Errors: invalid VPLs or clamping distance.
pub fn render_reference(
    scene: &Scene,
    g: &GBuffer,
    vpls: &[Vpl],
    clamp_dist: Option<f64>,
    progress: &dyn Progress,
) -> Result<Image<f32>> {
    let p = ImportanceCachingParams::default()
        .clamp_dist(clamp_dist)
        .filter(PixelFilter::Center);
    render_reference_filtered(scene, g, vpls, &p, progress)
}

/// The all-VPL reference under the pixel filter `p.filter` (`p.pixel_samples` sub-pixel
/// shading points per pixel, seeded by `p.seed`; `p.clamp_dist`): each sample's emitted
/// radiance plus every VPL's contribution. With many pixel samples this is the brute-force
/// box- (or tent-) filtered image.
///
/// Errors: invalid parameters, VPLs or clamping distance.
pub fn render_reference_filtered(
    scene: &Scene,
    g: &GBuffer,
    vpls: &[Vpl],
    p: &ImportanceCachingParams,
    progress: &dyn Progress,
) -> Result<Image<f32>> {
    p.validate()?;
    let sh = Shading::new(scene, vpls, p.clamp_dist)?;
    filtered(
        scene,
        g,
        p,
        0x7e_0000_0000,
        progress,
        |x, _: &mut Option<()>, _| {
            let mut out = x.emitted;
            add(&mut out, &sh.sum_all(&x.receiver()), 1.0);
            out
        },
    )
}

/// The baseline without a cache, under the pixel filter `p.filter`: `spp` VPLs per pixel
/// (shared out among the pixel samples) drawn in proportion to their
/// luminous intensity (`power psi`).
///
/// Errors: invalid VPLs or parameters, VPLs of zero power only.
pub fn render_power(
    scene: &Scene,
    g: &GBuffer,
    vpls: &[Vpl],
    p: &ImportanceCachingParams,
    progress: &dyn Progress,
) -> Result<Image<f32>> {
    p.validate()?;
    let sh = Shading::new(scene, vpls, p.clamp_dist)?;
    let w: Vec<f64> = sh.intensity.iter().map(luminance).collect();
    let pmf = Pmf::new(&w).ok_or_else(|| Error::invalid("vpls", "every VPL has zero power"))?;
    let sub = sub_params(p);
    filtered(
        scene,
        g,
        p,
        0x90_0000_0000,
        progress,
        |x, _: &mut Option<()>, rng| {
            let mut out = x.emitted;
            let r = x.receiver();
            for k in 0..sub.spp {
                if k % 1024 == 1023 && wscg_math::cancel::requested() {
                    break;
                }
                let j = pmf.sample(rng.random());
                let i = sh.contribution(&r, j);
                add(&mut out, &i, 1.0 / (sub.spp as f64 * pmf.pdf(j)));
            }
            out
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pixel_offsets_follow_their_filter() {
        let mut rng = wscg_math::rng::seeded(7);
        let (mut box_hist, mut tent_abs, mut n) = ([0usize; 10], 0.0, 0);
        for _ in 0..4000 {
            let shift = [rng.random(), rng.random()];
            for [dx, dy] in PixelFilter::Box.offsets(5, shift) {
                assert!((-0.5..0.5).contains(&dx) && (-0.5..0.5).contains(&dy));
                box_hist[((dx + 0.5) * 10.0) as usize] += 1;
            }
            for [dx, dy] in PixelFilter::Tent.offsets(5, shift) {
                assert!((-1.0..=1.0).contains(&dx) && (-1.0..=1.0).contains(&dy));
                tent_abs += dx.abs() + dy.abs();
                n += 2;
            }
            assert_eq!(PixelFilter::Center.offsets(3, shift), vec![[0.0; 2]; 3]);
        }
        // Box: uniform (2000 per tenth); tent: E|dx| = 1/3.
        assert!(
            box_hist.iter().all(|c| (1800..=2200).contains(c)),
            "{box_hist:?}"
        );
        assert!((tent_abs / n as f64 - 1.0 / 3.0).abs() < 0.01);
        for f in PixelFilter::ALL {
            assert_eq!(PixelFilter::parse(f.name()).unwrap(), f);
        }
        assert!(PixelFilter::parse("gauss").is_err());
    }
}
