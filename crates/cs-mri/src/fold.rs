//! Folding (wrapping) of a windowed spectrum onto a small grid and back, shared by the
//! UDCT (paper 11, section 2.2: the alias-free decimation of each band) and the wrapping
//! FDCT (Candes et al. 2006, section 3.3: the wedge wrapped around the origin).
//!
//! A band is the product of a sparse frequency window with the spectrum, periodised onto a
//! `small` grid and transformed there by one small FFT; its adjoint replicates the small FFT
//! over the full grid and multiplies by the window again.

use std::cell::RefCell;
use std::sync::Mutex;

use num_complex::Complex64;
use wscg_math::fft::{Direction, Plan2};

/// Rows of the full grid one parallel task scatters into.
pub(crate) const BLOCK_ROWS: usize = 8;

thread_local! {
    /// Per-thread FFT scratch and a transposed band buffer.
    static SCRATCH: RefCell<(Vec<Complex64>, Vec<Complex64>)> =
        const { RefCell::new((Vec::new(), Vec::new())) };
}

/// Runs `f` with this thread's FFT scratch buffer.
pub(crate) fn with_scratch<R>(f: impl FnOnce(&mut Vec<Complex64>) -> R) -> R {
    SCRATCH.with(|s| f(&mut s.borrow_mut().0))
}

/// The non-zero entries of a window on the full grid and where each folds to.
#[derive(Clone, Debug, Default)]
pub(crate) struct Support {
    /// Full-grid indices, increasing.
    pub(crate) full: Vec<u32>,
    /// Index of each entry on the decimated grid.
    pub(crate) fold: Vec<u32>,
    /// The same, on the decimated grid stored column by column.
    pub(crate) fold_t: Vec<u32>,
    /// Window values.
    pub(crate) weight: Vec<f64>,
}

impl Support {
    /// `buf[fold_t] += w * spec[full]` (column-major decimated grid).
    pub(crate) fn gather_t(&self, spec: &[Complex64], buf: &mut [Complex64]) {
        for ((&k, &f), &w) in self.full.iter().zip(&self.fold_t).zip(&self.weight) {
            buf[f as usize] += spec[k as usize] * w;
        }
    }

    /// [`Support::scatter`] from a column-major decimated grid.
    pub(crate) fn scatter_t(
        &self,
        small: &[Complex64],
        scale: f64,
        lo: u32,
        out: &mut [Complex64],
    ) {
        let a = self.full.partition_point(|&k| k < lo);
        let b = self.full.partition_point(|&k| k < lo + out.len() as u32);
        for e in a..b {
            out[(self.full[e] - lo) as usize] +=
                small[self.fold_t[e] as usize] * (self.weight[e] * scale);
        }
    }

    /// `buf[fold] += w * spec[full]` over the entries.
    pub(crate) fn gather(&self, spec: &[Complex64], buf: &mut [Complex64]) {
        for ((&k, &f), &w) in self.full.iter().zip(&self.fold).zip(&self.weight) {
            buf[f as usize] += spec[k as usize] * w;
        }
    }

    /// `out[full - lo] += scale * w * small[fold]` for the entries with
    /// `lo <= full < lo + out.len()`.
    pub(crate) fn scatter(&self, small: &[Complex64], scale: f64, lo: u32, out: &mut [Complex64]) {
        let a = self.full.partition_point(|&k| k < lo);
        let b = self.full.partition_point(|&k| k < lo + out.len() as u32);
        for e in a..b {
            out[(self.full[e] - lo) as usize] +=
                small[self.fold[e] as usize] * (self.weight[e] * scale);
        }
    }
}

impl Support {
    /// Appends an entry: full-grid index `k`, its index on the small grid row-major and
    /// column-major, and the window value.
    pub(crate) fn push(&mut self, k: u32, fold: u32, fold_t: u32, weight: f64) {
        self.full.push(k);
        self.fold.push(fold);
        self.fold_t.push(fold_t);
        self.weight.push(weight);
    }
}

/// `out = IFFT_small(fold(window, spec))` (unscaled) on the calling thread: the fold goes to
/// a column-major buffer so that the 2-D FFT needs one transpose.
pub(crate) fn fold_ifft(
    plan: &Plan2<f64>,
    support: &Support,
    spec: &[Complex64],
    out: &mut [Complex64],
) {
    let zero = Complex64::new(0.0, 0.0);
    SCRATCH.with(|s| {
        let (scratch, t) = &mut *s.borrow_mut();
        t.clear();
        t.resize(out.len(), zero);
        support.gather_t(spec, t);
        plan.process_from_transposed(t, out, Direction::Inverse, scratch);
    });
}

/// [`fft_t`] of a copy of `src` (kept in this thread's buffer; `src` is left as it is).
pub(crate) fn fft_t_copy(plan: &Plan2<f64>, src: &[Complex64], out: &mut [Complex64]) {
    SCRATCH.with(|s| {
        let (scratch, t) = &mut *s.borrow_mut();
        t.clear();
        t.extend_from_slice(src);
        plan.process_to_transposed(t, out, Direction::Forward, scratch);
    });
}

/// `out = FFT_small(src)` (unscaled) written column-major (`src` is overwritten), ready for
/// [`Support::scatter_t`].
pub(crate) fn fft_t(plan: &Plan2<f64>, src: &mut [Complex64], out: &mut [Complex64]) {
    SCRATCH.with(|s| {
        let (scratch, _) = &mut *s.borrow_mut();
        plan.process_to_transposed(src, out, Direction::Forward, scratch);
    });
}

/// Reused temporary buffers, so that a transform called in a loop does not page-fault a fresh
/// allocation on every call.
#[derive(Debug, Default)]
pub(crate) struct BufferPool(Mutex<Vec<Vec<Complex64>>>);

impl BufferPool {
    /// A buffer of `len` values (contents unspecified).
    pub(crate) fn take(&self, len: usize) -> Vec<Complex64> {
        let mut v = self
            .0
            .lock()
            .map(|mut p| p.pop())
            .ok()
            .flatten()
            .unwrap_or_default();
        v.resize(len, Complex64::new(0.0, 0.0));
        v
    }

    /// Returns a buffer taken with [`BufferPool::take`] (at most 8 are kept).
    pub(crate) fn give(&self, v: Vec<Complex64>) {
        if let Ok(mut p) = self.0.lock() {
            if p.len() < 8 {
                p.push(v);
            }
        }
    }
}
