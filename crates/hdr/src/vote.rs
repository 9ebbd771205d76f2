//! Synthesis of a source view aligned to a reference view (paper section 3.2): patch voting
//! with both fields of the bidirectional similarity of Simakov et al. (2008) (eq. 5), and the
//! direct warp it replaces (the paper's Fig. 5a).

use rayon::prelude::*;
use wscg_math::{Error, Image, Result};

use crate::nnf::{clamped, Nnf};
use crate::pm::check_patch;

/// Synthesises `src` (view `s`, any channels) aligned to the reference view `r` from both
/// fields of eq. 5: `nnf_rs` (reference to source, on the reference grid) and `nnf_sr`
/// (source to reference, on the source grid). Per reference pixel `p`:
///
/// `T(p) = [ (1/N_r) sum_{q: p in Q(q)} src(q + off_rs(q) + p - q)
///         + (1/N_s) sum_{t: p in Q(t + off_sr(t))} src(t + p - (t + off_sr(t))) ]
///         / [ n_1(p) / N_r + n_2(p) / N_s ]`,
///
/// `Q(q)` the `patch x patch` window at `q`, `n_1`, `n_2` the vote counts, `N_r`, `N_s` the
/// patch counts of the two views. The first term fetches every reference patch from the
/// source, the second pushes every source patch to where it matches in the reference, so
/// every pixel has votes; occluded areas get the colours of their best matches (the paper:
/// "accurate in colour, not geometry"). Votes whose source pixel falls outside `src` are
/// skipped. Each output row sums its votes in a fixed order, so the result does not depend
/// on the thread count.
///
/// Errors: field sizes that do not match the images; invalid patch.
pub fn vote_bds(src: &Image<f32>, nnf_rs: &Nnf, nnf_sr: &Nnf, patch: usize) -> Result<Image<f32>> {
    let (hs, ws, c) = src.shape();
    let (hr, wr) = (nnf_rs.height(), nnf_rs.width());
    if nnf_sr.height() != hs || nnf_sr.width() != ws {
        return Err(Error::ShapeMismatch(format!(
            "the source-to-reference field is {} x {}, the source image {hs} x {ws}",
            nnf_sr.height(),
            nnf_sr.width()
        )));
    }
    check_patch(patch, hr.min(hs), wr.min(ws))?;
    let h = (patch / 2) as i64;
    let (nr, ns) = ((hr * wr) as f64, (hs * ws) as f64);
    // Source pixels bucketed by the reference row of their match, in index order.
    let mut bucket: Vec<Vec<u32>> = vec![Vec::new(); hr];
    for t in 0..hs * ws {
        let o = nnf_sr.off[t];
        let my = (t / ws) as i64 + o[1] as i64;
        if (0..hr as i64).contains(&my) {
            bucket[my as usize].push(t as u32);
        }
    }
    // Adds the source pixels `sx0 + (px - px0)` of row `sy` to the accumulators of the output
    // pixels `px` in `px0..=px1`, keeping only sources inside the image: one contiguous run
    // of samples, added in the order of the pixels as a pixel-by-pixel loop would.
    let add_run = |acc: &mut [f64], n: &mut [u32], sy: i64, (px0, px1): (i64, i64), sx0: i64| {
        if !(0..hs as i64).contains(&sy) {
            return;
        }
        let (lo, hi) = (px0.max(px0 - sx0), px1.min(px0 - sx0 + ws as i64 - 1));
        if lo > hi {
            return;
        }
        let row = &src.data()[sy as usize * ws * c..(sy as usize + 1) * ws * c];
        let (s0, lo, len) = (
            (sx0 + lo - px0) as usize,
            lo as usize,
            (hi - lo + 1) as usize,
        );
        for (a, &v) in acc[lo * c..(lo + len) * c]
            .iter_mut()
            .zip(&row[s0 * c..(s0 + len) * c])
        {
            *a += v as f64;
        }
        for k in &mut n[lo..lo + len] {
            *k += 1;
        }
    };
    let mut out = vec![0f32; hr * wr * c];
    out.par_chunks_mut(wr * c)
        .enumerate()
        .for_each(|(py, row)| {
            let py = py as i64;
            let mut a1 = vec![0f64; wr * c];
            let mut a2 = vec![0f64; wr * c];
            let mut n1 = vec![0u32; wr];
            let mut n2 = vec![0u32; wr];
            // First term: reference patches Q(q) covering p fetch from the source.
            for qy in (py - h).max(0)..=(py + h).min(hr as i64 - 1) {
                for qx in 0..wr as i64 {
                    let o = nnf_rs.at(qy as usize, qx as usize);
                    let px0 = (qx - h).max(0);
                    let px1 = (qx + h).min(wr as i64 - 1);
                    add_run(
                        &mut a1,
                        &mut n1,
                        py + o[1] as i64,
                        (px0, px1),
                        px0 + o[0] as i64,
                    );
                }
            }
            // Second term: source patches pushed to their matches m = t + off_sr(t).
            for my in (py - h).max(0)..=(py + h).min(hr as i64 - 1) {
                for &t in &bucket[my as usize] {
                    let (ty, tx) = ((t as usize / ws) as i64, (t as usize % ws) as i64);
                    let mx = tx + nnf_sr.off[t as usize][0] as i64;
                    let px0 = (mx - h).max(0);
                    let px1 = (mx + h).min(wr as i64 - 1);
                    add_run(&mut a2, &mut n2, ty + py - my, (px0, px1), tx + px0 - mx);
                }
            }
            for x in 0..wr {
                let den = n1[x] as f64 / nr + n2[x] as f64 / ns;
                let o = &mut row[x * c..(x + 1) * c];
                if den > 0.0 {
                    for k in 0..c {
                        o[k] = ((a1[x * c + k] / nr + a2[x * c + k] / ns) / den) as f32;
                    }
                } else {
                    let d = nnf_rs.at(py as usize, x);
                    o.copy_from_slice(clamped(src, py + d[1] as i64, x as i64 + d[0] as i64));
                }
            }
        });
    Image::new(hr, wr, c, out)
}

/// Direct warp (the paper's Fig. 5a): `T(p) = src(p + off_rs(p))`, clamped into `src`.
pub fn warp_direct(src: &Image<f32>, nnf_rs: &Nnf) -> Result<Image<f32>> {
    let c = src.channels();
    let (hr, wr) = (nnf_rs.height(), nnf_rs.width());
    let mut out = vec![0f32; hr * wr * c];
    out.par_chunks_mut(c).enumerate().for_each(|(i, o)| {
        let (y, x) = (i / wr, i % wr);
        let d = nnf_rs.off[i];
        o.copy_from_slice(clamped(src, y as i64 + d[1] as i64, x as i64 + d[0] as i64));
    });
    Image::new(hr, wr, c, out)
}
