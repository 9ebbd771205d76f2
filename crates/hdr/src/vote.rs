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
    // Adds the votes of a run of patches that share one offset, centred at the output
    // columns `qa..=qb`: output pixel `px` receives the source pixel `(sy, px + dx)` once per
    // patch of the run whose window covers it (`w(px)` times), and only where that pixel lies
    // inside the source. Coherent fields have long runs, so a pixel takes one weighted vote
    // per run instead of one per patch.
    let add_run = |acc: &mut [f64], n: &mut [u32], sy: i64, (qa, qb): (i64, i64), dx: i64| {
        if !(0..hs as i64).contains(&sy) {
            return;
        }
        // Output columns the run covers whose source column lies inside the source.
        let lo = (qa - h).max(0).max(-dx);
        let hi = (qb + h).min(wr as i64 - 1).min(ws as i64 - 1 - dx);
        if lo > hi {
            return;
        }
        let row = &src.data()[sy as usize * ws * c..(sy as usize + 1) * ws * c];
        for px in lo..=hi {
            let w = (qb.min(px + h) - qa.max(px - h) + 1) as u32;
            let (o, sx) = (px as usize, (px + dx) as usize);
            let wf = w as f64;
            for (a, &v) in acc[o * c..(o + 1) * c]
                .iter_mut()
                .zip(&row[sx * c..(sx + 1) * c])
            {
                *a += wf * v as f64;
            }
            n[o] += w;
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
            // First term: reference patches Q(q) covering p fetch from the source; the patches
            // of row `qy` grouped into runs of equal offsets.
            for qy in (py - h).max(0)..=(py + h).min(hr as i64 - 1) {
                let offs = &nnf_rs.off[qy as usize * wr..(qy as usize + 1) * wr];
                let mut qa = 0;
                while qa < wr {
                    let o = offs[qa];
                    let qb = qa + offs[qa..].iter().take_while(|&&v| v == o).count() - 1;
                    let sy = py + o[1] as i64;
                    add_run(&mut a1, &mut n1, sy, (qa as i64, qb as i64), o[0] as i64);
                    qa = qb + 1;
                }
            }
            // Second term: source patches pushed to their matches m = t + off_sr(t); adjacent
            // source pixels with one offset (adjacent in the bucket, so in one row: the
            // bucket holds one match row) form a run of adjacent matches.
            for my in (py - h).max(0)..=(py + h).min(hr as i64 - 1) {
                let b = &bucket[my as usize];
                let mut k = 0;
                while k < b.len() {
                    let t0 = b[k] as usize;
                    let o = nnf_sr.off[t0];
                    let mut len = 1;
                    while k + len < b.len()
                        && b[k + len] as usize == t0 + len
                        && nnf_sr.off[t0 + len] == o
                    {
                        len += 1;
                    }
                    let mx = (t0 % ws) as i64 + o[0] as i64;
                    add_run(
                        &mut a2,
                        &mut n2,
                        py - o[1] as i64,
                        (mx, mx + len as i64 - 1),
                        -(o[0] as i64),
                    );
                    k += len;
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
