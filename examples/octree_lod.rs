//! Paper 10 in a few lines: build the unified triangle/voxel octree of a scene with and without
//! early stop, compare the memory (the paper's Table 2 columns), cast a far view in the three
//! trace modes and with the BVH baseline, and save the tree.
//!
//! `cargo run --release --example octree_lod [-- blob|atrium|city|forest]` (default: forest,
//! 1.4 M triangles; `wscg demo octree` runs the paper's full tables).

use std::time::Instant;

use rayon::prelude::*;
use wscg_octree::{build, render, scenes, BuildParams, Shading, TraceMode, TriangleBvh};

fn main() -> wscg_math::Result<()> {
    let name = std::env::args().nth(1).unwrap_or_else(|| "forest".into());
    let mesh = match name.as_str() {
        "blob" => scenes::blob(8)?,
        "atrium" => scenes::atrium(10)?,
        "city" => scenes::city(40, 7)?,
        _ => scenes::forest(13, 6, 64, 3)?,
    };
    let (full, _) = build(&mesh, &BuildParams::default().early_stop(false))?;
    let (oct, stats) = build(&mesh, &BuildParams::default())?;
    let (a, b) = (full.memory_report(), oct.memory_report());
    println!(
        "{name}: {} triangles, {} fragments, build {:.2} s; memory full {:.1} MB, early stop {:.1} MB (saved {:.1}%)",
        mesh.faces.len(),
        stats.fragments,
        stats.voxelize_s + stats.hierarchy_s + stats.attributes_s,
        a.total as f64 / 1048576.0,
        b.total as f64 / 1048576.0,
        100.0 * b.saving_against(&a)
    );
    let cam = scenes::orbit_path(&oct.cube, 1, 5.0, 5.0, 1024)[0];
    let light = scenes::default_light(&oct.cube);
    for (label, mode) in [
        ("voxels", TraceMode::VOXELS),
        ("triangles", TraceMode::Triangles),
        ("hybrid", TraceMode::HYBRID),
    ] {
        let (_, st) = render(&oct, &cam, &light, &mode, &Shading::default())?;
        println!(
            "far view 1024^2, {label:9}: {:.1} ms ({} triangle hits, {} voxel hits)",
            1e3 * st.seconds,
            st.triangle_hits,
            st.voxel_hits
        );
    }
    let bvh = TriangleBvh::build(&mesh)?;
    let rays = cam.ray_gen(&cam.frame()?);
    let t = Instant::now();
    let hits = (0..1024 * 1024)
        .into_par_iter()
        .filter(|i| bvh.intersect(&rays.ray(i % 1024, i / 1024)).is_some())
        .count();
    println!(
        "BVH baseline, primary rays only: {:.1} ms ({hits} hits)",
        1e3 * t.elapsed().as_secs_f64()
    );
    let path = std::env::temp_dir().join(format!("wscg-octree-{name}.bin"));
    oct.save(&path)?;
    println!(
        "saved to {} (render it with `wscg octree render`)",
        path.display()
    );
    Ok(())
}
