//! The deterministic pass of the fuzz targets (FUZZING.md): every committed corpus file under
//! `fuzz/corpus/<target>/`, its truncations at every sixteenth of its length and copies with
//! bytes flipped at fixed positions go through the reader of the target, which must return
//! (`Ok` or `Err`) and never panic. The coverage-guided campaigns run the same entry points
//! (`fuzz/src/targets.rs`) under AFL++.

use std::path::{Path, PathBuf};

#[allow(dead_code)]
#[path = "../fuzz/src/targets.rs"]
mod targets;

fn corpus_files(target: &str) -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fuzz/corpus")
        .join(target);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .collect();
    files.sort();
    files
}

/// The input, its truncations at `k / 16` of its length, and copies with the byte at each
/// sixteenth of the length replaced by its complement, by 0 and by 0xff.
fn variants(bytes: &[u8]) -> Vec<Vec<u8>> {
    let n = bytes.len();
    let mut out = vec![bytes.to_vec()];
    for k in 0..16 {
        out.push(bytes[..n * k / 16].to_vec());
    }
    if n > 0 {
        for k in 0..16 {
            let at = n * k / 16;
            for value in [!bytes[at], 0, 0xff] {
                let mut v = bytes.to_vec();
                v[at] = value;
                out.push(v);
            }
        }
    }
    out
}

#[test]
fn every_reader_returns_on_its_corpus_and_simple_mutations() {
    for target in targets::TARGETS.iter().chain(targets::READER_TARGETS) {
        let files = corpus_files(target);
        assert!(!files.is_empty(), "fuzz/corpus/{target} has no seed");
        for file in &files {
            let bytes = std::fs::read(file).unwrap();
            for (k, input) in variants(&bytes).iter().enumerate() {
                let ok =
                    std::panic::catch_unwind(|| targets::run(target, input)).unwrap_or_else(|_| {
                        panic!("{target}: variant {k} of {} panicked", file.display())
                    });
                // The seeds are valid files (the ones the fuzzer kept may not be), so each
                // unmodified seed must be read.
                let seed = file
                    .file_name()
                    .unwrap()
                    .to_string_lossy()
                    .starts_with("seed_");
                assert!(
                    ok || k != 0 || !seed,
                    "{target}: the seed {} was refused",
                    file.display()
                );
            }
        }
    }
}
