//! What the renderer and the photon tracer see of a plate: the nearest flake along a ray
//! ([`Microstructure`]) and the plate ready to render, its layers with its flakes ([`Plate`]).

use num_complex::Complex64;
use wscg_math::Result;

use super::layers::PlateStack;

/// A flake hit: distance along the ray, unit normal of the flake (either orientation), and a
/// flake identifier unique over the plate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlakeHit {
    /// Ray parameter of the hit (µm when the direction is a unit vector).
    pub t: f64,
    /// Unit normal of the flake's disc.
    pub normal: [f64; 3],
    /// Identifier of the flake.
    pub id: u64,
}

/// What the renderer needs of the binder's microstructure: the nearest flake along a ray.
/// Coordinates in µm: `x, y` in the plate's plane with the plate's centre at the origin (x
/// right, y towards the plate's top edge), `z` from the base (0) to the binder's top.
pub trait Microstructure: Send + Sync {
    /// The nearest flake hit with `0 < t <= t_max` along `origin + t dir` (`dir` unit).
    fn hit(&self, origin: [f64; 3], dir: [f64; 3], t_max: f64) -> Option<FlakeHit>;
}

/// A binder without flakes.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoFlakes;

impl Microstructure for NoFlakes {
    fn hit(&self, _: [f64; 3], _: [f64; 3], _: f64) -> Option<FlakeHit> {
        None
    }
}

/// A plate ready to render: its layers and its flakes. Build it once and render every view
/// from it, so that the left and right eyes see the same microstructure.
pub struct Plate {
    /// The layers.
    pub stack: PlateStack,
    micro: Box<dyn Microstructure>,
}

impl Plate {
    /// A plate from its layers and microstructure.
    ///
    /// Errors: invalid layers ([`PlateStack::validate`]).
    pub fn new(stack: PlateStack, micro: Box<dyn Microstructure>) -> Result<Self> {
        stack.validate()?;
        Ok(Self { stack, micro })
    }

    /// The nearest flake along a ray (plate coordinates, µm).
    pub fn hit(&self, origin: [f64; 3], dir: [f64; 3], t_max: f64) -> Option<FlakeHit> {
        self.micro.hit(origin, dir, t_max)
    }

    /// `(n + i k) / n_binder` of the flakes at `lambda_nm`: they sit in the binder.
    pub fn relative_index(&self, lambda_nm: f64) -> Complex64 {
        let (n, k) = self.stack.metal.nk(lambda_nm);
        Complex64::new(n, k) / self.stack.binder_ior
    }
}
