//! The directional filter bank (DFB) of the contourlet transform (Bamberger & Smith 1992; Do &
//! Vetterli 2005) in its ladder (lifting) form with the PKVA filters (Phoong, Kim,
//! Vaidyanathan & Ansari 1995), the DFB of Lu & Do's sharp-frequency-localized contourlet.
//!
//! An `n`-level DFB is a binary tree of two-channel filter banks that splits the frequency
//! plane into `2^n` wedges: two quincunx stages (fan, then quadrant filters) followed by
//! parallelogram stages (resampled by the shears `R1..R4`). Each two-channel stage is a
//! polyphase split (a permutation of the samples) followed by two ladder steps
//!
//! `y0 = (p0 - F p1) / sqrt 2`,  `y1 = -sqrt 2 p1 - F y0`,
//!
//! with `F = f ⊗ f` the modulated PKVA filter (a half-sample delay). The ladder makes the
//! bank perfectly reconstructing for any `f`; the PKVA filter makes it nearly orthogonal, so
//! the transform is a frame with bounds close to 1 and [`DirectionalFilterBank::adjoint`] differs slightly from
//! [`DirectionalFilterBank::inverse`].
//!
//! Boundaries are periodic; the first stage's polyphase components are quincunx-periodic
//! (a row wrap shifts the columns by half the width). The final back-sampling of Do's
//! implementation, a shear within each subband, is left out: it permutes the coefficients of
//! a band and changes neither their values nor any norm.

use num_complex::Complex64;
use rayon::prelude::*;
use wscg_math::{Error, Result};

/// The PKVA ladder filter of length 12 (Phoong et al. 1995; the `pkva12` filter of the
/// contourlet toolbox): one half of the symmetric impulse response.
const PKVA12_HALF: [f64; 6] = [0.6300, -0.1930, 0.0972, -0.0526, 0.0272, -0.0144];

/// The modulated ladder filter taps `(offset, weight)` of a 1-D pass with the given shift:
/// the output at `i` reads the input at `i + offset` (convolution with `f`, centred as the
/// toolbox's `sefilter2`).
fn ladder_taps(shift: i64) -> Vec<(i64, f64)> {
    let mut f: Vec<f64> = PKVA12_HALF.iter().rev().copied().collect();
    f.extend_from_slice(&PKVA12_HALF);
    let len = f.len() as i64;
    // Modulation: every other tap changes sign (the toolbox's f(1:2:end) = -f(1:2:end)).
    for (i, v) in f.iter_mut().enumerate() {
        if i % 2 == 0 {
            *v = -*v;
        }
    }
    let up = (len - 1) / 2 + shift;
    f.iter()
        .enumerate()
        .map(|(i, &w)| (len - 1 - i as i64 - up, w))
        .collect()
}

/// Polyphase split of a two-channel stage.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Split {
    /// Quincunx `Q1 = R2 D1 R3` (first level).
    Q1r,
    /// Quincunx `Q2 = R4 D2 R1` (second level).
    Q2c,
    /// Parallelogram `P1 = D1 R3`.
    P1,
    /// Parallelogram `P2 = D1 R4`.
    P2,
    /// Parallelogram `P3 = D2 R1`.
    P3,
    /// Parallelogram `P4 = D2 R2`.
    P4,
}

impl Split {
    /// Shape of each polyphase component of a `rows x cols` input.
    fn half(self, rows: usize, cols: usize) -> (usize, usize) {
        match self {
            Split::Q1r | Split::P1 | Split::P2 => (rows / 2, cols),
            Split::Q2c | Split::P3 | Split::P4 => (rows, cols / 2),
        }
    }

    /// Input indices of the two components (`src[k][j]` feeds element `j` of `p_k`).
    fn maps(self, rows: usize, cols: usize) -> [Vec<u32>; 2] {
        let (h, w) = self.half(rows, cols);
        let (ri, ci) = (rows as i64, cols as i64);
        let at = |r: i64, c: i64| (r.rem_euclid(ri) * ci + c.rem_euclid(ci)) as u32;
        let mut out = [Vec::with_capacity(h * w), Vec::with_capacity(h * w)];
        for a in 0..h as i64 {
            for b in 0..w as i64 {
                let (s0, s1) = match self {
                    // y = R2 x: y[r][c] = x[r - c][c]; p0[a][c] = y[2a][c + a],
                    // p1[a][c] = y[2a + 1][c + a + 1].
                    Split::Q1r => {
                        let c0 = (b + a).rem_euclid(ci);
                        let c1 = (b + a + 1).rem_euclid(ci);
                        (at(2 * a - c0, c0), at(2 * a + 1 - c1, c1))
                    }
                    // y = R4 x: y[r][c] = x[r][c - r]; p0[r][b] = y[r + b][2b],
                    // p1[r][b] = y[r + b + 1][2b + 1].
                    Split::Q2c => {
                        let r0 = (a + b).rem_euclid(ri);
                        let r1 = (a + b + 1).rem_euclid(ri);
                        (at(r0, 2 * b - r0), at(r1, 2 * b + 1 - r1))
                    }
                    Split::P1 => (at(2 * a, b + a), at(2 * a + 1, b + a + 1)),
                    Split::P2 => (at(2 * a, b - a), at(2 * a + 1, b - a)),
                    Split::P3 => (at(a + b, 2 * b), at(a + b + 1, 2 * b + 1)),
                    Split::P4 => (at(a - b, 2 * b), at(a - b, 2 * b + 1)),
                };
                out[0].push(s0);
                out[1].push(s1);
            }
        }
        out
    }
}

/// One two-channel stage of the tree, with its polyphase maps.
struct Stage {
    input: usize,
    outputs: [usize; 2],
    /// Shape of each output.
    shape: (usize, usize),
    /// Quincunx-periodic extension (first level).
    qper: bool,
    maps: [Vec<u32>; 2],
}

/// An `n`-level ladder DFB planned for one image shape.
pub struct DirectionalFilterBank {
    rows: usize,
    cols: usize,
    levels: usize,
    stages: Vec<Stage>,
    /// Buffer ids of the subbands, in directional order.
    leaves: Vec<usize>,
    /// Shape of every buffer.
    shapes: Vec<(usize, usize)>,
    taps: [Vec<(i64, f64)>; 2],
}

impl DirectionalFilterBank {
    /// Plans an `levels`-level DFB (`2^levels` directional subbands) for `rows x cols`
    /// images. Errors: sides not divisible by `2^levels`, or more than 8 levels.
    pub fn new(rows: usize, cols: usize, levels: usize) -> Result<Self> {
        if levels > 8 {
            return Err(Error::invalid(
                "dfb levels",
                format!("{levels} directional levels requested; at most 8 are supported"),
            ));
        }
        let need = 1usize << levels.max(1);
        if levels > 0
            && (!rows.is_multiple_of(need)
                || !cols.is_multiple_of(need)
                || rows < need
                || cols < need)
        {
            return Err(Error::invalid(
                "shape",
                format!(
                    "a {levels}-level directional filter bank needs both sides divisible by \
                     {need}; got {rows} x {cols}"
                ),
            ));
        }
        let mut shapes = vec![(rows, cols)];
        let mut stages = Vec::new();
        let mut add = |input: usize, split: Split, qper: bool, shapes: &mut Vec<(usize, usize)>| {
            let (r, c) = shapes[input];
            let shape = split.half(r, c);
            let a = shapes.len();
            shapes.push(shape);
            shapes.push(shape);
            stages.push(Stage {
                input,
                outputs: [a, a + 1],
                shape,
                qper,
                maps: split.maps(r, c),
            });
            (a, a + 1)
        };
        let leaves = match levels {
            0 => vec![0],
            1 => {
                let (a, b) = add(0, Split::Q1r, true, &mut shapes);
                vec![a, b]
            }
            _ => {
                let (x0, x1) = add(0, Split::Q1r, true, &mut shapes);
                let (a0, b0) = add(x0, Split::Q2c, false, &mut shapes);
                let (a1, b1) = add(x1, Split::Q2c, false, &mut shapes);
                let mut y = vec![b0, a0, b1, a1];
                for l in 3..=levels {
                    let half = 1usize << (l - 2);
                    let mut next = Vec::with_capacity(2 * y.len());
                    for (k, &id) in y.iter().enumerate() {
                        let split = match (k < half, k % 2) {
                            (true, 0) => Split::P1,
                            (true, _) => Split::P2,
                            (false, 0) => Split::P3,
                            (false, _) => Split::P4,
                        };
                        let (a, b) = add(id, split, false, &mut shapes);
                        next.push(b);
                        next.push(a);
                    }
                    y = next;
                }
                // The second half runs in the opposite angular order; flip it so that the
                // subbands sweep the directions monotonically.
                let h = y.len() / 2;
                y[h..].reverse();
                y
            }
        };
        Ok(DirectionalFilterBank {
            rows,
            cols,
            levels,
            stages,
            leaves,
            shapes,
            taps: [ladder_taps(0), ladder_taps(1)],
        })
    }

    /// Number of directional levels.
    pub fn levels(&self) -> usize {
        self.levels
    }

    /// Input shape.
    pub fn shape(&self) -> (usize, usize) {
        (self.rows, self.cols)
    }

    /// Shapes of the subbands in directional order (their sizes sum to the input size).
    pub fn band_shapes(&self) -> Vec<(usize, usize)> {
        self.leaves.iter().map(|&i| self.shapes[i]).collect()
    }

    /// Analysis: the subbands of `x` (`rows x cols`, row-major), concatenated in directional
    /// order into `out` (same length as `x`).
    pub fn forward(&self, x: &[Complex64], out: &mut [Complex64]) {
        let mut buf: Vec<Vec<Complex64>> = vec![Vec::new(); self.shapes.len()];
        buf[0] = x.to_vec();
        for st in &self.stages {
            let input = std::mem::take(&mut buf[st.input]);
            let (y0, y1) = self.stage_forward(st, &input);
            buf[st.outputs[0]] = y0;
            buf[st.outputs[1]] = y1;
        }
        self.gather_leaves(&mut buf, out);
    }

    /// Perfect reconstruction: `inverse(forward(x)) = x` up to rounding.
    pub fn inverse(&self, c: &[Complex64], out: &mut [Complex64]) {
        self.backward(c, out, false);
    }

    /// The adjoint `D^H` of [`DirectionalFilterBank::forward`].
    pub fn adjoint(&self, c: &[Complex64], out: &mut [Complex64]) {
        self.backward(c, out, true);
    }

    fn gather_leaves(&self, buf: &mut [Vec<Complex64>], out: &mut [Complex64]) {
        let mut off = 0;
        for &id in &self.leaves {
            let b = std::mem::take(&mut buf[id]);
            out[off..off + b.len()].copy_from_slice(&b);
            off += b.len();
        }
    }

    fn backward(&self, c: &[Complex64], out: &mut [Complex64], adjoint: bool) {
        let mut buf: Vec<Vec<Complex64>> = vec![Vec::new(); self.shapes.len()];
        let mut off = 0;
        for &id in &self.leaves {
            let (r, cc) = self.shapes[id];
            buf[id] = c[off..off + r * cc].to_vec();
            off += r * cc;
        }
        for st in self.stages.iter().rev() {
            let y0 = std::mem::take(&mut buf[st.outputs[0]]);
            let y1 = std::mem::take(&mut buf[st.outputs[1]]);
            buf[st.input] = self.stage_backward(st, &y0, &y1, adjoint);
        }
        out.copy_from_slice(&buf[0]);
    }

    fn stage_forward(&self, st: &Stage, x: &[Complex64]) -> (Vec<Complex64>, Vec<Complex64>) {
        let p0: Vec<Complex64> = st.maps[0].iter().map(|&i| x[i as usize]).collect();
        let p1: Vec<Complex64> = st.maps[1].iter().map(|&i| x[i as usize]).collect();
        let s2 = std::f64::consts::SQRT_2;
        let mut y0 = self.filter(&p1, st, 1, false);
        y0.iter_mut()
            .zip(&p0)
            .for_each(|(y, &p)| *y = (p - *y) / s2);
        let mut y1 = self.filter(&y0, st, 0, false);
        y1.iter_mut().zip(&p1).for_each(|(y, &p)| *y = -p * s2 - *y);
        (y0, y1)
    }

    fn stage_backward(
        &self,
        st: &Stage,
        y0: &[Complex64],
        y1: &[Complex64],
        adjoint: bool,
    ) -> Vec<Complex64> {
        let s2 = std::f64::consts::SQRT_2;
        let (p0, p1) = if adjoint {
            // y0 = (p0 - F1 p1)/sqrt2 and y1 = -sqrt2 p1 - F0 y0, transposed.
            let mut h = self.filter(y1, st, 0, true);
            h.iter_mut().zip(y0).for_each(|(v, &g)| *v = g - *v);
            let mut q1 = self.filter(&h, st, 1, true);
            q1.iter_mut()
                .zip(y1)
                .for_each(|(v, &g)| *v = -g * s2 - *v / s2);
            h.iter_mut().for_each(|v| *v /= s2);
            (h, q1)
        } else {
            let mut p1 = self.filter(y0, st, 0, false);
            p1.iter_mut()
                .zip(y1)
                .for_each(|(v, &g)| *v = -(g + *v) / s2);
            let mut p0 = self.filter(&p1, st, 1, false);
            p0.iter_mut().zip(y0).for_each(|(v, &g)| *v += g * s2);
            (p0, p1)
        };
        let (r, c) = self.shapes[st.input];
        let mut x = vec![Complex64::new(0.0, 0.0); r * c];
        for (k, p) in [p0, p1].iter().enumerate() {
            for (&i, &v) in st.maps[k].iter().zip(p) {
                x[i as usize] = v;
            }
        }
        x
    }

    /// The separable ladder filter `F = f ⊗ f` (or its transpose) on a stage output shape,
    /// with periodic or quincunx-periodic extension.
    fn filter(&self, x: &[Complex64], st: &Stage, shift: usize, transpose: bool) -> Vec<Complex64> {
        let (h, w) = st.shape;
        let sign = if transpose { -1 } else { 1 };
        let taps: Vec<(i64, f64)> = self.taps[shift]
            .iter()
            .map(|&(o, v)| (sign * o, v))
            .collect();
        let hi = h as i64;
        let half = if st.qper { w / 2 } else { 0 };
        // Vertical pass: a row wrap shifts the columns by w/2 when quincunx-periodic.
        let mut t = vec![Complex64::new(0.0, 0.0); h * w];
        // Rows per task: small subbands run on one thread (the pool's hand-offs would cost
        // more than the filtering).
        let min_rows = 8192usize.div_ceil(w);
        t.par_chunks_mut(w)
            .enumerate()
            .with_min_len(min_rows)
            .for_each(|(r, row)| {
                for &(o, v) in &taps {
                    let rr = r as i64 + o;
                    let src = &x[rr.rem_euclid(hi) as usize * w..][..w];
                    let cs = if rr.div_euclid(hi) % 2 != 0 { half } else { 0 };
                    let (a, b) = row.split_at_mut(w - cs);
                    a.iter_mut().zip(&src[cs..]).for_each(|(o, s)| *o += s * v);
                    b.iter_mut().zip(&src[..cs]).for_each(|(o, s)| *o += s * v);
                }
            });
        // Horizontal pass on a periodically padded copy of each row.
        let left = taps.iter().map(|t| -t.0).max().unwrap_or(0).max(0) as usize;
        let right = taps.iter().map(|t| t.0).max().unwrap_or(0).max(0) as usize;
        let mut y = vec![Complex64::new(0.0, 0.0); h * w];
        y.par_chunks_mut(w)
            .zip(t.par_chunks(w))
            .with_min_len(min_rows)
            .for_each_init(
                || Vec::with_capacity(w + left + right),
                |pad, (row, trow)| {
                    pad.clear();
                    pad.extend((0..left).map(|k| trow[(w * left - left + k) % w]));
                    pad.extend_from_slice(trow);
                    pad.extend((0..right).map(|k| trow[k % w]));
                    for &(o, v) in &taps {
                        let src = &pad[(left as i64 + o) as usize..][..w];
                        row.iter_mut().zip(src).for_each(|(o, s)| *o += s * v);
                    }
                },
            );
        y
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use wscg_math::rng;

    fn random(n: usize, seed: u64) -> Vec<Complex64> {
        rng::complex_normal_vec(seed, n, 1.0).unwrap()
    }

    #[test]
    fn perfect_reconstruction_and_adjoint() {
        for (r, c, n) in [
            (32, 32, 1),
            (32, 64, 2),
            (64, 32, 3),
            (64, 64, 4),
            (128, 128, 5),
        ] {
            let d = DirectionalFilterBank::new(r, c, n).unwrap();
            let shapes = d.band_shapes();
            assert_eq!(shapes.len(), 1 << n);
            assert_eq!(shapes.iter().map(|s| s.0 * s.1).sum::<usize>(), r * c);
            let x = random(r * c, 1);
            let mut y = vec![Complex64::new(0.0, 0.0); r * c];
            d.forward(&x, &mut y);
            let mut z = vec![Complex64::new(0.0, 0.0); r * c];
            d.inverse(&y, &mut z);
            let err = crate::sflct::max_diff(&x, &z);
            assert!(err < 1e-12, "{r}x{c} n={n}: {err}");
            // <D x, g> = <x, D^H g>.
            let g = random(r * c, 2);
            d.adjoint(&g, &mut z);
            let lhs: Complex64 = y.iter().zip(&g).map(|(a, b)| a.conj() * b).sum();
            let rhs: Complex64 = x.iter().zip(&z).map(|(a, b)| a.conj() * b).sum();
            assert!(
                (lhs - rhs).norm() < 1e-9 * lhs.norm().max(1.0),
                "{lhs} {rhs}"
            );
            // Nearly orthogonal: white noise gains a few per cent of energy per level.
            let ex: f64 = x.iter().map(|v| v.norm_sqr()).sum();
            let ey: f64 = y.iter().map(|v| v.norm_sqr()).sum();
            let ratio = ey / ex;
            assert!(
                ratio > 1.0 && ratio < 1.0 + 0.06 * n as f64,
                "n={n}: {ratio}"
            );
        }
    }

    /// Energy share of each subband of `DirectionalFilterBank::forward` for a real plane wave.
    fn band_shares(d: &DirectionalFilterBank, ky: f64, kx: f64) -> Vec<f64> {
        let (r, c) = d.shape();
        let tau = 2.0 * std::f64::consts::PI;
        let x: Vec<Complex64> = (0..r * c)
            .map(|i| {
                let (y, xx) = ((i / c) as f64, (i % c) as f64);
                Complex64::new((tau * (ky * y / r as f64 + kx * xx / c as f64)).cos(), 0.0)
            })
            .collect();
        let mut y = vec![Complex64::new(0.0, 0.0); r * c];
        d.forward(&x, &mut y);
        let mut off = 0;
        let mut e = Vec::new();
        for s in d.band_shapes() {
            let n = s.0 * s.1;
            e.push(y[off..off + n].iter().map(|v| v.norm_sqr()).sum::<f64>());
            off += n;
        }
        let t: f64 = e.iter().sum();
        e.iter().map(|v| v / t).collect()
    }

    /// The DFB's wedges: in the horizontal cone (|ky| <= |kx|) the `2^(n-1)` wedges are
    /// bounded by slopes `ky/kx = -1 + 2k/2^(n-1)`, in the vertical cone likewise with
    /// `kx/ky`. A plane wave at the centre of each wedge puts most of its energy in one
    /// subband, and the subbands sweep the directions in order (cyclically). The short PKVA
    /// filter softens the edges and moves the fan's 50 % line from 45 to about 41.5 degrees
    /// (a long half-sample-delay filter in the same ladder puts it at 45), so the narrow outer
    /// wedges of four levels keep only about half of a wave at their centre.
    #[test]
    fn plane_waves_land_in_their_wedge_in_order() {
        for n in [2usize, 3, 4] {
            let d = DirectionalFilterBank::new(128, 128, n).unwrap();
            let m = 1usize << (n - 1);
            let mut angles = Vec::new();
            for k in 0..m {
                let s = -1.0 + (2 * k + 1) as f64 / m as f64;
                angles.push(s.atan());
                angles.push(std::f64::consts::FRAC_PI_2 - s.atan());
            }
            for a in angles.iter_mut() {
                *a = a.rem_euclid(std::f64::consts::PI);
            }
            angles.sort_by(|a, b| a.total_cmp(b));
            let mut order = Vec::new();
            for &a in &angles {
                let (ky, kx) = ((40.0 * a.sin()).round(), (40.0 * a.cos()).round());
                let e = band_shares(&d, ky, kx);
                let (best, share) = e
                    .iter()
                    .enumerate()
                    .max_by(|a, b| a.1.total_cmp(b.1))
                    .map(|(i, &v)| (i, v))
                    .unwrap();
                let floor = if n < 4 { 0.9 } else { 0.45 };
                assert!(share >= floor, "n={n} angle {:.1}: {e:?}", a.to_degrees());
                order.push(best);
            }
            let first = order[0];
            for (i, &b) in order.iter().enumerate() {
                assert_eq!(b, (first + i) % (1 << n), "n={n}: band order {order:?}");
            }
        }
    }

    /// One ladder stage's expected energy gain on white noise, `trace(D^H D) / N`, from the
    /// taps alone: with `F0`, `F1` the two separable ladder filters the polyphase matrix is
    /// `[[1, -F1], [-F0, F0 F1 - 2]] / sqrt 2`, whose mean squared Frobenius norm over
    /// frequency, halved, is `(1 + |f1|^2 + |f0|^2 + |f0 * f1|^2 - 4 <f0, f1~> + 4) / 4` with
    /// 2-D norms the squares of the 1-D ones (1.038 for PKVA12). The measured gain of one
    /// level on noise matches it; a wrong modulation, tap placement or ladder sign does not.
    #[test]
    fn one_level_gain_matches_the_ladder_taps() {
        let t = [ladder_taps(0), ladder_taps(1)];
        let sq = |taps: &[(i64, f64)]| taps.iter().map(|p| p.1 * p.1).sum::<f64>().powi(2);
        // 1-D convolution of the two tap sets, by offset.
        let mut conv = std::collections::BTreeMap::<i64, f64>::new();
        for &(a, u) in &t[0] {
            for &(b, v) in &t[1] {
                *conv.entry(a + b).or_default() += u * v;
            }
        }
        let p = conv.values().map(|v| v * v).sum::<f64>().powi(2);
        // Zero lag of F0 F1 (the mean of the product over frequency).
        let r = conv.get(&0).copied().unwrap_or(0.0).powi(2);
        let want = (1.0 + sq(&t[0]) + sq(&t[1]) + p - 4.0 * r + 4.0) / 4.0;
        assert!((want - 1.038).abs() < 5e-4, "{want}");
        let d = DirectionalFilterBank::new(256, 256, 1).unwrap();
        let (mut ex, mut ey) = (0.0, 0.0);
        for seed in 0..4 {
            let x = random(256 * 256, 20 + seed);
            let mut y = vec![Complex64::new(0.0, 0.0); x.len()];
            d.forward(&x, &mut y);
            ex += x.iter().map(|v| v.norm_sqr()).sum::<f64>();
            ey += y.iter().map(|v| v.norm_sqr()).sum::<f64>();
        }
        assert!((ey / ex - want).abs() < 2e-3, "{} vs {want}", ey / ex);
    }

    #[test]
    fn bad_shapes_are_rejected() {
        assert!(DirectionalFilterBank::new(24, 32, 4).is_err());
        assert!(DirectionalFilterBank::new(64, 64, 9).is_err());
        assert!(DirectionalFilterBank::new(8, 8, 0).is_ok());
    }
}
