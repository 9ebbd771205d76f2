//! Triangle ray-casting baselines: brute force over every triangle (the reference of the
//! equivalence checks) and a binned-SAH bounding volume hierarchy ([`wscg_math::bvh`]), the
//! structure a ray tracer would otherwise use.

use rayon::prelude::*;
use wscg_math::bvh::{Aabb, Bvh};
use wscg_math::{Error, Result, TriMesh};

use crate::octree::Tri;
use crate::traverse::{intersect_tri, Ray};

/// Nearest triangle hit `(prim, t, u, v)` with `t` in the ray's range, testing every triangle.
pub fn brute_force(tris: &[Tri], ray: &Ray) -> Option<(u32, f32, f32, f32)> {
    let mut best: Option<(u32, f32, f32, f32)> = None;
    for (i, tri) in tris.iter().enumerate() {
        if let Some((t, u, v)) = intersect_tri(tri, ray.origin, ray.dir) {
            if t >= ray.t_min.max(0.0) && t <= ray.t_max && best.is_none_or(|b| t < b.1) {
                best = Some((i as u32, t, u, v));
            }
        }
    }
    best
}

/// A binned-SAH BVH over a mesh's triangles, intersected with the same Möller-Trumbore test as
/// the octree.
pub struct TriangleBvh {
    bvh: Bvh,
    tris: Vec<Tri>,
}

impl TriangleBvh {
    /// Builds the hierarchy (4 triangles per leaf where the SAH allows it).
    pub fn build(mesh: &TriMesh) -> Result<Self> {
        mesh.validate()?;
        if mesh.faces.is_empty() {
            return Err(Error::Empty("mesh faces"));
        }
        let boxes: Vec<Aabb> = mesh
            .faces
            .par_iter()
            .map(|f| Aabb::around(&f.map(|i| mesh.positions[i as usize])))
            .collect();
        let tris = crate::octree::prepare(mesh);
        Ok(Self {
            bvh: Bvh::build(&boxes, 4),
            tris,
        })
    }

    /// Nearest hit `(prim, t, u, v)` with `t` in the ray's range.
    pub fn intersect(&self, ray: &Ray) -> Option<(u32, f32, f32, f32)> {
        let o = ray.origin.map(f64::from);
        let d = ray.dir.map(f64::from);
        let t_min = ray.t_min.max(0.0);
        // Every accepted hit improves on the previous one, so the last accepted is the nearest.
        let mut last = None;
        self.bvh.nearest(o, d, f64::from(ray.t_max), |i, tb| {
            let (t, u, v) = intersect_tri(&self.tris[i as usize], ray.origin, ray.dir)?;
            (t >= t_min && f64::from(t) < tb).then(|| {
                last = Some((i, t, u, v));
                f64::from(t)
            })
        })?;
        last
    }
}
