//! Hand-crafted "physical" features of a segmented hand (paper §3.2.2, Table 4; the paper
//! cites [RYZ11, PKK09, CLEL12] for them): the baseline that the class-wise SFA is compared
//! against with a KNN classifier.
//!
//! All features are computed on the **largest 8-connected component** of the mask (the
//! segmented palm region), with pixels at integer coordinates `(x, y) = (column, row)`:
//!
//! | index | name | definition |
//! |---|---|---|
//! | 0, 1 | `tip_x`, `tip_y` | contour point farthest from the palm centre (ties: first in contour order) |
//! | 2, 3 | `centre_x`, `centre_y` | argmax of the exact Euclidean distance transform (ties: first in row-major order) |
//! | 4 | `palm_radius` | that maximum distance, px (radius of the largest inscribed disc) |
//! | 5 | `convex_ratio` | pixel count / pixel centres inside or on the convex hull of the pixel centres |
//! | 6 | `concave_depth` | largest convexity-defect depth, px |
//! | 7 | `polar_deg` | `atan2(-(tip_y - centre_y), tip_x - centre_x)` in degrees |
//! | 8 | `azimuth_deg` | `atan((depth_centre - depth_tip) / |tip - centre|)` in degrees (only with depth) |
//!
//! Choices where the paper leaves a gap:
//! - **Nine values.** The paper (§4) lists the fingertip and palm-centre coordinates, the
//!   convex ratio, the concave depth and the polar and azimuth angles of the finger: eight
//!   numbers. We add a ninth, the palm radius (the maximum of the
//!   distance transform), which comes with the palm centre and is the hand-size cue of the
//!   palm-centre methods cited. Without depth the azimuth is left out (8 values); it is the
//!   last entry so that the 8-D vector is a prefix of the 9-D one.
//! - **Contour**: the outer boundary of the component, traced clockwise by Moore-neighbour
//!   tracing ([`trace_contour`]); holes are ignored (the farthest point of a set from any point
//!   lies on its outer boundary, and OpenCV's convexity defects use the outer contour too).
//! - **Distance transform**: exact Euclidean, Felzenszwalb-Huttenlocher (rows then columns),
//!   with the area outside the image counted as background.
//! - **Convex ratio**: the hull is that of the pixel centres (Andrew's monotone chain); its
//!   "area" is measured like the mask's, by counting the pixel centres inside or on it (Pick's
//!   theorem, exact integers). The ratio is then 1 exactly for digitally convex shapes such as
//!   a digital disc, and in `(0, 1]` always. (Pixel count over the Euclidean area of the hull of
//!   the centres exceeds 1 for convex shapes; over the hull of the pixel corners it is about
//!   0.95 for a disc of radius 20.)
//! - **Concave depth**: as OpenCV's `convexityDefects`: for each pair of consecutive hull
//!   vertices, the largest distance of the contour points between them to the line through the
//!   two vertices; the feature is the largest over all pairs.
//! - **Angles**: the polar angle is measured counter-clockwise as the image is displayed (the
//!   y axis pointing up): 0 = right, 90 = up (towards row 0). The azimuth mixes millimetres
//!   (depth) with pixels (image distance), as the definition does: it is an elevation angle only
//!   up to the unknown pixel pitch; it is positive when the tip is closer to the camera than
//!   the palm centre.

use rayon::prelude::*;
use wscg_math::{Error, Image, ImageStackView, ImageView, Result};

use super::morphology::{
    bounding_box, convex_hull, hull_lattice_count, largest_component, max_defect_depth,
    squared_distance_transform, trace_contour,
};

/// Number of physical features with depth (without depth: one fewer).
pub const N_FEATURES: usize = 9;

/// Names of the features, in output order (the last one only with depth).
pub const FEATURE_NAMES: [&str; N_FEATURES] = [
    "tip_x",
    "tip_y",
    "centre_x",
    "centre_y",
    "palm_radius",
    "convex_ratio",
    "concave_depth",
    "polar_deg",
    "azimuth_deg",
];

/// The physical features of one single-channel mask (any non-zero byte is foreground; see
/// the module docs for the definitions and the order): 9 values with a depth map of the same
/// size (any unit, usually mm), 8 without.
///
/// Errors: `mask` or `depth` with more than one channel, `depth` of another size, non-finite
/// depth, a mask without foreground.
pub fn physical_features(
    mask: ImageView<'_, u8>,
    depth: Option<ImageView<'_, f32>>,
) -> Result<Vec<f64>> {
    mask.ensure_plane("mask")?;
    if let Some(d) = depth {
        mask.ensure_same_shape(&d, "depth")?;
        d.ensure_finite("depth")?;
    }
    features_unchecked(mask, depth)
}

fn features_unchecked(
    mask: ImageView<'_, u8>,
    depth: Option<ImageView<'_, f32>>,
) -> Result<Vec<f64>> {
    let w = mask.width();
    let (full, area) = largest_component(mask)?;
    if area == 0 {
        return Err(Error::Empty("mask"));
    }
    // Work in the component's bounding box: the area outside the image is background for the
    // distance transform and the contour, so the crop changes nothing but the offsets.
    let (ox, x1, oy, y1) = bounding_box(full.view(), 0, |&m| m != 0).ok_or(Error::Empty("mask"))?;
    let (cw, ch) = (x1 + 1 - ox, y1 + 1 - oy);
    let mut comp = Vec::with_capacity(cw * ch);
    for y in oy..oy + ch {
        comp.extend_from_slice(&full.data()[y * w + ox..y * w + ox + cw]);
    }
    let comp = Image::new(ch, cw, 1, comp)?;
    let (w_full, w) = (w, cw);
    // Palm centre: first maximum of the distance transform in row-major order.
    let dt = squared_distance_transform(comp.view())?;
    let (mut centre, mut best) = (0usize, -1.0f64);
    for (i, &d) in dt.data().iter().enumerate() {
        if comp.data()[i] != 0 && d > best {
            best = d;
            centre = i;
        }
    }
    let (cx, cy) = ((centre % w) as i64, (centre / w) as i64);
    let centre_full = (oy + centre / w) * w_full + ox + centre % w;
    // Fingertip: contour point farthest from the centre.
    let contour = trace_contour(comp.view())?;
    let mut tip = contour[0];
    let mut far = -1i64;
    for &p in &contour {
        let d2 = (p.0 - cx).pow(2) + (p.1 - cy).pow(2);
        if d2 > far {
            far = d2;
            tip = p;
        }
    }
    let hull = convex_hull(&contour);
    let convex_ratio = area as f64 / hull_lattice_count(&hull).max(1) as f64;
    let concave = max_defect_depth(&contour, &hull);
    let (dx, dy) = ((tip.0 - cx) as f64, (tip.1 - cy) as f64);
    let polar = (-dy).atan2(dx).to_degrees();
    let (ox_f, oy_f) = (ox as f64, oy as f64);
    let mut out = vec![
        tip.0 as f64 + ox_f,
        tip.1 as f64 + oy_f,
        cx as f64 + ox_f,
        cy as f64 + oy_f,
        best.sqrt(),
        convex_ratio,
        concave,
        polar,
    ];
    if let Some(d) = depth {
        let d = d.data();
        let dist = (dx * dx + dy * dy).sqrt();
        let tip_full = (oy + tip.1 as usize) * w_full + ox + tip.0 as usize;
        let rise = f64::from(d[centre_full]) - f64::from(d[tip_full]);
        let azimuth = if dist > 0.0 {
            (rise / dist).atan().to_degrees()
        } else {
            0.0
        };
        out.push(azimuth);
    }
    Ok(out)
}

/// [`physical_features`] of every mask of a stack (with depth maps likewise), frames in
/// parallel: one row of 9 values (8 without depth) per frame, row-major.
///
/// Errors: as [`physical_features`], for the first failing frame; `depth` not of the shape
/// of `masks`.
pub fn physical_features_batch(
    masks: ImageStackView<'_, u8>,
    depth: Option<ImageStackView<'_, f32>>,
) -> Result<Vec<f64>> {
    if let Some(d) = depth {
        masks.ensure_same_shape(&d, "depth")?;
        d.ensure_finite("depth")?;
    }
    let rows: Vec<Vec<f64>> = (0..masks.frames())
        .into_par_iter()
        .map(|i| {
            let m = masks.frame(i).expect("frame index in range");
            let d = depth.and_then(|d| d.frame(i));
            features_unchecked(m, d).map_err(|e| match e {
                Error::Empty(_) => Error::invalid("masks", format!("frame {i} is empty")),
                e => e,
            })
        })
        .collect::<Result<_>>()?;
    Ok(rows.concat())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [`physical_features`] of row-major buffers.
    fn features(mask: &[u8], depth: Option<&[f32]>, h: usize, w: usize) -> Result<Vec<f64>> {
        let depth = depth.map(|d| ImageView::plane(h, w, d)).transpose()?;
        physical_features(ImageView::plane(h, w, mask)?, depth)
    }

    /// [`physical_features_batch`] of row-major buffers.
    fn batch(
        masks: &[u8],
        depth: Option<&[f32]>,
        n: usize,
        h: usize,
        w: usize,
    ) -> Result<Vec<f64>> {
        let depth = depth.map(|d| ImageStackView::new(n, h, w, d)).transpose()?;
        physical_features_batch(ImageStackView::new(n, h, w, masks)?, depth)
    }

    /// Pixel centres `(x, y)` inside the union of discs and capsules.
    enum Shape {
        Disc((f64, f64), f64),
        Capsule((f64, f64), (f64, f64), f64),
    }

    fn raster(shapes: &[Shape], h: usize, w: usize) -> Vec<u8> {
        let mut m = vec![0u8; h * w];
        for y in 0..h {
            for x in 0..w {
                let q = (x as f64, y as f64);
                let inside = shapes.iter().any(|s| match *s {
                    Shape::Disc(c, r) => (q.0 - c.0).powi(2) + (q.1 - c.1).powi(2) <= r * r,
                    Shape::Capsule(a, b, r) => {
                        let (ex, ey) = (b.0 - a.0, b.1 - a.1);
                        let t = (((q.0 - a.0) * ex + (q.1 - a.1) * ey) / (ex * ex + ey * ey))
                            .clamp(0.0, 1.0);
                        let (px, py) = (a.0 + t * ex, a.1 + t * ey);
                        (q.0 - px).powi(2) + (q.1 - py).powi(2) <= r * r
                    }
                });
                m[y * w + x] = u8::from(inside);
            }
        }
        m
    }

    #[test]
    fn disc_is_convex() {
        let (h, w) = (60, 70);
        let m = raster(&[Shape::Disc((35.0, 30.0), 20.0)], h, w);
        let f = features(&m, None, h, w).unwrap();
        assert_eq!(f.len(), 8);
        eprintln!("disc r=20: {f:?}");
        assert!(f[5] >= 0.98, "convex ratio {}", f[5]);
        assert!(f[6] <= 1.0, "concave depth {}", f[6]);
        assert_eq!((f[2], f[3]), (35.0, 30.0));
        assert!((f[4] - 20.0).abs() < 1.0, "palm radius {}", f[4]);
    }

    #[test]
    fn finger_tip_and_polar_angle() {
        // Disc of radius 20 with a finger of length 30 (cap included) and width 8 leaving its
        // boundary at 30 degrees (counter-clockwise from the x axis, y up).
        let (h, w) = (130, 130);
        let c = (50.0, 80.0);
        let th = 30f64.to_radians();
        let u = (th.cos(), -th.sin());
        let at = |r: f64| (c.0 + r * u.0, c.1 + r * u.1);
        let m = raster(
            &[
                Shape::Disc(c, 20.0),
                Shape::Capsule(at(20.0), at(20.0 + 30.0 - 4.0), 4.0),
            ],
            h,
            w,
        );
        let tip = at(50.0);
        let mut depth = vec![0f32; h * w];
        for y in 0..h {
            for x in 0..w {
                // Surface rising towards the tip: 300 mm at the centre, 290 mm at the tip.
                let along = ((x as f64 - c.0) * u.0 + (y as f64 - c.1) * u.1).max(0.0);
                depth[y * w + x] = (300.0 - 10.0 * along / 50.0) as f32;
            }
        }
        let f = features(&m, Some(&depth), h, w).unwrap();
        eprintln!("disc + finger: {f:?}, analytic tip {tip:?}");
        assert_eq!(f.len(), 9);
        let err = ((f[0] - tip.0).powi(2) + (f[1] - tip.1).powi(2)).sqrt();
        assert!(err <= 2.0, "tip error {err}");
        assert!((f[7] - 30.0).abs() <= 3.0, "polar {}", f[7]);
        // Azimuth: rise over distance, both measured on the actual tip pixel.
        let dist = ((f[0] - f[2]).powi(2) + (f[1] - f[3]).powi(2)).sqrt();
        let z = |x: f64, y: f64| f64::from(depth[y as usize * w + x as usize]);
        let expect = ((z(f[2], f[3]) - z(f[0], f[1])) / dist).atan().to_degrees();
        assert!((f[8] - expect).abs() < 1e-4, "azimuth {} vs {expect}", f[8]);
        assert!((f[8] - (10.0f64 / 50.0).atan().to_degrees()).abs() < 1.0);
        // Without depth: the same first 8 values.
        assert_eq!(features(&m, None, h, w).unwrap(), f[..8].to_vec());
    }

    #[test]
    fn v_gap_depth() {
        // Two fingers (radius r, length l between segment ends) leaving a common base point at
        // +-theta from the vertical, on a palm disc. The crotch lies r / sin(theta) above the
        // base, the hull edge over the tips at l cos(theta) + r above it.
        let (h, w) = (120, 120);
        let (r, th) = (5.0, 20f64.to_radians());
        let l = 23.0;
        let expect = l * th.cos() + r - r / th.sin();
        let b = (60.0, 80.0);
        let tip = |s: f64| (b.0 + s * l * th.sin(), b.1 - l * th.cos());
        let m = raster(
            &[
                Shape::Disc((60.0, 95.0), 20.0),
                Shape::Capsule(b, tip(-1.0), r),
                Shape::Capsule(b, tip(1.0), r),
            ],
            h,
            w,
        );
        let f = features(&m, None, h, w).unwrap();
        eprintln!("V gap: analytic {expect:.3}, measured {:.3}", f[6]);
        assert!((f[6] - expect).abs() <= 1.5, "{} vs {expect}", f[6]);
        assert!((expect - 12.0).abs() < 0.05);
        assert!(f[5] < 0.97);
    }

    #[test]
    fn bad_input_is_rejected() {
        assert!(matches!(
            features(&[0; 12], None, 3, 4),
            Err(Error::Empty(_))
        ));
        assert!(features(&[1; 12], None, 4, 4).is_err());
        assert!(features(&[1; 12], None, 0, 4).is_err());
        let mut d = vec![1f32; 12];
        assert!(features(&[1; 12], Some(&d), 3, 4).is_ok());
        d[5] = f32::NAN;
        assert!(features(&[1; 12], Some(&d), 3, 4).is_err());
        assert!(features(&[1; 12], Some(&d[..11]), 3, 4).is_err());
        assert!(batch(&[], None, 0, 3, 4).is_err());
        assert!(batch(&[1; 12], None, 2, 3, 4).is_err());
        let mut two = vec![1u8; 24];
        two[12..].fill(0);
        assert!(batch(&two, None, 2, 3, 4).is_err());
    }

    #[test]
    fn batch_matches_single_frames() {
        let (h, w) = (40, 50);
        let a = raster(&[Shape::Disc((20.0, 20.0), 10.0)], h, w);
        let b = raster(
            &[
                Shape::Disc((25.0, 25.0), 8.0),
                Shape::Capsule((25.0, 25.0), (40.0, 5.0), 3.0),
            ],
            h,
            w,
        );
        let masks = [a.clone(), b.clone()].concat();
        let depth: Vec<f32> = (0..2 * h * w).map(|i| 300.0 - (i % 7) as f32).collect();
        let rows = batch(&masks, Some(&depth), 2, h, w).unwrap();
        assert_eq!(rows.len(), 18);
        let fa = features(&a, Some(&depth[..h * w]), h, w).unwrap();
        let fb = features(&b, Some(&depth[h * w..]), h, w).unwrap();
        assert_eq!(rows, [fa, fb].concat());
        let no_depth = batch(&masks, None, 2, h, w).unwrap();
        assert_eq!(no_depth.len(), 16);
    }
}
