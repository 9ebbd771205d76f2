//! Synthetic test videos with exact ground truth (the paper's sequences "Station", "Race to
//! Mars" and "Old town cross" are not distributable). A procedural texture defined at every
//! real coordinate (value noise, oriented lines, bricks) is filmed by a static, panning or
//! zooming camera; an object or a logo covers part of it. Deterministic given the seed.
//!
//! - [`sprite_clip`] (G1): static camera, an opaque disc moving across the scene: every hidden
//!   pixel is visible in other frames.
//! - [`pan_clip`] (G2): the camera pans by a fixed step per frame under a static logo hole.
//! - [`zoom_clip`] (G3): the camera zooms by a fixed factor per frame, a disc hole moves.
//! - [`periodic_clip`] (G4): a static hole on stripes and bricks, permanently hidden: only the
//!   periodicity tells what was there.

use wscg_math::{Error, Result};

use crate::video::{Mask3, Video};

/// A synthetic clip: the clean video, what the camera saw (with the object), and the hole to
/// remove.
#[derive(Clone, Debug)]
pub struct Clip {
    /// Ground truth without the object.
    pub clean: Video,
    /// The input: the clean video with the object (or logo) painted over the hole.
    pub observed: Video,
    /// The hole (the object's pixels).
    pub hole: Mask3,
}

fn hash(seed: u64, a: i64, b: i64) -> f64 {
    let mut z = seed
        ^ (a as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ (b as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64
}

/// Smooth value noise at `(y, x)` with lattice spacing `cell`.
fn value_noise(seed: u64, y: f64, x: f64, cell: f64) -> f64 {
    let (gy, gx) = (y / cell, x / cell);
    let (iy, ix) = (gy.floor(), gx.floor());
    let (fy, fx) = (gy - iy, gx - ix);
    let s = |t: f64| t * t * (3.0 - 2.0 * t);
    let (sy, sx) = (s(fy), s(fx));
    let (iy, ix) = (iy as i64, ix as i64);
    let v00 = hash(seed, iy, ix);
    let v01 = hash(seed, iy, ix + 1);
    let v10 = hash(seed, iy + 1, ix);
    let v11 = hash(seed, iy + 1, ix + 1);
    let top = v00 + (v01 - v00) * sx;
    let bot = v10 + (v11 - v10) * sx;
    top + (bot - top) * sy
}

/// The procedural texture at real coordinates `(y, x)`: RGB in `[0, 255]`. Three octaves of
/// colour noise, thin oriented lines and a brick pattern, so that it has both stochastic
/// texture and salient structure at several scales.
pub fn texture(seed: u64, y: f64, x: f64) -> [f64; 3] {
    let mut rgb = [0.0; 3];
    for (k, v) in rgb.iter_mut().enumerate() {
        let s = seed.wrapping_add(k as u64 * 1013);
        *v = 0.5 * value_noise(s, y, x, 48.0)
            + 0.3 * value_noise(s ^ 7, y, x, 16.0)
            + 0.2 * value_noise(s ^ 13, y, x, 5.0);
    }
    // Oriented lines (30 degrees, period 37 px, 3 px wide).
    let u = x * 0.866 + y * 0.5;
    let line = ((u / 37.0).fract() * 37.0) < 3.0;
    // Bricks: 40 x 18 with a half offset every other row and 3 px mortar.
    let row = (y / 18.0).floor();
    let bx = x + if row as i64 % 2 == 0 { 0.0 } else { 20.0 };
    let mortar = (y - row * 18.0) < 3.0 || (bx.rem_euclid(40.0)) < 3.0;
    let mut out = [0.0; 3];
    for k in 0..3 {
        let mut v = 40.0 + 170.0 * rgb[k];
        if mortar {
            v = 0.55 * v + 0.45 * 225.0;
        }
        if line {
            v *= 0.35;
        }
        out[k] = v.clamp(0.0, 255.0);
    }
    out
}

/// Stripes of period `period` px (vertical, two colours) over bricks: a permanently hidden
/// region of this texture is determined by its periodicity.
pub fn periodic_texture(y: f64, x: f64, period: f64) -> [f64; 3] {
    let stripe = (x.rem_euclid(period)) < period / 2.0;
    let row = (y / 16.0).floor();
    let bx = x + if row as i64 % 2 == 0 { 0.0 } else { period };
    let mortar = (y - row * 16.0) < 3.0 || bx.rem_euclid(2.0 * period) < 3.0;
    let base = if stripe {
        [200.0, 70.0, 60.0]
    } else {
        [60.0, 90.0, 190.0]
    };
    if mortar {
        [230.0, 225.0, 215.0]
    } else {
        base
    }
}

fn check_dims(frames: usize, h: usize, w: usize) -> Result<()> {
    if frames == 0 || h < 16 || w < 16 {
        return Err(Error::invalid(
            "size",
            format!(
                "a clip needs frames >= 1 and frames of at least 16 x 16, got {frames} x {h} x {w}"
            ),
        ));
    }
    // The clean clip and its painted copy, 3 bytes per pixel each.
    wscg_math::alloc::ensure_shape::<u8>("frames, height, width", &[frames, h, w, 3, 2])?;
    Ok(())
}

/// Renders `frames` frames of `h x w` with `colour(t, y, x)`; adds Gaussian noise of standard
/// deviation `noise` (grey levels; independent per pixel and channel, seeded) when positive.
fn render(
    frames: usize,
    h: usize,
    w: usize,
    noise: f64,
    seed: u64,
    colour: impl Fn(usize, f64, f64) -> [f64; 3] + Sync,
) -> Video {
    use rayon::prelude::*;
    let mut data = vec![0u8; frames * h * w * 3]; // sized by check_dims
    data.par_chunks_mut(w * 3)
        .enumerate()
        .for_each(|(row, out)| {
            let (t, y) = (row / h, row % h);
            for x in 0..w {
                let c = colour(t, y as f64, x as f64);
                for k in 0..3 {
                    let n = if noise > 0.0 {
                        noise
                            * normal(
                                hash(seed ^ 0xABCD, (row * w + x) as i64, k as i64),
                                hash(seed ^ 0x1234, (row * w + x) as i64, k as i64),
                            )
                    } else {
                        0.0
                    };
                    out[x * 3 + k] = (c[k] + n).round().clamp(0.0, 255.0) as u8;
                }
            }
        });
    Video {
        frames,
        height: h,
        width: w,
        channels: 3,
        data,
    }
}

/// Paints `colour` over the hole pixels of a copy of `clean`.
fn paint(clean: &Video, hole: &Mask3, colour: impl Fn(usize, usize, usize) -> [u8; 3]) -> Video {
    let mut v = clean.clone();
    paint_in_place(&mut v, hole, colour);
    v
}

fn paint_in_place(v: &mut Video, hole: &Mask3, colour: impl Fn(usize, usize, usize) -> [u8; 3]) {
    for p in hole.iter_points() {
        let o = v.offset(p);
        let c = colour(p[0] as usize, p[1] as usize, p[2] as usize);
        v.data[o..o + 3].copy_from_slice(&c);
    }
}

/// G1: static camera over the texture, an opaque disc of `radius` px crossing the frame
/// horizontally at `speed` px per frame (at mid height, starting `radius` px from the left
/// edge), Gaussian noise of `noise` grey levels on every pixel.
pub fn sprite_clip(
    frames: usize,
    h: usize,
    w: usize,
    radius: f64,
    speed: f64,
    noise: f64,
    seed: u64,
) -> Result<Clip> {
    check_dims(frames, h, w)?;
    let clean = render(frames, h, w, noise, seed, |_, y, x| texture(seed, y, x));
    let cy = h as f64 / 2.0;
    let hole = Mask3::from_fn(frames, h, w, |t, y, x| {
        let cx = radius + speed * t as f64;
        (y as f64 - cy).powi(2) + (x as f64 - cx).powi(2) <= radius * radius
    });
    let observed = paint(&clean, &hole, |_, y, x| {
        [220, (y % 40 * 5) as u8, (x % 50 * 4) as u8]
    });
    Ok(Clip {
        clean,
        observed,
        hole,
    })
}

/// G2: a `w x h` window panning right by `step` px per frame over the texture; a static
/// `hole_w x hole_h` logo hole centred in the frame.
pub fn pan_clip(
    frames: usize,
    h: usize,
    w: usize,
    step: f64,
    hole_h: usize,
    hole_w: usize,
    seed: u64,
) -> Result<Clip> {
    check_dims(frames, h, w)?;
    let clean = pan_render(frames, h, w, step, seed);
    let hole = logo_hole(frames, h, w, hole_h, hole_w);
    let observed = paint(&clean, &hole, logo_colour(h, hole_h));
    Ok(Clip {
        clean,
        observed,
        hole,
    })
}

/// The input of [`pan_clip`] alone (the video with the logo, and the hole), without holding
/// the ground truth: one copy of the video in memory, for large clips.
pub fn pan_input(
    frames: usize,
    h: usize,
    w: usize,
    step: f64,
    hole_h: usize,
    hole_w: usize,
    seed: u64,
) -> Result<(Video, Mask3)> {
    check_dims(frames, h, w)?;
    let mut v = pan_render(frames, h, w, step, seed);
    let hole = logo_hole(frames, h, w, hole_h, hole_w);
    paint_in_place(&mut v, &hole, logo_colour(h, hole_h));
    Ok((v, hole))
}

fn pan_render(frames: usize, h: usize, w: usize, step: f64, seed: u64) -> Video {
    render(frames, h, w, 0.0, seed, |t, y, x| {
        texture(seed, y, x + step * t as f64)
    })
}

fn logo_hole(frames: usize, h: usize, w: usize, hole_h: usize, hole_w: usize) -> Mask3 {
    let (y0, x0) = ((h - hole_h.min(h)) / 2, (w - hole_w.min(w)) / 2);
    Mask3::from_fn(frames, h, w, |_, y, x| {
        (y0..y0 + hole_h).contains(&y) && (x0..x0 + hole_w).contains(&x)
    })
}

/// The logo: horizontal white and black bars 5 px high.
fn logo_colour(h: usize, hole_h: usize) -> impl Fn(usize, usize, usize) -> [u8; 3] {
    let y0 = (h - hole_h.min(h)) / 2;
    move |_, y, _| {
        if (y - y0) % 10 < 5 {
            [250, 250, 250]
        } else {
            [10, 10, 10]
        }
    }
}

/// G3: a zoom by `zoom` per frame about the frame centre (frame `t` shows the texture scaled
/// by `zoom^t`); a disc hole of `radius` px moving right by `speed` px per frame.
pub fn zoom_clip(
    frames: usize,
    h: usize,
    w: usize,
    zoom: f64,
    radius: f64,
    speed: f64,
    seed: u64,
) -> Result<Clip> {
    check_dims(frames, h, w)?;
    let (cy, cx) = (h as f64 / 2.0, w as f64 / 2.0);
    let clean = render(frames, h, w, 0.0, seed, |t, y, x| {
        let s = zoom.powi(t as i32);
        texture(seed, cy + (y - cy) / s, cx + (x - cx) / s)
    });
    let hole = Mask3::from_fn(frames, h, w, |t, y, x| {
        let hx = w as f64 / 3.0 + speed * t as f64;
        (y as f64 - cy).powi(2) + (x as f64 - hx).powi(2) <= radius * radius
    });
    let observed = paint(&clean, &hole, |_, _, _| [0, 255, 0]);
    Ok(Clip {
        clean,
        observed,
        hole,
    })
}

/// G4: static camera on stripes of period `period` px over bricks, a static square hole of
/// `side` px in the centre, hidden in every frame.
pub fn periodic_clip(frames: usize, h: usize, w: usize, period: f64, side: usize) -> Result<Clip> {
    check_dims(frames, h, w)?;
    let clean = render(frames, h, w, 0.0, 0, |_, y, x| {
        periodic_texture(y, x, period)
    });
    let (y0, x0) = ((h - side.min(h)) / 2, (w - side.min(w)) / 2);
    let hole = Mask3::from_fn(frames, h, w, |_, y, x| {
        (y0..y0 + side).contains(&y) && (x0..x0 + side).contains(&x)
    });
    let observed = paint(&clean, &hole, |_, _, _| [0, 0, 0]);
    Ok(Clip {
        clean,
        observed,
        hole,
    })
}

/// A standard normal deviate from two uniform numbers in `[0, 1)` (Box-Muller).
fn normal(u1: f64, u2: f64) -> f64 {
    (-2.0 * (1.0 - u1).ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clips_have_the_described_geometry() {
        let c = pan_clip(3, 40, 60, 8.0, 10, 12, 1).unwrap();
        assert_eq!(c.hole.count(), 3 * 10 * 12);
        // Panning: frame 1 is frame 0 shifted left by 8 px.
        let (f0, f1) = (c.clean.frame(0), c.clean.frame(1));
        for y in 0..40 {
            for x in 0..52 {
                for k in 0..3 {
                    assert_eq!(f1[(y * 60 + x) * 3 + k], f0[(y * 60 + x + 8) * 3 + k]);
                }
            }
        }
        // Outside the hole the observed clip is the clean one.
        for i in 0..c.hole.len_grid() {
            if !c.hole.contains_index(i) {
                assert_eq!(
                    &c.observed.data[i * 3..i * 3 + 3],
                    &c.clean.data[i * 3..i * 3 + 3]
                );
            }
        }
        let g = sprite_clip(4, 32, 64, 6.0, 5.0, 0.0, 2).unwrap();
        assert!(g.hole.count() > 4 * 100);
        assert!(periodic_clip(2, 8, 8, 24.0, 4).is_err());
    }
}
