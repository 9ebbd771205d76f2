//! Test volumes standing in for the CT and ultrasound scenes of the paper-15 study (§5.1),
//! which are not public: the Marschner-Lobb aliasing test, analytic scenes with known light
//! transport, and the mapping of a tissue
//! label volume (such as the frog label volume shipped inside the `pyvista` wheel) to a
//! CT-like density field, each with a transfer function.

use wscg_math::filter::Border;
use wscg_math::{Error, Result, Volume, VolumeView};

use super::classify::TransferFunction;
use super::field::ScalarField;

/// The Marschner-Lobb function on `[-1, 1]^3` (`f_M = 6`, `alpha = 1/4`), values in `[0, 1]`.
pub fn marschner_lobb_value(x: f64, y: f64, z: f64) -> f64 {
    let (fm, alpha) = (6.0, 0.25);
    let r = (x * x + y * y).sqrt();
    let rho = (2.0 * std::f64::consts::PI * fm * (std::f64::consts::FRAC_PI_2 * r).cos()).cos();
    (1.0 - (std::f64::consts::FRAC_PI_2 * z).sin() + alpha * (1.0 + rho)) / (2.0 * (1.0 + alpha))
}

/// The Marschner-Lobb volume sampled at `n^3` points spanning `[-1, 1]^3` (standard `n = 41`).
/// Errors: `n < 2`.
pub fn marschner_lobb(n: usize) -> Result<ScalarField> {
    if n < 2 {
        return Err(Error::invalid(
            "n",
            format!("needs at least 2 samples, got {n}"),
        ));
    }
    let c = |i: usize| -1.0 + 2.0 * i as f64 / (n - 1) as f64;
    let mut data = Vec::with_capacity(n * n * n);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                data.push(marschner_lobb_value(c(i), c(j), c(k)).clamp(0.0, 1.0) as f32);
            }
        }
    }
    ScalarField::from_f32(Volume::new([n; 3], [1.0; 3], data)?)
}

/// A sharp transfer function for the Marschner-Lobb volume: a thin opaque shell around the
/// iso-value 1/2 (orange), 256 entries.
pub fn marschner_lobb_tf() -> TransferFunction {
    TransferFunction::from_points(
        &[
            (0.0, [1.0, 0.7, 0.4, 0.0]),
            (0.42, [1.0, 0.7, 0.4, 0.0]),
            (0.5, [1.0, 0.7, 0.4, 0.6]),
            (0.58, [1.0, 0.9, 0.7, 0.0]),
            (1.0, [1.0, 0.9, 0.7, 0.0]),
        ],
        256,
    )
    .expect("static transfer function")
}

/// A volume of `dims` filled with `value` (a homogeneous slab, whose light and image have
/// closed forms).
pub fn constant(dims: [usize; 3], value: f32) -> Result<ScalarField> {
    ScalarField::from_f32(Volume::filled(dims, [1.0; 3], value)?)
}

/// A half-plane occluder (a shadow edge whose blur measures the kernel): value 1 at the `z`
/// indices in `z_range` for `x < x_edge`, else 0.
pub fn half_plane(
    dims: [usize; 3],
    x_edge: usize,
    z_range: std::ops::Range<usize>,
) -> Result<ScalarField> {
    let [nx, ny, nz] = dims;
    let mut data = vec![0f32; nx * ny * nz];
    for z in z_range.clone().filter(|&z| z < nz) {
        for y in 0..ny {
            for x in 0..x_edge.min(nx) {
                data[x + nx * (y + ny * z)] = 1.0;
            }
        }
    }
    ScalarField::from_f32(Volume::new(dims, [1.0; 3], data)?)
}

/// Blobs in empty space: each `(centre, radius)` (voxel units) a cone of value
/// `1 - d / radius` at distance `d` from its centre, the maximum where blobs overlap, 0
/// elsewhere (the sparse volumes of the empty-space skipping tests).
pub fn blobs(
    dims: [usize; 3],
    spacing: [f64; 3],
    blobs: &[([f64; 3], f64)],
) -> Result<ScalarField> {
    let [nx, ny, nz] = dims;
    let mut data = vec![0f32; nx * ny * nz];
    for &(c, r) in blobs {
        for z in 0..nz {
            for y in 0..ny {
                for x in 0..nx {
                    let d = ((x as f64 - c[0]).powi(2)
                        + (y as f64 - c[1]).powi(2)
                        + (z as f64 - c[2]).powi(2))
                    .sqrt();
                    let i = x + nx * (y + ny * z);
                    data[i] = data[i].max((1.0 - d / r).clamp(0.0, 1.0) as f32);
                }
            }
        }
    }
    ScalarField::from_f32(Volume::new(dims, spacing, data)?)
}

/// A transfer function for [`blobs`]: transparent below 0.2 (the empty space around the
/// blobs), warm and increasingly opaque up to 0.9 at the centres.
pub fn blobs_tf() -> TransferFunction {
    TransferFunction::from_points(
        &[
            (0.0, [0.0; 4]),
            (0.2, [0.9, 0.5, 0.2, 0.0]),
            (0.5, [0.9, 0.6, 0.3, 0.4]),
            (1.0, [1.0, 1.0, 1.0, 0.9]),
        ],
        256,
    )
    .expect("static transfer function")
}

/// Density of tissue label `k` in a CT-like field: 0 for the background, otherwise spread over
/// `[0.3, 1]` in label order.
pub fn label_density(k: u8, max_label: u8) -> f32 {
    if k == 0 || max_label == 0 {
        0.0
    } else {
        0.3 + 0.7 * (k.min(max_label) - 1) as f32 / (max_label.max(2) - 1) as f32
    }
}

/// A CT-like density field from a tissue label volume: labels mapped by [`label_density`],
/// then a Gaussian blur of `sigma` voxels (sharp boundaries stay sharp for `sigma ~ 1`).
/// Errors: as [`ScalarField::from_f32`], negative `sigma`.
pub fn labels_to_field(labels: VolumeView<'_, u8>, sigma: f64) -> Result<ScalarField> {
    let max_label = labels.data().iter().copied().max().unwrap_or(0);
    let dens: Vec<f32> = labels
        .data()
        .iter()
        .map(|&k| label_density(k, max_label))
        .collect();
    let vol = Volume::new(labels.dims(), labels.spacing(), dens)?;
    let vol = if sigma > 0.0 {
        vol.gaussian_filter([sigma; 3], 3.0, Border::Nearest)?
    } else if sigma == 0.0 {
        vol
    } else {
        return Err(Error::invalid(
            "sigma",
            format!("must be >= 0, got {sigma}"),
        ));
    };
    ScalarField::from_f32(vol.map(|v| v.clamp(0.0, 1.0)))
}

/// A sharp transfer function for tissue fields made by [`labels_to_field`]: faint skin, red
/// organs and opaque white bone, 256 entries.
pub fn tissue_tf() -> TransferFunction {
    TransferFunction::from_points(
        &[
            (0.0, [0.0, 0.0, 0.0, 0.0]),
            (0.2, [0.9, 0.6, 0.4, 0.0]),
            (0.3, [0.9, 0.6, 0.4, 0.06]),
            (0.55, [0.9, 0.6, 0.4, 0.06]),
            (0.6, [0.8, 0.2, 0.15, 0.5]),
            (0.8, [0.8, 0.2, 0.15, 0.5]),
            (0.85, [1.0, 1.0, 0.95, 1.0]),
            (1.0, [1.0, 1.0, 0.95, 1.0]),
        ],
        256,
    )
    .expect("static transfer function")
}

/// A sharp "skin" transfer function for tissue fields made by [`labels_to_field`]: an
/// almost opaque surface where the density crosses 0.15 (the outer boundary of the body),
/// the kind of steep transfer function for which the paper reports the largest gains,
/// 256 entries.
pub fn skin_tf() -> TransferFunction {
    TransferFunction::from_points(
        &[
            (0.0, [0.0, 0.0, 0.0, 0.0]),
            (0.12, [0.95, 0.8, 0.7, 0.0]),
            (0.16, [0.95, 0.8, 0.7, 0.9]),
            (1.0, [0.95, 0.8, 0.7, 0.9]),
        ],
        256,
    )
    .expect("static transfer function")
}
