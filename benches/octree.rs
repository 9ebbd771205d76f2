//! Criterion benchmarks of paper 10 (the unified triangle/voxel octree): construction of the
//! 1.3 M-triangle blob at L = 9 with early stop and as a full octree (spec check 8), and
//! 1024^2 primary rays of a far view of the 1.4 M-triangle forest in the three trace modes,
//! against the binned-SAH BVH and parry3d's BVH on the same rays (spec section 5), and one
//! shaded far-view frame in the triangles and hybrid modes (spec check 7).

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use parry3d::math::Vector as PVec;
use parry3d::query::{Ray as PRay, RayCast};
use parry3d::shape::TriMesh as ParryMesh;
use rayon::prelude::*;
use wscg::octree::{build, render, scenes, BuildParams, Ray, Shading, TraceMode, TriangleBvh};

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("paper10");
    g.sample_size(10);
    let blob = scenes::blob(8).unwrap();
    g.bench_function("build blob 1.3M L=9 early stop", |b| {
        b.iter(|| black_box(build(&blob, &BuildParams::default()).unwrap()))
    });
    g.bench_function("build blob 1.3M L=9 full octree", |b| {
        let p = BuildParams::default().early_stop(false);
        b.iter(|| black_box(build(&blob, &p).unwrap()))
    });
    drop(blob);

    let forest = scenes::forest(13, 6, 64, 3).unwrap();
    let (oct, _) = build(&forest, &BuildParams::default()).unwrap();
    let cam = scenes::orbit_path(&oct.cube, 1, 2.5, 2.5, 1024)[0];
    let gen = cam.ray_gen(&cam.frame().unwrap());
    let rays: Vec<Ray> = (0..1024 * 1024)
        .map(|i| gen.ray(i % 1024, i / 1024))
        .collect();
    let fp = Some(cam.footprint());
    for (name, mode) in [
        ("triangles", TraceMode::Triangles),
        ("hybrid", TraceMode::HYBRID),
        ("voxels", TraceMode::VOXELS),
    ] {
        g.bench_function(format!("forest 1024^2 primary rays, octree {name}"), |b| {
            b.iter(|| {
                rays.par_iter()
                    .filter(|r| oct.intersect(r, &mode, fp).is_some())
                    .count()
            })
        });
    }
    // Spec check 7's workload, one frame: a far view (6 cube sides, the middle of the far-view
    // path) rendered with Phong shading and a shadow ray in the triangles and hybrid modes.
    let far = scenes::orbit_path(&oct.cube, 1, 6.0, 6.0, 1024)[0];
    let light = scenes::default_light(&oct.cube);
    for (name, mode) in [
        ("triangles", TraceMode::Triangles),
        ("hybrid", TraceMode::HYBRID),
    ] {
        g.bench_function(
            format!("forest far frame 1024^2 (6 sides), render {name}"),
            |b| {
                b.iter(|| {
                    black_box(render(&oct, &far, &light, &mode, &Shading::default()).unwrap())
                })
            },
        );
    }
    // The same walk without the normal and colour reads: what parry3d's `cast_local_ray`
    // returns (and the triangle with its barycentrics besides).
    g.bench_function("forest 1024^2 primary rays, octree triangles cast", |b| {
        b.iter(|| {
            rays.par_iter()
                .filter(|r| oct.cast(r, &TraceMode::Triangles, fp).is_some())
                .count()
        })
    });
    let bvh = TriangleBvh::build(&forest).unwrap();
    g.bench_function("forest 1024^2 primary rays, binned-SAH BVH", |b| {
        b.iter(|| {
            rays.par_iter()
                .filter(|r| bvh.intersect(r).is_some())
                .count()
        })
    });
    let pts = forest
        .positions
        .iter()
        .map(|p| PVec::new(p[0] as f32, p[1] as f32, p[2] as f32))
        .collect();
    let parry = ParryMesh::new(pts, forest.faces.clone()).unwrap();
    g.bench_function("forest 1024^2 primary rays, parry3d TriMesh BVH", |b| {
        b.iter(|| {
            rays.par_iter()
                .filter(|r| {
                    let pr = PRay::new(PVec::from(r.origin), PVec::from(r.dir));
                    parry.cast_local_ray(&pr, f32::MAX, true).is_some()
                })
                .count()
        })
    });
    // parry3d returning what our hit returns too (normal and triangle), not the distance alone.
    g.bench_function(
        "forest 1024^2 primary rays, parry3d TriMesh BVH with normals",
        |b| {
            b.iter(|| {
                rays.par_iter()
                    .filter(|r| {
                        let pr = PRay::new(PVec::from(r.origin), PVec::from(r.dir));
                        parry
                            .cast_local_ray_and_get_normal(&pr, f32::MAX, true)
                            .is_some()
                    })
                    .count()
            })
        },
    );
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
