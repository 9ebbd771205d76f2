//! Synthetic time-of-flight hand poses: a stand-in for the paper's private PMD-Nano recordings
//! (paper §3.2.1: 5 poses, 3000 frames per class from 3 subjects, 120 x 165 amplitude + depth
//! frames, palm segmented by thresholding the amplitude and keeping one contour), with the
//! paper's pre-processing (§3.2.2: downscaling by 3) and its split / rotation-augmentation
//! protocol (§3.2.1; the paper leaves the order of split and augmentation open, and here the
//! split comes first, see [`split_protocol`]).
//!
//! **These data are synthetic.** They come from the generative model below, designed for this
//! crate after the paper's description of the poses (§3.2.1, Fig. 3); nothing here
//! was measured on a real hand or camera, and accuracies obtained on them say nothing about the
//! paper's recordings.
//!
//! # The model
//! Coordinates are pixels, `x` to the right and `y` down; angles are measured from the hand
//! axis (pointing up, towards row 0), positive towards `+x`.
//! - **Subject** (drawn once per subject): palm ellipse semi-axes `a ~ U[18, 24]` (across) and
//!   `b ~ U[22, 28]` (along the hand axis), base finger length `L0 ~ U[30, 38]`, one width per
//!   finger `~ U[7, 9]`; relative lengths thumb 0.70, index 0.90, middle 1.0, ring 0.93,
//!   little 0.75.
//! - **Fingers** are capsules (segments with round ends, radius = width / 2). Finger `i` sits
//!   at angle `phi_i = s * anchor_i` with anchors thumb -65, index -20, middle 0, ring +18,
//!   little +36 degrees and `s` the class's spread; it is anchored at the palm-boundary point
//!   `A = (a sin phi, -b cos phi)` (elliptic parametrisation), starts inside the palm at
//!   `0.75 A` and ends at `A + e L u(phi)`, with `e` the extension (projected length fraction),
//!   `L = L0 x relative length` and `u(phi) = (sin phi, -cos phi)`: fingers point radially.
//! - **Classes** (`s`, `e`): FIST `s = 1`, `e = 0.2` for the four fingers, thumb `e = 0.35`
//!   folded across the palm (pointing at +50 degrees, over the knuckles); FLAT `s = 0.35`,
//!   `e = 1` for all five (the scaled thumb angle, -23 degrees, puts the thumb against the
//!   index: adducted); INDEX `s = 1`, index `e = 1`, the other fingers 0.2, thumb 0.35 folded
//!   as in FIST (the thumb's position in this pose is our choice); OPEN `s = 1.3`, `e = 1` (thumb at -85 degrees: abducted); GRAB `s = 1`,
//!   `e ~ U[0.55, 0.7]` per frame for all five, with a round fingertip blob (disc of radius
//!   0.75 x width) at each finger end.
//! - **Per frame**: every finger's `e` +- U(0.08) (then at least 0.05) and angle +- U(5
//!   degrees); the whole hand rotated by +- U(15 degrees), scaled by 1 +- U(0.1) and its palm
//!   centre placed at `(W / 2, 0.6 H)` +- U(t) px in each axis, with `t = 25` by default and
//!   `t = 8` in [`Jitter::tight`] (see *Difficulty* below). (Optionally the spread +-
//!   U(`Jitter::spread`), once per frame; 0 in both presets.)
//! - **Rasterisation** is analytic: a pixel belongs to a primitive when its centre (integer
//!   coordinates) lies in the transformed ellipse / capsule / disc; only the bounding box of
//!   each primitive is visited.
//! - **Depth** (mm): the palm is a plane, 300 mm at its centre, tilted by gradients
//!   `U(-0.3, 0.3)` mm/px in x and y; along each finger the surface rises towards the camera
//!   linearly from 0 at the capsule's start to `r` at its end (fingertip blobs: `r` all over),
//!   `r ~ U[20, 40]` mm for GRAB and FIST, `U[0, 10]` mm otherwise, drawn per finger; where
//!   primitives overlap the nearest surface is seen. Gaussian noise of 1 mm is added.
//! - **Boundary noise**: one of {nothing, a 1-px erosion, a 1-px dilation} (4-neighbourhood),
//!   equally likely; then 0-3 discs of radius `U[2, 4]` px centred on random boundary pixels,
//!   each added or removed with probability 1/2 (added pixels take the depth of the boundary
//!   pixel); then impulse noise on 0.5 % of the pixels (`round(0.005 H W)` random positions,
//!   drawn with replacement): a hand pixel drops out (no return), a background pixel becomes a
//!   bright "flying pixel" at 300 +- 5 mm.
//! - **Segmentation, as the paper does** (§3.2.1): the camera's amplitude is
//!   `reflectance / depth^2`, with reflectance 1 for skin and 0.35 for the background (a table
//!   at 700 mm, sloping by 0.2 mm per row), 0 for dropped-out pixels; the amplitude is
//!   thresholded at that of skin at 450 mm, and the largest 8-connected component of the result
//!   is kept, with its holes filled (the paper turns the chosen *contour* into the binary
//!   image, so drop-outs inside the hand do not survive; [`fill_holes`]). The paper keeps
//!   "the closest contour greater than a threshold area". Here the hand (over 1000 px at the default size) is always the only
//!   component that would pass any sensible area threshold (flying pixels and the bits cut
//!   off by noise are a few pixels), so the rule reduces to the largest component, which is
//!   what is implemented, with no threshold so that no frame can come out empty. The depth
//!   map is that of the kept pixels (filled drop-outs keep the depth of the surface there),
//!   0 elsewhere. What survives of the impulse noise is therefore at the border: notches
//!   where drop-outs hit boundary pixels and flying pixels touching the hand.
//!
//! The per-frame amplitudes above are those of [`Jitter::default`]; [`generate_with`] takes
//! others, such as [`Jitter::tight`].
//!
//! **Difficulty, and why the default translation is large.** On the paper's recordings the
//! baselines are far from perfect (KNN on PCA-35: 82.34 % mean, Table 5), so data standing in
//! for them should not be trivially separable either: we ask for FLAT/OPEN and FIST/GRAB (poses
//! that differ only in finger spread or extension) to be genuinely confusable, with KNN on
//! PCA-35 below 99 %. With the tight amplitudes ([`Jitter::tight`], translation +-8 px) the
//! classes are far apart: on the paper's protocol
//! (seed 0, 3000 frames per class, split + augmentation of [`split_protocol`]) KNN (k = 5) on
//! PCA-35 and the class-wise SFA (PCA-35, quadratic, m = 10, gamma = 1) both classify every
//! test frame correctly. Measured alternatives (same protocol, accuracy in % averaged over the
//! classes):
//!
//! | jitter changed from [`Jitter::tight`] | PCA-35 KNN | class SFA | lowest SFA class |
//! |---|---|---|---|
//! | none ([`Jitter::tight`]) | 100.00 | 100.00 | 100.0 |
//! | translation 20 px | 98.93 | 99.20 | 98.0 (OPEN) |
//! | translation 25 px ([`Jitter::default`]) | 97.93 | 98.87 | 98.3 (OPEN) |
//! | extension 0.12, finger angle 8, spread 0.2, rotation 20, scale 0.15, translation 12 | 93.20 | 96.40 | 89.7 (GRAB) |
//! | extension 0.15, finger angle 10, spread 0.3 | 91.33 | 96.73 | 89.3 (GRAB) |
//!
//! The default therefore translates the hand by +-25 px, the smallest change found that makes
//! the data confusable by that criterion; it also keeps the class-wise SFA near the paper's
//! "over 96% for each class" (abstract; we require >= 95 % per class and >= 96 % mean).
//! Larger pose variation brings the PCA-KNN baseline near the paper's 82 % but takes GRAB
//! below 95 % for the class-wise SFA. (The table was measured
//! with the generator and classifiers of this crate; the acceptance test of the default row is
//! `tests/paper05_handpose.rs`.)
//!
//! Frames are stored class by class (`n_per_class` frames of FIST, then FLAT, ...); within a
//! class the subjects take consecutive equal blocks. Subject `s` is drawn from stream 0 of the
//! seed, frame `i` from stream `i + 1` (see [`wscg_math::rng::stream`]), so the data depend on
//! the seed only, not on the number of threads.
//!
//! Memory: each frame takes `5 H W` bytes (mask + `f32` depth), 99 kB at 120 x 165; the
//! paper's 15000 frames take 1.5 GB.

use rand::Rng;
use rand_distr::{Distribution, Normal};
use rayon::prelude::*;
use wscg_math::rng::{self, Rng as SeededRng};
use wscg_math::{Error, Image, ImageStackView, ImageView, Result};

use super::morphology::{bounding_box, fill_holes, largest_component};
use crate::sfa::scatter::group_labels;

/// Names of the five poses, indexed by label.
pub const CLASS_NAMES: [&str; 5] = ["FIST", "FLAT", "INDEX", "OPEN", "GRAB"];

/// Number of pose classes.
pub const N_CLASSES: usize = 5;

/// Downscaling factor of the paper's pre-processing (§3.2.2: "one-third of its original
/// size"): 120 x 165 masks become 40 x 55 = 2200 values.
pub const DOWNSCALE: usize = 3;

/// Relative finger lengths: thumb, index, middle, ring, little.
const REL_LENGTH: [f64; 5] = [0.70, 0.90, 1.0, 0.93, 0.75];
/// Finger angles from the hand axis at spread 1, degrees.
const ANCHOR_DEG: [f64; 5] = [-65.0, -20.0, 0.0, 18.0, 36.0];
/// Direction of a thumb folded across the palm, degrees.
const THUMB_FOLDED_DEG: f64 = 50.0;
const PALM_DEPTH_MM: f64 = 300.0;
const BACKGROUND_DEPTH_MM: f64 = 700.0;
const BACKGROUND_REFLECTANCE: f64 = 0.35;
/// The amplitude threshold is that of skin at this distance.
const THRESHOLD_DEPTH_MM: f64 = 450.0;
const SALT_FRACTION: f64 = 0.005;
/// Largest `n x H x W` accepted (5 bytes per pixel).
const MAX_PIXELS: usize = 1 << 31;
/// Smallest canvas side accepted.
const MIN_SIDE: usize = 32;

wscg_math::params! {
    /// Parameters of [`generate`]; the defaults are the paper's data set.
    #[derive(Clone, Copy, Debug, PartialEq, Eq)]
    pub struct HandposeSynthParams {
        /// Frames per class (3000).
        pub n_per_class: usize,
        /// Number of subjects (3); each has its own palm and finger sizes.
        pub subjects: usize,
        /// Seed of every random draw (0).
        pub seed: u64,
        /// Canvas width in pixels (120).
        pub width: usize,
        /// Canvas height in pixels (165).
        pub height: usize,
    }
}

impl Default for HandposeSynthParams {
    fn default() -> Self {
        Self {
            n_per_class: 3000,
            subjects: 3,
            seed: 0,
            width: 120,
            height: 165,
        }
    }
}

impl HandposeSynthParams {
    /// Errors: `n_per_class` or `subjects` zero, a canvas side under 32 px. The total size is
    /// checked by [`generate`] ([`Error::LimitExceeded`] above 2^31 pixels).
    pub fn validate(&self) -> Result<()> {
        if self.n_per_class == 0 {
            return Err(Error::invalid("n_per_class", "must be at least 1"));
        }
        if self.subjects == 0 {
            return Err(Error::invalid("subjects", "must be at least 1"));
        }
        for (name, v) in [("width", self.width), ("height", self.height)] {
            if v < MIN_SIDE {
                return Err(Error::invalid(
                    name,
                    format!(
                        "canvas sides must be at least {MIN_SIDE} px, got {} x {}",
                        self.width, self.height
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// Amplitudes of the per-frame variation (each value is drawn uniformly in `[-a, a]`); the
/// defaults are those of [`Jitter::tight`] but for the translation (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Jitter {
    /// Added to each finger's extension (0.08).
    pub extension: f64,
    /// Added to each finger's angle, degrees (5).
    pub finger_angle_deg: f64,
    /// Added to the class's spread, once per frame (0: the spread is the class's).
    pub spread: f64,
    /// Rotation of the whole hand, degrees (15).
    pub rotation_deg: f64,
    /// Relative change of scale (0.1).
    pub scale: f64,
    /// Shift of the palm centre along each axis, px (25; 8 in [`Jitter::tight`]).
    pub translation_px: f64,
}

impl Default for Jitter {
    /// [`Jitter::tight`]'s amplitudes with the hand translated by +-25 px instead of +-8 px
    /// (see the module docs, *Difficulty*).
    fn default() -> Self {
        Self {
            translation_px: 25.0,
            ..Self::tight()
        }
    }
}

impl Jitter {
    /// The generator's tight amplitudes: extension 0.08, finger angle 5 degrees, no spread
    /// change, rotation 15 degrees, scale 0.1, translation 8 px. The paper gives no per-frame
    /// variation (its hands were recorded); under these small amplitudes the classes come out
    /// far apart (see the module docs, *Difficulty*), hence the wider [`Jitter::default`].
    pub fn tight() -> Self {
        Self {
            extension: 0.08,
            finger_angle_deg: 5.0,
            spread: 0.0,
            rotation_deg: 15.0,
            scale: 0.1,
            translation_px: 8.0,
        }
    }

    fn validate(&self) -> Result<()> {
        let v = [
            ("jitter.extension", self.extension),
            ("jitter.finger_angle_deg", self.finger_angle_deg),
            ("jitter.spread", self.spread),
            ("jitter.rotation_deg", self.rotation_deg),
            ("jitter.scale", self.scale),
            ("jitter.translation_px", self.translation_px),
        ];
        for (name, a) in v {
            if !(a.is_finite() && a >= 0.0) {
                return Err(Error::invalid(
                    name,
                    format!("must be finite and >= 0, got {a}"),
                ));
            }
        }
        if self.scale >= 1.0 {
            return Err(Error::invalid("jitter.scale", "must be below 1"));
        }
        Ok(())
    }
}

/// Uniform in `[-a, a]` (0 without a draw when `a == 0`).
fn sym(r: &mut SeededRng, a: f64) -> f64 {
    if a > 0.0 {
        r.random_range(-a..=a)
    } else {
        0.0
    }
}

/// Generated frames: `n = 5 x n_per_class` segmented masks with depth, labels and subjects.
#[derive(Clone, Debug, PartialEq)]
pub struct SynthData {
    /// `n x (height x width)` binary masks (0/1), row-major per frame.
    pub masks: Vec<u8>,
    /// `n x (height x width)` depth in mm where the mask is 1, 0 elsewhere.
    pub depth: Vec<f32>,
    /// Class of each frame, `0..5` (see [`CLASS_NAMES`]).
    pub labels: Vec<u32>,
    /// Subject of each frame, `0..subjects`.
    pub subjects: Vec<u32>,
    /// Frame height (rows).
    pub height: usize,
    /// Frame width (columns).
    pub width: usize,
}

impl SynthData {
    /// Number of frames.
    pub fn len(&self) -> usize {
        self.labels.len()
    }

    /// True when there are no frames.
    pub fn is_empty(&self) -> bool {
        self.labels.is_empty()
    }

    /// Pixels per frame.
    pub fn frame_len(&self) -> usize {
        self.height * self.width
    }

    /// Mask of frame `i` (`None` past the end or for an inconsistent data set).
    pub fn mask(&self, i: usize) -> Option<ImageView<'_, u8>> {
        self.mask_stack().ok()?.frame(i)
    }

    /// Depth map of frame `i` (`None` past the end or for an inconsistent data set).
    pub fn depth_map(&self, i: usize) -> Option<ImageView<'_, f32>> {
        self.depth_stack().ok()?.frame(i)
    }

    /// The masks as a stack of images.
    ///
    /// Errors: `masks` not `len() x height x width`, no frame.
    pub fn mask_stack(&self) -> Result<ImageStackView<'_, u8>> {
        ImageStackView::new(self.len(), self.height, self.width, &self.masks)
    }

    /// The depth maps as a stack of images.
    ///
    /// Errors: `depth` not `len() x height x width`, no frame.
    pub fn depth_stack(&self) -> Result<ImageStackView<'_, f32>> {
        ImageStackView::new(self.len(), self.height, self.width, &self.depth)
    }

    fn check(&self) -> Result<()> {
        let n = self.labels.len();
        if n == 0 {
            return Err(Error::Empty("data"));
        }
        let hw = self
            .height
            .checked_mul(self.width)
            .filter(|&p| p > 0)
            .ok_or_else(|| {
                Error::invalid(
                    "data",
                    format!("bad frame size {} x {}", self.height, self.width),
                )
            })?;
        if n.checked_mul(hw) != Some(self.masks.len()) {
            return Err(Error::ShapeMismatch(format!(
                "{} mask values for {n} frames of {} x {}",
                self.masks.len(),
                self.height,
                self.width
            )));
        }
        Ok(())
    }
}

/// Hand sizes of one subject.
#[derive(Clone, Copy, Debug)]
struct Subject {
    a: f64,
    b: f64,
    l0: f64,
    width: [f64; 5],
}

impl Subject {
    fn sample(r: &mut SeededRng) -> Self {
        let a = r.random_range(18.0..=24.0);
        let b = r.random_range(22.0..=28.0);
        let l0 = r.random_range(30.0..=38.0);
        let width = std::array::from_fn(|_| r.random_range(7.0..=9.0));
        Self { a, b, l0, width }
    }
}

/// Pose of a class before the per-frame jitter.
struct Pose {
    ext: [f64; 5],
    spread: f64,
    thumb_folded: bool,
    tip_blobs: bool,
    rise_mm: (f64, f64),
}

fn pose(class: usize, r: &mut SeededRng) -> Pose {
    let low = (0.0, 10.0);
    let high = (20.0, 40.0);
    match class {
        0 => Pose {
            ext: [0.35, 0.2, 0.2, 0.2, 0.2],
            spread: 1.0,
            thumb_folded: true,
            tip_blobs: false,
            rise_mm: high,
        },
        1 => Pose {
            ext: [1.0; 5],
            spread: 0.35,
            thumb_folded: false,
            tip_blobs: false,
            rise_mm: low,
        },
        2 => Pose {
            ext: [0.35, 1.0, 0.2, 0.2, 0.2],
            spread: 1.0,
            thumb_folded: true,
            tip_blobs: false,
            rise_mm: low,
        },
        3 => Pose {
            ext: [1.0; 5],
            spread: 1.3,
            thumb_folded: false,
            tip_blobs: false,
            rise_mm: low,
        },
        _ => Pose {
            ext: [r.random_range(0.55..=0.7); 5],
            spread: 1.0,
            thumb_folded: false,
            tip_blobs: true,
            rise_mm: high,
        },
    }
}

/// Per-thread buffers of the frame renderer.
struct Scratch {
    /// Depth of the scene's hand surface, infinite where there is no hand.
    z: Vec<f32>,
    z2: Vec<f32>,
    bright: Vec<u8>,
    boundary: Vec<usize>,
    /// Thresholded amplitude in the box around the hand.
    sub: Vec<u8>,
}

impl Scratch {
    fn new(hw: usize) -> Self {
        Self {
            z: vec![f32::INFINITY; hw],
            z2: vec![f32::INFINITY; hw],
            bright: vec![0; hw],
            boundary: Vec::new(),
            sub: Vec::with_capacity(hw),
        }
    }
}

/// Similarity placing the hand model on the canvas, and the palm plane.
struct Placement {
    c: (f64, f64),
    scale: f64,
    cos: f64,
    sin: f64,
    tilt: (f64, f64),
}

impl Placement {
    fn map(&self, p: (f64, f64)) -> (f64, f64) {
        (
            self.c.0 + self.scale * (self.cos * p.0 - self.sin * p.1),
            self.c.1 + self.scale * (self.sin * p.0 + self.cos * p.1),
        )
    }

    fn plane(&self, x: f64, y: f64) -> f64 {
        PALM_DEPTH_MM + self.tilt.0 * (x - self.c.0) + self.tilt.1 * (y - self.c.1)
    }
}

/// Inclusive pixel range covering `[lo, hi]`, clipped to `0..n`; `None` if empty.
fn pixel_range(lo: f64, hi: f64, n: usize) -> Option<(usize, usize)> {
    let a = lo.ceil().max(0.0);
    let b = hi.floor().min(n as f64 - 1.0);
    (a <= b).then_some((a as usize, b as usize))
}

/// Draws the palm ellipse (semi-axes `a`, `b` before scaling) into `z`.
fn draw_palm(z: &mut [f32], h: usize, w: usize, pl: &Placement, a: f64, b: f64) {
    let (sa, sb) = (pl.scale * a, pl.scale * b);
    let ex = (sa * sa * pl.cos * pl.cos + sb * sb * pl.sin * pl.sin).sqrt();
    let ey = (sa * sa * pl.sin * pl.sin + sb * sb * pl.cos * pl.cos).sqrt();
    let (Some((x0, x1)), Some((y0, y1))) = (
        pixel_range(pl.c.0 - ex, pl.c.0 + ex, w),
        pixel_range(pl.c.1 - ey, pl.c.1 + ey, h),
    ) else {
        return;
    };
    for y in y0..=y1 {
        let dy = y as f64 - pl.c.1;
        for x in x0..=x1 {
            let dx = x as f64 - pl.c.0;
            let lx = pl.cos * dx + pl.sin * dy;
            let ly = -pl.sin * dx + pl.cos * dy;
            if (lx / sa).powi(2) + (ly / sb).powi(2) <= 1.0 {
                let d = pl.plane(x as f64, y as f64) as f32;
                let v = &mut z[y * w + x];
                *v = v.min(d);
            }
        }
    }
}

/// Draws a capsule from `p0` to `p1` (canvas coordinates) of radius `r`; its surface rises by
/// `rise` mm from `p0` to `p1` above the palm plane (`flat`: by `rise` everywhere).
#[allow(clippy::too_many_arguments)]
fn draw_capsule(
    z: &mut [f32],
    h: usize,
    w: usize,
    pl: &Placement,
    p0: (f64, f64),
    p1: (f64, f64),
    r: f64,
    rise: f64,
    flat: bool,
) {
    let (Some((x0, x1)), Some((y0, y1))) = (
        pixel_range(p0.0.min(p1.0) - r, p0.0.max(p1.0) + r, w),
        pixel_range(p0.1.min(p1.1) - r, p0.1.max(p1.1) + r, h),
    ) else {
        return;
    };
    let (ex, ey) = (p1.0 - p0.0, p1.1 - p0.1);
    let len2 = ex * ex + ey * ey;
    for y in y0..=y1 {
        let qy = y as f64;
        for x in x0..=x1 {
            let qx = x as f64;
            let t = if len2 > 0.0 {
                (((qx - p0.0) * ex + (qy - p0.1) * ey) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let (px, py) = (p0.0 + t * ex, p0.1 + t * ey);
            if (qx - px).powi(2) + (qy - py).powi(2) <= r * r {
                let up = if flat { rise } else { rise * t };
                let d = (pl.plane(qx, qy) - up) as f32;
                let v = &mut z[y * w + x];
                *v = v.min(d);
            }
        }
    }
}

/// Renders frame number `class` pose of `subj` into `mask` / `depth` (see the module docs).
#[allow(clippy::too_many_arguments)]
fn render_frame(
    class: usize,
    subj: &Subject,
    jit: &Jitter,
    r: &mut SeededRng,
    h: usize,
    w: usize,
    s: &mut Scratch,
    mask: &mut [u8],
    depth: &mut [f32],
) {
    let unit = Normal::new(0.0, 1.0).expect("unit normal");
    let pose = pose(class, r);
    let spread = (pose.spread + sym(r, jit.spread)).max(0.0);
    let rho = sym(r, jit.rotation_deg).to_radians();
    let pl = Placement {
        c: (
            w as f64 / 2.0 + sym(r, jit.translation_px),
            0.6 * h as f64 + sym(r, jit.translation_px),
        ),
        scale: 1.0 + sym(r, jit.scale),
        cos: rho.cos(),
        sin: rho.sin(),
        tilt: (r.random_range(-0.3..=0.3), r.random_range(-0.3..=0.3)),
    };
    s.z.fill(f32::INFINITY);
    draw_palm(&mut s.z, h, w, &pl, subj.a, subj.b);
    for i in 0..5 {
        let jitter = sym(r, jit.finger_angle_deg);
        let phi = (spread * ANCHOR_DEG[i] + jitter).to_radians();
        let psi = if i == 0 && pose.thumb_folded {
            (THUMB_FOLDED_DEG + jitter).to_radians()
        } else {
            phi
        };
        let e = (pose.ext[i] + sym(r, jit.extension)).max(0.05);
        let rise = r.random_range(pose.rise_mm.0..=pose.rise_mm.1);
        let len = subj.l0 * REL_LENGTH[i];
        let anchor = (subj.a * phi.sin(), -subj.b * phi.cos());
        let p0 = pl.map((0.75 * anchor.0, 0.75 * anchor.1));
        let p1 = pl.map((
            anchor.0 + e * len * psi.sin(),
            anchor.1 - e * len * psi.cos(),
        ));
        let rad = pl.scale * subj.width[i] / 2.0;
        draw_capsule(&mut s.z, h, w, &pl, p0, p1, rad, rise, false);
        if pose.tip_blobs {
            let rb = pl.scale * 0.75 * subj.width[i];
            draw_capsule(&mut s.z, h, w, &pl, p1, p1, rb, rise, true);
        }
    }

    // Every pass below visits a box around the hand only: nothing outside it can change.
    let Some(hb) = hand_box(&s.z, h, w, 1) else {
        mask.fill(0);
        depth.fill(0.0);
        return;
    };
    // Boundary noise 1: erosion or dilation by one pixel (4-neighbourhood).
    let hand = |z: &[f32], x: isize, y: isize| -> Option<f32> {
        if x < 0 || y < 0 || x >= w as isize || y >= h as isize {
            return None;
        }
        let v = z[y as usize * w + x as usize];
        v.is_finite().then_some(v)
    };
    const N4: [(isize, isize); 4] = [(1, 0), (-1, 0), (0, 1), (0, -1)];
    let op = r.random_range(0..3u8);
    if op != 0 {
        s.z2.copy_from_slice(&s.z);
        for y in hb.2 as isize..=hb.3 as isize {
            for x in hb.0 as isize..=hb.1 as isize {
                let i = y as usize * w + x as usize;
                let inside = s.z2[i].is_finite();
                if op == 1 && inside {
                    if N4
                        .iter()
                        .any(|&(dx, dy)| hand(&s.z2, x + dx, y + dy).is_none())
                    {
                        s.z[i] = f32::INFINITY;
                    }
                } else if op == 2 && !inside {
                    let m = N4
                        .iter()
                        .filter_map(|&(dx, dy)| hand(&s.z2, x + dx, y + dy))
                        .fold(f32::INFINITY, f32::min);
                    s.z[i] = m;
                }
            }
        }
    }
    // Boundary noise 2: 0-3 discs added to or cut from the border.
    let blobs = r.random_range(0..=3u8);
    if blobs > 0 {
        s.boundary.clear();
        for y in hb.2 as isize..=hb.3 as isize {
            for x in hb.0 as isize..=hb.1 as isize {
                let i = y as usize * w + x as usize;
                if s.z[i].is_finite()
                    && N4
                        .iter()
                        .any(|&(dx, dy)| hand(&s.z, x + dx, y + dy).is_none())
                {
                    s.boundary.push(i);
                }
            }
        }
        for _ in 0..blobs {
            let centre = r.random_range(0..s.boundary.len().max(1));
            let rad = r.random_range(2.0..=4.0f64);
            let add = r.random_bool(0.5);
            let Some(&b) = s.boundary.get(centre) else {
                continue;
            };
            let (bx, by) = ((b % w) as f64, (b / w) as f64);
            let zb = s.z[b];
            let (Some((x0, x1)), Some((y0, y1))) = (
                pixel_range(bx - rad, bx + rad, w),
                pixel_range(by - rad, by + rad, h),
            ) else {
                continue;
            };
            for y in y0..=y1 {
                for x in x0..=x1 {
                    if (x as f64 - bx).powi(2) + (y as f64 - by).powi(2) <= rad * rad {
                        let v = &mut s.z[y * w + x];
                        if !add {
                            *v = f32::INFINITY;
                        } else if !v.is_finite() {
                            *v = zb;
                        }
                    }
                }
            }
        }
    }
    // The hand is final: the box of the segmentation, with a margin of 2 px for the flying
    // pixels that touch it.
    let Some((x0, x1, y0, y1)) = hand_box(&s.z, h, w, 2) else {
        mask.fill(0);
        depth.fill(0.0);
        return;
    };
    // Sensor noise on the hand's depth.
    for v in s.z.iter_mut().filter(|v| v.is_finite()) {
        *v += unit.sample(r) as f32;
    }
    // Impulse noise: drop-outs on the hand, flying pixels on the background.
    s.bright.fill(0);
    let salt = (SALT_FRACTION * (h * w) as f64).round() as usize;
    for _ in 0..salt {
        let i = r.random_range(0..h * w);
        if s.z[i].is_finite() {
            // The surface is still there (its depth is kept for hole filling), unseen.
            s.bright[i] = 2;
        } else {
            s.z[i] = (PALM_DEPTH_MM + 5.0 * unit.sample(r)) as f32;
            s.bright[i] = 1;
        }
    }
    // Amplitude image, threshold and largest component (the segmentation of the paper). Only
    // the box is segmented: outside it there are isolated flying pixels (at most
    // `round(0.005 H W)` of them, far fewer than the hand's pixels), which can be neither the
    // largest component nor part of it, so the result is that of the whole image.
    let threshold = 1.0 / (THRESHOLD_DEPTH_MM * THRESHOLD_DEPTH_MM);
    let (bw, bh) = (x1 - x0 + 1, y1 - y0 + 1);
    s.sub.clear();
    for y in y0..=y1 {
        let table = BACKGROUND_DEPTH_MM + 0.2 * (y as f64 - h as f64 / 2.0);
        let background = BACKGROUND_REFLECTANCE / (table * table);
        for x in x0..=x1 {
            let i = y * w + x;
            let amplitude = if s.bright[i] == 2 {
                0.0
            } else if s.z[i].is_finite() {
                let d = f64::from(s.z[i]);
                1.0 / (d * d)
            } else {
                background
            };
            s.sub.push(u8::from(amplitude > threshold));
        }
    }
    let comp = ImageView::plane(bh, bw, &s.sub)
        .and_then(largest_component)
        .and_then(|(c, _)| fill_holes(c.view()))
        .map(Image::into_data)
        .unwrap_or_else(|_| vec![0; bh * bw]);
    mask.fill(0);
    depth.fill(0.0);
    for y in y0..=y1 {
        for x in x0..=x1 {
            if comp[(y - y0) * bw + (x - x0)] == 0 {
                continue;
            }
            let i = y * w + x;
            mask[i] = 1;
            depth[i] = if s.z[i].is_finite() {
                s.z[i]
            } else {
                // A filled hole that no primitive covers: the palm plane behind it.
                pl.plane(x as f64, y as f64) as f32
            };
        }
    }
}

/// Inclusive box `(x0, x1, y0, y1)` of the hand (finite depth) in `z`, grown by `margin`.
fn hand_box(z: &[f32], h: usize, w: usize, margin: usize) -> Option<(usize, usize, usize, usize)> {
    bounding_box(ImageView::plane(h, w, z).ok()?, margin, |v| v.is_finite())
}

/// Generates the synthetic hand-pose data set (see the module docs), frames in parallel.
///
/// Errors: `n_per_class` or `subjects` zero, a canvas side under 32 px, more than 2^31 pixels
/// in all.
pub fn generate(cfg: &HandposeSynthParams) -> Result<SynthData> {
    generate_with(cfg, &Jitter::default())
}

/// [`generate`] with other per-frame variation amplitudes than the default ones (see the
/// module docs for measured effects on the classifiers). `generate_with(cfg, &Jitter::default())`
/// is `generate(cfg)`.
///
/// Errors: as [`generate`]; a [`Jitter`] amplitude negative or non-finite.
pub fn generate_with(cfg: &HandposeSynthParams, jitter: &Jitter) -> Result<SynthData> {
    cfg.validate()?;
    jitter.validate()?;
    let (h, w) = (cfg.height, cfg.width);
    let hw = h * w;
    let n = cfg
        .n_per_class
        .checked_mul(N_CLASSES)
        .filter(|n| n.checked_mul(hw).is_some_and(|p| p <= MAX_PIXELS))
        .ok_or_else(|| {
            Error::LimitExceeded(format!(
                "{} frames per class of {h} x {w} exceed {MAX_PIXELS} pixels",
                cfg.n_per_class
            ))
        })?;
    let subjects: Vec<Subject> = {
        let mut r = rng::stream(cfg.seed, 0);
        (0..cfg.subjects).map(|_| Subject::sample(&mut r)).collect()
    };
    let npc = cfg.n_per_class;
    let labels: Vec<u32> = (0..n).map(|i| (i / npc) as u32).collect();
    let subject_of: Vec<u32> = (0..n)
        .map(|i| ((i % npc) * cfg.subjects / npc) as u32)
        .collect();
    let mut masks = vec![0u8; n * hw];
    let mut depth = vec![0f32; n * hw];
    masks
        .par_chunks_mut(hw)
        .zip(depth.par_chunks_mut(hw))
        .enumerate()
        .for_each_init(
            || Scratch::new(hw),
            |s, (i, (m, d))| {
                let mut r = rng::stream(cfg.seed, i as u64 + 1);
                let subj = &subjects[subject_of[i] as usize];
                render_frame(labels[i] as usize, subj, jitter, &mut r, h, w, s, m, d);
            },
        );
    Ok(SynthData {
        masks,
        depth,
        labels,
        subjects: subject_of,
        height: h,
        width: w,
    })
}

/// Rotates a binary single-channel mask by `degrees` (counter-clockwise as displayed, y pointing
/// down) about the centroid of its foreground, by nearest-neighbour resampling: output pixel
/// `q` takes the value of the input pixel nearest to the centroid + `R(-degrees) (q -
/// centroid)`, 0 when that falls outside the image. The output is 0/1. Multiples of 90 degrees
/// use exact sines and cosines. An empty mask comes back unchanged (as 0/1).
///
/// Errors: a mask with more than one channel, non-finite `degrees`.
pub fn rotate_mask(mask: ImageView<'_, u8>, degrees: f64) -> Result<Image<u8>> {
    mask.ensure_plane("mask")?;
    let (h, w, mask) = (mask.height(), mask.width(), mask.data());
    if !degrees.is_finite() {
        return Err(Error::invalid(
            "degrees",
            format!("must be finite, got {degrees}"),
        ));
    }
    let (mut sx, mut sy, mut count) = (0.0f64, 0.0f64, 0usize);
    for (i, &m) in mask.iter().enumerate() {
        if m != 0 {
            sx += (i % w) as f64;
            sy += (i / w) as f64;
            count += 1;
        }
    }
    if count == 0 {
        return Image::filled(h, w, 1, 0);
    }
    let (cx, cy) = (sx / count as f64, sy / count as f64);
    let quarter = degrees / 90.0;
    let (sin, cos) = if quarter == quarter.round() {
        match (quarter.rem_euclid(4.0)) as u8 {
            0 => (0.0, 1.0),
            1 => (1.0, 0.0),
            2 => (0.0, -1.0),
            _ => (-1.0, 0.0),
        }
    } else {
        degrees.to_radians().sin_cos()
    };
    let mut out = vec![0u8; h * w];
    for y in 0..h {
        let dy = y as f64 - cy;
        for x in 0..w {
            let dx = x as f64 - cx;
            // Forward map (on screen, counter-clockwise): x' = c + cos dx + sin dy,
            // y' = c - sin dx + cos dy; this is its inverse.
            let srcx = (cx + cos * dx - sin * dy).round();
            let srcy = (cy + sin * dx + cos * dy).round();
            if srcx >= 0.0 && srcy >= 0.0 && srcx < w as f64 && srcy < h as f64 {
                out[y * w + x] = u8::from(mask[srcy as usize * w + srcx as usize] != 0);
            }
        }
    }
    Image::new(h, w, 1, out)
}

/// Area-average downscaling of a binary single-channel `h x w` mask by an integer `factor`: each output value
/// is the fraction of foreground pixels in its `factor x factor` block (in `[0, 1]`), an
/// image of `ceil(h / factor) x ceil(w / factor)`; blocks cut by the image edge average the
/// pixels they hold. 120 x 165 by 3 gives 40 x 55.
///
/// Errors: a mask with more than one channel, `factor == 0`.
pub fn downscale(mask: ImageView<'_, u8>, factor: usize) -> Result<Image<f64>> {
    mask.ensure_plane("mask")?;
    let (h, w, mask) = (mask.height(), mask.width(), mask.data());
    if factor == 0 {
        return Err(Error::invalid("factor", "must be at least 1"));
    }
    let (oh, ow) = (h.div_ceil(factor), w.div_ceil(factor));
    let mut sum = vec![0u32; oh * ow];
    let mut cnt = vec![0u32; oh * ow];
    for y in 0..h {
        let row = (y / factor) * ow;
        for x in 0..w {
            let o = row + x / factor;
            sum[o] += u32::from(mask[y * w + x] != 0);
            cnt[o] += 1;
        }
    }
    let mean = sum
        .iter()
        .zip(&cnt)
        .map(|(&s, &c)| f64::from(s) / f64::from(c))
        .collect();
    Image::new(oh, ow, 1, mean)
}

/// Train / test rows of the paper's protocol (see [`split_protocol`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Split {
    /// Training rows (downscaled masks, `dim` values each), original frames first, then the
    /// rotated copies.
    pub train_x: Vec<f64>,
    /// Label of each training row.
    pub train_y: Vec<u32>,
    /// Test rows (original frames only).
    pub test_x: Vec<f64>,
    /// Label of each test row.
    pub test_y: Vec<u32>,
    /// Values per row (2200 for 120 x 165 frames).
    pub dim: usize,
    /// `(height, width)` of the downscaled images (55 x 40).
    pub shape: (usize, usize),
    /// Source frame of each training row (a rotated copy points at the frame it was made from).
    pub train_index: Vec<usize>,
    /// Source frame of each test row.
    pub test_index: Vec<usize>,
    /// Rotation (degrees) applied to each training row: 0 for original frames.
    pub train_rotation: Vec<f64>,
}

/// The paper's protocol (§3.2.1), with the split made before the augmentation (the paper
/// leaves the order open; this way no test frame has a rotated copy in training): for each
/// class (in increasing label order), `test_per_class` frames chosen at random are the test
/// set and the others the training set; then `augment_per_class` of that class's **training**
/// frames, chosen at random without replacement, are rotated about their centroid by an angle
/// `~ U(10, 20)` degrees with a random sign ([`rotate_mask`]) and appended to the training set.
/// Every row is a mask downscaled by [`DOWNSCALE`] ([`downscale`]). Original rows are in frame
/// order; the rotated ones follow, class by class. Deterministic given `seed`.
///
/// Errors: inconsistent or empty `data`; a class with no more than `test_per_class` frames; a
/// class with fewer than `augment_per_class` training frames.
pub fn split_protocol(
    data: &SynthData,
    test_per_class: usize,
    augment_per_class: usize,
    seed: u64,
) -> Result<Split> {
    data.check()?;
    split_masks(
        data.mask_stack()?,
        &data.labels,
        test_per_class,
        augment_per_class,
        seed,
    )
}

/// [`split_protocol`] on any stack of binary masks (non-zero = foreground) with one label
/// each: the user's own silhouettes.
///
/// Errors: as [`split_protocol`]; not one label per mask.
pub fn split_masks(
    masks: ImageStackView<'_, u8>,
    labels: &[u32],
    test_per_class: usize,
    augment_per_class: usize,
    seed: u64,
) -> Result<Split> {
    if labels.len() != masks.frames() {
        return Err(Error::ShapeMismatch(format!(
            "{} labels for {} masks",
            labels.len(),
            masks.frames()
        )));
    }
    let (h, w) = (masks.height(), masks.width());
    let (classes, frames) = group_labels(labels);
    let mut r = rng::seeded(seed);
    let mut train = Vec::new();
    let mut test = Vec::new();
    let mut augment: Vec<(usize, f64)> = Vec::new();
    for (&c, mut idx) in classes.iter().zip(frames) {
        if idx.len() <= test_per_class {
            return Err(Error::invalid(
                "test_per_class",
                format!(
                    "class {c} has {} frames, need more than {test_per_class}",
                    idx.len()
                ),
            ));
        }
        let n_train = idx.len() - test_per_class;
        if augment_per_class > n_train {
            return Err(Error::invalid(
                "augment_per_class",
                format!(
                    "class {c} has only {n_train} training frames, asked for {augment_per_class}"
                ),
            ));
        }
        rng::shuffle(&mut idx, &mut r);
        test.extend_from_slice(&idx[..test_per_class]);
        let mut tr = idx[test_per_class..].to_vec();
        train.extend_from_slice(&tr);
        rng::shuffle(&mut tr, &mut r);
        for &f in &tr[..augment_per_class] {
            augment.push((f, signed_angle(&mut r, 10.0, 20.0)));
        }
    }
    train.sort_unstable();
    test.sort_unstable();
    let shape = (h.div_ceil(DOWNSCALE), w.div_ceil(DOWNSCALE));
    let dim = shape.0 * shape.1;
    let jobs: Vec<(usize, f64)> = train
        .iter()
        .map(|&f| (f, 0.0))
        .chain(augment.iter().copied())
        .collect();
    let train_x = frame_rows(masks, &jobs)?;
    let test_jobs: Vec<(usize, f64)> = test.iter().map(|&f| (f, 0.0)).collect();
    let test_x = frame_rows(masks, &test_jobs)?;
    Ok(Split {
        train_x,
        train_y: jobs.iter().map(|&(f, _)| labels[f]).collect(),
        test_x,
        test_y: test.iter().map(|&f| labels[f]).collect(),
        dim,
        shape,
        train_index: jobs.iter().map(|&(f, _)| f).collect(),
        test_index: test,
        train_rotation: jobs.iter().map(|&(_, a)| a).collect(),
    })
}

/// An angle `~ U(lo, hi)` degrees with a random sign (`lo` when `lo == hi`).
fn signed_angle(r: &mut SeededRng, lo: f64, hi: f64) -> f64 {
    let a = if hi > lo { r.random_range(lo..=hi) } else { lo };
    if r.random_bool(0.5) {
        a
    } else {
        -a
    }
}

/// One row per `(frame, degrees)` job: the mask of `frame` in the stack `masks`, rotated
/// about its centroid by `degrees` (not at all for 0) and downscaled by [`DOWNSCALE`]; jobs in
/// parallel.
fn frame_rows(masks: ImageStackView<'_, u8>, jobs: &[(usize, f64)]) -> Result<Vec<f64>> {
    let (h, w) = (masks.height(), masks.width());
    let dim = h.div_ceil(DOWNSCALE) * w.div_ceil(DOWNSCALE);
    let mut x = vec![0.0; jobs.len() * dim];
    x.par_chunks_mut(dim)
        .zip(jobs)
        .try_for_each(|(out, &(f, angle))| -> Result<()> {
            let m = masks
                .frame(f)
                .ok_or_else(|| Error::invalid("frames", format!("no frame {f} in the masks")))?;
            let d = if angle == 0.0 {
                downscale(m, DOWNSCALE)?
            } else {
                downscale(rotate_mask(m, angle)?.view(), DOWNSCALE)?
            };
            out.copy_from_slice(d.data());
            Ok(())
        })?;
    Ok(x)
}

/// The rows of the given frames of a mask stack, each rotated about its
/// centroid by an angle `~ U(lo, hi)` degrees with a random sign, then downscaled as
/// [`split_protocol`] does: the test of the rotational invariance that the augmentation trains
/// (§3.2.1; `lo = 10`, `hi = 20`, `frames` = [`Split::test_index`]). With `lo = hi = 0` the
/// rows equal the unrotated ones.
/// Deterministic given `seed`.
///
/// Errors: angles not finite or `lo > hi`, a frame index past the stack.
pub fn rotated_rows(
    masks: ImageStackView<'_, u8>,
    frames: &[usize],
    lo: f64,
    hi: f64,
    seed: u64,
) -> Result<Vec<f64>> {
    if !(lo.is_finite() && hi.is_finite() && 0.0 <= lo && lo <= hi) {
        return Err(Error::invalid(
            "angles",
            format!("need finite 0 <= lo <= hi, got {lo}, {hi}"),
        ));
    }
    let mut r = rng::seeded(seed);
    let jobs: Vec<(usize, f64)> = frames
        .iter()
        .map(|&f| (f, signed_angle(&mut r, lo, hi)))
        .collect();
    frame_rows(masks, &jobs)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [`rotate_mask`] of a row-major buffer.
    fn rot(mask: &[u8], h: usize, w: usize, degrees: f64) -> Result<Vec<u8>> {
        Ok(rotate_mask(ImageView::plane(h, w, mask)?, degrees)?.into_data())
    }

    /// [`downscale`] of a row-major buffer.
    fn down(mask: &[u8], h: usize, w: usize, factor: usize) -> Result<Vec<f64>> {
        Ok(downscale(ImageView::plane(h, w, mask)?, factor)?.into_data())
    }

    fn small(seed: u64) -> HandposeSynthParams {
        HandposeSynthParams {
            n_per_class: 40,
            seed,
            ..HandposeSynthParams::default()
        }
    }

    #[test]
    fn generator_is_deterministic_and_thread_independent() {
        let cfg = small(3);
        let a = generate(&cfg).unwrap();
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let b = pool.install(|| generate(&cfg).unwrap());
        assert_eq!(a, b);
        let c = generate(&small(4)).unwrap();
        assert_ne!(a.masks, c.masks);
    }

    #[test]
    fn generator_output_is_well_formed_and_classes_differ() {
        let d = generate(&small(0)).unwrap();
        let hw = 120 * 165;
        assert_eq!((d.height, d.width, d.len()), (165, 120, 200));
        assert_eq!(d.masks.len(), 200 * hw);
        assert_eq!(d.depth.len(), 200 * hw);
        for c in 0..5u32 {
            assert_eq!(d.labels.iter().filter(|&&l| l == c).count(), 40);
        }
        for s in 0..3u32 {
            assert!(d.subjects.iter().filter(|&&x| x == s).count() >= 60);
        }
        assert!(d.masks.iter().all(|&m| m <= 1));
        let mut area = [0.0f64; 5];
        let mut width = [0.0f64; 5];
        let mut rise = [0.0f64; 5];
        for i in 0..d.len() {
            let m = d.mask(i).unwrap().data();
            let z = d.depth_map(i).unwrap().data();
            let a = m.iter().filter(|&&v| v == 1).count();
            assert!(a > 1000, "frame {i} area {a}");
            // Depth is in the camera's range on the hand and 0 elsewhere.
            for (&mv, &zv) in m.iter().zip(z) {
                if mv == 1 {
                    assert!((200.0..340.0).contains(&zv), "{zv}");
                } else {
                    assert_eq!(zv, 0.0);
                }
            }
            let (min_z, mean_z) = {
                let v: Vec<f32> = z.iter().copied().filter(|&v| v > 0.0).collect();
                let min = v.iter().copied().fold(f32::INFINITY, f32::min);
                (min, v.iter().sum::<f32>() / v.len() as f32)
            };
            let c = d.labels[i] as usize;
            area[c] += a as f64 / 40.0;
            rise[c] += f64::from(mean_z - min_z) / 40.0;
            // Horizontal extent of the mask (columns holding foreground).
            let cols = (0..120)
                .filter(|&x| (0..165).any(|y| m[y * 120 + x] == 1))
                .count();
            width[c] += cols as f64 / 40.0;
        }
        eprintln!("mean area per class {CLASS_NAMES:?}: {area:.0?}");
        eprintln!("mean columns per class: {width:.1?}");
        eprintln!("mean (mean - min) depth per class: {rise:.1?}");
        let [fist, flat, index, open, grab] = area;
        assert!(fist < index && fist < grab && fist < flat && fist < open);
        assert!(open > flat && open > grab && open > index);
        assert!(flat > index);
        assert!(width[3] > width[1] + 10.0, "open is wider than flat");
        // Raised fingers: GRAB and FIST surfaces reach closer to the camera.
        assert!(rise[4] > rise[3] && rise[0] > rise[1]);
    }

    #[test]
    fn generated_frames_have_features() {
        let d = generate(&HandposeSynthParams {
            n_per_class: 4,
            ..HandposeSynthParams::default()
        })
        .unwrap();
        let f = crate::sfa::handpose::physical_features_batch(
            d.mask_stack().unwrap(),
            Some(d.depth_stack().unwrap()),
        )
        .unwrap();
        assert_eq!(f.len(), 20 * 9);
        assert!(f.iter().all(|v| v.is_finite()));
        // The extended index finger puts the fingertip far from the palm centre (in palm
        // radii), the fist does not; spread fingers leave deeper convexity defects than a
        // fist.
        let mean = |class: usize, value: &dyn Fn(&[f64]) -> f64| {
            (0..d.len())
                .filter(|&i| d.labels[i] as usize == class)
                .map(|i| value(&f[9 * i..9 * (i + 1)]))
                .sum::<f64>()
                / 4.0
        };
        let reach = |r: &[f64]| (r[0] - r[2]).hypot(r[1] - r[3]) / r[4];
        let (fist, index, open) = (mean(0, &reach), mean(2, &reach), mean(3, &reach));
        assert!(index > 1.5 * fist, "index {index} fist {fist}");
        let (open_defect, fist_defect) = (mean(3, &|r| r[6]), mean(0, &|r| r[6]));
        assert!(
            open_defect > fist_defect,
            "{open_defect} vs {fist_defect} (reach {open})"
        );
    }

    #[test]
    fn bad_configs_are_rejected() {
        for cfg in [
            HandposeSynthParams {
                n_per_class: 0,
                ..HandposeSynthParams::default()
            },
            HandposeSynthParams {
                subjects: 0,
                ..HandposeSynthParams::default()
            },
            HandposeSynthParams {
                width: 10,
                ..HandposeSynthParams::default()
            },
            HandposeSynthParams {
                n_per_class: usize::MAX / 2,
                ..HandposeSynthParams::default()
            },
        ] {
            assert!(generate(&cfg).is_err(), "{cfg:?}");
        }
        let cfg = HandposeSynthParams {
            n_per_class: 1,
            ..HandposeSynthParams::default()
        };
        for j in [
            Jitter {
                scale: 1.0,
                ..Jitter::default()
            },
            Jitter {
                translation_px: -1.0,
                ..Jitter::default()
            },
            Jitter {
                spread: f64::NAN,
                ..Jitter::default()
            },
        ] {
            assert!(generate_with(&cfg, &j).is_err(), "{j:?}");
        }
        assert_eq!(
            generate_with(&cfg, &Jitter::default()).unwrap(),
            generate(&cfg).unwrap()
        );
        let wide = Jitter {
            translation_px: 25.0,
            spread: 0.3,
            ..Jitter::default()
        };
        let d = generate_with(&cfg, &wide).unwrap();
        assert!((0..d.len()).all(|i| d.mask(i).unwrap().data().contains(&1)));
    }

    #[test]
    fn rotation_by_zero_is_identity_and_by_90_is_exact() {
        let (h, w) = (21, 25);
        // Plus sign centred at (12, 10): symmetric under quarter turns.
        let mut plus = vec![0u8; h * w];
        for k in 0..=12 {
            plus[10 * w + 6 + k] = 1; // row 10, columns 6..=18
            plus[(4 + k) * w + 12] = 1; // column 12, rows 4..=16
        }
        assert_eq!(rot(&plus, h, w, 0.0).unwrap(), plus);
        assert_eq!(rot(&plus, h, w, 90.0).unwrap(), plus);
        assert_eq!(rot(&plus, h, w, -270.0).unwrap(), plus);
        // A horizontal bar through (12, 10) becomes a vertical one.
        let mut bar = vec![0u8; h * w];
        let mut vbar = vec![0u8; h * w];
        for k in 0..=6 {
            bar[10 * w + 9 + k] = 1;
            vbar[(7 + k) * w + 12] = 1;
        }
        assert_eq!(rot(&bar, h, w, 90.0).unwrap(), vbar);
        assert_eq!(rot(&vbar, h, w, -90.0).unwrap(), bar);
        // An L: foot to the right at the bottom; +90 (counter-clockwise on screen) turns the
        // foot upwards.
        let mut l = vec![0u8; h * w];
        for k in 0..5 {
            l[(8 + k) * w + 10] = 1; // stem, rows 8..=12 at column 10
        }
        l[12 * w + 11] = 1;
        l[12 * w + 12] = 1;
        let rl = rot(&l, h, w, 90.0).unwrap();
        assert_eq!(rl.iter().filter(|&&v| v == 1).count(), 7);
        let pts: Vec<(usize, usize)> = (0..h * w)
            .filter(|&i| rl[i] == 1)
            .map(|i| (i % w, i / w))
            .collect();
        // The stem is horizontal now and the foot points up from its right end.
        let ys: Vec<usize> = pts.iter().map(|p| p.1).collect();
        let xs: Vec<usize> = pts.iter().map(|p| p.0).collect();
        let bottom = *ys.iter().max().unwrap();
        assert_eq!(ys.iter().filter(|&&y| y == bottom).count(), 5);
        let right = *xs.iter().max().unwrap();
        assert_eq!(xs.iter().filter(|&&x| x == right).count(), 3);
        // Arbitrary angles keep the mask binary; a 360 turn is the identity.
        let r = rot(&l, h, w, 13.7).unwrap();
        assert!(r.iter().all(|&v| v <= 1));
        assert_eq!(rot(&l, h, w, 360.0).unwrap(), l);
        // Any non-zero byte counts as foreground.
        let l7: Vec<u8> = l.iter().map(|&v| 7 * v).collect();
        assert_eq!(rot(&l7, h, w, 0.0).unwrap(), l);
        assert!(rot(&l, h, w, f64::NAN).is_err());
        assert!(rot(&l, h, w + 1, 10.0).is_err());
        assert_eq!(rot(&[0; 6], 2, 3, 30.0).unwrap(), vec![0; 6]);
    }

    #[test]
    fn downscale_averages_exactly() {
        #[rustfmt::skip]
        let m = [
            1, 1, 0, 1, 0,
            1, 0, 0, 1, 1,
            0, 0, 0, 0, 1,
            1, 1, 1, 1, 0,
        ];
        let d = down(&m, 4, 5, 3).unwrap();
        // Blocks: rows 0-2 x cols 0-2, rows 0-2 x cols 3-4, row 3 x cols 0-2, row 3 x 3-4.
        assert_eq!(d, vec![3.0 / 9.0, 4.0 / 6.0, 1.0, 0.5]);
        let d = down(&m, 4, 5, 1).unwrap();
        assert_eq!(d, m.iter().map(|&v| f64::from(v)).collect::<Vec<_>>());
        assert!(down(&m, 4, 5, 0).is_err());
        assert!(down(&m, 5, 5, 2).is_err());
        let full = vec![1u8; 165 * 120];
        let d = down(&full, 165, 120, DOWNSCALE).unwrap();
        assert_eq!(d.len(), 2200);
        assert!(d.iter().all(|&v| v == 1.0));
    }

    /// Frames of the right count and labels with tiny 6 x 6 masks, for protocol tests at the
    /// paper's sizes.
    fn tiny(n_per_class: usize) -> SynthData {
        let n = 5 * n_per_class;
        let mut masks = vec![0u8; n * 36];
        for i in 0..n {
            // A 2x2 square at a frame-dependent place: lets rows be traced back to frames.
            let (x, y) = (i % 5, (i / 5) % 5);
            for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                masks[i * 36 + (y + dy) * 6 + x + dx] = 1;
            }
        }
        SynthData {
            masks,
            depth: vec![0.0; n * 36],
            labels: (0..n).map(|i| (i / n_per_class) as u32).collect(),
            subjects: vec![0; n],
            height: 6,
            width: 6,
        }
    }

    #[test]
    fn split_has_paper_sizes_and_no_leakage() {
        let d = tiny(3000);
        let s = split_protocol(&d, 300, 1000, 0).unwrap();
        assert_eq!((s.dim, s.shape), (4, (2, 2)));
        assert_eq!(s.train_y.len(), 5 * 3700);
        assert_eq!(s.test_y.len(), 5 * 300);
        assert_eq!(s.train_x.len(), 5 * 3700 * 4);
        assert_eq!(s.test_x.len(), 5 * 300 * 4);
        for c in 0..5u32 {
            assert_eq!(s.train_y.iter().filter(|&&y| y == c).count(), 3700);
            assert_eq!(s.test_y.iter().filter(|&&y| y == c).count(), 300);
            let rotated = (0..s.train_y.len())
                .filter(|&i| s.train_y[i] == c && s.train_rotation[i] != 0.0)
                .count();
            assert_eq!(rotated, 1000);
        }
        let test: std::collections::HashSet<usize> = s.test_index.iter().copied().collect();
        assert_eq!(test.len(), 1500);
        assert!(s.train_index.iter().all(|f| !test.contains(f)));
        // Originals are each used once, rotated copies come from distinct training frames.
        let originals: std::collections::HashSet<usize> = (0..s.train_index.len())
            .filter(|&i| s.train_rotation[i] == 0.0)
            .map(|i| s.train_index[i])
            .collect();
        assert_eq!(originals.len(), 5 * 2700);
        let copies: std::collections::HashSet<usize> = (0..s.train_index.len())
            .filter(|&i| s.train_rotation[i] != 0.0)
            .map(|i| s.train_index[i])
            .collect();
        assert_eq!(copies.len(), 5 * 1000);
        assert!(s
            .train_rotation
            .iter()
            .all(|&a| a == 0.0 || (10.0..=20.0).contains(&a.abs())));
        assert!(s.train_rotation.iter().any(|&a| a < 0.0));
        assert!(s.train_rotation.iter().any(|&a| a > 0.0));
        for (i, &f) in s.train_index.iter().enumerate() {
            assert_eq!(s.train_y[i], d.labels[f]);
        }
        assert_eq!(s, split_protocol(&d, 300, 1000, 0).unwrap());
        assert_ne!(
            s.test_index,
            split_protocol(&d, 300, 1000, 1).unwrap().test_index
        );
        // Too many test or augmented frames.
        assert!(split_protocol(&d, 3000, 0, 0).is_err());
        assert!(split_protocol(&d, 300, 2701, 0).is_err());
        let mut bad = tiny(3);
        bad.masks.pop();
        assert!(split_protocol(&bad, 1, 1, 0).is_err());
    }

    #[test]
    fn split_of_generated_frames() {
        let d = generate(&small(1)).unwrap();
        let s = split_protocol(&d, 10, 15, 2).unwrap();
        assert_eq!((s.dim, s.shape), (2200, (55, 40)));
        assert_eq!(s.train_y.len(), 5 * 45);
        assert_eq!(s.test_y.len(), 50);
        assert!(s
            .train_x
            .iter()
            .chain(&s.test_x)
            .all(|&v| (0.0..=1.0).contains(&v)));
        // Original rows are the downscaled frames.
        let f = s.train_index[0];
        assert_eq!(
            &s.train_x[..2200],
            downscale(d.mask(f).unwrap(), 3).unwrap().data()
        );
        let test: std::collections::HashSet<usize> = s.test_index.iter().copied().collect();
        assert!(s.train_index.iter().all(|f| !test.contains(f)));
        // A rotated copy is the rotated, downscaled source frame.
        let i = s.train_rotation.iter().position(|&a| a != 0.0).unwrap();
        let (f, a) = (s.train_index[i], s.train_rotation[i]);
        let want = downscale(rotate_mask(d.mask(f).unwrap(), a).unwrap().view(), 3).unwrap();
        assert_eq!(&s.train_x[i * 2200..(i + 1) * 2200], want.data());
        // Rotated test rows: none at angle 0; otherwise the test frames rotated.
        let same = rotated_rows(d.mask_stack().unwrap(), &s.test_index, 0.0, 0.0, 5).unwrap();
        assert_eq!(same, s.test_x);
        let rot = rotated_rows(d.mask_stack().unwrap(), &s.test_index, 10.0, 20.0, 5).unwrap();
        assert_eq!(rot.len(), s.test_x.len());
        assert_ne!(rot, s.test_x);
        assert!(rotated_rows(d.mask_stack().unwrap(), &s.test_index, 20.0, 10.0, 5).is_err());
        assert!(rotated_rows(d.mask_stack().unwrap(), &[d.len()], 10.0, 20.0, 5).is_err());
    }
}
