//! Criterion benchmarks of paper 07 (spectral rendering of metallic-flake paint and its study
//! statistics) and paper 08 (many-light rendering with adaptive importance caching).
//! Workload names match `benches/peers/07.py` (Mitsuba 3 on the same plate) and
//! `benches/peers/08.py` (Embree's shadow rays, Mitsuba 3's path tracer).

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use wscg::doe::{ccd, fit_quadratic, CcdAlpha, CcdFace};
use wscg::raytrace::paint::{
    generate_tile, render, DiscLight, FlakeParams, FlakePlate, PaintRenderParams, Plate,
    PlateStack, Rect,
};
use wscg::raytrace::stereo::{Eye, StereoRig};

fn bench_paint(c: &mut Criterion) {
    let mut g = c.benchmark_group("paper07");
    g.sample_size(10);
    let p = FlakeParams::default();
    g.bench_function("generate_tile 450 um (Boolean, r 30, density 6.5)", |b| {
        b.iter(|| black_box(generate_tile(&p, 1).unwrap()))
    });
    let stack = PlateStack::default();
    let micro = FlakePlate::new(&p, stack.size_mm, 3).unwrap();
    let plate = Plate::new(stack, Box::new(micro)).unwrap();
    let rig = StereoRig::default();
    let light = DiscLight::from_elevation(75.0, 1.0);
    let patch = PaintRenderParams::default()
        .spp(64)
        .region_mm(Some(Rect::centred(0.0, 0.0, 10.0, 10.0)))
        .magnification(4.0);
    g.bench_function("render 10x10 mm at 4x (144x144), 64 spp", |b| {
        b.iter(|| black_box(render(&plate, &light, &rig, Eye::Left, &patch).unwrap()))
    });
    // The peer benchmark's view: 20 x 20 mm on 256 x 256 pixels, cyclopean eye.
    let peer = PaintRenderParams::default()
        .spp(64)
        .region_mm(Some(Rect::centred(0.0, 0.0, 20.0, 20.0)))
        .magnification(256.0 * rig.pixel_pitch_m().0 * 1e3 / 20.0);
    g.bench_function("render 20x20 mm 256x256, 64 spp (peer view)", |b| {
        b.iter(|| black_box(render(&plate, &light, &rig, Eye::Cyclopean, &peer).unwrap()))
    });
    let design = ccd(2, CcdFace::Inscribed, CcdAlpha::Rotatable, 5).unwrap();
    let y: Vec<f64> = design
        .row_iter()
        .enumerate()
        .map(|(i, r)| 3.0 + 6.0 * r[0] * r[0] + 2.0 * r[1] * r[1] + 0.1 * (i % 3) as f64)
        .collect();
    g.bench_function("fit_rsm 13-run CCI with interaction", |b| {
        b.iter(|| black_box(fit_quadratic(&design, &y, true).unwrap()))
    });
    g.finish();
}

fn bench_manylight(c: &mut Criterion) {
    use wscg::raytrace::manylight::placement::AdaptiveParams;
    use wscg::raytrace::manylight::{
        build_cache, generate_vpls, render, scenes, trace_primary, ImportanceCachingParams, Interp,
        Placement, VplParams,
    };
    use wscg_math::progress::NoProgress;
    let mut g = c.benchmark_group("paper08");
    g.sample_size(10);
    // Shadow rays: 100 000 random segments in the colonnade of 96 000 triangles.
    let (big, _) = scenes::colonnade(20, 64, 48).unwrap();
    let b = big.bounds();
    // Low-discrepancy points of the scene's box (additive recurrences).
    let pt = |k: usize| {
        let f = |a: f64| (0.5 + k as f64 * a).fract();
        let u = [f(0.754_877_666), f(0.569_840_291), f(0.362_361_227)];
        let e = b.extent();
        [0, 1, 2].map(|c| b.min[c] + e[c] * u[c] * 0.98 + e[c] * 0.01)
    };
    let (a, t): (Vec<_>, Vec<_>) = (0..100_000).map(|k| (pt(2 * k), pt(2 * k + 1))).unzip();
    g.bench_function("shadow rays 100k, colonnade 96k triangles", |bch| {
        bch.iter(|| black_box(big.occluded_batch(&a, &t).unwrap()))
    });
    // Cache and render on the colonnade at 256 x 192 with 490 records, ~4200 VPLs.
    let (scene, cam) = scenes::colonnade(1, 256, 192).unwrap();
    let vpls = generate_vpls(&scene, &VplParams::default().n_paths(1400)).unwrap();
    let gb = trace_primary(&scene, &cam).unwrap();
    let p = ImportanceCachingParams::default().n_cache(490);
    let adaptive = Placement::Adaptive(AdaptiveParams::default());
    g.bench_function("cache adaptive colonnade 256x192 490 records", |bch| {
        bch.iter(|| {
            black_box(build_cache(&scene, &gb, &vpls, &adaptive, Interp::default(), &p).unwrap())
        })
    });
    g.bench_function("cache ic colonnade 256x192 490 records", |bch| {
        bch.iter(|| {
            black_box(
                build_cache(
                    &scene,
                    &gb,
                    &vpls,
                    &Placement::RandomScreen,
                    Interp::Uniform,
                    &p,
                )
                .unwrap(),
            )
        })
    });
    let (cache, _) = build_cache(&scene, &gb, &vpls, &adaptive, Interp::default(), &p).unwrap();
    g.bench_function("render adaptive colonnade 256x192 16 spp", |bch| {
        bch.iter(|| black_box(render(&scene, &gb, &vpls, &cache, &p, &NoProgress).unwrap()))
    });
    g.finish();
}

criterion_group!(benches, bench_paint, bench_manylight);
criterion_main!(benches);
