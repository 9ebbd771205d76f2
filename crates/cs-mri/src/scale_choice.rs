//! Choosing the number of UDCT scales `J` from the measured data, by hold-out validation.
//!
//! The paper fixes the UDCT configuration per image class (section 4: one scale with 12
//! directional bands for the brain images, three scales for the water phantom). The best `J`
//! depends on the image: more scales help natural images with smooth regions and textures,
//! one scale helps images whose energy sits in a few sharp harmonics. This module chooses `J`
//! without a reference image:
//!
//! 1. The sampled positions that lie outside the fully sampled region are eligible for hold
//!    out (held-out samples inside it would measure errors that the acquisition never
//!    makes). Each of `folds` disjoint sets of `holdout` times the number of samples is
//!    made of clusters: the eligible samples within `cluster` (k-space positions, wrapped)
//!    of a seed drawn at random, seeds drawn until the set is full. A cluster leaves a gap
//!    that the prior must fill from samples farther away, as it fills the mask's own gaps;
//!    an isolated held-out sample is pinned down by its neighbours (the spectrum of an image
//!    of finite extent is smooth), so its error hardly depends on the prior. Single samples
//!    (`cluster = 0`) were measured to prefer two scales on diamond lattices under
//!    pseudo-radial masks, 0.7 to 1.0 dB below one scale; clusters of radius 2 chose within
//!    0.15 dB of the best `J` on every image tried (photographs, Shepp-Logan rasters and
//!    lattices under Cartesian and pseudo-radial masks).
//! 2. For each candidate `J` and fold, C-SALSA reconstructs from the samples that remain (the
//!    noise radius scaled by the square root of the fraction kept), and the squared errors of
//!    its Fourier values at the held-out positions are summed with the weight `(1 - d) / d`,
//!    where `d` is the sampling density of the sample's ring of radial frequency. The weight
//!    turns the hold-out error into an estimate of the error over the *unmeasured* positions
//!    of its ring (`(1 - d) / d` unmeasured positions per measured one), which by Parseval is
//!    the image's squared error.
//! 3. The `J` with the smallest summed score over the folds wins; the caller then
//!    reconstructs from all samples with it.
//!
//! The threshold `tau0` is kept as given: scoring `J` and `tau0` jointly was measured to pick
//! a smaller `tau0` than the best one on piecewise-constant images (0.39 dB below the best
//! on a Shepp-Logan raster at 256 x 256), while the ranking of `J` at a fixed `tau0` was
//! stable. The cost is `folds x candidates` reconstructions from about 95 % of the samples
//! (9 with the defaults) before the final one.

use num_complex::Complex64;
use wscg_math::{rng, Error, Result};

use crate::csalsa::{reconstruct, CsalsaParams, Regularizer};
use crate::fourier::{signed_frequency, Fourier};
use crate::kspace::KSpace;
use crate::sparsifier::UdctSparsifier;
use crate::udct::UdctParams;

/// Sampling density of a ring at or above which it counts as fully sampled.
const FULL: f64 = 0.999;

wscg_math::params! {
    /// Settings of [`choose_udct_scales`].
    #[derive(Clone, Debug, PartialEq)]
    pub struct ScaleChoiceParams {
        /// Candidate numbers of scales `J` (default 1, 2, 3). Candidates the image size does
        /// not allow are skipped; at least one must be possible.
        pub candidates: Vec<usize>,
        /// Disjoint hold-out sets scored per candidate (default 3).
        pub folds: usize,
        /// Fraction of the samples held out per fold (default 0.05).
        pub holdout: f64,
        /// Radius of the held-out clusters in k-space positions (default 2: up to 13
        /// neighbouring samples per cluster; 0: single samples).
        pub cluster: f64,
        /// Seed of the hold-out draw.
        pub seed: u64,
    }
}

impl Default for ScaleChoiceParams {
    fn default() -> Self {
        ScaleChoiceParams {
            candidates: vec![1, 2, 3],
            folds: 3,
            holdout: 0.05,
            cluster: 2.0,
            seed: 0,
        }
    }
}

impl ScaleChoiceParams {
    /// Checks the ranges: at least one candidate, each from 1 to 8; 1 to 20 folds; a
    /// hold-out fraction in `(0, 0.5]` with `folds x holdout <= 1`; a cluster radius from 0
    /// to 16.
    pub fn validate(&self) -> Result<()> {
        if self.candidates.is_empty() || self.candidates.iter().any(|&j| j == 0 || j > 8) {
            return Err(Error::invalid(
                "candidates",
                format!(
                    "{:?}: give at least one number of scales, each from 1 to 8",
                    self.candidates
                ),
            ));
        }
        if !(1..=20).contains(&self.folds) {
            return Err(Error::invalid(
                "folds",
                format!("{} must be from 1 to 20", self.folds),
            ));
        }
        if !(self.holdout > 0.0 && self.holdout <= 0.5) || self.holdout * self.folds as f64 > 1.0 {
            return Err(Error::invalid(
                "holdout",
                format!(
                    "{} must lie in (0, 0.5] with folds x holdout <= 1 ({} folds)",
                    self.holdout, self.folds
                ),
            ));
        }
        if !(0.0..=16.0).contains(&self.cluster) {
            return Err(Error::invalid(
                "cluster",
                format!("{} must be from 0 to 16 k-space positions", self.cluster),
            ));
        }
        Ok(())
    }
}

/// The hold-out score of one candidate.
#[derive(Clone, Debug, PartialEq)]
pub struct ScaleScore {
    /// Number of UDCT scales.
    pub scales: usize,
    /// Weighted squared hold-out error per fold (k-space units squared): an estimate of the
    /// squared error over the unmeasured positions.
    pub fold_errors: Vec<f64>,
}

impl ScaleScore {
    /// The sum over the folds, the quantity minimised.
    pub fn total(&self) -> f64 {
        self.fold_errors.iter().sum()
    }
}

/// The outcome of [`choose_udct_scales`].
#[derive(Clone, Debug, PartialEq)]
pub struct ScaleChoice {
    /// The chosen number of scales.
    pub scales: usize,
    /// The score of every candidate tried, in the order given.
    pub scores: Vec<ScaleScore>,
    /// Samples held out per fold (0 when nothing was eligible and the first candidate was
    /// returned unscored).
    pub held_out: usize,
}

/// Sampling density of each position's ring of radial frequency: the fraction of the ring's
/// positions that are sampled. The ring of `(u, v)` (signed frequencies) is
/// `floor(sqrt((u / rows)^2 + (v / cols)^2) * min(rows, cols))`.
pub fn ring_density(rows: usize, cols: usize, mask: &[bool]) -> Result<Vec<f64>> {
    if mask.len() != rows * cols || mask.is_empty() {
        return Err(Error::ShapeMismatch(format!(
            "the mask has {} values, not {rows} x {cols}",
            mask.len()
        )));
    }
    let scale = rows.min(cols) as f64;
    let ring: Vec<usize> = (0..rows * cols)
        .map(|k| {
            let u = signed_frequency(k / cols, rows) as f64 / rows as f64;
            let v = signed_frequency(k % cols, cols) as f64 / cols as f64;
            ((u * u + v * v).sqrt() * scale) as usize
        })
        .collect();
    let n_rings = ring.iter().max().map_or(0, |&r| r + 1);
    let mut count = vec![0usize; n_rings];
    let mut sampled = vec![0usize; n_rings];
    for (&r, &m) in ring.iter().zip(mask) {
        count[r] += 1;
        sampled[r] += usize::from(m);
    }
    Ok(ring
        .iter()
        .map(|&r| sampled[r] as f64 / count[r] as f64)
        .collect())
}

/// The `c.folds` disjoint hold-out sets, each of `round(c.holdout x m)` sampled positions
/// (`m` samples; fewer when the eligible positions run short): the sampled positions whose
/// ring `density` is below 1 are eligible; seeds drawn at random (`c.seed`) among them in
/// turn give each set, round robin, the eligible positions within `c.cluster` of the seed
/// (wrapped around the k-space grid, nearest first, none taken twice) until every set is
/// full. Empty sets when no position is eligible.
pub fn holdout_folds(
    data: &KSpace,
    density: &[f64],
    c: &ScaleChoiceParams,
) -> Result<Vec<Vec<usize>>> {
    c.validate()?;
    let (rows, cols) = data.shape();
    let mut eligible = vec![false; rows * cols];
    let seeds: Vec<usize> = data
        .sampled()
        .iter()
        .copied()
        .filter(|&k| density.get(k).is_some_and(|&d| d < FULL))
        .collect();
    seeds.iter().for_each(|&k| eligible[k] = true);
    let per_fold =
        ((c.holdout * data.sampled().len() as f64).round() as usize).min(seeds.len() / c.folds);
    let offsets = disc_offsets(c.cluster);
    let order = rng::permutation(c.seed, seeds.len())?;
    let mut folds = vec![Vec::with_capacity(per_fold); c.folds];
    let mut fold = 0;
    for &i in &order {
        if folds.iter().all(|f| f.len() >= per_fold) {
            break;
        }
        if !eligible[seeds[i]] {
            continue;
        }
        let (r0, c0) = (seeds[i] / cols, seeds[i] % cols);
        while folds[fold].len() >= per_fold {
            fold = (fold + 1) % c.folds;
        }
        for &(dr, dc) in &offsets {
            let r = (r0 as isize + dr).rem_euclid(rows as isize) as usize;
            let k = r * cols + (c0 as isize + dc).rem_euclid(cols as isize) as usize;
            if eligible[k] && folds[fold].len() < per_fold {
                eligible[k] = false;
                folds[fold].push(k);
            }
        }
        fold = (fold + 1) % c.folds;
    }
    Ok(folds)
}

/// The integer offsets within `radius` of the origin, nearest first (the origin leads).
fn disc_offsets(radius: f64) -> Vec<(isize, isize)> {
    let reach = radius.floor() as isize;
    let mut offsets: Vec<(isize, isize)> = (-reach..=reach)
        .flat_map(|dr| (-reach..=reach).map(move |dc| (dr, dc)))
        .filter(|&(dr, dc)| ((dr * dr + dc * dc) as f64) <= radius * radius)
        .collect();
    offsets.sort_by_key(|&(dr, dc)| (dr * dr + dc * dc, dr, dc));
    offsets
}

/// The hold-out score of one reconstruction: `sum |X_k - y_k|^2 (1 - d_k) / d_k` over the
/// held-out positions `k`, with `X` the reconstruction's spectrum, `y` the measured data and
/// `d_k` the ring density. Held-out uniformly among the eligible samples, it estimates the
/// squared error over the unmeasured positions of their rings (scaled by the fraction of the
/// eligible samples held out).
pub fn weighted_holdout_error(
    spectrum: &[Complex64],
    data: &KSpace,
    held: &[usize],
    density: &[f64],
) -> f64 {
    held.iter()
        .map(|&k| {
            let d = density[k];
            (spectrum[k] - data.data()[k]).norm_sqr() * (1.0 - d) / d
        })
        .sum()
}

/// Chooses the number of UDCT scales for `data` by hold-out validation (see the module
/// documentation). `p` are the C-SALSA settings of the final reconstruction (its `tau0`,
/// iteration cap, noise radius ...), `udct` the transform's configuration whose first
/// scale's wedge counts are repeated for every scale of a candidate.
///
/// When no sampled position lies outside the fully sampled rings (nothing is unmeasured
/// there), the first candidate the size allows is returned unscored.
///
/// Errors: invalid settings; no candidate the image size allows (the UDCT's own error for
/// the smallest one is quoted).
pub fn choose_udct_scales(
    data: &KSpace,
    reg: Regularizer,
    p: &CsalsaParams,
    udct: &UdctParams,
    c: &ScaleChoiceParams,
) -> Result<ScaleChoice> {
    c.validate()?;
    p.validate()?;
    udct.validate()?;
    let (rows, cols) = data.shape();
    let wedge = udct.wedges[0];
    let mut priors = Vec::new();
    let mut first_error = None;
    for &j in &c.candidates {
        let cfg = UdctParams {
            wedges: vec![wedge; j],
            ..udct.clone()
        };
        match UdctSparsifier::new(rows, cols, &cfg) {
            Ok(s) => priors.push((j, s)),
            Err(e) => {
                log::debug!("{j} UDCT scales are not possible at {rows} x {cols}: {e}");
                first_error.get_or_insert(e);
            }
        }
    }
    if priors.is_empty() {
        return Err(Error::invalid(
            "candidates",
            format!(
                "none of {:?} scales is possible at {rows} x {cols}: {}",
                c.candidates,
                first_error.map_or_else(String::new, |e| e.to_string())
            ),
        ));
    }
    let density = ring_density(rows, cols, data.mask())?;
    let folds = holdout_folds(data, &density, c)?;
    let per_fold = folds.first().map_or(0, Vec::len);
    if per_fold == 0 {
        return Ok(ScaleChoice {
            scales: priors[0].0,
            scores: Vec::new(),
            held_out: 0,
        });
    }
    let kept = (data.sampled().len() - per_fold) as f64 / data.sampled().len() as f64;
    let fold_p = p
        .clone()
        .epsilon(p.epsilon * kept.sqrt())
        .record_history(false);
    let fourier = Fourier::new(rows, cols)?;
    let fold_data: Vec<KSpace> = folds
        .iter()
        .map(|held| {
            let mut mask = data.mask().to_vec();
            held.iter().for_each(|&k| mask[k] = false);
            KSpace::new(rows, cols, data.data().to_vec(), mask)
        })
        .collect::<Result<_>>()?;
    let mut scores = Vec::with_capacity(priors.len());
    for (j, psi) in &priors {
        let mut fold_errors = Vec::with_capacity(folds.len());
        for (held, train) in folds.iter().zip(&fold_data) {
            let mut spectrum = reconstruct(train, psi, reg, &fold_p)?.image;
            fourier.forward(&mut spectrum);
            fold_errors.push(weighted_holdout_error(&spectrum, data, held, &density));
        }
        log::debug!("{j} UDCT scales: hold-out scores {fold_errors:?}");
        scores.push(ScaleScore {
            scales: *j,
            fold_errors,
        });
    }
    let best = scores
        .iter()
        .min_by(|a, b| a.total().total_cmp(&b.total()))
        .map(|s| s.scales)
        .unwrap_or(priors[0].0);
    log::info!("hold-out validation chose {best} UDCT scales");
    Ok(ScaleChoice {
        scales: best,
        scores,
        held_out: per_fold,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::masks;
    use crate::phantom;

    #[test]
    fn ring_density_counts_the_sampled_fraction_of_each_ring() {
        let (rows, cols) = (16, 16);
        // Sample every position with |u| <= 2 (rows 0, 1, 2, 14, 15) and nothing else.
        let mask: Vec<bool> = (0..rows * cols)
            .map(|k| signed_frequency(k / cols, rows).abs() <= 2)
            .collect();
        let d = ring_density(rows, cols, &mask).unwrap();
        // DC and ring 1 ((0, +-1), (+-1, 0)) and (1, 1) are sampled in full.
        assert_eq!(d[0], 1.0);
        assert_eq!(d[1], 1.0);
        // A high ring contains no sampled position.
        let corner = 8 * cols + 8;
        assert_eq!(d[corner], 0.0);
        // Every density lies in [0, 1] and the sampled mass adds up.
        assert!(d.iter().all(|&v| (0.0..=1.0).contains(&v)));
        assert!(ring_density(4, 4, &[true; 3]).is_err());
    }

    #[test]
    fn folds_are_disjoint_sampled_and_outside_the_fully_sampled_rings() {
        let n = 64;
        let mask = masks::cartesian(n, n, 0.4, 0.08, 4).unwrap();
        let data = KSpace::new(n, n, phantom::shepp_logan_kspace(n).unwrap(), mask).unwrap();
        let density = ring_density(n, n, data.mask()).unwrap();
        assert!(density.contains(&1.0), "the mask has a full centre");
        let c = ScaleChoiceParams::default().folds(3).seed(9);
        let folds = holdout_folds(&data, &density, &c).unwrap();
        let expected = (0.05 * data.sampled().len() as f64).round() as usize;
        let mut seen = std::collections::HashSet::new();
        for fold in &folds {
            assert_eq!(fold.len(), expected);
            for &k in fold {
                assert!(data.mask()[k] && density[k] < 1.0, "position {k}");
                assert!(seen.insert(k), "position {k} in two folds");
            }
        }
        // Another seed, other sets.
        let other = holdout_folds(&data, &density, &c.clone().seed(10)).unwrap();
        assert_ne!(folds, other);
    }

    /// Wrapped distance between two positions of an `n x n` grid.
    fn grid_distance(n: usize, a: usize, b: usize) -> f64 {
        let d = |x: usize, y: usize| {
            let t = x.abs_diff(y);
            t.min(n - t) as f64
        };
        d(a / n, b / n).hypot(d(a % n, b % n))
    }

    #[test]
    fn folds_are_made_of_clusters_and_radius_zero_holds_out_single_samples() {
        let n = 64;
        let mask = masks::cartesian(n, n, 0.4, 0.08, 4).unwrap();
        let data = KSpace::new(n, n, phantom::shepp_logan_kspace(n).unwrap(), mask).unwrap();
        let density = ring_density(n, n, data.mask()).unwrap();
        // Share of held-out samples with another sample of their own fold within `r`.
        let neighboured = |folds: &[Vec<usize>], r: f64| {
            let (mut with, mut all) = (0, 0);
            for fold in folds {
                for &a in fold {
                    all += 1;
                    with +=
                        usize::from(fold.iter().any(|&b| b != a && grid_distance(n, a, b) <= r));
                }
            }
            with as f64 / all as f64
        };
        let c = ScaleChoiceParams::default().seed(5);
        let clustered = holdout_folds(&data, &density, &c).unwrap();
        let single = holdout_folds(&data, &density, &c.clone().cluster(0.0)).unwrap();
        assert_eq!(clustered[0].len(), single[0].len());
        let (a, b) = (neighboured(&clustered, 2.0), neighboured(&single, 2.0));
        // A cluster's members lie within its radius of the seed, so within twice the radius
        // of each other; clusters of one sample have neighbours only by chance (the mask
        // keeps 40 % of the positions, a fold 5 % of those).
        assert!(a > 0.9, "clustered: {a}");
        assert!(b < 0.5, "single samples: {b}");
        // The offsets of a radius-2 disc: 13, nearest first.
        let d = disc_offsets(2.0);
        assert_eq!(d.len(), 13);
        assert_eq!(d[0], (0, 0));
        assert!(d.windows(2).all(|w| {
            let r = |(x, y): (isize, isize)| x * x + y * y;
            r(w[0]) <= r(w[1])
        }));
        assert_eq!(disc_offsets(0.0), vec![(0, 0)]);
    }

    /// Holding out every eligible sample, the weights turn a unit error at every position
    /// into the count of unmeasured positions outside the fully sampled rings: the estimate
    /// of the unmeasured error is exact for an error that is constant per ring.
    #[test]
    fn weights_count_the_unmeasured_positions_of_each_ring() {
        let n = 48;
        let mask = masks::cartesian(n, n, 0.35, 0.1, 2).unwrap();
        let data = KSpace::new(n, n, phantom::shepp_logan_kspace(n).unwrap(), mask).unwrap();
        let density = ring_density(n, n, data.mask()).unwrap();
        let held: Vec<usize> = data
            .sampled()
            .iter()
            .copied()
            .filter(|&k| density[k] < 1.0)
            .collect();
        let unmeasured = (0..n * n)
            .filter(|&k| !data.mask()[k] && density[k] > 0.0)
            .count();
        let spectrum: Vec<Complex64> = data
            .data()
            .iter()
            .map(|y| y + Complex64::new(0.6, 0.8))
            .collect();
        let score = weighted_holdout_error(&spectrum, &data, &held, &density);
        assert!(
            (score - unmeasured as f64).abs() < 1e-6 * unmeasured as f64,
            "{score} vs {unmeasured}"
        );
        // Without the weights the sum would be the number of held-out samples.
        assert_ne!(held.len(), unmeasured);
    }

    #[test]
    fn scores_are_finite_and_the_smallest_total_wins() {
        let n = 64;
        let mask = masks::cartesian(n, n, 0.4, 0.08, 4).unwrap();
        let data = KSpace::new(n, n, phantom::shepp_logan_kspace(n).unwrap(), mask).unwrap();
        let c = ScaleChoiceParams::default().candidates(vec![1, 2]).folds(2);
        let p = CsalsaParams::default().max_iter(15);
        let choice = choose_udct_scales(
            &data,
            Regularizer::default(),
            &p,
            &UdctParams::default(),
            &c,
        )
        .unwrap();
        assert_eq!(choice.scores.len(), 2);
        let expected = (0.05 * data.sampled().len() as f64).round() as usize;
        assert_eq!(choice.held_out, expected);
        for s in &choice.scores {
            assert_eq!(s.fold_errors.len(), 2);
            assert!(s.fold_errors.iter().all(|e| e.is_finite() && *e > 0.0));
        }
        let min = choice
            .scores
            .iter()
            .map(ScaleScore::total)
            .fold(f64::INFINITY, f64::min);
        let chosen = choice.scores.iter().find(|s| s.scales == choice.scales);
        assert_eq!(chosen.unwrap().total(), min);
    }

    #[test]
    fn fully_sampled_data_returns_the_first_possible_candidate_unscored() {
        let n = 32;
        let data = KSpace::new(
            n,
            n,
            phantom::shepp_logan_kspace(n).unwrap(),
            vec![true; n * n],
        )
        .unwrap();
        let c = ScaleChoiceParams::default().candidates(vec![2, 1]);
        let choice = choose_udct_scales(
            &data,
            Regularizer::default(),
            &CsalsaParams::default(),
            &UdctParams::default(),
            &c,
        )
        .unwrap();
        assert_eq!((choice.scales, choice.held_out), (2, 0));
        assert!(choice.scores.is_empty());
    }

    #[test]
    fn bad_settings_are_refused_by_name() {
        let n = 32;
        let data = KSpace::new(
            n,
            n,
            phantom::shepp_logan_kspace(n).unwrap(),
            masks::cartesian(n, n, 0.4, 0.08, 1).unwrap(),
        )
        .unwrap();
        let run = |c: ScaleChoiceParams| {
            choose_udct_scales(
                &data,
                Regularizer::default(),
                &CsalsaParams::default(),
                &UdctParams::default(),
                &c,
            )
            .unwrap_err()
            .to_string()
        };
        let d = ScaleChoiceParams::default();
        assert!(run(d.clone().candidates(vec![])).contains("candidates"));
        assert!(run(d.clone().candidates(vec![0])).contains("candidates"));
        assert!(run(d.clone().folds(0)).contains("folds"));
        assert!(run(d.clone().holdout(0.0)).contains("holdout"));
        assert!(run(d.clone().holdout(f64::NAN)).contains("holdout"));
        assert!(run(d.clone().folds(4).holdout(0.3)).contains("holdout"));
        assert!(run(d.clone().cluster(-1.0)).contains("cluster"));
        assert!(run(d.clone().cluster(f64::NAN)).contains("cluster"));
        // Eight scales are not possible on a 32 x 32 grid.
        assert!(run(d.candidates(vec![8])).contains("candidates"));
    }
}
