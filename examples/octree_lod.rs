//! Paper 10 on the synthetic scenes: the memory of the early-stop octree against the full
//! octree (Table 2), build times, and fly-throughs of the forest in the three trace modes
//! (Table 3) with the BVH baseline on the same primary rays.
//!
//! `cargo run --release --example octree_lod [-- --quick]`

use std::time::Instant;

use rayon::prelude::*;
use wscg_octree::{
    build, render, scenes, BuildParams, Camera, HybridOctree, Shading, TraceMode, TriangleBvh,
};

fn mb(b: usize) -> f64 {
    b as f64 / (1024.0 * 1024.0)
}

/// Seconds per mode (voxels, triangles, hybrid, hybrid with small leaves as voxels, BVH
/// primary rays only) summed over `path`.
fn fly(oct: &HybridOctree, bvh: &TriangleBvh, path: &[Camera]) -> wscg_math::Result<[f64; 5]> {
    let light = scenes::default_light(&oct.cube);
    let mut totals = [0f64; 5];
    let alt = TraceMode::Hybrid {
        lod_scale: 1.0,
        blend: true,
        small_leaves_as_voxels: true,
    };
    for cam in path {
        for (i, mode) in [
            TraceMode::VOXELS,
            TraceMode::Triangles,
            TraceMode::HYBRID,
            alt,
        ]
        .iter()
        .enumerate()
        {
            totals[i] += render(oct, cam, &light, mode, &Shading::default())?
                .1
                .seconds;
        }
        let frame = cam.frame()?;
        let t = Instant::now();
        let hits = (0..cam.width * cam.height)
            .into_par_iter()
            .filter(|i| {
                bvh.intersect(&cam.ray(&frame, i % cam.width, i / cam.width))
                    .is_some()
            })
            .count();
        totals[4] += t.elapsed().as_secs_f64();
        std::hint::black_box(hits);
    }
    Ok(totals)
}

fn main() -> wscg_math::Result<()> {
    let quick = std::env::args().any(|a| a == "--quick");
    let scenes: Vec<(&str, wscg_math::TriMesh)> = vec![
        ("atrium", scenes::atrium(10)?),
        ("city", scenes::city(40, 7)?),
        ("blob", scenes::blob(if quick { 6 } else { 8 })?),
        (
            "forest",
            if quick {
                scenes::forest(13, 4, 16, 3)?
            } else {
                scenes::forest(13, 6, 64, 3)?
            },
        ),
    ];
    println!("Table 2 at L = 9 (MB): nodes / triangles / tri-index / voxels / total");
    for (name, mesh) in &scenes {
        let t = Instant::now();
        let (full, _) = build(
            mesh,
            &BuildParams {
                early_stop: false,
                ..Default::default()
            },
        )?;
        let tf = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let (early, es) = build(mesh, &BuildParams::default())?;
        let te = t.elapsed().as_secs_f64();
        let (a, b) = (full.memory_report(), early.memory_report());
        println!(
            "{name:7} {:>9} tris {:>9} fragments | full {:7.2} / {:7.2} / {:6.2} / {:7.2} / {:7.2} ({tf:.2} s) | early {:7.2} / {:7.2} / {:6.2} / {:7.2} / {:7.2} ({te:.2} s) | saved {:5.2}%",
            mesh.faces.len(),
            es.fragments,
            mb(a.nodes), mb(a.triangles), mb(a.tri_index), mb(a.voxels), mb(a.total),
            mb(b.nodes), mb(b.triangles), mb(b.tri_index), mb(b.voxels), mb(b.total),
            100.0 * b.saving_against(&a),
        );
    }
    let (_, mesh) = &scenes[3];
    let (oct, _) = build(mesh, &BuildParams::default())?;
    let bvh = TriangleBvh::build(mesh)?;
    let res = if quick { 256 } else { 1024 };
    for (label, frames, near, far) in [
        ("far-view path", 50, 4.0, 8.0),
        ("near-to-far orbit", 100, 0.6, 8.0),
    ] {
        let frames = if quick { frames / 10 } else { frames };
        let path = scenes::orbit_path(&oct.cube, frames, near, far, res);
        let t = fly(&oct, &bvh, &path)?;
        let fps = |s: f64| frames as f64 / s;
        println!(
            "forest {label} ({frames} frames at {res}^2, {near}-{far} S; shading + shadow rays): fps voxels {:.2}, triangles {:.2}, hybrid {:.2} ({:.2}x triangles), hybrid with small leaves as voxels {:.2} ({:.2}x); BVH primary rays only {:.2} fps",
            fps(t[0]), fps(t[1]), fps(t[2]), t[1] / t[2], fps(t[3]), t[1] / t[3], fps(t[4])
        );
    }
    Ok(())
}
