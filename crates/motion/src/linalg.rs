//! Small dense solves of the alternating least-squares steps (systems of a few unknowns, solved
//! millions of times, where a general-purpose factorisation would mostly allocate).

use num_complex::Complex64;
use wscg_math::{Error, Result};

/// Solve `A x = b` in place (`a` is `n × n` row-major and is destroyed; `b` becomes `x`) by
/// Gaussian elimination with partial pivoting. A relative ridge `ridge · max|diag|` is added to
/// the diagonal first, so that a rank-deficient normal matrix yields a finite, minimum-effort
/// answer instead of an error.
pub fn solve_in_place(a: &mut [f64], b: &mut [f64], n: usize, ridge: f64) -> Result<()> {
    debug_assert_eq!(b.len(), n);
    solve_many_in_place(a, b, n, ridge)
}

/// [`solve_in_place`] for several right-hand sides with one elimination: `b` holds them one
/// after another (`n` values each) and each becomes its solution, exactly as
/// [`solve_in_place`] would give it.
pub fn solve_many_in_place(a: &mut [f64], b: &mut [f64], n: usize, ridge: f64) -> Result<()> {
    debug_assert_eq!(a.len(), n * n);
    debug_assert_eq!(b.len() % n.max(1), 0);
    let scale = (0..n).map(|i| a[i * n + i].abs()).fold(0.0, f64::max);
    let lift = ridge * scale.max(f64::MIN_POSITIVE);
    for i in 0..n {
        a[i * n + i] += lift;
    }
    for col in 0..n {
        let piv = (col..n)
            .max_by(|&p, &q| a[p * n + col].abs().total_cmp(&a[q * n + col].abs()))
            .unwrap_or(col);
        let pv = a[piv * n + col];
        if !pv.is_finite() || pv.abs() <= f64::MIN_POSITIVE {
            return Err(Error::Numerical(format!(
                "singular {n}x{n} normal matrix in a least-squares step"
            )));
        }
        if piv != col {
            for c in 0..n {
                a.swap(piv * n + c, col * n + c);
            }
            for rhs in b.chunks_exact_mut(n) {
                rhs.swap(piv, col);
            }
        }
        for r in col + 1..n {
            let f = a[r * n + col] / pv;
            if f != 0.0 {
                for c in col..n {
                    a[r * n + c] -= f * a[col * n + c];
                }
                for rhs in b.chunks_exact_mut(n) {
                    rhs[r] -= f * rhs[col];
                }
            }
        }
    }
    for rhs in b.chunks_exact_mut(n) {
        for col in (0..n).rev() {
            let mut v = rhs[col];
            for c in col + 1..n {
                v -= a[col * n + c] * rhs[c];
            }
            rhs[col] = v / a[col * n + col];
        }
    }
    Ok(())
}

/// Solve the complex system `H c = r` (`H` is `n × n` row-major) through its real embedding
/// `[Re H, −Im H; Im H, Re H]`, with the same ridge as [`solve_in_place`].
pub fn solve_complex(
    h: &[Complex64],
    r: &[Complex64],
    n: usize,
    ridge: f64,
) -> Result<Vec<Complex64>> {
    let m = 2 * n;
    let mut a = vec![0.0; m * m];
    let mut b = vec![0.0; m];
    for i in 0..n {
        for j in 0..n {
            let v = h[i * n + j];
            a[i * m + j] = v.re;
            a[i * m + n + j] = -v.im;
            a[(n + i) * m + j] = v.im;
            a[(n + i) * m + n + j] = v.re;
        }
        b[i] = r[i].re;
        b[n + i] = r[i].im;
    }
    solve_in_place(&mut a, &mut b, m, ridge)?;
    Ok((0..n).map(|i| Complex64::new(b[i], b[n + i])).collect())
}

/// Least squares `min ‖Σ_c x_c cols[c] − y‖²` over a few columns through the normal equations.
pub fn lstsq_columns(cols: &[&[f64]], y: &[f64], ridge: f64) -> Result<Vec<f64>> {
    let n = cols.len();
    let mut a = vec![0.0; n * n];
    let mut b = vec![0.0; n];
    for i in 0..n {
        for j in i..n {
            let v: f64 = cols[i].iter().zip(cols[j]).map(|(p, q)| p * q).sum();
            a[i * n + j] = v;
            a[j * n + i] = v;
        }
        b[i] = cols[i].iter().zip(y).map(|(p, q)| p * q).sum();
    }
    solve_in_place(&mut a, &mut b, n, ridge)?;
    Ok(b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn many_right_hand_sides_equal_single_solves() {
        let a0 = vec![0.5, 2.0, -1.0, 3.0, 1.0, 0.25, -2.0, 0.75, 4.0];
        let rhs: Vec<f64> = (0..12).map(|i| ((i * 7) % 5) as f64 - 1.5).collect();
        let mut many = rhs.clone();
        solve_many_in_place(&mut a0.clone(), &mut many, 3, 0.0).unwrap();
        for (one, got) in rhs.chunks_exact(3).zip(many.chunks_exact(3)) {
            let mut b = one.to_vec();
            solve_in_place(&mut a0.clone(), &mut b, 3, 0.0).unwrap();
            assert_eq!(b, got);
            // And it is a solution (the first pivot is not on the diagonal).
            for r in 0..3 {
                let v: f64 = (0..3).map(|c| a0[r * 3 + c] * got[c]).sum();
                assert!((v - one[r]).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn solves_real_and_complex() {
        let mut a = vec![4.0, 1.0, 2.0, 3.0];
        let mut b = vec![1.0, 2.0];
        solve_in_place(&mut a, &mut b, 2, 0.0).unwrap();
        assert!(
            (4.0 * b[0] + b[1] - 1.0).abs() < 1e-14
                && (2.0 * b[0] + 3.0 * b[1] - 2.0).abs() < 1e-14
        );
        let h = [
            Complex64::new(2.0, 0.0),
            Complex64::new(0.0, 1.0),
            Complex64::new(0.0, -1.0),
            Complex64::new(3.0, 0.0),
        ];
        let r = [Complex64::new(1.0, 1.0), Complex64::new(0.5, -2.0)];
        let c = solve_complex(&h, &r, 2, 0.0).unwrap();
        for i in 0..2 {
            let v = h[i * 2] * c[0] + h[i * 2 + 1] * c[1];
            assert!((v - r[i]).norm() < 1e-13);
        }
    }
}
