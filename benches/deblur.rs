//! Criterion benchmarks of paper 12 (gyroscope-driven multi-frame deblurring), specification
//! section 5: Krishnan-Fergus on one 64x64 window, one 720x480 frame deblurred region by
//! region (24 x 16 regions with their gyro kernels; peers: scikit-image `richardson_lucy` and
//! `wiener` called per region, benches/peers/12.py), and the full 5-frame pipeline.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use wscg::deblur::synth::{self, BlurRenderParams, Burst, ShakeParams};
use wscg::deblur::{
    deblur_multiframe, deblur_piecewise, deconv_hl, kernel_grid, Gamma, GyroTrack,
    HyperLaplacianParams, Intrinsics, Kernel, Method, MultiframeParams, Tiling,
};
use wscg::math::progress::NoProgress;

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("paper12");
    g.sample_size(10);
    let small = synth::scene(64, 64, 1).unwrap();
    let k = Kernel::line(9.0, 0.5).unwrap();
    g.bench_function("deconv_hl 64x64 (6 beta steps)", |b| {
        b.iter(|| black_box(deconv_hl(&small, &k, &HyperLaplacianParams::default()).unwrap()))
    });
    let (h, w) = (480, 720);
    let sharp = synth::scene(h, w, 2).unwrap();
    let burst = Burst::default();
    let sb = synth::make_burst(
        &sharp,
        &burst,
        &ShakeParams::default(),
        2,
        0.002,
        &BlurRenderParams::default(),
        1,
    )
    .unwrap();
    let track = GyroTrack::from_camera_rates(&sb.measured).unwrap();
    let kk = Intrinsics::centred(600.0, w, h);
    let mut lin = sb.frames[2].image.clone();
    Gamma::default().linearise(lin.data_mut());
    let timing = burst.timing(2, h);
    let opts = MultiframeParams::default().t_delay(burst.t_delay);
    g.bench_function("kernel_grid 720x480 (24x16 regions)", |b| {
        b.iter(|| black_box(kernel_grid(&track, &timing, &kk, w, h, 30, &opts.kernel).unwrap()))
    });
    let grid = kernel_grid(&track, &timing, &kk, w, h, 30, &opts.kernel).unwrap();
    for (name, m) in [
        (
            "KS",
            Method::HyperLaplacian(HyperLaplacianParams::default()),
        ),
        ("Wiener", Method::Wiener { nsr: 0.01 }),
        ("RL 30 it", Method::RichardsonLucy { iters: 30 }),
    ] {
        g.bench_function(format!("piecewise {name} 720x480"), |b| {
            b.iter(|| black_box(deblur_piecewise(&lin, &grid, &m, &Tiling::default()).unwrap()))
        });
    }
    g.bench_function("multiframe KM 5 frames 720x480", |b| {
        b.iter(|| {
            black_box(deblur_multiframe(&sb.frames, 2, &track, &kk, &opts, &NoProgress).unwrap())
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
