//! Allocations whose size comes from a user's argument, checked before any memory is taken.
//!
//! Rust aborts the process when an allocation fails, and on Linux (which overcommits memory)
//! a request far larger than the machine often *succeeds* and the process is killed later by
//! the out-of-memory killer. So every buffer whose length follows from an argument (an image
//! size, a sample count, a number of frames) goes through this module, which
//!
//! 1. multiplies the dimensions with overflow checks ([`elements`]),
//! 2. refuses a request larger than the memory limit ([`limit`]): by default the machine's
//!    physical memory, read once from the operating system; a user may raise or lower it with
//!    the environment variable `WSCG_MAX_MEMORY` (bytes, read on first use) or with
//!    [`set_limit`] (the Python `wscg.set_memory_limit`),
//! 3. reserves with [`Vec::try_reserve_exact`], so a refusal of the allocator is an error too.
//!
//! A refusal is [`Error::OutOfMemory`] naming the argument; the Python bindings raise
//! `MemoryError` for it, as numpy does for an array that does not fit.

use crate::error::{Error, Result};
pub use crate::memory_limit::{default_limit, limit, physical_memory, set_limit, ENV_VAR};

/// Refuses a request of `bytes` bytes (`None`: a count that overflowed) for the argument
/// `what` that exceeds [`limit`].
pub fn ensure_bytes(what: &'static str, bytes: Option<u128>) -> Result<()> {
    let limit = limit();
    match bytes {
        Some(b) if b <= limit as u128 && b <= isize::MAX as u128 => Ok(()),
        _ => Err(Error::OutOfMemory {
            what,
            bytes,
            limit: Some(limit),
        }),
    }
}

/// The error for a size that overflows before it can be counted in bytes (a product or sum
/// of arguments beyond `usize`), naming `what`.
pub fn overflow(what: &'static str) -> Error {
    Error::OutOfMemory {
        what,
        bytes: None,
        limit: Some(limit()),
    }
}

/// The product of `dims`, the number of elements of an array of that shape, checked: an
/// overflow of `usize` is [`Error::OutOfMemory`] naming `what`.
pub fn elements(what: &'static str, dims: &[usize]) -> Result<usize> {
    dims.iter()
        .try_fold(1usize, |acc, &d| acc.checked_mul(d))
        .ok_or_else(|| Error::OutOfMemory {
            what,
            bytes: dims
                .iter()
                .try_fold(1u128, |acc, &d| acc.checked_mul(d as u128)),
            limit: Some(limit()),
        })
}

/// Checks that `n` values of `T` fit in [`limit`].
pub fn ensure<T>(what: &'static str, n: usize) -> Result<()> {
    ensure_bytes(
        what,
        (n as u128).checked_mul(std::mem::size_of::<T>() as u128),
    )
}

/// Checks that an array of shape `dims` with elements of `T` fits; returns its element count.
pub fn ensure_shape<T>(what: &'static str, dims: &[usize]) -> Result<usize> {
    let n = elements(what, dims)?;
    ensure::<T>(what, n)?;
    Ok(n)
}

/// An empty vector with room for `n` values of `T`, or [`Error::OutOfMemory`] naming `what`
/// when `n` values exceed [`limit`] or the allocator refuses them.
pub fn try_with_capacity<T>(what: &'static str, n: usize) -> Result<Vec<T>> {
    ensure::<T>(what, n)?;
    let mut v = Vec::new();
    v.try_reserve_exact(n).map_err(|_| Error::OutOfMemory {
        what,
        bytes: (n as u128).checked_mul(std::mem::size_of::<T>() as u128),
        limit: None,
    })?;
    Ok(v)
}

/// `n` copies of `value` (`vec![value; n]`), or [`Error::OutOfMemory`] naming `what`.
pub fn try_vec<T: Clone>(what: &'static str, value: T, n: usize) -> Result<Vec<T>> {
    let mut v = try_with_capacity(what, n)?;
    v.resize(n, value);
    Ok(v)
}

/// `vec![value; n]` for an `n` that a user's argument sets: evaluates to
/// `wscg_math::Result<Vec<_>>`, refusing with [`Error::OutOfMemory`] naming the argument
/// (`try_vec![0.0f32; h * w; "shape"]`; the size expression is computed as written, so
/// multiply with [`elements`] where a product could overflow).
#[macro_export]
macro_rules! try_vec {
    ($value:expr; $n:expr; $what:expr) => {
        $crate::alloc::try_vec($what, $value, $n)
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overflowing_shapes_are_refused_by_name() {
        let e = elements("shape", &[usize::MAX, 2]).unwrap_err();
        assert_eq!(e.argument(), Some("shape"));
        assert!(matches!(e, Error::OutOfMemory { .. }));
        assert_eq!(elements("shape", &[3, 4, 5]).unwrap(), 60);
        assert_eq!(elements("shape", &[]).unwrap(), 1);
    }

    #[test]
    fn requests_above_the_limit_are_refused_before_allocating() {
        // 2^61 f64 values are 16 EiB: more than any machine, so refused whatever the limit.
        let e = try_vec("n", 0.0f64, 1usize << 61).unwrap_err();
        assert_eq!(e.argument(), Some("n"));
        let msg = e.to_string();
        assert!(msg.contains("`n`") && msg.contains("bytes"), "{msg}");
        assert_eq!(try_vec("n", 7u8, 3).unwrap(), vec![7, 7, 7]);
        assert_eq!(crate::try_vec![1i32; 2; "k"].unwrap(), vec![1, 1]);
        assert!(try_with_capacity::<u64>("n", 10).unwrap().capacity() >= 10);
    }

    #[test]
    fn physical_memory_is_the_default_limit() {
        if std::env::var_os(ENV_VAR).is_none() {
            if let Some(m) = physical_memory() {
                assert!(m > 1 << 20);
                assert_eq!(default_limit(), m);
            }
        }
        assert!(limit() > 0);
    }
}
