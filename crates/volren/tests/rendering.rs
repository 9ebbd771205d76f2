//! Checks 7 and 8 of paper 03: rendering consistency of the hybrid client and the gain of
//! the ROI path over the low-resolution context alone.

use wscg_math::metrics::psnr;
use wscg_math::Image;
use wscg_volren::phantoms::{head, head_tfs};
use wscg_volren::{
    render_reference, Camera, HybridClient, HybridServer, RenderParams, Roi, ServerParams,
};

/// The RGB values of the masked pixels.
fn rgb(img: &Image<f32>, mask: &[bool]) -> Vec<f32> {
    let d = img.data();
    let mut out = Vec::new();
    for (p, &m) in mask.iter().enumerate() {
        if m {
            out.extend_from_slice(&d[4 * p..4 * p + 3]);
        }
    }
    out
}

#[test]
fn hybrid_rendering_is_consistent_and_helps_in_the_roi() {
    let dims = [256, 256, 112];
    let v = head(dims, 5).unwrap();
    let tfs = head_tfs();
    let server = HybridServer::new(&v, tfs.clone(), 0, ServerParams::default()).unwrap();
    let mut client = HybridClient::from_static(&server.static_package()).unwrap();
    let n = 160;
    let cam = Camera::orbit(dims, 30.0, 20.0, n);
    let opts = RenderParams::default();
    // Check 7a: without a ROI the hybrid image is the context image, bit for bit.
    let context = client.render_context(&cam, &opts).unwrap();
    assert_eq!(client.render(&cam, 1, &opts).unwrap(), context);
    // Check 7b: with the ROI covering the volume it is the full Gradient Octree image.
    client
        .set_roi(&server.roi_package([0, 0, 0], [256, 256, 112]).unwrap())
        .unwrap();
    assert_eq!(
        client.render(&cam, 1, &opts).unwrap(),
        client.render_octree(&cam, 1, &opts).unwrap()
    );
    // Check 8: a bone ROI of the paper's 128 x 64 x 64 across the skull facing the camera; on
    // the pixels whose rays meet the ROI, the hybrid is closer to the full-resolution
    // reference than the context alone.
    let (lo, hi) = ([128, 128, 32], [256, 192, 96]);
    client
        .set_roi(&server.roi_package(lo, hi).unwrap())
        .unwrap();
    let roi = Roi { min: lo, max: hi };
    let hybrid = client.render(&cam, 1, &opts).unwrap();
    let reference = render_reference(&v, &tfs[0], Some((&roi, &tfs[1])), &cam, &opts).unwrap();
    // Pixels whose rays cross the ROI box: where the hybrid differs from the context image or
    // where the reference does.
    let mask: Vec<bool> = (0..n * n)
        .map(|p| {
            (0..3).any(|k| {
                (hybrid.data()[4 * p + k] - context.data()[4 * p + k]).abs() > 1e-6
                    || (reference.data()[4 * p + k] - context.data()[4 * p + k]).abs() > 0.02
            })
        })
        .collect();
    let covered = mask.iter().filter(|&&m| m).count();
    assert!(covered > 200, "{covered} ROI pixels");
    let r = rgb(&reference, &mask);
    let p_h = psnr(&r, &rgb(&hybrid, &mask), 1.0).unwrap();
    let p_c = psnr(&r, &rgb(&context, &mask), 1.0).unwrap();
    println!("{covered} ROI pixels: PSNR hybrid {p_h:.2} dB, context only {p_c:.2} dB");
    assert!(p_h >= p_c + 2.0, "hybrid {p_h} vs context {p_c}");
    // Baseline [1], the wavelet scheme: the full-resolution decode inside the ROI, unlit. Its
    // coder nulls the voxels transparent under the canonical (soft-tissue) function, bone
    // included, so under the bone function the hybrid is closer to the reference.
    let full_pkg = wscg_volren::wavelet::encode_blocks(
        &v,
        &tfs[0],
        &wscg_volren::wavelet::HaarQuant::default(),
        4,
    )
    .unwrap();
    let full = wscg_volren::wavelet::decode_lowres(&full_pkg, 4).unwrap();
    let wavelet = client.render_wavelet_scheme(&full, &cam, 1, &opts).unwrap();
    let p_w = psnr(&r, &rgb(&wavelet, &mask), 1.0).unwrap();
    println!("wavelet scheme on ROI pixels: PSNR {p_w:.2} dB");
    assert!(p_h > p_w + 2.0, "{p_h} vs {p_w}");
    // Check 7c: the 18-bit normals cost little: on ROI pixels the hybrid image is within
    // 40 dB PSNR of the same rendering with unquantised normals.
    let exact = client.render_exact_normals(&v, &cam, 1, &opts).unwrap();
    let p_n = psnr(&rgb(&exact, &mask), &rgb(&hybrid, &mask), 1.0).unwrap();
    println!("quantised vs exact normals on ROI pixels: PSNR {p_n:.2} dB");
    assert!(p_n >= 40.0, "{p_n}");
    // Bad input.
    assert!(client.render(&cam, 7, &opts).is_err());
    let mut bad = cam;
    bad.target = bad.eye;
    assert!(client.render(&bad, 1, &opts).is_err());
    let zero = opts.step(0.0);
    assert!(client.render(&cam, 1, &zero).is_err());
}
