//! Analytic scalar fields with exact gradients, for the paper's section 5.2 (Table 3) and the
//! acceptance checks, and a sampler onto grids.
//!
//! The paper names its fields but gives neither formulas nor grid sizes; the definitions here
//! are the standard ones where a standard exists (Marschner-Lobb, Bourke's genus-3 surface,
//! MATLAB's peaks) and ours otherwise (six peaks, flower).

use rand_distr::{Distribution, Normal};
use std::f64::consts::PI;
use wscg_math::{rng, Error, Result, VolumeView};

use crate::grid::ScalarGrid;

/// A scalar field with its exact gradient.
pub trait Field: Sync {
    /// Field value at `p`.
    fn value(&self, p: [f64; 3]) -> f64;
    /// Exact gradient at `p`.
    fn gradient(&self, p: [f64; 3]) -> [f64; 3];
    /// The isovalue of the surface the paper extracts.
    fn iso(&self) -> f64 {
        0.0
    }
}

/// Signed distance to a sphere: `|p - centre| - radius` (isovalue 0, gradient outward).
#[derive(Clone, Copy, Debug)]
pub struct Sphere {
    /// Centre.
    pub centre: [f64; 3],
    /// Radius.
    pub radius: f64,
}

impl Field for Sphere {
    fn value(&self, p: [f64; 3]) -> f64 {
        norm(sub(p, self.centre)) - self.radius
    }
    fn gradient(&self, p: [f64; 3]) -> [f64; 3] {
        let d = sub(p, self.centre);
        let n = norm(d).max(1e-300);
        d.map(|x| x / n)
    }
}

/// Torus `(sqrt(x^2 + y^2) - R)^2 + z^2 - r^2` around `centre` (axis z, isovalue 0).
#[derive(Clone, Copy, Debug)]
pub struct Torus {
    /// Centre.
    pub centre: [f64; 3],
    /// Major radius R.
    pub major: f64,
    /// Minor radius r.
    pub minor: f64,
}

impl Field for Torus {
    fn value(&self, p: [f64; 3]) -> f64 {
        let d = sub(p, self.centre);
        let s = (d[0] * d[0] + d[1] * d[1]).sqrt();
        (s - self.major).powi(2) + d[2] * d[2] - self.minor * self.minor
    }
    fn gradient(&self, p: [f64; 3]) -> [f64; 3] {
        let d = sub(p, self.centre);
        let s = (d[0] * d[0] + d[1] * d[1]).sqrt().max(1e-300);
        let k = 2.0 * (s - self.major) / s;
        [k * d[0], k * d[1], 2.0 * d[2]]
    }
}

/// The Marschner-Lobb test signal on `[-1, 1]^3` (f_M = 6, alpha = 0.25), isovalue 0.5:
/// `rho = (1 - sin(pi z / 2) + alpha (1 + cos(2 pi f_M cos(pi r / 2)))) / (2 (1 + alpha))`,
/// `r = sqrt(x^2 + y^2)`.
#[derive(Clone, Copy, Debug)]
pub struct MarschnerLobb {
    /// Frequency f_M.
    pub fm: f64,
    /// Modulation alpha.
    pub alpha: f64,
}

impl Default for MarschnerLobb {
    fn default() -> Self {
        Self {
            fm: 6.0,
            alpha: 0.25,
        }
    }
}

impl Field for MarschnerLobb {
    fn value(&self, p: [f64; 3]) -> f64 {
        let r = (p[0] * p[0] + p[1] * p[1]).sqrt();
        let rr = (2.0 * PI * self.fm * (PI * r / 2.0).cos()).cos();
        (1.0 - (PI * p[2] / 2.0).sin() + self.alpha * (1.0 + rr)) / (2.0 * (1.0 + self.alpha))
    }
    fn gradient(&self, p: [f64; 3]) -> [f64; 3] {
        let k = 1.0 / (2.0 * (1.0 + self.alpha));
        let r = (p[0] * p[0] + p[1] * p[1]).sqrt();
        let drr = (2.0 * PI * self.fm * (PI * r / 2.0).cos()).sin()
            * 2.0
            * PI
            * self.fm
            * (PI / 2.0)
            * (PI * r / 2.0).sin();
        let (gx, gy) = if r > 0.0 {
            (self.alpha * drr * p[0] / r, self.alpha * drr * p[1] / r)
        } else {
            (0.0, 0.0)
        };
        [k * gx, k * gy, -k * (PI / 2.0) * (PI * p[2] / 2.0).cos()]
    }
    fn iso(&self) -> f64 {
        0.5
    }
}

/// Paul Bourke's genus-3 implicit surface on `[-2, 2]^3`:
/// `2y(y^2 - 3x^2)(1 - z^2) + (x^2 + y^2)^2 - (9z^2 - 1)(1 - z^2)`.
#[derive(Clone, Copy, Debug, Default)]
pub struct Genus3;

impl Field for Genus3 {
    fn value(&self, p: [f64; 3]) -> f64 {
        let [x, y, z] = p;
        let s = x * x + y * y;
        2.0 * y * (y * y - 3.0 * x * x) * (1.0 - z * z) + s * s
            - (9.0 * z * z - 1.0) * (1.0 - z * z)
    }
    fn gradient(&self, p: [f64; 3]) -> [f64; 3] {
        let [x, y, z] = p;
        let s = x * x + y * y;
        [
            -12.0 * x * y * (1.0 - z * z) + 4.0 * x * s,
            (1.0 - z * z) * (6.0 * y * y - 6.0 * x * x) + 4.0 * y * s,
            -4.0 * y * z * (y * y - 3.0 * x * x) - 20.0 * z + 36.0 * z * z * z,
        ]
    }
}

/// MATLAB's peaks as a height field, `z - P(x, y) / 4`, on x, y in [-3, 3], z in [-2.5, 2.5].
#[derive(Clone, Copy, Debug, Default)]
pub struct Peaks;

impl Peaks {
    fn terms(x: f64, y: f64) -> (f64, [f64; 2]) {
        let e1 = (-x * x - (y + 1.0) * (y + 1.0)).exp();
        let e2 = (-x * x - y * y).exp();
        let e3 = (-(x + 1.0) * (x + 1.0) - y * y).exp();
        let m = x / 5.0 - x.powi(3) - y.powi(5);
        let p = 3.0 * (1.0 - x).powi(2) * e1 - 10.0 * m * e2 - e3 / 3.0;
        let px = 3.0 * (-2.0 * (1.0 - x) - 2.0 * x * (1.0 - x).powi(2)) * e1
            - 10.0 * ((0.2 - 3.0 * x * x) - 2.0 * x * m) * e2
            + (2.0 / 3.0) * (x + 1.0) * e3;
        let py = -6.0 * (1.0 - x).powi(2) * (y + 1.0) * e1
            - 10.0 * (-5.0 * y.powi(4) - 2.0 * y * m) * e2
            + (2.0 / 3.0) * y * e3;
        (p, [px, py])
    }
}

impl Field for Peaks {
    fn value(&self, p: [f64; 3]) -> f64 {
        p[2] - Self::terms(p[0], p[1]).0 / 4.0
    }
    fn gradient(&self, p: [f64; 3]) -> [f64; 3] {
        let (_, d) = Self::terms(p[0], p[1]);
        [-d[0] / 4.0, -d[1] / 4.0, 1.0]
    }
}

/// Six Gaussian bumps at `(+-0.5, 0, 0)`, `(0, +-0.5, 0)`, `(0, 0, +-0.5)` on `[-1, 1]^3`:
/// `sum_k exp(-|x - c_k|^2 / 0.1) - 0.5` (our definition).
#[derive(Clone, Copy, Debug, Default)]
pub struct SixPeaks;

const SIX: [[f64; 3]; 6] = [
    [0.5, 0.0, 0.0],
    [-0.5, 0.0, 0.0],
    [0.0, 0.5, 0.0],
    [0.0, -0.5, 0.0],
    [0.0, 0.0, 0.5],
    [0.0, 0.0, -0.5],
];

impl Field for SixPeaks {
    fn value(&self, p: [f64; 3]) -> f64 {
        SIX.iter()
            .map(|c| (-dot2(sub(p, *c)) / 0.1).exp())
            .sum::<f64>()
            - 0.5
    }
    fn gradient(&self, p: [f64; 3]) -> [f64; 3] {
        let mut g = [0.0; 3];
        for c in &SIX {
            let d = sub(p, *c);
            let e = (-dot2(d) / 0.1).exp();
            for i in 0..3 {
                g[i] -= 2.0 * d[i] / 0.1 * e;
            }
        }
        g
    }
}

/// A five-petal flower: `|x| - (0.6 + 0.2 sin(5 phi) sin^2(theta))` on `[-1, 1]^3` (theta
/// polar, phi azimuth; our definition).
#[derive(Clone, Copy, Debug, Default)]
pub struct Flower;

impl Field for Flower {
    fn value(&self, p: [f64; 3]) -> f64 {
        let rho = norm(p);
        let s2 = p[0] * p[0] + p[1] * p[1];
        let phi = p[1].atan2(p[0]);
        let sin2 = if rho > 0.0 { s2 / (rho * rho) } else { 0.0 };
        rho - (0.6 + 0.2 * (5.0 * phi).sin() * sin2)
    }
    fn gradient(&self, p: [f64; 3]) -> [f64; 3] {
        let [x, y, z] = p;
        let rho = norm(p).max(1e-300);
        let s2 = x * x + y * y;
        let r2 = rho * rho;
        let phi = y.atan2(x);
        let sin2 = s2 / r2;
        // grad(s^2 / rho^2) and grad(phi).
        let gs = [
            2.0 * x / r2 - 2.0 * s2 * x / (r2 * r2),
            2.0 * y / r2 - 2.0 * s2 * y / (r2 * r2),
            -2.0 * s2 * z / (r2 * r2),
        ];
        let gphi = if s2 > 0.0 {
            [-y / s2, x / s2, 0.0]
        } else {
            [0.0; 3]
        };
        let (s5, c5) = (5.0 * phi).sin_cos();
        [0, 1, 2].map(|i| p[i] / rho - 0.2 * (5.0 * c5 * gphi[i] * sin2 + s5 * gs[i]))
    }
}

/// A linear field `a . p + b`.
#[derive(Clone, Copy, Debug)]
pub struct Linear {
    /// Gradient.
    pub a: [f64; 3],
    /// Offset.
    pub b: f64,
}

impl Field for Linear {
    fn value(&self, p: [f64; 3]) -> f64 {
        self.a[0] * p[0] + self.a[1] * p[1] + self.a[2] * p[2] + self.b
    }
    fn gradient(&self, _p: [f64; 3]) -> [f64; 3] {
        self.a
    }
}

/// A field sampled on a grid over an axis-aligned box.
#[derive(Clone, Debug)]
pub struct Sampled {
    /// Samples, x fastest.
    pub values: Vec<f32>,
    /// Sample counts.
    pub dims: [usize; 3],
    /// Sample spacing.
    pub spacing: [f32; 3],
    /// Field coordinates of sample (0, 0, 0).
    pub origin: [f64; 3],
}

impl Sampled {
    /// The samples as a volume view (spacing widened to `f64`).
    pub fn view(&self) -> VolumeView<'_, f32> {
        VolumeView::new(self.dims, self.spacing.map(f64::from), &self.values)
            .expect("sample() checks dims and spacing")
    }

    /// The grid view of the samples (no side hints).
    pub fn grid(&self) -> Result<ScalarGrid<'_>> {
        ScalarGrid::with_spacing(self.dims, self.spacing, &self.values)
    }

    /// Field coordinates of a vertex in grid world units.
    pub fn to_field(&self, v: [f32; 3]) -> [f64; 3] {
        [0, 1, 2].map(|i| self.origin[i] + v[i] as f64)
    }

    /// Exact unit normals (gradient direction) of `field` at the vertices.
    pub fn exact_normals(&self, field: &dyn Field, vertices: &[[f32; 3]]) -> Vec<[f32; 3]> {
        use rayon::prelude::*;
        vertices
            .par_iter()
            .map(|&v| {
                let g = field.gradient(self.to_field(v));
                let n = norm(g);
                if n > 0.0 {
                    g.map(|x| (x / n) as f32)
                } else {
                    [0.0; 3]
                }
            })
            .collect()
    }
}

/// Samples `field` on a `dims` grid spanning the box `[lo, hi]` (corners are samples).
pub fn sample(field: &dyn Field, dims: [usize; 3], lo: [f64; 3], hi: [f64; 3]) -> Result<Sampled> {
    use rayon::prelude::*;
    if dims.iter().any(|&n| n < 2) {
        return Err(Error::invalid(
            "dims",
            format!("need at least 2 samples per axis, got {dims:?}"),
        ));
    }
    let spacing64 = [0, 1, 2].map(|i| (hi[i] - lo[i]) / (dims[i] - 1) as f64);
    if spacing64.iter().any(|h| !(h.is_finite() && *h > 0.0)) {
        return Err(Error::invalid(
            "hi",
            format!("the box {lo:?}..{hi:?} must have positive size"),
        ));
    }
    let [nx, ny, _] = dims;
    let n = wscg_math::alloc::ensure_shape::<f32>("dims", &dims)?;
    let mut values = wscg_math::alloc::try_vec("dims", 0.0f32, n)?;
    values
        .par_chunks_mut(nx * ny)
        .enumerate()
        .for_each(|(z, slice)| {
            for y in 0..ny {
                for x in 0..nx {
                    let p = [
                        lo[0] + x as f64 * spacing64[0],
                        lo[1] + y as f64 * spacing64[1],
                        lo[2] + z as f64 * spacing64[2],
                    ];
                    slice[x + nx * y] = field.value(p) as f32;
                }
            }
        });
    Ok(Sampled {
        values,
        dims,
        spacing: spacing64.map(|h| h as f32),
        origin: lo,
    })
}

/// Samples `field` at integer coordinates `0..dims` (unit spacing, origin 0).
pub fn sample_voxels(field: &dyn Field, dims: [usize; 3]) -> Result<Sampled> {
    sample(
        field,
        dims,
        [0.0; 3],
        dims.map(|n| n.saturating_sub(1) as f64),
    )
}

/// A stand-in for the paper's sensed 8-bit data sets (section 5.1), which are not bundled: a
/// noisy 8-bit sphere,
/// `round(255 / (1 + exp((r - radius) / width)) + N(0, noise))` clamped to `[0, 255]`, at
/// integer coordinates (values stay `f32` holding integers). Surfaces at integer isovalues then
/// hit samples exactly and give degenerate triangles, as 8-bit scans do.
pub fn noisy_sphere_u8(
    dims: [usize; 3],
    centre: [f64; 3],
    radius: f64,
    width: f64,
    noise: f64,
    seed: u64,
) -> Result<Sampled> {
    if !(width > 0.0 && noise >= 0.0 && width.is_finite() && noise.is_finite()) {
        return Err(Error::invalid("width", "width must be > 0 and noise >= 0"));
    }
    let mut s = sample_voxels(
        &Logistic {
            centre,
            radius,
            width,
        },
        dims,
    )?;
    let normal = Normal::new(0.0, noise).map_err(|e| Error::invalid("noise", e.to_string()))?;
    let mut r = rng::seeded(seed);
    for v in &mut s.values {
        *v = (*v as f64 + normal.sample(&mut r))
            .round()
            .clamp(0.0, 255.0) as f32;
    }
    Ok(s)
}

/// `255 / (1 + exp((|p - c| - R) / w))`: a smooth ball, bright inside.
#[derive(Clone, Copy, Debug)]
struct Logistic {
    centre: [f64; 3],
    radius: f64,
    width: f64,
}

impl Field for Logistic {
    fn value(&self, p: [f64; 3]) -> f64 {
        255.0 / (1.0 + ((norm(sub(p, self.centre)) - self.radius) / self.width).exp())
    }
    fn gradient(&self, p: [f64; 3]) -> [f64; 3] {
        let d = sub(p, self.centre);
        let r = norm(d).max(1e-300);
        let e = ((r - self.radius) / self.width).exp();
        let k = -255.0 * e / (self.width * (1.0 + e) * (1.0 + e)) / r;
        d.map(|x| k * x)
    }
    fn iso(&self) -> f64 {
        127.5
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot2(a: [f64; 3]) -> f64 {
    a[0] * a[0] + a[1] * a[1] + a[2] * a[2]
}

fn norm(a: [f64; 3]) -> f64 {
    dot2(a).sqrt()
}

/// The centre used by the named sphere and torus on an `n^3` voxel grid: near the grid centre
/// but off the sample lattice (on 64^3 about (30.88, 32.21, 30.83)).
pub fn grid_centre(n: usize) -> [f64; 3] {
    let m = n.saturating_sub(1) as f64;
    [0.4902 * m, 0.5113 * m, 0.4894 * m]
}

/// Names accepted by [`named`].
pub const FIELD_NAMES: [&str; 8] = [
    "sphere",
    "torus",
    "marschner_lobb",
    "genus3",
    "peaks",
    "six_peaks",
    "flower",
    "linear",
];

/// A named field sampled on an `n^3` grid over its usual domain, with the field itself (for
/// exact normals): `sphere` (signed distance, radius `0.3125 n`, centre near the grid centre;
/// R = 20 on 64^3), `torus` (R = `0.25 n`, r = `0.094 n`), `marschner_lobb`,
/// `genus3`, `peaks`, `six_peaks`, `flower`, `linear` (`0.3x + 0.5y + 0.7z + 0.01` in voxel
/// units). The sphere, torus and linear fields are in voxel coordinates.
pub fn named(name: &str, n: usize) -> Result<(Box<dyn Field>, Sampled)> {
    if n < 2 {
        return Err(Error::invalid(
            "n",
            format!("need at least 2 samples per axis, got {n}"),
        ));
    }
    let m = (n - 1) as f64;
    let centre = grid_centre(n);
    let cube = |h: f64| ([-h; 3], [h; 3]);
    let voxels = ([0.0; 3], [m; 3]);
    let (field, (lo, hi)): (Box<dyn Field>, ([f64; 3], [f64; 3])) = match name {
        "sphere" => (
            Box::new(Sphere {
                centre,
                radius: 0.3125 * n as f64,
            }),
            voxels,
        ),
        "torus" => (
            Box::new(Torus {
                centre,
                major: 0.25 * n as f64,
                minor: 0.09375 * n as f64,
            }),
            voxels,
        ),
        "marschner_lobb" => (Box::new(MarschnerLobb::default()), cube(1.0)),
        "genus3" => (Box::new(Genus3), cube(2.0)),
        "peaks" => (Box::new(Peaks), ([-3.0, -3.0, -2.5], [3.0, 3.0, 2.5])),
        "six_peaks" => (Box::new(SixPeaks), cube(1.0)),
        "flower" => (Box::new(Flower), cube(1.0)),
        "linear" => (
            Box::new(Linear {
                a: [0.3, 0.5, 0.7],
                b: 0.01,
            }),
            voxels,
        ),
        other => {
            return Err(Error::invalid(
                "name",
                format!(
                    "{other:?} is not a field; valid: {}",
                    FIELD_NAMES.join(", ")
                ),
            ))
        }
    };
    let s = sample(field.as_ref(), [n; 3], lo, hi)?;
    Ok((field, s))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check_gradient(f: &dyn Field, points: &[[f64; 3]]) {
        for &p in points {
            let g = f.gradient(p);
            for i in 0..3 {
                let h = 1e-6;
                let (mut a, mut b) = (p, p);
                a[i] += h;
                b[i] -= h;
                let d = (f.value(a) - f.value(b)) / (2.0 * h);
                assert!(
                    (d - g[i]).abs() <= 1e-5 * (1.0 + d.abs()),
                    "component {i} at {p:?}: {d} vs {}",
                    g[i]
                );
            }
        }
    }

    #[test]
    fn gradients_match_finite_differences() {
        let pts = [[0.3, -0.2, 0.45], [-0.7, 0.15, -0.3], [0.1, 0.8, 0.05]];
        check_gradient(
            &Sphere {
                centre: [0.1, 0.2, 0.3],
                radius: 0.5,
            },
            &pts,
        );
        check_gradient(
            &Torus {
                centre: [0.0; 3],
                major: 0.5,
                minor: 0.2,
            },
            &pts,
        );
        check_gradient(&MarschnerLobb::default(), &pts);
        check_gradient(&Genus3, &pts);
        check_gradient(&Peaks, &pts);
        check_gradient(&SixPeaks, &pts);
        check_gradient(&Flower, &pts);
        check_gradient(
            &Linear {
                a: [0.3, 0.5, 0.7],
                b: 0.01,
            },
            &pts,
        );
        check_gradient(
            &Logistic {
                centre: [0.0; 3],
                radius: 0.5,
                width: 0.2,
            },
            &pts,
        );
    }
}
