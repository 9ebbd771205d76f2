//! Geometry of binary masks: 8-connected components, hole filling, the exact Euclidean
//! distance transform, dilation / erosion / closing with exact Euclidean disks, Moore-neighbour
//! contour tracing, convex hulls and convexity defects. Used by the hand-pose generator and
//! features (paper 05) and by the ear occlusion detector (paper 14).
//!
//! Conventions: masks are single-channel [`ImageView`]s of bytes, any non-zero byte is
//! foreground; a pixel
//! is identified with its centre, at integer coordinates `(x, y) = (column, row)`; the area
//! outside the image is background (the disk operations state their own border rule).

use wscg_math::{Error, Image, ImageView, Result};

/// The eight neighbour offsets `(dx, dy)`, clockwise on screen (y pointing down), starting
/// east: E, SE, S, SW, W, NW, N, NE.
const DIRS: [(i64, i64); 8] = [
    (1, 0),
    (1, 1),
    (0, 1),
    (-1, 1),
    (-1, 0),
    (-1, -1),
    (0, -1),
    (1, -1),
];

/// Index into [`DIRS`] of the offset `(dx, dy)` (each in `-1..=1`, not both 0).
fn dir_index(dx: i64, dy: i64) -> usize {
    match (dx, dy) {
        (1, 0) => 0,
        (1, 1) => 1,
        (0, 1) => 2,
        (-1, 1) => 3,
        (-1, 0) => 4,
        (-1, -1) => 5,
        (0, -1) => 6,
        _ => 7,
    }
}

/// The values, height and width of a single-channel mask (the error names `mask`).
fn plane(mask: ImageView<'_, u8>) -> Result<(&[u8], usize, usize)> {
    mask.ensure_plane("mask")?;
    Ok((mask.data(), mask.height(), mask.width()))
}

/// Inclusive box `(x0, x1, y0, y1)` of the pixels of the single-channel image `v` for which
/// `inside` holds, grown by `margin` and clipped to the image; `None` when there are none.
pub fn bounding_box<T: Copy>(
    v: ImageView<'_, T>,
    margin: usize,
    inside: impl Fn(&T) -> bool,
) -> Option<(usize, usize, usize, usize)> {
    let (h, w) = (v.height(), v.width());
    let (mut x0, mut x1, mut y0, mut y1) = (usize::MAX, 0, usize::MAX, 0);
    for y in 0..h {
        let row = &v.data()[y * w..(y + 1) * w];
        let Some(first) = row.iter().position(&inside) else {
            continue;
        };
        let last = row.iter().rposition(&inside).unwrap_or(first);
        x0 = x0.min(first);
        x1 = x1.max(last);
        y0 = y0.min(y);
        y1 = y;
    }
    (x0 != usize::MAX).then(|| {
        (
            x0.saturating_sub(margin),
            (x1 + margin).min(w - 1),
            y0.saturating_sub(margin),
            (y1 + margin).min(h - 1),
        )
    })
}

/// The largest 8-connected component of `mask` as a 0/1 mask, with its area in pixels.
///
/// Ties go to the component reached first in row-major order. An empty mask gives an all-zero
/// mask and area 0. Errors: a mask with more than one channel.
pub fn largest_component(mask: ImageView<'_, u8>) -> Result<(Image<u8>, usize)> {
    let (mask, h, w) = plane(mask)?;
    let mut label = vec![0u32; h * w];
    let mut stack = Vec::new();
    let (mut best_label, mut best_area) = (0u32, 0usize);
    let mut next = 0u32;
    for start in 0..h * w {
        if mask[start] == 0 || label[start] != 0 {
            continue;
        }
        next += 1;
        label[start] = next;
        stack.push(start);
        let mut area = 0usize;
        while let Some(i) = stack.pop() {
            area += 1;
            let (y, x) = (i / w, i % w);
            for &(dx, dy) in &DIRS {
                let (nx, ny) = (x as i64 + dx, y as i64 + dy);
                if nx < 0 || ny < 0 || nx >= w as i64 || ny >= h as i64 {
                    continue;
                }
                let j = ny as usize * w + nx as usize;
                if mask[j] != 0 && label[j] == 0 {
                    label[j] = next;
                    stack.push(j);
                }
            }
        }
        if area > best_area {
            best_area = area;
            best_label = next;
        }
    }
    let out = label
        .iter()
        .map(|&l| u8::from(best_area > 0 && l == best_label))
        .collect();
    Ok((Image::new(h, w, 1, out)?, best_area))
}

/// `mask` with its holes filled: background pixels that are not 4-connected to the image
/// border (the background connectivity that goes with 8-connected foreground) become 1. The
/// result is 0/1, the binary image of the filled outer contours (as OpenCV's `drawContours`
/// with `FILLED` of the external contours). Errors: a mask with more than one channel.
pub fn fill_holes(mask: ImageView<'_, u8>) -> Result<Image<u8>> {
    let (mask, h, w) = plane(mask)?;
    // 0: background not reached (yet), 1: foreground, 2: background reached from the border.
    let mut state: Vec<u8> = mask.iter().map(|&m| u8::from(m != 0)).collect();
    let mut stack: Vec<usize> = Vec::new();
    for y in 0..h {
        for x in 0..w {
            if (y == 0 || x == 0 || y + 1 == h || x + 1 == w) && state[y * w + x] == 0 {
                state[y * w + x] = 2;
                stack.push(y * w + x);
            }
        }
    }
    while let Some(i) = stack.pop() {
        let (y, x) = (i / w, i % w);
        let mut visit = |j: usize| {
            if state[j] == 0 {
                state[j] = 2;
                stack.push(j);
            }
        };
        if x > 0 {
            visit(i - 1);
        }
        if x + 1 < w {
            visit(i + 1);
        }
        if y > 0 {
            visit(i - w);
        }
        if y + 1 < h {
            visit(i + w);
        }
    }
    Image::new(h, w, 1, state.iter().map(|&s| u8::from(s != 2)).collect())
}

/// Exact squared Euclidean distance of every pixel to the nearest background pixel (0 on the
/// background; the area outside the image counts as background, so a pixel on the image edge
/// has distance 1).
///
/// Felzenszwalb-Huttenlocher ([`wscg_math::distance::squared_edt`]): `O(h w)`, exact.
/// Errors: a mask with more than one channel.
pub fn squared_distance_transform(mask: ImageView<'_, u8>) -> Result<Image<f64>> {
    let (mask, h, w) = plane(mask)?;
    let background: Vec<bool> = mask.iter().map(|&m| m == 0).collect();
    let d2 = wscg_math::distance::squared_edt(&background, &[h, w], &[1.0, 1.0], true)?;
    Image::new(h, w, 1, d2)
}

/// Exact Euclidean distance transform: the square root of [`squared_distance_transform`].
pub fn distance_transform(mask: ImageView<'_, u8>) -> Result<Image<f64>> {
    let mut d = squared_distance_transform(mask)?;
    for v in d.data_mut() {
        *v = v.sqrt();
    }
    Ok(d)
}

/// Dilation of `mask` by the exact Euclidean disk `{(dx, dy): dx^2 + dy^2 <= radius^2}`: a
/// pixel is set iff some foreground pixel lies within `radius` of it. The outside of the image
/// is background (it dilates nothing in). Computed as a threshold of the exact distance
/// transform of the foreground, `O(h w)` for any radius. Result 0/1.
///
/// Errors: a mask with more than one channel, a negative or non-finite radius.
pub fn dilate_disk(mask: ImageView<'_, u8>, radius: f64) -> Result<Image<u8>> {
    disk_threshold(mask, radius, true)
}

/// Erosion of `mask` by the exact Euclidean disk of `radius`: a pixel stays set iff no
/// background pixel of the image lies within `radius` of it. The outside of the image counts
/// as foreground, so erosion does not eat in from the border (the convention of
/// `skimage.morphology.binary_erosion` and of `scipy.ndimage.binary_erosion(border_value=1)`).
/// Result 0/1. Errors as [`dilate_disk`].
pub fn erode_disk(mask: ImageView<'_, u8>, radius: f64) -> Result<Image<u8>> {
    disk_threshold(mask, radius, false)
}

/// Closing (dilation, then erosion) by the exact Euclidean disk of `radius`, with the border
/// rules of [`dilate_disk`] and [`erode_disk`]; the closing is then extensive (every input
/// foreground pixel stays set), equal to `skimage.morphology.binary_closing(mask,
/// skimage.morphology.disk(radius))` for integer radii. Errors as [`dilate_disk`].
pub fn close_disk(mask: ImageView<'_, u8>, radius: f64) -> Result<Image<u8>> {
    let d = dilate_disk(mask, radius)?;
    erode_disk(d.view(), radius)
}

/// Dilation (`dilate`) or erosion as a threshold of an exact squared distance transform.
fn disk_threshold(mask: ImageView<'_, u8>, radius: f64, dilate: bool) -> Result<Image<u8>> {
    let (mask, h, w) = plane(mask)?;
    if !(radius.is_finite() && radius >= 0.0) {
        return Err(Error::invalid(
            "radius",
            format!("must be finite and >= 0, got {radius}"),
        ));
    }
    // Distance to the foreground (dilation) or to the background (erosion); the outside of
    // the image is never a feature, so it neither dilates in nor erodes in.
    let feature: Vec<bool> = mask.iter().map(|&m| (m != 0) == dilate).collect();
    let d2 = wscg_math::distance::squared_edt(&feature, &[h, w], &[1.0, 1.0], false)?;
    let r2 = radius * radius;
    let out = d2
        .iter()
        .map(|&d| u8::from(if dilate { d <= r2 } else { d > r2 }))
        .collect();
    Image::new(h, w, 1, out)
}

/// Outer boundary of the 8-connected component holding the first foreground pixel in
/// row-major order, traced clockwise on screen by Moore-neighbour tracing, as pixel
/// coordinates `(x, y)`.
///
/// The trace starts at that first pixel and stops when the step from the start pixel to the
/// second boundary pixel would repeat, so pixels on one-pixel-wide parts appear once per
/// visit (as the contours of OpenCV's `findContours`). Holes are not traced. An empty mask
/// gives an empty contour, a lone pixel a one-point contour. Errors: a mask with more than
/// one channel.
pub fn trace_contour(mask: ImageView<'_, u8>) -> Result<Vec<(i64, i64)>> {
    let (mask, h, w) = plane(mask)?;
    let Some(first) = mask.iter().position(|&m| m != 0) else {
        return Ok(Vec::new());
    };
    let fg = |x: i64, y: i64| -> bool {
        x >= 0 && y >= 0 && x < w as i64 && y < h as i64 && mask[y as usize * w + x as usize] != 0
    };
    // From `p`, whose neighbour in direction `back` is background, sweep clockwise to the
    // next foreground neighbour; return it with the direction from it to the last background
    // pixel of the sweep.
    let step = |p: (i64, i64), back: usize| -> Option<((i64, i64), usize)> {
        for k in 1..=8 {
            let nd = (back + k) % 8;
            let q = (p.0 + DIRS[nd].0, p.1 + DIRS[nd].1);
            if fg(q.0, q.1) {
                let pd = (back + k - 1) % 8;
                let b = (p.0 + DIRS[pd].0, p.1 + DIRS[pd].1);
                return Some((q, dir_index(b.0 - q.0, b.1 - q.1)));
            }
        }
        None
    };
    let start = ((first % w) as i64, (first / w) as i64);
    // The first foreground pixel has background to its west (and the whole row above).
    let Some((second, back)) = step(start, 4) else {
        return Ok(vec![start]);
    };
    let area = mask.iter().filter(|&&m| m != 0).count();
    let cap = 4 * area + 8;
    let mut contour = vec![start];
    let (mut p, mut back) = (second, back);
    while contour.len() < cap {
        let Some((q, nb)) = step(p, back) else {
            break;
        };
        if p == start && q == second {
            break;
        }
        contour.push(p);
        p = q;
        back = nb;
    }
    Ok(contour)
}

fn cross(o: (i64, i64), a: (i64, i64), b: (i64, i64)) -> i64 {
    (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0)
}

/// Convex hull of integer points by Andrew's monotone chain: the vertices, without repeated or
/// collinear points, counter-clockwise in `(x, y)` coordinates (clockwise on screen, where y
/// points down). One point gives one vertex, collinear points their two ends, none gives none.
pub fn convex_hull(points: &[(i64, i64)]) -> Vec<(i64, i64)> {
    let mut p = points.to_vec();
    p.sort_unstable();
    p.dedup();
    if p.len() <= 2 {
        return p;
    }
    let mut hull: Vec<(i64, i64)> = Vec::with_capacity(2 * p.len());
    for &pt in &p {
        while hull.len() >= 2 && cross(hull[hull.len() - 2], hull[hull.len() - 1], pt) <= 0 {
            hull.pop();
        }
        hull.push(pt);
    }
    let lower = hull.len() + 1;
    for &pt in p.iter().rev().skip(1) {
        while hull.len() >= lower && cross(hull[hull.len() - 2], hull[hull.len() - 1], pt) <= 0 {
            hull.pop();
        }
        hull.push(pt);
    }
    hull.pop();
    hull
}

fn gcd(mut a: i64, mut b: i64) -> i64 {
    a = a.abs();
    b = b.abs();
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a
}

/// Number of lattice points (pixel centres) inside or on the convex polygon `hull` (vertices
/// in order, as [`convex_hull`] returns them), by Pick's theorem: `A + B / 2 + 1` with `A` the
/// polygon area and `B` the lattice points on its boundary. Exact integer arithmetic; also right
/// for the degenerate hulls (one point, a segment). Zero for no vertices.
pub fn hull_lattice_count(hull: &[(i64, i64)]) -> u64 {
    match hull.len() {
        0 => 0,
        1 => 1,
        n => {
            let (mut twice_area, mut boundary) = (0i64, 0i64);
            for i in 0..n {
                let (a, b) = (hull[i], hull[(i + 1) % n]);
                twice_area += a.0 * b.1 - b.0 * a.1;
                boundary += gcd(b.0 - a.0, b.1 - a.1);
            }
            // Pick: 2A = 2I + B - 2, so 2A + B is even.
            ((twice_area.abs() + boundary) / 2 + 1) as u64
        }
    }
}

/// Largest convexity-defect depth of a closed `contour` (as OpenCV's `convexityDefects`): for
/// every pair of consecutive hull vertices, the largest distance of the contour points between
/// them (in contour order) to the line through the two vertices. `hull` must hold points of the
/// contour (as [`convex_hull`] of the contour gives). Zero when the hull has fewer than two
/// vertices.
pub fn max_defect_depth(contour: &[(i64, i64)], hull: &[(i64, i64)]) -> f64 {
    let mut idx: Vec<usize> = hull
        .iter()
        .filter_map(|v| contour.iter().position(|p| p == v))
        .collect();
    idx.sort_unstable();
    idx.dedup();
    if idx.len() < 2 {
        return 0.0;
    }
    let n = contour.len();
    let mut best = 0.0f64;
    for k in 0..idx.len() {
        let (i0, i1) = (idx[k], idx[(k + 1) % idx.len()]);
        let (a, b) = (contour[i0], contour[i1]);
        let (ex, ey) = ((b.0 - a.0) as f64, (b.1 - a.1) as f64);
        let len = (ex * ex + ey * ey).sqrt();
        if len == 0.0 {
            continue;
        }
        let mut j = (i0 + 1) % n;
        while j != i1 {
            let p = contour[j];
            let c = ex * (p.1 - a.1) as f64 - ey * (p.0 - a.0) as f64;
            best = best.max(c.abs() / len);
            j = (j + 1) % n;
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::Rng;

    fn brute_sq_dt(mask: &[u8], h: usize, w: usize) -> Vec<f64> {
        // Background: every zero pixel plus the one-pixel ring around the image.
        let mut bg = Vec::new();
        for y in -1..=h as i64 {
            for x in -1..=w as i64 {
                let inside = x >= 0 && y >= 0 && x < w as i64 && y < h as i64;
                if !inside || mask[y as usize * w + x as usize] == 0 {
                    bg.push((x, y));
                }
            }
        }
        (0..h * w)
            .map(|i| {
                let (x, y) = ((i % w) as i64, (i / w) as i64);
                bg.iter()
                    .map(|&(bx, by)| ((bx - x).pow(2) + (by - y).pow(2)) as f64)
                    .fold(f64::INFINITY, f64::min)
            })
            .collect()
    }

    #[test]
    fn distance_transform_equals_brute_force() {
        let mut r = wscg_math::rng::seeded(11);
        for (h, w, p) in [(13, 17, 0.8), (20, 9, 0.95), (1, 6, 1.0), (7, 7, 0.3)] {
            let mask: Vec<u8> = (0..h * w).map(|_| u8::from(r.random_bool(p))).collect();
            let view = ImageView::plane(h, w, &mask).unwrap();
            let fast = squared_distance_transform(view).unwrap().into_data();
            let slow = brute_sq_dt(&mask, h, w);
            for (a, b) in fast.iter().zip(&slow) {
                assert!((a - b).abs() <= 1e-12, "{a} vs {b}");
            }
            let e = distance_transform(view).unwrap().into_data();
            for (a, b) in e.iter().zip(&slow) {
                assert!((a - b.sqrt()).abs() <= 1e-12);
            }
        }
    }

    #[test]
    fn largest_component_uses_8_connectivity() {
        // Two diagonal pixels (one 8-component of 2) and a pair of 3 pixels.
        #[rustfmt::skip]
        let m = [
            1, 0, 0, 0, 0,
            0, 1, 0, 1, 1,
            0, 0, 0, 0, 1,
        ];
        let (c, area) = largest_component(ImageView::plane(3, 5, &m).unwrap()).unwrap();
        assert_eq!(area, 3);
        assert_eq!(c.data(), [0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 0, 0, 0, 0, 1]);
        let (c, area) = largest_component(ImageView::plane(2, 3, &[0; 6]).unwrap()).unwrap();
        assert_eq!((c.data(), area), (&[0u8; 6][..], 0));
        assert!(largest_component(ImageView::new(1, 5, 3, &m).unwrap()).is_err());
    }

    #[test]
    fn holes_are_filled() {
        // A ring with a one-pixel hole, a diagonal gap (closed for 8-connected foreground, so
        // the pixel inside is a hole too) and a notch open to the outside.
        #[rustfmt::skip]
        let m = [
            0, 0, 0, 0, 0, 0, 0,
            0, 1, 1, 1, 0, 1, 0,
            0, 1, 0, 1, 1, 0, 1,
            0, 1, 1, 1, 0, 1, 0,
            0, 0, 0, 0, 0, 0, 0,
        ];
        #[rustfmt::skip]
        let want = [
            0, 0, 0, 0, 0, 0, 0,
            0, 1, 1, 1, 0, 1, 0,
            0, 1, 1, 1, 1, 1, 1,
            0, 1, 1, 1, 0, 1, 0,
            0, 0, 0, 0, 0, 0, 0,
        ];
        let filled = |m: &[u8], h, w| fill_holes(ImageView::plane(h, w, m).unwrap()).unwrap();
        assert_eq!(filled(&m, 5, 7).data(), want);
        assert_eq!(filled(&[1, 0, 1], 1, 3).data(), [1, 0, 1]);
        assert!(fill_holes(ImageView::new(5, 1, 7, &m).unwrap()).is_err());
    }

    #[test]
    fn contour_of_a_square_and_of_a_line() {
        // 3x3 square at (1..=3, 1..=3) in a 5x5 image: 8 boundary pixels, clockwise on screen.
        let mut m = vec![0u8; 25];
        for y in 1..4 {
            for x in 1..4 {
                m[y * 5 + x] = 1;
            }
        }
        let trace = |m: &[u8], h, w| trace_contour(ImageView::plane(h, w, m).unwrap()).unwrap();
        let c = trace(&m, 5, 5);
        assert_eq!(
            c,
            vec![
                (1, 1),
                (2, 1),
                (3, 1),
                (3, 2),
                (3, 3),
                (2, 3),
                (1, 3),
                (1, 2)
            ]
        );
        // A horizontal line is walked out and back.
        let c = trace(&[1, 1, 1], 1, 3);
        assert_eq!(c, vec![(0, 0), (1, 0), (2, 0), (1, 0)]);
        assert_eq!(trace(&[0, 1], 1, 2), vec![(1, 0)]);
        assert!(trace(&[0, 0], 1, 2).is_empty());
    }

    #[test]
    fn hull_and_lattice_count() {
        let pts = [(0, 0), (4, 0), (4, 3), (0, 3), (2, 1), (2, 0)];
        let h = convex_hull(&pts);
        assert_eq!(h, vec![(0, 0), (4, 0), (4, 3), (0, 3)]);
        assert_eq!(hull_lattice_count(&h), 20);
        assert_eq!(hull_lattice_count(&convex_hull(&[(0, 0), (6, 3)])), 4);
        assert_eq!(hull_lattice_count(&convex_hull(&[(5, 5)])), 1);
        // Triangle (0,0), (4,0), (0,4): 15 lattice points.
        assert_eq!(hull_lattice_count(&[(0, 0), (4, 0), (0, 4)]), 15);
    }

    #[test]
    fn disk_closing_matches_a_brute_force_reference() {
        let (h, w) = (23usize, 19usize);
        let mut state = 12345u64;
        let mask: Vec<u8> = (0..h * w)
            .map(|_| {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                u8::from((state >> 33) % 10 < 4)
            })
            .collect();
        let r = 3.0f64;
        let brute = |m: &[u8], dilate: bool| -> Vec<u8> {
            let mut out = vec![0u8; h * w];
            for y in 0..h as i64 {
                for x in 0..w as i64 {
                    let mut hit = !dilate;
                    for dy in -3i64..=3 {
                        for dx in -3i64..=3 {
                            if dx * dx + dy * dy > 9 {
                                continue;
                            }
                            let (yy, xx) = (y + dy, x + dx);
                            let inside = yy >= 0 && xx >= 0 && yy < h as i64 && xx < w as i64;
                            let v = inside && m[yy as usize * w + xx as usize] != 0;
                            if dilate && v {
                                hit = true;
                            }
                            if !dilate && inside && !v {
                                hit = false;
                            }
                        }
                    }
                    out[y as usize * w + x as usize] = u8::from(hit);
                }
            }
            out
        };
        let view = ImageView::plane(h, w, &mask).unwrap();
        let d = dilate_disk(view, r).unwrap();
        assert_eq!(d.data(), brute(&mask, true));
        let e = erode_disk(view, r).unwrap();
        assert_eq!(e.data(), brute(&mask, false));
        let c = close_disk(view, r).unwrap();
        assert_eq!(c.data(), brute(&brute(&mask, true), false));
        assert!(mask.iter().zip(c.data()).all(|(&m, &c)| m == 0 || c == 1));
        assert!(dilate_disk(view, f64::NAN).is_err());
        let two = ImageView::new(h, w / 2, 2, &mask[..h * (w / 2) * 2]).unwrap();
        assert!(close_disk(two, 2.0).is_err());
    }
}
