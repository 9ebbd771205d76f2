//! Inputs that made a reader panic under fuzzing (FUZZING.md), kept as files: each must now
//! be an error naming the file.

use std::path::Path;

use wscg_math::{Error, Image};

/// A progressive JPEG whose upsampling scratch buffer the JPEG decoder sizes too small
/// (an assertion in its AVX2 upsampler, in release builds too; other CPUs take another path).
#[test]
fn progressive_jpeg_that_fails_the_decoders_upsampler_is_not_a_panic() {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/fuzz_progressive_upsampler.jpg");
    if let Err(err) = Image::<f32>::load(&path) {
        assert!(matches!(err, Error::Format { .. }), "{err}");
        assert!(
            err.to_string().contains("fuzz_progressive_upsampler.jpg"),
            "{err}"
        );
    }
}
