//! Space-time patches (paper 06, section 3.2): the cube `w_p` of `px x py x pt` pixels centred
//! at `p`, the SSD of RGB between two cubes (eq. 1's `D`, without Wexler's derivative
//! channels, as the paper does), and the valid source centres (cubes inside the video and
//! inside the known region `E`).

use rayon::prelude::*;
use wscg_math::{Error, Result};

use crate::patchmatch::{PatchSpace, P3};
use crate::video::{Mask3, Video};

/// Patch extents in pixels along `x`, `y` and `t` (odd; 5 x 5 x 5 by default, the paper's
/// choice for most videos; 7 x 7 x 5 for larger structures).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PatchSize {
    /// Width (x).
    pub px: usize,
    /// Height (y).
    pub py: usize,
    /// Duration (t, frames).
    pub pt: usize,
}

impl Default for PatchSize {
    fn default() -> Self {
        Self {
            px: 5,
            py: 5,
            pt: 5,
        }
    }
}

impl PatchSize {
    /// Half-sizes `(t, y, x)`.
    pub fn radius(&self) -> [u32; 3] {
        [
            (self.pt / 2) as u32,
            (self.py / 2) as u32,
            (self.px / 2) as u32,
        ]
    }

    /// Voxels per cube.
    pub fn voxels(&self) -> usize {
        self.px * self.py * self.pt
    }

    /// Errors unless every extent is odd and positive.
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [("px", self.px), ("py", self.py), ("pt", self.pt)] {
            if v == 0 || v % 2 == 0 {
                return Err(Error::invalid(
                    "patch",
                    format!("patch extent {name} = {v} must be odd and positive"),
                ));
            }
        }
        Ok(())
    }

    /// Errors unless every extent is odd and positive and the video holds at least one cube.
    pub fn check(&self, dims: [usize; 3]) -> Result<()> {
        self.validate()?;
        if self.pt > dims[0] || self.py > dims[1] || self.px > dims[2] {
            return Err(Error::invalid(
                "patch",
                format!(
                    "a {} x {} x {} (x, y, t) patch does not fit in {} frames of {} x {}",
                    self.px, self.py, self.pt, dims[0], dims[1], dims[2]
                ),
            ));
        }
        Ok(())
    }
}

/// The valid source centres of a video level: points `p` whose cube lies inside the video
/// and contains no hole pixel. Computed as the erosion of `E` by the cube: a separable
/// running count along `x` and `y` per frame, then an AND over the `pt` frames.
pub fn valid_sources(hole: &Mask3, patch: PatchSize) -> Mask3 {
    let [f, h, w] = hole.dims();
    let [rt, ry, rx] = patch.radius().map(|r| r as usize);
    // Per frame: centres whose py x px rectangle is inside the frame and hole-free.
    let frames: Vec<Vec<u64>> = (0..f)
        .into_par_iter()
        .map(|t| {
            let base = t * h * w;
            let mut rows = vec![false; h * w];
            // Known pixels in a run ending at x (then at y): one buffer per frame.
            let mut ok = vec![0u32; w.max(h)];
            for y in 0..h {
                let mut run = 0usize;
                for (x, o) in ok[..w].iter_mut().enumerate() {
                    run = if hole.contains_index(base + y * w + x) {
                        0
                    } else {
                        run + 1
                    };
                    *o = run as u32;
                }
                for x in rx..w.saturating_sub(rx) {
                    rows[y * w + x] = ok[x + rx] as usize > 2 * rx;
                }
            }
            // One bit per pixel: the per-frame sets stay 1/8 of a frame of bytes.
            let mut bits = vec![0u64; (h * w).div_ceil(64)];
            for x in rx..w.saturating_sub(rx) {
                let mut run = 0usize;
                for (y, o) in ok[..h].iter_mut().enumerate() {
                    run = if rows[y * w + x] { run + 1 } else { 0 };
                    *o = run as u32;
                }
                for y in ry..h.saturating_sub(ry) {
                    if ok[y + ry] as usize > 2 * ry {
                        let i = y * w + x;
                        bits[i >> 6] |= 1 << (i & 63);
                    }
                }
            }
            bits
        })
        .collect();
    let mut m = Mask3::empty(f, h, w);
    let bit = |s: usize, i: usize| frames[s][i >> 6] >> (i & 63) & 1 == 1;
    for t in rt..f.saturating_sub(rt) {
        for i in 0..h * w {
            if (t - rt..=t + rt).all(|s| bit(s, i)) {
                m.insert_index(t * h * w + i);
            }
        }
    }
    m
}

/// The cubes of one video level as a [`PatchSpace`]: `D` is the mean over the compared
/// voxels of the squared RGB difference (a target cube that sticks out of the video is
/// clipped and normalised by its in-video voxel count, a case the paper does not treat).
/// Voxels in `ignore` (hole pixels not yet visited in the first pass from a random start)
/// take no part.
pub struct Cubes<'a> {
    /// The current colours (hole pixels hold their current estimates).
    pub video: &'a Video,
    /// Valid source centres.
    pub sources: &'a Mask3,
    /// Patch extents.
    pub patch: PatchSize,
    /// Voxels left out of the comparison.
    pub ignore: Option<&'a Mask3>,
}

impl<'a> Cubes<'a> {
    /// The cubes of `video` compared over all their voxels.
    pub fn new(video: &'a Video, sources: &'a Mask3, patch: PatchSize) -> Self {
        Self {
            video,
            sources,
            patch,
            ignore: None,
        }
    }

    /// `D(w_t, w_s)` with early exit: once the partial sum proves `D >= bound`, returns it.
    pub fn ssd(&self, t: P3, s: P3, bound: f32) -> f32 {
        let v = self.video;
        let [rt, ry, rx] = self.patch.radius().map(|r| r as i64);
        let (f, h, w, c) = (v.frames as i64, v.height as i64, v.width as i64, v.channels);
        let (t0, t1) = ((t[0] as i64 - rt).max(0), (t[0] as i64 + rt).min(f - 1));
        let (y0, y1) = ((t[1] as i64 - ry).max(0), (t[1] as i64 + ry).min(h - 1));
        let (x0, x1) = ((t[2] as i64 - rx).max(0), (t[2] as i64 + rx).min(w - 1));
        let possible = ((t1 - t0 + 1) * (y1 - y0 + 1) * (x1 - x0 + 1)) as f32;
        let limit = bound * possible;
        let run = (x1 - x0 + 1) as usize * c;
        let (dt, dy, dx) = (
            s[0] as i64 - t[0] as i64,
            s[1] as i64 - t[1] as i64,
            s[2] as i64 - t[2] as i64,
        );
        let mut sum = 0u64;
        let mut count = 0usize;
        for tt in t0..=t1 {
            for yy in y0..=y1 {
                let a = v.offset([tt as u32, yy as u32, x0 as u32]);
                let b = v.offset([(tt + dt) as u32, (yy + dy) as u32, (x0 + dx) as u32]);
                let (ra, rb) = (&v.data[a..a + run], &v.data[b..b + run]);
                match self.ignore {
                    None => {
                        sum += row_ssd(ra, rb);
                        count += (x1 - x0 + 1) as usize;
                    }
                    Some(ig) => {
                        for k in 0..=(x1 - x0) as usize {
                            if ig.contains([tt as u32, yy as u32, x0 as u32 + k as u32]) {
                                continue;
                            }
                            sum += row_ssd(&ra[k * c..(k + 1) * c], &rb[k * c..(k + 1) * c]);
                            count += 1;
                        }
                    }
                }
            }
            if sum as f32 >= limit {
                return sum as f32 / possible;
            }
        }
        if count == 0 {
            return 0.0;
        }
        sum as f32 / count as f32
    }
}

/// Sum of squared byte differences of two equal-length runs (widened before squaring).
#[inline]
pub fn row_ssd(a: &[u8], b: &[u8]) -> u64 {
    a.iter()
        .zip(b)
        .map(|(&x, &y)| {
            let d = x as i32 - y as i32;
            (d * d) as u32
        })
        .sum::<u32>() as u64
}

impl PatchSpace for Cubes<'_> {
    fn dims(&self) -> [usize; 3] {
        self.video.dims()
    }
    fn is_source(&self, s: P3) -> bool {
        self.sources.contains(s)
    }
    fn distance(&self, t: P3, s: P3, bound: f32) -> f32 {
        self.ssd(t, s, bound)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sources_are_hole_free_cubes_inside_the_video() {
        let (f, h, w) = (7, 9, 11);
        let hole = Mask3::from_fn(f, h, w, |t, y, x| t == 3 && y == 4 && x == 5);
        let p = PatchSize {
            px: 3,
            py: 5,
            pt: 3,
        };
        let src = valid_sources(&hole, p);
        for t in 0..f {
            for y in 0..h {
                for x in 0..w {
                    let inside = t >= 1 && t + 1 < f && y >= 2 && y + 2 < h && x >= 1 && x + 1 < w;
                    let touches = t.abs_diff(3) <= 1 && y.abs_diff(4) <= 2 && x.abs_diff(5) <= 1;
                    assert_eq!(
                        src.contains([t as u32, y as u32, x as u32]),
                        inside && !touches
                    );
                }
            }
        }
    }

    #[test]
    fn ssd_is_the_mean_squared_difference_with_clipping() {
        let (f, h, w) = (5, 6, 7);
        let data: Vec<u8> = (0..f * h * w * 3).map(|i| (i * 7 % 251) as u8).collect();
        let v = Video::new(f, h, w, 3, data).unwrap();
        let hole = Mask3::empty(f, h, w);
        let p = PatchSize {
            px: 3,
            py: 3,
            pt: 3,
        };
        let src = valid_sources(&hole, p);
        let cubes = Cubes::new(&v, &src, p);
        let brute = |t: [i64; 3], s: [i64; 3]| {
            let (mut sum, mut n) = (0.0f64, 0.0f64);
            for a in -1..=1 {
                for b in -1..=1 {
                    for c in -1..=1 {
                        let q = [t[0] + a, t[1] + b, t[2] + c];
                        if q[0] < 0
                            || q[1] < 0
                            || q[2] < 0
                            || q[0] >= f as i64
                            || q[1] >= h as i64
                            || q[2] >= w as i64
                        {
                            continue;
                        }
                        let r = [s[0] + a, s[1] + b, s[2] + c];
                        let (x, y) = (
                            v.pixel([q[0] as u32, q[1] as u32, q[2] as u32]),
                            v.pixel([r[0] as u32, r[1] as u32, r[2] as u32]),
                        );
                        sum += x
                            .iter()
                            .zip(y)
                            .map(|(&i, &j)| (i as f64 - j as f64).powi(2))
                            .sum::<f64>();
                        n += 1.0;
                    }
                }
            }
            sum / n
        };
        for (t, s) in [
            ([2, 3, 3], [1, 1, 1]),
            ([0, 0, 0], [3, 4, 5]),
            ([4, 5, 6], [2, 2, 2]),
        ] {
            let d = cubes.ssd(t, s, f32::INFINITY);
            let want = brute(t.map(|v| v as i64), s.map(|v| v as i64));
            assert!(
                (d as f64 - want).abs() < 1e-3 * want.max(1.0),
                "{t:?} {s:?}: {d} vs {want}"
            );
            // Early exit returns a value at or above the bound.
            assert!(cubes.ssd(t, s, d / 4.0) >= d / 4.0);
        }
        assert_eq!(cubes.ssd([2, 2, 2], [2, 2, 2], f32::INFINITY), 0.0);
    }
}
