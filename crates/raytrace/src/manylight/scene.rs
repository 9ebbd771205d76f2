//! Triangle scenes for many-light rendering (paper 08): Lambertian triangles, some of them
//! emissive, in a bounding volume hierarchy for nearest-hit and shadow rays.

use nalgebra::Vector3;
use rayon::prelude::*;
use wscg_math::vec3::{add, add_scaled, norm, sub};
use wscg_math::{Error, Result};

use crate::bvh::{Aabb, Bvh};

/// Linear RGB.
pub type Rgb = [f64; 3];

/// Luminance of linear RGB (ITU-R BT.709 weights), the scalar importance of the pmfs.
#[inline]
pub fn luminance(c: &Rgb) -> f64 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

/// One triangle, prepared for intersection.
#[derive(Clone, Copy, Debug)]
pub struct Triangle {
    /// First vertex.
    pub p0: [f64; 3],
    /// `p1 - p0`.
    pub e1: [f64; 3],
    /// `p2 - p0`.
    pub e2: [f64; 3],
    /// Unit geometric normal, `e1 x e2` normalised (counter-clockwise front).
    pub normal: [f64; 3],
    /// Area.
    pub area: f64,
}

impl Triangle {
    /// The triangle `a, b, c`; `None` when degenerate (zero area).
    pub fn new(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> Option<Self> {
        let a3 = Vector3::from(a);
        Self::from_edges(
            a,
            (Vector3::from(b) - a3).into(),
            (Vector3::from(c) - a3).into(),
        )
    }

    /// The triangle with first vertex `p0` and edges `e1 = p1 - p0`, `e2 = p2 - p0` (the
    /// fields of a triangle, which rebuild it exactly); `None` when degenerate.
    pub fn from_edges(a: [f64; 3], e1: [f64; 3], e2: [f64; 3]) -> Option<Self> {
        let (a, e1, e2) = (Vector3::from(a), Vector3::from(e1), Vector3::from(e2));
        let n = e1.cross(&e2);
        let len = n.norm();
        let scale = e1.norm() * e2.norm();
        if !(len > 1e-12 * scale && len > 0.0) {
            return None;
        }
        Some(Self {
            p0: a.into(),
            e1: e1.into(),
            e2: e2.into(),
            normal: (n / len).into(),
            area: 0.5 * len,
        })
    }

    /// Möller-Trumbore: the hit parameter along `o + t d` when `t_min < t <= t_max`.
    #[inline]
    pub fn intersect(&self, o: [f64; 3], d: [f64; 3], t_max: f64) -> Option<f64> {
        let (o, d) = (Vector3::from(o), Vector3::from(d));
        let (e1, e2) = (Vector3::from(self.e1), Vector3::from(self.e2));
        let p = d.cross(&e2);
        let det = e1.dot(&p);
        if det.abs() < 1e-300 {
            return None;
        }
        let inv = 1.0 / det;
        let s = o - Vector3::from(self.p0);
        let u = s.dot(&p) * inv;
        if !(0.0..=1.0).contains(&u) {
            return None;
        }
        let q = s.cross(&e1);
        let v = d.dot(&q) * inv;
        if v < 0.0 || u + v > 1.0 {
            return None;
        }
        let t = e2.dot(&q) * inv;
        (t > 0.0 && t <= t_max).then_some(t)
    }

    /// The point at barycentric square coordinates `(u1, u2)` in `[0, 1)^2`, uniform in area.
    pub fn sample(&self, u1: f64, u2: f64) -> [f64; 3] {
        let s = u1.sqrt();
        let (a, b) = (s * (1.0 - u2), s * u2);
        [0, 1, 2].map(|k| self.p0[k] + self.e1[k] * a + self.e2[k] * b)
    }

    /// Bounding box.
    pub fn bounds(&self) -> Aabb {
        let p0 = self.p0;
        Aabb::around(&[p0, add(p0, self.e1), add(p0, self.e2)])
    }
}

/// A ray hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter.
    pub t: f64,
    /// Triangle index.
    pub tri: u32,
    /// Hit point.
    pub pos: [f64; 3],
    /// Unit geometric normal of the triangle (its front side).
    pub normal: [f64; 3],
}

/// Checks per-face albedos (finite, in `[0, 1]`) and emissions (finite, `>= 0`).
fn check_materials(albedo: &[Rgb], emission: &[Rgb]) -> Result<()> {
    for (i, (a, e)) in albedo.iter().zip(emission).enumerate() {
        if a.iter()
            .any(|c| !(c.is_finite() && (0.0..=1.0).contains(c)))
        {
            return Err(Error::invalid(
                "albedo",
                format!("face {i}: {a:?} must lie in [0, 1]"),
            ));
        }
        if e.iter().any(|c| !(c.is_finite() && *c >= 0.0)) {
            return Err(Error::invalid(
                "emission",
                format!("face {i}: {e:?} must be finite and >= 0"),
            ));
        }
    }
    Ok(())
}

/// A scene of Lambertian triangles with per-triangle albedo and emitted radiance.
#[derive(Clone, Debug)]
pub struct Scene {
    tris: Vec<Triangle>,
    albedo: Vec<Rgb>,
    emission: Vec<Rgb>,
    emitters: Vec<u32>,
    bvh: Bvh,
    bounds: Aabb,
    /// Degenerate (zero-area) input triangles that were skipped.
    pub skipped_degenerate: usize,
}

impl Scene {
    /// A scene from an indexed triangle mesh: per-face albedo (in `[0, 1]`) and emitted
    /// radiance (`>= 0`; emitters radiate from their front side, counter-clockwise seen from
    /// the front). Degenerate triangles are skipped and counted.
    ///
    /// Errors: no triangle, a vertex index out of range, a non-finite vertex, per-face arrays
    /// of the wrong length, a negative or non-finite albedo or emission, an albedo above 1.
    pub fn from_triangles(
        vertices: &[[f64; 3]],
        faces: &[[u32; 3]],
        albedo: &[Rgb],
        emission: &[Rgb],
    ) -> Result<Self> {
        if faces.is_empty() {
            return Err(Error::Empty("faces"));
        }
        if albedo.len() != faces.len() || emission.len() != faces.len() {
            return Err(Error::ShapeMismatch(format!(
                "{} faces but {} albedos and {} emissions",
                faces.len(),
                albedo.len(),
                emission.len()
            )));
        }
        for (i, v) in vertices.iter().enumerate() {
            if v.iter().any(|c| !c.is_finite()) {
                return Err(Error::NonFinite {
                    name: "vertices",
                    index: i,
                });
            }
        }
        check_materials(albedo, emission)?;
        let mut tris = Vec::with_capacity(faces.len());
        let mut alb = Vec::with_capacity(faces.len());
        let mut emi = Vec::with_capacity(faces.len());
        let mut skipped = 0;
        for (i, f) in faces.iter().enumerate() {
            let mut p = [[0.0; 3]; 3];
            for k in 0..3 {
                p[k] = *vertices.get(f[k] as usize).ok_or_else(|| {
                    Error::invalid(
                        "faces",
                        format!("face {i} uses vertex {} of {}", f[k], vertices.len()),
                    )
                })?;
            }
            match Triangle::new(p[0], p[1], p[2]) {
                Some(t) => {
                    tris.push(t);
                    alb.push(albedo[i]);
                    emi.push(emission[i]);
                }
                None => skipped += 1,
            }
        }
        if tris.is_empty() {
            return Err(Error::invalid("faces", "every triangle is degenerate"));
        }
        Self::from_parts(tris, alb, emi, skipped)
    }

    /// A scene from its parts: the triangles (see [`Triangle::from_edges`]), their albedo and
    /// emission, and the count of degenerate input triangles that were skipped. The parts of
    /// a scene ([`Self::triangles`], [`Self::albedo`], [`Self::emission`],
    /// [`Self::skipped_degenerate`]) rebuild the same scene.
    ///
    /// Errors: no triangle, per-triangle arrays of another length, a negative or non-finite
    /// albedo or emission, an albedo above 1, a non-finite triangle.
    pub fn from_parts(
        tris: Vec<Triangle>,
        alb: Vec<Rgb>,
        emi: Vec<Rgb>,
        skipped: usize,
    ) -> Result<Self> {
        if tris.is_empty() {
            return Err(Error::Empty("triangles"));
        }
        if alb.len() != tris.len() || emi.len() != tris.len() {
            return Err(Error::ShapeMismatch(format!(
                "{} triangles but {} albedos and {} emissions",
                tris.len(),
                alb.len(),
                emi.len()
            )));
        }
        check_materials(&alb, &emi)?;
        if let Some(index) = tris.iter().position(|t| {
            !(t.p0.iter().chain(&t.e1).chain(&t.e2).all(|c| c.is_finite()) && t.area > 0.0)
        }) {
            return Err(Error::NonFinite {
                name: "triangles",
                index,
            });
        }
        let boxes: Vec<Aabb> = tris.iter().map(Triangle::bounds).collect();
        let bounds = boxes.iter().fold(Aabb::empty(), |a, b| a.union(b));
        let emitters = (0..tris.len() as u32)
            .filter(|&i| luminance(&emi[i as usize]) > 0.0)
            .collect();
        Ok(Self {
            bvh: Bvh::build(&boxes, 4),
            tris,
            albedo: alb,
            emission: emi,
            emitters,
            bounds,
            skipped_degenerate: skipped,
        })
    }

    /// Number of (non-degenerate) triangles.
    pub fn len(&self) -> usize {
        self.tris.len()
    }

    /// Whether the scene has no triangle (never true for a built scene).
    pub fn is_empty(&self) -> bool {
        self.tris.is_empty()
    }

    /// The triangles.
    pub fn triangles(&self) -> &[Triangle] {
        &self.tris
    }

    /// Albedo of triangle `i`.
    pub fn albedo(&self, i: u32) -> Rgb {
        self.albedo[i as usize]
    }

    /// Emitted radiance of triangle `i`.
    pub fn emission(&self, i: u32) -> Rgb {
        self.emission[i as usize]
    }

    /// Indices of the emissive triangles.
    pub fn emitters(&self) -> &[u32] {
        &self.emitters
    }

    /// Bounding box of the scene.
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// Length of the bounding box's diagonal.
    pub fn diagonal(&self) -> f64 {
        self.bounds.diagonal()
    }

    /// The nearest hit along `o + t d` (`d` unit) with `0 < t <= t_max`.
    pub fn intersect(&self, o: [f64; 3], d: [f64; 3], t_max: f64) -> Option<Hit> {
        let (i, t) = self.bvh.nearest(o, d, t_max, |i, tb| {
            self.tris[i as usize].intersect(o, d, tb)
        })?;
        Some(Hit {
            t,
            tri: i,
            pos: add_scaled(o, t, d),
            normal: self.tris[i as usize].normal,
        })
    }

    /// Whether anything lies on the segment from `a` to `b` (both ends excluded by the
    /// caller's offsets).
    pub fn occluded(&self, a: [f64; 3], b: [f64; 3]) -> bool {
        let d = sub(b, a);
        let len = norm(d);
        if len <= 0.0 {
            return false;
        }
        let d = d.map(|c| c / len);
        self.bvh
            .any(a, d, len, |i, tb| self.tris[i as usize].intersect(a, d, tb))
    }

    /// Shadow rays in parallel: whether each segment `origins[i] -> targets[i]` is blocked.
    ///
    /// Errors: slices of different lengths.
    pub fn occluded_batch(&self, origins: &[[f64; 3]], targets: &[[f64; 3]]) -> Result<Vec<bool>> {
        if origins.len() != targets.len() {
            return Err(Error::ShapeMismatch(format!(
                "{} origins but {} targets",
                origins.len(),
                targets.len()
            )));
        }
        Ok(origins
            .par_iter()
            .zip(targets)
            .map(|(a, b)| self.occluded(*a, *b))
            .collect())
    }
}
