//! Many-light rendering with adaptive importance caching (paper 08: Yoshida, Nabata,
//! Iwasaki, Dobashi and Nishita, "Adaptive importance caching for many-light rendering",
//! on top of Georgiev et al. 2012's importance caching).
//!
//! - [`scene`]: Lambertian triangle scenes with emitters, nearest-hit and shadow rays.
//! - [`scenes`], [`obj`]: procedural test scenes (Cornell box, colonnade, conference room,
//!   plane with a light) and Wavefront OBJ + MTL scenes.
//! - [`camera`], [`gbuffer`]: the pinhole camera and the shading point of each pixel.
//! - [`vpl`]: virtual point lights from light paths.
//! - [`shading`]: one VPL's contribution (eq. 1), the reference sum.
//! - [`pmf`], [`cache`]: records and their four distributions.
//! - [`near`]: beyond the paper, each pixel's distribution over its nearest VPLs.
//! - [`weights`]: the similarity weights of eqs. (2)-(4).
//! - [`placement`]: screen-grid records (the baseline), clustering and adaptive insertion.
//! - [`mod@render`]: the alpha-max estimator, the reference, power sampling, pixel filters.
//! - [`method`]: every method of the comparison behind one call.

pub mod cache;
pub mod camera;
pub mod gbuffer;
pub mod method;
pub mod near;
pub mod obj;
pub mod placement;
pub mod pmf;
pub mod render;
pub mod scene;
pub mod scenes;
pub mod shading;
pub mod vpl;
pub mod weights;

pub use cache::{Distributions, ImportanceCache, Record};
pub use camera::{Camera, CameraFrame};
pub use gbuffer::{trace_primary, GBuffer, ShadingPoint};
pub use method::{compare, run, run_with, to_display, ManyLightParams, ManyLightResult, Method};
pub use obj::load_obj;
pub use placement::{AdaptiveParams, Placement};
pub use render::{
    build_cache, render, render_power, render_reference, render_reference_filtered, CacheStats,
    ImportanceCachingParams, PixelFilter, DEFAULT_NEAR_SHARE, DEFAULT_NEAR_VPLS,
};
pub use scene::{luminance, Hit, Rgb, Scene, Triangle};
pub use scenes::{colonnade, conference_room, cornell_box, plane_with_light};
pub use shading::{Receiver, Shading};
pub use vpl::{generate_vpls, Vpl, VplKind, VplParams};
pub use weights::{Interp, DEFAULT_DEFENSIVE};
