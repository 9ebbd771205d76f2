//! Williams Latin squares: presentation orders balanced for first-order carry-over effects.
//!
//! Paper 07 (§4) presents the 13 plates to every observer "following a Williams Latin Square
//! Design". A Williams design is a set of sequences (one per subject) in which
//!
//! * every sequence is a permutation of the `n` treatments,
//! * every treatment appears equally often in every position, and
//! * every ordered pair of distinct treatments `(a, b)`, `b` presented immediately after `a`,
//!   occurs equally often.
//!
//! For even `n` one Latin square of `n` rows achieves this (each ordered pair exactly once). For
//! odd `n` no single square can, and the design is the square followed by its mirror image
//! (each row reversed): `2n` rows, each position holding each treatment twice and each ordered
//! pair occurring exactly twice. For the paper's `n = 13` that is 26 sequences, one per observer.
//!
//! Construction (Williams 1949): the first row is `0, 1, n−1, 2, n−2, 3, …`; row `i` adds `i`
//! modulo `n` to every entry.

use wscg_math::{Error, Result};

/// Largest `n` accepted by [`williams_square`] (the design holds up to `2n²` entries).
pub const MAX_TREATMENTS: usize = 4096;

/// Williams design for `n` treatments (numbered `0..n`): `n` sequences for even `n`, `2n` for
/// odd `n` (the square and its mirror). Subject `s` is given sequence `s % rows`.
///
/// # Errors
/// [`Error::InvalidArgument`] for `n < 2`; [`Error::LimitExceeded`] for `n > MAX_TREATMENTS`.
pub fn williams_square(n: usize) -> Result<Vec<Vec<usize>>> {
    if n < 2 {
        return Err(Error::invalid(
            "n",
            format!("a Williams design needs at least 2 treatments, got {n}"),
        ));
    }
    if n > MAX_TREATMENTS {
        return Err(Error::LimitExceeded(format!(
            "n = {n} treatments; at most {MAX_TREATMENTS} are supported"
        )));
    }
    // First row 0, 1, n-1, 2, n-2, ...: alternate climbing from the bottom and descending from the top.
    let mut first = Vec::with_capacity(n);
    first.push(0);
    let (mut lo, mut hi) = (1usize, n);
    for j in 1..n {
        if j % 2 == 1 {
            first.push(lo);
            lo += 1;
        } else {
            hi -= 1;
            first.push(hi);
        }
    }
    let mut rows: Vec<Vec<usize>> = (0..n)
        .map(|i| first.iter().map(|&v| (v + i) % n).collect())
        .collect();
    if n % 2 == 1 {
        let mirrored: Vec<Vec<usize>> = rows
            .iter()
            .map(|r| r.iter().rev().copied().collect())
            .collect();
        rows.extend(mirrored);
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_rows_follow_williams_construction() {
        let s = williams_square(4).unwrap();
        assert_eq!(
            s,
            vec![
                vec![0, 1, 3, 2],
                vec![1, 2, 0, 3],
                vec![2, 3, 1, 0],
                vec![3, 0, 2, 1]
            ]
        );
        let s = williams_square(3).unwrap();
        assert_eq!(s.len(), 6);
        assert_eq!(s[0], vec![0, 1, 2]);
        assert_eq!(s[3], vec![2, 1, 0]);
    }

    #[test]
    fn small_and_huge_n_are_errors() {
        assert!(williams_square(0).is_err());
        assert!(williams_square(1).is_err());
        assert!(matches!(
            williams_square(MAX_TREATMENTS + 1),
            Err(Error::LimitExceeded(_))
        ));
    }
}
