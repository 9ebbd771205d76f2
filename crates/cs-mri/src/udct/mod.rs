//! The 2-D uniform discrete curvelet transform (UDCT) of Nguyen & Chauris (2010), the
//! sparsifying frame of paper 11 (section 2.2, Fig. 1).
//!
//! For a real `N1 x N2` image `x` with FFT `X` (numpy's unnormalised convention), the
//! coefficients are
//!
//! - low-pass: `c_L = Re( downsample_{D_L}( ifft(X W_L) ) )`, real;
//! - band `(j, d, l)`: `c = downsample_D( ifft(X W_{j,d,l}) )`, complex (one-sided window);
//!
//! and the inverse is `x = Re( sum ifft( fft(upsample_D c) W ) )`, which is also the adjoint:
//! the windows make a tight frame, so `||c||^2 = ||x||^2` and `backward(forward(x)) = x`
//! exactly. Counting a complex coefficient as two reals the transform has `4 N1 N2`
//! coefficients for every valid configuration (the paper's "redundancy 4").
//!
//! The downsampled inverse FFT is computed the fast way: the windowed spectrum is folded
//! (periodised) onto the decimated grid and transformed by one small FFT of size `N / D`
//! per band; the inverse replicates the small FFT over the full grid. Only the non-zero
//! window entries are stored and visited, and bands run in parallel.

mod window;

use crate::fold::{self, BufferPool, Support};

use num_complex::Complex64;
use rayon::prelude::*;
use wscg_math::fft::{Direction, Plan2, RealPlan2};
use wscg_math::{Error, Result};

wscg_math::params! {
    /// Transform configuration (paper 11, section 2.2 and 3.1).
    #[derive(Clone, Debug, PartialEq)]
    pub struct UdctParams {
        /// Per scale (coarse to fine) the wedge counts `[n_rows, n_cols]`: the number of angular
        /// windows spanning the axis. Each must be a multiple of 3 and at least 3. The paper uses
        /// one scale with 12 directional bands (`[[6, 6]]`) for brain images and three such
        /// scales for the water phantom.
        pub wedges: Vec<[usize; 2]>,
        /// Angular overlap of neighbouring wedges (paper and `ucurv`: 0.1).
        pub alpha: f64,
        /// Radial window corners `r1..r4`: default `pi (1/3, 2/3, 2/3, 4/3)`.
        pub radial: [f64; 4],
        /// Exact tight frame (default): window tails that would alias on the decimated grid are
        /// dropped before normalisation, so Parseval holds to rounding. `false` keeps every
        /// entry, which reproduces the reference implementation `ucurv` 0.1.1 bit for bit in
        /// its windows but is tight only to about 1e-10.
        pub tight: bool,
    }
}

impl Default for UdctParams {
    fn default() -> Self {
        use std::f64::consts::PI;
        UdctParams {
            wedges: vec![[6, 6]],
            alpha: 0.1,
            radial: [
                PI * (1.0 / 3.0),
                PI * (2.0 / 3.0),
                PI * (2.0 / 3.0),
                PI * (4.0 / 3.0),
            ],
            tight: true,
        }
    }
}

impl UdctParams {
    /// `scales` scales of `[n, n]` wedges each.
    pub fn uniform(scales: usize, n: usize) -> Self {
        UdctParams {
            wedges: vec![[n, n]; scales],
            ..Default::default()
        }
    }

    /// Checks the wedge counts, overlap and radial corners.
    pub fn validate(&self) -> Result<()> {
        if self.wedges.is_empty() {
            return Err(Error::invalid(
                "wedges",
                "needs at least one scale (J = 0 is not a curvelet transform)",
            ));
        }
        if self.wedges.len() > 8 {
            return Err(Error::invalid(
                "wedges",
                format!("{} scales is more than 8", self.wedges.len()),
            ));
        }
        for (s, w) in self.wedges.iter().enumerate() {
            for &n in w {
                if n < 3 || n % 3 != 0 {
                    return Err(Error::invalid(
                        "wedges",
                        format!(
                            "scale {s} has {n} wedges; each count must be a multiple of 3 and at least 3"
                        ),
                    ));
                }
            }
        }
        if !(self.alpha > 0.0 && self.alpha < 0.5) {
            return Err(Error::invalid(
                "alpha",
                format!("{} is outside (0, 0.5)", self.alpha),
            ));
        }
        let r = self.radial;
        if !(r.iter().all(|v| v.is_finite()) && 0.0 < r[0] && r[0] < r[1] && r[2] < r[3]) {
            return Err(Error::invalid(
                "radial",
                format!("{r:?} must be finite with 0 < r1 < r2 and r3 < r4"),
            ));
        }
        Ok(())
    }
}

/// Which band a block of coefficients belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct BandId {
    /// Scale, 0 = coarsest.
    pub scale: usize,
    /// Pyramid: the axis along which the band's frequencies are dominant (0 = rows).
    pub pyramid: usize,
    /// Wedge index inside the pyramid.
    pub wedge: usize,
}

/// One band (or the low-pass): its sparse window and folding map.
#[derive(Clone, Debug)]
struct Band {
    id: Option<BandId>,
    decimation: [usize; 2],
    small: [usize; 2],
    /// Offset of the band's coefficients in the concatenated band buffer.
    offset: usize,
    /// The window.
    support: Support,
    /// The mirrored window `W(-k)` (for complex images; empty for the low-pass).
    mirror: Support,
    /// Index into `Udct::plans`.
    plan: usize,
}

impl Band {
    fn len(&self) -> usize {
        self.small[0] * self.small[1]
    }
}

/// Neumaier's compensated sum: accurate to about one rounding whatever the length.
pub fn compensated_sum(values: impl IntoIterator<Item = f64>) -> f64 {
    let (mut sum, mut c) = (0.0f64, 0.0f64);
    for v in values {
        let t = sum + v;
        c += if sum.abs() >= v.abs() {
            (sum - t) + v
        } else {
            (v - t) + sum
        };
        sum = t;
    }
    sum + c
}

/// UDCT coefficients: the real low-pass block and every band, concatenated.
#[derive(Clone, Debug, PartialEq)]
pub struct UdctCoeffs {
    /// Low-pass coefficients, row-major on the decimated grid.
    pub lowpass: Vec<f64>,
    /// Complex band coefficients, band after band in [`Udct::bands`] order, each row-major.
    pub bands: Vec<Complex64>,
}

impl UdctCoeffs {
    /// Sum of squares of every real and imaginary part (compensated summation, so that
    /// Parseval checks on large images see the transform's error, not the sum's).
    pub fn energy(&self) -> f64 {
        compensated_sum(
            self.lowpass
                .iter()
                .map(|v| v * v)
                .chain(self.bands.iter().map(|v| v.norm_sqr())),
        )
    }

    /// Real inner product `sum Re(conj(a) b)` over all coefficients.
    pub fn dot(&self, other: &UdctCoeffs) -> f64 {
        self.lowpass
            .iter()
            .zip(&other.lowpass)
            .map(|(a, b)| a * b)
            .sum::<f64>()
            + self
                .bands
                .iter()
                .zip(&other.bands)
                .map(|(a, b)| (a.conj() * b).re)
                .sum::<f64>()
    }
}

/// A planned UDCT for one image size and configuration.
pub struct Udct {
    rows: usize,
    cols: usize,
    config: UdctParams,
    lowpass: Band,
    bands: Vec<Band>,
    plans: Vec<Plan2<f64>>,
    /// Real-input transforms of the image and of the (real) low-pass block.
    real_full: RealPlan2<f64>,
    real_low: RealPlan2<f64>,
    band_len: usize,
    /// Reused temporary buffers (avoids page-faulting fresh allocations on every call).
    pool: BufferPool,
}

/// Plans above this many elements are transformed with the lines spread over rayon.
const PAR_FFT: usize = 1 << 15;

impl std::fmt::Debug for Udct {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Udct")
            .field("rows", &self.rows)
            .field("cols", &self.cols)
            .field("config", &self.config)
            .field("bands", &self.bands.len())
            .finish()
    }
}

impl Udct {
    /// Plans the transform of `rows x cols` images.
    ///
    /// Errors: an invalid configuration, or a size not divisible by every decimation factor
    /// (the message names the divisor each axis needs).
    pub fn new(rows: usize, cols: usize, config: &UdctParams) -> Result<Self> {
        config.validate()?;
        let need = Self::required_divisors(config);
        for (axis, (&n, &d)) in [rows, cols].iter().zip(&need).enumerate() {
            if n == 0 || n % d != 0 {
                let name = if axis == 0 { "rows" } else { "cols" };
                return Err(Error::ShapeMismatch(format!(
                    "a UDCT with wedges {:?} needs {name} divisible by {d} (its decimation \
                     factors and the 4-periodic frequency grid); the image is {rows} x {cols}",
                    config.wedges
                )));
            }
        }
        // One window of rows x cols per band and the low pass, indexed with u32.
        let bands = 1 + config.wedges.iter().map(|w| w[0] + w[1]).sum::<usize>();
        let pixels = wscg_math::alloc::elements("shape", &[rows, cols])?;
        wscg_math::alloc::ensure_shape::<f64>("shape", &[pixels, bands])?;
        if pixels > u32::MAX as usize {
            return Err(Error::invalid(
                "shape",
                format!("{rows} x {cols} has more than 2^32 - 1 pixels"),
            ));
        }
        let (low_w, band_w) = window::windows(rows, cols, config);
        let mut plans: Vec<Plan2<f64>> = Vec::new();
        let mut plan_for = |small: [usize; 2]| -> Result<usize> {
            if let Some(i) = plans.iter().position(|p| p.shape() == (small[0], small[1])) {
                return Ok(i);
            }
            plans.push(Plan2::new(small[0], small[1])?);
            Ok(plans.len() - 1)
        };
        let make =
            |id: Option<BandId>, dec: [usize; 2], w: &[f64], offset: usize, plan: usize| -> Band {
                let small = [rows / dec[0], cols / dec[1]];
                let fold_of =
                    |k: usize| ((k / cols % small[0]) * small[1] + k % cols % small[1]) as u32;
                let fold_t =
                    |k: usize| ((k % cols % small[1]) * small[0] + k / cols % small[0]) as u32;
                let mut support = Support::default();
                let mut mirrored: Vec<(u32, f64)> = Vec::new();
                for (k, &v) in w.iter().enumerate() {
                    if v != 0.0 {
                        support.push(k as u32, fold_of(k), fold_t(k), v);
                        let (i, j) = (k / cols, k % cols);
                        mirrored.push(((((rows - i) % rows) * cols + (cols - j) % cols) as u32, v));
                    }
                }
                let mut mirror = Support::default();
                if id.is_some() {
                    mirrored.sort_by_key(|m| m.0);
                    for (k, v) in mirrored {
                        mirror.push(k, fold_of(k as usize), fold_t(k as usize), v);
                    }
                }
                Band {
                    id,
                    decimation: dec,
                    small,
                    offset,
                    support,
                    mirror,
                    plan,
                }
            };
        let dl = window::lowpass_decimation(config);
        let lp = plan_for([rows / dl[0], cols / dl[1]])?;
        let lowpass = make(None, dl, &low_w, 0, lp);
        let mut bands = Vec::with_capacity(band_w.len());
        let mut offset = 0;
        let mut it = band_w.iter();
        for (s, w) in config.wedges.iter().enumerate() {
            for pyr in 0..2 {
                let dec = window::band_decimation(config, s, pyr);
                let p = plan_for([rows / dec[0], cols / dec[1]])?;
                for wedge in 0..w[1 - pyr] {
                    let win = it.next().expect("one window per band");
                    let id = BandId {
                        scale: s,
                        pyramid: pyr,
                        wedge,
                    };
                    let b = make(Some(id), dec, win, offset, p);
                    offset += b.len();
                    bands.push(b);
                }
            }
        }
        Ok(Udct {
            rows,
            cols,
            config: config.clone(),
            lowpass,
            bands,
            plans,
            real_full: RealPlan2::new(rows, cols)?,
            real_low: RealPlan2::new(rows / dl[0], cols / dl[1])?,
            band_len: offset,
            pool: BufferPool::default(),
        })
    }

    /// The divisor each axis length must be a multiple of: every decimation factor along it
    /// and 4 (the frequency grid of the windows is rolled by three quarters).
    pub fn required_divisors(config: &UdctParams) -> [usize; 2] {
        let lcm = |a: usize, b: usize| {
            let (mut x, mut y) = (a, b);
            while y != 0 {
                (x, y) = (y, x % y);
            }
            a / x * b
        };
        let mut need = [4usize, 4];
        if config.validate().is_err() {
            return need;
        }
        let dl = window::lowpass_decimation(config);
        for (a, n) in need.iter_mut().enumerate() {
            *n = lcm(*n, dl[a]);
            for s in 0..config.wedges.len() {
                for pyr in 0..2 {
                    *n = lcm(*n, window::band_decimation(config, s, pyr)[a]);
                }
            }
        }
        need
    }

    /// `(rows, cols)`.
    pub fn shape(&self) -> (usize, usize) {
        (self.rows, self.cols)
    }

    /// The configuration.
    pub fn config(&self) -> &UdctParams {
        &self.config
    }

    /// The band identifiers in coefficient order.
    pub fn bands(&self) -> Vec<BandId> {
        self.bands.iter().filter_map(|b| b.id).collect()
    }

    /// Shape of the low-pass block.
    pub fn lowpass_shape(&self) -> [usize; 2] {
        self.lowpass.small
    }

    /// Shape, decimation and coefficient range of band `b` in [`UdctCoeffs::bands`].
    pub fn band_layout(
        &self,
        b: usize,
    ) -> Option<([usize; 2], [usize; 2], std::ops::Range<usize>)> {
        let band = self.bands.get(b)?;
        Some((
            band.small,
            band.decimation,
            band.offset..band.offset + band.len(),
        ))
    }

    /// Number of real coefficients (a complex one counts twice): `4 * rows * cols`.
    pub fn num_real_coeffs(&self) -> usize {
        self.lowpass.len() + 2 * self.band_len
    }

    /// Number of complex band coefficients.
    pub fn band_coeff_len(&self) -> usize {
        self.band_len
    }

    /// Zero coefficients of the right sizes.
    pub fn zeros(&self) -> UdctCoeffs {
        UdctCoeffs {
            lowpass: vec![0.0; self.lowpass.len()],
            bands: vec![Complex64::new(0.0, 0.0); self.band_len],
        }
    }

    /// The window of band `b` (or of the low-pass when `b` is `None`) as a dense
    /// `rows x cols` array in FFT order (DC at index 0), `ucurv`'s `Msubwin` / `FL`.
    pub fn window(&self, b: Option<usize>) -> Option<Vec<f64>> {
        let band = match b {
            None => &self.lowpass,
            Some(i) => self.bands.get(i)?,
        };
        let mut w = vec![0.0; self.rows * self.cols];
        for (&k, &v) in band.support.full.iter().zip(&band.support.weight) {
            w[k as usize] = v;
        }
        Some(w)
    }

    fn check_len(&self, name: &'static str, len: usize) -> Result<()> {
        if len != self.rows * self.cols {
            return Err(Error::ShapeMismatch(format!(
                "`{name}` has {len} values; the transform is planned for {} x {} = {}",
                self.rows,
                self.cols,
                self.rows * self.cols
            )));
        }
        Ok(())
    }

    /// Forward transform of a real image (row-major, `rows * cols` values).
    ///
    /// Errors: a length mismatch or a non-finite value.
    pub fn forward(&self, x: &[f64]) -> Result<UdctCoeffs> {
        let mut out = self.zeros();
        let chunks = self.split_bands(&mut out.bands);
        self.forward_parts(x, &mut out.lowpass, chunks)?;
        Ok(out)
    }

    /// [`Udct::forward`] into caller-provided blocks: the low-pass (`lowpass_shape`) and one
    /// slice per band in [`Udct::bands`] order (lengths from [`Udct::band_layout`]), so that
    /// the coefficients can go straight into separate arrays (the Python binding's numpy
    /// outputs) without a concatenated buffer.
    ///
    /// Errors: a length mismatch of the image or of a block, or a non-finite value.
    pub fn forward_parts(
        &self,
        x: &[f64],
        low: &mut [f64],
        bands: Vec<&mut [Complex64]>,
    ) -> Result<()> {
        self.check_len("x", x.len())?;
        self.check_parts(low.len(), bands.iter().map(|b| b.len()))?;
        if let Some(i) = x.iter().position(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                name: "x",
                index: i,
            });
        }
        // The spectrum is a pooled buffer: a fresh 16 * rows * cols bytes per call cost more
        // in page faults than the transform itself (512^2: 11-14 ms against 4.5 ms).
        let mut spec = self.pool.take(x.len());
        let mut work = self.pool.take(0);
        self.real_full.forward_full(x, &mut spec, &mut work);
        self.pool.give(work);
        self.forward_bands(&spec, 1.0 / (self.rows * self.cols) as f64, low, bands);
        self.pool.give(spec);
        Ok(())
    }

    /// Inverse (and adjoint) transform to a real image.
    ///
    /// Errors: coefficient blocks of the wrong sizes.
    pub fn backward(&self, c: &UdctCoeffs) -> Result<Vec<f64>> {
        self.check_coeffs(c)?;
        self.backward_parts(&c.lowpass, &self.band_slices(&c.bands))
    }

    /// [`Udct::backward`] from separate blocks: the low-pass and one slice per band in
    /// [`Udct::bands`] order.
    ///
    /// Errors: blocks of the wrong number or sizes.
    pub fn backward_parts(&self, low: &[f64], bands: &[&[Complex64]]) -> Result<Vec<f64>> {
        self.check_parts(low.len(), bands.iter().map(|b| b.len()))?;
        let mut spec = self.pool.take(self.rows * self.cols);
        self.backward_bands(low, bands, &mut spec);
        let mut out = vec![0.0; self.rows * self.cols];
        let mut work = self.pool.take(0);
        let n = (self.rows * self.cols) as f64;
        self.real_full
            .inverse_real_part(&spec, &mut out, 1.0 / n, &mut work);
        self.pool.give(work);
        self.pool.give(spec);
        Ok(out)
    }

    /// Checks a low-pass block length and the band block lengths, in band order.
    fn check_parts(&self, low: usize, bands: impl ExactSizeIterator<Item = usize>) -> Result<()> {
        if low != self.lowpass.len() {
            return Err(Error::ShapeMismatch(format!(
                "the low-pass block has {low} values; this transform has {}",
                self.lowpass.len()
            )));
        }
        if bands.len() != self.bands.len() {
            return Err(Error::ShapeMismatch(format!(
                "{} bands given; this transform has {}",
                bands.len(),
                self.bands.len()
            )));
        }
        for (b, (len, band)) in bands.zip(&self.bands).enumerate() {
            if len != band.len() {
                return Err(Error::ShapeMismatch(format!(
                    "band {b} has {len} values; this transform's band {b} has {} ({} x {})",
                    band.len(),
                    band.small[0],
                    band.small[1]
                )));
            }
        }
        Ok(())
    }

    /// Checks the block sizes of `c`.
    pub fn check_coeffs(&self, c: &UdctCoeffs) -> Result<()> {
        if c.lowpass.len() != self.lowpass.len() || c.bands.len() != self.band_len {
            return Err(Error::ShapeMismatch(format!(
                "coefficients hold {} low-pass and {} band values; this transform has {} and {}",
                c.lowpass.len(),
                c.bands.len(),
                self.lowpass.len(),
                self.band_len
            )));
        }
        Ok(())
    }

    /// In-place unscaled FFT of one band's decimated grid.
    fn band_fft(&self, band: &Band, buf: &mut [Complex64], dir: Direction) {
        let plan = &self.plans[band.plan];
        if buf.len() >= PAR_FFT {
            plan.process_par(buf, dir);
        } else {
            fold::with_scratch(|s| plan.process(buf, dir, s));
        }
    }

    /// `out = IFFT_small(fold(window, spec))` for a band that is not transformed in parallel:
    /// the fold goes to a column-major buffer so that the 2-D FFT needs one transpose.
    fn fold_ifft(&self, band: &Band, support: &Support, spec: &[Complex64], out: &mut [Complex64]) {
        fold::fold_ifft(&self.plans[band.plan], support, spec, out);
    }

    /// `out = FFT_small(src)` written column-major (`src` is overwritten), for the scatter.
    fn fft_t(&self, band: &Band, src: &mut [Complex64], out: &mut [Complex64]) {
        fold::fft_t(&self.plans[band.plan], src, out);
    }

    /// Per-band views of a concatenated band buffer.
    fn band_slices<'a>(&self, bands: &'a [Complex64]) -> Vec<&'a [Complex64]> {
        self.bands
            .iter()
            .map(|b| &bands[b.offset..b.offset + b.len()])
            .collect()
    }

    /// Splits a concatenated band buffer into per-band slices.
    fn split_bands<'a>(&self, mut rest: &'a mut [Complex64]) -> Vec<&'a mut [Complex64]> {
        let mut chunks = Vec::with_capacity(self.bands.len());
        for b in &self.bands {
            let (head, tail) = rest.split_at_mut(b.len());
            chunks.push(head);
            rest = tail;
        }
        chunks
    }

    /// Analysis from a spectrum: `c = scale * IFFT_small(fold(W spec))` per band (unscaled
    /// inverse FFT), real part for the low-pass. With `spec` the unnormalised FFT of a real
    /// image and `scale = 1 / (rows * cols)` this is [`Udct::forward`].
    pub fn forward_spectrum(&self, spec: &[Complex64], scale: f64, out: &mut UdctCoeffs) {
        self.forward_into(spec, scale, &mut out.lowpass, &mut out.bands);
    }

    /// [`Udct::forward_spectrum`] into caller-provided low-pass and band buffers.
    pub fn forward_into(
        &self,
        spec: &[Complex64],
        scale: f64,
        low: &mut [f64],
        bands: &mut [Complex64],
    ) {
        self.forward_bands(spec, scale, low, self.split_bands(bands));
    }

    /// [`Udct::forward_into`] with one output slice per band (lengths already checked).
    fn forward_bands(
        &self,
        spec: &[Complex64],
        scale: f64,
        low: &mut [f64],
        chunks: Vec<&mut [Complex64]>,
    ) {
        let zero = Complex64::new(0.0, 0.0);
        rayon::join(
            || {
                // The low-pass is the real part of its band: a complex-to-real transform.
                let mut buf = self.pool.take(self.lowpass.len());
                let mut work = self.pool.take(0);
                buf.iter_mut().for_each(|v| *v = zero);
                self.lowpass.support.gather(spec, &mut buf);
                self.real_low.inverse_real_part(&buf, low, scale, &mut work);
                self.pool.give(work);
                self.pool.give(buf);
            },
            || {
                self.bands
                    .par_iter()
                    .zip(chunks.into_par_iter())
                    .for_each(|(band, buf)| {
                        self.fold_ifft(band, &band.support, spec, buf);
                        buf.iter_mut().for_each(|v| *v *= scale);
                    });
            },
        );
    }

    /// Analysis of the real and imaginary parts of a complex image at once, from its spectrum
    /// `spec`: the coefficients of `Re x` go to `low[0]`, `bands[0]`, those of `Im x` to
    /// `low[1]`, `bands[1]`, each scaled by `scale` as in [`Udct::forward_into`].
    ///
    /// For a real image `r` the band computed with the mirrored window `W(-k)` is the complex
    /// conjugate of the band with `W(k)`; so with `u = band(W, x)` and `v = band(W(-.), x)`,
    /// `band(Re x) = (u + conj v) / 2` and `band(Im x) = (u - conj v) / 2i`, and the symmetric
    /// low-pass gives `Re x` and `Im x` as the real and imaginary parts of one band.
    pub fn forward_pair(
        &self,
        spec: &[Complex64],
        scale: f64,
        low: [&mut [f64]; 2],
        bands: [&mut [Complex64]; 2],
    ) {
        let zero = Complex64::new(0.0, 0.0);
        let [low_r, low_i] = low;
        let [bands_r, bands_i] = bands;
        let chunks_r = self.split_bands(bands_r);
        let chunks_i = self.split_bands(bands_i);
        rayon::join(
            || {
                let mut buf = self.pool.take(self.lowpass.len());
                buf.iter_mut().for_each(|v| *v = zero);
                self.lowpass.support.gather(spec, &mut buf);
                self.band_fft(&self.lowpass, &mut buf, Direction::Inverse);
                for ((r, i), v) in low_r.iter_mut().zip(low_i.iter_mut()).zip(&buf) {
                    *r = v.re * scale;
                    *i = v.im * scale;
                }
                self.pool.give(buf);
            },
            || {
                self.bands
                    .par_iter()
                    .zip(chunks_r.into_par_iter().zip(chunks_i.into_par_iter()))
                    .for_each(|(band, (u, v))| {
                        self.fold_ifft(band, &band.support, spec, u);
                        self.fold_ifft(band, &band.mirror, spec, v);
                        let h = 0.5 * scale;
                        for (a, b) in u.iter_mut().zip(v.iter_mut()) {
                            let (p, q) = (*a, b.conj());
                            let d = p - q;
                            *a = (p + q) * h;
                            *b = Complex64::new(d.im, -d.re) * h;
                        }
                    });
            },
        );
    }

    /// Synthesis of `U^*(a) + i U^*(b)` into its (unnormalised) spectrum, `a` being
    /// `(low[0], bands[0])` and `b` `(low[1], bands[1])`: with `P = FFT(a + i b)` and
    /// `G = FFT(conj a + i conj b)` per band, `spec = sum (W P + W(-.) G) / 2`, plus
    /// `W_L FFT(a_L + i b_L)` for the low-pass. `spec` is overwritten.
    pub fn backward_pair(
        &self,
        low: [&[f64]; 2],
        bands: [&[Complex64]; 2],
        spec: &mut [Complex64],
    ) {
        let zero = Complex64::new(0.0, 0.0);
        let i = Complex64::new(0.0, 1.0);
        let nl = self.lowpass.len();
        let nb = self.band_len;
        let mut small = self.pool.take(nl + 2 * nb);
        {
            let (lo, hi) = small.split_at_mut(nl);
            let (p, g) = hi.split_at_mut(nb);
            rayon::join(
                || {
                    for ((o, &a), &b) in lo.iter_mut().zip(low[0]).zip(low[1]) {
                        *o = Complex64::new(a, b);
                    }
                    self.band_fft(&self.lowpass, lo, Direction::Forward);
                },
                || {
                    let cp = self.split_bands(p);
                    let cg = self.split_bands(g);
                    self.bands
                        .par_iter()
                        .zip(cp.into_par_iter().zip(cg.into_par_iter()))
                        .for_each(|(band, (p, g))| {
                            let r = band.offset..band.offset + band.len();
                            let (a, b) = (&bands[0][r.clone()], &bands[1][r]);
                            let mut tmp: Vec<Complex64> =
                                a.iter().zip(b).map(|(&a, &b)| a + i * b).collect();
                            self.fft_t(band, &mut tmp, p);
                            for ((t, &a), &b) in tmp.iter_mut().zip(a).zip(b) {
                                *t = a.conj() + i * b.conj();
                            }
                            self.fft_t(band, &mut tmp, g);
                        });
                },
            );
        }
        let cols = self.cols;
        let (lo_s, rest) = small.split_at(nl);
        let (p, g) = rest.split_at(nb);
        spec.par_chunks_mut(fold::BLOCK_ROWS * cols)
            .enumerate()
            .for_each(|(blk, out)| {
                out.iter_mut().for_each(|v| *v = zero);
                let lo = (blk * fold::BLOCK_ROWS * cols) as u32;
                self.lowpass.support.scatter(lo_s, 1.0, lo, out);
                for band in &self.bands {
                    let r = band.offset..band.offset + band.len();
                    band.support.scatter_t(&p[r.clone()], 0.5, lo, out);
                    band.mirror.scatter_t(&g[r], 0.5, lo, out);
                }
            });
        self.pool.give(small);
    }

    /// Synthesis into a spectrum: `spec = sum W rep(FFT_small(c))` over the low-pass and every
    /// band (unscaled FFTs). The image [`Udct::backward`] returns is
    /// `Re(IFFT(spec)) / (rows * cols)`. `spec` is overwritten.
    pub fn backward_spectrum(&self, c: &UdctCoeffs, spec: &mut [Complex64]) {
        self.backward_from(&c.lowpass, &c.bands, spec);
    }

    /// [`Udct::backward_spectrum`] from separate low-pass and band buffers.
    pub fn backward_from(&self, low: &[f64], bands: &[Complex64], spec: &mut [Complex64]) {
        self.backward_bands(low, &self.band_slices(bands), spec);
    }

    /// [`Udct::backward_from`] with one slice per band (lengths already checked).
    fn backward_bands(&self, low: &[f64], bands: &[&[Complex64]], spec: &mut [Complex64]) {
        let zero = Complex64::new(0.0, 0.0);
        let mut small = self.pool.take(self.lowpass.len() + self.band_len);
        {
            let (lo, hi) = small.split_at_mut(self.lowpass.len());
            let chunks = self.split_bands(hi);
            rayon::join(
                || {
                    let mut work = self.pool.take(0);
                    self.real_low.forward_full(low, lo, &mut work);
                    self.pool.give(work);
                },
                || {
                    self.bands
                        .par_iter()
                        .zip(chunks.into_par_iter())
                        .zip(bands.par_iter())
                        .for_each(|((band, buf), &src)| {
                            fold::fft_t_copy(&self.plans[band.plan], src, buf);
                        });
                },
            );
        }
        // Scatter in parallel over blocks of rows; each band's entries are sorted by full
        // index, so a block's entries form one contiguous run per band.
        let cols = self.cols;
        let all: Vec<(&Band, usize)> = std::iter::once((&self.lowpass, 0))
            .chain(
                self.bands
                    .iter()
                    .map(|b| (b, self.lowpass.len() + b.offset)),
            )
            .collect();
        let small_ref = &small;
        spec.par_chunks_mut(fold::BLOCK_ROWS * cols)
            .enumerate()
            .for_each(|(blk, out)| {
                out.iter_mut().for_each(|v| *v = zero);
                let lo = (blk * fold::BLOCK_ROWS * cols) as u32;
                for &(band, base) in &all {
                    let src = &small_ref[base..base + band.len()];
                    if band.id.is_some() {
                        band.support.scatter_t(src, 1.0, lo, out);
                    } else {
                        band.support.scatter(src, 1.0, lo, out);
                    }
                }
            });
        self.pool.give(small);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use wscg_math::rng;

    #[test]
    fn meyer_window_shape() {
        let p = [0.0, 1.0, 2.0, 3.0];
        assert_eq!(window::meyer(-0.5, p), 0.0);
        assert_eq!(window::meyer(1.5, p), 1.0);
        assert_eq!(window::meyer(3.5, p), 0.0);
        assert!((window::meyer(0.5, p) - 0.5).abs() < 1e-12);
        assert!((window::meyer(2.5, p) - 0.5).abs() < 1e-12);
    }

    #[test]
    fn small_transform_is_a_tight_frame() {
        let (r, c) = (32, 48);
        let u = Udct::new(r, c, &UdctParams::default()).unwrap();
        assert_eq!(u.num_real_coeffs(), 4 * r * c);
        let x = rng::normal_vec(1, r * c, 0.0, 1.0).unwrap();
        let co = u.forward(&x).unwrap();
        let ex: f64 = x.iter().map(|v| v * v).sum();
        assert!(
            (co.energy() - ex).abs() < 1e-12 * ex,
            "{} vs {ex}",
            co.energy()
        );
        let y = u.backward(&co).unwrap();
        let err: f64 = x
            .iter()
            .zip(&y)
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>()
            .sqrt();
        assert!(err < 1e-12 * ex.sqrt(), "{err}");
    }

    #[test]
    fn block_outputs_and_pooled_buffers_match_the_plain_transform() {
        let (r, c) = (32, 48);
        let cfg = UdctParams::default();
        let u = Udct::new(r, c, &cfg).unwrap();
        let x1 = rng::normal_vec(2, r * c, 0.0, 1.0).unwrap();
        let x2 = rng::normal_vec(3, r * c, 0.0, 1.0).unwrap();
        // Later calls reuse the pooled buffers the calls on x1 leave, holding stale values;
        // a buffer not fully overwritten would break the exact round trip of x2.
        u.backward(&u.forward(&x1).unwrap()).unwrap();
        let fresh = Udct::new(r, c, &cfg).unwrap();
        let expect = fresh.forward(&x2).unwrap();
        assert_eq!(u.forward(&x2).unwrap(), expect);
        let y = u.backward(&expect).unwrap();
        let err = x2
            .iter()
            .zip(&y)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(err < 1e-12, "{err}");
        assert_eq!(
            u.backward(&expect).unwrap(),
            fresh.backward(&expect).unwrap()
        );

        let mut low = vec![0.0; u.lowpass.len()];
        let mut blocks: Vec<Vec<Complex64>> = (0..u.bands().len())
            .map(|b| vec![Complex64::new(0.0, 0.0); u.band_layout(b).unwrap().2.len()])
            .collect();
        let outs: Vec<&mut [Complex64]> = blocks.iter_mut().map(|v| v.as_mut_slice()).collect();
        u.forward_parts(&x2, &mut low, outs).unwrap();
        assert_eq!(low, expect.lowpass);
        assert_eq!(blocks.concat(), expect.bands);
        let views: Vec<&[Complex64]> = blocks.iter().map(|v| v.as_slice()).collect();
        assert_eq!(
            u.backward_parts(&low, &views).unwrap(),
            u.backward(&expect).unwrap()
        );

        let err = u.backward_parts(&low, &views[..5]).unwrap_err().to_string();
        assert!(err.contains("5 bands given"), "{err}");
        let mut short = views.clone();
        short[3] = &views[3][1..];
        let err = u.backward_parts(&low, &short).unwrap_err().to_string();
        assert!(err.contains("band 3 has"), "{err}");
        let err = u.backward_parts(&low[1..], &views).unwrap_err().to_string();
        assert!(err.contains("low-pass block"), "{err}");
        let mut nan = x2.clone();
        nan[7] = f64::NAN;
        let outs: Vec<&mut [Complex64]> = blocks.iter_mut().map(|v| v.as_mut_slice()).collect();
        assert!(u.forward_parts(&nan, &mut low, outs).is_err());
    }
}
