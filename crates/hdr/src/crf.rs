//! Camera response functions: the inverse response `f^-1(Z)` as a table per channel, and its
//! recovery from a static multi-exposure stack by Debevec & Malik (1997), the calibration the
//! paper's pipeline needs for 8-bit views (section 3: "for 8bits LDR images a CRF per camera
//! needs to be estimated").

use faer::Mat;
use wscg_math::{dense, Error, Image, Result};

/// An inverse camera response: `inv(z, c) = f^-1(z)` for codes `0..=z_max` and each channel
/// (a one-channel table applies to every channel of an image).
#[derive(Clone, Debug, PartialEq)]
pub struct Crf {
    /// Row-major `(levels, channels)` table.
    inv: Vec<f32>,
    levels: usize,
    channels: usize,
}

impl Crf {
    /// The gamma response `f^-1(Z) = (Z / z_max)^gamma` of a `bits`-bit camera (`gamma = 2.2`
    /// undoes the usual display encoding).
    pub fn gamma(gamma: f64, bits: u8, channels: usize) -> Result<Self> {
        if !(gamma.is_finite() && gamma > 0.0) {
            return Err(Error::invalid(
                "gamma",
                format!("must be finite and > 0, got {gamma}"),
            ));
        }
        let levels = levels_of(bits)?;
        let zmax = (levels - 1) as f64;
        let mut t = Vec::with_capacity(levels * channels.max(1));
        for z in 0..levels {
            let v = (z as f64 / zmax).powf(gamma) as f32;
            t.extend(std::iter::repeat_n(v, channels.max(1)));
        }
        Self::from_table(&t, levels, channels)
    }

    /// The linear response `f^-1(Z) = Z / z_max` (RAW sensor data with the black level
    /// removed, as the paper's 10-bit Octo-cam views).
    pub fn linear(bits: u8, channels: usize) -> Result<Self> {
        Self::gamma(1.0, bits, channels)
    }

    /// A response from its table, row-major `(levels, channels)`: `levels` is `z_max + 1`
    /// (256 for 8-bit views). Values must be finite, `>= 0` and non-decreasing in `Z`, with
    /// `f^-1(z_max) > 0`.
    pub fn from_table(table: &[f32], levels: usize, channels: usize) -> Result<Self> {
        if channels == 0 {
            return Err(Error::invalid("crf", "needs at least one channel"));
        }
        if !(2..=65536).contains(&levels) {
            return Err(Error::invalid(
                "crf",
                format!("needs 2..=65536 levels (z_max + 1), got {levels}"),
            ));
        }
        if table.len() != levels * channels {
            return Err(Error::invalid(
                "crf",
                format!(
                    "table has {} values, expected levels x channels = {levels} x {channels}",
                    table.len()
                ),
            ));
        }
        for c in 0..channels {
            let col = |z: usize| table[z * channels + c];
            for z in 0..levels {
                let v = col(z);
                if !(v.is_finite() && v >= 0.0) {
                    return Err(Error::invalid(
                        "crf",
                        format!("f^-1({z}) of channel {c} must be finite and >= 0, got {v}"),
                    ));
                }
                if z > 0 && v < col(z - 1) {
                    return Err(Error::invalid(
                        "crf",
                        format!("not monotone: f^-1({z}) < f^-1({}) in channel {c}", z - 1),
                    ));
                }
            }
            if col(levels - 1) <= 0.0 {
                return Err(Error::invalid("crf", "f^-1(z_max) must be > 0"));
            }
        }
        Ok(Self {
            inv: table.to_vec(),
            levels,
            channels,
        })
    }

    /// Number of codes, `z_max + 1`.
    pub fn levels(&self) -> usize {
        self.levels
    }

    /// The largest code `z_max`.
    pub fn z_max(&self) -> u16 {
        (self.levels - 1) as u16
    }

    /// Channels of the table (1: shared by all channels of an image).
    pub fn channels(&self) -> usize {
        self.channels
    }

    /// `f^-1(z)` of channel `c` (channel 0 for a one-channel table).
    #[inline]
    pub fn inv(&self, z: u16, c: usize) -> f32 {
        let c = if self.channels == 1 { 0 } else { c };
        self.inv[z as usize * self.channels + c]
    }

    /// The table, row-major `(levels, channels)`.
    pub fn table(&self) -> &[f32] {
        &self.inv
    }

    /// Checks that the response can convert an image of `channels` channels whose codes are
    /// at most `max_code`.
    pub fn check_image(&self, channels: usize, max_code: u16) -> Result<()> {
        if self.channels != 1 && self.channels != channels {
            return Err(Error::invalid(
                "crf",
                format!(
                    "has {} channels but the image has {channels}",
                    self.channels
                ),
            ));
        }
        if max_code > self.z_max() {
            return Err(Error::invalid(
                "crf",
                format!(
                    "covers codes up to {} but the image holds code {max_code}: the bit depth \
                     is larger than the response table",
                    self.z_max()
                ),
            ));
        }
        Ok(())
    }
}

/// Codes of a `bits`-bit camera: `2^bits`.
pub fn levels_of(bits: u8) -> Result<usize> {
    if !(1..=16).contains(&bits) {
        return Err(Error::invalid(
            "bits",
            format!("must be in 1..=16, got {bits}"),
        ));
    }
    Ok(1usize << bits)
}

/// Largest bit depth [`calibrate_debevec`] solves at (1024 codes: the dense least-squares
/// system stays below a few thousand unknowns); deeper codes are reduced to it.
pub const MAX_CALIBRATION_BITS: u8 = 10;

/// Hat weight of Debevec & Malik, `h(z) = min(z, z_max - z)`.
fn hat(z: usize, zmax: usize) -> f64 {
    z.min(zmax - z) as f64
}

/// The sample pixels of a calibration: `samples` points on a regular grid, as OpenCV's
/// `CalibrateDebevec` with `random = false` places them.
pub fn sample_grid(height: usize, width: usize, samples: usize) -> Result<Vec<(usize, usize)>> {
    if samples == 0 {
        return Err(Error::invalid("samples", "must be >= 1"));
    }
    let xp = ((samples as f64 * width as f64 / height as f64).sqrt() as usize).max(1);
    let yp = samples / xp;
    if xp > width || yp == 0 || yp > height {
        return Err(Error::invalid(
            "samples",
            format!("{samples} samples do not fit a {height} x {width} image"),
        ));
    }
    let (sx, sy) = (width / xp, height / yp);
    let mut pts = Vec::with_capacity(xp * yp);
    for i in 0..xp {
        for j in 0..yp {
            let (x, y) = (sx / 2 + i * sx, sy / 2 + j * sy);
            if x < width && y < height {
                pts.push((y, x));
            }
        }
    }
    Ok(pts)
}

/// Checks exposure times: `n` of them, all finite and `> 0`.
pub fn check_times(times: &[f64], n: usize) -> Result<()> {
    if times.len() != n {
        return Err(Error::invalid(
            "times",
            format!("{} exposure times for {n} images", times.len()),
        ));
    }
    if let Some((i, t)) = times
        .iter()
        .enumerate()
        .find(|(_, t)| !(t.is_finite() && **t > 0.0))
    {
        return Err(Error::invalid(
            "times",
            format!("exposure time {i} must be finite and > 0, got {t}"),
        ));
    }
    Ok(())
}

/// Checks a static calibration stack: at least two exposures of one shape, one valid time
/// each, every code below `2^bits`. Returns the number of codes and the images' shape.
pub(crate) fn check_stack(
    stack: &[Image<u16>],
    times: &[f64],
    bits: u8,
) -> Result<(usize, (usize, usize, usize))> {
    let levels = levels_of(bits)?;
    if stack.len() < 2 {
        return Err(Error::invalid(
            "stack",
            format!("needs at least 2 exposures, got {}", stack.len()),
        ));
    }
    check_times(times, stack.len())?;
    let shape = stack[0].shape();
    for (k, im) in stack.iter().enumerate() {
        if im.shape() != shape {
            return Err(Error::ShapeMismatch(format!(
                "exposure {k} is {:?}, exposure 0 is {shape:?}",
                im.shape(),
            )));
        }
        if let Some(&z) = im.data().iter().find(|&&z| z as usize >= levels) {
            return Err(Error::invalid(
                "stack",
                format!("exposure {k} holds code {z}, above the {bits}-bit maximum"),
            ));
        }
    }
    Ok((levels, shape))
}

/// Recovers the inverse response from a static stack of `bits`-bit exposures with exposure
/// times `times` (Debevec & Malik 1997): per channel, the least-squares solution of
///
/// `min_{g, ln E_i} sum_ij [h(Z_ij) (g(Z_ij) - ln E_i - ln dt_j)]^2
///                 + sum_z [lambda h(z) g''(z)]^2`, `g(z_mid) = 0`,
///
/// over `samples` grid pixels (rows scaled by `lambda` as in Debevec's `gsolve` and OpenCV),
/// solved by SVD; `f^-1 = exp(g)`. Codes the samples never reach are filled by the
/// smoothness term. Errors when the recovered `g` is not monotone over the observed codes
/// ("CRF calibration failed").
///
/// Codes of more than [`MAX_CALIBRATION_BITS`] bits (12- to 16-bit TIFFs) are reduced to
/// that depth before solving (`z >> (bits - 10)`: 64 codes of a 16-bit camera a bin), and the
/// solved `g` is interpolated linearly back to all `2^bits` codes at the bins' centres, so the
/// returned table has `2^bits` levels and applies to the full-depth codes.
pub fn calibrate_debevec(
    stack: &[Image<u16>],
    times: &[f64],
    bits: u8,
    samples: usize,
    lambda: f64,
) -> Result<Crf> {
    let (levels, (h, w, ch)) = check_stack(stack, times, bits)?;
    if bits > MAX_CALIBRATION_BITS {
        let shift = bits - MAX_CALIBRATION_BITS;
        let reduced: Vec<Image<u16>> = stack.iter().map(|im| im.map(|z| z >> shift)).collect();
        let coarse = calibrate_debevec(&reduced, times, MAX_CALIBRATION_BITS, samples, lambda)?;
        return expand_levels(&coarse, levels, shift);
    }
    if !(lambda.is_finite() && lambda > 0.0) {
        return Err(Error::invalid(
            "lambda",
            format!("must be finite and > 0, got {lambda}"),
        ));
    }
    let pts = sample_grid(h, w, samples)?;
    let (n, p, zmax) = (pts.len(), stack.len(), levels - 1);
    let rows = n * p + 1 + (levels - 2);
    let cols = levels + n;
    let mut table = vec![0f32; levels * ch];
    for c in 0..ch {
        let mut a = Mat::<f64>::zeros(rows, cols);
        let mut b = Mat::<f64>::zeros(rows, 1);
        let (mut zlo, mut zhi) = (usize::MAX, 0);
        let mut eq = 0;
        for (i, &(y, x)) in pts.iter().enumerate() {
            for (j, im) in stack.iter().enumerate() {
                let z = im.at(y, x, c) as usize;
                let wz = hat(z, zmax);
                if wz > 0.0 {
                    zlo = zlo.min(z);
                    zhi = zhi.max(z);
                }
                a[(eq, z)] = wz;
                a[(eq, levels + i)] = -wz;
                b[(eq, 0)] = wz * times[j].ln();
                eq += 1;
            }
        }
        a[(eq, levels / 2)] = 1.0;
        eq += 1;
        for z in 1..zmax {
            let wz = lambda * hat(z, zmax);
            a[(eq, z - 1)] = wz;
            a[(eq, z)] = -2.0 * wz;
            a[(eq, z + 1)] = wz;
            eq += 1;
        }
        let x = dense::lstsq(a.as_ref(), b.as_ref(), None)?;
        let g: Vec<f64> = (0..levels).map(|z| x[(z, 0)]).collect();
        let g = monotone_channel(&g, (zlo, zhi), c, "lambda too small")?;
        for (z, v) in g.iter().enumerate() {
            table[z * ch + c] = v.exp() as f32;
        }
    }
    Crf::from_table(&table, levels, ch)
}

/// A table of `coarse.levels()` codes spread over `levels = coarse.levels() << shift` codes:
/// code `z` lies at `(z + 0.5) / 2^shift - 0.5` on the coarse axis (the centre of its bin),
/// and `ln f^-1` is interpolated linearly there (held constant past the end bins' centres).
fn expand_levels(coarse: &Crf, levels: usize, shift: u8) -> Result<Crf> {
    let (n, ch) = (coarse.levels(), coarse.channels());
    let g: Vec<f64> = coarse
        .table()
        .iter()
        .map(|&v| f64::from(v.max(f32::MIN_POSITIVE)).ln())
        .collect();
    let scale = (1usize << shift) as f64;
    let mut table = vec![0f32; levels * ch];
    for z in 0..levels {
        let u = ((z as f64 + 0.5) / scale - 0.5).clamp(0.0, (n - 1) as f64);
        let k = (u.floor() as usize).min(n - 2);
        let a = u - k as f64;
        for c in 0..ch {
            let v = (1.0 - a) * g[k * ch + c] + a * g[(k + 1) * ch + c];
            table[z * ch + c] = v.exp() as f32;
        }
    }
    Crf::from_table(&table, levels, ch)
}

/// One channel's fitted response values `v(z)` (any increasing function of `f^-1`) made
/// into a table: an error ("CRF calibration failed") when no sample was well exposed or when
/// `v` decreases over the observed codes `observed.0..=observed.1`; outside them the table is
/// kept non-decreasing (codes below the lowest observed one capped at its value, a running
/// maximum above). `hint` names the setting to change.
pub(crate) fn monotone_channel(
    v: &[f64],
    (zlo, zhi): (usize, usize),
    c: usize,
    hint: &str,
) -> Result<Vec<f64>> {
    if zlo >= zhi {
        return Err(Error::Numerical(format!(
            "CRF calibration failed: channel {c} has no well-exposed samples"
        )));
    }
    for z in zlo..zhi {
        if v[z + 1] < v[z] {
            return Err(Error::Numerical(format!(
                "CRF calibration failed: the recovered response of channel {c} decreases \
                 between codes {z} and {} (too few exposures or samples, or {hint})",
                z + 1
            )));
        }
    }
    let mut prev = f64::NEG_INFINITY;
    Ok(v.iter()
        .enumerate()
        .map(|(z, &x)| {
            prev = prev.max(if z < zlo { x.min(v[zlo]) } else { x });
            prev
        })
        .collect())
}
