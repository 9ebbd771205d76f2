//! k-space sampling masks (paper 11, Fig. 2; the exact masks are not published). Masks are
//! un-shifted like the k-space (DC at index 0).

use rand::Rng;

use crate::fourier::signed_frequency as signed;
use wscg_math::{Error, Result};

fn check_rate(rate: f64) -> Result<()> {
    if !(rate > 0.0 && rate <= 1.0) {
        return Err(Error::invalid("rate", format!("{rate} is outside (0, 1]")));
    }
    Ok(())
}

/// Variable-density Cartesian mask: whole rows (phase encodes; every column of a chosen row
/// is sampled), `round(rate * rows)` of them. The `round(center_frac * rows)` rows nearest
/// DC are always taken; the others are drawn without replacement with probability
/// proportional to `(1 - |k| / k_max)^2` (seeded).
pub fn cartesian(
    rows: usize,
    cols: usize,
    rate: f64,
    center_frac: f64,
    seed: u64,
) -> Result<Vec<bool>> {
    check_rate(rate)?;
    if rows == 0 || cols == 0 {
        return Err(Error::Empty("mask shape"));
    }
    let n = wscg_math::alloc::ensure_shape::<bool>("shape", &[rows, cols])?;
    if !(0.0..=rate).contains(&center_frac) {
        return Err(Error::invalid(
            "center_frac",
            format!("{center_frac} must lie in [0, rate = {rate}]"),
        ));
    }
    let total = ((rate * rows as f64).round() as usize).clamp(1, rows);
    let centre = ((center_frac * rows as f64).round() as usize).min(total);
    let mut order: Vec<usize> = (0..rows).collect();
    order.sort_by_key(|&i| (signed(i, rows).abs(), signed(i, rows) < 0));
    let mut chosen = vec![false; rows];
    for &i in order.iter().take(centre) {
        chosen[i] = true;
    }
    // Weighted sampling without replacement (Efraimidis & Spirakis keys u^(1/w)).
    let kmax = rows as f64 / 2.0;
    let mut r = wscg_math::rng::seeded(seed);
    let mut keyed: Vec<(f64, usize)> = (0..rows)
        .filter(|&i| !chosen[i])
        .map(|i| {
            let w = (1.0 - signed(i, rows).abs() as f64 / kmax).max(0.0).powi(2);
            let u: f64 = r.random_range(f64::MIN_POSITIVE..1.0);
            let key = if w > 0.0 {
                u.ln() / w
            } else {
                f64::NEG_INFINITY
            };
            (key, i)
        })
        .collect();
    keyed.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    for &(_, i) in keyed.iter().take(total - centre) {
        chosen[i] = true;
    }
    let mut mask = wscg_math::alloc::try_with_capacity("shape", n)?;
    mask.extend((0..n).map(|k| chosen[k / cols]));
    Ok(mask)
}

/// Marks the pixels of a Bresenham line from `(r0, c0)` to `(r1, c1)` that fall inside the grid.
fn bresenham(
    mask: &mut [bool],
    rows: usize,
    cols: usize,
    (r0, c0): (i64, i64),
    (r1, c1): (i64, i64),
) {
    let (dr, dc) = ((r1 - r0).abs(), (c1 - c0).abs());
    let (sr, sc) = (if r1 >= r0 { 1 } else { -1 }, if c1 >= c0 { 1 } else { -1 });
    let (mut r, mut c) = (r0, c0);
    let mut err = dc - dr;
    loop {
        if r >= 0 && c >= 0 && (r as usize) < rows && (c as usize) < cols {
            mask[r as usize * cols + c as usize] = true;
        }
        if r == r1 && c == c1 {
            break;
        }
        let e2 = 2 * err;
        if e2 > -dr {
            err -= dr;
            c += sc;
        }
        if e2 < dc {
            err += dc;
            r += sr;
        }
    }
}

/// `lines` straight lines through the k-space centre at angles `pi l / lines`, rasterised
/// with Bresenham's algorithm; returned un-shifted.
pub fn radial_lines(rows: usize, cols: usize, lines: usize) -> Result<Vec<bool>> {
    if rows < 2 || cols < 2 {
        return Err(Error::invalid(
            "shape",
            format!("{rows} x {cols} is too small for radial lines"),
        ));
    }
    if lines == 0 {
        return Err(Error::invalid("lines", "must be at least 1"));
    }
    let n = wscg_math::alloc::ensure_shape::<bool>("shape", &[rows, cols])?;
    let mut centred = wscg_math::alloc::try_vec("shape", false, n)?;
    let (cr, cc) = ((rows / 2) as i64, (cols / 2) as i64);
    let reach = rows.max(cols) as f64;
    for l in 0..lines {
        let th = std::f64::consts::PI * l as f64 / lines as f64;
        let (s, c) = th.sin_cos();
        let a = (
            cr - (reach * s).round() as i64,
            cc - (reach * c).round() as i64,
        );
        let b = (
            cr + (reach * s).round() as i64,
            cc + (reach * c).round() as i64,
        );
        bresenham(&mut centred, rows, cols, a, b);
    }
    wscg_math::fft::ifftshift(&centred, &[rows, cols])
}

/// Pseudo-radial mask: the smallest number of [`radial_lines`] whose coverage reaches
/// `rate`. Returns the mask and the number of lines.
pub fn pseudo_radial(rows: usize, cols: usize, rate: f64) -> Result<(Vec<bool>, usize)> {
    check_rate(rate)?;
    let limit = 4 * rows.max(cols);
    for lines in 1..=limit {
        let m = radial_lines(rows, cols, lines)?;
        let cover = m.iter().filter(|&&v| v).count() as f64 / m.len() as f64;
        if cover >= rate {
            return Ok((m, lines));
        }
    }
    Ok((radial_lines(rows, cols, limit)?, limit))
}

/// Fraction of sampled positions.
pub fn sampling_rate(mask: &[bool]) -> f64 {
    mask.iter().filter(|&&v| v).count() as f64 / mask.len().max(1) as f64
}
