//! Local frames around a direction.

use nalgebra::Vector3;

/// Two unit tangents completing the unit vector `n` to an orthonormal frame `(t, b, n)`.
pub(crate) fn tangent_frame(n: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let helper = if n.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let t = n.cross(&helper).normalize();
    (t, n.cross(&t))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_is_orthonormal() {
        for n in [
            Vector3::x(),
            Vector3::new(0.3, -0.5, 0.8).normalize(),
            -Vector3::z(),
        ] {
            let (t, b) = tangent_frame(&n);
            for (u, v) in [(t, b), (t, n), (b, n)] {
                assert!(u.dot(&v).abs() < 1e-12);
            }
            assert!((t.norm() - 1.0).abs() < 1e-12 && (b.norm() - 1.0).abs() < 1e-12);
            assert!((t.cross(&b) - n).norm() < 1e-12);
        }
    }
}
