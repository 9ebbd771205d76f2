//! Fast Fourier transforms in 1, 2, 3 and N dimensions (rustfft), with numpy's conventions.
//!
//! Arrays are C-ordered (last axis fastest), as in numpy. The forward transform is
//! `X[k] = sum_n x[n] exp(-2 pi i k n / N)`; the inverse uses `+i`. Scaling follows
//! `numpy.fft`'s `norm` argument ([`Norm`]): `Backward` (default: no scaling forward,
//! `1/N` inverse), `Ortho` (`1/sqrt(N)` both ways, a unitary transform) and `Forward`.
//! Lines along each axis are transformed in parallel with rayon.

use std::sync::Arc;

use num_complex::Complex;
use rayon::prelude::*;
use realfft::{ComplexToReal, RealFftPlanner, RealToComplex};
use rustfft::{Fft, FftNum, FftPlanner};

use crate::error::{Error, Result};

/// Transform direction.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Direction {
    /// `exp(-2 pi i k n / N)`.
    Forward,
    /// `exp(+2 pi i k n / N)`.
    Inverse,
}

/// Normalisation, as numpy's `norm=` argument.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Norm {
    /// No scaling forward, `1/N` on the inverse (numpy's default).
    #[default]
    Backward,
    /// `1/sqrt(N)` both ways: the transform is unitary (Parseval holds exactly).
    Ortho,
    /// `1/N` forward, no scaling on the inverse.
    Forward,
}

impl Norm {
    fn factor(self, dir: Direction, n: usize) -> f64 {
        let n = n as f64;
        match (self, dir) {
            (Norm::Backward, Direction::Forward) | (Norm::Forward, Direction::Inverse) => 1.0,
            (Norm::Backward, Direction::Inverse) | (Norm::Forward, Direction::Forward) => 1.0 / n,
            (Norm::Ortho, _) => 1.0 / n.sqrt(),
        }
    }
}

fn check_shape(len: usize, shape: &[usize]) -> Result<()> {
    if shape.is_empty() {
        return Err(Error::invalid("shape", "needs at least one axis"));
    }
    if shape.contains(&0) {
        return Err(Error::Empty("fft input (an axis has length 0)"));
    }
    let n: usize = shape.iter().product();
    if n != len {
        return Err(Error::ShapeMismatch(format!(
            "fft data has {len} values but shape {shape:?} holds {n}"
        )));
    }
    Ok(())
}

/// In-place N-dimensional FFT of C-ordered `data` with the given `shape`, over every axis.
///
/// Errors: empty axes or a `shape` whose product differs from `data.len()`.
pub fn fftn<T: FftNum>(
    data: &mut [Complex<T>],
    shape: &[usize],
    dir: Direction,
    norm: Norm,
) -> Result<()> {
    let axes: Vec<usize> = (0..shape.len()).collect();
    fft_axes(data, shape, &axes, dir, norm)
}

/// In-place FFT over the listed `axes` only (each at most once).
pub fn fft_axes<T: FftNum>(
    data: &mut [Complex<T>],
    shape: &[usize],
    axes: &[usize],
    dir: Direction,
    norm: Norm,
) -> Result<()> {
    check_shape(data.len(), shape)?;
    let mut seen = vec![false; shape.len()];
    for &a in axes {
        if a >= shape.len() || seen[a] {
            return Err(Error::invalid(
                "axes",
                format!(
                    "{axes:?} is not a list of distinct axes of a {}-D array",
                    shape.len()
                ),
            ));
        }
        seen[a] = true;
    }
    let mut planner = FftPlanner::<T>::new();
    let fdir = match dir {
        Direction::Forward => rustfft::FftDirection::Forward,
        Direction::Inverse => rustfft::FftDirection::Inverse,
    };
    let mut total = 1usize;
    for &a in axes {
        let plan = planner.plan_fft(shape[a], fdir);
        transform_axis(data, shape, a, &plan);
        total *= shape[a];
    }
    let f = norm.factor(dir, total);
    if f != 1.0 {
        let f = T::from_f64(f).expect("a float type represents the scale");
        data.par_iter_mut().for_each(|v| *v = *v * f);
    }
    Ok(())
}

/// Transforms every line of `data` along `axis` with `plan` (no scaling).
fn transform_axis<T: FftNum>(
    data: &mut [Complex<T>],
    shape: &[usize],
    axis: usize,
    plan: &Arc<dyn Fft<T>>,
) {
    let n = shape[axis];
    let stride: usize = shape[axis + 1..].iter().product();
    let scratch_len = plan.get_inplace_scratch_len();
    if stride == 1 {
        data.par_chunks_mut(n).for_each_init(
            || vec![Complex::new(T::zero(), T::zero()); scratch_len],
            |scratch, line| plan.process_with_scratch(line, scratch),
        );
        return;
    }
    // Strided axis: each task gathers a group of COLS adjacent lines (contiguous runs of
    // each row) into a buffer, transforms them there and writes them back.
    const COLS: usize = 16;
    let zero = Complex::new(T::zero(), T::zero());
    for block in data.chunks_mut(n * stride) {
        let base = SharedMut(block.as_mut_ptr());
        (0..stride.div_ceil(COLS)).into_par_iter().for_each_init(
            || (vec![zero; COLS * n], vec![zero; scratch_len]),
            |(buf, scratch), g| {
                let c0 = g * COLS;
                let bw = COLS.min(stride - c0);
                for j in 0..n {
                    // SAFETY: rows have `stride` elements and c0 + bw <= stride, so the run is
                    // inside `block`; tasks touch disjoint column ranges [c0, c0 + bw).
                    let row = unsafe { std::slice::from_raw_parts(base.at(j * stride + c0), bw) };
                    for (b, &v) in row.iter().enumerate() {
                        buf[b * n + j] = v;
                    }
                }
                for line in buf.chunks_mut(n).take(bw) {
                    plan.process_with_scratch(line, scratch);
                }
                for j in 0..n {
                    // SAFETY: as above; no other task reads or writes these elements.
                    let row =
                        unsafe { std::slice::from_raw_parts_mut(base.at(j * stride + c0), bw) };
                    for (b, v) in row.iter_mut().enumerate() {
                        *v = buf[b * n + j];
                    }
                }
            },
        );
    }
}

/// A planned 2-D complex FFT of a fixed `rows x cols` C-ordered array, reused across calls.
///
/// Unlike [`fft2`], which plans on every call, a `Plan2` plans once; [`Plan2::process`]
/// transforms on the calling thread (for many small transforms run in parallel by the caller),
/// [`Plan2::process_par`] spreads the lines over rayon (for one large transform). No scaling
/// is applied: the forward transform is numpy's `fft2`, the inverse `N * ifft2`.
pub struct Plan2<T: FftNum> {
    rows: usize,
    cols: usize,
    row: [Arc<dyn Fft<T>>; 2],
    col: [Arc<dyn Fft<T>>; 2],
    scratch_len: usize,
}

impl<T: FftNum> Plan2<T> {
    /// Plans both directions for `rows x cols` arrays. Errors: a zero dimension.
    pub fn new(rows: usize, cols: usize) -> Result<Self> {
        if rows == 0 || cols == 0 {
            return Err(Error::Empty("fft plan (an axis has length 0)"));
        }
        let mut planner = FftPlanner::<T>::new();
        let row = [
            planner.plan_fft_forward(cols),
            planner.plan_fft_inverse(cols),
        ];
        let col = [
            planner.plan_fft_forward(rows),
            planner.plan_fft_inverse(rows),
        ];
        let scratch_len = row
            .iter()
            .chain(col.iter())
            .map(|p| p.get_inplace_scratch_len())
            .max()
            .unwrap_or(0);
        Ok(Plan2 {
            rows,
            cols,
            row,
            col,
            scratch_len,
        })
    }

    /// `(rows, cols)`.
    pub fn shape(&self) -> (usize, usize) {
        (self.rows, self.cols)
    }

    /// Length of the scratch buffer [`Plan2::process`] needs.
    pub fn scratch_len(&self) -> usize {
        self.scratch_len + self.rows * self.cols
    }

    /// Unscaled in-place transform on the calling thread; `scratch` is resized as needed.
    /// Rows are transformed in one batch; columns by a blocked transpose, one batch and a
    /// transpose back. Panics when `data.len() != rows * cols` (an internal-invariant check).
    pub fn process(&self, data: &mut [Complex<T>], dir: Direction, scratch: &mut Vec<Complex<T>>) {
        assert_eq!(data.len(), self.rows * self.cols, "Plan2 data length");
        let d = usize::from(dir == Direction::Inverse);
        let zero = Complex::new(T::zero(), T::zero());
        if scratch.len() < self.scratch_len() {
            scratch.resize(self.scratch_len(), zero);
        }
        let (t, work) = scratch.split_at_mut(self.rows * self.cols);
        self.row[d].process_with_scratch(data, work);
        if self.rows == 1 {
            return;
        }
        transpose(data, t, self.rows, self.cols);
        self.col[d].process_with_scratch(t, work);
        transpose(t, data, self.cols, self.rows);
    }

    /// Unscaled transform of an array given column by column: `src` holds the `rows x cols`
    /// array transposed (`src[j * rows + i]`, overwritten); the result is written row-major
    /// into `dst`. One transpose instead of two. Panics on wrong lengths (an
    /// internal-invariant check).
    pub fn process_from_transposed(
        &self,
        src: &mut [Complex<T>],
        dst: &mut [Complex<T>],
        dir: Direction,
        scratch: &mut Vec<Complex<T>>,
    ) {
        self.one_transpose(src, dst, dir, scratch, true);
    }

    /// Unscaled transform of the row-major `src` (overwritten), written column by column
    /// into `dst` (`dst[j * rows + i]`). Panics on wrong lengths.
    pub fn process_to_transposed(
        &self,
        src: &mut [Complex<T>],
        dst: &mut [Complex<T>],
        dir: Direction,
        scratch: &mut Vec<Complex<T>>,
    ) {
        self.one_transpose(src, dst, dir, scratch, false);
    }

    /// Lines of `src` along its contiguous axis, a transpose into `dst`, lines of `dst`.
    fn one_transpose(
        &self,
        src: &mut [Complex<T>],
        dst: &mut [Complex<T>],
        dir: Direction,
        scratch: &mut Vec<Complex<T>>,
        src_transposed: bool,
    ) {
        let n = self.rows * self.cols;
        assert!(src.len() == n && dst.len() == n, "Plan2 data length");
        let d = usize::from(dir == Direction::Inverse);
        if scratch.len() < self.scratch_len {
            scratch.resize(self.scratch_len, Complex::new(T::zero(), T::zero()));
        }
        let work = &mut scratch[..self.scratch_len];
        let (first, second, (r, c)) = if src_transposed {
            (&self.col[d], &self.row[d], (self.cols, self.rows))
        } else {
            (&self.row[d], &self.col[d], (self.rows, self.cols))
        };
        first.process_with_scratch(src, work);
        transpose(src, dst, r, c);
        second.process_with_scratch(dst, work);
    }

    /// Unscaled in-place transform with the lines spread over rayon.
    /// Panics when `data.len() != rows * cols` (an internal-invariant check).
    pub fn process_par(&self, data: &mut [Complex<T>], dir: Direction) {
        assert_eq!(data.len(), self.rows * self.cols, "Plan2 data length");
        let d = usize::from(dir == Direction::Inverse);
        let shape = [self.rows, self.cols];
        transform_axis(data, &shape, 1, &self.row[d]);
        transform_axis(data, &shape, 0, &self.col[d]);
    }
}

/// A planned 2-D FFT of real `rows x cols` C-ordered arrays (realfft along the rows, rustfft
/// along the columns of the `cols / 2 + 1` non-negative column frequencies), about half the
/// work of a complex [`Plan2`]. Both methods spread their lines over rayon and apply no
/// scaling of their own: [`RealPlan2::forward_full`] is numpy's `fft2` of a real array and
/// [`RealPlan2::inverse_real_part`] is `Re(N * ifft2)` of any spectrum.
pub struct RealPlan2<T: FftNum> {
    rows: usize,
    cols: usize,
    r2c: Arc<dyn RealToComplex<T>>,
    c2r: Arc<dyn ComplexToReal<T>>,
    col: [Arc<dyn Fft<T>>; 2],
}

impl<T: FftNum> RealPlan2<T> {
    /// Plans `rows x cols` real arrays. Errors: a zero dimension.
    pub fn new(rows: usize, cols: usize) -> Result<Self> {
        if rows == 0 || cols == 0 {
            return Err(Error::Empty("real fft plan (an axis has length 0)"));
        }
        let mut real = RealFftPlanner::<T>::new();
        let mut planner = FftPlanner::<T>::new();
        Ok(RealPlan2 {
            rows,
            cols,
            r2c: real.plan_fft_forward(cols),
            c2r: real.plan_fft_inverse(cols),
            col: [
                planner.plan_fft_forward(rows),
                planner.plan_fft_inverse(rows),
            ],
        })
    }

    /// `(rows, cols)`.
    pub fn shape(&self) -> (usize, usize) {
        (self.rows, self.cols)
    }

    /// Checks that both arrays of a transform hold `rows * cols` values (an internal
    /// invariant: panics otherwise), sizes `work` for the half spectrum and returns
    /// `(rows, cols, cols / 2 + 1)`.
    fn prepare(&self, a: usize, b: usize, work: &mut Vec<Complex<T>>) -> (usize, usize, usize) {
        let (rows, cols) = (self.rows, self.cols);
        assert!(
            a == rows * cols && b == rows * cols,
            "RealPlan2 data length"
        );
        let h = cols / 2 + 1;
        work.resize(rows * h, Complex::new(T::zero(), T::zero()));
        (rows, cols, h)
    }

    /// The full unnormalised spectrum of the real array `x` into `out` (`rows * cols` each):
    /// the half spectrum is transformed, the other half is its Hermitian mirror
    /// `X[i][j] = conj X[-i][-j]`. `work` is resized as needed. Panics on wrong lengths (an
    /// internal-invariant check).
    pub fn forward_full(&self, x: &[T], out: &mut [Complex<T>], work: &mut Vec<Complex<T>>) {
        let (rows, cols, h) = self.prepare(x.len(), out.len(), work);
        let zero = Complex::new(T::zero(), T::zero());
        let r2c = &self.r2c;
        x.par_chunks(cols)
            .zip(work.par_chunks_mut(h))
            .for_each_init(
                || (vec![T::zero(); cols], vec![zero; r2c.get_scratch_len()]),
                |(line, scratch), (row, spec)| {
                    line.copy_from_slice(row);
                    r2c.process_with_scratch(line, spec, scratch)
                        .expect("internal: real FFT lengths");
                },
            );
        transform_axis(work, &[rows, h], 0, &self.col[0]);
        let half = &*work;
        out.par_chunks_mut(cols).enumerate().for_each(|(i, row)| {
            row[..h].copy_from_slice(&half[i * h..(i + 1) * h]);
            let mirror = &half[(rows - i) % rows * h..][..h];
            for (j, v) in row.iter_mut().enumerate().skip(h) {
                *v = mirror[cols - j].conj();
            }
        });
    }

    /// `out = scale * Re(IFFT(spec))` with the unnormalised inverse transform, for any
    /// `spec` (`rows * cols` each): the real part of the inverse is the inverse of the
    /// Hermitian part `(S[k] + conj S[-k]) / 2`, which a complex-to-real transform computes
    /// from its non-negative column frequencies. `work` is resized as needed. Panics on
    /// wrong lengths (an internal-invariant check).
    pub fn inverse_real_part(
        &self,
        spec: &[Complex<T>],
        out: &mut [T],
        scale: T,
        work: &mut Vec<Complex<T>>,
    ) {
        let (rows, cols, h) = self.prepare(spec.len(), out.len(), work);
        let zero = Complex::new(T::zero(), T::zero());
        let one_half = T::from_f64(0.5).expect("a float type represents 1/2");
        work.par_chunks_mut(h).enumerate().for_each(|(i, line)| {
            let row = &spec[i * cols..(i + 1) * cols];
            let mirror = &spec[(rows - i) % rows * cols..][..cols];
            line[0] = (row[0] + mirror[0].conj()) * one_half;
            for (j, v) in line.iter_mut().enumerate().skip(1) {
                *v = (row[j] + mirror[cols - j].conj()) * one_half;
            }
        });
        transform_axis(work, &[rows, h], 0, &self.col[1]);
        let c2r = &self.c2r;
        work.par_chunks_mut(h)
            .zip(out.par_chunks_mut(cols))
            .for_each_init(
                || vec![zero; c2r.get_scratch_len()],
                |scratch, (line, row)| {
                    // The DC and (even widths) Nyquist columns of a Hermitian spectrum are
                    // real after the column transform; drop their round-off.
                    line[0].im = T::zero();
                    if cols % 2 == 0 {
                        line[h - 1].im = T::zero();
                    }
                    c2r.process_with_scratch(line, row, scratch)
                        .expect("internal: real FFT lengths");
                    row.iter_mut().for_each(|v| *v = *v * scale);
                },
            );
    }
}

/// `dst[j * rows + i] = src[i * cols + j]` for a `rows x cols` `src`, in cache-sized blocks.
fn transpose<T: Copy>(src: &[T], dst: &mut [T], rows: usize, cols: usize) {
    const B: usize = 16;
    assert!(src.len() >= rows * cols && dst.len() >= rows * cols);
    for i0 in (0..rows).step_by(B) {
        let i1 = (i0 + B).min(rows);
        for j0 in (0..cols).step_by(B) {
            let j1 = (j0 + B).min(cols);
            for i in i0..i1 {
                let row = &src[i * cols + j0..i * cols + j1];
                for (jj, &v) in row.iter().enumerate() {
                    // SAFETY: (j0 + jj) < cols and i < rows, so the index is < rows * cols,
                    // which the assertion above bounds by dst.len().
                    unsafe { *dst.get_unchecked_mut((j0 + jj) * rows + i) = v };
                }
            }
        }
    }
}

/// A pointer into a buffer whose disjoint parts are written by several rayon tasks.
struct SharedMut<T>(*mut T);

// SAFETY: used only for tasks that access disjoint elements (see `transform_axis`).
unsafe impl<T: Send> Send for SharedMut<T> {}
unsafe impl<T: Send> Sync for SharedMut<T> {}

impl<T> SharedMut<T> {
    /// Pointer to element `i`.
    fn at(&self, i: usize) -> *mut T {
        // SAFETY: callers stay inside the buffer.
        unsafe { self.0.add(i) }
    }
}

/// One-dimensional FFT returning a new vector.
pub fn fft1<T: FftNum>(
    input: &[Complex<T>],
    dir: Direction,
    norm: Norm,
) -> Result<Vec<Complex<T>>> {
    let mut out = input.to_vec();
    fftn(&mut out, &[input.len()], dir, norm)?;
    Ok(out)
}

/// Two-dimensional FFT of a `rows x cols` C-ordered array, in place.
pub fn fft2<T: FftNum>(
    data: &mut [Complex<T>],
    rows: usize,
    cols: usize,
    dir: Direction,
    norm: Norm,
) -> Result<()> {
    fftn(data, &[rows, cols], dir, norm)
}

/// Three-dimensional FFT of an `n0 x n1 x n2` C-ordered array, in place.
pub fn fft3<T: FftNum>(
    data: &mut [Complex<T>],
    dims: [usize; 3],
    dir: Direction,
    norm: Norm,
) -> Result<()> {
    fftn(data, &dims, dir, norm)
}

/// Moves the zero-frequency element to the centre of every axis (numpy's `fftshift`).
pub fn fftshift<T: Copy + Send + Sync>(data: &[T], shape: &[usize]) -> Result<Vec<T>> {
    roll(data, shape, |n| n / 2)
}

/// Inverse of [`fftshift`] (numpy's `ifftshift`); differs from it for odd lengths.
pub fn ifftshift<T: Copy + Send + Sync>(data: &[T], shape: &[usize]) -> Result<Vec<T>> {
    roll(data, shape, |n| n - n / 2)
}

/// Cyclic shift of every axis by `shift(len)`: `out[(i + s) % n] = in[i]`.
fn roll<T: Copy + Send + Sync>(
    data: &[T],
    shape: &[usize],
    shift: impl Fn(usize) -> usize + Sync,
) -> Result<Vec<T>> {
    check_shape(data.len(), shape)?;
    let nd = shape.len();
    let mut strides = vec![1usize; nd];
    for a in (0..nd.saturating_sub(1)).rev() {
        strides[a] = strides[a + 1] * shape[a + 1];
    }
    let shifts: Vec<usize> = shape.iter().map(|&n| shift(n)).collect();
    let out: Vec<T> = (0..data.len())
        .into_par_iter()
        .map(|dst| {
            let mut rem = dst;
            let mut src = 0;
            for a in 0..nd {
                let i = rem / strides[a];
                rem %= strides[a];
                let n = shape[a];
                src += ((i + n - shifts[a]) % n) * strides[a];
            }
            data[src]
        })
        .collect();
    Ok(out)
}

/// Sample frequencies of an FFT of length `n` with sample spacing `d` (numpy's `fftfreq`).
///
/// Errors: [`crate::Error::OutOfMemory`] naming `n` when `n` values do not fit in memory.
pub fn fftfreq(n: usize, d: f64) -> Result<Vec<f64>> {
    let half = n.div_ceil(2);
    let mut out = crate::alloc::try_with_capacity("n", n)?;
    out.extend((0..n).map(|i| {
        let k = if i < half {
            i as f64
        } else {
            i as f64 - n as f64
        };
        k / (n as f64 * d)
    }));
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng;
    use rand::Rng;

    type C = Complex<f64>;

    fn random(n: usize, seed: u64) -> Vec<C> {
        let mut r = rng::seeded(seed);
        (0..n)
            .map(|_| C::new(r.random_range(-1.0..1.0), r.random_range(-1.0..1.0)))
            .collect()
    }

    /// Naive separable DFT over every axis of a C-ordered array.
    fn naive(data: &[C], shape: &[usize], sign: f64) -> Vec<C> {
        let mut cur = data.to_vec();
        for axis in 0..shape.len() {
            let n = shape[axis];
            let stride: usize = shape[axis + 1..].iter().product();
            let mut next = vec![C::new(0.0, 0.0); cur.len()];
            for (idx, out) in next.iter_mut().enumerate() {
                let k = (idx / stride) % n;
                let base = idx - k * stride;
                for j in 0..n {
                    let ang = sign * 2.0 * std::f64::consts::PI * (k * j) as f64 / n as f64;
                    *out += cur[base + j * stride] * C::new(ang.cos(), ang.sin());
                }
            }
            cur = next;
        }
        cur
    }

    fn max_err(a: &[C], b: &[C]) -> f64 {
        a.iter()
            .zip(b)
            .map(|(x, y)| (x - y).norm())
            .fold(0.0, f64::max)
    }

    #[test]
    fn matches_naive_dft_in_1_2_3_dimensions() {
        for shape in [vec![17usize], vec![12, 7], vec![5, 6, 9], vec![3, 4, 5, 2]] {
            let n: usize = shape.iter().product();
            let x = random(n, n as u64);
            let mut y = x.clone();
            fftn(&mut y, &shape, Direction::Forward, Norm::Backward).unwrap();
            assert!(max_err(&y, &naive(&x, &shape, -1.0)) < 1e-9, "{shape:?}");
            let mut z = x.clone();
            fftn(&mut z, &shape, Direction::Inverse, Norm::Backward).unwrap();
            let r: Vec<C> = naive(&x, &shape, 1.0)
                .iter()
                .map(|v| v / n as f64)
                .collect();
            assert!(max_err(&z, &r) < 1e-9, "{shape:?}");
        }
    }

    #[test]
    fn round_trip_and_parseval_with_ortho() {
        let shape = [16, 10, 6];
        let x = random(960, 3);
        let mut y = x.clone();
        fft3(&mut y, shape, Direction::Forward, Norm::Ortho).unwrap();
        let ex: f64 = x.iter().map(|v| v.norm_sqr()).sum();
        let ey: f64 = y.iter().map(|v| v.norm_sqr()).sum();
        assert!((ex - ey).abs() < 1e-9 * ex);
        fft3(&mut y, shape, Direction::Inverse, Norm::Ortho).unwrap();
        assert!(max_err(&x, &y) < 1e-12);
        let mut z = x.clone();
        fft2(&mut z, 96, 10, Direction::Forward, Norm::Forward).unwrap();
        fft2(&mut z, 96, 10, Direction::Inverse, Norm::Forward).unwrap();
        assert!(max_err(&x, &z) < 1e-12);
    }

    #[test]
    fn f32_transform_of_a_cosine_is_two_spikes() {
        let n = 64;
        let x: Vec<Complex<f32>> = (0..n)
            .map(|i| {
                Complex::new(
                    (2.0 * std::f32::consts::PI * 5.0 * i as f32 / n as f32).cos(),
                    0.0,
                )
            })
            .collect();
        let y = fft1(&x, Direction::Forward, Norm::Backward).unwrap();
        for (k, v) in y.iter().enumerate() {
            let expect = if k == 5 || k == n - 5 {
                n as f32 / 2.0
            } else {
                0.0
            };
            assert!(
                (v.re - expect).abs() < 1e-3 && v.im.abs() < 1e-3,
                "k={k} {v}"
            );
        }
    }

    #[test]
    fn partial_axes_transform_only_those() {
        let shape = [4, 6];
        let x = random(24, 9);
        let mut y = x.clone();
        fft_axes(&mut y, &shape, &[1], Direction::Forward, Norm::Backward).unwrap();
        for r in 0..4 {
            let row = naive(&x[r * 6..r * 6 + 6], &[6], -1.0);
            assert!(max_err(&row, &y[r * 6..r * 6 + 6]) < 1e-10);
        }
        assert!(fft_axes(&mut y, &shape, &[1, 1], Direction::Forward, Norm::Backward).is_err());
        assert!(fft_axes(&mut y, &shape, &[2], Direction::Forward, Norm::Backward).is_err());
    }

    #[test]
    fn plan2_matches_fft2_both_ways() {
        for (r, c) in [(8usize, 12usize), (1, 6), (5, 1), (16, 16)] {
            let x = random(r * c, (r * 31 + c) as u64);
            let plan = Plan2::<f64>::new(r, c).unwrap();
            let mut scratch = Vec::new();
            for dir in [Direction::Forward, Direction::Inverse] {
                let mut want = x.clone();
                fft2(&mut want, r, c, dir, Norm::Backward).unwrap();
                if dir == Direction::Inverse {
                    want.iter_mut().for_each(|v| *v *= (r * c) as f64);
                }
                let mut a = x.clone();
                plan.process(&mut a, dir, &mut scratch);
                let mut b = x.clone();
                plan.process_par(&mut b, dir);
                let mut t = vec![C::new(0.0, 0.0); r * c];
                for i in 0..r {
                    for j in 0..c {
                        t[j * r + i] = x[i * c + j];
                    }
                }
                let mut d1 = t.clone();
                plan.process_from_transposed(&mut t, &mut d1, dir, &mut scratch);
                assert!(
                    max_err(&d1, &want) < 1e-9,
                    "{r}x{c} {dir:?} from transposed"
                );
                let mut src = x.clone();
                let mut d2 = x.clone();
                plan.process_to_transposed(&mut src, &mut d2, dir, &mut scratch);
                for i in 0..r {
                    for j in 0..c {
                        assert!((d2[j * r + i] - want[i * c + j]).norm() < 1e-9);
                    }
                }
                assert!(max_err(&a, &want) < 1e-9, "{r}x{c} {dir:?}");
                assert!(max_err(&b, &want) < 1e-9, "{r}x{c} {dir:?}");
            }
        }
        assert!(Plan2::<f64>::new(0, 3).is_err());
    }

    #[test]
    fn shifts_match_numpy() {
        // numpy.fft.fftshift(np.arange(5)) == [3, 4, 0, 1, 2]
        assert_eq!(
            fftshift(&[0, 1, 2, 3, 4], &[5]).unwrap(),
            vec![3, 4, 0, 1, 2]
        );
        assert_eq!(
            ifftshift(&[0, 1, 2, 3, 4], &[5]).unwrap(),
            vec![2, 3, 4, 0, 1]
        );
        assert_eq!(fftshift(&[0, 1, 2, 3], &[4]).unwrap(), vec![2, 3, 0, 1]);
        let a: Vec<usize> = (0..12).collect();
        let s = fftshift(&a, &[3, 4]).unwrap();
        assert_eq!(ifftshift(&s, &[3, 4]).unwrap(), a);
        // Row 0 of the shifted 3x4 grid is old row 2, shifted by 2: [10, 11, 8, 9].
        assert_eq!(&s[0..4], &[10, 11, 8, 9]);
        assert_eq!(fftfreq(5, 0.5).unwrap(), vec![0.0, 0.4, 0.8, -0.8, -0.4]);
    }

    #[test]
    fn bad_shapes_are_rejected() {
        let mut x = random(10, 1);
        assert!(fftn(&mut x, &[3, 3], Direction::Forward, Norm::Backward).is_err());
        assert!(fftn(&mut x, &[], Direction::Forward, Norm::Backward).is_err());
        let mut e: Vec<C> = vec![];
        assert!(fftn(&mut e, &[0], Direction::Forward, Norm::Backward).is_err());
    }

    #[test]
    fn real_plan_matches_the_complex_plan() {
        for (k, &(r, c)) in [(1, 7), (5, 6), (8, 12), (7, 9), (64, 48), (6, 1)]
            .iter()
            .enumerate()
        {
            let n = r * c;
            let x: Vec<f64> = random(n, 40 + k as u64).iter().map(|v| v.re).collect();
            let plan = Plan2::<f64>::new(r, c).unwrap();
            let real = RealPlan2::<f64>::new(r, c).unwrap();
            let mut work = Vec::new();
            let mut want: Vec<C> = x.iter().map(|&v| C::new(v, 0.0)).collect();
            plan.process_par(&mut want, Direction::Forward);
            let mut got = vec![C::new(0.0, 0.0); n];
            real.forward_full(&x, &mut got, &mut work);
            let scale = want.iter().map(|v| v.norm()).fold(1.0, f64::max);
            for (a, b) in got.iter().zip(&want) {
                assert!((a - b).norm() < 1e-12 * scale, "{r}x{c}: {a} vs {b}");
            }
            // Any spectrum, not only a Hermitian one: the real part of its inverse.
            let spec = random(n, 60 + k as u64);
            let mut inv = spec.clone();
            plan.process_par(&mut inv, Direction::Inverse);
            let mut out = vec![0.0; n];
            real.inverse_real_part(&spec, &mut out, 0.5, &mut work);
            for (a, b) in out.iter().zip(&inv) {
                assert!(
                    (a - 0.5 * b.re).abs() < 1e-12 * n as f64,
                    "{r}x{c}: {a} vs {b}"
                );
            }
        }
        assert!(RealPlan2::<f64>::new(0, 3).is_err());
    }
}
