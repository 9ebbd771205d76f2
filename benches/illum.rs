//! Criterion benchmarks of paper 15 (convolution-based volume illumination), specification
//! section 5: one 256 x 256 frame of the head phantom (192 x 192 x 84) with ICS at slice
//! distances 0.2 and 0.8, SCS and PI-SCS at 0.8 with 3 sub-samples, and the Blinn-Phong ray
//! caster; and the pre-integration table. Peers (VTK's CPU ray caster, the Table-1 and
//! equal-quality studies on the frog volume) are in benches/peers/15.py.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use wscg::volren::illumination::scenes::tissue_tf;
use wscg::volren::illumination::{
    render, IlluminationParams, Kernel, Light, Method, Phong, PreIntegrationTable, ScalarField,
    SliceCamera,
};
use wscg::volren::phantoms::head;

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("paper15");
    g.sample_size(10);
    let v = head([192, 192, 84], 1).unwrap();
    let field = ScalarField::from_u8(v.view()).unwrap();
    let tf = tissue_tf();
    let cam = SliceCamera::orbit(&field, 30.0, 25.0, 256).unwrap();
    let light = Light {
        kernel: Kernel::Gaussian { spread: 0.5 },
        ..Default::default()
    };
    let s = IlluminationParams::default();
    for (name, m) in [
        ("ICS ds=0.2", Method::ics(0.2)),
        ("ICS ds=0.8", Method::ics(0.8)),
        ("SCS ds=0.8 m=3", Method::scs(0.8, 3)),
        ("PI-ICS ds=0.8", Method::pi_scs(0.8, 0)),
        ("PI-SCS ds=0.8 m=3", Method::pi_scs(0.8, 3)),
        (
            "Phong ray casting step=0.5",
            Method::RaycastPhong {
                step: 0.5,
                phong: Phong::default(),
            },
        ),
    ] {
        g.bench_function(format!("frame 256x256 {name}"), |b| {
            b.iter(|| render(black_box(&field), &tf, &cam, &light, &m, &s).unwrap())
        });
    }
    g.bench_function("pre-integration table 256x256, ds=0.2", |b| {
        b.iter(|| PreIntegrationTable::build(black_box(&tf), 0.2).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
