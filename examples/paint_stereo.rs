//! Paper 07: render a 10 x 10 mm patch of metallic paint for both eyes of the off-axis rig,
//! write the pair as sRGB PNGs, and compare the glints the two eyes see.
//!
//! `cargo run --release --example paint_stereo -- [radius_um] [density]`

use wscg::math::Result;
use wscg::raytrace::paint::{
    binocular_overlap, glint_stats, render, DiscLight, FlakeParams, FlakePlate, PaintRenderParams,
    Plate, PlateStack, Rect,
};
use wscg::raytrace::spectral::XYZ_TO_SRGB;
use wscg::raytrace::stereo::{Eye, StereoRig};

fn main() -> Result<()> {
    let args: Vec<f64> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    let flakes = FlakeParams::default()
        .radius_um(args.first().copied().unwrap_or(30.0))
        .density(args.get(1).copied().unwrap_or(6.5));
    let stack = PlateStack::default();
    // One microstructure for both eyes: the same flakes, seen from 6.5 cm apart.
    let micro = FlakePlate::new(&flakes, stack.size_mm, 1)?;
    let plate = Plate::new(stack, Box::new(micro))?;
    let light = DiscLight::from_elevation(75.0, 1.0);
    let settings = PaintRenderParams::default()
        .region_mm(Some(Rect::centred(0.0, 0.0, 10.0, 10.0)))
        .magnification(4.0);
    let rig = StereoRig::default();
    let mut views = Vec::new();
    for (eye, file) in [
        (Eye::Left, "paint_left.png"),
        (Eye::Right, "paint_right.png"),
    ] {
        let img = render(&plate, &light, &rig, eye, &settings)?;
        img.to_display(1.0, &XYZ_TO_SRGB)?.save(file)?;
        let s = glint_stats(img.luminance().view(), img.mm_per_px)?;
        println!(
            "{file}: {} x {} px, {:.2} glints per mm², mean glint area {:.4} mm²",
            img.width, img.height, s.glint_density_per_mm2, s.mean_glint_area_mm2
        );
        views.push(img);
    }
    println!(
        "flakes glinting for both eyes: {:.1} % (the lamp's 1-degree cones for the two eyes do not overlap)",
        100.0 * binocular_overlap(&views[0].glint_ids, &views[1].glint_ids)
    );
    Ok(())
}
