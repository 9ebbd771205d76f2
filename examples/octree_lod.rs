//! Paper 10 on the synthetic scenes: the memory of the early-stop octree against the full
//! octree (Table 2) and the time of a fly-through in the three trace modes (Table 3), with the
//! BVH baseline on the same primary rays.
//!
//! `cargo run --release --example octree_lod [-- --quick]`

use std::time::Instant;

use wscg_octree::{build, render, scenes, BuildParams, Camera, PointLight, Shading, TraceMode, TriangleBvh};

fn mb(b: usize) -> f64 {
    b as f64 / (1024.0 * 1024.0)
}

fn main() -> wscg_math::Result<()> {
    let quick = std::env::args().any(|a| a == "--quick");
    let scenes: Vec<(&str, wscg_math::TriMesh)> = vec![
        ("atrium", scenes::atrium(10)?),
        ("city", scenes::city(40, 7)?),
        ("blob", scenes::blob(if quick { 6 } else { 8 })?),
        ("forest", if quick { scenes::forest(13, 4, 8, 3)? } else { scenes::forest(13, 6, 64, 3)? }),
    ];
    println!("Table 2 (MB): nodes / triangles / tri-index / voxels / total");
    for (name, mesh) in &scenes {
        let t = Instant::now();
        let (full, fs) = build(mesh, &BuildParams { early_stop: false, ..Default::default() })?;
        let tf = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let (early, es) = build(mesh, &BuildParams::default())?;
        let te = t.elapsed().as_secs_f64();
        let (a, b) = (full.memory_report(), early.memory_report());
        println!(
            "{name:7} {:>9} tris  full {:7.2} / {:7.2} / {:6.2} / {:7.2} / {:7.2} ({tf:.2} s)  early {:7.2} / {:7.2} / {:6.2} / {:7.2} / {:7.2} ({te:.2} s)  saved {:5.2}%  fragments {}",
            mesh.faces.len(),
            mb(a.nodes), mb(a.triangles), mb(a.tri_index), mb(a.voxels), mb(a.total),
            mb(b.nodes), mb(b.triangles), mb(b.tri_index), mb(b.voxels), mb(b.total),
            100.0 * b.saving_against(&a),
            es.fragments,
        );
        let _ = fs;
    }
    // Fly-through of the forest: near to far.
    let (name, mesh) = &scenes[3];
    let (oct, _) = build(mesh, &BuildParams::default())?;
    let bvh = TriangleBvh::build(mesh)?;
    let c = oct.cube;
    let centre = [0, 1, 2].map(|k| (c.min[k] + 0.5 * c.size) as f32);
    let light = PointLight { position: [centre[0] + c.size as f32, centre[1] - c.size as f32, 3.0 * c.size as f32], intensity: 1.0 };
    let frames = if quick { 8 } else { 50 };
    let res = if quick { 256 } else { 1024 };
    let mut totals = [0f64; 4];
    for f in 0..frames {
        let a = f as f32 / frames as f32 * std::f32::consts::TAU;
        let dist = c.size as f32 * (0.8 + 8.0 * f as f32 / frames as f32);
        let cam = Camera {
            eye: [centre[0] + dist * a.cos(), centre[1] + dist * a.sin(), 0.3 * dist + 0.5],
            target: [centre[0], centre[1], 0.5],
            up: [0.0, 0.0, 1.0],
            fov_y_deg: 45.0,
            width: res,
            height: res,
        };
        for (i, mode) in [TraceMode::VOXELS, TraceMode::Triangles, TraceMode::HYBRID].iter().enumerate() {
            let (_, st) = render(&oct, &cam, &light, mode, &Shading::default())?;
            totals[i] += st.seconds;
        }
        let frame = cam.frame()?;
        let t = Instant::now();
        use rayon::prelude::*;
        let hits: usize = (0..res * res)
            .into_par_iter()
            .filter(|i| bvh.intersect(&cam.ray(&frame, i % res, i / res)).is_some())
            .count();
        totals[3] += t.elapsed().as_secs_f64();
        let _ = hits;
    }
    println!(
        "Table 3 ({name}, {frames} frames, {res}^2, shadows; BVH: primary rays only): fps voxels {:.2}  triangles {:.2}  hybrid {:.2}  hybrid/triangles {:.2}x  BVH primary {:.2}",
        frames as f64 / totals[0],
        frames as f64 / totals[1],
        frames as f64 / totals[2],
        totals[1] / totals[2],
        frames as f64 / totals[3]
    );
    Ok(())
}
