//! Triangle / axis-aligned box overlap by the separating-axis theorem (Akenine-Möller 2001):
//! the 3 box axes, the triangle normal and the 9 cross products of a box axis with a triangle
//! edge. The box is closed, so touching counts as overlap; this is what makes the voxelization
//! conservative and the octree traversal exact.

use wscg_math::vec3::{cross, sub};

/// Half-side of a unit grid cell used by the voxelizer: `0.5` widened by `1e-7` cells, so that
/// rounding of the grid coordinates never drops a cell the triangle touches.
pub const CELL_HALF: f64 = 0.5 + 1e-7;

/// Whether triangle `(a, b, c)` overlaps the closed cube of centre `centre` and half-side `h`.
#[inline]
pub fn tri_box_overlap(centre: [f64; 3], h: f64, a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> bool {
    let v = [sub(a, centre), sub(b, centre), sub(c, centre)];
    // Box axes: the triangle's bounding box against the cube.
    for ((&a, &b), &c) in v[0].iter().zip(&v[1]).zip(&v[2]) {
        let lo = a.min(b).min(c);
        let hi = a.max(b).max(c);
        if lo > h || hi < -h {
            return false;
        }
    }
    let e = [sub(v[1], v[0]), sub(v[2], v[1]), sub(v[0], v[2])];
    // Triangle normal: the plane against the cube's projection radius.
    let n = cross(e[0], e[2]);
    let d = n[0] * v[0][0] + n[1] * v[0][1] + n[2] * v[0][2];
    let r = h * (n[0].abs() + n[1].abs() + n[2].abs());
    if d > r || d < -r {
        return false;
    }
    // Edge x box-axis: axis u_k x e = (0,-e.z,e.y), (e.z,0,-e.x), (-e.y,e.x,0).
    for ed in &e {
        let axes = [
            [0.0, -ed[2], ed[1]],
            [ed[2], 0.0, -ed[0]],
            [-ed[1], ed[0], 0.0],
        ];
        for ax in &axes {
            let p0 = ax[0] * v[0][0] + ax[1] * v[0][1] + ax[2] * v[0][2];
            let p1 = ax[0] * v[1][0] + ax[1] * v[1][1] + ax[2] * v[1][2];
            let p2 = ax[0] * v[2][0] + ax[1] * v[2][1] + ax[2] * v[2][2];
            let lo = p0.min(p1).min(p2);
            let hi = p0.max(p1).max(p2);
            let r = h * (ax[0].abs() + ax[1].abs() + ax[2].abs());
            if lo > r || hi < -r {
                return false;
            }
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_cases() {
        let c = [0.5; 3];
        // Inside, touching a face, touching only an edge, just outside, crossing diagonally.
        assert!(tri_box_overlap(
            c,
            0.5,
            [0.2, 0.2, 0.5],
            [0.8, 0.2, 0.5],
            [0.2, 0.8, 0.5]
        ));
        assert!(tri_box_overlap(
            c,
            0.5,
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [1.0, 0.0, 1.0]
        ));
        assert!(tri_box_overlap(
            c,
            0.5,
            [1.0, 1.0, 0.0],
            [2.0, 2.0, 0.0],
            [2.0, 0.5, 1.0]
        ));
        assert!(!tri_box_overlap(
            c,
            0.5,
            [1.01, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [2.0, 1.0, 1.0]
        ));
        // A triangle whose bounding box covers the cube but which passes beside its corner:
        // only an edge axis separates it.
        assert!(!tri_box_overlap(
            c,
            0.5,
            [2.1, 0.0, 0.5],
            [0.0, 2.1, 0.5],
            [2.1, 2.1, 0.5]
        ));
        assert!(tri_box_overlap(
            c,
            0.5,
            [1.9, 0.0, 0.5],
            [0.0, 1.9, 0.5],
            [2.1, 2.1, 0.5]
        ));
        // Plane separation: a tilted triangle above the corner (1,1,1).
        assert!(!tri_box_overlap(
            c,
            0.5,
            [3.1, 0.0, 0.0],
            [0.0, 3.1, 0.0],
            [0.0, 0.0, 3.1]
        ));
        assert!(tri_box_overlap(
            c,
            0.5,
            [2.9, 0.0, 0.0],
            [0.0, 2.9, 0.0],
            [0.0, 0.0, 2.9]
        ));
    }
}
