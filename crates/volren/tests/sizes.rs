//! Check 9 of paper 03: the byte ordering of the schemes and the hybrid's shrinking rate as
//! the volume grows (Tables 1 and 2), from serialized packages.

use wscg_volren::phantoms::{head, head_tfs, thorax, thorax_tfs};
use wscg_volren::{Camera, HybridServer, ServerParams, SizeReport};

fn print(name: &str, r: &SizeReport) {
    println!(
        "{name}: raw {} B; wavelets {} ({:.1} %), gradient octree {} ({:.1} %), hybrid {} ({:.2} %: \
         static {}, ROI {}); thin-client frame {:?} B, break-even frames {:.1} / {:.1} / {:.1}",
        r.raw,
        r.wavelets,
        100.0 * r.rate(r.wavelets),
        r.gradient_octree,
        100.0 * r.rate(r.gradient_octree),
        r.hybrid(),
        100.0 * r.rate(r.hybrid()),
        r.hybrid_static,
        r.hybrid_roi,
        r.thin_client_frame,
        r.break_even(r.wavelets).unwrap_or(f64::NAN),
        r.break_even(r.gradient_octree).unwrap_or(f64::NAN),
        r.break_even(r.hybrid()).unwrap_or(f64::NAN),
    );
}

#[test]
fn head_sizes_follow_the_papers_ordering() {
    let dims = [256, 256, 112];
    let s = HybridServer::new(
        &head(dims, 1).unwrap(),
        head_tfs(),
        0,
        ServerParams::default(),
    )
    .unwrap();
    // The paper's skull ROI, 128 x 64 x 64, and a small thin-client view.
    let cam = Camera::orbit(dims, 30.0, 20.0, 128);
    let r = s
        .size_report([64, 96, 24], [192, 160, 88], 1, Some(&cam))
        .unwrap();
    print("head 256x256x112", &r);
    assert!(r.hybrid() < r.gradient_octree && r.gradient_octree < r.raw);
    assert!(r.thin_client_frame.unwrap() > 0);
}

#[test]
fn thorax_hybrid_rate_shrinks_with_resolution() {
    // Check 9 scalability: the thorax at 256^3 and at the paper's 512^3, the same relative
    // ROI.
    let rate = |n: usize| {
        let v = thorax([n; 3], 2).unwrap();
        let s = HybridServer::new(&v, thorax_tfs(), 0, ServerParams::default()).unwrap();
        let q = |f: f64| (f * n as f64) as u32;
        let r = s
            .size_report(
                [q(0.25), q(0.3), q(0.25)],
                [q(0.75), q(0.6), q(0.75)],
                1,
                None,
            )
            .unwrap();
        print(&format!("thorax {n}^3"), &r);
        assert!(r.hybrid() < r.gradient_octree && r.gradient_octree < r.raw);
        r.rate(r.hybrid())
    };
    let (small, large) = (rate(256), rate(512));
    assert!(large <= 0.75 * small, "{large} vs {small}");
}
