//! The frequency windows of the 2-D uniform discrete curvelet transform (Nguyen & Chauris,
//! "Uniform discrete curvelet transform", IEEE TSP 58(7), 2010), built on the same sampling
//! grids as the reference implementation `ucurv` 0.1.1 so that windows agree to rounding.
//!
//! Construction (paper 11, section 2.2, after Nguyen & Chauris eqs. 20-30):
//!
//! - a smooth step `nu(t) = 35 t^4 - 84 t^5 + 70 t^6 - 20 t^7` and the window
//!   `M(x; a, b, c, d)` rising on `[a, b]`, flat on `[b, c]`, falling on `[c, d]`;
//! - radial profiles `phi_j(w) = M(|w|; -2, -1, r1 / 2^(J-1-j), r2 / 2^(J-1-j))` for
//!   `j < J` and `phi_J(w) = M(|w|; -2, -1, r3, r4)`, on the grid `w_k = -1.5 pi + 2 pi k / N`;
//!   band-pass `BP_j = phi_{j+1} x phi_{j+1} - phi_j x phi_j`;
//! - in pyramid `d` (where `|w_d| >= |w_other|`), `n` angular windows uniform in the slope
//!   `t = -w_other / w_d`, `A_l(t) = M(t; -1 + 2l/n + (2/n)(-alpha, alpha, 1 - alpha, 1 + alpha))`,
//!   extended past the cone edges by `t +- 2`; each raw window `BP_j A_l` covers one half of
//!   the cone (one-sided), mirrored windows are obtained by `w -> -w`;
//! - normalisation by the periodised sum `S = Phi_0 + sum (U(w) + U(-w))`:
//!   `W = sqrt(2 |D| U / S)` for bands, `W_L = sqrt(|D_L| Phi_0 / S)` for the low-pass, which
//!   makes the transform a tight frame (Parseval).

use std::f64::consts::PI;

use super::UdctParams;

/// The window `M(x; p)`, evaluated as `ucurv.util.fun_meyer` does (the falling edge is
/// applied last).
pub(crate) fn meyer(x: f64, p: [f64; 4]) -> f64 {
    let poly = |t: f64| {
        let mut y = 0.0;
        for c in [-20.0, 70.0, -84.0, 35.0, 0.0, 0.0, 0.0, 0.0] {
            y = y * t + c;
        }
        y
    };
    let mut y = 1.0;
    if x <= p[0] || x >= p[3] {
        y = 0.0;
    }
    if x >= p[0] && x <= p[1] {
        y = poly((x - p[0]) / (p[1] - p[0]));
    }
    if x >= p[2] && x <= p[3] {
        y = poly((x - p[3]) / (p[2] - p[3]));
    }
    y
}

/// numpy's `linspace(start, stop, n)`: `k * step + start`, the last point set to `stop`.
fn linspace(start: f64, stop: f64, n: usize) -> Vec<f64> {
    let step = (stop - start) / (n - 1) as f64;
    let mut v: Vec<f64> = (0..n).map(|k| k as f64 * step + start).collect();
    v[n - 1] = stop;
    v
}

/// The band-pass grid `w_k = -1.5 pi + 2 pi k / n`.
fn shifted_grid(n: usize) -> Vec<f64> {
    linspace(-1.5 * PI, 0.5 * PI - PI / (n as f64 / 2.0), n)
}

/// The low-pass grid `w_k = -pi + 2 pi k / n`.
fn centred_grid(n: usize) -> Vec<f64> {
    linspace(-PI, PI - PI / (n as f64 / 2.0), n)
}

/// The slope grid of one pyramid (`ucurv.tan_theta_grid`): `s1` runs along the pyramid's
/// axis (rows of the result), `s2` along the other axis. Inside the cone the value is the
/// slope `-w2 / w1` in [-1, 1]; outside it is shifted by +-2 so that windows continue across
/// the cone edge; the half `w1 >= 0` is set to -2 (outside every window).
fn slope_grid(s1: &[f64], s2: &[f64]) -> Vec<f64> {
    let mut m = Vec::with_capacity(s1.len() * s2.len());
    for &x2 in s1 {
        for &x1 in s2 {
            if x2 >= 0.0 {
                m.push(-2.0);
                continue;
            }
            let t1 = if x2 != 0.0 && x1.abs() <= x2.abs() {
                -x1 / x2
            } else {
                0.0
            };
            let t2 = if x1 != 0.0 && x2.abs() < x1.abs() {
                x2 / x1
            } else {
                0.0
            };
            let t3 = if t2 < 0.0 {
                t2 + 2.0
            } else if t2 > 0.0 {
                t2 - 2.0
            } else {
                t2
            };
            m.push(t1 + t3);
        }
    }
    m
}

/// `out[(i + s) mod n] = in[i]` on both axes of an `r x c` array.
fn roll2(a: &[f64], r: usize, c: usize, sr: usize, sc: usize) -> Vec<f64> {
    let mut out = vec![0.0; r * c];
    for i in 0..r {
        for j in 0..c {
            out[((i + sr) % r) * c + (j + sc) % c] = a[i * c + j];
        }
    }
    out
}

/// `w -> -w` along axis 1 of an `r x c` array on an FFT-ordered grid: `out[i][j] = a[i][(c - j) mod c]`.
fn flip_axis1(a: &[f64], r: usize, c: usize) -> Vec<f64> {
    let mut out = vec![0.0; r * c];
    for i in 0..r {
        for j in 0..c {
            out[i * c + j] = a[i * c + (c - j) % c];
        }
    }
    out
}

/// Transpose of an `r x c` array.
fn transpose(a: &[f64], r: usize, c: usize) -> Vec<f64> {
    let mut out = vec![0.0; r * c];
    for i in 0..r {
        for j in 0..c {
            out[j * r + i] = a[i * c + j];
        }
    }
    out
}

/// Makes a raw window fold onto its decimated grid without overlap: of the entries that land
/// on the same decimated frequency, only the largest is kept.
///
/// With the paper's corners and overlap the support of the finest bands is slightly longer
/// than the decimated period (by the angular overlap), so a few tail entries (raw values
/// below about 1e-5) alias onto others; `ucurv` keeps them and is tight only to about 1e-10.
/// Removing them before the normalisation makes the frame exactly tight.
fn remove_aliases(w: &mut [f64], r: usize, c: usize, dec: [usize; 2]) {
    let (m0, m1) = (r / dec[0], c / dec[1]);
    let mut best: Vec<Option<usize>> = vec![None; m0 * m1];
    for k in 0..r * c {
        if w[k] == 0.0 {
            continue;
        }
        let f = ((k / c) % m0) * m1 + (k % c) % m1;
        match best[f] {
            None => best[f] = Some(k),
            Some(b) if w[k] > w[b] => {
                w[b] = 0.0;
                best[f] = Some(k);
            }
            Some(_) => w[k] = 0.0,
        }
    }
}

/// numpy's `fftshift` of an `r x c` array (both axes).
fn fftshift2(a: &[f64], r: usize, c: usize) -> Vec<f64> {
    roll2(a, r, c, r / 2, c / 2)
}

/// The decimation factors `[rows, cols]` of band `(scale, pyramid)` for `J` scales:
/// `2^(J - scale)` along the pyramid's axis, `2 (n / 3) 2^(J - scale - 1)` along the other,
/// `n` being the wedge count of that other axis.
pub(crate) fn band_decimation(cfg: &UdctParams, scale: usize, pyramid: usize) -> [usize; 2] {
    let j = cfg.wedges.len();
    let mut d = [0; 2];
    for (axis, v) in d.iter_mut().enumerate() {
        *v = if axis == pyramid {
            1 << (j - scale)
        } else {
            2 * (cfg.wedges[scale][axis] / 3) * (1 << (j - scale - 1))
        };
    }
    d
}

/// The low-pass decimation `2^(J-1)` on both axes.
pub(crate) fn lowpass_decimation(cfg: &UdctParams) -> [usize; 2] {
    let d = 1 << (cfg.wedges.len() - 1);
    [d, d]
}

/// The windows of a `rows x cols` transform in FFT order (DC at index 0): the low-pass window
/// and the band windows in the order scale, pyramid, wedge (`ucurv`'s dictionary order).
pub(crate) fn windows(rows: usize, cols: usize, cfg: &UdctParams) -> (Vec<f64>, Vec<Vec<f64>>) {
    let n = [rows, cols];
    let nscales = cfg.wedges.len();
    let r = cfg.radial;
    let sg = [shifted_grid(rows), shifted_grid(cols)];
    // f1d[scale][axis]
    let f1d: Vec<[Vec<f64>; 2]> = (0..=nscales)
        .map(|s| {
            let p = if s < nscales {
                let f = (1usize << (nscales - 1 - s)) as f64;
                [-2.0, -1.0, r[0] / f, r[1] / f]
            } else {
                [-2.0, -1.0, r[2], r[3]]
            };
            [0, 1].map(|a| sg[a].iter().map(|w| meyer(w.abs(), p)).collect())
        })
        .collect();
    let low_p = {
        let f = (1usize << (nscales - 1)) as f64;
        [-2.0, -1.0, r[0] / f, r[1] / f]
    };
    let fl1d: [Vec<f64>; 2] = [rows, cols].map(|len| {
        centred_grid(len)
            .iter()
            .map(|w| meyer(w.abs(), low_p))
            .collect()
    });
    let mut low = vec![0.0; rows * cols];
    for i in 0..rows {
        for j in 0..cols {
            low[i * cols + j] = fl1d[0][i] * fl1d[1][j];
        }
    }

    let mut raw: Vec<(usize, usize, Vec<f64>)> = Vec::new();
    for s in 0..nscales {
        for pyr in 0..2 {
            let other = 1 - pyr;
            let (n1, n2) = (n[pyr], n[other]);
            let slope = slope_grid(&sg[pyr], &sg[other]);
            let mut bp = vec![0.0; n1 * n2];
            for i in 0..n1 {
                for j in 0..n2 {
                    let outer = f1d[s + 1][pyr][i] * f1d[s + 1][other][j];
                    let inner = f1d[s][pyr][i] * f1d[s][other][j];
                    bp[i * n2 + j] = outer - inner;
                }
            }
            let nw = cfg.wedges[s][other];
            let angd = 2.0 / nw as f64;
            let a = cfg.alpha;
            let ang = [-a, a, 1.0 - a, 1.0 + a].map(|v| angd * v);
            let mut wedges = vec![Vec::new(); nw];
            for id in 0..nw.div_ceil(2) {
                let base = -1.0 + id as f64 * angd;
                let p = ang.map(|v| base + v);
                let x: Vec<f64> = slope
                    .iter()
                    .zip(&bp)
                    .map(|(&t, &b)| meyer(t, p) * b)
                    .collect();
                let x = roll2(&x, n1, n2, 3 * n1 / 4, 3 * n2 / 4);
                wedges[nw - 1 - id] = flip_axis1(&x, n1, n2);
                if nw - 1 - id != id {
                    wedges[id] = x;
                }
            }
            for w in wedges {
                let w = if pyr == 0 { w } else { transpose(&w, n1, n2) };
                raw.push((s, pyr, w));
            }
        }
    }

    if cfg.tight {
        for (s, pyr, w) in raw.iter_mut() {
            remove_aliases(w, rows, cols, band_decimation(cfg, *s, *pyr));
        }
    }
    let mut sum = vec![0.0; rows * cols];
    for (_, _, w) in &raw {
        sum.iter_mut().zip(w).for_each(|(s, v)| *s += v);
    }
    let mirrored: Vec<f64> = (0..rows * cols)
        .map(|k| {
            let (i, j) = (k / cols, k % cols);
            sum[((rows - i) % rows) * cols + (cols - j) % cols]
        })
        .collect();
    sum.iter_mut()
        .zip(mirrored.iter().zip(&low))
        .for_each(|(s, (m, l))| *s = *s + m + l);

    let normalise = |w: &[f64], factor: f64, outside: f64| -> Vec<f64> {
        let v: Vec<f64> = w
            .iter()
            .zip(&sum)
            .map(|(&u, &s)| {
                if s > 0.0 {
                    (factor * u / s).sqrt()
                } else {
                    outside
                }
            })
            .collect();
        fftshift2(&v, rows, cols)
    };
    let bands = raw
        .iter()
        .map(|(s, pyr, w)| {
            let d = band_decimation(cfg, *s, *pyr);
            normalise(w, 2.0 * (d[0] * d[1]) as f64, 0.0)
        })
        .collect();
    let dl = lowpass_decimation(cfg);
    let low = normalise(&low, 1.0, 0.0)
        .into_iter()
        .map(|v| ((dl[0] * dl[1]) as f64).sqrt() * v)
        .collect();
    (low, bands)
}
