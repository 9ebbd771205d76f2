//! Post-classification: a 1-D RGBA transfer function whose opacity refers
//! to one unit of length, its extinction `tau(s) = -ln(1 - a(s))`, and the opacity-corrected
//! lookup tables the renderers sample at a given step.

use wscg_math::{Error, Result};

/// Largest opacity kept finite in the extinction (`a` is clamped to `1 - 1e-6`).
const A_MAX: f32 = 1.0 - 1e-6;

/// Entries of an opacity-corrected lookup table.
const LUT_SIZE: usize = 4096;

/// A 1-D transfer function: `n >= 2` evenly spaced entries over `s in [0, 1]`, each an RGB
/// colour and an opacity for a reference length of one world unit. Between entries the colour
/// and the **extinction** `tau = -ln(1 - a)` are interpolated linearly, so an extinction
/// linear in `s` is reproduced exactly.
#[derive(Clone, Debug, PartialEq)]
pub struct TransferFunction {
    rgb: Vec<[f32; 3]>,
    tau: Vec<f32>,
    rgba: Vec<[f32; 4]>,
}

impl TransferFunction {
    /// A transfer function from `n >= 2` RGBA entries (colour and opacity in `[0, 1]`).
    /// Errors: fewer than 2 entries, a value outside `[0, 1]` or not finite.
    pub fn from_lut(lut: &[[f32; 4]]) -> Result<Self> {
        if lut.len() < 2 {
            return Err(Error::invalid(
                "tf",
                format!("needs at least 2 entries, got {}", lut.len()),
            ));
        }
        for (i, e) in lut.iter().enumerate() {
            if !e.iter().all(|v| (0.0..=1.0).contains(v)) {
                return Err(Error::invalid(
                    "tf",
                    format!("entry {i} = {e:?}: colours and opacity must be in [0, 1]"),
                ));
            }
        }
        Ok(Self {
            rgb: lut.iter().map(|e| [e[0], e[1], e[2]]).collect(),
            tau: lut.iter().map(|e| -(1.0 - e[3].min(A_MAX)).ln()).collect(),
            rgba: lut.to_vec(),
        })
    }

    /// Reads a transfer function of `n` entries from a JSON file `[[s, r, g, b, a], ...]` of
    /// control points (see [`TransferFunction::from_points`]).
    ///
    /// Errors: [`Error::Io`] when unreadable; [`Error::Format`] naming the path for text that
    /// is not such a list; the errors of [`TransferFunction::from_points`].
    pub fn read_json(path: &std::path::Path, n: usize) -> Result<Self> {
        Self::from_json_bytes(&wscg_math::error::read_file(path)?, path, n)
    }

    /// [`TransferFunction::read_json`] of a file held in memory; `origin` names the file in
    /// errors.
    pub fn from_json_bytes(bytes: &[u8], origin: &std::path::Path, n: usize) -> Result<Self> {
        let pts: Vec<[f32; 5]> = serde_json::from_slice(bytes)
            .map_err(|e| Error::format(origin, format!("expected [[s, r, g, b, a], ...]: {e}")))?;
        let pts: Vec<(f32, [f32; 4])> = pts
            .iter()
            .map(|p| (p[0], [p[1], p[2], p[3], p[4]]))
            .collect();
        Self::from_points(&pts, n)
    }

    /// A transfer function of `n` entries interpolating the control points `(s, rgba)`
    /// piecewise linearly (constant beyond the first and last point). Errors: no point,
    /// positions not increasing or outside `[0, 1]`, values outside `[0, 1]`, `n < 2`.
    pub fn from_points(points: &[(f32, [f32; 4])], n: usize) -> Result<Self> {
        if points.is_empty() {
            return Err(Error::Empty("tf points"));
        }
        if n < 2 {
            return Err(Error::invalid(
                "n",
                format!("needs at least 2 entries, got {n}"),
            ));
        }
        for w in points.windows(2) {
            if w[1].0 < w[0].0 {
                return Err(Error::invalid("tf points", "positions must not decrease"));
            }
        }
        if !points.iter().all(|p| (0.0..=1.0).contains(&p.0)) {
            return Err(Error::invalid("tf points", "positions must be in [0, 1]"));
        }
        let lut: Vec<[f32; 4]> = (0..n)
            .map(|i| {
                let s = i as f32 / (n - 1) as f32;
                let k = points.partition_point(|p| p.0 <= s);
                if k == 0 {
                    points[0].1
                } else if k == points.len() {
                    points[k - 1].1
                } else {
                    let (s0, a) = points[k - 1];
                    let (s1, b) = points[k];
                    let t = if s1 > s0 { (s - s0) / (s1 - s0) } else { 1.0 };
                    std::array::from_fn(|c| a[c] + (b[c] - a[c]) * t)
                }
            })
            .collect();
        Self::from_lut(&lut)
    }

    /// A transfer function with a given extinction per entry (`tau >= 0`, world units^-1)
    /// and colour; opacity `a = 1 - exp(-tau)`. Errors: as [`TransferFunction::from_lut`],
    /// negative or non-finite extinction.
    pub fn from_extinction(rgb: &[[f32; 3]], tau: &[f32]) -> Result<Self> {
        if rgb.len() != tau.len() {
            return Err(Error::ShapeMismatch(format!(
                "{} colours for {} extinctions",
                rgb.len(),
                tau.len()
            )));
        }
        if !tau.iter().all(|t| t.is_finite() && *t >= 0.0) {
            return Err(Error::invalid("tau", "extinctions must be finite and >= 0"));
        }
        let lut: Vec<[f32; 4]> = rgb
            .iter()
            .zip(tau)
            .map(|(c, t)| [c[0], c[1], c[2], 1.0 - (-t).exp()])
            .collect();
        let mut tf = Self::from_lut(&lut)?;
        tf.tau = tau.to_vec();
        Ok(tf)
    }

    /// Number of entries.
    pub fn len(&self) -> usize {
        self.tau.len()
    }

    /// Always false (at least 2 entries); present for API symmetry.
    pub fn is_empty(&self) -> bool {
        self.tau.is_empty()
    }

    /// The RGBA entries as given.
    pub fn entries(&self) -> &[[f32; 4]] {
        &self.rgba
    }

    /// Colour and extinction at `s in [0, 1]` (clamped), linearly interpolated.
    #[inline]
    pub fn eval(&self, s: f32) -> ([f32; 3], f32) {
        let n = self.tau.len();
        let x = s.clamp(0.0, 1.0) * (n - 1) as f32;
        let i = (x as usize).min(n - 2);
        let t = x - i as f32;
        let (c0, c1) = (self.rgb[i], self.rgb[i + 1]);
        (
            std::array::from_fn(|c| c0[c] + (c1[c] - c0[c]) * t),
            self.tau[i] + (self.tau[i + 1] - self.tau[i]) * t,
        )
    }

    /// True if the extinction is zero for every value in `[lo, hi]` (clamped to `[0, 1]`).
    pub fn transparent_on(&self, lo: f32, hi: f32) -> bool {
        let n = self.tau.len();
        let k = (n - 1) as f32;
        let i0 = (lo.clamp(0.0, 1.0) * k).floor() as usize;
        let i1 = ((hi.clamp(0.0, 1.0) * k).ceil() as usize).min(n - 1);
        i0 > i1 || self.tau[i0..=i1].iter().all(|&t| t == 0.0)
    }

    /// True if the value 0 (the outside of the volume) is fully transparent.
    pub fn transparent_at_zero(&self) -> bool {
        self.tau[0] == 0.0
    }

    /// The opacity-corrected lookup table for samples `step` world units apart.
    pub fn sampled(&self, step: f32) -> SampleLut {
        SampleLut::new(self, step)
    }
}

/// Opacity-corrected classification for one sampling distance `delta`:
/// `alpha = 1 - exp(-tau(s) delta)` and associated colour `alpha c(s)`, tabulated at 4096
/// points and linearly interpolated.
#[derive(Clone, Debug)]
pub struct SampleLut {
    table: Vec<[f32; 4]>,
}

impl SampleLut {
    fn new(tf: &TransferFunction, step: f32) -> Self {
        let table: Vec<[f32; 4]> = (0..=LUT_SIZE)
            .map(|i| {
                let (c, tau) = tf.eval(i as f32 / LUT_SIZE as f32);
                let a = -(-(tau as f64) * step as f64).exp_m1() as f32;
                [c[0] * a, c[1] * a, c[2] * a, a]
            })
            .collect();
        Self { table }
    }

    /// Associated colour and opacity `[a r, a g, a b, a]` of the sample value `s`.
    #[inline]
    pub fn get(&self, s: f32) -> [f32; 4] {
        let x = s.clamp(0.0, 1.0) * LUT_SIZE as f32;
        let i = (x as usize).min(LUT_SIZE - 1);
        let t = x - i as f32;
        let (a, b) = (self.table[i], self.table[i + 1]);
        [
            a[0] + (b[0] - a[0]) * t,
            a[1] + (b[1] - a[1]) * t,
            a[2] + (b[2] - a[2]) * t,
            a[3] + (b[3] - a[3]) * t,
        ]
    }
}
