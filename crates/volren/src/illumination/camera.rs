//! The orthographic camera and its view-aligned slices: pixel `(i, j)` at
//! depth `z` is the world point `C + (i - W/2 + 1/2) h r + (j - H/2 + 1/2) h v + z d`, with
//! `d` the view direction, `r = d x up` (image right) and `v = d x r` (image down); slices are
//! the planes `z_n = z_start + (n + 1/2) ds` covering the volume's depth range, shared by all
//! pixels.

use wscg_math::vec3::{add_scaled, cross, dot, sub, try_normalize};
use wscg_math::{Error, Result};

use super::field::ScalarField;

type V3 = [f64; 3];

/// An orthographic camera in world units (see [`ScalarField`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SliceCamera {
    /// Viewing direction (need not be unit length).
    pub dir: V3,
    /// Up vector (not parallel to `dir`).
    pub up: V3,
    /// World point at the image centre (depth 0).
    pub center: V3,
    /// Image width in pixels.
    pub width: usize,
    /// Image height in pixels.
    pub height: usize,
    /// Pixel size in world units.
    pub pixel_size: f64,
}

impl SliceCamera {
    /// A camera looking along `dir` at the volume's centre whose `width x height` image holds
    /// the volume's whole projection with a 2 % border. Errors: as [`SliceCamera::frame`].
    pub fn fit(field: &ScalarField, dir: V3, up: V3, width: usize, height: usize) -> Result<Self> {
        let mut cam = Self {
            dir,
            up,
            center: field.world_center(),
            width,
            height,
            pixel_size: 1.0,
        };
        let f = cam.frame()?;
        let (lo, hi) = field.world_box();
        let (mut ext_r, mut ext_v) = (0f64, 0f64);
        for corner in corners(lo, hi) {
            let q = sub(corner, cam.center);
            ext_r = ext_r.max(dot(q, f.right).abs());
            ext_v = ext_v.max(dot(q, f.down).abs());
        }
        let h = (2.0 * ext_r / width as f64).max(2.0 * ext_v / height as f64) * 1.02;
        cam.pixel_size = if h > 0.0 { h } else { 1.0 };
        Ok(cam)
    }

    /// A camera on an orbit around the volume: azimuth about the volume's `z` axis and
    /// elevation above its `xy` plane (degrees), looking at the centre, `size x size` pixels,
    /// the whole volume in view. Errors: as [`SliceCamera::fit`].
    pub fn orbit(field: &ScalarField, azimuth: f64, elevation: f64, size: usize) -> Result<Self> {
        let (a, e) = (azimuth.to_radians(), elevation.to_radians());
        let dir = [-e.cos() * a.cos(), -e.cos() * a.sin(), -e.sin()];
        let up = if e.cos().abs() < 1e-6 {
            [0.0, 1.0, 0.0]
        } else {
            [0.0, 0.0, 1.0]
        };
        Self::fit(field, dir, up, size, size)
    }

    /// The camera frame. Errors: zero image size or more than 2^26 pixels, pixel size not
    /// finite and positive, non-finite vectors, zero `dir`, `up` parallel to `dir`.
    pub fn frame(&self) -> Result<Frame> {
        if self.width == 0 || self.height == 0 || self.width.saturating_mul(self.height) > 1 << 26 {
            return Err(Error::invalid(
                "size",
                format!(
                    "image size {}x{} must be positive and at most 2^26 pixels",
                    self.width, self.height
                ),
            ));
        }
        if !(self.pixel_size.is_finite() && self.pixel_size > 0.0) {
            return Err(Error::invalid(
                "pixel_size",
                format!("must be finite and > 0, got {}", self.pixel_size),
            ));
        }
        let finite = |v: V3| v.iter().all(|c| c.is_finite());
        if !(finite(self.dir) && finite(self.up) && finite(self.center)) {
            return Err(Error::invalid(
                "camera",
                "dir, up and center must be finite",
            ));
        }
        let d = try_normalize(self.dir, 1e-12)
            .ok_or_else(|| Error::invalid("view_dir", "must not be zero"))?;
        let right = try_normalize(cross(d, self.up), 1e-9)
            .ok_or_else(|| Error::invalid("up", "must not be parallel to the view direction"))?;
        let down = cross(d, right);
        Ok(Frame {
            d,
            right,
            down,
            center: self.center,
            h: self.pixel_size,
            width: self.width,
            height: self.height,
        })
    }
}

/// The eight corners of a box.
pub(crate) fn corners(lo: V3, hi: V3) -> impl Iterator<Item = V3> {
    (0..8).map(move |k| std::array::from_fn(|a| if k >> a & 1 == 1 { hi[a] } else { lo[a] }))
}

/// A validated camera: unit view direction `d`, image right `right` and image down `down`.
#[derive(Clone, Copy, Debug)]
pub struct Frame {
    /// Unit view direction.
    pub d: V3,
    /// Unit image-right vector.
    pub right: V3,
    /// Unit image-down vector.
    pub down: V3,
    /// World point at the image centre, depth 0.
    pub center: V3,
    /// Pixel size (world units).
    pub h: f64,
    /// Image width.
    pub width: usize,
    /// Image height.
    pub height: usize,
}

impl Frame {
    /// World point of pixel position `(x, y)` (pixel centres at `i + 1/2` offsets handled by
    /// the caller) at depth `z`: `x` and `y` are pixel indices, possibly outside the image.
    pub fn point(&self, x: f64, y: f64, z: f64) -> V3 {
        let px = (x - 0.5 * self.width as f64 + 0.5) * self.h;
        let py = (y - 0.5 * self.height as f64 + 0.5) * self.h;
        add_scaled(
            add_scaled(add_scaled(self.center, px, self.right), py, self.down),
            z,
            self.d,
        )
    }

    /// The voxel coordinates of pixel `(x0, y0)` at depth 0 and the voxel-space steps of one
    /// pixel right, one pixel down and one world unit in depth (the renderers' incremental
    /// sample positions).
    pub fn voxel_steps(&self, field: &ScalarField, x0: f64, y0: f64) -> [[f32; 3]; 4] {
        let s = field.scale();
        let to_vox = |p: V3| -> [f32; 3] { std::array::from_fn(|a| (p[a] / s[a]) as f32) };
        [
            to_vox(self.point(x0, y0, 0.0)),
            to_vox(self.right.map(|c| c * self.h)),
            to_vox(self.down.map(|c| c * self.h)),
            to_vox(self.d),
        ]
    }

    /// Depth range `[z_min, z_max]` of the volume box along `d`.
    pub fn depth_range(&self, field: &ScalarField) -> (f64, f64) {
        let (lo, hi) = field.world_box();
        corners(lo, hi)
            .map(|c| dot(sub(c, self.center), self.d))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), z| {
                (a.min(z), b.max(z))
            })
    }

    /// The pixel rectangle `[x0, x1) x [y0, y1)` (possibly outside the image) covering the
    /// box's projection.
    pub fn footprint(&self, field: &ScalarField) -> [i64; 4] {
        let (lo, hi) = field.world_box();
        let (mut x0, mut x1, mut y0, mut y1) = (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        );
        for c in corners(lo, hi) {
            let q = sub(c, self.center);
            let x = dot(q, self.right) / self.h + 0.5 * self.width as f64 - 0.5;
            let y = dot(q, self.down) / self.h + 0.5 * self.height as f64 - 0.5;
            x0 = x0.min(x);
            x1 = x1.max(x);
            y0 = y0.min(y);
            y1 = y1.max(y);
        }
        [
            x0.floor() as i64 - 1,
            x1.ceil() as i64 + 2,
            y0.floor() as i64 - 1,
            y1.ceil() as i64 + 2,
        ]
    }

    /// The world direction of a light given in view coordinates (`x` right, `y` up, `z`
    /// towards the viewer), pointing towards the light.
    pub fn light_world(&self, l: V3) -> V3 {
        let v = add_scaled(add_scaled([0.0; 3], l[0], self.right), -l[1], self.down);
        add_scaled(v, -l[2], self.d)
    }
}

/// The slices of one render: `n` planes at depths `z_start + (k + 1/2) ds`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Slicing {
    /// Front of the volume's depth range (along `d`, relative to the camera centre).
    pub z_start: f64,
    /// Slice distance (world units).
    pub ds: f64,
    /// Number of slices.
    pub n: usize,
}

impl Slicing {
    /// Slices of distance `ds` covering the volume's depth range.
    pub fn new(frame: &Frame, field: &ScalarField, ds: f64) -> Self {
        let (z0, z1) = frame.depth_range(field);
        let n = (((z1 - z0) / ds) - 1e-9).ceil().max(1.0) as usize;
        Self { z_start: z0, ds, n }
    }

    /// [`Slicing::new`], refusing more than `max` slices (`name` is the distance's argument
    /// name in the error).
    pub fn bounded(
        frame: &Frame,
        field: &ScalarField,
        ds: f64,
        max: usize,
        name: &'static str,
    ) -> Result<Self> {
        let s = Self::new(frame, field, ds);
        if s.n > max {
            return Err(Error::invalid(
                name,
                format!(
                    "{ds} gives {} slices or samples per ray through the volume (at most {max})",
                    s.n
                ),
            ));
        }
        Ok(s)
    }

    /// Depth of slice `k`.
    pub fn z(&self, k: usize) -> f64 {
        self.z_start + (k as f64 + 0.5) * self.ds
    }
}
