//! Criterion benchmarks of paper 07 (spectral rendering of metallic-flake paint and its study
//! statistics). Workload names match `benches/peers/07.py`, which times the Python binding
//! against Mitsuba 3 on the same plate.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use wscg::doe::{ccd, fit_quadratic, CcdAlpha, CcdFace};
use wscg::raytrace::paint::{
    generate_tile, render, DiscLight, FlakeParams, FlakePlate, Plate, PlateStack, Rect,
    RenderSettings,
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
    let patch = RenderSettings {
        spp: 64,
        region_mm: Some(Rect::centred(0.0, 0.0, 10.0, 10.0)),
        magnification: 4.0,
        ..RenderSettings::default()
    };
    g.bench_function("render 10x10 mm at 4x (144x144), 64 spp", |b| {
        b.iter(|| black_box(render(&plate, &light, &rig, Eye::Left, &patch).unwrap()))
    });
    // The peer benchmark's view: 20 x 20 mm on 256 x 256 pixels, cyclopean eye.
    let peer = RenderSettings {
        spp: 64,
        region_mm: Some(Rect::centred(0.0, 0.0, 20.0, 20.0)),
        magnification: 256.0 * rig.pixel_pitch_m().0 * 1e3 / 20.0,
        ..RenderSettings::default()
    };
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

criterion_group!(benches, bench_paint);
criterion_main!(benches);
