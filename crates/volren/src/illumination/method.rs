//! Rendering methods, light and settings (paper §3 and the baselines of §5.1).

use wscg_math::{Error, Result};

use super::field::Interp;
use super::kernel::Kernel;

/// Most tissue sub-samples per slice accepted.
pub const MAX_SUBSAMPLES: u32 = 64;

/// How the light is attenuated between two slices when there are sub-samples (the paper does
/// not say).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LightAtten {
    /// By every tissue sample of the segment, each with its own opacity correction.
    #[default]
    Segment,
    /// By the slice sample only, corrected to the slice distance.
    SliceOnly,
}

/// What the light propagated through the slices meets outside the volume's box (the paper
/// renders a volume in empty space and does not say; its light buffer starts at the slicing's
/// first slice).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LightBorder {
    /// The outside of the box is empty: light passes round an occluder that does not reach
    /// the box's sides and, with a blurring kernel, leaks in under its edges from outside.
    #[default]
    Open,
    /// The outside of the box is opaque to the propagated light beyond every face that is
    /// not turned towards the light (the sides for a light along an axis, and the back): the
    /// light enters only through the faces turned towards it, so a blurring kernel cannot
    /// carry light from outside round an occluder. Without blur (the delta kernel) nothing
    /// changes, since light moving away from the light never re-enters the box through such
    /// a face. The shadow-ray caster's rays leave the box only through the faces turned
    /// towards the light, so it is the same for both borders.
    Closed,
}

/// Blinn-Phong weights of the local-illumination baseline.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Phong {
    /// Ambient weight.
    pub ka: f32,
    /// Diffuse weight.
    pub kd: f32,
    /// Specular weight.
    pub ks: f32,
    /// Specular exponent.
    pub shininess: f32,
}

impl Default for Phong {
    fn default() -> Self {
        Self {
            ka: 0.3,
            kd: 0.6,
            ks: 0.3,
            shininess: 20.0,
        }
    }
}

/// A rendering method: the paper's four slice-based variants and its baselines.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Method {
    /// Ray casting, emission-absorption, no lighting (baseline 1), samples `step` apart.
    RaycastEa {
        /// Sample distance (world units).
        step: f32,
    },
    /// Ray casting with Blinn-Phong local illumination (baseline 2).
    RaycastPhong {
        /// Sample distance (world units).
        step: f32,
        /// Shading weights.
        phong: Phong,
    },
    /// Ray casting with a Beer-Lambert shadow ray per sample (validation baseline 7).
    ShadowRays {
        /// Sample distance along the view and the shadow rays (world units).
        step: f32,
    },
    /// Slice-based instant convolution shadows: ICS (`subsamples = 0`), SCS (`subsamples >
    /// 0`), PI-ICS and PI-SCS (`preintegrated`).
    Ics {
        /// Slice distance `ds` (world units).
        slice: f32,
        /// Tissue sub-samples `m` between slices (tissue step `ds / (m + 1)`, the formula of
        /// §5.2).
        subsamples: u32,
        /// Pre-integrated classification of each tissue segment (§3.1).
        preintegrated: bool,
        /// Light attenuation between slices.
        light_atten: LightAtten,
    },
}

impl Method {
    /// Instant convolution shadows at slice distance `slice`.
    pub fn ics(slice: f32) -> Self {
        Method::Ics {
            slice,
            subsamples: 0,
            preintegrated: false,
            light_atten: LightAtten::Segment,
        }
    }

    /// Supersampled convolution shadows: `m` tissue sub-samples per slice.
    pub fn scs(slice: f32, m: u32) -> Self {
        Method::Ics {
            slice,
            subsamples: m,
            preintegrated: false,
            light_atten: LightAtten::Segment,
        }
    }

    /// Pre-integrated (supersampled when `m > 0`) convolution shadows.
    pub fn pi_scs(slice: f32, m: u32) -> Self {
        Method::Ics {
            slice,
            subsamples: m,
            preintegrated: true,
            light_atten: LightAtten::Segment,
        }
    }

    /// Short name: `ics`, `scs`, `pi-ics`, `pi-scs`, `raycast`, `phong`, `shadow-rays`.
    pub fn name(&self) -> &'static str {
        match *self {
            Method::RaycastEa { .. } => "raycast",
            Method::RaycastPhong { .. } => "phong",
            Method::ShadowRays { .. } => "shadow-rays",
            Method::Ics {
                subsamples,
                preintegrated,
                ..
            } => match (preintegrated, subsamples > 0) {
                (false, false) => "ics",
                (false, true) => "scs",
                (true, false) => "pi-ics",
                (true, true) => "pi-scs",
            },
        }
    }

    /// Errors: a distance not finite and positive, more than [`MAX_SUBSAMPLES`] sub-samples.
    pub fn check(&self) -> Result<()> {
        let positive = |name: &'static str, v: f32| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(Error::invalid(
                    name,
                    format!("must be finite and > 0, got {v}"),
                ))
            }
        };
        match *self {
            Method::RaycastEa { step } | Method::ShadowRays { step } => positive("step", step),
            Method::RaycastPhong { step, phong } => {
                positive("step", step)?;
                let w = [phong.ka, phong.kd, phong.ks, phong.shininess];
                if w.iter().all(|v| v.is_finite() && *v >= 0.0) {
                    Ok(())
                } else {
                    Err(Error::invalid("phong", "weights must be finite and >= 0"))
                }
            }
            Method::Ics {
                slice, subsamples, ..
            } => {
                positive("slice_distance", slice)?;
                if subsamples > MAX_SUBSAMPLES {
                    return Err(Error::invalid(
                        "subsamples",
                        format!("at most {MAX_SUBSAMPLES}, got {subsamples}"),
                    ));
                }
                Ok(())
            }
        }
    }
}

/// The light: a direction in view coordinates (`x` right, `y` up, `z` towards the viewer;
/// `(0, 0, 1)` is the headlight), an ambient term and the propagation kernel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Light {
    /// Direction towards the light in view coordinates; `z > 0` required.
    pub dir_view: [f64; 3],
    /// Ambient term `k_a` of the shading `S = k_a + (1 - k_a) L`.
    pub ambient: f32,
    /// Light-propagation kernel.
    pub kernel: Kernel,
}

impl Default for Light {
    fn default() -> Self {
        Self {
            dir_view: [0.0, 0.0, 1.0],
            ambient: 0.0,
            kernel: Kernel::default(),
        }
    }
}

impl Light {
    /// The unit direction. Errors: non-finite, zero, `z <= 0` (light behind the volume is
    /// not supported by view-aligned slicing), ambient outside `[0, 1]`, bad kernel.
    pub fn unit_dir(&self) -> Result<[f64; 3]> {
        self.kernel.check()?;
        if !(self.ambient.is_finite() && (0.0..=1.0).contains(&self.ambient)) {
            return Err(Error::invalid(
                "ambient",
                format!("must be in [0, 1], got {}", self.ambient),
            ));
        }
        let l = self.dir_view;
        let n = (l[0] * l[0] + l[1] * l[1] + l[2] * l[2]).sqrt();
        if !(n.is_finite() && n > 0.0) {
            return Err(Error::invalid(
                "light_dir",
                format!("{l:?} must be finite and non-zero"),
            ));
        }
        if l[2] / n <= 1e-3 {
            return Err(Error::invalid(
                "light_dir",
                format!("{l:?}: the light must be on the viewer's side (z > 0); view-aligned slicing cannot propagate light from behind"),
            ));
        }
        Ok(l.map(|c| c / n))
    }
}

wscg_math::params! {
    /// Settings shared by every method.
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct IlluminationParams {
        /// Reconstruction filter.
        pub interp: Interp,
        /// Background colour composited behind the volume.
        pub background: [f32; 3],
        /// Opacity at which a ray stops (ray casters) or a pixel's eye pass stops compositing.
        pub early_stop: f32,
        /// The outside of the box for the propagated light (open by default).
        pub border: LightBorder,
    }
}

impl Default for IlluminationParams {
    fn default() -> Self {
        Self {
            interp: Interp::Trilinear,
            background: [0.0; 3],
            early_stop: 0.999,
            border: LightBorder::Open,
        }
    }
}

impl IlluminationParams {
    /// Errors: background outside `[0, 1]`, early stop outside `(0, 1]` (`interp` and
    /// `border` are choices, each valid).
    pub fn validate(&self) -> Result<()> {
        if !self.background.iter().all(|v| (0.0..=1.0).contains(v)) {
            return Err(Error::invalid(
                "background",
                format!("must be in [0, 1], got {:?}", self.background),
            ));
        }
        if !(self.early_stop > 0.0 && self.early_stop <= 1.0) {
            return Err(Error::invalid(
                "early_stop",
                format!("must be in (0, 1], got {}", self.early_stop),
            ));
        }
        Ok(())
    }

    /// [`IlluminationParams::validate`] under its earlier name.
    pub fn check(&self) -> Result<()> {
        self.validate()
    }
}
