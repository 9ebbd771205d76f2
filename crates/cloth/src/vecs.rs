//! The public 3-vector is `[f64; 3]`; the solvers compute with nalgebra's `Vector3<f64>`,
//! which has the same size and alignment. These views convert whole slices and vectors
//! between the two without copying, checked by bytemuck (no `unsafe` here).

use nalgebra::Vector3;

/// The solvers' 3-vector.
pub(crate) type V3 = Vector3<f64>;

/// `[f64; 3]` points as nalgebra vectors (the same memory).
#[inline]
pub(crate) fn v3s(a: &[[f64; 3]]) -> &[V3] {
    bytemuck::cast_slice(a)
}

/// nalgebra vectors as `[f64; 3]` points (the same memory).
#[inline]
pub(crate) fn arrays(a: &[V3]) -> &[[f64; 3]] {
    bytemuck::cast_slice(a)
}

/// A vector of nalgebra vectors as one of `[f64; 3]` points (the same allocation).
#[inline]
pub(crate) fn into_arrays(a: Vec<V3>) -> Vec<[f64; 3]> {
    bytemuck::allocation::cast_vec(a)
}
