//! Many-light rendering with adaptive importance caching (paper 08: Yoshida, Nabata,
//! Iwasaki, Dobashi and Nishita, "Adaptive importance caching for many-light rendering",
//! on top of Georgiev et al. 2012's importance caching).
//!
//! - [`scene`]: Lambertian triangle scenes with emitters, nearest-hit and shadow rays.
//! - [`camera`]: the pinhole camera.

pub mod camera;
pub mod scene;

pub use camera::{Camera, CameraFrame};
pub use scene::{luminance, Hit, Rgb, Scene, Triangle};
