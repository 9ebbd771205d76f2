//! Orthonormal Daubechies wavelets with periodic extension, in 1-D and separable 2-D.
//!
//! The transforms are PyWavelets' `dwt` / `wavedec2` with `mode="periodization"`: for a
//! filter of length `L` the analysis is `a[i] = sum_k lo[k] x[(2i + L/2 - k) mod n]` (and
//! `d` with the high-pass `hi[k] = (-1)^(k+1) lo[L-1-k]`), so the transform is orthogonal and
//! its inverse is its transpose. Multi-level 2-D coefficients are kept in the usual in-place
//! (Mallat) layout: after level `l` the approximation occupies the top-left block of
//! `rows / 2^l x cols / 2^l`; each level's details sit in the three blocks beside it
//! (top-right: high-pass along columns, PyWavelets' `cV`; bottom-left: high-pass along rows,
//! `cH`; bottom-right: both, `cD`).

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::image::Image;
use crate::view::ImageView;

/// Decomposition low-pass filters of Daubechies' orthonormal wavelets db1 ... db8, as
/// PyWavelets lists them (`pywt.Wavelet("dbN").dec_lo`).
const DB_LO: [&[f64]; 8] = [
    &[
        std::f64::consts::FRAC_1_SQRT_2,
        std::f64::consts::FRAC_1_SQRT_2,
    ],
    &[
        -0.12940952255126037,
        0.2241438680420134,
        0.8365163037378079,
        0.48296291314453416,
    ],
    &[
        0.03522629188570953,
        -0.08544127388202666,
        -0.13501102001025458,
        0.45987750211849154,
        0.8068915093110925,
        0.33267055295008263,
    ],
    &[
        -0.010597401785069032,
        0.0328830116668852,
        0.030841381835560764,
        -0.18703481171909309,
        -0.027983769416859854,
        0.6308807679298589,
        0.7148465705529157,
        0.2303778133088965,
    ],
    &[
        0.0033357252854737712,
        -0.012580751999081999,
        -0.006241490212798274,
        0.07757149384004572,
        -0.032244869584638375,
        -0.24229488706638203,
        0.13842814590132074,
        0.7243085284377729,
        0.6038292697971896,
        0.16010239797419293,
    ],
    &[
        -0.0010773010853084796,
        0.004777257510945511,
        0.0005538422011614961,
        -0.03158203931748603,
        0.027522865530305727,
        0.09750160558732304,
        -0.12976686756726194,
        -0.22626469396543983,
        0.31525035170919763,
        0.7511339080210954,
        0.49462389039845306,
        0.11154074335010947,
    ],
    &[
        0.00035371379997452024,
        -0.0018016407040474908,
        0.0004295779729213665,
        0.01255099855609984,
        -0.01657454163066688,
        -0.03802993693501441,
        0.08061260915108308,
        0.07130921926683026,
        -0.22403618499387498,
        -0.14390600392856498,
        0.4697822874051931,
        0.7291320908462351,
        0.3965393194819173,
        0.07785205408500918,
    ],
    &[
        -0.00011747678412476953,
        0.0006754494064505693,
        -0.00039174037337694705,
        -0.004870352993451574,
        0.008746094047405777,
        0.013981027917398282,
        -0.044088253930794755,
        -0.017369301001807547,
        0.12874742662047847,
        0.0004724845739132828,
        -0.2840155429615469,
        -0.015829105256349306,
        0.5853546836542067,
        0.6756307362972898,
        0.31287159091429995,
        0.05441584224310401,
    ],
];

/// An orthonormal Daubechies filter pair (`dbN`, N vanishing moments, length 2N).
#[derive(Clone, Debug, PartialEq)]
pub struct Daubechies {
    order: usize,
    lo: Vec<f64>,
    hi: Vec<f64>,
}

impl Daubechies {
    /// `dbN` for N in 1..=8 (db1 is the Haar wavelet).
    pub fn new(order: usize) -> Result<Self> {
        if !(1..=8).contains(&order) {
            return Err(Error::invalid(
                "order",
                format!("db{order} is not available; orders 1 to 8 are"),
            ));
        }
        let lo = DB_LO[order - 1].to_vec();
        let l = lo.len();
        let hi = (0..l)
            .map(|k| {
                if k % 2 == 0 {
                    -lo[l - 1 - k]
                } else {
                    lo[l - 1 - k]
                }
            })
            .collect();
        Ok(Daubechies { order, lo, hi })
    }

    /// The number of vanishing moments N.
    pub fn order(&self) -> usize {
        self.order
    }

    /// Decomposition low-pass filter.
    pub fn lo(&self) -> &[f64] {
        &self.lo
    }

    /// Decomposition high-pass filter.
    pub fn hi(&self) -> &[f64] {
        &self.hi
    }

    /// One analysis step on a line `x` of even length `n`: approximation into `out[..n/2]`,
    /// detail into `out[n/2..n]`. `pad` is a work buffer.
    fn analyze(&self, x: &[f64], out: &mut [f64], pad: &mut Vec<f64>) {
        let n = x.len();
        let l = self.lo.len();
        // pad[t] = x[(t - l) mod n], so x[(2i + l/2 - k) mod n] = pad[2i + l/2 - k + l].
        pad.clear();
        if l <= n {
            pad.extend_from_slice(&x[n - l..]);
            pad.extend_from_slice(x);
            pad.extend_from_slice(&x[..l]);
        } else {
            pad.extend((0..n + 2 * l).map(|t| x[(t + l * n - l) % n]));
        }
        let half = l / 2;
        let (a, d) = out[..n].split_at_mut(n / 2);
        for i in 0..n / 2 {
            let base = 2 * i + half + l;
            let (mut sa, mut sd) = (0.0, 0.0);
            for k in 0..l {
                let v = pad[base - k];
                sa += self.lo[k] * v;
                sd += self.hi[k] * v;
            }
            a[i] = sa;
            d[i] = sd;
        }
    }

    /// The transpose of [`Self::analyze`]: `c[..n/2]` approximation, `c[n/2..]` detail.
    fn synthesize(&self, c: &[f64], out: &mut [f64], pad: &mut Vec<f64>) {
        let n = c.len();
        let l = self.lo.len();
        let half = l / 2;
        pad.clear();
        pad.resize(n + 2 * l, 0.0);
        for i in 0..n / 2 {
            let (a, d) = (c[i], c[n / 2 + i]);
            let base = 2 * i + half + l;
            for k in 0..l {
                pad[base - k] += self.lo[k] * a + self.hi[k] * d;
            }
        }
        // Fold the padding back: pad[t] belongs to x[(t - l) mod n].
        if l <= n {
            out[..n].copy_from_slice(&pad[l..l + n]);
            for t in 0..l {
                out[n - l + t] += pad[t];
                out[t] += pad[n + l + t];
            }
        } else {
            out[..n].iter_mut().for_each(|v| *v = 0.0);
            for (t, &v) in pad.iter().enumerate() {
                out[(t + l * n - l) % n] += v;
            }
        }
    }
}

/// Approximation (LL) band of one level of the orthonormal 2-D Haar transform of a
/// single-channel image `x`: `LL[u][v] = (x[2u][2v] + x[2u][2v+1] + x[2u+1][2v] +
/// x[2u+1][2v+1]) / 2`, an image of half the height and width. For even sizes this is the
/// approximation of [`Wavelet2`] with `db1` and of `pywt.dwt2(x, "haar")[0]` (any extension
/// mode, since the Haar filter never reaches past an even-sized edge); it is the only band
/// paper 14's ear features keep.
///
/// Errors: an odd size, more than one channel.
pub fn haar_ll(plane: ImageView<'_, f64>) -> Result<Image<f64>> {
    plane.ensure_plane("plane")?;
    let (rows, cols) = (plane.height(), plane.width());
    if rows % 2 == 1 || cols % 2 == 1 {
        return Err(Error::ShapeMismatch(format!(
            "the Haar LL band needs even sizes; the plane is {rows} x {cols}"
        )));
    }
    let (hr, hc) = (rows / 2, cols / 2);
    let mut out = Vec::with_capacity(hr * hc);
    for u in 0..hr {
        let (a, b) = (plane.row(2 * u), plane.row(2 * u + 1));
        for v in 0..hc {
            out.push(0.5 * ((a[2 * v] + a[2 * v + 1]) + (b[2 * v] + b[2 * v + 1])));
        }
    }
    Image::new(hr, hc, 1, out)
}

/// A multi-level separable 2-D periodic wavelet transform of `rows x cols` images.
#[derive(Clone, Debug)]
pub struct Wavelet2 {
    rows: usize,
    cols: usize,
    levels: usize,
    filter: Daubechies,
}

impl Wavelet2 {
    /// Plans a `levels`-level transform. Both sizes must be divisible by `2^levels`.
    pub fn new(rows: usize, cols: usize, filter: Daubechies, levels: usize) -> Result<Self> {
        if levels == 0 {
            return Err(Error::invalid("levels", "must be at least 1"));
        }
        if levels > 20 {
            return Err(Error::invalid(
                "levels",
                format!("{levels} is more than 20"),
            ));
        }
        let div = 1usize << levels;
        if rows == 0 || cols == 0 || !rows.is_multiple_of(div) || !cols.is_multiple_of(div) {
            return Err(Error::ShapeMismatch(format!(
                "a {levels}-level wavelet transform needs both sizes divisible by {div}; \
                 the image is {rows} x {cols}"
            )));
        }
        Ok(Wavelet2 {
            rows,
            cols,
            levels,
            filter,
        })
    }

    /// `(rows, cols)`.
    pub fn shape(&self) -> (usize, usize) {
        (self.rows, self.cols)
    }

    /// Number of levels.
    pub fn levels(&self) -> usize {
        self.levels
    }

    /// The filter pair.
    pub fn filter(&self) -> &Daubechies {
        &self.filter
    }

    /// Forward transform of `x` (C order) into the Mallat layout `out` (same length).
    /// Panics when a length differs from `rows * cols` (an internal-invariant check).
    pub fn forward(&self, x: &[f64], out: &mut [f64]) {
        let (rows, cols) = (self.rows, self.cols);
        assert!(x.len() == rows * cols && out.len() == rows * cols);
        out.copy_from_slice(x);
        let (mut r, mut c) = (rows, cols);
        for _ in 0..self.levels {
            self.level(out, r, c, true);
            r /= 2;
            c /= 2;
        }
    }

    /// Inverse (= transpose) of [`Self::forward`].
    pub fn inverse(&self, coeffs: &[f64], out: &mut [f64]) {
        let (rows, cols) = (self.rows, self.cols);
        assert!(coeffs.len() == rows * cols && out.len() == rows * cols);
        out.copy_from_slice(coeffs);
        for l in (0..self.levels).rev() {
            self.level(out, rows >> l, cols >> l, false);
        }
    }

    /// One level on the top-left `r x c` block: rows then columns (forward), or columns then
    /// rows (inverse).
    fn level(&self, buf: &mut [f64], r: usize, c: usize, forward: bool) {
        let cols = self.cols;
        let f = &self.filter;
        let step = |line: &mut [f64], tmp: &mut Vec<f64>, pad: &mut Vec<f64>| {
            tmp.clear();
            tmp.resize(line.len(), 0.0);
            if forward {
                f.analyze(line, tmp, pad);
            } else {
                f.synthesize(line, tmp, pad);
            }
            line.copy_from_slice(tmp);
        };
        let along_rows = |buf: &mut [f64]| {
            buf.par_chunks_mut(cols).take(r).for_each_init(
                || (Vec::new(), Vec::new()),
                |(tmp, pad), line| step(&mut line[..c], tmp, pad),
            )
        };
        // Columns: each output row is a weighted sum of whole input rows (the same taps as
        // `analyze` / `synthesize`, vectorised across the columns), rows in parallel.
        let along_cols = |buf: &mut [f64]| {
            let (l, half, h) = (f.lo.len(), f.lo.len() / 2, r / 2);
            let mut t = vec![0.0; r * c];
            {
                let src = &*buf;
                let row = |i: usize| &src[i * cols..i * cols + c];
                t.par_chunks_mut(c).enumerate().for_each(|(o, out)| {
                    if forward {
                        // a[i] = sum_k lo[k] x[(2i + l/2 - k) mod r], d[i] likewise with hi.
                        let (i, taps) = if o < h { (o, &f.lo) } else { (o - h, &f.hi) };
                        for (k, &w) in taps.iter().enumerate() {
                            let x = row((2 * i + half + r * l - k) % r);
                            out.iter_mut().zip(x).for_each(|(y, &v)| *y += w * v);
                        }
                    } else {
                        // The transpose: x[o] gathers lo[k] a[i] + hi[k] d[i] over the taps
                        // with 2 i = o + k - l/2 (mod r).
                        for k in 0..l {
                            let s = o + k + r * l - half;
                            if s % 2 == 1 {
                                continue;
                            }
                            let i = (s % r) / 2;
                            let (a, d) = (row(i), row(h + i));
                            let (wl, wh) = (f.lo[k], f.hi[k]);
                            for ((y, &p), &q) in out.iter_mut().zip(a).zip(d) {
                                *y += wl * p + wh * q;
                            }
                        }
                    }
                });
            }
            for (i, line) in t.chunks(c).enumerate() {
                buf[i * cols..i * cols + c].copy_from_slice(line);
            }
        };
        if forward {
            along_rows(buf);
            along_cols(buf);
        } else {
            along_cols(buf);
            along_rows(buf);
        }
    }

    /// The level (1 = finest) and orientation (0: high-pass along columns, 1: along rows,
    /// 2: both) of the detail coefficient at Mallat index `idx`, or `None` for the coarsest
    /// approximation.
    pub fn band_of(&self, idx: usize) -> Option<(usize, usize)> {
        let (i, j) = (idx / self.cols, idx % self.cols);
        for l in 1..=self.levels {
            let (hr, hc) = (self.rows >> l, self.cols >> l);
            if i >= hr || j >= hc {
                let o = match (i >= hr, j >= hc) {
                    (false, true) => 0,
                    (true, false) => 1,
                    _ => 2,
                };
                return Some((l, o));
            }
        }
        None
    }

    /// Mallat index of the parent of detail coefficient `idx`: the coefficient of the same
    /// orientation one level coarser at half the position. `None` for the approximation and
    /// for details of the coarsest level.
    pub fn parent(&self, idx: usize) -> Option<usize> {
        let (l, _) = self.band_of(idx)?;
        if l == self.levels {
            return None;
        }
        let (i, j) = (idx / self.cols, idx % self.cols);
        let (hr, hc) = (self.rows >> l, self.cols >> l);
        // Position inside the band, then the same band one level coarser.
        let (bi, oi) = if i >= hr { (i - hr, hr / 2) } else { (i, 0) };
        let (bj, oj) = if j >= hc { (j - hc, hc / 2) } else { (j, 0) };
        Some((oi + bi / 2) * self.cols + oj + bj / 2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng;

    /// One level by the plain definition: `analyze` / `synthesize` on every row and, through
    /// an explicit transpose, on every column of the top-left `r x c` block.
    fn level_by_lines(w: &Wavelet2, buf: &mut [f64], r: usize, c: usize, forward: bool) {
        let cols = w.cols;
        let (mut tmp, mut pad) = (Vec::new(), Vec::new());
        let mut step = |line: &mut [f64]| {
            tmp.clear();
            tmp.resize(line.len(), 0.0);
            if forward {
                w.filter.analyze(line, &mut tmp, &mut pad);
            } else {
                w.filter.synthesize(line, &mut tmp, &mut pad);
            }
            line.copy_from_slice(&tmp);
        };
        let mut t = vec![0.0; r * c];
        let mut pass = |buf: &mut [f64], rows_first: bool| {
            if rows_first {
                for i in 0..r {
                    step(&mut buf[i * cols..i * cols + c]);
                }
            } else {
                for i in 0..r {
                    for j in 0..c {
                        t[j * r + i] = buf[i * cols + j];
                    }
                }
                t.chunks_mut(r).for_each(&mut step);
                for i in 0..r {
                    for j in 0..c {
                        buf[i * cols + j] = t[j * r + i];
                    }
                }
            }
        };
        pass(buf, forward);
        pass(buf, !forward);
    }

    #[test]
    fn levels_equal_the_line_by_line_definition() {
        for (order, rows, cols) in [(4, 64, 96), (8, 32, 16), (1, 8, 12), (8, 8, 8)] {
            let w = Wavelet2::new(rows, cols, Daubechies::new(order).unwrap(), 2).unwrap();
            let x = rng::normal_vec(order as u64, rows * cols, 0.0, 1.0).unwrap();
            for (r, c) in [(rows, cols), (rows / 2, cols / 2)] {
                for forward in [true, false] {
                    let (mut a, mut b) = (x.clone(), x.clone());
                    w.level(&mut a, r, c, forward);
                    level_by_lines(&w, &mut b, r, c, forward);
                    let err = a
                        .iter()
                        .zip(&b)
                        .map(|(p, q)| (p - q).abs())
                        .fold(0.0, f64::max);
                    assert!(err < 1e-12, "db{order} {r}x{c} forward={forward}: {err}");
                }
            }
        }
    }

    #[test]
    fn filters_are_orthonormal() {
        for n in 1..=8 {
            let f = Daubechies::new(n).unwrap();
            let l = f.lo().len();
            assert_eq!(l, 2 * n);
            for s in (0..l).step_by(2) {
                let dot: f64 = (0..l - s).map(|k| f.lo()[k] * f.lo()[k + s]).sum();
                let want = if s == 0 { 1.0 } else { 0.0 };
                assert!((dot - want).abs() < 1e-12, "db{n} shift {s}: {dot}");
            }
            let cross: f64 = f.lo().iter().zip(f.hi()).map(|(a, b)| a * b).sum();
            assert!(cross.abs() < 1e-12);
        }
        assert!(Daubechies::new(0).is_err() && Daubechies::new(9).is_err());
    }

    #[test]
    fn round_trip_and_parseval() {
        let (r, c) = (32, 48);
        let x = rng::normal_vec(5, r * c, 0.0, 1.0).unwrap();
        for n in [1, 2, 4, 8] {
            let w = Wavelet2::new(r, c, Daubechies::new(n).unwrap(), 3).unwrap();
            let mut y = vec![0.0; r * c];
            w.forward(&x, &mut y);
            let ex: f64 = x.iter().map(|v| v * v).sum();
            let ey: f64 = y.iter().map(|v| v * v).sum();
            assert!((ex - ey).abs() < 1e-10 * ex, "db{n}");
            let mut z = vec![0.0; r * c];
            w.inverse(&y, &mut z);
            let err = x
                .iter()
                .zip(&z)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(err < 1e-12, "db{n}: {err}");
        }
    }

    #[test]
    fn haar_of_a_constant_is_all_approximation() {
        let w = Wavelet2::new(8, 8, Daubechies::new(1).unwrap(), 3).unwrap();
        let mut y = vec![0.0; 64];
        w.forward(&[1.0; 64], &mut y);
        assert!((y[0] - 8.0).abs() < 1e-12);
        assert!(y[1..].iter().all(|v| v.abs() < 1e-12));
    }

    #[test]
    fn parents_are_one_level_coarser_same_orientation() {
        let w = Wavelet2::new(16, 16, Daubechies::new(2).unwrap(), 3).unwrap();
        // Finest vertical-detail band: rows 0..8, cols 8..16.
        let child = 5 * 16 + 13;
        let p = w.parent(child).unwrap();
        assert_eq!(w.band_of(child), Some((1, 0)));
        assert_eq!(w.band_of(p), Some((2, 0)));
        assert_eq!(p, 2 * 16 + (4 + 2));
        assert_eq!(w.parent(0), None);
        assert_eq!(w.parent(3 * 16 + 2), None); // coarsest level details
        assert!(Wavelet2::new(12, 16, Daubechies::new(2).unwrap(), 3).is_err());
    }

    #[test]
    fn haar_ll_is_the_db1_approximation_band() {
        let (r, c) = (6, 10);
        let x: Vec<f64> = (0..r * c)
            .map(|i| ((i * 37) % 11) as f64 * 0.3 - 1.0)
            .collect();
        let ll = haar_ll(ImageView::plane(r, c, &x).unwrap()).unwrap();
        let ll = ll.data();
        let w = Wavelet2::new(r, c, Daubechies::new(1).unwrap(), 1).unwrap();
        let mut y = vec![0.0; r * c];
        w.forward(&x, &mut y);
        for u in 0..r / 2 {
            for v in 0..c / 2 {
                assert!((ll[u * c / 2 + v] - y[u * c + v]).abs() < 1e-12);
            }
        }
        assert!(haar_ll(ImageView::plane(5, 12, &x).unwrap()).is_err());
        assert!(haar_ll(ImageView::plane(6, 8, &x[..48]).unwrap()).is_ok());
        assert!(haar_ll(ImageView::new(3, 10, 2, &x).unwrap()).is_err());
    }
}
