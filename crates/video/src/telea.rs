//! Fast-marching image inpainting (Telea 2004, "An image inpainting technique based on the
//! fast marching method"): the hole is filled from its boundary inwards in order of the
//! distance `T` to the known region (computed by the fast marching method on the way); each
//! pixel takes the weighted mean of the first-order extrapolations `I(q) + grad I(q) . (p - q)`
//! of the known pixels `q` within `radius`, weighted by direction (`|(p - q) . N| / |p - q|`,
//! `N` the normal `grad T`), distance (`1 / |p - q|^2`) and level-set closeness
//! (`1 / (1 + |T(q) - T(p)|)`). One of stage 1's initialisations (the paper uses image
//! inpainting to start from the colours around the hole).

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use wscg_math::{Error, Image, ImageView, Result};

/// Most channels a frame may have (grey, grey + alpha, RGB, RGBA).
pub const MAX_CHANNELS: usize = 4;

#[derive(Clone, Copy, PartialEq, Eq)]
enum Flag {
    Known,
    Band,
    Inside,
}

/// A min-heap entry: a key and an index, smallest key first, ties to the smaller index (so
/// that pops do not depend on insertion order).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct MinEntry(pub f32, pub usize);

impl Eq for MinEntry {}

impl PartialOrd for MinEntry {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}

impl Ord for MinEntry {
    fn cmp(&self, o: &Self) -> Ordering {
        o.0.total_cmp(&self.0).then(o.1.cmp(&self.1))
    }
}

/// The eikonal update from two neighbouring arrival times (Telea's `solve`).
fn solve(a: f32, b: f32) -> f32 {
    match (a.is_finite(), b.is_finite()) {
        (true, true) => {
            let r = 2.0 - (a - b) * (a - b);
            if r >= 0.0 {
                let s = (a + b + r.sqrt()) / 2.0;
                if s >= a.max(b) {
                    return s;
                }
            }
            1.0 + a.min(b)
        }
        (true, false) => 1.0 + a,
        (false, true) => 1.0 + b,
        _ => f32::INFINITY,
    }
}

/// `frame` (up to [`MAX_CHANNELS`] channels) with the pixels where the single-channel `hole`
/// is true inpainted from the others, with neighbourhood radius `radius` (pixels). The other
/// pixels are copied unchanged.
///
/// Errors: more than [`MAX_CHANNELS`] channels, `hole` not one channel of the frame's height
/// and width, a hole covering the whole frame (nothing to fill from), `radius` not finite and
/// at least 1.
pub fn telea(
    frame: ImageView<'_, u8>,
    hole: ImageView<'_, bool>,
    radius: f32,
) -> Result<Image<u8>> {
    let (h, w, c) = frame.shape();
    if c > MAX_CHANNELS {
        return Err(Error::invalid(
            "frame",
            format!("has {c} channels, at most {MAX_CHANNELS} are supported"),
        ));
    }
    hole.ensure_plane("hole")?;
    if (hole.height(), hole.width()) != (h, w) {
        return Err(Error::ShapeMismatch(format!(
            "`hole` is {} x {}, the frame {h} x {w}",
            hole.height(),
            hole.width()
        )));
    }
    if hole.data().iter().all(|&b| b) {
        return Err(Error::invalid(
            "hole",
            "covers the whole frame: no known pixel to fill from",
        ));
    }
    if !(radius.is_finite() && radius >= 1.0) {
        return Err(Error::invalid(
            "radius",
            format!("must be finite and at least 1, got {radius}"),
        ));
    }
    let mut out = frame.to_image();
    telea_in_place(out.data_mut(), h, w, c, hole.data(), radius);
    Ok(out)
}

/// [`telea`] on an unchecked `h x w x c` frame buffer, written in place (the shapes are the
/// caller's invariant; `c <= MAX_CHANNELS`).
pub(crate) fn telea_in_place(
    frame: &mut [u8],
    h: usize,
    w: usize,
    c: usize,
    hole: &[bool],
    radius: f32,
) {
    let n = h * w;
    let mut flag: Vec<Flag> = hole
        .iter()
        .map(|&b| if b { Flag::Inside } else { Flag::Known })
        .collect();
    let mut t = vec![f32::INFINITY; n];
    let mut val: Vec<f32> = frame.iter().map(|&v| v as f32).collect();
    let mut heap = BinaryHeap::new();
    let nb = |i: usize| -> [Option<usize>; 4] {
        let (y, x) = (i / w, i % w);
        [
            (y > 0).then(|| i - w),
            (y + 1 < h).then(|| i + w),
            (x > 0).then(|| i - 1),
            (x + 1 < w).then(|| i + 1),
        ]
    };
    // The band: known pixels next to the hole, at T = 0.
    for i in 0..n {
        if flag[i] == Flag::Known {
            t[i] = 0.0;
            if nb(i).iter().flatten().any(|&j| flag[j] == Flag::Inside) {
                flag[i] = Flag::Band;
                heap.push(MinEntry(0.0, i));
            }
        }
    }
    let r = radius.max(1.0);
    let ri = r.ceil() as i64;
    while let Some(MinEntry(_, i)) = heap.pop() {
        if flag[i] == Flag::Known && t[i] > 0.0 {
            continue;
        }
        flag[i] = Flag::Known;
        for j in nb(i).into_iter().flatten() {
            if flag[j] == Flag::Known {
                continue;
            }
            // Arrival time from the two axis pairs.
            let (y, x) = ((j / w) as i64, (j % w) as i64);
            let tk = |yy: i64, xx: i64| -> f32 {
                if yy < 0 || xx < 0 || yy >= h as i64 || xx >= w as i64 {
                    return f32::INFINITY;
                }
                let k = yy as usize * w + xx as usize;
                if flag[k] == Flag::Inside {
                    f32::INFINITY
                } else {
                    t[k]
                }
            };
            let (tu, td, tl, tr) = (tk(y - 1, x), tk(y + 1, x), tk(y, x - 1), tk(y, x + 1));
            let tj = solve(tu, tl)
                .min(solve(td, tl))
                .min(solve(tu, tr))
                .min(solve(td, tr));
            if flag[j] == Flag::Inside {
                t[j] = tj;
                // Normal from the arrival times (central differences where defined).
                let grad = |a: f32, b: f32| {
                    if a.is_finite() && b.is_finite() {
                        (b - a) / 2.0
                    } else {
                        0.0
                    }
                };
                let (ny, nx) = (grad(tu, td), grad(tl, tr));
                let nn = (ny * ny + nx * nx).sqrt().max(1e-6);
                let (ny, nx) = (ny / nn, nx / nn);
                let mut acc = [0.0f32; 4];
                let mut wsum = 0.0f32;
                // The neighbourhood clipped to the frame (a radius beyond it is the frame).
                for dy in (-ri).max(-y)..=ri.min(h as i64 - 1 - y) {
                    for dx in (-ri).max(-x)..=ri.min(w as i64 - 1 - x) {
                        let (qy, qx) = (y + dy, x + dx);
                        if dy == 0 && dx == 0 {
                            continue;
                        }
                        let d2 = (dy * dy + dx * dx) as f32;
                        if d2 > r * r {
                            continue;
                        }
                        let q = qy as usize * w + qx as usize;
                        if flag[q] != Flag::Known {
                            continue;
                        }
                        // p - q = (-dy, -dx).
                        let dir =
                            ((-(dy as f32) * ny - dx as f32 * nx).abs() / d2.sqrt()).max(1e-6);
                        let lev = 1.0 / (1.0 + (t[q] - tj).abs());
                        let wt = dir * lev / d2;
                        for k in 0..c {
                            // Gradient of I at q from known neighbours (central or one-sided).
                            let at = |yy: i64, xx: i64| -> Option<f32> {
                                if yy < 0 || xx < 0 || yy >= h as i64 || xx >= w as i64 {
                                    return None;
                                }
                                let m = yy as usize * w + xx as usize;
                                (flag[m] == Flag::Known).then(|| val[m * c + k])
                            };
                            let g = |a: Option<f32>, b: Option<f32>, mid: f32| match (a, b) {
                                (Some(a), Some(b)) => (b - a) / 2.0,
                                (None, Some(b)) => b - mid,
                                (Some(a), None) => mid - a,
                                _ => 0.0,
                            };
                            let vq = val[q * c + k];
                            let gy = g(at(qy - 1, qx), at(qy + 1, qx), vq);
                            let gx = g(at(qy, qx - 1), at(qy, qx + 1), vq);
                            acc[k] += wt * (vq + gy * (-(dy as f32)) + gx * (-(dx as f32)));
                        }
                        wsum += wt;
                    }
                }
                if wsum > 0.0 {
                    for k in 0..c {
                        val[j * c + k] = (acc[k] / wsum).clamp(0.0, 255.0);
                    }
                }
                flag[j] = Flag::Band;
                heap.push(MinEntry(tj, j));
            } else if tj < t[j] {
                t[j] = tj;
            }
        }
    }
    for i in 0..n {
        if hole[i] {
            for k in 0..c {
                frame[i * c + k] = val[i * c + k].round() as u8;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fills_a_ramp_and_leaves_known_pixels() {
        // First-order extrapolation reproduces a linear ramp closely.
        let (h, w) = (30, 40);
        let data: Vec<u8> = (0..h * w)
            .map(|i| (3 * (i % w) + 2 * (i / w) + 20) as u8)
            .collect();
        let hole: Vec<bool> = (0..h * w)
            .map(|i| (8..20).contains(&(i / w)) && (10..28).contains(&(i % w)))
            .collect();
        let mut f = data.clone();
        for (v, &b) in f.iter_mut().zip(&hole) {
            if b {
                *v = 0;
            }
        }
        let holes = ImageView::plane(h, w, &hole).unwrap();
        let f = telea(ImageView::plane(h, w, &f).unwrap(), holes, 5.0)
            .unwrap()
            .into_data();
        let err = f
            .iter()
            .zip(&data)
            .map(|(a, b)| a.abs_diff(*b))
            .max()
            .unwrap();
        assert!(err <= 3, "max error {err}");
        for i in 0..h * w {
            if !hole[i] {
                assert_eq!(f[i], data[i]);
            }
        }
    }

    #[test]
    fn a_radius_beyond_the_frame_is_the_whole_frame() {
        // Every pixel of a 30 x 40 frame lies within 50 pixels of every other, so any larger
        // radius weighs the same neighbours (a radius of 1e15 looped over its whole square).
        let (h, w) = (30, 40);
        let data: Vec<u8> = (0..h * w).map(|i| ((i * 37) % 251) as u8).collect();
        let hole: Vec<bool> = (0..h * w)
            .map(|i| (8..20).contains(&(i / w)) && (10..28).contains(&(i % w)))
            .collect();
        let f = ImageView::plane(h, w, &data).unwrap();
        let m = ImageView::plane(h, w, &hole).unwrap();
        let near = telea(f, m, 50.0).unwrap().into_data();
        assert_eq!(telea(f, m, 1e15).unwrap().into_data(), near);
        assert_eq!(telea(f, m, f32::MAX).unwrap().into_data(), near);
        assert_ne!(telea(f, m, 5.0).unwrap().into_data(), near);
    }

    #[test]
    fn bad_arguments_are_refused_by_name() {
        let frame = vec![0u8; 12];
        let hole = [true, false, false, false];
        let f = ImageView::new(2, 2, 3, &frame).unwrap();
        let m = ImageView::plane(2, 2, &hole[..]).unwrap();
        assert!(telea(f, m, 3.0).is_ok());
        let arg = |r: Result<Image<u8>>| r.unwrap_err().argument();
        assert_eq!(arg(telea(f, m, 0.5)), Some("radius"));
        assert_eq!(arg(telea(f, m, f32::NAN)), Some("radius"));
        let all = ImageView::plane(2, 2, &[true; 4][..]).unwrap();
        assert_eq!(arg(telea(f, all, 3.0)), Some("hole"));
        let wide = ImageView::new(1, 2, 6, &frame).unwrap();
        let m2 = ImageView::plane(1, 2, &hole[..2]).unwrap();
        assert_eq!(arg(telea(wide, m2, 3.0)), Some("frame"));
        let small = ImageView::plane(1, 2, &hole[..2]).unwrap();
        assert!(telea(f, small, 3.0).is_err());
    }
}
