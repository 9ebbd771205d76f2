//! From tristimulus values to display RGB (paper 07, Fig. 2: the renderer's XYZ output goes
//! through the display's calibration matrix; sRGB is the default display).

use nalgebra::{Matrix3, Vector3};

/// XYZ to linear sRGB (IEC 61966-2-1, D65 white).
pub const XYZ_TO_SRGB: [[f64; 3]; 3] = [
    [3.2404542, -1.5371385, -0.4985314],
    [-0.9692660, 1.8760108, 0.0415560],
    [0.0556434, -0.2040259, 1.0572252],
];

/// The Bradford cone-response matrix (chromatic adaptation).
pub const BRADFORD: [[f64; 3]; 3] = [
    [0.8951, 0.2664, -0.1614],
    [-0.7502, 1.7135, 0.0367],
    [0.0389, -0.0685, 1.0296],
];

/// `m * xyz` for a 3 x 3 matrix given by rows (a display's calibration matrix, or
/// [`XYZ_TO_SRGB`]).
pub fn xyz_to_rgb(xyz: [f64; 3], m: &[[f64; 3]; 3]) -> [f64; 3] {
    let mut out = [0.0; 3];
    for (o, row) in out.iter_mut().zip(m) {
        *o = row[0] * xyz[0] + row[1] * xyz[1] + row[2] * xyz[2];
    }
    out
}

/// Chromaticity `(x, y)` of tristimulus values; `(0, 0)` for black.
pub fn xyz_to_xy(xyz: [f64; 3]) -> [f64; 2] {
    let s = xyz[0] + xyz[1] + xyz[2];
    if s == 0.0 {
        [0.0, 0.0]
    } else {
        [xyz[0] / s, xyz[1] / s]
    }
}

/// The sRGB transfer function (IEC 61966-2-1) of a linear value, clamped to [0, 1].
pub fn srgb_oetf(v: f64) -> f64 {
    let v = v.clamp(0.0, 1.0);
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// The Bradford chromatic adaptation matrix taking colours seen under `src_white` to
/// `dst_white` (both XYZ with any scale).
pub fn bradford_adaptation(src_white: [f64; 3], dst_white: [f64; 3]) -> [[f64; 3]; 3] {
    let b = Matrix3::from_fn(|i, j| BRADFORD[i][j]);
    let bi = b.try_inverse().unwrap_or_else(Matrix3::identity);
    let s = b * Vector3::from(src_white);
    let d = b * Vector3::from(dst_white);
    let gain = Matrix3::from_diagonal(&Vector3::new(d[0] / s[0], d[1] / s[1], d[2] / s[2]));
    let m = bi * gain * b;
    [0, 1, 2].map(|i| [0, 1, 2].map(|j| m[(i, j)]))
}
