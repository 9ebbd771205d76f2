//! Periodic (FFT) machinery of the region solvers: planned transforms per window size with the
//! finite-difference spectra of the KF prior, kernel transfer functions, MATLAB-style edge
//! tapering, and window extraction with mirrored borders.

use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

use num_complex::Complex32;
use realfft::{ComplexToReal, RealFftPlanner, RealToComplex};
use rustfft::{Fft, FftPlanner};
use wscg_math::{Error, Result};

use crate::kernel::Kernel;

/// Smallest `n' >= n` whose only prime factors are 2, 3 and 5 (fast FFT sizes).
pub fn smooth_size(n: usize) -> usize {
    let mut m = n.max(1);
    loop {
        let mut r = m;
        for p in [2, 3, 5] {
            while r.is_multiple_of(p) {
                r /= p;
            }
        }
        if r == 1 {
            return m;
        }
        m += 1;
    }
}

/// Planned grids by `(rows, cols)`.
type GridCache = HashMap<(usize, usize), Arc<Grid>>;

/// Scratch buffers of the transforms of one thread.
#[derive(Default)]
pub(crate) struct Scratch {
    c: Vec<Complex32>,
    r: Vec<f32>,
}

/// A planned `rows x cols` periodic grid with real-input transforms, and
/// `|F_x|^2 + |F_y|^2` of the difference filters `f_x = [1 -1]`, `f_y = [1 -1]^T` (paper
/// eq. 7). Spectra hold the `cols / 2 + 1` non-negative column frequencies of every row
/// frequency, stored column-frequency major (`j * rows + i`); every operation of the solvers
/// is elementwise on them.
pub(crate) struct Grid {
    pub rows: usize,
    pub cols: usize,
    half: usize,
    r2c: Arc<dyn RealToComplex<f32>>,
    c2r: Arc<dyn ComplexToReal<f32>>,
    col: [Arc<dyn Fft<f32>>; 2],
    work_len: usize,
    pub grad2: Vec<f32>,
}

impl Grid {
    fn new(rows: usize, cols: usize) -> Result<Self> {
        if rows == 0 || cols == 0 {
            return Err(Error::Empty("fft grid"));
        }
        let mut real = RealFftPlanner::<f32>::new();
        let mut planner = FftPlanner::<f32>::new();
        let (r2c, c2r) = (real.plan_fft_forward(cols), real.plan_fft_inverse(cols));
        let col = [
            planner.plan_fft_forward(rows),
            planner.plan_fft_inverse(rows),
        ];
        let work_len = r2c
            .get_scratch_len()
            .max(c2r.get_scratch_len())
            .max(col[0].get_inplace_scratch_len())
            .max(col[1].get_inplace_scratch_len());
        let half = cols / 2 + 1;
        let two_pi = 2.0 * std::f64::consts::PI;
        let grad2 = (0..half * rows)
            .map(|idx| {
                let (j, i) = (idx / rows, idx % rows);
                (4.0 - 2.0 * (two_pi * i as f64 / rows as f64).cos()
                    - 2.0 * (two_pi * j as f64 / cols as f64).cos()) as f32
            })
            .collect();
        Ok(Grid {
            rows,
            cols,
            half,
            r2c,
            c2r,
            col,
            work_len,
            grad2,
        })
    }

    /// A shared grid of this size, planned on first use.
    pub fn shared(rows: usize, cols: usize) -> Result<Arc<Grid>> {
        static CACHE: OnceLock<Mutex<GridCache>> = OnceLock::new();
        let cache = CACHE.get_or_init(Default::default);
        if let Some(g) = cache
            .lock()
            .ok()
            .and_then(|c| c.get(&(rows, cols)).cloned())
        {
            return Ok(g);
        }
        let g = Arc::new(Grid::new(rows, cols)?);
        if let Ok(mut c) = cache.lock() {
            c.insert((rows, cols), g.clone());
        }
        Ok(g)
    }

    /// Pixels of the grid.
    pub fn len(&self) -> usize {
        self.rows * self.cols
    }

    /// Length of a spectrum.
    pub fn spec_len(&self) -> usize {
        self.half * self.rows
    }

    /// Forward transform of a real `rows x cols` array into the spectrum `out`.
    pub fn forward(&self, data: &[f32], out: &mut Vec<Complex32>, s: &mut Scratch) {
        let (rows, cols, half) = (self.rows, self.cols, self.half);
        let zero = Complex32::new(0.0, 0.0);
        out.clear();
        out.resize(half * rows, zero);
        s.c.resize(half * rows + self.work_len, zero);
        s.r.resize(cols, 0.0);
        let (tmp, work) = s.c.split_at_mut(half * rows);
        for (row, line) in data.chunks_exact(cols).zip(tmp.chunks_exact_mut(half)) {
            s.r.copy_from_slice(row);
            self.r2c
                .process_with_scratch(&mut s.r, line, work)
                .expect("internal: real FFT lengths");
        }
        transpose(tmp, out, rows, half);
        self.col[0].process_with_scratch(out, work);
    }

    /// Inverse transform of the spectrum `spec` (overwritten) into the real `out`, scaled by `1/N`.
    pub fn inverse_real(&self, spec: &mut [Complex32], out: &mut [f32], s: &mut Scratch) {
        let (rows, cols, half) = (self.rows, self.cols, self.half);
        s.c.resize(half * rows + self.work_len, Complex32::new(0.0, 0.0));
        let (tmp, work) = s.c.split_at_mut(half * rows);
        self.col[1].process_with_scratch(spec, work);
        transpose(spec, tmp, half, rows);
        let scale = 1.0 / self.len() as f32;
        for (line, row) in tmp.chunks_exact_mut(half).zip(out.chunks_exact_mut(cols)) {
            // The spectrum of a real array has real DC and Nyquist terms; drop round-off.
            line[0].im = 0.0;
            if cols % 2 == 0 {
                line[half - 1].im = 0.0;
            }
            self.c2r
                .process_with_scratch(line, row, work)
                .expect("internal: real FFT lengths");
            row.iter_mut().for_each(|v| *v *= scale);
        }
    }

    /// Transfer function of `k` (origin moved to index (0, 0), wrapped periodically).
    pub fn otf(&self, k: &Kernel, s: &mut Scratch) -> Vec<Complex32> {
        let mut pad = vec![0f32; self.len()];
        for i in 0..k.size {
            let r = (i as isize - k.origin.0 as isize).rem_euclid(self.rows as isize) as usize;
            for j in 0..k.size {
                let c = (j as isize - k.origin.1 as isize).rem_euclid(self.cols as isize) as usize;
                pad[r * self.cols + c] += k.data[i * k.size + j];
            }
        }
        let mut out = Vec::with_capacity(self.spec_len());
        self.forward(&pad, &mut out, s);
        out
    }

    /// Periodic convolution of `data` with the kernel of transfer function `otf`
    /// (`conj = true`: correlation, the adjoint).
    pub fn convolve(
        &self,
        data: &[f32],
        otf: &[Complex32],
        conj: bool,
        out: &mut [f32],
        buf: &mut Vec<Complex32>,
        s: &mut Scratch,
    ) {
        self.forward(data, buf, s);
        buf.iter_mut()
            .zip(otf)
            .for_each(|(b, k)| *b *= if conj { k.conj() } else { *k });
        self.inverse_real(buf, out, s);
    }

    /// MATLAB `edgetaper`: `J = a B + (1 - a) (B (*) k)` with `a(y, x) = (1 - b_y(y)) (1 - b_x(x))`,
    /// `b` the peak-normalised periodic autocorrelation of the kernel's projection on each
    /// axis, so the window becomes smooth across its periodic borders.
    pub fn edgetaper(
        &self,
        data: &mut [f32],
        k: &Kernel,
        otf: &[Complex32],
        buf: &mut Vec<Complex32>,
        s: &mut Scratch,
    ) {
        if k.size == 1 {
            return;
        }
        let mut py = vec![0f64; k.size];
        let mut px = vec![0f64; k.size];
        for (i, row) in k.data.chunks(k.size).enumerate() {
            for (j, &v) in row.iter().enumerate() {
                py[i] += v as f64;
                px[j] += v as f64;
            }
        }
        let ay = taper_axis(&py, self.rows);
        let ax = taper_axis(&px, self.cols);
        let mut blurred = vec![0f32; self.len()];
        self.convolve(data, otf, false, &mut blurred, buf, s);
        for ((row, brow), &a_y) in data
            .chunks_mut(self.cols)
            .zip(blurred.chunks(self.cols))
            .zip(&ay)
        {
            for ((d, &b), &a_x) in row.iter_mut().zip(brow).zip(&ax) {
                let a = a_y * a_x;
                *d = a * *d + (1.0 - a) * b;
            }
        }
    }
}

/// `1 - b` along one axis of length `n` (see [`Grid::edgetaper`]): `b` is the periodic
/// autocorrelation of the projection on `n - 1` samples, repeated at the end, over its peak.
fn taper_axis(proj: &[f64], n: usize) -> Vec<f32> {
    if n < 2 {
        return vec![1.0; n];
    }
    let m = n - 1;
    let mut p = vec![0f64; m];
    for (i, &v) in proj.iter().enumerate() {
        p[i % m] += v;
    }
    let nz: Vec<usize> = (0..m).filter(|&i| p[i] != 0.0).collect();
    let mut z: Vec<f64> = (0..m)
        .map(|lag| nz.iter().map(|&i| p[i] * p[(i + lag) % m]).sum())
        .collect();
    z.push(z[0]);
    let peak = z.iter().cloned().fold(0.0, f64::max).max(1e-300);
    z.iter().map(|&v| (1.0 - v / peak) as f32).collect()
}

/// Index into `0..n` of a periodically mirrored signal (`... 1 0 | 0 1 ... n-1 | n-1 ...`).
#[inline]
pub(crate) fn mirror(i: isize, n: usize) -> usize {
    let p = 2 * n as isize;
    let r = i.rem_euclid(p);
    if r < n as isize {
        r as usize
    } else {
        (p - 1 - r) as usize
    }
}

/// The `rows x cols` window of a `h x w` plane whose top-left is `(y0, x0)` (may be outside),
/// mirrored at the plane's borders.
pub(crate) fn window(
    plane: &[f32],
    h: usize,
    w: usize,
    y0: isize,
    x0: isize,
    rows: usize,
    cols: usize,
) -> Vec<f32> {
    let xs: Vec<usize> = (0..cols).map(|j| mirror(x0 + j as isize, w)).collect();
    let mut out = Vec::with_capacity(rows * cols);
    for i in 0..rows {
        let row = &plane[mirror(y0 + i as isize, h) * w..][..w];
        out.extend(xs.iter().map(|&x| row[x]));
    }
    out
}

/// `dst[j * rows + i] = src[i * cols + j]` for a `rows x cols` `src`.
fn transpose<T: Copy>(src: &[T], dst: &mut [T], rows: usize, cols: usize) {
    for (i, row) in src.chunks_exact(cols).take(rows).enumerate() {
        for (j, &v) in row.iter().enumerate() {
            dst[j * rows + i] = v;
        }
    }
}
