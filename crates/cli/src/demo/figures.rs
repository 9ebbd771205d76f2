//! Small raster figures for the demos: image montages and line plots (no text; captions
//! describe the colours and axes).

use wscg_math::image::Image;
use wscg_math::{Error, Result};

/// Tiles equally sized images into a grid of `cols` columns, each pixel enlarged to
/// `scale x scale`, with a one-cell white gap. Grey tiles stay grey; values are clamped to
/// `[0, 1]` on saving.
pub fn montage(tiles: &[Image], cols: usize, scale: usize) -> Result<Image> {
    let first = tiles.first().ok_or(Error::Empty("tiles"))?;
    let (h, w, c) = first.shape();
    if cols == 0 || scale == 0 {
        return Err(Error::invalid("cols", "cols and scale must be positive"));
    }
    if let Some(t) = tiles.iter().find(|t| t.shape() != (h, w, c)) {
        return Err(Error::ShapeMismatch(format!(
            "tile of shape {:?} among tiles of shape {:?}",
            t.shape(),
            (h, w, c)
        )));
    }
    let rows = tiles.len().div_ceil(cols);
    let (th, tw) = (h * scale + scale, w * scale + scale);
    let (oh, ow) = (rows * th + scale, cols * tw + scale);
    let mut out = Image::filled(oh, ow, c, 1.0f32)?;
    for (k, t) in tiles.iter().enumerate() {
        let (r0, c0) = (scale + (k / cols) * th, scale + (k % cols) * tw);
        for y in 0..h * scale {
            for x in 0..w * scale {
                for ch in 0..c {
                    out.set(r0 + y, c0 + x, ch, t.at(y / scale, x / scale, ch));
                }
            }
        }
    }
    Ok(out)
}

/// A plotted series: points `(x, y)` and an RGB colour.
pub struct Series {
    /// The points, in drawing order.
    pub points: Vec<(f64, f64)>,
    /// Line colour.
    pub color: [f32; 3],
}

/// Draws the series as polylines on a white `height x width` canvas with a grey frame and
/// light grid lines at the given x and y values; `x_range`/`y_range` map to the frame.
pub fn line_plot(
    series: &[Series],
    (height, width): (usize, usize),
    x_range: (f64, f64),
    y_range: (f64, f64),
    grid: (&[f64], &[f64]),
) -> Result<Image> {
    if x_range.1 <= x_range.0 || y_range.1 <= y_range.0 {
        return Err(Error::invalid("range", "each range needs max > min"));
    }
    let mut img = Image::filled(height, width, 3, 1.0f32)?;
    let m = 8.0;
    let (pw, ph) = (width as f64 - 2.0 * m, height as f64 - 2.0 * m);
    let px = |x: f64| m + (x - x_range.0) / (x_range.1 - x_range.0) * pw;
    let py = |y: f64| m + (1.0 - (y - y_range.0) / (y_range.1 - y_range.0)) * ph;
    let put = |img: &mut Image, x: f64, y: f64, col: [f32; 3], thick: f64| {
        let r = thick.ceil() as i64;
        for dy in -r..=r {
            for dx in -r..=r {
                let (xi, yi) = (x.round() as i64 + dx, y.round() as i64 + dy);
                if ((dx * dx + dy * dy) as f64) <= thick * thick
                    && xi >= 0
                    && yi >= 0
                    && (xi as usize) < width
                    && (yi as usize) < height
                {
                    for (ch, v) in col.iter().enumerate() {
                        img.set(yi as usize, xi as usize, ch, *v);
                    }
                }
            }
        }
    };
    let segment = |img: &mut Image, a: (f64, f64), b: (f64, f64), col, thick| {
        let steps = ((b.0 - a.0).abs().max((b.1 - a.1).abs()).ceil() as usize).max(1);
        for s in 0..=steps {
            let t = s as f64 / steps as f64;
            put(
                img,
                a.0 + t * (b.0 - a.0),
                a.1 + t * (b.1 - a.1),
                col,
                thick,
            );
        }
    };
    let light = [0.88, 0.88, 0.88];
    for &gx in grid.0 {
        segment(&mut img, (px(gx), m), (px(gx), m + ph), light, 0.0);
    }
    for &gy in grid.1 {
        segment(&mut img, (m, py(gy)), (m + pw, py(gy)), light, 0.0);
    }
    let frame = [0.4, 0.4, 0.4];
    let corners = [(m, m), (m + pw, m), (m + pw, m + ph), (m, m + ph), (m, m)];
    for w2 in corners.windows(2) {
        segment(&mut img, w2[0], w2[1], frame, 0.0);
    }
    for s in series {
        for p in s.points.windows(2) {
            let a = (px(p[0].0), py(p[0].1.clamp(y_range.0, y_range.1)));
            let b = (px(p[1].0), py(p[1].1.clamp(y_range.0, y_range.1)));
            segment(&mut img, a, b, s.color, 1.0);
        }
    }
    Ok(img)
}

/// A triangle mesh to draw: positions, triangles and an RGB colour.
pub struct Shape<'a> {
    /// Vertex positions.
    pub positions: &'a [[f64; 3]],
    /// Triangles (vertex indices).
    pub faces: &'a [[usize; 3]],
    /// Surface colour.
    pub color: [f32; 3],
    /// Per-vertex normals for smooth (Gouraud-interpolated normal) shading; `None` shades each
    /// triangle by its own normal. A zero normal shades black, as a renderer does with an
    /// undefined normal.
    pub normals: Option<&'a [[f64; 3]]>,
}

/// Renders the shapes on a white `size x size` canvas: orthographic view along `view` (from
/// the eye into the scene, `y` up), z-buffered, two-sided Lambert shading with a light
/// from the eye's upper left. The view is fitted to the shapes' bounding box.
pub fn shaded_meshes(shapes: &[Shape], view: [f64; 3], size: usize) -> Result<Image> {
    use nalgebra::Vector3;
    let f = Vector3::from(view)
        .try_normalize(1e-12)
        .ok_or_else(|| Error::invalid("view", "must be non-zero"))?;
    let r = f
        .cross(&Vector3::y())
        .try_normalize(1e-9)
        .unwrap_or_else(Vector3::x);
    let u = r.cross(&f);
    let light = (u + r * -0.5 - f).normalize();
    let pts: Vec<Vec<Vector3<f64>>> = shapes
        .iter()
        .map(|s| {
            s.positions
                .iter()
                .map(|&p| {
                    let p = Vector3::from(p);
                    Vector3::new(p.dot(&r), p.dot(&u), p.dot(&f))
                })
                .collect()
        })
        .collect();
    let all = || pts.iter().flatten();
    let (x0, x1) = all().fold((f64::MAX, f64::MIN), |a, p| (a.0.min(p.x), a.1.max(p.x)));
    let (y0, y1) = all().fold((f64::MAX, f64::MIN), |a, p| (a.0.min(p.y), a.1.max(p.y)));
    if !(x1 >= x0 && y1 >= y0) {
        return Err(Error::Empty("shapes"));
    }
    let span = (x1 - x0).max(y1 - y0).max(1e-12);
    let scale = 0.9 * size as f64 / span;
    let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let to_px = |p: &Vector3<f64>| {
        (
            0.5 * size as f64 + (p.x - cx) * scale,
            0.5 * size as f64 - (p.y - cy) * scale,
        )
    };
    let mut img = Image::filled(size, size, 3, 1.0f32)?;
    let mut depth = vec![f64::INFINITY; size * size];
    for (shape, p) in shapes.iter().zip(&pts) {
        for t in shape.faces {
            let (a, b, c) = (p[t[0]], p[t[1]], p[t[2]]);
            let n = (b - a).cross(&(c - a));
            let Some(n) = n.try_normalize(1e-300) else {
                continue;
            };
            let world_n = r * n.x + u * n.y + f * n.z;
            let shade = (0.3 + 0.7 * world_n.dot(&light).abs()) as f32;
            let q = [to_px(&a), to_px(&b), to_px(&c)];
            let area =
                (q[1].0 - q[0].0) * (q[2].1 - q[0].1) - (q[2].0 - q[0].0) * (q[1].1 - q[0].1);
            if area.abs() < 1e-12 {
                continue;
            }
            let xs = q.iter().map(|v| v.0);
            let ys = q.iter().map(|v| v.1);
            let lo_x = xs.clone().fold(f64::MAX, f64::min).floor().max(0.0) as usize;
            let hi_x = (xs.fold(f64::MIN, f64::max).ceil() as usize).min(size - 1);
            let lo_y = ys.clone().fold(f64::MAX, f64::min).floor().max(0.0) as usize;
            let hi_y = (ys.fold(f64::MIN, f64::max).ceil() as usize).min(size - 1);
            for py in lo_y..=hi_y {
                for px in lo_x..=hi_x {
                    let (sx, sy) = (px as f64 + 0.5, py as f64 + 0.5);
                    let w0 = ((q[1].0 - sx) * (q[2].1 - sy) - (q[2].0 - sx) * (q[1].1 - sy)) / area;
                    let w1 = ((q[2].0 - sx) * (q[0].1 - sy) - (q[0].0 - sx) * (q[2].1 - sy)) / area;
                    let w2 = 1.0 - w0 - w1;
                    if w0 < 0.0 || w1 < 0.0 || w2 < 0.0 {
                        continue;
                    }
                    let z = w0 * a.z + w1 * b.z + w2 * c.z;
                    let k = py * size + px;
                    if z < depth[k] {
                        depth[k] = z;
                        let shade = match shape.normals {
                            Some(vn) => {
                                let vn = t.map(|q| Vector3::from(vn[q]));
                                let n = vn[0] * w0 + vn[1] * w1 + vn[2] * w2;
                                (0.3 * n.norm().min(1.0) + 0.7 * n.dot(&light).abs()) as f32
                            }
                            None => shade,
                        };
                        for ch in 0..3 {
                            img.set(py, px, ch, shape.color[ch] * shade);
                        }
                    }
                }
            }
        }
    }
    Ok(img)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn montage_places_tiles() {
        let a = Image::filled(2, 3, 1, 0.0f32).unwrap();
        let m = montage(&[a.clone(), a.clone(), a], 2, 2).unwrap();
        assert_eq!(m.shape(), (2 * (4 + 2) + 2, 2 * (6 + 2) + 2, 1));
        assert_eq!(m.at(2, 2, 0), 0.0);
        assert_eq!(m.at(0, 0, 0), 1.0);
        // The fourth cell is empty.
        assert_eq!(m.at(8 + 1, 10 + 1, 0), 1.0);
        assert!(montage(&[], 2, 1).is_err());
    }

    #[test]
    fn plot_draws_lines_inside_frame() {
        let s = Series {
            points: vec![(0.0, 0.0), (1.0, 1.0)],
            color: [1.0, 0.0, 0.0],
        };
        let img = line_plot(&[s], (50, 50), (0.0, 1.0), (0.0, 1.0), (&[], &[])).unwrap();
        assert_eq!(img.at(25, 25, 0), 1.0);
        assert_eq!(img.at(25, 25, 1), 0.0);
        assert!(line_plot(&[], (10, 10), (1.0, 1.0), (0.0, 1.0), (&[], &[])).is_err());
    }

    #[test]
    fn shaded_meshes_draws_the_nearer_surface() {
        // Two unit squares facing the viewer (looking along -z), the red one nearer.
        let square = |z: f64| vec![[0.0, 0.0, z], [1.0, 0.0, z], [1.0, 1.0, z], [0.0, 1.0, z]];
        let faces = [[0, 1, 2], [0, 2, 3]];
        let (near, far) = (square(1.0), square(0.0));
        let img = shaded_meshes(
            &[
                Shape {
                    positions: &far,
                    faces: &faces,
                    color: [0.0, 0.0, 1.0],
                    normals: None,
                },
                Shape {
                    positions: &near,
                    faces: &faces,
                    color: [1.0, 0.0, 0.0],
                    normals: None,
                },
            ],
            [0.0, 0.0, -1.0],
            40,
        )
        .unwrap();
        assert!(img.at(20, 20, 0) > 0.2 && img.at(20, 20, 2) == 0.0);
        // The squares fill 90 % of the canvas; the corners stay white.
        assert_eq!(img.at(0, 0, 1), 1.0);
        let covered = (0..40 * 40)
            .filter(|k| img.at(k / 40, k % 40, 1) < 1.0)
            .count();
        assert!((covered as f64 - 36.0 * 36.0).abs() < 80.0, "{covered}");
    }
}
