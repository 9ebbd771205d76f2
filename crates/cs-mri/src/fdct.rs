//! The fast discrete curvelet transform via wrapping (FDCT) of Candes, Demanet, Donoho &
//! Ying, "Fast discrete curvelet transforms" (2006), the curvelet prior paper 11 compares
//! its UDCT against (Tables 2 and 3).
//!
//! The frequency plane of an `N1 x N2` image (unitary FFT, frequencies `f = (f1, f2)`) is
//! tiled as in the 2006 paper, section 3:
//!
//! - **scales** (section 3.1): `Phi_j(f) = phi(f1 / M_j1) phi(f2 / M_j2)` with the 1-D
//!   window `phi = 1` on `|t| <= 1`, `0` on `|t| >= 2` and a `C^inf` (Meyer) transition;
//!   `M_j = (N1, N2) / 3 / 2^(J-2-j)` for `j = 0 .. J-2`. The coarse band is `Phi_0`, scale
//!   `j` is `W_j = sqrt(Phi_j^2 - Phi_(j-1)^2)` and the finest is `sqrt(1 - Phi_(J-2)^2)`,
//!   so `sum_j W_j^2 = 1` (the paper's `W_j = sqrt(Phi_(j+1)^2 - Phi_j^2)`, indexed from 0);
//! - **angles** (section 3.1, "digital corona"): scale `j >= 1` is cut into
//!   `n_j = A 2^ceil((j-1)/2)` wedges (`A` = 16 by default, doubling every other scale, the
//!   parabolic scaling `width ~ length^2`) that are equispaced in slope within each of the
//!   four cones `|f2| >= |f1|` (east, west) and `|f1| > |f2|` (north, south); the angular
//!   windows `V_l` are Meyer windows of the slope with `sum_l V_l^2 = 1`, and the wedges on
//!   the diagonals straddle two cones, as in the paper;
//! - **wrapping** (section 3.3): the product `U_(j,l) f^` of a wedge window with the
//!   spectrum is supported in a sheared parallelogram. It is periodised onto an
//!   `L1 x L2` rectangle (the wedge's radial extent by its widest cross-section, so the
//!   periodisation is one to one on the support) and transformed there by one inverse FFT
//!   of that size. The coefficients are `c_(j,l) = IFFT_L(W(U_(j,l) f^))` (unitary).
//!
//! Because the squared windows sum to one and wrapping is one to one, the transform is a
//! tight frame: `||c|| = ||x||`, and the adjoint (unwrap, window, sum) is the inverse. The
//! windows are normalised by their computed squared sum, so this holds to rounding.
//!
//! The transform is complex: it maps a complex image to complex coefficients (CurveLab's
//! `is_real = 0`). The finest scale holds wavelets (one band, the default) or curvelets
//! (`Finest::Curvelets`). With the paper's angular window (two wedge widths) the redundancy
//! at 256 x 256 is 5.3 with wavelets at the finest scale and 5.6 with curvelets; CurveLab's
//! tighter wedges give 2.8 with wavelets at the finest scale. [`FdctParams::transition`] trades smoothness for fewer
//! coefficients.

use std::ops::Range;

use num_complex::Complex64;
use rayon::prelude::*;
use wscg_math::fft::{Direction, Plan2};
use wscg_math::{Error, Result};

use crate::fold::{self, BufferPool, Support};
use crate::fourier::signed_frequency;

/// What the finest scale holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Finest {
    /// One isotropic band (CurveLab's default `finest = 2`): the finest curvelets would be
    /// cut by the Nyquist square.
    #[default]
    Wavelets,
    /// Curvelet wedges up to the edge of the frequency grid.
    Curvelets,
}

impl Finest {
    /// `"wavelets"` or `"curvelets"`.
    pub fn by_name(name: &str) -> Result<Self> {
        match name {
            "wavelets" => Ok(Finest::Wavelets),
            "curvelets" => Ok(Finest::Curvelets),
            _ => Err(Error::invalid(
                "finest",
                format!("{name:?} is neither \"wavelets\" nor \"curvelets\""),
            )),
        }
    }
}

wscg_math::params! {
    /// FDCT configuration (CurveLab's `fdct_wrapping` arguments).
    #[derive(Clone, Debug, PartialEq)]
    pub struct FdctParams {
        /// Number of scales `J` including the coarse one; `None`: `ceil(log2(min(N1, N2))) - 3`
        /// (5 for 256 x 256), at least 2.
        pub scales: Option<usize>,
        /// Wedges at the coarsest curvelet scale: a multiple of 4, at least 8 (default 16).
        pub angles_coarse: usize,
        /// Wavelets or curvelets at the finest scale.
        pub finest: Finest,
        /// Share of a wedge's width taken by its angular transitions, in `(0, 1]`. The default
        /// 1 is the paper's `V`, supported on two wedge widths (`sum_l V^2(t - l) = 1` with
        /// `V` on `[-1, 1]`); smaller values give narrower wedges and fewer coefficients
        /// (redundancy at 256 x 256 with wavelets at the finest scale: 5.3 at 1, 4.2 at 0.5,
        /// 3.5 at 0.25).
        pub transition: f64,
    }
}

impl Default for FdctParams {
    fn default() -> Self {
        FdctParams {
            scales: None,
            angles_coarse: 16,
            finest: Finest::Wavelets,
            transition: 1.0,
        }
    }
}

/// The FDCT takes 2 to 16 scales.
fn check_scale_count(j: usize) -> Result<()> {
    if !(2..=16).contains(&j) {
        return Err(Error::invalid(
            "scales",
            format!("{j} scales; the FDCT needs 2 to 16"),
        ));
    }
    Ok(())
}

impl FdctParams {
    /// The number of scales for a `rows x cols` image.
    pub fn scales_for(&self, rows: usize, cols: usize) -> usize {
        self.scales.unwrap_or_else(|| {
            let m = rows.min(cols).max(1) as f64;
            (m.log2().ceil() as usize).saturating_sub(3).max(2)
        })
    }

    /// Checks what does not depend on the image size: the wedge count (a multiple of 4
    /// between 8 and 256), the transition share in `(0, 1]` and a given scale count in
    /// `2..=16`.
    pub fn validate(&self) -> Result<()> {
        if self.angles_coarse < 8
            || !self.angles_coarse.is_multiple_of(4)
            || self.angles_coarse > 256
        {
            return Err(Error::invalid(
                "angles_coarse",
                format!(
                    "{} wedges; the count must be a multiple of 4 between 8 and 256",
                    self.angles_coarse
                ),
            ));
        }
        if !(self.transition > 0.0 && self.transition <= 1.0) {
            return Err(Error::invalid(
                "transition",
                format!("{} is outside (0, 1]", self.transition),
            ));
        }
        if let Some(j) = self.scales {
            check_scale_count(j)?;
        }
        Ok(())
    }

    /// [`FdctParams::validate`], then the configuration against a `rows x cols` image;
    /// returns the number of scales.
    pub fn validate_for(&self, rows: usize, cols: usize) -> Result<usize> {
        self.validate()?;
        if rows == 0 || cols == 0 {
            return Err(Error::Empty("FDCT image (an axis has length 0)"));
        }
        let j = self.scales_for(rows, cols);
        check_scale_count(j)?;
        // The coarse window must be at least a few samples wide: M_0 >= 1 on both axes.
        let m0 = rows.min(cols) as f64 / 3.0 / f64::powi(2.0, j as i32 - 2);
        if m0 < 1.0 {
            let most = ((rows.min(cols) as f64 / 3.0).log2().floor() as usize + 2).max(2);
            return Err(Error::invalid(
                "scales",
                format!(
                    "{j} scales are too many for a {rows} x {cols} image (the coarse band \
                     would be narrower than one sample); use at most {most}"
                ),
            ));
        }
        Ok(j)
    }

    /// Wedges at scale `j` (1-based curvelet scales; 1 for the coarse band and a wavelet
    /// finest scale).
    pub fn angles(&self, scales: usize, j: usize) -> usize {
        if j == 0 || (j == scales - 1 && self.finest == Finest::Wavelets) {
            1
        } else {
            self.angles_coarse << (j - 1).div_ceil(2)
        }
    }
}

/// One FDCT band: its scale, wedge and block of coefficients.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FdctBand {
    /// Scale, 0 = coarse.
    pub scale: usize,
    /// Wedge index within the scale, counter-clockwise from the east cone's lower edge
    /// (0 for the coarse and wavelet bands).
    pub angle: usize,
    /// Shape of the wrapped rectangle `[L1, L2]` (rows, columns) the coefficients fill.
    pub shape: [usize; 2],
    /// Where the band's coefficients sit in the coefficient vector (row-major).
    pub range: Range<usize>,
}

/// A band's window support, wrapping and FFT plan.
#[derive(Debug)]
struct Band {
    info: FdctBand,
    support: Support,
    plan: usize,
    /// `1 / sqrt(L1 L2)`: makes the small inverse FFT unitary.
    scale: f64,
}

/// A planned wrapping FDCT for one image size and configuration.
pub struct Fdct {
    rows: usize,
    cols: usize,
    scales: usize,
    config: FdctParams,
    bands: Vec<Band>,
    plans: Vec<Plan2<f64>>,
    full: Plan2<f64>,
    len: usize,
    pool: BufferPool,
}

impl std::fmt::Debug for Fdct {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Fdct")
            .field("rows", &self.rows)
            .field("cols", &self.cols)
            .field("scales", &self.scales)
            .field("config", &self.config)
            .field("bands", &self.bands.len())
            .finish()
    }
}

/// Meyer's polynomial `nu(x) = x^4 (35 - 84 x + 70 x^2 - 20 x^3)`, `nu(x) + nu(1 - x) = 1`.
fn nu(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    x.powi(4) * (35.0 - 84.0 * x + 70.0 * x * x - 20.0 * x * x * x)
}

/// The 1-D low-pass `phi`: 1 on `|t| <= 1`, 0 on `|t| >= 2`, `cos(pi/2 nu(|t| - 1))`
/// between.
fn phi(t: f64) -> f64 {
    let a = t.abs();
    if a <= 1.0 {
        1.0
    } else if a >= 2.0 {
        0.0
    } else {
        (std::f64::consts::FRAC_PI_2 * nu(a - 1.0)).cos()
    }
}

/// Position of the direction `(y, x)` on the boundary of the square, in `[0, 4)`: the
/// slope `y / x` mapped linearly onto `[0, 1]` in the east cone, then the north, west and
/// south cones counter-clockwise. Wedges equispaced in `u` are equispaced in slope inside
/// each cone (section 3.1).
fn square_angle(y: f64, x: f64) -> f64 {
    if x.abs() >= y.abs() {
        if x > 0.0 {
            0.5 * (y / x + 1.0)
        } else if x < 0.0 {
            2.0 + 0.5 * (1.0 + y / x)
        } else {
            0.0
        }
    } else if y > 0.0 {
        1.0 + 0.5 * (1.0 - x / y)
    } else {
        3.0 + 0.5 * (1.0 - x / y)
    }
}

/// The angular window `V_m(u)` of wedge `m` of `n` (width `4 / n` in `u`): a Meyer window
/// with transitions of half-width `transition * width / 2` centred on the wedge edges, so
/// `sum_m V_m^2 = 1` around the square.
fn angular(u: f64, m: usize, n: usize, transition: f64) -> f64 {
    let delta = 4.0 / n as f64;
    let h = 0.5 * transition * delta;
    let mut s = (u - m as f64 * delta).rem_euclid(4.0);
    if s > 2.0 {
        s -= 4.0;
    }
    let edge = |p: f64| (std::f64::consts::FRAC_PI_2 * nu(p)).sin();
    if s <= -h || s >= delta + h {
        0.0
    } else if s < h {
        edge((s + h) / (2.0 * h))
    } else if s <= delta - h {
        1.0
    } else {
        edge((delta + h - s) / (2.0 * h))
    }
}

/// One window entry while the bands are built: full index, signed frequencies, value.
type Entry = (u32, i64, i64, f64);

impl Fdct {
    /// Plans the transform of `rows x cols` images.
    ///
    /// Errors: a zero dimension, an invalid configuration, or more scales than the image
    /// size allows.
    pub fn new(rows: usize, cols: usize, config: &FdctParams) -> Result<Self> {
        let scales = config.validate_for(rows, cols)?;
        let nbands: Vec<usize> = (0..scales).map(|j| config.angles(scales, j)).collect();
        let first: Vec<usize> = nbands
            .iter()
            .scan(0, |acc, &n| {
                let f = *acc;
                *acc += n;
                Some(f)
            })
            .collect();
        let total: usize = nbands.iter().sum();
        let m: Vec<[f64; 2]> = (0..scales - 1)
            .map(|j| {
                let d = f64::powi(2.0, (scales - 2 - j) as i32);
                [rows as f64 / 3.0 / d, cols as f64 / 3.0 / d]
            })
            .collect();
        // Window values on the grid, row by row in parallel, then regrouped per band.
        let per_row: Vec<Vec<(usize, Entry)>> = (0..rows)
            .into_par_iter()
            .map(|i| {
                let f1 = signed_frequency(i, rows);
                let mut out = Vec::new();
                let mut here: Vec<(usize, f64)> = Vec::with_capacity(8);
                let mut lp: Vec<f64> = Vec::with_capacity(m.len());
                for j in 0..cols {
                    let f2 = signed_frequency(j, cols);
                    here.clear();
                    lp.clear();
                    lp.extend(
                        m.iter()
                            .map(|mj| phi(f1 as f64 / mj[0]) * phi(f2 as f64 / mj[1])),
                    );
                    let u = square_angle(f1 as f64 / rows as f64, f2 as f64 / cols as f64);
                    for s in 0..scales {
                        let r2 = if s == 0 {
                            lp[0] * lp[0]
                        } else if s == scales - 1 {
                            1.0 - lp[s - 1] * lp[s - 1]
                        } else {
                            lp[s] * lp[s] - lp[s - 1] * lp[s - 1]
                        };
                        if r2 <= 0.0 {
                            continue;
                        }
                        let n = nbands[s];
                        if n == 1 {
                            here.push((first[s], r2));
                            continue;
                        }
                        let delta = 4.0 / n as f64;
                        let m0 = (u / delta).floor() as usize;
                        for k in [m0 + n - 1, m0, m0 + 1] {
                            let w = angular(u, k % n, n, config.transition);
                            if w > 0.0 {
                                here.push((first[s] + k % n, r2 * w * w));
                            }
                        }
                    }
                    let norm: f64 = here.iter().map(|e| e.1).sum();
                    let k = (i * cols + j) as u32;
                    for &(b, w2) in &here {
                        out.push((b, (k, f1, f2, (w2 / norm).sqrt())));
                    }
                }
                out
            })
            .collect();
        let mut entries: Vec<Vec<Entry>> = vec![Vec::new(); total];
        for row in per_row {
            for (b, e) in row {
                entries[b].push(e);
            }
        }
        let mut plans: Vec<Plan2<f64>> = Vec::new();
        let mut bands = Vec::with_capacity(total);
        let mut offset = 0;
        for s in 0..scales {
            for a in 0..nbands[s] {
                let e = &entries[first[s] + a];
                let shape = if s == scales - 1 && nbands[s] == 1 {
                    [rows, cols]
                } else if nbands[s] == 1 {
                    [extent(e.iter().map(|p| p.1)), extent(e.iter().map(|p| p.2))]
                } else {
                    let delta = 4.0 / nbands[s] as f64;
                    let cone = (((a as f64 + 0.5) * delta).floor() as usize) % 4;
                    if cone.is_multiple_of(2) {
                        [widest(e, |p| p.2, |p| p.1), extent(e.iter().map(|p| p.2))]
                    } else {
                        [extent(e.iter().map(|p| p.1)), widest(e, |p| p.1, |p| p.2)]
                    }
                };
                let [l1, l2] = shape;
                let mut support = Support::default();
                for &(k, f1, f2, w) in e {
                    let (r, c) = (
                        f1.rem_euclid(l1 as i64) as u32,
                        f2.rem_euclid(l2 as i64) as u32,
                    );
                    support.push(k, r * l2 as u32 + c, c * l1 as u32 + r, w);
                }
                let plan = match plans.iter().position(|p| p.shape() == (l1, l2)) {
                    Some(p) => p,
                    None => {
                        plans.push(Plan2::new(l1, l2)?);
                        plans.len() - 1
                    }
                };
                bands.push(Band {
                    info: FdctBand {
                        scale: s,
                        angle: a,
                        shape,
                        range: offset..offset + l1 * l2,
                    },
                    support,
                    plan,
                    scale: 1.0 / ((l1 * l2) as f64).sqrt(),
                });
                offset += l1 * l2;
            }
        }
        Ok(Fdct {
            rows,
            cols,
            scales,
            config: config.clone(),
            bands,
            plans,
            full: Plan2::new(rows, cols)?,
            len: offset,
            pool: BufferPool::default(),
        })
    }

    /// `(rows, cols)`.
    pub fn shape(&self) -> (usize, usize) {
        (self.rows, self.cols)
    }

    /// The configuration.
    pub fn config(&self) -> &FdctParams {
        &self.config
    }

    /// Number of scales, the coarse one included.
    pub fn num_scales(&self) -> usize {
        self.scales
    }

    /// The bands in coefficient order: coarse, then each scale's wedges, finest last.
    pub fn bands(&self) -> Vec<FdctBand> {
        self.bands.iter().map(|b| b.info.clone()).collect()
    }

    /// Number of complex coefficients.
    pub fn coeff_len(&self) -> usize {
        self.len
    }

    /// Coefficients per pixel (complex ones counted once).
    pub fn redundancy(&self) -> f64 {
        self.len as f64 / (self.rows * self.cols) as f64
    }

    /// Direction (radians in `(-pi, pi]`, `atan2(f1, f2)` with `f1` the row frequency) of the
    /// centre of band `b`'s wedge; `None` for the coarse and wavelet bands and for an invalid
    /// index.
    pub fn direction(&self, b: usize) -> Option<f64> {
        let band = self.bands.get(b)?;
        let n = self.config.angles(self.scales, band.info.scale);
        if n == 1 {
            return None;
        }
        // Invert `square_angle`: the wedge centre on the boundary of the square.
        let u = (band.info.angle as f64 + 0.5) * 4.0 / n as f64;
        let (cone, t) = (u.floor(), 2.0 * u.fract() - 1.0);
        let (y, x) = match cone as usize {
            0 => (t, 1.0),
            1 => (1.0, -t),
            2 => (-t, -1.0),
            _ => (-1.0, t),
        };
        Some((y * self.rows as f64).atan2(x * self.cols as f64))
    }

    /// The window of band `b` as a dense `rows x cols` array in FFT order (DC at index 0).
    pub fn window(&self, b: usize) -> Option<Vec<f64>> {
        let band = self.bands.get(b)?;
        let mut w = vec![0.0; self.rows * self.cols];
        for (&k, &v) in band.support.full.iter().zip(&band.support.weight) {
            w[k as usize] = v;
        }
        Some(w)
    }

    fn check_len(&self, name: &'static str, len: usize, want: usize) -> Result<()> {
        if len != want {
            return Err(Error::ShapeMismatch(format!(
                "`{name}` has {len} values; the FDCT of a {} x {} image needs {want}",
                self.rows, self.cols
            )));
        }
        Ok(())
    }

    /// Forward transform of a complex image (row-major).
    ///
    /// Errors: a length mismatch or a non-finite value.
    pub fn forward(&self, x: &[Complex64]) -> Result<Vec<Complex64>> {
        self.check_len("x", x.len(), self.rows * self.cols)?;
        if let Some(i) = x
            .iter()
            .position(|v| !(v.re.is_finite() && v.im.is_finite()))
        {
            return Err(Error::NonFinite {
                name: "x",
                index: i,
            });
        }
        let mut spec = self.pool.take(x.len());
        spec.copy_from_slice(x);
        self.full.process_par(&mut spec, Direction::Forward);
        let s = 1.0 / ((self.rows * self.cols) as f64).sqrt();
        spec.par_iter_mut().for_each(|v| *v *= s);
        let mut out = vec![Complex64::new(0.0, 0.0); self.len];
        self.forward_spectrum(&spec, &mut out);
        self.pool.give(spec);
        Ok(out)
    }

    /// Forward transform of a real image.
    pub fn forward_real(&self, x: &[f64]) -> Result<Vec<Complex64>> {
        let z: Vec<Complex64> = x.iter().map(|&v| Complex64::new(v, 0.0)).collect();
        self.forward(&z)
    }

    /// Inverse (and adjoint) transform to a complex image.
    ///
    /// Errors: a coefficient vector of the wrong length or with a non-finite value.
    pub fn backward(&self, c: &[Complex64]) -> Result<Vec<Complex64>> {
        self.check_len("coefficients", c.len(), self.len)?;
        if let Some(i) = c
            .iter()
            .position(|v| !(v.re.is_finite() && v.im.is_finite()))
        {
            return Err(Error::NonFinite {
                name: "coefficients",
                index: i,
            });
        }
        let mut spec = vec![Complex64::new(0.0, 0.0); self.rows * self.cols];
        self.backward_spectrum(c, &mut spec);
        self.full.process_par(&mut spec, Direction::Inverse);
        let s = 1.0 / ((self.rows * self.cols) as f64).sqrt();
        spec.par_iter_mut().for_each(|v| *v *= s);
        Ok(spec)
    }

    /// A coefficient buffer cut into the bands' blocks.
    fn split<'a>(&self, mut rest: &'a mut [Complex64]) -> Vec<&'a mut [Complex64]> {
        let mut chunks = Vec::with_capacity(self.bands.len());
        for b in &self.bands {
            let (head, tail) = rest.split_at_mut(b.info.range.len());
            chunks.push(head);
            rest = tail;
        }
        chunks
    }

    /// Coefficients from the unitary spectrum `xhat = F x`: per band the windowed spectrum
    /// wrapped onto its rectangle and inverse transformed (unitary). `out` has
    /// [`Fdct::coeff_len`] values.
    pub fn forward_spectrum(&self, xhat: &[Complex64], out: &mut [Complex64]) {
        self.bands
            .par_iter()
            .zip(self.split(out).into_par_iter())
            .for_each(|(band, buf)| {
                fold::fold_ifft(&self.plans[band.plan], &band.support, xhat, buf);
                buf.iter_mut().for_each(|v| *v *= band.scale);
            });
    }

    /// The unitary spectrum `F Psi^H c` of the synthesis: per band the unitary FFT of the
    /// coefficients, unwrapped onto the window's support and windowed again, summed.
    /// `out` (`rows * cols` values) is overwritten.
    pub fn backward_spectrum(&self, c: &[Complex64], out: &mut [Complex64]) {
        let zero = Complex64::new(0.0, 0.0);
        let mut small = self.pool.take(self.len);
        self.bands
            .par_iter()
            .zip(self.split(&mut small).into_par_iter())
            .for_each(|(band, buf)| {
                fold::fft_t_copy(&self.plans[band.plan], &c[band.info.range.clone()], buf);
            });
        let cols = self.cols;
        let sm = &small;
        out.par_chunks_mut(fold::BLOCK_ROWS * cols)
            .enumerate()
            .for_each(|(blk, o)| {
                o.iter_mut().for_each(|v| *v = zero);
                let lo = (blk * fold::BLOCK_ROWS * cols) as u32;
                for band in &self.bands {
                    band.support
                        .scatter_t(&sm[band.info.range.clone()], band.scale, lo, o);
                }
            });
        self.pool.give(small);
    }
}

/// `max - min + 1` of a non-empty set of integers (1 for an empty one).
fn extent(v: impl Iterator<Item = i64>) -> usize {
    let (lo, hi) = v.fold((i64::MAX, i64::MIN), |(a, b), x| (a.min(x), b.max(x)));
    if lo > hi {
        1
    } else {
        (hi - lo + 1) as usize
    }
}

/// The widest cross-section of a wedge: over the lines of constant `along`, the largest
/// extent of `across`.
fn widest(e: &[Entry], along: impl Fn(&Entry) -> i64, across: impl Fn(&Entry) -> i64) -> usize {
    let mut lines: std::collections::HashMap<i64, (i64, i64)> = std::collections::HashMap::new();
    for p in e {
        let x = across(p);
        let r = lines.entry(along(p)).or_insert((x, x));
        r.0 = r.0.min(x);
        r.1 = r.1.max(x);
    }
    lines
        .values()
        .map(|&(a, b)| (b - a + 1) as usize)
        .max()
        .unwrap_or(1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use wscg_math::rng;

    fn random(n: usize, seed: u64) -> Vec<Complex64> {
        rng::complex_normal_vec(seed, n, 1.0).unwrap()
    }

    fn energy(v: &[Complex64]) -> f64 {
        crate::udct::compensated_sum(v.iter().map(|z| z.norm_sqr()))
    }

    #[test]
    fn windows_partition_unity_and_wrap_one_to_one() {
        for (r, c, fin) in [
            (64, 64, Finest::Wavelets),
            (48, 80, Finest::Curvelets),
            (37, 50, Finest::Wavelets),
        ] {
            let f = Fdct::new(
                r,
                c,
                &FdctParams {
                    finest: fin,
                    ..Default::default()
                },
            )
            .unwrap();
            let mut sum = vec![0.0; r * c];
            for b in &f.bands {
                let mut seen = vec![false; b.info.range.len()];
                for (&k, (&fo, &w)) in b
                    .support
                    .full
                    .iter()
                    .zip(b.support.fold.iter().zip(&b.support.weight))
                {
                    assert!(!seen[fo as usize], "band {:?}: wrap collides", b.info);
                    seen[fo as usize] = true;
                    sum[k as usize] += w * w;
                }
            }
            assert!(sum.iter().all(|s| (s - 1.0).abs() < 1e-14), "{r}x{c}");
        }
    }

    #[test]
    fn small_transform_is_a_tight_frame() {
        let (r, c) = (40, 56);
        for fin in [Finest::Wavelets, Finest::Curvelets] {
            let f = Fdct::new(
                r,
                c,
                &FdctParams {
                    finest: fin,
                    ..Default::default()
                },
            )
            .unwrap();
            let x = random(r * c, 3);
            let co = f.forward(&x).unwrap();
            let (ex, ec) = (energy(&x), energy(&co));
            assert!((ex - ec).abs() < 1e-12 * ex, "{ex} vs {ec}");
            let y = f.backward(&co).unwrap();
            assert!(x.iter().zip(&y).all(|(a, b)| (a - b).norm() < 1e-12));
        }
    }
}
