//! A small clip shared by the unit tests of the search modules.

use crate::patch::{valid_sources, PatchSize};
use crate::synth::{pan_clip, Clip};
use crate::video::Mask3;

/// A 6 x 24 x 32 pan with a 4 x 4 logo hole, 3 x 3 x 3 patches and the valid sources.
pub(crate) fn small_pan() -> (Clip, PatchSize, Mask3) {
    let clip = pan_clip(6, 24, 32, 2.0, 4, 4, 3).unwrap();
    let patch = PatchSize {
        px: 3,
        py: 3,
        pt: 3,
    };
    let sources = valid_sources(&clip.hole, patch);
    (clip, patch, sources)
}
