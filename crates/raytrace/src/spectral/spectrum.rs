//! Sampled spectra on a regular wavelength grid, the CIE 1931 2-degree observer, CIE
//! daylight (D-series) and Planck illuminants.

use wscg_math::{Error, Result};

use super::tables;

/// A regular wavelength grid: `n` samples from `l0_nm` in steps of `step_nm`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpectralGrid {
    /// First wavelength (nm).
    pub l0_nm: f64,
    /// Step (nm).
    pub step_nm: f64,
    /// Number of samples.
    pub n: usize,
}

impl SpectralGrid {
    /// The paper's grid: 380 to 780 nm in 5 nm steps, 81 samples.
    pub const VISIBLE: SpectralGrid = SpectralGrid {
        l0_nm: 380.0,
        step_nm: 5.0,
        n: 81,
    };

    /// Wavelength of sample `i` (nm).
    pub fn wavelength(&self, i: usize) -> f64 {
        self.l0_nm + self.step_nm * i as f64
    }

    /// The wavelengths of the grid (nm).
    pub fn wavelengths(&self) -> impl Iterator<Item = f64> + '_ {
        (0..self.n).map(|i| self.wavelength(i))
    }
}

impl Default for SpectralGrid {
    fn default() -> Self {
        Self::VISIBLE
    }
}

/// Values sampled on a [`SpectralGrid`] (radiance, reflectance, relative power, ...).
#[derive(Clone, Debug, PartialEq)]
pub struct Spectrum {
    /// The grid.
    pub grid: SpectralGrid,
    /// One value per wavelength of the grid.
    pub v: Vec<f64>,
}

impl Spectrum {
    /// A spectrum from its samples.
    ///
    /// Errors: a length other than `grid.n`, a non-finite value, an empty grid or a
    /// non-positive step.
    pub fn new(grid: SpectralGrid, v: Vec<f64>) -> Result<Self> {
        if grid.n == 0 {
            return Err(Error::Empty("spectral grid"));
        }
        if !(grid.step_nm.is_finite() && grid.step_nm > 0.0 && grid.l0_nm.is_finite()) {
            return Err(Error::invalid(
                "grid",
                format!(
                    "start {} nm and step {} nm must be finite with a positive step",
                    grid.l0_nm, grid.step_nm
                ),
            ));
        }
        if v.len() != grid.n {
            return Err(Error::ShapeMismatch(format!(
                "{} values for a grid of {} wavelengths",
                v.len(),
                grid.n
            )));
        }
        if let Some(index) = v.iter().position(|x| !x.is_finite()) {
            return Err(Error::NonFinite {
                name: "spectrum",
                index,
            });
        }
        Ok(Self { grid, v })
    }

    /// The same value at every wavelength of `grid`.
    pub fn constant(grid: SpectralGrid, value: f64) -> Self {
        Self {
            grid,
            v: vec![value; grid.n],
        }
    }

    /// `self * factor`.
    pub fn scaled(&self, factor: f64) -> Self {
        Self {
            grid: self.grid,
            v: self.v.iter().map(|x| x * factor).collect(),
        }
    }

    /// The product of two spectra wavelength by wavelength.
    ///
    /// Errors: the spectra are sampled on different grids.
    pub fn mul(&self, other: &Spectrum) -> Result<Spectrum> {
        self.same_grid(other)?;
        Ok(Self {
            grid: self.grid,
            v: self.v.iter().zip(&other.v).map(|(a, b)| a * b).collect(),
        })
    }

    /// Errors unless `other` is sampled on the same grid.
    pub fn same_grid(&self, other: &Spectrum) -> Result<()> {
        if self.grid != other.grid {
            return Err(Error::ShapeMismatch(format!(
                "spectra on different grids: {:?} and {:?}",
                self.grid, other.grid
            )));
        }
        Ok(())
    }

    /// Linear interpolation at `lambda_nm` (clamped to the grid's ends).
    pub fn at(&self, lambda_nm: f64) -> f64 {
        let u = ((lambda_nm - self.grid.l0_nm) / self.grid.step_nm)
            .clamp(0.0, (self.grid.n - 1) as f64);
        let i = (u.floor() as usize).min(self.grid.n.saturating_sub(2));
        if self.grid.n == 1 {
            return self.v[0];
        }
        let f = u - i as f64;
        self.v[i] * (1.0 - f) + self.v[i + 1] * f
    }
}

fn visible(values: &[f64; 81]) -> Spectrum {
    Spectrum {
        grid: SpectralGrid::VISIBLE,
        v: values.to_vec(),
    }
}

/// The CIE 1931 2-degree colour-matching functions x-bar, y-bar, z-bar on the visible grid.
pub fn cie1931_2deg() -> [Spectrum; 3] {
    [
        visible(&tables::CMF_X),
        visible(&tables::CMF_Y),
        visible(&tables::CMF_Z),
    ]
}

/// Tristimulus values `X = sum_l s(l) x-bar(l) dl` (and Y, Z) of a spectrum on the visible
/// grid (rectangle rule with the grid step, CIE 15 "Integration").
///
/// Errors: a spectrum on another grid.
pub fn to_xyz(s: &Spectrum) -> Result<[f64; 3]> {
    if s.grid != SpectralGrid::VISIBLE {
        return Err(Error::ShapeMismatch(format!(
            "tristimulus values need the 380-780 nm, 5 nm grid, got {:?}",
            s.grid
        )));
    }
    let mut xyz = [0.0; 3];
    for (k, cmf) in [&tables::CMF_X, &tables::CMF_Y, &tables::CMF_Z]
        .into_iter()
        .enumerate()
    {
        xyz[k] = s.v.iter().zip(cmf).map(|(a, b)| a * b).sum::<f64>() * s.grid.step_nm;
    }
    Ok(xyz)
}

/// The chromaticity of CIE daylight of correlated colour temperature `cct_k` (CIE 15:2004,
/// 4000 K to 25000 K).
pub fn daylight_xy(cct_k: f64) -> Result<[f64; 2]> {
    if !(4000.0..=25000.0).contains(&cct_k) {
        return Err(Error::invalid(
            "cct_k",
            format!("the CIE daylight locus covers 4000 K to 25000 K, got {cct_k} K"),
        ));
    }
    let t = cct_k;
    let x = if t <= 7000.0 {
        -4.6070e9 / t.powi(3) + 2.9678e6 / t.powi(2) + 0.09911e3 / t + 0.244063
    } else {
        -2.0064e9 / t.powi(3) + 1.9018e6 / t.powi(2) + 0.24748e3 / t + 0.237040
    };
    let y = -3.0 * x * x + 2.870 * x - 0.275;
    Ok([x, y])
}

/// The relative spectral power of CIE daylight of correlated colour temperature `cct_k`
/// (D-series: `S0 + M1 S1 + M2 S2`, with M1, M2 rounded to three decimals as CIE 15 does;
/// 100 near 560 nm). Paper 07's SOLUX 4700K lamp is sold as a daylight simulator: its default
/// spectrum here is `daylight_d(4700.0)`.
///
/// Errors: `cct_k` outside 4000 K to 25000 K.
pub fn daylight_d(cct_k: f64) -> Result<Spectrum> {
    let [x, y] = daylight_xy(cct_k)?;
    let m = 0.0241 + 0.2562 * x - 0.7341 * y;
    let round3 = |v: f64| (v * 1000.0).round() / 1000.0;
    let m1 = round3((-1.3515 - 1.7703 * x + 5.9114 * y) / m);
    let m2 = round3((0.0300 - 31.4424 * x + 30.0717 * y) / m);
    let v = (0..81)
        .map(|i| tables::D_S0[i] + m1 * tables::D_S1[i] + m2 * tables::D_S2[i])
        .collect();
    Ok(Spectrum {
        grid: SpectralGrid::VISIBLE,
        v,
    })
}

/// Planck's spectral radiance of a black body at `t_k` kelvin, in W / (sr m^2 nm), on the
/// visible grid: `2 h c^2 / l^5 / (exp(c2 / (l T)) - 1)` (times 1e-9 m per nm).
///
/// Errors: a temperature that is not finite and positive.
pub fn blackbody(t_k: f64) -> Result<Spectrum> {
    if !(t_k.is_finite() && t_k > 0.0) {
        return Err(Error::invalid(
            "t_k",
            format!("temperature must be finite and positive, got {t_k}"),
        ));
    }
    // First radiation constant for radiance 2 h c^2, and CIE 15's second radiation constant
    // c2 = 1.4388e-2 m K (the colorimetric convention, rather than CODATA's 1.438777e-2).
    const C1L: f64 = 2.0 * 6.626_070_15e-34 * 299_792_458.0 * 299_792_458.0;
    const C2: f64 = 1.4388e-2;
    let grid = SpectralGrid::VISIBLE;
    let v = grid
        .wavelengths()
        .map(|l| {
            let l = l * 1e-9;
            1e-9 * C1L / l.powi(5) / ((C2 / (l * t_k)).exp() - 1.0)
        })
        .collect();
    Ok(Spectrum { grid, v })
}
