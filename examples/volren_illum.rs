//! Paper 15 in a few lines: render a volume with instant convolution shadows (ICS) at a fine
//! slice distance and with the paper's supersampled (SCS) and pre-integrated (PI-SCS) variants
//! at a coarse one, and compare quality (mean absolute difference) and time.
//!
//! `cargo run --release --example volren_illum -- [out_prefix]`

use std::time::Instant;

use wscg::volren::illumination::scenes::{marschner_lobb, marschner_lobb_tf};
use wscg::volren::illumination::study::mean_abs_diff;
use wscg::volren::illumination::{render, IlluminationParams, Light, Method, SliceCamera};

fn main() -> wscg::math::Result<()> {
    let prefix = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "volren_illum".into());
    let field = marschner_lobb(41)?;
    let tf = marschner_lobb_tf();
    let cam = SliceCamera::orbit(&field, 30.0, 25.0, 256)?;
    // Headlight, variance-additive Gaussian kernel (spread 0.5), no ambient term.
    let light = Light::default();
    let settings = IlluminationParams::default();
    let mut reference = None;
    for method in [
        Method::ics(0.2),
        Method::ics(0.8),
        Method::scs(0.8, 3),
        Method::pi_scs(0.8, 3),
    ] {
        let t0 = Instant::now();
        let r = render(&field, &tf, &cam, &light, &method, &settings)?;
        let ms = 1e3 * t0.elapsed().as_secs_f64();
        let mad = match &reference {
            Some(img) => mean_abs_diff(&r.image, img)?,
            None => 0.0,
        };
        let out = format!("{prefix}_{}.png", method.name());
        wscg::volren::render::rgb(&r.image)?.save(&out)?;
        println!(
            "{:<7} {:>4} slices {ms:>7.1} ms  MAD vs ICS(0.2) {mad:.4}  -> {out}",
            method.name(),
            r.slices
        );
        reference.get_or_insert(r.image);
    }
    Ok(())
}
