//! The voxels under a scalar field and their reconstruction: values in `[0, 1]`, `x`
//! fastest, voxel `i` centred at `i`, trilinear (edge-clamped) or nearest sampling inside the
//! box `[-1/2, n - 1/2]` and 0 outside. The field, the value ranges of its cells and the
//! Phong ray caster's bricks are all built on them.

/// Reconstruction filter of the scalar field.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Interp {
    /// Trilinear interpolation of the eight surrounding voxels (edge-clamped).
    #[default]
    Trilinear,
    /// The nearest voxel, `floor(p + 1/2)`.
    Nearest,
}

/// The voxel grid of a field.
#[derive(Clone, Debug)]
pub(crate) struct Voxels {
    /// Voxel counts `[nx, ny, nz]`.
    pub(crate) dims: [usize; 3],
    /// World units per voxel along each axis (`spacing / min(spacing)`).
    pub(crate) scale: [f64; 3],
    /// Normalised values, `x` fastest.
    pub(crate) data: Vec<f32>,
}

impl Voxels {
    /// The sample at `p` in **voxel** coordinates; 0 outside the box `[-1/2, n - 1/2]`.
    #[inline]
    pub(crate) fn sample(&self, p: [f32; 3], interp: Interp) -> f32 {
        if !self.contains(p) {
            return 0.0;
        }
        self.sample_inside(p, interp)
    }

    /// True if `p` (voxel coordinates) lies in the box `[-1/2, n - 1/2)`.
    #[inline]
    pub(crate) fn contains(&self, p: [f32; 3]) -> bool {
        let inside = |c: f32, n: usize| c >= -0.5 && c < n as f32 - 0.5;
        inside(p[0], self.dims[0]) && inside(p[1], self.dims[1]) && inside(p[2], self.dims[2])
    }

    /// The sample at `p` known to be inside the box (coordinates are clamped to it).
    #[inline(always)]
    pub(crate) fn sample_inside(&self, p: [f32; 3], interp: Interp) -> f32 {
        match interp {
            Interp::Trilinear => self.trilinear_inside(p),
            Interp::Nearest => self.nearest_inside(p),
        }
    }

    /// Nearest sample of a point known to be inside the box.
    #[inline]
    fn nearest_inside(&self, p: [f32; 3]) -> f32 {
        let [nx, ny, nz] = self.dims;
        self.data
            [axis_nearest(p[0], nx) + nx * (axis_nearest(p[1], ny) + ny * axis_nearest(p[2], nz))]
    }

    /// Trilinear sample of a point known to be inside the box (edge-clamped).
    #[inline(always)]
    fn trilinear_inside(&self, p: [f32; 3]) -> f32 {
        let [nx, ny, nz] = self.dims;
        let (x0, x1, tx) = axis_cell(p[0], nx);
        let (y0, y1, ty) = axis_cell(p[1], ny);
        let (z0, z1, tz) = axis_cell(p[2], nz);
        let d = &self.data;
        let r00 = nx * (y0 + ny * z0);
        let r10 = nx * (y1 + ny * z0);
        let r01 = nx * (y0 + ny * z1);
        let r11 = nx * (y1 + ny * z1);
        let l = |a: f32, b: f32, t: f32| a + (b - a) * t;
        let c00 = l(d[r00 + x0], d[r00 + x1], tx);
        let c10 = l(d[r10 + x0], d[r10 + x1], tx);
        let c01 = l(d[r01 + x0], d[r01 + x1], tx);
        let c11 = l(d[r11 + x0], d[r11 + x1], tx);
        l(l(c00, c10, ty), l(c01, c11, ty), tz)
    }

    /// Gradient by central differences of samples one voxel apart, in value per world unit:
    /// the definition the Phong ray caster's bricks reproduce (their test's reference).
    #[cfg(test)]
    pub(crate) fn gradient(&self, p: [f32; 3], interp: Interp) -> [f32; 3] {
        std::array::from_fn(|a| {
            let mut lo = p;
            let mut hi = p;
            lo[a] -= 1.0;
            hi[a] += 1.0;
            0.5 * (self.sample(hi, interp) - self.sample(lo, interp)) / self.scale[a] as f32
        })
    }
}

/// The voxel along one axis nearest to coordinate `c`, `floor(c + 1/2)` clamped to `[0, n - 1]`.
#[inline]
pub(crate) fn axis_nearest(c: f32, n: usize) -> usize {
    ((c + 0.5).floor().max(0.0) as usize).min(n - 1)
}

/// The two voxels along one axis that a trilinear sample at coordinate `c` interpolates, and
/// the weight of the second: edge-clamped to `[0, n - 1]`.
#[inline]
pub(crate) fn axis_cell(c: f32, n: usize) -> (usize, usize, f32) {
    let c = c.clamp(0.0, (n - 1) as f32);
    let i = (c as usize).min(n.saturating_sub(2));
    let t = c - i as f32;
    (i, (i + 1).min(n - 1), t)
}
