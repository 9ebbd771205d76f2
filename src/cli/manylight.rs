//! `wscg raytrace manylight`: paper 08 (many-light rendering with adaptive importance
//! caching) on a procedural scene or the user's OBJ + MTL scene.
//!
//! Writes the linear radiance as OpenEXR (`.exr`) or a display image (`.png`, sRGB of the
//! radiance times the exposure); `--compare` renders the reference and every method on the
//! same VPLs, the baseline with the adaptive run's final record count, and prints the
//! paper's table (records, cache and render seconds, RMSE against the reference).

use std::path::{Path, PathBuf};

use clap::{Args, ValueEnum};
use nalgebra::Vector3;
use wscg_math::image::Image;
use wscg_math::progress::NoProgress;
use wscg_math::{Error, Result};
use wscg_raytrace::manylight::{
    generate_vpls, load_obj, run_with, scenes, trace_primary, Camera, Method, Output, Scene,
    Settings,
};
use wscg_raytrace::spectral::srgb_oetf;

use super::progress::Bars;

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum SceneName {
    /// The Cornell box (the paper's Fig. 3).
    Cornell,
    /// A hall of pillars lit through a roof opening (Sponza stand-in).
    Colonnade,
    /// A room with a table and chairs (Conference stand-in).
    Conference,
    /// A plane under a tiny light (closed form).
    Plane,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum MethodName {
    /// The paper: clustering, adaptive insertion, similarity weights.
    Adaptive,
    /// The paper's ablation: its records with uniform weights.
    AdaptiveUniform,
    /// Importance caching (Georgiev 2012): screen-grid records, uniform weights.
    Ic,
    /// VPLs drawn by power, no cache.
    Power,
    /// Every VPL at every pixel.
    Reference,
}

impl MethodName {
    fn method(self) -> Method {
        match self {
            MethodName::Adaptive => Method::Adaptive,
            MethodName::AdaptiveUniform => Method::AdaptiveUniform,
            MethodName::Ic => Method::Ic,
            MethodName::Power => Method::Power,
            MethodName::Reference => Method::Reference,
        }
    }
}

#[derive(Args, Debug)]
pub struct ManyLightArgs {
    /// OBJ scene (MTL `Kd` albedo, `Ke` emission); give the camera with --eye/--target.
    obj: Option<PathBuf>,
    /// Built-in scene (when no OBJ is given).
    #[arg(long, value_enum, default_value_t = SceneName::Cornell)]
    scene: SceneName,
    /// Quad subdivision of the built-in scene (more triangles, same picture).
    #[arg(long, default_value_t = 1)]
    subdiv: u32,
    /// Method.
    #[arg(long, value_enum, default_value_t = MethodName::Adaptive)]
    method: MethodName,
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
    /// VPL samples per pixel.
    #[arg(long, default_value_t = 16)]
    spp: u32,
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
                eye: c + Vector3::new(0.0, 0.3 * r, 2.2 * r),
                target: c,
                up: Vector3::y(),
                fov_deg: 45.0,
                width: a.width,
                height: a.height,
            };
            (s, cam)
        }
        None => match a.scene {
            SceneName::Cornell => scenes::cornell_box(a.subdiv, a.width, a.height)?,
            SceneName::Colonnade => scenes::colonnade(a.subdiv, a.width, a.height)?,
            SceneName::Conference => scenes::conference_room(a.subdiv, a.width, a.height)?,
            SceneName::Plane => scenes::plane_with_light(a.subdiv, a.width, a.height)?,
        },
    };
    let v = |o: &Option<Vec<f64>>, d: Vector3<f64>| {
        o.as_ref().map_or(d, |v| Vector3::new(v[0], v[1], v[2]))
    };
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
    let exr = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
    if exr {
        img.save(path)
    } else {
        img.map(|v| srgb_oetf((v as f64 * exposure).clamp(0.0, 1.0)) as f32)
            .save(path)
    }
}

/// `path` with `_suffix` added to its stem.
fn suffixed(path: &Path, suffix: &str) -> PathBuf {
    let stem = path
        .file_stem()
        .map_or("out".into(), |s| s.to_string_lossy());
    let ext = path
        .extension()
        .map_or("exr".into(), |s| s.to_string_lossy());
    path.with_file_name(format!("{stem}_{suffix}.{ext}"))
}

fn report(o: &Output, method: Method, rmse: Option<f64>) {
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
    if !(a.exposure.is_finite() && a.exposure > 0.0) {
        return Err(Error::invalid("exposure", "must be finite and positive"));
    }
    let (scene, cam) = scene_of(a)?;
    let mut s = Settings::default();
    s.vpl.n_paths = a.vpl_paths;
    s.vpl.max_bounces = a.max_bounces;
    s.ic.spp = a.spp;
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
        let m = a.method.method();
        let o = run_with(&scene, &g, &vpls, m, &s, &Bars::new(m.name()), 0.0)?;
        report(&o, m, None);
        return save(&o.image, a.exposure, &a.out);
    }
    let reference = run_with(
        &scene,
        &g,
        &vpls,
        Method::Reference,
        &s,
        &Bars::new("reference"),
        0.0,
    )?;
    report(&reference, Method::Reference, None);
    save(&reference.image, a.exposure, &suffixed(&a.out, "reference"))?;
    let mut records = s.ic.n_cache;
    for m in [
        Method::Adaptive,
        Method::AdaptiveUniform,
        Method::Ic,
        Method::Power,
    ] {
        let mut st = s;
        if m == Method::Ic {
            // The baseline gets the same number of records as the paper's method.
            st.ic.n_cache = records;
        }
        let o = run_with(&scene, &g, &vpls, m, &st, &NoProgress, 0.0)?;
        if m == Method::Adaptive {
            records = o.records.len().max(1);
        }
        let e = wscg_math::metrics::rmse(o.image.data(), reference.image.data())?;
        report(&o, m, Some(e));
        save(&o.image, a.exposure, &suffixed(&a.out, m.name()))?;
    }
    Ok(())
}
