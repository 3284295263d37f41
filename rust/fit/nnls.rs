//! Lawson–Hanson non-negative least squares on a small dense system.
//!
//! Every unconstrained sub-problem is solved by a Householder QR of the passive
//! columns; callers scale the columns first (τ spans many decades, so raw
//! columns differ by up to 10²⁰ in norm). The sub-problems are at most 18
//! columns by a few dozen rows and a fit solves thousands of them, so the QR is
//! an unblocked one on a buffer the whole NNLS reuses: faer's blocked QR spent
//! more time allocating and dispatching than factorising at this size, and its
//! matrix products dispatch on the CPU (AVX-512, AVX2 or portable kernels that
//! round differently), where this loop gives the same bits on every CPU. The
//! Fisher matrix is inverted by the same QR. Reference: Lawson & Hanson,
//! *Solving Least Squares Problems* (1974), ch. 23.

use faer::Mat;

use crate::error::{CoreError, CoreResult};

/// Relative size below which a diagonal entry of R makes the sub-problem
/// numerically rank deficient.
const RANK_TOL: f64 = 1e-12;

/// The same for the Fisher matrix's inverse, whose columns are scaled to unit
/// diagonal first.
const INVERSE_RANK_TOL: f64 = 1e-13;

/// Householder QR, in place, of the n × p column-major matrix at the front of
/// `work`, every later n-row column of `work` (right-hand sides) reflected with
/// it; R stays above the diagonal. R's diagonal, or `None` for a zero or
/// non-finite column.
fn householder(work: &mut [f64], n: usize, p: usize) -> Option<Vec<f64>> {
    let mut diag = vec![0.0; p];
    for c in 0..p {
        let (done, rest) = work.split_at_mut((c + 1) * n);
        let v = &mut done[c * n + c..];
        let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        if norm == 0.0 || !norm.is_finite() {
            return None;
        }
        let alpha = if v[0] > 0.0 { -norm } else { norm };
        v[0] -= alpha;
        let vv = v.iter().map(|x| x * x).sum::<f64>();
        diag[c] = alpha;
        if vv == 0.0 {
            continue;
        }
        let beta = 2.0 / vv;
        // Reflect every later column and the right-hand sides.
        for col in rest.chunks_exact_mut(n) {
            let tail = &mut col[c..];
            let s = beta * v.iter().zip(tail.iter()).map(|(x, y)| x * y).sum::<f64>();
            for (t, x) in tail.iter_mut().zip(v.iter()) {
                *t -= s * x;
            }
        }
    }
    Some(diag)
}

/// Whether R (its diagonal) is numerically full rank: no pivot below
/// `tol` times the largest.
fn full_rank(diag: &[f64], tol: f64) -> bool {
    let rmax = diag.iter().fold(0.0_f64, |m, d| m.max(d.abs()));
    !(rmax.is_nan() || rmax <= 0.0 || diag.iter().any(|d| d.abs() <= tol * rmax))
}

/// Solves R x = y by back-substitution, R from [`householder`] (its rows of
/// length n in `work`, its diagonal `diag`); `None` if x is not finite.
fn back_substitute(work: &[f64], n: usize, diag: &[f64], y: &[f64]) -> Option<Vec<f64>> {
    let p = diag.len();
    let mut x = vec![0.0; p];
    for c in (0..p).rev() {
        let mut s = y[c];
        for d in c + 1..p {
            s -= work[d * n + c] * x[d];
        }
        x[c] = s / diag[c];
        if !x[c].is_finite() {
            return None;
        }
    }
    Some(x)
}

/// Least squares restricted to the columns in `passive`; `None` when that
/// sub-problem is not numerically full rank. `work` is scratch space.
fn solve_passive(
    a: &Mat<f64>,
    b: &[f64],
    passive: &[bool],
    work: &mut Vec<f64>,
) -> Option<Vec<f64>> {
    let k = a.ncols();
    let cols: Vec<usize> = (0..k).filter(|&j| passive[j]).collect();
    let mut out = vec![0.0; k];
    let p = cols.len();
    if p == 0 {
        return Some(out);
    }
    let n = a.nrows();
    if n < p {
        return None;
    }
    // Column-major n × p copy of the passive columns, then the right-hand side.
    work.clear();
    for &j in &cols {
        work.extend_from_slice(a.col_as_slice(j));
    }
    work.extend_from_slice(b);
    let diag = householder(work, n, p)?;
    if !full_rank(&diag, RANK_TOL) {
        return None;
    }
    let x = back_substitute(work, n, &diag, &work[p * n..])?;
    for (c, &j) in cols.iter().enumerate() {
        out[j] = x[c];
    }
    Some(out)
}

/// Minimise ‖a x − b‖ subject to x ≥ 0 and x_j = 0 where `!allowed[j]`.
pub fn nnls(a: &Mat<f64>, b: &[f64], allowed: &[bool]) -> CoreResult<Vec<f64>> {
    let (n, k) = (a.nrows(), a.ncols());
    let mut x = vec![0.0; k];
    let mut passive = vec![false; k];
    // The gradient aᵀ(b − a x), a column at a time (faer stores columns contiguously).
    let gradient = |x: &[f64]| -> Vec<f64> {
        let mut r = b.to_vec();
        for (j, &xj) in x.iter().enumerate() {
            if xj != 0.0 {
                for (ri, aij) in r.iter_mut().zip(a.col_as_slice(j)) {
                    *ri -= aij * xj;
                }
            }
        }
        (0..k)
            .map(|j| {
                a.col_as_slice(j)
                    .iter()
                    .zip(&r)
                    .map(|(aij, ri)| aij * ri)
                    .sum()
            })
            .collect()
    };
    let scale = b
        .iter()
        .map(|v| v * v)
        .sum::<f64>()
        .sqrt()
        .max(f64::MIN_POSITIVE);
    let tol = 1e-12 * scale * (n as f64).sqrt();
    let limit = 3 * k + 10;
    let mut work = Vec::with_capacity(n * (k + 1));
    for _ in 0..limit {
        let w = gradient(&x);
        let candidate = (0..k)
            .filter(|&j| allowed[j] && !passive[j] && w[j] > tol)
            .max_by(|&i, &j| w[i].total_cmp(&w[j]));
        let Some(j) = candidate else {
            return Ok(x);
        };
        passive[j] = true;
        let mut inner = 0;
        loop {
            inner += 1;
            if inner > limit {
                return Err(CoreError::Numerical(
                    "noise-model NNLS did not converge (inner loop)".into(),
                ));
            }
            let Some(z) = solve_passive(a, b, &passive, &mut work) else {
                // The new column is (numerically) dependent on the others.
                passive[j] = false;
                if passive.iter().all(|p| !p) {
                    return Ok(x);
                }
                break;
            };
            if (0..k).all(|c| !passive[c] || z[c] > 0.0) {
                x = z;
                break;
            }
            // Step from x towards z as far as feasibility allows.
            let mut alpha = f64::INFINITY;
            for c in 0..k {
                if passive[c] && z[c] <= 0.0 {
                    let denom = x[c] - z[c];
                    alpha = alpha.min(if denom > 0.0 { x[c] / denom } else { 0.0 });
                }
            }
            if !alpha.is_finite() {
                alpha = 0.0;
            }
            for c in 0..k {
                x[c] += alpha * (z[c] - x[c]);
                if passive[c] && x[c] <= 1e-15 * (x[c].abs() + z[c].abs()).max(f64::MIN_POSITIVE) {
                    x[c] = 0.0;
                    passive[c] = false;
                }
            }
            if passive.iter().all(|p| !p) {
                break;
            }
        }
    }
    Err(CoreError::Numerical(
        "noise-model NNLS did not converge".into(),
    ))
}

/// Invert the symmetric positive definite k × k matrix `m` (row-major);
/// `None` when it is singular. The same unblocked QR as the sub-problems: its
/// operations do not depend on the CPU, so neither do the fit's uncertainties.
pub fn invert_spd(m: &[Vec<f64>]) -> Option<Vec<Vec<f64>>> {
    let k = m.len();
    if k == 0 {
        return Some(Vec::new());
    }
    // Scale to unit diagonal so the pivots compare, then invert by QR solves.
    let d: Vec<f64> = (0..k).map(|i| m[i][i].abs().sqrt()).collect();
    if d.iter().any(|v| *v == 0.0 || !v.is_finite()) {
        return None;
    }
    // Column-major: the scaled matrix, then the identity's k columns.
    let mut work = Vec::with_capacity(2 * k * k);
    for j in 0..k {
        work.extend((0..k).map(|i| m[i][j] / (d[i] * d[j])));
    }
    for j in 0..k {
        work.extend((0..k).map(|i| if i == j { 1.0 } else { 0.0 }));
    }
    let diag = householder(&mut work, k, k)?;
    if !full_rank(&diag, INVERSE_RANK_TOL) {
        return None;
    }
    let columns: Vec<Vec<f64>> = (0..k)
        .map(|j| back_substitute(&work, k, &diag, &work[(k + j) * k..(k + j + 1) * k]))
        .collect::<Option<_>>()?;
    Some(
        (0..k)
            .map(|i| (0..k).map(|j| columns[j][i] / (d[i] * d[j])).collect())
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clamps_the_negative_direction() {
        // b = 1·col0 − 0.5·col1: the constrained optimum has x1 = 0.
        let a = Mat::from_fn(4, 2, |i, j| if j == 0 { 1.0 } else { i as f64 });
        let b: Vec<f64> = (0..4).map(|i| 1.0 - 0.5 * i as f64).collect();
        let x = nnls(&a, &b, &[true, true]).unwrap();
        assert_eq!(x[1], 0.0);
        assert!(x[0] >= 0.0);
    }

    #[test]
    fn exact_positive_solution() {
        let a = Mat::from_fn(5, 3, |i, j| ((i + 1) as f64).powi(j as i32));
        let truth = [2.0, 0.5, 0.25];
        let b: Vec<f64> = (0..5)
            .map(|i| (0..3).map(|j| a[(i, j)] * truth[j]).sum())
            .collect();
        let x = nnls(&a, &b, &[true; 3]).unwrap();
        for j in 0..3 {
            assert!((x[j] - truth[j]).abs() < 1e-10);
        }
        let none = nnls(&a, &b, &[false; 3]).unwrap();
        assert_eq!(none, vec![0.0; 3]);
    }

    #[test]
    fn inverse_of_spd() {
        let m = vec![vec![4.0, 1.0], vec![1.0, 3.0]];
        let inv = invert_spd(&m).unwrap();
        let det = 11.0;
        assert!((inv[0][0] - 3.0 / det).abs() < 1e-14);
        assert!((inv[0][1] + 1.0 / det).abs() < 1e-14);
        assert!(invert_spd(&[vec![1.0, 1.0], vec![1.0, 1.0]]).is_none());
    }
}
