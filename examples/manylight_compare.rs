//! Paper 08 example: the colonnade (a stand-in for the paper's Sponza) rendered with the
//! all-VPL reference, the paper's adaptive importance caching, its ablation with uniform
//! weights and importance caching (Georgiev 2012) at equal record count and samples, with
//! the RMSE and the time of each, as in the paper's Table 1. Writes `manylight_<method>.exr`.
//!
//! Run: `cargo run --release --example manylight_compare [width height]`.

use wscg::raytrace::manylight::{
    compare, generate_vpls, run_with, scenes, trace_primary, ManyLightParams, Method, VplParams,
};
use wscg_math::progress::NoProgress;

fn main() -> wscg_math::Result<()> {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    let (w, h) = (*args.first().unwrap_or(&256), *args.get(1).unwrap_or(&192));
    let (scene, cam) = scenes::colonnade(1, w, h)?;
    let mut s = ManyLightParams::default().vpl(VplParams::default().n_paths(1400));
    s.ic.n_cache = (w * h / 100).max(1);
    let vpls = generate_vpls(&scene, &s.vpl)?;
    let g = trace_primary(&scene, &cam)?;
    let reference = run_with(&scene, &g, &vpls, Method::Reference, &s, &NoProgress, 0.0)?;
    println!(
        "colonnade {w} x {h}: {} triangles, {} VPLs; reference {:.2} s",
        scene.len(),
        vpls.len(),
        reference.render_seconds
    );
    reference.image.save("manylight_reference.exr")?;
    let methods = [Method::Adaptive, Method::AdaptiveUniform, Method::Ic];
    for (m, o) in compare(&scene, &g, &vpls, &methods, &s, &NoProgress)? {
        o.image.save(format!("manylight_{}.exr", m.name()))?;
        let e = wscg_math::metrics::rmse(o.image.data(), reference.image.data())?;
        println!(
            "{:<17} records {:>5}  cache {:>6.3} s  render {:>6.3} s  RMSE {e:.5}",
            m.name(),
            o.records.len(),
            o.cache_seconds,
            o.render_seconds
        );
    }
    Ok(())
}
