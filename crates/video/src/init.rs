//! Initial colours of the hole at the coarsest level (paper 06, Fig. 3 stage 1.2). The paper
//! uses image inpainting (Bertalmio et al. 2001) to start from the colours around the hole
//! rather than random values as Wexler et al. do; the exact choice only affects convergence.
//! Here: harmonic interpolation (the Laplace equation `Delta I = 0` in the hole with the known
//! colours as Dirichlet data, solved by red-black SOR) per frame or over the space-time
//! volume, and seeded random colours for the Wexler baseline.

use rand::Rng as _;
use rayon::prelude::*;

use crate::video::{Mask3, Video};

/// How the hole is initialised.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InitMethod {
    /// Per frame and channel, `Delta I = 0` in the hole (4-neighbour Laplacian).
    Harmonic2D,
    /// `Delta I = 0` over the space-time volume (6-neighbour Laplacian).
    Harmonic3D,
    /// Per frame, fast-marching inpainting (Telea 2004, radius 5).
    Telea,
    /// Uniform random colours (Wexler et al. 2007).
    Random {
        /// Seed of the colours.
        seed: u64,
    },
}

/// SOR stops when the largest update of a sweep is below this (grey levels).
const TOLERANCE: f32 = 1e-3;
/// Upper bound on SOR sweeps.
const MAX_SWEEPS: usize = 20_000;

/// Writes initial colours into the hole pixels of `video` (known pixels are not touched).
pub fn initialize(video: &mut Video, hole: &Mask3, method: InitMethod) {
    match method {
        InitMethod::Random { seed } => {
            let pts = hole.points();
            let c = video.channels;
            for (i, p) in pts.iter().enumerate() {
                let mut r = wscg_math::rng::stream(seed, i as u64);
                let o = video.offset(*p);
                for k in 0..c {
                    video.data[o + k] = r.random_range(0..=255u8);
                }
            }
        }
        InitMethod::Harmonic2D => {
            let (h, w, c) = (video.height, video.width, video.channels);
            let n = h * w * c;
            video
                .data
                .par_chunks_mut(n)
                .enumerate()
                .for_each(|(t, frame)| {
                    if hole.frame_any(t) {
                        let inside =
                            |y: usize, x: usize| hole.contains([t as u32, y as u32, x as u32]);
                        harmonic(frame, [1, h, w], c, &|_, y, x| inside(y, x));
                    }
                });
        }
        InitMethod::Telea => {
            let (h, w, c) = (video.height, video.width, video.channels);
            video
                .data
                .par_chunks_mut(h * w * c)
                .enumerate()
                .for_each(|(t, frame)| {
                    if hole.frame_any(t) {
                        let m: Vec<bool> = (0..h * w)
                            .map(|i| hole.contains_index(t * h * w + i))
                            .collect();
                        crate::telea::telea_in_place(frame, h, w, c, &m, 5.0);
                    }
                });
        }
        InitMethod::Harmonic3D => {
            let dims = video.dims();
            let c = video.channels;
            harmonic(&mut video.data, dims, c, &|t, y, x| {
                hole.contains([t as u32, y as u32, x as u32])
            });
        }
    }
}

/// Red-black SOR for `Delta I = 0` on the points where `inside` holds, in a `dims` grid of
/// `c`-channel bytes; neighbours outside the grid are left out of the stencil.
fn harmonic(
    data: &mut [u8],
    dims: [usize; 3],
    c: usize,
    inside: &(dyn Fn(usize, usize, usize) -> bool + Sync),
) {
    let [f, h, w] = dims;
    let pts: Vec<[usize; 3]> = (0..f)
        .flat_map(|t| (0..h).flat_map(move |y| (0..w).map(move |x| [t, y, x])))
        .filter(|p| inside(p[0], p[1], p[2]))
        .collect();
    if pts.is_empty() {
        return;
    }
    let idx = |p: [usize; 3]| (p[0] * h + p[1]) * w + p[2];
    let mut val: Vec<f32> = data.iter().map(|&v| v as f32).collect();
    // Start from the mean known colour next to the hole, per channel.
    let mut mean = vec![0.0f64; c];
    let mut n = 0usize;
    for &p in &pts {
        for q in neighbours(p, dims) {
            if !inside(q[0], q[1], q[2]) {
                for k in 0..c {
                    mean[k] += val[idx(q) * c + k] as f64;
                }
                n += 1;
            }
        }
    }
    for &p in &pts {
        for k in 0..c {
            val[idx(p) * c + k] = if n > 0 {
                (mean[k] / n as f64) as f32
            } else {
                128.0
            };
        }
    }
    // The stencil of every point, built once: red points (even t + y + x) first, then black,
    // so that one pass over the list is one red-black sweep.
    let mut stencil: Vec<(usize, Vec<usize>)> = pts
        .iter()
        .map(|&p| (idx(p), neighbours(p, dims).map(idx).collect()))
        .collect();
    stencil.sort_by_key(|(i, _)| {
        let (t, y, x) = (i / (h * w), (i / w) % h, i % w);
        ((t + y + x) % 2, *i)
    });
    let omega = 1.9f32;
    for _ in 0..MAX_SWEEPS {
        let mut change = 0.0f32;
        for (i, nb) in &stencil {
            for k in 0..c {
                let avg = nb.iter().map(|&q| val[q * c + k]).sum::<f32>() / nb.len() as f32;
                let d = omega * (avg - val[i * c + k]);
                val[i * c + k] += d;
                change = change.max(d.abs());
            }
        }
        if change < TOLERANCE {
            break;
        }
    }
    for &p in &pts {
        let i = idx(p);
        for k in 0..c {
            data[i * c + k] = val[i * c + k].round().clamp(0.0, 255.0) as u8;
        }
    }
}

/// The grid neighbours of `p` along every axis of extent above 1.
fn neighbours(p: [usize; 3], dims: [usize; 3]) -> impl Iterator<Item = [usize; 3]> {
    (0..3).flat_map(move |a| {
        let mut out = [None, None];
        if p[a] > 0 {
            let mut q = p;
            q[a] -= 1;
            out[0] = Some(q);
        }
        if p[a] + 1 < dims[a] {
            let mut q = p;
            q[a] += 1;
            out[1] = Some(q);
        }
        out.into_iter().flatten()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn harmonic_fill_of_a_linear_ramp_is_the_ramp() {
        // A horizontal ramp is harmonic: the fill must reproduce it inside the hole.
        let (h, w) = (20, 30);
        let data: Vec<u8> = (0..h * w).map(|i| (4 * (i % w) + 20) as u8).collect();
        let mut v = Video::new(1, h, w, 1, data.clone()).unwrap();
        let hole = Mask3::from_fn(1, h, w, |_, y, x| {
            (5..15).contains(&y) && (8..22).contains(&x)
        });
        for p in hole.points() {
            let o = v.offset(p);
            v.data[o] = 0;
        }
        initialize(&mut v, &hole, InitMethod::Harmonic2D);
        for (a, b) in v.data.iter().zip(&data) {
            assert!(a.abs_diff(*b) <= 1, "{a} vs {b}");
        }
        let mut r = Video::new(1, h, w, 1, data.clone()).unwrap();
        initialize(&mut r, &hole, InitMethod::Random { seed: 1 });
        let outside_same = (0..h * w)
            .filter(|&i| !hole.contains_index(i))
            .all(|i| r.data[i] == data[i]);
        assert!(outside_same);
    }
}
