//! Editing of a label volume after the random walks: the local 3D "grow" brush of paper
//! section 2.6 (stage 3 of the workflow), the removal of small label islands (an optional
//! clean-up, not in the paper), and the seed strokes files of the command line
//! ([`read_strokes`]: the seed strokes a user paints).

use std::path::Path;

use rayon::prelude::*;
use wscg_math::{Error, Result, Volume};

use crate::graph::intensity_map;
use crate::params::{IntensityNorm, RandomWalkParams};
use crate::preprocess::threshold;

/// Weights of the grow brush's affinity `W_ij` (section 2.6; the paper names the three
/// terms, not their weights, which are ours).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GrowWeights {
    /// Weight of `ρ_j`, the fraction of `p_j`'s 26 neighbours carrying the active label (0.5).
    pub ratio: f64,
    /// Weight of the intensity similarity `1 − min(1, |g_i − g_j| / gradient_scale)` (0.3).
    pub gradient: f64,
    /// Weight of the closeness to the brush centre `1 − |p_j − c| / r` (0.2).
    pub distance: f64,
    /// Normalised-intensity difference at which the similarity term vanishes (0.05).
    pub gradient_scale: f64,
    /// Threshold `τ` on `W_ij` (0.5).
    pub tau: f64,
    /// Largest number of sweeps (10).
    pub max_sweeps: usize,
}

impl Default for GrowWeights {
    fn default() -> Self {
        Self {
            ratio: 0.5,
            gradient: 0.3,
            distance: 0.2,
            gradient_scale: 0.05,
            tau: 0.5,
            max_sweeps: 10,
        }
    }
}

/// Offsets of the 26-neighbourhood.
fn offsets26() -> impl Iterator<Item = [i64; 3]> {
    (-1..=1i64).flat_map(|z| {
        (-1..=1i64).flat_map(move |y| {
            (-1..=1i64)
                .filter(move |&x| (x, y, z) != (0, 0, 0))
                .map(move |x| [x, y, z])
        })
    })
}

/// The local grow brush (paper section 2.6): inside the ball of `radius` voxels around
/// `center` (voxel coordinates x, y, z), a bone voxel `p_j` (`ct >= p.t_bone`) takes the
/// `active` label from a 26-neighbour `p_i` that carries it when
/// `W_ij = ratio·ρ_j + gradient·(1 − min(1, |g_i − g_j|/scale)) + distance·(1 − |p_j − c|/r)`
/// exceeds `τ` (`g` normalised as for the graph, `p.norm`). Sweeps read the labels of the
/// previous sweep and repeat until nothing changes or `max_sweeps`. Returns the number of
/// voxels that changed label.
///
/// Errors: shape mismatch, label 0, a radius that is not positive and finite, a non-finite
/// centre, invalid parameters.
pub fn local_grow_edit(
    labels: &mut Volume<u16>,
    ct: &Volume<f32>,
    p: &RandomWalkParams,
    center: [f64; 3],
    radius: f64,
    active: u16,
    w: &GrowWeights,
) -> Result<usize> {
    p.validate()?;
    if labels.dims() != ct.dims() {
        return Err(Error::ShapeMismatch(format!(
            "labels are {:?}, the CT {:?}",
            labels.dims(),
            ct.dims()
        )));
    }
    if active == 0 {
        return Err(Error::invalid("active", "the brush's label must be >= 1"));
    }
    if !(radius.is_finite() && radius > 0.0) {
        return Err(Error::invalid(
            "radius",
            format!("must be > 0, got {radius}"),
        ));
    }
    if center.iter().any(|c| !c.is_finite()) {
        return Err(Error::invalid("center", "must be finite"));
    }
    let dims = ct.dims();
    let is_bone = |i: usize| f64::from(ct.data()[i]) >= p.t_bone;
    // The whole-volume mask only matters for the min-max normalisation; a brush stroke
    // otherwise touches just the voxels of its ball.
    let mask = match p.norm {
        IntensityNorm::MinMax => threshold(ct, p.t_bone),
        _ => Vec::new(),
    };
    let g = intensity_map(ct, &mask, p.norm);
    // The brush's voxels (bounding box of the ball, clipped to the volume).
    let lo: Vec<i64> = (0..3)
        .map(|a| ((center[a] - radius).floor() as i64).max(0))
        .collect();
    let hi: Vec<i64> = (0..3)
        .map(|a| ((center[a] + radius).ceil() as i64).min(dims[a] as i64 - 1))
        .collect();
    let idx = |c: [i64; 3]| c[0] as usize + dims[0] * (c[1] as usize + dims[1] * c[2] as usize);
    let inside = |c: [i64; 3]| (0..3).all(|a| c[a] >= 0 && c[a] < dims[a] as i64);
    let mut brush = Vec::new();
    for z in lo[2]..=hi[2] {
        for y in lo[1]..=hi[1] {
            for x in lo[0]..=hi[0] {
                let c = [x, y, z];
                let d2: f64 = (0..3).map(|a| (c[a] as f64 - center[a]).powi(2)).sum();
                if d2 <= radius * radius && is_bone(idx(c)) {
                    brush.push((c, d2.sqrt()));
                }
            }
        }
    }
    let offs: Vec<[i64; 3]> = offsets26().collect();
    let mut changed = 0;
    for _ in 0..w.max_sweeps {
        wscg_math::cancel::check()?;
        let cur = labels.data();
        let grow: Vec<usize> = brush
            .par_iter()
            .filter_map(|&(c, dist)| {
                let j = idx(c);
                if cur[j] == active {
                    return None;
                }
                let carrying = || {
                    offs.iter()
                        .map(|o| [c[0] + o[0], c[1] + o[1], c[2] + o[2]])
                        .filter(|&q| inside(q))
                        .map(idx)
                        .filter(|&i| cur[i] == active)
                };
                let rho = carrying().count() as f64 / 26.0;
                let gj = g(ct.data()[j]);
                let near = 1.0 - dist / radius;
                carrying()
                    .any(|i| {
                        let sim = 1.0 - ((g(ct.data()[i]) - gj).abs() / w.gradient_scale).min(1.0);
                        w.ratio * rho + w.gradient * sim + w.distance * near > w.tau
                    })
                    .then_some(j)
            })
            .collect();
        if grow.is_empty() {
            break;
        }
        changed += grow.len();
        let data = labels.data_mut();
        for j in grow {
            data[j] = active;
        }
    }
    Ok(changed)
}

/// Relabels every 6-connected component of a non-zero label that has fewer than
/// `min_voxels` voxels to the most frequent other non-zero label among its 6-neighbours
/// (ties: the lowest); components with no labelled neighbour stay. Returns the number of
/// voxels that changed.
pub fn remove_small_components(labels: &mut Volume<u16>, min_voxels: usize) -> usize {
    let dims = labels.dims();
    let n = labels.len();
    let data = labels.data().to_vec();
    let out = labels.data_mut();
    let mut seen = vec![false; n];
    let mut changed = 0;
    let nbrs = |v: usize| {
        let c = [
            v % dims[0],
            (v / dims[0]) % dims[1],
            v / (dims[0] * dims[1]),
        ];
        let strides = [1, dims[0], dims[0] * dims[1]];
        (0..3).flat_map(move |a| {
            let down = (c[a] > 0).then(|| v - strides[a]);
            let up = (c[a] + 1 < dims[a]).then(|| v + strides[a]);
            down.into_iter().chain(up)
        })
    };
    let mut comp = Vec::new();
    for start in 0..n {
        if seen[start] || data[start] == 0 {
            continue;
        }
        let l = data[start];
        comp.clear();
        comp.push(start);
        seen[start] = true;
        let mut head = 0;
        while head < comp.len() && comp.len() < min_voxels {
            let v = comp[head];
            head += 1;
            for u in nbrs(v) {
                if !seen[u] && data[u] == l {
                    seen[u] = true;
                    comp.push(u);
                }
            }
        }
        if comp.len() >= min_voxels {
            // Large: finish marking it without keeping the voxels.
            while let Some(v) = comp.pop() {
                for u in nbrs(v) {
                    if !seen[u] && data[u] == l {
                        seen[u] = true;
                        comp.push(u);
                    }
                }
            }
            continue;
        }
        let mut votes = std::collections::BTreeMap::<u16, usize>::new();
        for &v in &comp {
            for u in nbrs(v) {
                if data[u] != 0 && data[u] != l {
                    *votes.entry(data[u]).or_default() += 1;
                }
            }
        }
        if let Some((&best, _)) = votes.iter().max_by(|a, b| a.1.cmp(b.1).then(b.0.cmp(a.0))) {
            for &v in &comp {
                out[v] = best;
            }
            changed += comp.len();
        }
    }
    changed
}

/// One JSON stroke.
#[derive(serde::Deserialize)]
struct Stroke {
    label: u16,
    points: Vec<[f64; 3]>,
    #[serde(default = "one")]
    radius: f64,
}

fn one() -> f64 {
    1.0
}

/// Reads a strokes file and paints it into a seed volume of `dims` voxels of `spacing`:
/// JSON `[{"label": k, "points": [[x, y, z], ...], "radius": r}, ...]` (voxel indices;
/// `radius` in voxels, default 1); every voxel centre within `radius` of a point of a stroke
/// gets the stroke's label (later strokes over earlier ones), the others 0.
///
/// Errors: [`Error::Io`] when unreadable; [`Error::InvalidArgument`] naming `strokes` for text
/// that is not such a list, a label of 0, a negative or non-finite radius, a stroke without
/// points, a point outside the volume, or a stroke that covers no voxel centre.
pub fn read_strokes(path: &Path, dims: [usize; 3], spacing: [f64; 3]) -> Result<Volume<u16>> {
    paint_strokes(&wscg_math::error::read_file(path)?, path, dims, spacing)
}

/// [`read_strokes`] of a file held in memory; `origin` names the file in errors.
pub fn paint_strokes(
    bytes: &[u8],
    origin: &Path,
    dims: [usize; 3],
    spacing: [f64; 3],
) -> Result<Volume<u16>> {
    let path = origin;
    let strokes: Vec<Stroke> = serde_json::from_slice(bytes).map_err(|e| {
        Error::invalid(
            "strokes",
            format!("{}: not a JSON list of strokes ({e})", path.display()),
        )
    })?;
    let mut v = Volume::filled(dims, spacing, 0u16)?;
    let d = dims;
    for (n, s) in strokes.iter().enumerate() {
        if s.label == 0 || !(s.radius.is_finite() && s.radius >= 0.0) {
            return Err(Error::invalid(
                "strokes",
                format!("stroke {n}: label must be >= 1 and radius finite and >= 0"),
            ));
        }
        if s.points.is_empty() {
            return Err(Error::invalid(
                "strokes",
                format!(
                    "{}: stroke {n} (label {}) has no points",
                    path.display(),
                    s.label
                ),
            ));
        }
        let mut painted = false;
        for c in &s.points {
            if c.iter().any(|x| !x.is_finite()) {
                return Err(Error::invalid(
                    "strokes",
                    format!("stroke {n}: non-finite point"),
                ));
            }
            if c.iter().zip(d).any(|(&x, n)| x < 0.0 || x > (n - 1) as f64) {
                return Err(Error::invalid(
                    "strokes",
                    format!(
                        "{}: stroke {n} (label {}) has the point {c:?} outside the volume: \
                         points are voxel indices [x, y, z] within [0, {}] x [0, {}] x [0, {}]",
                        path.display(),
                        s.label,
                        d[0] - 1,
                        d[1] - 1,
                        d[2] - 1
                    ),
                ));
            }
            let lo = c.map(|x| (x - s.radius).floor().max(0.0) as usize);
            let hi: Vec<f64> = c.iter().map(|x| (x + s.radius).ceil()).collect();
            for z in lo[2]..=(hi[2].max(0.0) as usize).min(d[2].saturating_sub(1)) {
                for y in lo[1]..=(hi[1].max(0.0) as usize).min(d[1].saturating_sub(1)) {
                    for x in lo[0]..=(hi[0].max(0.0) as usize).min(d[0].saturating_sub(1)) {
                        let r2 = (x as f64 - c[0]).powi(2)
                            + (y as f64 - c[1]).powi(2)
                            + (z as f64 - c[2]).powi(2);
                        if r2 <= s.radius * s.radius {
                            v.set(x, y, z, s.label);
                            painted = true;
                        }
                    }
                }
            }
        }
        if !painted {
            return Err(Error::invalid(
                "strokes",
                format!(
                    "{}: stroke {n} (label {}) covers no voxel centre (radius {} around \
                     non-integer points): give a radius of at least 0.5",
                    path.display(),
                    s.label,
                    s.radius
                ),
            ));
        }
    }
    Ok(v)
}
