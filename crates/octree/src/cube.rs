//! The octree's domain (a cube) and the Morton order of its finest cells (paper §3).

use wscg_math::{Error, Result};

/// Deepest level a 63-bit Morton code can address (21 bits per axis).
pub const MAX_DEPTH: u8 = 21;

/// An axis-aligned cube: the root cell of the octree.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cube {
    /// Lower corner.
    pub min: [f64; 3],
    /// Side length (> 0).
    pub size: f64,
}

impl Cube {
    /// A cube from its lower corner and side; the side must be finite and positive.
    pub fn new(min: [f64; 3], size: f64) -> Result<Self> {
        if !(size.is_finite() && size > 0.0) || min.iter().any(|v| !v.is_finite()) {
            return Err(Error::invalid(
                "domain",
                format!("a cube needs a finite corner and a positive side, got {min:?}, {size}"),
            ));
        }
        Ok(Self { min, size })
    }

    /// The default domain of a point set: side = largest extent of the bounding box times
    /// `1 + 1e-5`, centred on the box centre, so flat meshes do not lie on a cube face. A
    /// point set of zero extent gets a unit cube around the point.
    pub fn around(lo: [f64; 3], hi: [f64; 3]) -> Self {
        let ext = (0..3).map(|k| hi[k] - lo[k]).fold(0.0f64, f64::max);
        let size = if ext > 0.0 { ext * (1.0 + 1e-5) } else { 1.0 };
        let min = std::array::from_fn(|k| 0.5 * (lo[k] + hi[k]) - 0.5 * size);
        Self { min, size }
    }

    /// Whether the closed cube contains the closed box `[lo, hi]`.
    pub fn contains_box(&self, lo: [f64; 3], hi: [f64; 3]) -> bool {
        (0..3).all(|k| lo[k] >= self.min[k] && hi[k] <= self.min[k] + self.size)
    }

    /// Side of a cell at `level`: `v_w(l) = S / 2^l`.
    #[inline]
    pub fn cell_size(&self, level: u8) -> f64 {
        self.size / (1u64 << level) as f64
    }

    /// Maps a point to grid units of `level` (cells are the unit cubes `[i, i + 1]`).
    #[inline]
    pub fn to_grid(&self, p: [f64; 3], level: u8) -> [f64; 3] {
        let s = (1u64 << level) as f64 / self.size;
        std::array::from_fn(|k| (p[k] - self.min[k]) * s)
    }
}

/// Checks a requested depth against the 21-level Morton budget.
pub fn check_depth(max_depth: u8) -> Result<()> {
    if max_depth > MAX_DEPTH {
        return Err(Error::invalid(
            "max_depth",
            format!(
                "{max_depth} exceeds {MAX_DEPTH}: 2^(3L) cells need a 63-bit Morton code, 21 bits per axis"
            ),
        ));
    }
    Ok(())
}

/// Spreads the low 21 bits of `v` to every third bit.
#[inline]
fn spread(v: u32) -> u64 {
    let mut x = u64::from(v) & 0x1f_ffff;
    x = (x | x << 32) & 0x1f00000000ffff;
    x = (x | x << 16) & 0x1f0000ff0000ff;
    x = (x | x << 8) & 0x100f00f00f00f00f;
    x = (x | x << 4) & 0x10c30c30c30c30c3;
    (x | x << 2) & 0x1249249249249249
}

/// Gathers every third bit of `x` into the low 21 bits.
#[inline]
fn compact(x: u64) -> u32 {
    let mut x = x & 0x1249249249249249;
    x = (x ^ (x >> 2)) & 0x10c30c30c30c30c3;
    x = (x ^ (x >> 4)) & 0x100f00f00f00f00f;
    x = (x ^ (x >> 8)) & 0x1f0000ff0000ff;
    x = (x ^ (x >> 16)) & 0x1f00000000ffff;
    x = (x ^ (x >> 32)) & 0x1f_ffff;
    x as u32
}

/// Morton code of cell `(x, y, z)`: x in bit 0, y in bit 1, z in bit 2 of every triple.
#[inline]
pub fn morton(c: [u32; 3]) -> u64 {
    spread(c[0]) | spread(c[1]) << 1 | spread(c[2]) << 2
}

/// Cell `(x, y, z)` of a Morton code.
#[inline]
pub fn demorton(m: u64) -> [u32; 3] {
    [compact(m), compact(m >> 1), compact(m >> 2)]
}

/// Octant of the child at level `level + 1` that holds the finest cell `m` of a tree of depth
/// `depth`: `(m >> 3 (L - l - 1)) & 7`.
#[inline]
pub fn child_octant(m: u64, level: u8, depth: u8) -> usize {
    ((m >> (3 * u32::from(depth - level - 1))) & 7) as usize
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn morton_round_trips_and_orders_octants() {
        for c in [
            [0, 0, 0],
            [1, 0, 0],
            [0, 1, 0],
            [0, 0, 1],
            [5, 9, 1 << 20],
            [(1 << 21) - 1; 3],
        ] {
            assert_eq!(demorton(morton(c)), c);
        }
        assert_eq!(morton([1, 0, 0]), 1);
        assert_eq!(morton([0, 1, 0]), 2);
        assert_eq!(morton([0, 0, 1]), 4);
        // Octant of (3, 2, 1) below the root of a depth-2 tree: (1, 1, 0) -> 3.
        assert_eq!(child_octant(morton([3, 2, 1]), 0, 2), 3);
        assert_eq!(child_octant(morton([3, 2, 1]), 1, 2), 1 | 4);
    }

    #[test]
    fn around_centres_a_flat_box() {
        let c = Cube::around([0.0, 0.0, 1.0], [2.0, 1.0, 1.0]);
        assert!((c.size - 2.0 * (1.0 + 1e-5)).abs() < 1e-12);
        assert!((c.min[2] + 0.5 * c.size - 1.0).abs() < 1e-12);
        assert!(check_depth(22).is_err() && check_depth(21).is_ok());
    }
}
