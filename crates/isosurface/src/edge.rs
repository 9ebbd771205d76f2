//! The grid edges of marching cubes: which edge a vertex lies on ([`EdgeId`]) and where an
//! edge crosses the isovalue ([`vertex_on_edge`]), shared by the extraction and the normal
//! estimators.

use crate::grid::{Sample, ScalarGrid};

/// The grid edge a vertex lies on: the edge from grid point `point` to `point + e_axis`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct EdgeId {
    /// Low end of the edge (sample indices x, y, z).
    pub point: [u32; 3],
    /// Axis of the edge (0 = x, 1 = y, 2 = z).
    pub axis: u8,
}

impl EdgeId {
    /// The low end as `usize` indices.
    #[inline]
    pub fn low(&self) -> [usize; 3] {
        self.point.map(|c| c as usize)
    }

    /// The high end as `usize` indices.
    #[inline]
    pub fn high(&self) -> [usize; 3] {
        step(self.low(), self.axis as usize)
    }
}

/// Position of the vertex on the edge from `p` along `axis`, and its parameter `t`, when the
/// edge crosses `iso` (both samples defined, exactly one inside).
#[inline]
pub fn vertex_on_edge<T: Sample>(
    g: &ScalarGrid<T>,
    iso: T,
    p: [usize; 3],
    axis: usize,
) -> Option<([T; 3], T)> {
    if p[axis] + 1 >= g.dims[axis] {
        return None;
    }
    let q = step(p, axis);
    let fp = g.value(p)?;
    let fq = g.value(q)?;
    if (fp >= iso) == (fq >= iso) {
        return None;
    }
    let t = (iso - fp) / (fq - fp);
    Some((position(g, p, axis, t), t))
}

/// `p + e_axis`, built without an indexed store (which would stall the next vector load).
#[inline(always)]
fn step(p: [usize; 3], axis: usize) -> [usize; 3] {
    [
        p[0] + (axis == 0) as usize,
        p[1] + (axis == 1) as usize,
        p[2] + (axis == 2) as usize,
    ]
}

/// World position of the point at parameter `t` on the edge from `p` along `axis`.
#[inline]
fn position<T: Sample>(g: &ScalarGrid<T>, p: [usize; 3], axis: usize, t: T) -> [T; 3] {
    let mut v = [T::default(); 3];
    for i in 0..3 {
        let c = T::from_index(p[i]) + if i == axis { t } else { T::default() };
        v[i] = c * g.spacing[i];
    }
    v
}
