//! Index-based partial matching (section 3.4, eqs. 7-18), the whole-ear Haar baseline
//! (Fig. 12) and CMC curves.
//!
//! Probe block `j` (grid position `(i_j, c_j)`, features `t_j`) is compared under shift
//! `s = (dr, dc)` with enrolled block `(i_j + dr, c_j + dc)` when that lies inside the grid
//! (the set `V_s`). Distances are normalised to `[0, 1]` (the paper's `S = 1 - D` needs it;
//! its eq. 7 is unnormalised): `d_{s,j} = |t_j - r_partner| / (2 sqrt(block_len))`. The
//! per-shift score (eqs. 8-16) is `S_s = 1 - sqrt(mean_{j in V_s} d_{s,j}^2)`, defined when
//! `|V_s| >= ceil(m / 2)`; the rules of [`ScoreRule`] combine them.
//!
//! [`Gallery`] stores templates block-major and feature-major (`[block][feature][template]`),
//! so one probe block against all templates is a run of contiguous SIMD-friendly loads, and
//! a gallery chunk's block is loaded once for the up to nine probe blocks that map onto it.

use rayon::prelude::*;
use wscg_math::image::Image;
use wscg_math::{Error, Result};

use super::features::{block_features, check_input, feature_plane, normalise, EarTemplate};
use super::occlusion::{detect_on_normalised, OcclusionReport};
use super::params::{EarParams, ScoreRule};

/// Probe features: the Haar LL of the kept blocks and their indices.
#[derive(Clone, Debug, PartialEq)]
pub struct Probe {
    /// `m x block_len` features of the kept blocks, in index order.
    pub feats: Vec<f32>,
    /// Block indices of the kept blocks (the index vector `I`), ascending.
    pub index: Vec<usize>,
    /// The occlusion report (`None` for a baseline probe, which skips detection).
    pub report: Option<OcclusionReport>,
}

impl Probe {
    /// Whether occlusion detection rejected this probe (step 12).
    pub fn rejected(&self) -> bool {
        self.report.as_ref().is_some_and(|r| r.rejected)
    }

    /// Number of kept blocks `m`.
    pub fn len(&self) -> usize {
        self.index.len()
    }

    /// Whether no block is kept.
    pub fn is_empty(&self) -> bool {
        self.index.is_empty()
    }
}

/// Builds the probe of an RGB ear crop: occlusion detection (Algorithm 1), then the Haar LL
/// of the un-occluded blocks of `F` (or of the masked `X = F . Z` with `p.mask_features`).
/// A rejected probe is a normal result ([`Probe::rejected`]); its features are still filled
/// so it can be inspected.
///
/// Errors: an image under 2 x 2, a non-RGB image, bad parameters.
pub fn make_probe(img: &Image<u8>, p: &EarParams) -> Result<Probe> {
    p.validate()?;
    check_input(img, false)?;
    let small = normalise(img, p)?;
    let report = detect_on_normalised(&small, p)?;
    let within = p.equalize_on_skin.then(|| report.skin_mask.data());
    let mut plane = feature_plane(&small, within)?;
    if p.mask_features {
        for (v, &z) in plane.data_mut().iter_mut().zip(report.skin_mask.data()) {
            *v *= z as f64;
        }
    }
    let all = block_features(plane.view(), p)?;
    let index = report.index();
    let k = p.block_len();
    let feats = index
        .iter()
        .flat_map(|&b| all[b * k..(b + 1) * k].iter().copied())
        .collect();
    Ok(Probe {
        feats,
        index,
        report: Some(report),
    })
}

/// The baseline probe (Fig. 12): Haar features of the whole image, every block kept, no
/// occlusion detection. Errors as [`make_probe`] (grey input allowed with `gray_enrolment`).
pub fn make_baseline_probe(img: &Image<u8>, p: &EarParams) -> Result<Probe> {
    p.validate()?;
    check_input(img, p.gray_enrolment)?;
    let plane = feature_plane(&normalise(img, p)?, None)?;
    Ok(Probe {
        feats: block_features(plane.view(), p)?,
        index: (0..p.blocks()).collect(),
        report: None,
    })
}

/// Parameters of the baseline as a configuration of the proposed pipeline: every block,
/// the single shift `B0`, the overall maximum (which is then `S_0`).
pub fn baseline_params(p: &EarParams) -> EarParams {
    EarParams {
        shifts: vec![(0, 0)],
        score: ScoreRule::OverallMax,
        ..p.clone()
    }
}

/// Baseline score of a whole-ear probe against one template (Fig. 12): the Euclidean
/// distance of the full LL vectors, `1 - |t - r| / (2 sqrt(block_len) sqrt(blocks))`.
/// Errors: a template or probe that does not hold every block of `p`.
pub fn baseline_score(probe: &Probe, t: &EarTemplate, p: &EarParams) -> Result<f64> {
    t.check(p)?;
    if probe.feats.len() != t.features().len() {
        return Err(Error::ShapeMismatch(format!(
            "baseline probe has {} values, the template {}",
            probe.feats.len(),
            t.features().len()
        )));
    }
    let d2: f64 = probe
        .feats
        .iter()
        .zip(t.features())
        .map(|(&a, &b)| ((a - b) as f64).powi(2))
        .sum();
    Ok(1.0 - d2.sqrt() / (p.distance_scale() * (p.blocks() as f64).sqrt()))
}

/// Shift geometry of one probe: partner block of every (shift, probe block) pair and the
/// template-independent counts.
struct Layout {
    m: usize,
    n_shifts: usize,
    /// `partner[s * m + j]`.
    partner: Vec<Option<usize>>,
    /// `|V_s|`.
    shift_count: Vec<usize>,
    /// Shifts whose `S_s` is defined (`|V_s| >= ceil(m / 2)`).
    defined: Vec<bool>,
    /// Number of shifts with a valid partner, per probe block.
    n_valid: Vec<usize>,
    /// `2 sqrt(block_len)`.
    scale: f64,
}

impl Layout {
    fn new(probe: &Probe, p: &EarParams) -> Result<Self> {
        let (gr, gc) = p.grid();
        let m = probe.index.len();
        if m == 0 {
            return Err(Error::invalid("probe", "has no un-occluded block to match"));
        }
        if probe.feats.len() != m * p.block_len() {
            return Err(Error::ShapeMismatch(format!(
                "probe has {} values for {m} blocks of {} features",
                probe.feats.len(),
                p.block_len()
            )));
        }
        if let Some(&b) = probe.index.iter().find(|&&b| b >= gr * gc) {
            return Err(Error::invalid(
                "probe",
                format!("block index {b} outside the {gr} x {gc} grid"),
            ));
        }
        let n_shifts = p.shifts.len();
        let mut partner = Vec::with_capacity(n_shifts * m);
        for &(dr, dc) in &p.shifts {
            for &b in &probe.index {
                let (r, c) = ((b / gc) as i64 + dr as i64, (b % gc) as i64 + dc as i64);
                let ok = r >= 0 && c >= 0 && r < gr as i64 && c < gc as i64;
                partner.push(ok.then(|| r as usize * gc + c as usize));
            }
        }
        let shift_count: Vec<usize> = (0..n_shifts)
            .map(|s| partner[s * m..(s + 1) * m].iter().flatten().count())
            .collect();
        let defined = shift_count
            .iter()
            .map(|&c| c > 0 && c >= m.div_ceil(2))
            .collect();
        let n_valid = (0..m)
            .map(|j| {
                (0..n_shifts)
                    .filter(|&s| partner[s * m + j].is_some())
                    .count()
            })
            .collect();
        Ok(Layout {
            m,
            n_shifts,
            partner,
            shift_count,
            defined,
            n_valid,
            scale: p.distance_scale(),
        })
    }

    /// Combines one template's statistics into the score of `rule`: `min_d2(j)` the smallest
    /// raw squared distance of block `j` over its valid shifts, `sum_d(j)` the sum of its raw
    /// distances, `shift_d2(s)` the sum of raw squared distances over `V_s`. A rule with
    /// nothing defined (no valid shift) scores `-inf`.
    fn score(
        &self,
        rule: ScoreRule,
        min_d2: impl Fn(usize) -> f32,
        sum_d: impl Fn(usize) -> f32,
        shift_d2: impl Fn(usize) -> f32,
    ) -> f64 {
        let sc = self.scale;
        let blocks = (0..self.m).filter(|&j| self.n_valid[j] > 0);
        let per_shift = (0..self.n_shifts).filter(|&s| self.defined[s]).map(|s| {
            1.0 - (shift_d2(s) as f64 / self.shift_count[s] as f64)
                .max(0.0)
                .sqrt()
                / sc
        });
        let mean = |it: &mut dyn Iterator<Item = f64>| {
            let (n, t) = it.fold((0usize, 0.0), |(n, t), v| (n + 1, t + v));
            if n == 0 {
                f64::NEG_INFINITY
            } else {
                t / n as f64
            }
        };
        match rule {
            ScoreRule::BlockwiseMax => {
                mean(&mut blocks.map(|j| 1.0 - (min_d2(j) as f64).max(0.0).sqrt() / sc))
            }
            ScoreRule::BlockwiseMean => {
                mean(&mut blocks.map(|j| 1.0 - sum_d(j) as f64 / (self.n_valid[j] as f64 * sc)))
            }
            ScoreRule::OverallMax => per_shift.fold(f64::NEG_INFINITY, f64::max),
            ScoreRule::OverallMean => mean(&mut per_shift.into_iter()),
            ScoreRule::LiteralEq18 => blocks
                .map(|j| 1.0 - (min_d2(j) as f64).max(0.0).sqrt() / sc)
                .fold(f64::NEG_INFINITY, f64::max),
        }
    }
}

/// Every quantity of the match of one probe against one template.
#[derive(Clone, Debug, PartialEq)]
pub struct ScoreBreakdown {
    /// Normalised block distances `d_{s,j}` (`shifts x m`, row-major by shift); `None` where
    /// the partner block lies outside the grid.
    pub distances: Vec<Option<f64>>,
    /// Per-shift scores `S_s` (eqs. 8-16); `None` where undefined.
    pub per_shift: Vec<Option<f64>>,
    /// For every probe block, the shift with the smallest distance (ties: the first).
    pub best_shift: Vec<usize>,
    /// Scores under every rule, in the order of [`ScoreRule::ALL`].
    pub rules: [f64; 5],
}

impl ScoreBreakdown {
    /// The score under `rule`.
    pub fn get(&self, rule: ScoreRule) -> f64 {
        self.rules[rule.index()]
    }
}

/// Matches a probe against one template and returns every intermediate quantity (the
/// reference path; [`identify`] computes the same scores for a whole gallery at once).
///
/// Errors: a template that does not fit `p`, a probe without blocks, bad parameters.
pub fn score(probe: &Probe, t: &EarTemplate, p: &EarParams) -> Result<ScoreBreakdown> {
    p.validate()?;
    t.check(p)?;
    let lay = Layout::new(probe, p)?;
    let (m, k) = (lay.m, p.block_len());
    let raw: Vec<Option<f32>> = lay
        .partner
        .iter()
        .enumerate()
        .map(|(i, part)| {
            part.map(|b| {
                let tj = &probe.feats[(i % m) * k..(i % m + 1) * k];
                tj.iter()
                    .zip(t.block(b))
                    .map(|(&a, &r)| (a - r) * (a - r))
                    .sum::<f32>()
            })
        })
        .collect();
    let at = |s: usize, j: usize| raw[s * m + j];
    let min_d2 = |j: usize| {
        (0..lay.n_shifts)
            .filter_map(|s| at(s, j))
            .fold(f32::INFINITY, f32::min)
    };
    let sum_d = |j: usize| {
        (0..lay.n_shifts)
            .filter_map(|s| at(s, j))
            .map(f32::sqrt)
            .sum()
    };
    let shift_d2 = |s: usize| (0..m).filter_map(|j| at(s, j)).sum();
    let rules = ScoreRule::ALL.map(|r| lay.score(r, min_d2, sum_d, shift_d2));
    let best_shift = (0..m)
        .map(|j| {
            (0..lay.n_shifts)
                .filter_map(|s| at(s, j).map(|d| (s, d)))
                .fold((0, f32::INFINITY), |a, b| if b.1 < a.1 { b } else { a })
                .0
        })
        .collect();
    let per_shift = (0..lay.n_shifts)
        .map(|s| {
            lay.defined[s]
                .then(|| 1.0 - (shift_d2(s) as f64 / lay.shift_count[s] as f64).sqrt() / lay.scale)
        })
        .collect();
    Ok(ScoreBreakdown {
        distances: raw
            .iter()
            .map(|d| d.map(|d| (d as f64).sqrt() / lay.scale))
            .collect(),
        per_shift,
        best_shift,
        rules,
    })
}

/// Enrolled templates in the block-major, feature-major layout of fast identification.
#[derive(Clone, Debug)]
pub struct Gallery {
    n: usize,
    blocks: usize,
    block_len: usize,
    /// `data[(b * block_len + f) * n + g]`.
    data: Vec<f32>,
}

impl Gallery {
    /// Lays out `templates` (all of one shape). Errors: an empty list, mixed shapes.
    pub fn new(templates: &[EarTemplate]) -> Result<Self> {
        let first = templates.first().ok_or(Error::Empty("gallery"))?;
        let (nb, k) = (first.blocks(), first.block_len());
        let mut flat = Vec::with_capacity(templates.len() * nb * k);
        for (i, t) in templates.iter().enumerate() {
            if (t.blocks(), t.block_len()) != (nb, k) {
                return Err(Error::ShapeMismatch(format!(
                    "template {i} has {} x {} features, template 0 {nb} x {k}",
                    t.blocks(),
                    t.block_len()
                )));
            }
            flat.extend_from_slice(t.features());
        }
        Self::from_features(&flat, templates.len(), nb, k)
    }

    /// Lays out `n` templates given as one `n x blocks x block_len` row-major array.
    /// Errors: a length mismatch, zero sizes, non-finite values.
    pub fn from_features(flat: &[f32], n: usize, blocks: usize, block_len: usize) -> Result<Self> {
        if n == 0 {
            return Err(Error::Empty("gallery"));
        }
        if blocks == 0 || block_len == 0 || flat.len() != n * blocks * block_len {
            return Err(Error::ShapeMismatch(format!(
                "gallery has {} values, expected {n} templates x {blocks} blocks x \
                 {block_len} features",
                flat.len()
            )));
        }
        if let Some(i) = flat.iter().position(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                name: "gallery",
                index: i,
            });
        }
        let per = blocks * block_len;
        let mut data = vec![0.0f32; flat.len()];
        data.par_chunks_mut(n).enumerate().for_each(|(bf, row)| {
            for (g, v) in row.iter_mut().enumerate() {
                *v = flat[g * per + bf];
            }
        });
        Ok(Gallery {
            n,
            blocks,
            block_len,
            data,
        })
    }

    /// Number of templates.
    pub fn len(&self) -> usize {
        self.n
    }

    /// Always false (a gallery holds at least one template).
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// Template `g` in the usual layout.
    pub fn template(&self, g: usize) -> Result<EarTemplate> {
        if g >= self.n {
            return Err(Error::invalid(
                "index",
                format!("{g} outside a gallery of {}", self.n),
            ));
        }
        let feats = (0..self.blocks * self.block_len)
            .map(|bf| self.data[bf * self.n + g])
            .collect();
        EarTemplate::new(feats, self.blocks, self.block_len)
    }

    fn check(&self, p: &EarParams) -> Result<()> {
        p.check_layout("gallery", self.blocks, self.block_len)
    }
}

/// Templates per work item of [`scores`]: a multiple of the SIMD width, small enough that a
/// chunk's accumulators stay in L1/L2.
const CHUNK: usize = 64;

/// Score of `probe` against every template of `gallery` under `p.score`, in gallery order
/// (parallel over template chunks). Errors: shape mismatches, a probe without blocks.
pub fn scores(probe: &Probe, gallery: &Gallery, p: &EarParams) -> Result<Vec<f64>> {
    let mut all = scores_by_rule(probe, gallery, p, &[p.score])?;
    Ok(all.swap_remove(0))
}

/// Scores under each of `rules` (one vector per rule, in gallery order) from a single pass
/// over the gallery: every rule is a different reduction of the same block distances.
/// Errors as [`scores`].
pub fn scores_by_rule(
    probe: &Probe,
    gallery: &Gallery,
    p: &EarParams,
    rules: &[ScoreRule],
) -> Result<Vec<Vec<f64>>> {
    p.validate()?;
    gallery.check(p)?;
    let lay = Layout::new(probe, p)?;
    let (m, k, n, ns) = (lay.m, p.block_len(), gallery.n, lay.n_shifts);
    // Pairs (shift, probe block) grouped by the enrolled block they read.
    let mut by_block: Vec<Vec<(usize, usize)>> = vec![Vec::new(); gallery.blocks];
    for s in 0..ns {
        for j in 0..m {
            if let Some(b) = lay.partner[s * m + j] {
                by_block[b].push((s, j));
            }
        }
    }
    let kernel = ChunkKernel {
        feats: &probe.feats,
        gallery,
        by_block: &by_block,
        k,
        need_sum_d: rules.contains(&ScoreRule::BlockwiseMean),
    };
    // Template-major while filling (one chunk per task), then split per rule.
    let nr = rules.len();
    let mut flat = vec![0.0f64; n * nr];
    flat.par_chunks_mut(CHUNK * nr)
        .enumerate()
        .for_each(|(ci, out_chunk)| {
            let cw = out_chunk.len() / nr;
            let mut acc = ChunkStats {
                min_d2: vec![f32::INFINITY; m * CHUNK],
                sum_d: vec![0.0f32; if kernel.need_sum_d { m * CHUNK } else { 0 }],
                shift_d2: vec![0.0f32; ns * CHUNK],
            };
            kernel.run(ci * CHUNK, cw, &mut acc);
            for (gi, o) in out_chunk.chunks_exact_mut(nr).enumerate() {
                for (o, &rule) in o.iter_mut().zip(rules) {
                    *o = lay.score(
                        rule,
                        |j| acc.min_d2[j * CHUNK + gi],
                        |j| acc.sum_d[j * CHUNK + gi],
                        |s| acc.shift_d2[s * CHUNK + gi],
                    );
                }
            }
        });
    Ok((0..nr)
        .map(|r| flat.iter().skip(r).step_by(nr).copied().collect())
        .collect())
}

/// Per-template statistics of one chunk (`[probe block or shift][template in chunk]`).
struct ChunkStats {
    /// Smallest raw squared distance of each probe block over its valid shifts.
    min_d2: Vec<f32>,
    /// Sum of raw distances of each probe block (block-wise mean only).
    sum_d: Vec<f32>,
    /// Sum of raw squared distances of each shift over its valid blocks.
    shift_d2: Vec<f32>,
}

/// The inner loop of [`scores`]: every (shift, probe block) pair against a chunk of
/// templates, reading each enrolled block once for all pairs that map onto it.
struct ChunkKernel<'a> {
    feats: &'a [f32],
    gallery: &'a Gallery,
    by_block: &'a [Vec<(usize, usize)>],
    k: usize,
    need_sum_d: bool,
}

impl ChunkKernel<'_> {
    /// Accumulates templates `g0 .. g0 + cw` into `acc`, with AVX2 + FMA when the CPU has
    /// them (detected at run time) and portable code otherwise; both give the same result
    /// up to float rounding.
    fn run(&self, g0: usize, cw: usize, acc: &mut ChunkStats) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
        {
            // SAFETY: the CPU supports the features the function is compiled for.
            unsafe { self.run_avx2(g0, cw, acc) };
            return;
        }
        self.body(g0, cw, acc);
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn run_avx2(&self, g0: usize, cw: usize, acc: &mut ChunkStats) {
        self.body(g0, cw, acc);
    }

    #[inline(always)]
    fn body(&self, g0: usize, cw: usize, acc: &mut ChunkStats) {
        let (k, n) = (self.k, self.gallery.n);
        let mut d2 = [0.0f32; CHUNK];
        for (b, pairs) in self.by_block.iter().enumerate() {
            for &(s, j) in pairs {
                let tj = &self.feats[j * k..(j + 1) * k];
                let d2 = &mut d2[..cw];
                d2.fill(0.0);
                for (f, &tv) in tj.iter().enumerate() {
                    let base = (b * k + f) * n + g0;
                    let row = &self.gallery.data[base..base + cw];
                    for (a, &r) in d2.iter_mut().zip(row) {
                        let e = tv - r;
                        *a += e * e;
                    }
                }
                let mn = &mut acc.min_d2[j * CHUNK..j * CHUNK + cw];
                let sd = &mut acc.shift_d2[s * CHUNK..s * CHUNK + cw];
                for ((mn, sd), &d) in mn.iter_mut().zip(sd.iter_mut()).zip(d2.iter()) {
                    *mn = mn.min(d);
                    *sd += d;
                }
                if self.need_sum_d {
                    let su = &mut acc.sum_d[j * CHUNK..j * CHUNK + cw];
                    su.iter_mut()
                        .zip(d2.iter())
                        .for_each(|(a, &d)| *a += d.sqrt());
                }
            }
        }
    }
}

/// Outcome of an identification.
#[derive(Clone, Debug, PartialEq)]
pub enum Identification {
    /// The probe was rejected (too occluded; step 12): reacquire it.
    Rejected {
        /// Its occlusion percentage.
        occluded_pct: f64,
    },
    /// Gallery indices with scores, best first (ties: lower index first).
    Ranked(Vec<(usize, f64)>),
}

impl Identification {
    /// The ranking, or `None` for a rejected probe.
    pub fn ranking(&self) -> Option<&[(usize, f64)]> {
        match self {
            Identification::Ranked(r) => Some(r),
            Identification::Rejected { .. } => None,
        }
    }

    /// 0-based rank of gallery entry `id` (`None` if rejected).
    pub fn rank_of(&self, id: usize) -> Option<usize> {
        self.ranking()
            .and_then(|r| r.iter().position(|&(g, _)| g == id))
    }
}

/// Gallery indices sorted by descending score (ties: lower index first).
pub fn rank(scores: &[f64]) -> Vec<(usize, f64)> {
    let mut order: Vec<(usize, f64)> = scores.iter().copied().enumerate().collect();
    order.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
    order
}

/// Identifies a probe against the gallery: rejected probes are reported, not ranked.
/// Errors as [`scores`].
pub fn identify(probe: &Probe, gallery: &Gallery, p: &EarParams) -> Result<Identification> {
    if let Some(r) = probe.report.as_ref().filter(|r| r.rejected) {
        return Ok(Identification::Rejected {
            occluded_pct: r.occluded_pct,
        });
    }
    Ok(Identification::Ranked(rank(&scores(probe, gallery, p)?)))
}

/// Identifies an RGB ear crop: [`make_probe`] then [`identify`].
pub fn identify_image(img: &Image<u8>, gallery: &Gallery, p: &EarParams) -> Result<Identification> {
    identify(&make_probe(img, p)?, gallery, p)
}

/// Ranks a whole-ear baseline probe (Fig. 12) against the gallery.
pub fn identify_baseline(
    img: &Image<u8>,
    gallery: &Gallery,
    p: &EarParams,
) -> Result<Identification> {
    let probe = make_baseline_probe(img, p)?;
    let bp = baseline_params(p);
    Ok(Identification::Ranked(rank(&scores(&probe, gallery, &bp)?)))
}

/// Cumulative match characteristic: `cmc[r - 1]` is the fraction of accepted probes whose
/// true identity is within the top `r`. `ranks` holds each probe's 0-based rank of the true
/// identity, `None` for a rejected probe (excluded: neither a success nor a failure).
///
/// Errors: `max_rank == 0`, no accepted probe.
pub fn cmc(ranks: &[Option<usize>], max_rank: usize) -> Result<Vec<f64>> {
    if max_rank == 0 {
        return Err(Error::invalid("max_rank", "must be >= 1"));
    }
    let accepted: Vec<usize> = ranks.iter().flatten().copied().collect();
    if accepted.is_empty() {
        return Err(Error::Empty("ranks (no accepted probe)"));
    }
    let n = accepted.len() as f64;
    // Probes per rank, then the running sum: O(probes + max_rank).
    let mut curve = wscg_math::alloc::try_vec("max_rank", 0.0f64, max_rank)?;
    for &a in accepted.iter().filter(|&&a| a < max_rank) {
        curve[a] += 1.0;
    }
    let mut total = 0.0;
    for c in &mut curve {
        total += *c;
        *c = total / n;
    }
    Ok(curve)
}
