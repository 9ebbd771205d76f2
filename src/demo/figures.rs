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
}
