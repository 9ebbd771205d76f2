//! `wscg raytrace manylight`: paper 08 (many-light rendering with adaptive importance
//! caching) on a procedural scene or the user's OBJ + MTL scene.
//!
//! Writes the linear radiance as OpenEXR (`.exr`) or a display image (`.png`, sRGB of the
//! radiance times the exposure); `--compare` renders the reference and every method on the
//! same VPLs, the baseline with the adaptive run's final record count, and prints the
//! paper's table (records, cache and render seconds, RMSE against the reference).

use std::path::{Path, PathBuf};

use clap::Args;
use wscg_math::image::Image;
use wscg_math::vec3::add;
use wscg_math::{Error, Result};
use wscg_raytrace::manylight::{
    compare, generate_vpls, load_obj, run_with, scenes, to_display, trace_primary, Camera,
    ManyLightParams, ManyLightResult, Method, PixelFilter, Scene, DEFAULT_DEFENSIVE,
    DEFAULT_NEAR_SHARE, DEFAULT_NEAR_VPLS,
};

use crate::progress::Bars;

#[derive(Args, Debug)]
pub struct ManyLightArgs {
    /// OBJ scene (MTL `Kd` albedo, `Ke` emission); give the camera with --eye/--target.
    obj: Option<PathBuf>,
    /// Built-in scene when no OBJ is given: cornell (the paper's Fig. 3), colonnade (Sponza
    /// stand-in), conference (Conference stand-in), plane (closed form).
    #[arg(long, default_value = "cornell")]
    scene: String,
    /// Quad subdivision of the built-in scene (more triangles, same picture).
    #[arg(long, default_value_t = 1)]
    subdiv: u32,
    /// Method: adaptive (the paper), adaptive_uniform (its ablation), ic (importance caching),
    /// power (no cache), reference (every VPL).
    #[arg(long, default_value = "adaptive", value_parser = Method::parse)]
    method: Method,
    /// Image width.
    #[arg(long, default_value_t = 512)]
    width: usize,
    /// Image height.
    #[arg(long, default_value_t = 384)]
    height: usize,
    /// Camera position (x y z); default the scene's camera.
    #[arg(long, num_args = 3, allow_negative_numbers = true)]
    eye: Option<Vec<f64>>,
    /// Point looked at (x y z).
    #[arg(long, num_args = 3, allow_negative_numbers = true)]
    target: Option<Vec<f64>>,
    /// Up direction (x y z).
    #[arg(long, num_args = 3, allow_negative_numbers = true)]
    up: Option<Vec<f64>>,
    /// Vertical field of view (degrees).
    #[arg(long)]
    fov: Option<f64>,
    /// Light paths traced from the emitters (one VPL per vertex).
    #[arg(long, default_value_t = 1500)]
    vpl_paths: usize,
    /// Bounces per light path.
    #[arg(long, default_value_t = 2)]
    max_bounces: u32,
    /// Records (default 1 % of the pixels).
    #[arg(long)]
    n_cache: Option<usize>,
    /// VPL samples per pixel (shared out among the pixel samples).
    #[arg(long, default_value_t = 16)]
    spp: u32,
    /// Pixel filter: box (sub-pixel positions uniform over the pixel, as a film renderer's
    /// pixels), tent (radius one pixel) or center (one ray through the pixel centre, the
    /// paper's setting).
    #[arg(long, default_value = "box", value_parser = PixelFilter::parse)]
    filter: PixelFilter,
    /// Sub-pixel positions per pixel under the box and tent filters.
    #[arg(long, default_value_t = 4)]
    pixel_samples: u32,
    /// Defensive share of the similarity weights (adaptive method): the weights of eqs.
    /// (2)-(4) blended with the uniform ones, (1 - c) w + c u, so that no VPL's probability
    /// falls below c times the uniform weights' one; 0 gives the paper's weights.
    #[arg(long, default_value_t = DEFAULT_DEFENSIVE)]
    defensive: f64,
    /// Beyond the paper: share of the unoccluded strategy's VPL samples drawn from each
    /// pixel's own distribution over its nearest VPLs, which removes the single bright
    /// pixels next to VPLs far from every record (20-30 % more render time); 0 gives the
    /// paper's strategies.
    #[arg(long, default_value_t = DEFAULT_NEAR_SHARE)]
    near_share: f64,
    /// VPLs of that distribution.
    #[arg(long, default_value_t = DEFAULT_NEAR_VPLS)]
    near_vpls: usize,
    /// Clamping distance of the geometry term (default 1 % of the scene's diagonal; 0: none).
    #[arg(long)]
    clamp: Option<f64>,
    /// Seed of the records and samples.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Exposure of a PNG output.
    #[arg(long, default_value_t = 1.0)]
    exposure: f64,
    /// Render the reference and every method; print the table; write OUT_<method>.
    #[arg(long)]
    compare: bool,
    /// Output image: .exr (linear radiance) or .png (sRGB display).
    #[arg(long)]
    out: PathBuf,
}

/// The scene and camera of the arguments.
fn scene_of(a: &ManyLightArgs) -> Result<(Scene, Camera)> {
    let (scene, base) = match &a.obj {
        Some(path) => {
            let s = load_obj(path)?;
            let b = s.bounds();
            let c = b.centre();
            let r = 0.5 * s.diagonal();
            let cam = Camera {
                eye: add(c, [0.0, 0.3 * r, 2.2 * r]),
                target: c,
                up: [0.0, 1.0, 0.0],
                fov_deg: 45.0,
                width: a.width,
                height: a.height,
            };
            (s, cam)
        }
        None => scenes::by_name(&a.scene, a.subdiv, a.width, a.height)?,
    };
    let v = |o: &Option<Vec<f64>>, d: [f64; 3]| o.as_ref().map_or(d, |v| [v[0], v[1], v[2]]);
    let cam = Camera {
        eye: v(&a.eye, base.eye),
        target: v(&a.target, base.target),
        up: v(&a.up, base.up),
        fov_deg: a.fov.unwrap_or(base.fov_deg),
        ..base
    };
    cam.frame()?;
    Ok((scene, cam))
}

/// Writes linear radiance as EXR, or as a display image for other extensions.
fn save(img: &Image<f32>, exposure: f64, path: &Path) -> Result<()> {
    if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"))
    {
        img.save(path)
    } else {
        to_display(img, exposure).save(path)
    }
}

fn report(o: &ManyLightResult, method: Method, rmse: Option<f64>) {
    let records = o.cache.as_ref().map_or(0, |c| c.records);
    let inserted = o.cache.as_ref().map_or(0, |c| c.inserted);
    println!(
        "{:<17} {:>8} {:>9} {:>9.3} {:>9.3} {:>12}",
        method.name(),
        records,
        inserted,
        o.cache_seconds,
        o.render_seconds,
        rmse.map_or("-".into(), |r| format!("{r:.6}"))
    );
}

/// Runs `wscg raytrace manylight`.
pub fn run(a: &ManyLightArgs) -> Result<()> {
    crate::commands::overwrite::check_file("out", &a.out, &a.obj)?;
    if !(a.exposure.is_finite() && a.exposure > 0.0) {
        return Err(Error::invalid("exposure", "must be finite and positive"));
    }
    let (scene, cam) = scene_of(a)?;
    let mut s = ManyLightParams::default();
    s.vpl.n_paths = a.vpl_paths;
    s.vpl.max_bounces = a.max_bounces;
    s.ic.spp = a.spp;
    s.ic.filter = a.filter;
    s.ic.pixel_samples = a.pixel_samples;
    s.ic.near_share = a.near_share;
    s.ic.near_vpls = a.near_vpls;
    s.weights = s.weights.with_defensive(a.defensive);
    s.ic.seed = a.seed;
    s.ic.clamp_dist = a.clamp;
    s.ic.n_cache = a.n_cache.unwrap_or((cam.width * cam.height / 100).max(1));
    let vpls = generate_vpls(&scene, &s.vpl)?;
    let g = trace_primary(&scene, &cam)?;
    println!(
        "{} triangles ({} emitting), {} VPLs, {} x {} px, {} of them on the scene",
        scene.len(),
        scene.emitters().len(),
        vpls.len(),
        cam.width,
        cam.height,
        g.valid()
    );
    println!(
        "{:<17} {:>8} {:>9} {:>9} {:>9} {:>12}",
        "method", "records", "inserted", "cache s", "render s", "RMSE"
    );
    if !a.compare {
        let o = run_with(
            &scene,
            &g,
            &vpls,
            a.method,
            &s,
            &Bars::new(a.method.name()),
            0.0,
        )?;
        report(&o, a.method, None);
        return save(&o.image, a.exposure, &a.out);
    }
    let methods = [
        Method::Reference,
        Method::Adaptive,
        Method::AdaptiveUniform,
        Method::Ic,
        Method::Power,
    ];
    let all = compare(&scene, &g, &vpls, &methods, &s, &Bars::new("compare"))?;
    let reference = &all[0].1.image;
    let ext = a
        .out
        .extension()
        .map_or("exr".into(), |e| e.to_string_lossy());
    for (m, o) in &all {
        let e = (*m != Method::Reference)
            .then(|| wscg_math::metrics::rmse(o.image.data(), reference.data()))
            .transpose()?;
        report(o, *m, e);
        save(
            &o.image,
            a.exposure,
            &super::sibling(&a.out, &format!("_{}", m.name()), &ext),
        )?;
    }
    Ok(())
}
