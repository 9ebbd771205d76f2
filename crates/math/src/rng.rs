//! Seeded, portable random generation.
//!
//! Every random process in wscg takes an explicit `u64` seed. The generator is ChaCha8
//! (`rand_chacha`), whose output is the same on every platform and version, so a seed
//! reproduces a result exactly. Parallel fills split the output into fixed blocks, each with
//! its own ChaCha stream, so the result does not depend on the number of threads.

use rand::{Rng as _, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use rayon::prelude::*;

use crate::error::{Error, Result};

/// The generator used throughout wscg.
pub type Rng = ChaCha8Rng;

/// Values per independent stream in the parallel fills.
const BLOCK: usize = 4096;

/// A generator seeded with `seed`.
pub fn seeded(seed: u64) -> Rng {
    ChaCha8Rng::seed_from_u64(seed)
}

/// Generator number `stream` of the family seeded with `seed`: streams are independent and
/// reproducible, for splitting work between threads or items.
pub fn stream(seed: u64, stream: u64) -> Rng {
    let mut r = ChaCha8Rng::seed_from_u64(seed);
    r.set_stream(stream);
    r
}

/// `n` samples of a normal distribution N(`mean`, `std`^2), filled in parallel.
///
/// Errors: `std` negative or non-finite, `mean` non-finite.
pub fn normal_vec(seed: u64, n: usize, mean: f64, std: f64) -> Result<Vec<f64>> {
    if !mean.is_finite() {
        return Err(Error::invalid(
            "mean",
            format!("must be finite, got {mean}"),
        ));
    }
    let dist = Normal::new(mean, std)
        .ok()
        .filter(|_| std.is_finite() && std >= 0.0)
        .ok_or_else(|| Error::invalid("std", format!("must be finite and >= 0, got {std}")))?;
    par_fill(seed, n, |r| dist.sample(r))
}

/// `n` complex samples with independent N(0, `std`^2) real and imaginary parts.
///
/// Errors: as [`normal_vec`].
pub fn complex_normal_vec(seed: u64, n: usize, std: f64) -> Result<Vec<num_complex::Complex64>> {
    let twice = crate::alloc::elements("n", &[n, 2])?;
    let v = normal_vec(seed, twice, 0.0, std)?;
    Ok(v.chunks(2)
        .map(|p| num_complex::Complex64::new(p[0], p[1]))
        .collect())
}

/// `n` values drawn by `sample`, in blocks of [`BLOCK`] with one stream per block, so the
/// output depends on the seed only, not on the thread count.
///
/// Errors: [`Error::OutOfMemory`] naming `n` when `n` values do not fit ([`crate::alloc`]).
pub fn par_fill<T: Send + Default + Clone>(
    seed: u64,
    n: usize,
    sample: impl Fn(&mut Rng) -> T + Sync,
) -> Result<Vec<T>> {
    let mut out = crate::alloc::try_vec("n", T::default(), n)?;
    out.par_chunks_mut(BLOCK)
        .enumerate()
        .for_each(|(b, chunk)| {
            let mut r = stream(seed, b as u64);
            for v in chunk {
                *v = sample(&mut r);
            }
        });
    Ok(out)
}

/// `n` samples uniform in `[lo, hi)`, filled in parallel.
///
/// Errors: bounds non-finite or `lo >= hi`.
pub fn uniform_vec(seed: u64, n: usize, lo: f64, hi: f64) -> Result<Vec<f64>> {
    if !(lo.is_finite() && hi.is_finite() && lo < hi) {
        return Err(Error::invalid(
            "lo, hi",
            format!("need finite lo < hi, got [{lo}, {hi})"),
        ));
    }
    par_fill(seed, n, |r| r.random_range(lo..hi))
}

/// A uniformly random permutation of `0..n`.
///
/// Errors: [`Error::OutOfMemory`] naming `n` when `n` indices do not fit ([`crate::alloc`]).
pub fn permutation(seed: u64, n: usize) -> Result<Vec<usize>> {
    let mut p = crate::alloc::try_with_capacity("n", n)?;
    p.extend(0..n);
    shuffle(&mut p, &mut seeded(seed));
    Ok(p)
}

/// Shuffles `v` in place (Fisher-Yates, from the last element down).
pub fn shuffle<T>(v: &mut [T], r: &mut Rng) {
    for i in (1..v.len()).rev() {
        let j = r.random_range(0..=i);
        v.swap(i, j);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_seed_same_values_independent_of_threads() {
        let a = normal_vec(7, 10_000, 1.0, 2.0).unwrap();
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let b = pool.install(|| normal_vec(7, 10_000, 1.0, 2.0).unwrap());
        assert_eq!(a, b);
        assert_ne!(a, normal_vec(8, 10_000, 1.0, 2.0).unwrap());
    }

    #[test]
    fn normal_moments_are_right() {
        let n = 200_000;
        let v = normal_vec(1, n, 3.0, 0.5).unwrap();
        let mean = v.iter().sum::<f64>() / n as f64;
        let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n as f64;
        // Standard errors: 0.5/sqrt(n) = 0.0011 for the mean, ~0.0008 for the variance.
        assert!((mean - 3.0).abs() < 0.006, "{mean}");
        assert!((var - 0.25).abs() < 0.004, "{var}");
        let u = uniform_vec(2, n, -1.0, 3.0).unwrap();
        assert!(u.iter().all(|&x| (-1.0..3.0).contains(&x)));
        let m = u.iter().sum::<f64>() / n as f64;
        assert!((m - 1.0).abs() < 0.015, "{m}");
    }

    #[test]
    fn streams_differ_and_permutation_is_a_permutation() {
        let a: u64 = stream(1, 0).random();
        let b: u64 = stream(1, 1).random();
        assert_ne!(a, b);
        let mut p = permutation(3, 100).unwrap();
        assert_ne!(p, (0..100).collect::<Vec<_>>());
        p.sort();
        assert_eq!(p, (0..100).collect::<Vec<_>>());
    }

    #[test]
    fn bad_parameters_are_rejected() {
        assert!(normal_vec(0, 3, 0.0, -1.0).is_err());
        assert!(normal_vec(0, 3, f64::NAN, 1.0).is_err());
        assert!(uniform_vec(0, 3, 1.0, 1.0).is_err());
    }
}
