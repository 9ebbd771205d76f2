//! Paper 03 in a few lines: a server prepares a volume, a client receives the static package
//! once and one ROI package, and renders the hybrid image.
//!
//! `cargo run --release --example volren_roi -- [out.png]`

use wscg::volren::phantoms::{head, head_tfs};
use wscg::volren::{Camera, HybridClient, HybridServer, RenderParams, ServerParams};

fn main() -> wscg::math::Result<()> {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "volren_roi.png".into());
    let dims = [256, 256, 112];
    let volume = head(dims, 1)?;
    // Transfer function 0 (soft tissue) colours the context, 1 (bone) the ROI.
    let server = HybridServer::new(&volume, head_tfs(), 0, ServerParams::default())?;
    let static_package = server.static_package();
    let roi_package = server.roi_package([128, 128, 32], [256, 192, 96])?;
    let mut client = HybridClient::from_static(&static_package)?;
    client.set_roi(&roi_package)?;
    let img = client.render(
        &Camera::orbit(dims, 30.0, 20.0, 512),
        1,
        &RenderParams::default(),
    )?;
    wscg::volren::render::rgb(&img)?.save(&out)?;
    println!(
        "raw volume {} B, static package {} B, ROI package {} B; image written to {out}",
        volume.len(),
        static_package.len(),
        roi_package.len()
    );
    Ok(())
}
