//! A fractured-shell CT phantom with exact fragment labels, standing in for the paper's
//! clinical cases (section 3), which are not public: an ellipsoidal
//! bone shell split into `K` fragments by the spherical Voronoi cells of random directions,
//! fracture gaps of lower (but still bone) density so that the thresholded bone stays in one
//! piece, soft tissue inside, air outside, partial-volume blur and CT noise. Seed strokes are
//! balls inside each fragment away from its Voronoi site, so that nearest-seed labelling does
//! not reproduce the truth by construction.

use rand_distr::{Distribution, StandardNormal};
use wscg_math::filter::Border;
use wscg_math::rng::stream;
use wscg_math::vec3::{dot, norm, sub};
use wscg_math::{Error, Result, Volume};

wscg_math::params! {
    /// Parameters of [`fractured_shell_phantom`].
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct PhantomParams {
        /// Volume size (x, y, z).
        pub dims: [usize; 3],
        /// Number of fragments `K` (6).
        pub fragments: usize,
        /// Seed of the sites, strokes and noise.
        pub seed: u64,
        /// Shell radii as fractions of the half-size ([0.60, 0.68]).
        pub shell: [f64; 2],
        /// Bone density, HU (1200).
        pub bone_hu: f64,
        /// Fracture-gap density, HU (450: above the 300 HU threshold).
        pub gap_hu: f64,
        /// Half-width of the fracture gap, voxels of arc (0.75).
        pub gap_width: f64,
        /// Partial-volume blur, voxels (0.8).
        pub blur_sigma: f64,
        /// CT noise standard deviation, HU (30).
        pub noise_hu: f64,
        /// Bone threshold used for the truth mask, HU (300).
        pub t_bone: f64,
        /// Stroke ball radius, voxels (2).
        pub stroke_radius: f64,
        /// Smallest arc distance of a stroke centre from its fragment's boundary, voxels (4).
        pub stroke_margin: f64,
        /// Strokes painted on the outer surface (as with the paper's 3D brush): the bone voxels
        /// with a 6-neighbour outside the bone within 3 voxels of a point of the outer surface,
        /// instead of balls at mid-shell.
        pub surface_strokes: bool,
    }
}

impl Default for PhantomParams {
    fn default() -> Self {
        Self {
            dims: [128, 128, 128],
            fragments: 6,
            seed: 0,
            shell: [0.60, 0.68],
            bone_hu: 1200.0,
            gap_hu: 450.0,
            gap_width: 0.75,
            blur_sigma: 0.8,
            noise_hu: 30.0,
            t_bone: 300.0,
            stroke_radius: 2.0,
            stroke_margin: 4.0,
            surface_strokes: false,
        }
    }
}

impl PhantomParams {
    /// Errors: fewer than 2 or more than 65535 fragments, a side below 16 voxels, a blur
    /// outside `0..=16` voxels, non-finite densities or widths, a negative gap width, noise,
    /// stroke radius or stroke margin, shell radii that are not `0 < inner < outer < 0.9`.
    pub fn validate(&self) -> Result<()> {
        if self.fragments < 2 || self.fragments > u16::MAX as usize {
            return Err(Error::invalid(
                "fragments",
                format!("needs 2..=65535, got {}", self.fragments),
            ));
        }
        if self.dims.iter().any(|&d| d < 16) {
            return Err(Error::invalid(
                "dims",
                format!("each side needs at least 16 voxels, got {:?}", self.dims),
            ));
        }
        // Per voxel: HU and boundary distance (f64), label (u16), the blurred and stored
        // copies; 32 bytes bound them.
        wscg_math::alloc::ensure_shape::<[u8; 32]>("dims", &self.dims)?;
        if !(self.blur_sigma.is_finite() && (0.0..=16.0).contains(&self.blur_sigma)) {
            return Err(Error::invalid(
                "blur_sigma",
                format!("needs 0..=16 voxels, got {}", self.blur_sigma),
            ));
        }
        for (name, v) in [
            ("bone_hu", self.bone_hu),
            ("gap_hu", self.gap_hu),
            ("t_bone", self.t_bone),
        ] {
            if !v.is_finite() {
                return Err(Error::invalid(name, format!("must be finite, got {v}")));
            }
        }
        for (name, v) in [
            ("gap_width", self.gap_width),
            ("noise_hu", self.noise_hu),
            ("stroke_radius", self.stroke_radius),
            ("stroke_margin", self.stroke_margin),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::invalid(
                    name,
                    format!("must be finite and >= 0, got {v}"),
                ));
            }
        }
        if !(self.shell[0] > 0.0 && self.shell[1] > self.shell[0] && self.shell[1] < 0.9) {
            return Err(Error::invalid("shell", "needs 0 < inner < outer < 0.9"));
        }
        Ok(())
    }
}

/// The phantom CT, its truth and seed strokes.
#[derive(Clone, Debug)]
pub struct Phantom {
    /// CT values, HU (rounded to integers as a 16-bit scan).
    pub ct: Volume<f32>,
    /// Fragment label (1..=K) of every voxel at or above the threshold, 0 elsewhere.
    pub truth: Volume<u16>,
    /// Seed strokes (label per voxel, 0 = none), inside the thresholded bone.
    pub seeds: Volume<u16>,
    /// Arc distance (voxels) of every voxel from the nearest fracture boundary.
    pub boundary_distance: Vec<f64>,
    /// Unit directions of the Voronoi sites.
    pub sites: Vec<[f64; 3]>,
}

/// Nearest and second-nearest site of direction `d` and the angular distance (radians) to
/// their bisecting great circle.
fn voronoi(d: [f64; 3], sites: &[[f64; 3]]) -> (usize, f64) {
    let mut order: Vec<(f64, usize)> = sites
        .iter()
        .enumerate()
        .map(|(k, s)| (-dot(d, *s), k))
        .collect();
    order.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (a, b) = (sites[order[0].1], sites[order[1].1]);
    let n = sub(a, b);
    let nn = norm(n);
    let ang = if nn > 0.0 {
        (dot(d, n) / nn).clamp(-1.0, 1.0).asin().abs()
    } else {
        0.0
    };
    (order[0].1, ang)
}

/// Generates the phantom. Errors: fewer than 2 fragments, a side below 16 voxels, invalid
/// radii or densities.
pub fn fractured_shell_phantom(c: &PhantomParams) -> Result<Phantom> {
    c.validate()?;
    let mut rng = stream(c.seed, 18);
    let gauss = |r: &mut wscg_math::rng::Rng| -> f64 { StandardNormal.sample(r) };
    let sites: Vec<[f64; 3]> = (0..c.fragments)
        .map(|_| {
            let v = [gauss(&mut rng), gauss(&mut rng), gauss(&mut rng)];
            let n = norm(v).max(1e-12);
            [v[0] / n, v[1] / n, v[2] / n]
        })
        .collect();
    let [nx, ny, nz] = c.dims;
    let half = [nx as f64 / 2.0, ny as f64 / 2.0, nz as f64 / 2.0];
    let n = nx * ny * nz;
    let mut hu = vec![0.0; n];
    let mut label = vec![0u16; n];
    let mut bdist = vec![f64::INFINITY; n];
    for (i, h) in hu.iter_mut().enumerate() {
        let p = [
            (i % nx) as f64 + 0.5,
            ((i / nx) % ny) as f64 + 0.5,
            (i / (nx * ny)) as f64 + 0.5,
        ];
        let d = sub(p, half);
        let rho = norm([d[0] / half[0], d[1] / half[1], d[2] / half[2]]);
        let r = norm(d).max(1e-12);
        let dir = [d[0] / r, d[1] / r, d[2] / r];
        let (k, ang) = voronoi(dir, &sites);
        label[i] = k as u16 + 1;
        bdist[i] = ang * r;
        *h = if rho >= c.shell[0] && rho <= c.shell[1] {
            if bdist[i] <= c.gap_width {
                c.gap_hu
            } else {
                c.bone_hu
            }
        } else if rho < 0.9 {
            40.0
        } else {
            -1000.0
        };
    }
    if c.blur_sigma > 0.0 {
        let v = Volume::new(c.dims, [1.0; 3], hu)?;
        hu = v
            .gaussian_filter([c.blur_sigma; 3], 4.0, Border::Nearest)?
            .into_data();
    }
    let mut noise = stream(c.seed, 0x0cd);
    let ct: Vec<f32> = hu
        .iter()
        .map(|&h| {
            let e: f64 = StandardNormal.sample(&mut noise);
            (h + c.noise_hu * e).round() as f32
        })
        .collect();
    let truth: Vec<u16> = ct
        .iter()
        .zip(&label)
        .map(|(&v, &l)| if v as f64 >= c.t_bone { l } else { 0 })
        .collect();
    // Strokes: a ball around a mid-shell point of each fragment, away from its boundary.
    let mut seeds = vec![0u16; n];
    let (mid, rr) = if c.surface_strokes {
        (c.shell[1], 3.0)
    } else {
        (0.5 * (c.shell[0] + c.shell[1]), c.stroke_radius)
    };
    let on_surface = |x: usize, y: usize, z: usize| {
        let i = x + nx * (y + ny * z);
        let s = [1, nx, nx * ny];
        let cc = [x, y, z];
        (0..3).any(|a| {
            cc[a] == 0 || cc[a] + 1 == c.dims[a] || truth[i - s[a]] == 0 || truth[i + s[a]] == 0
        })
    };
    for k in 0..c.fragments {
        let mut centre = None;
        for _ in 0..100_000 {
            let v = [gauss(&mut rng), gauss(&mut rng), gauss(&mut rng)];
            let nv = norm(v).max(1e-12);
            let u = [v[0] / nv, v[1] / nv, v[2] / nv];
            let p = [
                half[0] + mid * half[0] * u[0],
                half[1] + mid * half[1] * u[1],
                half[2] + mid * half[2] * u[2],
            ];
            let d = sub(p, half);
            let r = norm(d).max(1e-12);
            let (kk, ang) = voronoi([d[0] / r, d[1] / r, d[2] / r], &sites);
            if kk == k && ang * r >= c.stroke_margin {
                centre = Some(p);
                break;
            }
        }
        let Some(p) = centre else {
            return Err(Error::invalid(
                "fragments",
                format!(
                    "fragment {} is too small for a stroke {} voxels from its boundary",
                    k + 1,
                    c.stroke_margin
                ),
            ));
        };
        let lo = |a: usize| (p[a] - rr - 1.0).floor().max(0.0) as usize;
        let hi = |a: usize| ((p[a] + rr + 1.0).ceil() as usize).min(c.dims[a] - 1);
        for z in lo(2)..=hi(2) {
            for y in lo(1)..=hi(1) {
                for x in lo(0)..=hi(0) {
                    let q = [x as f64 + 0.5, y as f64 + 0.5, z as f64 + 0.5];
                    let i = x + nx * (y + ny * z);
                    if norm(sub(q, p)) <= rr
                        && truth[i] != 0
                        && (!c.surface_strokes || on_surface(x, y, z))
                    {
                        seeds[i] = k as u16 + 1;
                    }
                }
            }
        }
    }
    let spacing = [1.0; 3];
    Ok(Phantom {
        ct: Volume::new(c.dims, spacing, ct)?,
        truth: Volume::new(c.dims, spacing, truth)?,
        seeds: Volume::new(c.dims, spacing, seeds)?,
        boundary_distance: bdist,
        sites,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn voronoi_distance_is_zero_on_the_bisector() {
        let sites = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let s = std::f64::consts::FRAC_1_SQRT_2;
        let (_, ang) = voronoi([s, s, 0.0], &sites);
        assert!(ang.abs() < 1e-12);
        let (k, ang) = voronoi([1.0, 0.0, 0.0], &sites);
        assert_eq!(k, 0);
        assert!((ang - std::f64::consts::FRAC_PI_4).abs() < 1e-12);
    }
}
