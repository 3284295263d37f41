//! Weighted non-negative least squares of the IEEE 952 / 1293 noise model.
//!
//! The Allan variance of an inertial sensor is modelled as
//!
//! ```text
//! σ²(τ) = 3Q²/τ² + N²/τ + (2 ln2/π)·B² + K²τ/3 + R²τ²/2
//! ```
//!
//! which is linear in the squared coefficients `p = (Q², N², B², K², R²)`, each of
//! which must be ≥ 0. Each Allan variance estimate σ̂²ᵢ is χ²-distributed with
//! `edfᵢ` degrees of freedom, so var(σ̂²ᵢ) ≈ 2σ⁴ᵢ/edfᵢ and the weight is
//! wᵢ = edfᵢ / (2σ⁴ᵢ). Weights from the *measured* σ̂² favour the points that
//! happen to lie low (a downward bias), so after the first solve the weights are
//! recomputed from the model curve (iteratively reweighted least squares).
//!
//! The non-negativity constraint is handled with the Lawson–Hanson active-set
//! algorithm; every unconstrained sub-problem is solved by a faer QR
//! factorisation of the column-scaled, row-weighted design matrix (τ spans many
//! decades, so the raw columns differ by up to 10²⁰ in norm). The covariance of the
//! estimates comes from the final passive set: cov = D (RᵀR)⁻¹ D, with `D` the
//! column scaling and `R` the triangular QR factor, inflated by the Birge ratio
//! χ²/dof when the model fits worse than the EDF says it should.
//!
//! A term that never reaches `min_share` of the total model over the fitted taus,
//! or whose squared coefficient is less than `min_z` standard uncertainties above
//! zero, is removed (value 0, flagged unsupported) and the fit is repeated, one
//! term at a time, so a reported coefficient is always one the data constrain.
//!
//! References: IEEE Std 952-1997, Annex C; Lawson & Hanson, *Solving Least
//! Squares Problems* (1974), ch. 23; Riley, NIST SP 1065 (2008), §5.3.

use faer::linalg::solvers::SolveLstsq;
use faer::Mat;

use crate::error::{CoreError, CoreResult};

/// Number of terms of the model: Q, N, B, K, R.
pub const TERMS: usize = 5;

/// (2 ln 2)/π: the Allan variance of flicker rate noise per unit B².
pub const FLICKER_FACTOR: f64 = 2.0 * std::f64::consts::LN_2 / std::f64::consts::PI;

/// Value of each basis function (the model per unit squared coefficient) at `tau`.
pub fn basis(tau: f64) -> [f64; TERMS] {
    [
        3.0 / (tau * tau),
        1.0 / tau,
        FLICKER_FACTOR,
        tau / 3.0,
        tau * tau / 2.0,
    ]
}

/// Model Allan variance at `tau` for squared coefficients `p`.
pub fn model(p: &[f64; TERMS], tau: f64) -> f64 {
    basis(tau).iter().zip(p).map(|(b, c)| b * c).sum()
}

/// Options of [`fit_wls`].
#[derive(Debug, Clone, Copy)]
pub struct FitOptions {
    /// Which of Q, N, B, K, R may enter the model.
    pub terms: [bool; TERMS],
    /// Reweighting passes after the first solve (weights from the model curve).
    pub reweight: usize,
    /// A term must reach this share of the total model at some fitted tau.
    pub min_share: f64,
    /// A squared coefficient must be at least this many standard uncertainties
    /// above 0 (2 on N² means N ≥ 4·u(N)).
    pub min_z: f64,
}

impl Default for FitOptions {
    fn default() -> Self {
        FitOptions {
            terms: [true; TERMS],
            reweight: 3,
            min_share: 0.25,
            min_z: 2.0,
        }
    }
}

/// Result of [`fit_wls`] for one channel.
#[derive(Debug, Clone, PartialEq)]
pub struct WlsFit {
    /// Estimates of (Q², N², B², K², R²), all ≥ 0.
    pub coef: [f64; TERMS],
    /// Covariance of `coef` (rows/columns of terms fixed at 0 are 0).
    pub cov: [[f64; TERMS]; TERMS],
    /// Whether each term is in the model (positive and supported by the data).
    pub supported: [bool; TERMS],
    /// Weighted residual sum of squares (with the final weights).
    pub chi2: f64,
    /// Degrees of freedom of the fit: points − free terms.
    pub dof: usize,
}

fn invalid(msg: String) -> CoreError {
    CoreError::InvalidArgument(msg)
}

/// Check the inputs of [`fit_wls`]; returns the number of points.
fn validate(taus: &[f64], var: &[f64], edf: &[f64]) -> CoreResult<usize> {
    let n = taus.len();
    if n == 0 {
        return Err(invalid("taus must not be empty".into()));
    }
    if var.len() != n || edf.len() != n {
        return Err(invalid(format!(
            "taus, var and edf must have the same length; got {}, {} and {}",
            n,
            var.len(),
            edf.len()
        )));
    }
    for (i, &t) in taus.iter().enumerate() {
        if !(t.is_finite() && t > 0.0) {
            return Err(invalid(format!(
                "taus must be finite and > 0; taus[{i}] = {t}"
            )));
        }
        if i > 0 && t <= taus[i - 1] {
            return Err(invalid(format!(
                "taus must be strictly increasing; taus[{}] = {} ≥ taus[{i}] = {t}",
                i - 1,
                taus[i - 1]
            )));
        }
    }
    for (i, &v) in var.iter().enumerate() {
        if !(v.is_finite() && v > 0.0) {
            return Err(invalid(format!(
                "var must be finite and > 0; var[{i}] = {v}"
            )));
        }
    }
    for (i, &e) in edf.iter().enumerate() {
        if !(e.is_finite() && e > 0.0) {
            return Err(invalid(format!(
                "edf must be finite and > 0; edf[{i}] = {e}"
            )));
        }
    }
    Ok(n)
}

/// Unconstrained weighted least squares restricted to the columns in `passive`.
///
/// `a` is the scaled, weighted design (n × TERMS), `b` the weighted data.
/// Returns the solution (0 outside `passive`) or `None` when the sub-problem is
/// not numerically full rank.
fn solve_passive(a: &Mat<f64>, b: &[f64], passive: &[bool; TERMS]) -> Option<[f64; TERMS]> {
    let cols: Vec<usize> = (0..TERMS).filter(|&j| passive[j]).collect();
    let mut out = [0.0; TERMS];
    if cols.is_empty() {
        return Some(out);
    }
    let n = a.nrows();
    if n < cols.len() {
        return None;
    }
    let sub = Mat::from_fn(n, cols.len(), |i, k| a[(i, cols[k])]);
    let rhs = Mat::from_fn(n, 1, |i, _| b[i]);
    let qr = sub.qr();
    // Rank check on the triangular factor before trusting the solve.
    let r = qr.thin_R();
    let rmax = (0..cols.len()).map(|k| r[(k, k)].abs()).fold(0.0, f64::max);
    if rmax.is_nan() || rmax <= 0.0 || (0..cols.len()).any(|k| r[(k, k)].abs() <= 1e-12 * rmax) {
        return None;
    }
    let x = qr.solve_lstsq(&rhs);
    for (k, &j) in cols.iter().enumerate() {
        let v = x[(k, 0)];
        if !v.is_finite() {
            return None;
        }
        out[j] = v;
    }
    Some(out)
}

/// Lawson–Hanson NNLS: minimise ‖a x − b‖ subject to x ≥ 0, x_j = 0 where `!allowed[j]`.
fn nnls(a: &Mat<f64>, b: &[f64], allowed: &[bool; TERMS]) -> CoreResult<[f64; TERMS]> {
    let n = a.nrows();
    let mut x = [0.0; TERMS];
    let mut passive = [false; TERMS];
    let gradient = |x: &[f64; TERMS]| -> [f64; TERMS] {
        // w = aᵀ(b − a x)
        let mut w = [0.0; TERMS];
        for i in 0..n {
            let mut r = b[i];
            for (j, xj) in x.iter().enumerate() {
                r -= a[(i, j)] * xj;
            }
            for (j, wj) in w.iter_mut().enumerate() {
                *wj += a[(i, j)] * r;
            }
        }
        w
    };
    let scale = b
        .iter()
        .map(|v| v * v)
        .sum::<f64>()
        .sqrt()
        .max(f64::MIN_POSITIVE);
    let tol = 1e-12 * scale * (n as f64).sqrt();
    for _outer in 0..(3 * TERMS + 10) {
        let w = gradient(&x);
        // The most promising term not yet free.
        let candidate = (0..TERMS)
            .filter(|&j| allowed[j] && !passive[j] && w[j] > tol)
            .max_by(|&i, &j| w[i].total_cmp(&w[j]));
        let Some(j) = candidate else {
            return Ok(x);
        };
        passive[j] = true;
        let mut inner = 0;
        loop {
            inner += 1;
            if inner > 3 * TERMS + 10 {
                return Err(CoreError::Numerical(
                    "noise-model NNLS did not converge (inner loop)".into(),
                ));
            }
            let Some(z) = solve_passive(a, b, &passive) else {
                // The new column is (numerically) dependent on the others: drop it.
                passive[j] = false;
                if passive.iter().all(|p| !p) {
                    return Ok(x);
                }
                break;
            };
            if (0..TERMS).all(|k| !passive[k] || z[k] > 0.0) {
                x = z;
                break;
            }
            // Step from x towards z as far as feasibility allows.
            let mut alpha = f64::INFINITY;
            for k in 0..TERMS {
                if passive[k] && z[k] <= 0.0 {
                    let denom = x[k] - z[k];
                    let step = if denom > 0.0 { x[k] / denom } else { 0.0 };
                    alpha = alpha.min(step);
                }
            }
            if !alpha.is_finite() {
                alpha = 0.0;
            }
            for k in 0..TERMS {
                x[k] += alpha * (z[k] - x[k]);
                if passive[k] && x[k] <= 1e-15 * (x[k].abs() + z[k].abs()).max(f64::MIN_POSITIVE) {
                    x[k] = 0.0;
                    passive[k] = false;
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

/// Invert an upper-triangular k × k matrix given as rows; `None` if singular.
#[allow(clippy::needless_range_loop)] // triangular index arithmetic reads best as loops
fn invert_upper(r: &[Vec<f64>]) -> Option<Vec<Vec<f64>>> {
    let k = r.len();
    let mut inv = vec![vec![0.0; k]; k];
    for col in 0..k {
        for row in (0..=col).rev() {
            let mut s = if row == col { 1.0 } else { 0.0 };
            for m in (row + 1)..=col {
                s -= r[row][m] * inv[m][col];
            }
            let d = r[row][row];
            if d == 0.0 || !d.is_finite() {
                return None;
            }
            inv[row][col] = s / d;
        }
    }
    Some(inv)
}

/// Weighted design, data and per-row weights for the current weights.
struct System {
    a: Mat<f64>,
    b: Vec<f64>,
    scale: [f64; TERMS],
}

fn build_system(taus: &[f64], var: &[f64], weight: &[f64]) -> System {
    let n = taus.len();
    let sw: Vec<f64> = weight.iter().map(|w| w.sqrt()).collect();
    // Column norms of the weighted design, for scaling.
    let mut scale = [0.0; TERMS];
    for i in 0..n {
        let f = basis(taus[i]);
        for j in 0..TERMS {
            let v = f[j] * sw[i];
            scale[j] += v * v;
        }
    }
    for s in scale.iter_mut() {
        *s = if *s > 0.0 && s.is_finite() {
            1.0 / s.sqrt()
        } else {
            1.0
        };
    }
    let a = Mat::from_fn(n, TERMS, |i, j| basis(taus[i])[j] * sw[i] * scale[j]);
    let b = (0..n).map(|i| var[i] * sw[i]).collect();
    System { a, b, scale }
}

/// Fit the five-term noise model to one channel's Allan variance.
///
/// `taus` (s, strictly increasing), `var` (σ̂², > 0) and `edf` (> 0) have one
/// entry per averaging time. Returns the squared coefficients, their covariance
/// and which terms the data support.
pub fn fit_wls(taus: &[f64], var: &[f64], edf: &[f64], opts: &FitOptions) -> CoreResult<WlsFit> {
    validate(taus, var, edf)?;
    if !(opts.min_share.is_finite() && (0.0..1.0).contains(&opts.min_share)) {
        return Err(invalid(format!(
            "min_share must be in [0, 1); got {}",
            opts.min_share
        )));
    }
    if !(opts.min_z.is_finite() && opts.min_z >= 0.0) {
        return Err(invalid(format!(
            "min_z must be finite and >= 0; got {}",
            opts.min_z
        )));
    }
    let mut allowed = opts.terms;
    loop {
        let Solved {
            mut coef,
            weight,
            system,
        } = solve(taus, var, edf, &allowed, opts.reweight)?;
        // Drop the least supported term if any falls below the share threshold.
        let mut share = [0.0f64; TERMS];
        for &t in taus {
            let total = model(&coef, t);
            if total > 0.0 {
                let f = basis(t);
                for j in 0..TERMS {
                    share[j] = share[j].max(f[j] * coef[j] / total);
                }
            }
        }
        let weakest = (0..TERMS)
            .filter(|&j| allowed[j] && coef[j] > 0.0 && share[j] < opts.min_share)
            .min_by(|&i, &j| share[i].total_cmp(&share[j]));
        if let Some(j) = weakest {
            allowed[j] = false;
            continue;
        }
        let supported: [bool; TERMS] = std::array::from_fn(|j| allowed[j] && coef[j] > 0.0);
        for j in 0..TERMS {
            if !supported[j] {
                coef[j] = 0.0;
            }
        }
        let (cov, chi2, dof) = covariance(taus, var, &weight, &system, &coef, &supported);
        // Terms not distinguishable from 0. Two nearly collinear terms (K and R
        // at long tau) can each look insignificant while one of them is needed:
        // remove the one whose absence the data mind least (lowest χ² refit).
        let insignificant: Vec<usize> = (0..TERMS)
            .filter(|&j| supported[j])
            .filter(|&j| {
                let z = coef[j] / cov[j][j].sqrt();
                z.is_finite() && z < opts.min_z
            })
            .collect();
        if !insignificant.is_empty() {
            let mut best: Option<(usize, f64)> = None;
            for &j in &insignificant {
                let mut trial = allowed;
                trial[j] = false;
                let s = solve(taus, var, edf, &trial, opts.reweight)?;
                let c2 = residual_chi2(taus, var, &s.weight, &s.coef);
                if best.is_none_or(|(_, b)| c2 < b) {
                    best = Some((j, c2));
                }
            }
            if let Some((j, _)) = best {
                allowed[j] = false;
                continue;
            }
        }
        return Ok(WlsFit {
            coef,
            cov,
            supported,
            chi2,
            dof,
        });
    }
}

/// One NNLS fit with reweighting: coefficients, final weights and system.
struct Solved {
    coef: [f64; TERMS],
    weight: Vec<f64>,
    system: System,
}

fn solve(
    taus: &[f64],
    var: &[f64],
    edf: &[f64],
    allowed: &[bool; TERMS],
    reweight: usize,
) -> CoreResult<Solved> {
    let n = taus.len();
    // First pass: weights from the measured variance; then from the model.
    let mut weight: Vec<f64> = (0..n).map(|i| edf[i] / (2.0 * var[i] * var[i])).collect();
    let mut coef = [0.0; TERMS];
    let mut system = build_system(taus, var, &weight);
    for pass in 0..=reweight {
        let x = nnls(&system.a, &system.b, allowed)?;
        for j in 0..TERMS {
            coef[j] = x[j] * system.scale[j];
        }
        if pass == reweight {
            break;
        }
        let next: Vec<f64> = (0..n)
            .map(|i| {
                let m = model(&coef, taus[i]);
                edf[i] / (2.0 * m * m)
            })
            .collect();
        if !next.iter().all(|w| w.is_finite() && *w > 0.0) {
            break;
        }
        weight = next;
        system = build_system(taus, var, &weight);
    }
    Ok(Solved {
        coef,
        weight,
        system,
    })
}

fn residual_chi2(taus: &[f64], var: &[f64], weight: &[f64], coef: &[f64; TERMS]) -> f64 {
    (0..taus.len())
        .map(|i| {
            let r = var[i] - model(coef, taus[i]);
            r * r * weight[i]
        })
        .sum()
}

/// Covariance of the squared coefficients from the final passive set, the
/// weighted residual sum of squares and the degrees of freedom.
fn covariance(
    taus: &[f64],
    var: &[f64],
    weight: &[f64],
    system: &System,
    coef: &[f64; TERMS],
    supported: &[bool; TERMS],
) -> ([[f64; TERMS]; TERMS], f64, usize) {
    let n = taus.len();
    let cols: Vec<usize> = (0..TERMS).filter(|&j| supported[j]).collect();
    let mut cov = [[0.0; TERMS]; TERMS];
    let chi2 = residual_chi2(taus, var, weight, coef);
    let dof = n.saturating_sub(cols.len());
    if cols.is_empty() {
        return (cov, chi2, dof);
    }
    let sub = Mat::from_fn(n, cols.len(), |i, k| system.a[(i, cols[k])]);
    let qr = sub.qr();
    let rf = qr.thin_R();
    let rows: Vec<Vec<f64>> = (0..cols.len())
        .map(|r| {
            (0..cols.len())
                .map(|c| if c >= r { rf[(r, c)] } else { 0.0 })
                .collect()
        })
        .collect();
    let birge = if dof > 0 {
        (chi2 / dof as f64).max(1.0)
    } else {
        1.0
    };
    match invert_upper(&rows) {
        Some(rinv) => {
            let k = cols.len();
            for (a, &ja) in cols.iter().enumerate() {
                for (b, &jb) in cols.iter().enumerate() {
                    // (RᵀR)⁻¹ = R⁻¹ R⁻ᵀ
                    let s: f64 = (0..k).map(|m| rinv[a][m] * rinv[b][m]).sum();
                    cov[ja][jb] = s * birge * system.scale[ja] * system.scale[jb];
                }
            }
        }
        None => {
            for &j in &cols {
                cov[j][j] = f64::NAN;
            }
        }
    }
    (cov, chi2, dof)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn octave_taus(t0: f64, count: usize) -> Vec<f64> {
        (0..count).map(|k| t0 * 2f64.powi(k as i32)).collect()
    }

    #[test]
    fn recovers_exact_model() {
        let truth = [1e-8, 4e-6, 1e-6, 1e-10, 0.0];
        let taus = octave_taus(1e-3, 27);
        let var: Vec<f64> = taus.iter().map(|&t| model(&truth, t)).collect();
        let edf = vec![100.0; taus.len()];
        let fit = fit_wls(&taus, &var, &edf, &FitOptions::default()).unwrap();
        for (j, &t) in truth.iter().enumerate().take(4) {
            assert!(
                (fit.coef[j] - t).abs() <= 1e-6 * t,
                "term {j}: {} vs {t}",
                fit.coef[j]
            );
            assert!(fit.supported[j]);
        }
        assert_eq!(fit.coef[4], 0.0);
        assert!(!fit.supported[4]);
    }

    #[test]
    fn negative_direction_is_clamped_to_zero() {
        // White noise only, plus a downward wiggle at long tau that an
        // unconstrained fit would explain with a negative K².
        let taus = octave_taus(0.01, 15);
        let var: Vec<f64> = taus
            .iter()
            .map(|&t| 1e-4 / t * (1.0 - 0.02 * (t / 164.0)))
            .collect();
        let edf = vec![50.0; taus.len()];
        let fit = fit_wls(&taus, &var, &edf, &FitOptions::default()).unwrap();
        assert!(fit.coef.iter().all(|&c| c >= 0.0));
        assert!(fit.supported[1]);
        assert!((fit.coef[1] - 1e-4).abs() < 0.01e-4);
    }

    #[test]
    fn unsupported_term_is_removed() {
        // Pure white noise: a tiny B² that never reaches 25 % must be dropped.
        let taus = octave_taus(0.025, 16);
        let truth = [0.0, 1e-6, 1e-14, 0.0, 0.0];
        let var: Vec<f64> = taus.iter().map(|&t| model(&truth, t)).collect();
        let edf = vec![30.0; taus.len()];
        let fit = fit_wls(&taus, &var, &edf, &FitOptions::default()).unwrap();
        assert!(!fit.supported[2]);
        assert_eq!(fit.coef[2], 0.0);
        assert!(fit.supported[1]);
    }

    #[test]
    fn uncertainty_shrinks_with_edf() {
        let taus = octave_taus(0.025, 16);
        let truth = [0.0, 1e-6, 1e-7, 1e-10, 0.0];
        let var: Vec<f64> = taus.iter().map(|&t| model(&truth, t)).collect();
        let lo = fit_wls(&taus, &var, &[100.0; 16], &FitOptions::default()).unwrap();
        let hi = fit_wls(&taus, &var, &[10000.0; 16], &FitOptions::default()).unwrap();
        assert_eq!(lo.supported, [false, true, true, true, false]);
        assert_eq!(hi.supported, lo.supported);
        for j in 1..4 {
            assert!(lo.cov[j][j] > 0.0);
            let ratio = lo.cov[j][j] / hi.cov[j][j];
            assert!((ratio - 100.0).abs() < 1.0, "term {j}: ratio {ratio}");
        }
    }

    #[test]
    fn bad_inputs_are_errors_not_panics() {
        let o = FitOptions::default();
        assert!(fit_wls(&[], &[], &[], &o).is_err());
        assert!(fit_wls(&[1.0], &[1.0, 2.0], &[1.0], &o).is_err());
        assert!(fit_wls(&[1.0, f64::NAN], &[1.0, 2.0], &[1.0, 1.0], &o).is_err());
        assert!(fit_wls(&[1.0, 2.0], &[1.0, -2.0], &[1.0, 1.0], &o).is_err());
        assert!(fit_wls(&[2.0, 1.0], &[1.0, 2.0], &[1.0, 1.0], &o).is_err());
        assert!(fit_wls(&[1.0, 2.0], &[1.0, 2.0], &[0.0, 1.0], &o).is_err());
        // A single tau is a valid (if weak) problem: one term at most.
        let one = fit_wls(&[1.0], &[1.0], &[5.0], &o).unwrap();
        assert!(one.coef.iter().all(|c| c.is_finite() && *c >= 0.0));
    }

    #[test]
    fn no_terms_allowed_gives_zero_model() {
        let o = FitOptions {
            terms: [false; TERMS],
            ..FitOptions::default()
        };
        let fit = fit_wls(&[1.0, 2.0], &[1.0, 0.5], &[5.0, 5.0], &o).unwrap();
        assert_eq!(fit.coef, [0.0; TERMS]);
        assert_eq!(fit.supported, [false; TERMS]);
    }
}
