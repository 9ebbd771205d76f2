//! The 3-byte voxel code of the Gradient Octree (paper 03, section 4: "three bytes per node
//! including material"): bits 23..18 the material (6 bits, 0..=63), bits 17..9 and 8..0 the
//! unit normal in octahedral coordinates (9 + 9 bits, rounded to nearest), stored big-endian.
//! The split is ours (the paper does not give it); 9 + 9 bits keep the angular error below
//! half a degree.

/// Quantisation levels of each octahedral coordinate.
const LEVELS: f32 = 511.0;

fn sign(v: f32) -> f32 {
    if v >= 0.0 {
        1.0
    } else {
        -1.0
    }
}

/// Octahedral map of a unit vector to `[-1, 1]^2`.
fn octahedral(n: [f32; 3]) -> [f32; 2] {
    let l1 = n[0].abs() + n[1].abs() + n[2].abs();
    if !(l1 > 0.0 && l1.is_finite()) {
        return [0.0, 0.0];
    }
    let (x, y, z) = (n[0] / l1, n[1] / l1, n[2] / l1);
    if z >= 0.0 {
        [x, y]
    } else {
        [(1.0 - y.abs()) * sign(x), (1.0 - x.abs()) * sign(y)]
    }
}

/// Inverse octahedral map, normalised.
fn from_octahedral(p: [f32; 2]) -> [f32; 3] {
    let (mut x, mut y) = (p[0], p[1]);
    let z = 1.0 - x.abs() - y.abs();
    if z < 0.0 {
        (x, y) = (
            (1.0 - p[1].abs()) * sign(p[0]),
            (1.0 - p[0].abs()) * sign(p[1]),
        );
    }
    let l = (x * x + y * y + z * z).sqrt();
    [x / l, y / l, z / l]
}

/// Encodes a material (0..=63; higher bits are dropped) and a unit normal (a zero or
/// non-finite normal encodes as +z).
pub fn encode_voxel(material: u8, n: [f32; 3]) -> [u8; 3] {
    let p = octahedral(n);
    let q = p.map(|c| (((c.clamp(-1.0, 1.0) + 1.0) * 0.5 * LEVELS).round()) as u32);
    let bits = ((material as u32 & 63) << 18) | (q[0] << 9) | q[1];
    [(bits >> 16) as u8, (bits >> 8) as u8, bits as u8]
}

/// Decodes a voxel code into its material and unit normal.
pub fn decode_voxel(c: [u8; 3]) -> (u8, [f32; 3]) {
    let bits = ((c[0] as u32) << 16) | ((c[1] as u32) << 8) | c[2] as u32;
    let q = [(bits >> 9) & 511, bits & 511];
    let p = q.map(|v| v as f32 / LEVELS * 2.0 - 1.0);
    ((bits >> 18) as u8, from_octahedral(p))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normals_round_trip_within_half_a_degree() {
        // 10^6 random unit vectors, max error <= 0.5 deg, mean <= 0.2 deg.
        let u = wscg_math::rng::uniform_vec(6, 3 * 1_000_000, -1.0, 1.0).unwrap();
        let (mut worst, mut sum, mut count) = (0.0f64, 0.0f64, 0usize);
        for v in u.chunks(3) {
            let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            if !(0.1..=1.0).contains(&l) {
                continue;
            }
            let n = [(v[0] / l) as f32, (v[1] / l) as f32, (v[2] / l) as f32];
            let (m, d) = decode_voxel(encode_voxel(17, n));
            assert_eq!(m, 17);
            let dot: f32 = (0..3).map(|k| n[k] * d[k]).sum();
            let err = (dot.clamp(-1.0, 1.0) as f64).acos().to_degrees();
            worst = worst.max(err);
            sum += err;
            count += 1;
        }
        let mean = sum / count as f64;
        println!("{count} normals: max {worst:.3} deg, mean {mean:.3} deg");
        assert!(worst <= 0.5, "max {worst}");
        assert!(mean <= 0.2, "mean {mean}");
    }

    #[test]
    fn materials_round_trip() {
        for m in 0..=63u8 {
            assert_eq!(decode_voxel(encode_voxel(m, [0.0, -1.0, 0.0])).0, m);
        }
        let (_, n) = decode_voxel(encode_voxel(5, [0.0, 0.0, 0.0]));
        assert!((n[2] - 1.0).abs() < 1e-4, "{n:?}");
        let (_, n) = decode_voxel(encode_voxel(5, [0.0, 0.0, -1.0]));
        assert!((n[2] + 1.0).abs() < 1e-4, "{n:?}");
    }
}
