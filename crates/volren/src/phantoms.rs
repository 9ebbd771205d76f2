//! Analytic CT-like phantoms standing in for the paper's clinical volumes (the skull,
//! 256 x 256 x 112, and the thorax, 512^3), with their transfer functions. Deterministic for a
//! given seed.
//!
//! - [`head`]: the 3-D modified Shepp-Logan phantom (ten ellipsoids, Schabel's `phantom3d`
//!   table) on `[-1, 1]^3`, densities `round(255 clamp(v, 0, 1))`, noise of standard deviation
//!   2, then a Gaussian blur of 0.7 voxel (the blur after the noise makes it spatially
//!   correlated, as CT noise is).
//! - [`thorax`]: an elliptic-cylinder body with a skin layer, two lungs with vessel tubes, a
//!   heart, a spine cut into vertebrae and twelve rib pairs; noise 3, then a blur of 1 voxel.

use rayon::prelude::*;
use wscg_math::filter::Border;
use wscg_math::{Error, Result, Volume};

use crate::tf::PiecewiseTransferFunction;

/// Schabel's modified Shepp-Logan table: value, semi-axes (a, b, c), centre (x0, y0, z0),
/// Euler angles (phi, theta, psi) in degrees.
const SHEPP_LOGAN: [[f64; 10]; 10] = [
    [1.0, 0.69, 0.92, 0.81, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [-0.8, 0.6624, 0.874, 0.78, 0.0, -0.0184, 0.0, 0.0, 0.0, 0.0],
    [-0.2, 0.11, 0.31, 0.22, 0.22, 0.0, 0.0, -18.0, 0.0, 10.0],
    [-0.2, 0.16, 0.41, 0.28, -0.22, 0.0, 0.0, 18.0, 0.0, 10.0],
    [0.1, 0.21, 0.25, 0.41, 0.0, 0.35, -0.15, 0.0, 0.0, 0.0],
    [0.1, 0.046, 0.046, 0.05, 0.0, 0.1, 0.25, 0.0, 0.0, 0.0],
    [0.1, 0.046, 0.046, 0.05, 0.0, -0.1, 0.25, 0.0, 0.0, 0.0],
    [0.1, 0.046, 0.023, 0.05, -0.08, -0.605, 0.0, 0.0, 0.0, 0.0],
    [0.1, 0.023, 0.023, 0.02, 0.0, -0.606, 0.0, 0.0, 0.0, 0.0],
    [0.1, 0.023, 0.046, 0.02, 0.06, -0.605, 0.0, 0.0, 0.0, 0.0],
];

/// An ellipsoid of the head table: rotation, semi-axes, centre, value.
struct Ellipsoid {
    rot: [[f64; 3]; 3],
    axes: [f64; 3],
    centre: [f64; 3],
    value: f64,
}

impl Ellipsoid {
    fn contains(&self, p: [f64; 3]) -> bool {
        (0..3)
            .map(|i| {
                let q: f64 = (0..3).map(|j| self.rot[i][j] * p[j]).sum();
                ((q - self.centre[i]) / self.axes[i]).powi(2)
            })
            .sum::<f64>()
            <= 1.0
    }
}

/// Voxel centre `i` of `n` in `[-1, 1]`.
fn coord(i: usize, n: usize) -> f64 {
    -1.0 + (2 * i + 1) as f64 / n as f64
}

/// Samples `f` on `[-1, 1]^3` (voxel centres), adds Gaussian noise, blurs, rounds to u8.
fn rasterise(
    dims: [usize; 3],
    blur: f64,
    noise: f64,
    seed: u64,
    f: impl Fn([f64; 3], [f64; 3]) -> f64 + Sync,
) -> Result<Volume<u8>> {
    if dims.contains(&0) {
        return Err(Error::Empty("phantom dims"));
    }
    // The samples, their noise (f64), the blurred copy and the bytes: 4 f32 per voxel.
    let n = wscg_math::alloc::ensure_shape::<[f32; 4]>("dims", &dims)?;
    // Size of a voxel in phantom units along each axis.
    let h = dims.map(|n| 2.0 / n as f64);
    let mut data = wscg_math::alloc::try_vec("dims", 0.0f32, n)?;
    data.par_chunks_mut(dims[0] * dims[1])
        .enumerate()
        .for_each(|(z, slab)| {
            for y in 0..dims[1] {
                for x in 0..dims[0] {
                    let p = [coord(x, dims[0]), coord(y, dims[1]), coord(z, dims[2])];
                    slab[x + dims[0] * y] = f(p, h) as f32;
                }
            }
        });
    // Noise first, then the blur: the noise comes out spatially correlated, as in CT.
    let n = wscg_math::rng::normal_vec(seed, data.len(), 0.0, noise)?;
    data.iter_mut().zip(&n).for_each(|(d, e)| *d += *e as f32);
    let v = Volume::new(dims, [1.0; 3], data)?.gaussian_filter([blur; 3], 4.0, Border::Reflect)?;
    let out = v
        .data()
        .iter()
        .map(|&d| (d as f64).round().clamp(0.0, 255.0) as u8)
        .collect();
    Volume::new(dims, [1.0; 3], out)
}

/// The 3-D modified Shepp-Logan head (the paper's skull is 256 x 256 x 112).
pub fn head(dims: [usize; 3], seed: u64) -> Result<Volume<u8>> {
    let ellipsoids: Vec<Ellipsoid> = SHEPP_LOGAN
        .iter()
        .map(|e| {
            let (phi, theta, psi) = (e[7].to_radians(), e[8].to_radians(), e[9].to_radians());
            let (cf, sf, ct, st, cp, sp) = (
                phi.cos(),
                phi.sin(),
                theta.cos(),
                theta.sin(),
                psi.cos(),
                psi.sin(),
            );
            // phantom3d's Euler rotation (z-x-z).
            let rot = [
                [cf * cp - ct * sf * sp, cf * sp + ct * sf * cp, sp * st],
                [-sf * cp - ct * cf * sp, -sf * sp + ct * cf * cp, cp * st],
                [st * sf, -st * cf, ct],
            ];
            Ellipsoid {
                rot,
                axes: [e[1], e[2], e[3]],
                centre: [e[4], e[5], e[6]],
                value: e[0],
            }
        })
        .collect();
    rasterise(dims, 0.7, 2.0, seed, |p, _| {
        let v: f64 = ellipsoids
            .iter()
            .filter(|e| e.contains(p))
            .map(|e| e.value)
            .sum();
        255.0 * v.clamp(0.0, 1.0)
    })
}

/// Transfer functions of [`head`]: soft tissue (canonical, index 0) and bone.
pub fn head_tfs() -> Vec<PiecewiseTransferFunction> {
    let soft = PiecewiseTransferFunction::new(vec![
        (30.0, [0.9, 0.6, 0.5, 0.0]),
        (60.0, [0.9, 0.6, 0.5, 0.05]),
        (110.0, [0.9, 0.6, 0.5, 0.05]),
        (120.0, [0.9, 0.6, 0.5, 0.0]),
    ]);
    let bone = PiecewiseTransferFunction::new(vec![
        (180.0, [1.0, 1.0, 0.9, 0.0]),
        (255.0, [1.0, 1.0, 0.9, 0.8]),
    ]);
    vec![soft.expect("valid"), bone.expect("valid")]
}

/// Distance from `p` to the segment `a`-`b`.
fn segment_distance(p: [f64; 3], a: [f64; 3], b: [f64; 3]) -> f64 {
    let ab: [f64; 3] = std::array::from_fn(|i| b[i] - a[i]);
    let ap: [f64; 3] = std::array::from_fn(|i| p[i] - a[i]);
    let l2: f64 = ab.iter().map(|v| v * v).sum();
    let t = if l2 > 0.0 {
        (ap.iter().zip(&ab).map(|(u, v)| u * v).sum::<f64>() / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (0..3)
        .map(|i| (ap[i] - t * ab[i]).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// A thorax on `[-1, 1]^3` (z the body axis; the paper's thorax is 512^3).
pub fn thorax(dims: [usize; 3], seed: u64) -> Result<Volume<u8>> {
    let lungs = [[-0.35, 0.0, 0.1], [0.35, 0.0, 0.1]];
    let lung_axes = [0.28, 0.35, 0.6];
    let in_ellipsoid = |p: [f64; 3], c: [f64; 3], ax: [f64; 3]| {
        (0..3).map(|i| ((p[i] - c[i]) / ax[i]).powi(2)).sum::<f64>() <= 1.0
    };
    // Ten vessel tubes per lung between random points of its central part.
    let u = wscg_math::rng::uniform_vec(seed ^ 0x7e55e1, 20 * 6, -0.7, 0.7)?;
    let vessels: Vec<([f64; 3], [f64; 3])> = (0..20)
        .map(|k| {
            let c = lungs[k / 10];
            let q = &u[6 * k..6 * k + 6];
            let pt = |o: usize| std::array::from_fn(|i| c[i] + q[o + i] * lung_axes[i]);
            (pt(0), pt(3))
        })
        .collect();
    rasterise(dims, 1.0, 3.0, seed, |p, h| {
        let body = (p[0] / 0.8).powi(2) + (p[1] / 0.55).powi(2);
        if body > 1.0 {
            return 0.0;
        }
        // Ribs: elliptic tubes of radius 0.02 around the body at 12 heights, open in front.
        for k in 0..12 {
            let zk = -0.8 + 1.4 * k as f64 / 11.0;
            let rho = ((p[0] / 0.72).powi(2) + (p[1] / 0.48).powi(2)).sqrt();
            let front = p[1] > 0.0 && p[0].abs() < 0.15;
            if !front && ((rho - 1.0) * 0.6).hypot(p[2] - zk) < 0.02 {
                return 220.0;
            }
        }
        // Spine: a cylinder cut into vertebrae by discs two voxels thick.
        if p[0].hypot(p[1] + 0.4) < 0.08 {
            let phase = (p[2] + 1.0).rem_euclid(0.12);
            return if phase < 2.0 * h[2] { 120.0 } else { 230.0 };
        }
        if in_ellipsoid(p, [0.05, 0.05, -0.05], [0.2, 0.18, 0.22]) {
            return 130.0;
        }
        if lungs.iter().any(|&c| in_ellipsoid(p, c, lung_axes)) {
            let vessel = vessels
                .iter()
                .any(|&(a, b)| segment_distance(p, a, b) < 0.015);
            return if vessel { 60.0 } else { 15.0 };
        }
        // Skin: the outer three voxels of the body.
        let skin = 3.0 * h[0].max(h[1]);
        let inner = (p[0] / (0.8 - skin)).powi(2) + (p[1] / (0.55 - skin)).powi(2);
        if inner > 1.0 {
            70.0
        } else {
            100.0
        }
    })
}

/// Transfer functions of [`thorax`]: all structures (canonical, index 0), bone (ramp 170 to
/// 230), lungs (window 5 to 30) and skin (window 55 to 85).
pub fn thorax_tfs() -> Vec<PiecewiseTransferFunction> {
    let tf = |pts: Vec<(f32, [f32; 4])>| PiecewiseTransferFunction::new(pts).expect("valid");
    vec![
        tf(vec![
            (5.0, [0.8, 0.5, 0.4, 0.0]),
            (30.0, [0.8, 0.5, 0.4, 0.02]),
            (55.0, [0.9, 0.6, 0.5, 0.02]),
            (85.0, [0.9, 0.6, 0.5, 0.04]),
            (170.0, [1.0, 1.0, 0.9, 0.04]),
            (230.0, [1.0, 1.0, 0.9, 0.6]),
        ]),
        tf(vec![
            (170.0, [1.0, 1.0, 0.9, 0.0]),
            (230.0, [1.0, 1.0, 0.9, 0.8]),
        ]),
        tf(vec![
            (5.0, [0.8, 0.4, 0.4, 0.0]),
            (10.0, [0.8, 0.4, 0.4, 0.3]),
            (25.0, [0.8, 0.4, 0.4, 0.3]),
            (30.0, [0.8, 0.4, 0.4, 0.0]),
        ]),
        tf(vec![
            (55.0, [0.9, 0.7, 0.6, 0.0]),
            (65.0, [0.9, 0.7, 0.6, 0.3]),
            (75.0, [0.9, 0.7, 0.6, 0.3]),
            (85.0, [0.9, 0.7, 0.6, 0.0]),
        ]),
    ]
}
