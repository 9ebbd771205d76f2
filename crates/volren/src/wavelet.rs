//! Transfer-function-aware block Haar wavelets (paper 03, section 4). The paper leaves the
//! smoothing, quantisation and coding unspecified; they are fixed here so that package sizes
//! are reproducible:
//!
//! 1. Voxels transparent under the canonical transfer function are set to 0 (the null code).
//! 2. The volume is padded with zeros to multiples of 16 and smoothed inside each 16^3 block by
//!    the separable filter `[1, 2, 1] / 4` with clamped borders (blocks stay independent).
//! 3. Each block takes 4 steps of the non-standard 3-D Haar transform with averaging
//!    normalisation: for a 2 x 2 x 2 group `v_abc` (`a, b, c` the x, y, z offsets)
//!    `A = (1/8) sum v_abc` and `D_uvw = (1/8) sum (-1)^(au + bv + cw) v_abc` for
//!    `(u, v, w) != 0`; the inverse is `v_abc = A + sum (-1)^(au + bv + cw) D_uvw`. After 4
//!    steps a block is its mean and 7 + 56 + 448 + 3584 details.
//! 4. Quantisation: the root to u8 (rounded), the details of every step to `round(D / delta)`
//!    in i8 (`delta = 2` by default).
//! 5. Coding of a block: one header byte, 0 all null, 1 raw (the `(2^w)^3` u8 means of the
//!    resolution sent follow), 2 coefficients (the root, then for the steps 4 down to
//!    `5 - w`, for each parent in Morton order (x the high bit) a byte whose bit `k` marks a
//!    non-zero detail `k + 1` (`k + 1 = 4u + 2v + w`), followed by those details as i8). The
//!    encoder keeps the shorter of 1 and 2.
//!
//! A client decodes `w_l` steps: a volume of `dims / 2^(4 - w_l)` (`w_l = 2`: 4^3 values a
//! block, a 1/64 of the voxels, the paper's low-resolution volume `V_W`).

use rayon::prelude::*;
use wscg_math::{Error, Result, Volume};

use crate::bytes::Reader;
use crate::tf::PiecewiseTransferFunction;

/// Block side.
pub const BLOCK: usize = 16;
const BLOCK3: usize = BLOCK * BLOCK * BLOCK;
/// Haar steps per block.
pub const STEPS: usize = 4;

/// Quantisation step of the details of each transform step (index 0: step 1, the finest).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HaarQuant {
    /// `delta_j` for the steps 1..=4.
    pub delta: [f32; 4],
}

impl Default for HaarQuant {
    fn default() -> Self {
        Self { delta: [2.0; 4] }
    }
}

/// The coefficients of one block after 4 steps: the root mean and, per step `j = 1..=4`, the
/// 7 details of each parent in raster order of the parents' grid (`8 / 2^(j-1)` per side).
#[derive(Clone, Debug, PartialEq)]
pub struct BlockCoefficients {
    /// The block mean.
    pub root: f32,
    /// `details[j - 1][parent][k]`: detail `k + 1 = 4u + 2v + w` of step `j`.
    pub details: Vec<Vec<[f32; 7]>>,
}

#[inline]
fn sign(a: usize, k: usize) -> f32 {
    // (-1)^(au + bv + cw) for the corner a = (a_x a_y a_z) and detail k = (u v w), x high.
    if (a & k).count_ones().is_multiple_of(2) {
        1.0
    } else {
        -1.0
    }
}

/// One forward step on an `s^3` grid of means: the `(s/2)^3` means and details.
fn forward_step(values: &[f32], s: usize) -> (Vec<f32>, Vec<[f32; 7]>) {
    let h = s / 2;
    let mut means = vec![0.0; h * h * h];
    let mut details = vec![[0.0f32; 7]; h * h * h];
    for z in 0..h {
        for y in 0..h {
            for x in 0..h {
                let p = x + h * (y + h * z);
                let mut corner = [0.0f32; 8];
                for (a, c) in corner.iter_mut().enumerate() {
                    let (ax, ay, az) = ((a >> 2) & 1, (a >> 1) & 1, a & 1);
                    *c = values[(2 * x + ax) + s * ((2 * y + ay) + s * (2 * z + az))];
                }
                means[p] = corner.iter().sum::<f32>() / 8.0;
                for k in 1..8 {
                    details[p][k - 1] = (0..8).map(|a| sign(a, k) * corner[a]).sum::<f32>() / 8.0;
                }
            }
        }
    }
    (means, details)
}

/// One inverse step: `(s/2)^3` means and details to an `s^3` grid.
fn inverse_step(means: &[f32], details: &[[f32; 7]], s: usize) -> Vec<f32> {
    let h = s / 2;
    let mut out = vec![0.0; s * s * s];
    for z in 0..h {
        for y in 0..h {
            for x in 0..h {
                let p = x + h * (y + h * z);
                for a in 0..8 {
                    let (ax, ay, az) = ((a >> 2) & 1, (a >> 1) & 1, a & 1);
                    let v = means[p] + (1..8).map(|k| sign(a, k) * details[p][k - 1]).sum::<f32>();
                    out[(2 * x + ax) + s * ((2 * y + ay) + s * (2 * z + az))] = v;
                }
            }
        }
    }
    out
}

/// The 4-step forward transform of a 16^3 block (x fastest).
pub fn forward_block(block: &[f32]) -> BlockCoefficients {
    let mut values = block.to_vec();
    let mut details = Vec::with_capacity(STEPS);
    let mut s = BLOCK;
    for _ in 0..STEPS {
        let (m, d) = forward_step(&values, s);
        details.push(d);
        values = m;
        s /= 2;
    }
    BlockCoefficients {
        root: values[0],
        details,
    }
}

/// Number of coefficients of a block: the root and every detail.
pub const PACKED: usize = BLOCK3;

impl BlockCoefficients {
    /// The coefficients as one vector of 4096: the root, then the details of steps 4, 3, 2,
    /// 1, each step's parents in raster order with their 7 details in order `k + 1 = 4u +
    /// 2v + w`.
    pub fn packed(&self) -> Vec<f32> {
        let mut out = Vec::with_capacity(PACKED);
        out.push(self.root);
        for d in self.details.iter().rev() {
            out.extend(d.iter().flatten());
        }
        out
    }
}

/// The forward transform of many 16^3 blocks (x fastest inside a block), in parallel:
/// [`BlockCoefficients::packed`] of each.
///
/// Errors: a length that is not a multiple of 4096.
pub fn forward_blocks(blocks: &[f32]) -> Result<Vec<f32>> {
    if !blocks.len().is_multiple_of(BLOCK3) {
        return Err(Error::ShapeMismatch(format!(
            "{} values are not whole 16^3 blocks",
            blocks.len()
        )));
    }
    let mut out = vec![0.0f32; blocks.len()];
    out.par_chunks_mut(BLOCK3)
        .zip(blocks.par_chunks(BLOCK3))
        .for_each(|(o, b)| o.copy_from_slice(&forward_block(b).packed()));
    Ok(out)
}

/// The inverse of `steps` (0..=4) transform steps: the block at `2^steps` per side.
pub fn inverse_block(c: &BlockCoefficients, steps: usize) -> Vec<f32> {
    let mut values = vec![c.root];
    let mut s = 2;
    for j in (STEPS + 1 - steps..=STEPS).rev() {
        values = inverse_step(&values, &c.details[j - 1], s);
        s *= 2;
    }
    values
}

/// The parents of steps 1..=4 (index `j - 1`) in Morton order, computed once per encode or
/// decode.
fn morton_orders() -> [Vec<usize>; STEPS] {
    std::array::from_fn(|j| morton_order(BLOCK >> (j + 1)))
}

/// Raster indices of an `n^3` grid in Morton order (x the high bit of each level).
fn morton_order(n: usize) -> Vec<usize> {
    let bits = n.trailing_zeros();
    (0..n * n * n)
        .map(|code| {
            let (mut x, mut y, mut z) = (0, 0, 0);
            for b in 0..bits {
                let s = code >> (3 * b);
                x |= ((s >> 2) & 1) << b;
                y |= ((s >> 1) & 1) << b;
                z |= (s & 1) << b;
            }
            x + n * (y + n * z)
        })
        .collect()
}

/// The pre-processed volume (steps 1 and 2 above): null voxels zeroed, padded to multiples
/// of 16, smoothed per block. Dimensions are the padded ones.
pub fn preprocess(v: &Volume<u8>, canonical: &PiecewiseTransferFunction) -> Result<Volume<f32>> {
    let dims = v.dims();
    if dims.contains(&0) {
        return Err(Error::Empty("volume"));
    }
    let nb = dims.map(|d| d.div_ceil(BLOCK));
    let pd = nb.map(|b| b * BLOCK);
    let visible: Vec<bool> = (0..256)
        .map(|d| canonical.eval(d as f32)[3] > 0.0)
        .collect();
    let mut out = Volume::filled(pd, v.spacing(), 0.0f32)?;
    let blocks: Vec<(usize, Vec<f32>)> = (0..nb[0] * nb[1] * nb[2])
        .into_par_iter()
        .map(|b| {
            let (bx, by, bz) = (b % nb[0], b / nb[0] % nb[1], b / (nb[0] * nb[1]));
            let mut blk = vec![0.0f32; BLOCK3];
            for z in 0..BLOCK {
                for y in 0..BLOCK {
                    for x in 0..BLOCK {
                        let p = [bx * BLOCK + x, by * BLOCK + y, bz * BLOCK + z];
                        if p[0] < dims[0] && p[1] < dims[1] && p[2] < dims[2] {
                            let d = v.at(p[0], p[1], p[2]);
                            if visible[d as usize] {
                                blk[x + BLOCK * (y + BLOCK * z)] = d as f32;
                            }
                        }
                    }
                }
            }
            (b, smooth_block(&blk))
        })
        .collect();
    for (b, blk) in blocks {
        put_block(&mut out, nb, b, BLOCK, &blk);
    }
    Ok(out)
}

/// Writes the `side^3` values of block `b` (raster index in an `nb` grid of blocks) into `out`.
fn put_block(out: &mut Volume<f32>, nb: [usize; 3], b: usize, side: usize, values: &[f32]) {
    let origin = [b % nb[0], b / nb[0] % nb[1], b / (nb[0] * nb[1])].map(|c| c * side);
    for z in 0..side {
        for y in 0..side {
            for x in 0..side {
                out.set(
                    origin[0] + x,
                    origin[1] + y,
                    origin[2] + z,
                    values[x + side * (y + side * z)],
                );
            }
        }
    }
}

/// Separable `[1, 2, 1] / 4` inside a 16^3 block, clamped borders.
fn smooth_block(blk: &[f32]) -> Vec<f32> {
    let mut cur = blk.to_vec();
    for axis in 0..3 {
        let stride = [1, BLOCK, BLOCK * BLOCK][axis];
        let mut next = vec![0.0f32; BLOCK3];
        for (i, o) in next.iter_mut().enumerate() {
            let c = (i / stride) % BLOCK;
            let lo = if c > 0 { i - stride } else { i };
            let hi = if c + 1 < BLOCK { i + stride } else { i };
            *o = 0.25 * cur[lo] + 0.5 * cur[i] + 0.25 * cur[hi];
        }
        cur = next;
    }
    cur
}

/// Copies block `(bx, by, bz)` of a padded volume (x fastest).
fn block_of(v: &Volume<f32>, b: [usize; 3]) -> Vec<f32> {
    let mut blk = vec![0.0f32; BLOCK3];
    for z in 0..BLOCK {
        for y in 0..BLOCK {
            for x in 0..BLOCK {
                blk[x + BLOCK * (y + BLOCK * z)] =
                    v.at(b[0] * BLOCK + x, b[1] * BLOCK + y, b[2] * BLOCK + z);
            }
        }
    }
    blk
}

/// A coded wavelet volume.
#[derive(Clone, Debug, PartialEq)]
pub struct WaveletPackage {
    /// Volume size (x, y, z) before padding.
    pub dims: [usize; 3],
    /// Transform steps sent (1..=4).
    pub steps_sent: u8,
    /// Quantisation.
    pub quant: HaarQuant,
    /// The coded blocks in raster block order.
    pub blocks: Vec<u8>,
}

fn check_steps(name: &'static str, w: u8) -> Result<()> {
    if (1..=STEPS as u8).contains(&w) {
        Ok(())
    } else {
        Err(Error::invalid(name, format!("must be in 1..=4, got {w}")))
    }
}

/// Codes one block's coefficients for `w` steps sent.
fn code_block(
    c: &BlockCoefficients,
    blk: &[f32],
    q: &HaarQuant,
    w: usize,
    orders: &[Vec<usize>; STEPS],
    out: &mut Vec<u8>,
) {
    if blk.iter().all(|&x| x == 0.0) {
        out.push(0);
        return;
    }
    let mut coded = vec![2u8, c.root.round().clamp(0.0, 255.0) as u8];
    for j in (STEPS + 1 - w..=STEPS).rev() {
        for &p in &orders[j - 1] {
            let qd = c.details[j - 1][p]
                .map(|d| (d / q.delta[j - 1]).round().clamp(-128.0, 127.0) as i8);
            let mask = (0..7)
                .filter(|&k| qd[k] != 0)
                .fold(0u8, |m, k| m | (1 << k));
            coded.push(mask);
            coded.extend(qd.iter().filter(|&&d| d != 0).map(|&d| d as u8));
        }
    }
    let raw_len = 1 + (1usize << (3 * w));
    if raw_len < coded.len() {
        out.push(1);
        let means = inverse_block(c, w);
        out.extend(means.iter().map(|m| m.round().clamp(0.0, 255.0) as u8));
    } else {
        out.extend_from_slice(&coded);
    }
}

/// Encodes `v` with `w_sent` transform steps (1..=4) under the canonical transfer function.
///
/// Errors: empty volume, `w_sent` outside 1..=4, a non-positive quantisation step.
pub fn encode_blocks(
    v: &Volume<u8>,
    canonical: &PiecewiseTransferFunction,
    q: &HaarQuant,
    w_sent: u8,
) -> Result<WaveletPackage> {
    check_steps("steps_sent", w_sent)?;
    if q.delta.iter().any(|d| !(d.is_finite() && *d > 0.0)) {
        return Err(Error::invalid("delta", "quantisation steps must be > 0"));
    }
    let pre = preprocess(v, canonical)?;
    let nb = pre.dims().map(|d| d / BLOCK);
    let orders = morton_orders();
    let coded: Vec<Vec<u8>> = (0..nb[0] * nb[1] * nb[2])
        .into_par_iter()
        .map(|b| {
            let blk = block_of(&pre, [b % nb[0], b / nb[0] % nb[1], b / (nb[0] * nb[1])]);
            let mut out = Vec::new();
            let c = forward_block(&blk);
            code_block(&c, &blk, q, w_sent as usize, &orders, &mut out);
            out
        })
        .collect();
    Ok(WaveletPackage {
        dims: v.dims(),
        steps_sent: w_sent,
        quant: *q,
        blocks: coded.concat(),
    })
}

/// Decodes `w_l` steps (1..=steps sent): the low-resolution volume of `ceil(dims / 16) *
/// 2^w_l` voxels per side (padded blocks included), spacing scaled accordingly.
///
/// Errors: `w_l` outside 1..=steps sent, a truncated or corrupted block stream.
pub fn decode_lowres(p: &WaveletPackage, w_l: u8) -> Result<Volume<f32>> {
    check_steps("w_l", w_l)?;
    check_steps("steps_sent", p.steps_sent)?;
    if w_l > p.steps_sent {
        return Err(Error::invalid(
            "w_l",
            format!("{w_l} steps requested, {} sent", p.steps_sent),
        ));
    }
    if p.dims.contains(&0) {
        return Err(Error::Empty("volume"));
    }
    let (w, ws) = (w_l as usize, p.steps_sent as usize);
    let side = 1usize << w;
    let nb = p.dims.map(|d| d.div_ceil(BLOCK));
    let out_dims = nb.map(|b| b * side);
    let mut out = Volume::filled(out_dims, [1.0 * (BLOCK / side) as f64; 3], 0.0f32)?;
    let mut rd = Reader::new(&p.blocks, "wavelet package");
    let orders = morton_orders();
    for b in 0..nb[0] * nb[1] * nb[2] {
        let values: Vec<f32> = match rd.u8()? {
            0 => vec![0.0; side * side * side],
            1 => {
                let raw = rd.take(1 << (3 * ws))?;
                pool(
                    &raw.iter().map(|&x| x as f32).collect::<Vec<_>>(),
                    1 << ws,
                    side,
                )
            }
            2 => {
                let root = rd.u8()? as f32;
                let mut details = vec![Vec::new(); STEPS];
                for j in (STEPS + 1 - ws..=STEPS).rev() {
                    let n = BLOCK >> j;
                    let mut d = vec![[0.0f32; 7]; n * n * n];
                    for &p_idx in &orders[j - 1] {
                        let mask = rd.u8()?;
                        if mask & 0x80 != 0 {
                            return Err(rd.bad(format!("corrupted significance mask {mask:#04x}")));
                        }
                        for (k, dk) in d[p_idx].iter_mut().enumerate() {
                            if mask >> k & 1 == 1 {
                                *dk = rd.u8()? as i8 as f32 * p.quant.delta[j - 1];
                            }
                        }
                    }
                    details[j - 1] = d;
                }
                inverse_block(&BlockCoefficients { root, details }, w)
            }
            h => return Err(rd.bad(format!("unknown block header {h} in block {b}"))),
        };
        put_block(&mut out, nb, b, side, &values);
    }
    rd.done()?;
    Ok(out)
}

/// Mean pooling of an `n^3` grid to `m^3` (`m` divides `n`).
pub fn pool(values: &[f32], n: usize, m: usize) -> Vec<f32> {
    let f = n / m;
    let mut out = vec![0.0f32; m * m * m];
    for z in 0..n {
        for y in 0..n {
            for x in 0..n {
                out[x / f + m * (y / f + m * (z / f))] += values[x + n * (y + n * z)];
            }
        }
    }
    let norm = (f * f * f) as f32;
    out.iter_mut().for_each(|v| *v /= norm);
    out
}
