//! Spatial pyramids of a video and its hole (paper 06, Fig. 3 stage 1.1 and section 3.2):
//! the temporal resolution is kept, each level is an integer spatial down-scaling.
//!
//! The "any" rule: a coarse pixel is a hole when any fine pixel of its block is, and its
//! colour is the mean of the block's known fine pixels. So the coarse known region is fully
//! known, and every fine hole pixel has a hole parent (which the level transfer and the
//! up-scaling of the match list rely on).

use rayon::prelude::*;

use crate::video::{Mask3, Video};

/// The video and hole down-scaled by the integer `factor` (block means of known pixels, "any"
/// rule for the hole). Partial blocks at the right and bottom edges count as blocks.
pub fn downscale(video: &Video, hole: &Mask3, factor: usize) -> (Video, Mask3) {
    let factor = factor.max(1);
    if factor == 1 {
        return (video.clone(), hole.clone());
    }
    let (f, h, w, c) = (video.frames, video.height, video.width, video.channels);
    let (ch, cw) = (h.div_ceil(factor), w.div_ceil(factor));
    let mut data = vec![0u8; f * ch * cw * c];
    data.par_chunks_mut(ch * cw * c)
        .enumerate()
        .for_each(|(t, frame)| {
            for cy in 0..ch {
                for cx in 0..cw {
                    let mut sum = [0u32; 3];
                    let mut n = 0u32;
                    for y in cy * factor..((cy + 1) * factor).min(h) {
                        for x in cx * factor..((cx + 1) * factor).min(w) {
                            let p = [t as u32, y as u32, x as u32];
                            if hole.contains(p) {
                                continue;
                            }
                            for (s, &v) in sum.iter_mut().zip(video.pixel(p)) {
                                *s += v as u32;
                            }
                            n += 1;
                        }
                    }
                    let px = &mut frame[(cy * cw + cx) * c..(cy * cw + cx + 1) * c];
                    for (d, s) in px.iter_mut().zip(sum) {
                        *d = (s + n / 2).checked_div(n).unwrap_or(0) as u8;
                    }
                }
            }
        });
    let v = Video {
        frames: f,
        height: ch,
        width: cw,
        channels: c,
        data,
    };
    (v, downscale_mask(hole, factor))
}

/// The hole alone down-scaled by `factor` with the "any" rule.
pub fn downscale_mask(hole: &Mask3, factor: usize) -> Mask3 {
    let factor = factor.max(1);
    let (f, h, w) = (hole.frames, hole.height, hole.width);
    let (ch, cw) = (h.div_ceil(factor), w.div_ceil(factor));
    let mut m = Mask3::empty(f, ch, cw);
    for p in hole.iter_points() {
        m.insert([p[0], p[1] / factor as u32, p[2] / factor as u32]);
    }
    m
}

/// The working-resolution factor of stage 1: `max(1, round(width / target_width))`
/// (1920 -> 480 for the paper's 480 x 270).
pub fn working_factor(width: usize, target_width: usize) -> usize {
    ((width as f64 / target_width.max(1) as f64).round() as usize).max(1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn any_rule_and_known_means() {
        // 1 frame of 4 x 4 grey; hole at (1, 1) only.
        let data: Vec<u8> = (0..16).map(|i| (i * 10) as u8).collect();
        let v = Video::new(1, 4, 4, 1, data).unwrap();
        let hole = Mask3::from_fn(1, 4, 4, |_, y, x| y == 1 && x == 1);
        let (c, m) = downscale(&v, &hole, 2);
        assert_eq!((c.height, c.width), (2, 2));
        // Block (0, 0): known 0, 10, 40 (50 is the hole) -> mean 16.7 -> 17, and a hole.
        assert_eq!(c.data[0], 17);
        assert!(m.contains([0, 0, 0]));
        assert!(!m.contains([0, 0, 1]));
        // Block (1, 1): 100, 110, 140, 150 -> 125.
        assert_eq!(c.data[3], 125);
        assert_eq!(downscale_mask(&hole, 2), m);
        assert_eq!(working_factor(1920, 480), 4);
        assert_eq!(working_factor(300, 480), 1);
    }
}
