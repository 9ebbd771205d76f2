//! PatchMatch on a scanline (paper section 3.1): the epipolar variant of the paper, with the
//! coherence-penalised cost `D = SSD / C` (eqs. 2-4) and the 1-D random search of eq. 1, and
//! the original 2-D PatchMatch of Barnes et al. (2009) it is compared against.
//!
//! Both run the classic sequential order: even iterations scan top-left to bottom-right and
//! propagate from the left and top neighbours, odd iterations scan back and propagate from
//! the right and bottom ones, so a good match travels across the whole image in one sweep.
//! The cost of a pixel's current match is recomputed before every comparison, because the
//! coherence term depends on neighbours that have moved since it was stored. The rows of a
//! sweep run on the pool's threads as a pipeline that shows every pixel exactly the
//! neighbours of the sequential scan (see `Run::sweep`), with one random stream per row and
//! sweep, so one field uses every core (the paper matches the pairs of views in parallel;
//! so does [`crate::multiscopic_hdr`]) and the result depends on the seed only.
//!
//! The parts: `kernels`, the sums of squared differences (portable and AVX2); `cost`, the
//! patch distance over two images and the coherence term (eqs. 2-4); `search`, the
//! initialisation, propagation and random search of a run; `schedule`, the row pipeline of
//! a sweep. This module holds the parameters and the entry points.

mod cost;
mod kernels;
mod schedule;
mod search;

use wscg_math::{Error, Image, Result};

use self::cost::{coherence_table, Space};
use self::kernels::{avx2_available, padded, tail_mask};
use self::search::Run;
use crate::nnf::Nnf;

wscg_math::params! {
    /// Parameters of [`patchmatch`].
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct PatchMatchParams {
        /// Patch side `N` (odd, `>= 3`; the paper's figures use 7).
        pub patch: usize,
        /// Iterations (the paper: "two iterations were enough").
        pub iters: usize,
        /// Smallest horizontal offset searched (epipolar mode).
        pub d_min: i32,
        /// Largest horizontal offset searched (epipolar mode).
        pub d_max: i32,
        /// Vertical tolerance of the epipolar search (0: exact rectification).
        pub v_tol: i32,
        /// Ratio `alpha` of the random search radii (eq. 1; 1/2 as suggested).
        pub alpha: f32,
        /// Search on the epipolar line (the paper) or over the whole image (2-D).
        pub epipolar: bool,
        /// Divide the SSD by the coherence term `C` (eq. 2) or use the SSD alone.
        pub coherence: bool,
        /// Lower bound of `C` (the paper leaves `C <= 0` undefined).
        pub c_min: f32,
        /// Seed of the initialisation and the random search.
        pub seed: u64,
        /// Not in the paper (an ablation): weight each squared difference by the smaller Khan
        /// weight of the two samples, so clipped pixels do not drive the match (used by
        /// [`patchmatch_weighted`] and the multiscopic driver; plain [`patchmatch`] has no
        /// weights and ignores it).
        pub weighted_cost: bool,
    }
}

impl Default for PatchMatchParams {
    fn default() -> Self {
        Self {
            patch: 7,
            iters: 2,
            d_min: -64,
            d_max: 64,
            v_tol: 0,
            alpha: 0.5,
            epipolar: true,
            coherence: true,
            c_min: 0.05,
            seed: 0,
            weighted_cost: false,
        }
    }
}

impl PatchMatchParams {
    /// The original PatchMatch of Barnes et al. 2009: 2-D search over the whole source image,
    /// SSD cost without the coherence term.
    pub fn barnes(patch: usize, iters: usize, seed: u64) -> Self {
        Self {
            patch,
            iters,
            epipolar: false,
            coherence: false,
            seed,
            ..Self::default()
        }
    }

    /// The largest displacement `Max_disp` (eq. 4, and `w` of eq. 1) of the epipolar search.
    pub fn max_disp(&self) -> i32 {
        self.d_min
            .unsigned_abs()
            .max(self.d_max.unsigned_abs())
            .clamp(1, i32::MAX as u32) as i32
    }

    /// Checks the ranges: `patch` odd and `>= 3`, `alpha` in `(0, 1)`, `c_min` in `(0, 1]`,
    /// and in epipolar mode `d_min <= d_max` and `v_tol >= 0` (the bounds set by the image
    /// size are checked by [`PatchMatchParams::validate_for`]).
    pub fn validate(&self) -> Result<()> {
        if self.patch < 3 || self.patch.is_multiple_of(2) {
            return Err(Error::invalid(
                "patch",
                format!("must be odd and >= 3, got {}", self.patch),
            ));
        }
        if self.epipolar {
            if self.d_min > self.d_max {
                return Err(Error::invalid(
                    "d_min",
                    format!("d_min = {} > d_max = {}", self.d_min, self.d_max),
                ));
            }
            if self.v_tol < 0 {
                return Err(Error::invalid(
                    "v_tol",
                    format!("must be >= 0, got {}", self.v_tol),
                ));
            }
        }
        if !(self.alpha > 0.0 && self.alpha < 1.0) {
            return Err(Error::invalid(
                "alpha",
                format!("must be in (0, 1), got {}", self.alpha),
            ));
        }
        if !(self.c_min > 0.0 && self.c_min <= 1.0) {
            return Err(Error::invalid(
                "c_min",
                format!("must be in (0, 1], got {}", self.c_min),
            ));
        }
        Ok(())
    }

    /// [`PatchMatchParams::validate`], then the bounds for images of `(height, width)`: the
    /// patch fits, and in epipolar mode the largest disparity is below the width and `v_tol`
    /// below the height.
    pub fn validate_for(&self, height: usize, width: usize) -> Result<()> {
        self.validate()?;
        check_patch(self.patch, height, width)?;
        if self.epipolar {
            if self.max_disp() as usize >= width {
                return Err(Error::invalid(
                    "max_disparity",
                    format!(
                        "|disparity| up to {} must be < the image width {width}",
                        self.max_disp()
                    ),
                ));
            }
            if self.v_tol as usize >= height {
                return Err(Error::invalid(
                    "v_tol",
                    format!("must be in 0..{height}, got {}", self.v_tol),
                ));
            }
        }
        Ok(())
    }
}

/// Checks a patch side: odd, `>= 3` and at most the smaller image side.
pub fn check_patch(patch: usize, height: usize, width: usize) -> Result<()> {
    if patch < 3 || patch.is_multiple_of(2) || patch > height.min(width) {
        return Err(Error::invalid(
            "patch",
            format!(
                "must be odd, >= 3 and <= min(height, width) = {}, got {patch}",
                height.min(width)
            ),
        ));
    }
    Ok(())
}

/// Checks that two images can be matched: same channel count, finite values.
pub fn check_pair(a: &Image<f32>, b: &Image<f32>) -> Result<()> {
    if a.channels() != b.channels() {
        return Err(Error::ShapeMismatch(format!(
            "images have {} and {} channels",
            a.channels(),
            b.channels()
        )));
    }
    if a.data().is_empty() || b.data().is_empty() {
        return Err(Error::invalid("image", "is empty"));
    }
    a.ensure_finite("a")?;
    b.ensure_finite("b")
}

/// The nearest-neighbour field from `a` to `b` (paper section 3.1), with [`PatchMatchParams`]
/// choosing the paper's epipolar, coherence-penalised search (the default) or the original
/// 2-D PatchMatch ([`PatchMatchParams::barnes`]). Images may differ in size but not in channels.
///
/// Epipolar mode: offsets `(d, dy)` with `d` in `[d_min, d_max]` and `|dy| <= v_tol`, every
/// source centre inside `b`; initialised uniformly in that range (the paper: "random
/// transformation values within a maximal disparity range on the same epipolar line").
/// 2-D mode: sources anywhere in `b`, initialised uniformly over `b`, random search from
/// radius `max(W, H)`.
///
/// Errors: channel counts differ; non-finite values; invalid parameters (see
/// [`PatchMatchParams::validate_for`]).
pub fn patchmatch(a: &Image<f32>, b: &Image<f32>, p: &PatchMatchParams) -> Result<Nnf> {
    p.validate()?;
    run_patchmatch(a, b, None, p)
}

/// [`patchmatch`] with per-sample weights `wa`, `wb` (same shapes as `a`, `b`; Khan weights
/// in the multiscopic driver): with `p.weighted_cost` every squared difference is multiplied
/// by `min(wa, wb)`, so clipped samples (weight 0) do not drive the match. Not in the paper,
/// which reports failures in saturated areas; an ablation.
///
/// Errors: as [`patchmatch`]; weights of other shapes or not finite.
pub fn patchmatch_weighted(
    a: &Image<f32>,
    b: &Image<f32>,
    wa: &Image<f32>,
    wb: &Image<f32>,
    p: &PatchMatchParams,
) -> Result<Nnf> {
    p.validate()?;
    if wa.shape() != a.shape() || wb.shape() != b.shape() {
        return Err(Error::ShapeMismatch(
            "the weights must have the shapes of their images".into(),
        ));
    }
    wa.ensure_finite("wa")?;
    wb.ensure_finite("wb")?;
    let weights = p.weighted_cost.then_some((wa.data(), wb.data()));
    run_patchmatch(a, b, weights, p)
}

fn run_patchmatch(
    a: &Image<f32>,
    b: &Image<f32>,
    weights: Option<(&[f32], &[f32])>,
    p: &PatchMatchParams,
) -> Result<Nnf> {
    check_pair(a, b)?;
    let (ha, wa, c) = a.shape();
    let (hb, wb, _) = b.shape();
    p.validate_for(ha.min(hb), wa.min(wb))?;
    let n = ha * wa;
    // The 4-lane padded layout serves the weighted ablation and patch rows of fewer than 8
    // samples; otherwise every path reads the samples as they are and nothing is copied.
    let side = p.patch / 2 * 2 + 1;
    let pad = weights.is_some() || side * c < 8;
    let lay = |data| {
        if pad {
            padded(data, c)
        } else {
            std::borrow::Cow::Borrowed(data)
        }
    };
    let (pa, pb) = (lay(a.data()), lay(b.data()));
    let pw = weights.map(|(x, y)| (padded(x, c), padded(y, c)));
    let w = if p.epipolar {
        p.max_disp() as f32
    } else {
        wa.max(ha) as f32
    };
    let mut run = Run {
        sp: Space {
            a: &pa,
            b: &pb,
            ua: a.data(),
            ub: b.data(),
            avx2: avx2_available(),
            tail: tail_mask(side * c),
            weights: pw.as_ref().map(|(x, y)| (&x[..], &y[..])),
            wa: wa as i32,
            ha: ha as i32,
            wb: wb as i32,
            hb: hb as i32,
            c: if pad { c.div_ceil(4) * 4 } else { c },
            c_real: c,
            half: (p.patch / 2) as i32,
        },
        p: *p,
        off: vec![[0, 0]; n],
        cost: vec![f32::INFINITY; n],
        ssd: vec![f32::NAN; n],
        w,
        coh: coherence_table(p, w),
    };
    run.init();
    for it in 0..p.iters {
        wscg_math::cancel::check()?;
        run.sweep(it);
    }
    if p.iters == 0 {
        for y in 0..ha as i32 {
            for x in 0..wa as i32 {
                let i = (y * wa as i32 + x) as usize;
                run.cost[i] = run.cost_of(x, y, run.off[i], f32::INFINITY);
            }
        }
    }
    Nnf::new(ha, wa, run.off, run.cost)
}

/// The original PatchMatch (Barnes et al. 2009) baseline: 2-D, SSD only.
pub fn patchmatch_2d(
    a: &Image<f32>,
    b: &Image<f32>,
    patch: usize,
    iters: usize,
    seed: u64,
) -> Result<Nnf> {
    patchmatch(a, b, &PatchMatchParams::barnes(patch, iters, seed))
}
