//! Power-law noise identification by the lag-1 autocorrelation method
//! (Riley & Greenhall, "Power law noise identification using the lag 1
//! autocorrelation", 18th EFTF, 2004), applied to phase data.
//!
//! The phase is decimated by the averaging factor, a quadratic is removed, and
//! the series is differenced until ρ = r1/(1 + r1) falls below 0.25 (or `dmax`
//! differences are done). Then α = 2 − round(2ρ) − 2d, the exponent of the
//! fractional-frequency PSD S_y(f) ∝ f^α.

// Small fixed-size linear algebra below indexes rows and columns as the formulas do.
#![allow(clippy::needless_range_loop)]

/// Fewer decimated points than this and the lag-1 estimate is too noisy to use.
pub const MIN_POINTS: usize = 30;

/// At most this many decimated points are used: the central stretch of the
/// record. The standard error of ρ is then below 0.005, far finer than the
/// rounding of 2ρ needs, and identification at short taus of long records costs
/// microseconds instead of a pass over the whole record per difference order.
pub const MAX_POINTS: usize = 1 << 16;

/// The identified integer α, or `None` when the decimated series is too short.
///
/// Records longer than [`MAX_POINTS`] decimated points are identified on their
/// central [`MAX_POINTS`]. Streams over `c` without copying it: the quadratic is fitted in one pass and
/// the residuals and their differences are evaluated on the fly.
pub fn identify_alpha(c: &[f64], m: usize, dmax: u32) -> Option<i32> {
    identify(c, m, dmax).map(|(alpha, _)| alpha)
}

/// [`identify_alpha`] with the ρ it was decided on.
fn identify(c: &[f64], m: usize, dmax: u32) -> Option<(i32, f64)> {
    let (len, first) = decimation(c.len(), m)?;
    let x = |k: usize| c[(first + k) * m];
    let trend = QuadraticTrend::fit(len, x)?;
    let residual = |k: usize| x(k) - trend.at(k);
    for d in 0..=dmax {
        let count = len - d as usize;
        let value = |k: usize| difference(d, k, residual);
        let r1 = lag1_autocorrelation(count, value)?;
        let rho = r1 / (1.0 + r1);
        if rho < 0.25 || d >= dmax {
            return Some((alpha_of(rho, d), rho));
        }
    }
    None
}

/// The points of the decimated series and the first of them (its central
/// stretch), or `None` when it is too short to identify.
fn decimation(points: usize, m: usize) -> Option<(usize, usize)> {
    if m == 0 {
        return None;
    }
    let available = points.div_ceil(m);
    if available < MIN_POINTS {
        return None;
    }
    let len = available.min(MAX_POINTS);
    Some((len, (available - len) / 2))
}

fn alpha_of(rho: f64, d: u32) -> i32 {
    2 - (2.0 * rho).round_ties_even() as i32 - 2 * d as i32
}

/// [`identify_alpha`] of `c` at every averaging factor of `ms`, with the same
/// bits: the factors whose decimated series are equally long (all those of a
/// long record up to `len(c)/MAX_POINTS`) run [`LANES`] at a time, one in each
/// lane of the same operations in the same order, on a gathered copy of their
/// points, with the quadratic's normal matrix (which depends on the length
/// only) formed once. The identification of a long record's short taus was a
/// few passes of dependent additions over strided points for each tau; here
/// the lanes' chains overlap and the points are read contiguously.
pub fn identify_alphas(c: &[f64], ms: &[usize], dmax: u32) -> Vec<Option<i32>> {
    let mut out = vec![None; ms.len()];
    let mut full: Vec<usize> = Vec::new();
    for (i, &m) in ms.iter().enumerate() {
        match decimation(c.len(), m) {
            Some((len, _)) if len == MAX_POINTS => full.push(i),
            // Its points gathered once: the passes then read them contiguously
            // (the series of factor 1 of the gathered points is the same).
            Some((len, first)) => {
                let points: Vec<f64> = (first..first + len).map(|k| c[k * m]).collect();
                out[i] = identify_alpha(&points, 1, dmax);
            }
            None => {}
        }
    }
    for group in full.chunks(LANES) {
        // A short group is padded with its first factor (its result is dropped).
        let lanes: [usize; LANES] = std::array::from_fn(|l| ms[group[l.min(group.len() - 1)]]);
        let found = identify_lanes(c, lanes, dmax);
        for (l, &i) in group.iter().enumerate() {
            out[i] = found[l].map(|(alpha, _)| alpha);
        }
    }
    out
}

/// Factors identified together by [`identify_alphas`].
const LANES: usize = 8;

/// [`identify`] at `LANES` factors whose decimated series all have
/// [`MAX_POINTS`] points; compiled for AVX2 or AVX-512 where the CPU has them
/// (the operations, and so the bits, are the same on every path).
fn identify_lanes(c: &[f64], ms: [usize; LANES], dmax: u32) -> [Option<(i32, f64)>; LANES] {
    #[cfg(target_arch = "x86_64")]
    {
        use crate::simd::{level, Level};
        if level() >= Level::Avx512 {
            // SAFETY: the CPU has AVX-512F (the level never exceeds the CPU's).
            return unsafe { identify_lanes_avx512(c, ms, dmax) };
        }
        if level() >= Level::Avx2 {
            // SAFETY: the CPU has AVX2.
            return unsafe { identify_lanes_avx2(c, ms, dmax) };
        }
    }
    identify_lanes_portable(c, ms, dmax)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
unsafe fn identify_lanes_avx512(
    c: &[f64],
    ms: [usize; LANES],
    dmax: u32,
) -> [Option<(i32, f64)>; LANES] {
    identify_lanes_portable(c, ms, dmax)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn identify_lanes_avx2(
    c: &[f64],
    ms: [usize; LANES],
    dmax: u32,
) -> [Option<(i32, f64)>; LANES] {
    identify_lanes_portable(c, ms, dmax)
}

type Lanes = [f64; LANES];

#[inline(always)]
fn identify_lanes_portable(
    c: &[f64],
    ms: [usize; LANES],
    dmax: u32,
) -> [Option<(i32, f64)>; LANES] {
    let len = MAX_POINTS;
    let firsts: [usize; LANES] = std::array::from_fn(|l| {
        decimation(c.len(), ms[l])
            .expect("a full decimated series")
            .1
    });
    let mut r: Vec<Lanes> = (0..len)
        .map(|k| std::array::from_fn(|l| c[(firsts[l] + k) * ms[l]]))
        .collect();
    // The quadratic: QuadraticTrend::fit's sums, the normal matrix once.
    let scale = 2.0 / (len - 1) as f64;
    let mut gram = [[0.0f64; 3]; 3];
    let mut rhs = [[0.0f64; LANES]; 3];
    for (k, x) in r.iter().enumerate() {
        let t = k as f64 * scale - 1.0;
        let basis = [1.0, t, t * t];
        for p in 0..3 {
            for l in 0..LANES {
                rhs[p][l] += basis[p] * x[l];
            }
            for q in p..3 {
                gram[p][q] += basis[p] * basis[q];
            }
        }
    }
    for p in 0..3 {
        for q in 0..p {
            gram[p][q] = gram[q][p];
        }
    }
    let mut coef = [[0.0f64; 3]; LANES];
    for l in 0..LANES {
        match solve3(gram, [rhs[0][l], rhs[1][l], rhs[2][l]]) {
            Some(x) => coef[l] = x,
            None => return [None; LANES],
        }
    }
    // The residuals in place (QuadraticTrend::at).
    for (k, x) in r.iter_mut().enumerate() {
        let t = k as f64 * scale - 1.0;
        for l in 0..LANES {
            x[l] -= coef[l][0] + t * (coef[l][1] + t * coef[l][2]);
        }
    }
    let mut found: [Option<Option<(i32, f64)>>; LANES] = [None; LANES];
    for d in 0..=dmax {
        let count = len - d as usize;
        let r1 = match d {
            0 => lag1_lanes(count, |k| r[k]),
            1 => lag1_lanes(count, |k| {
                std::array::from_fn(|l| difference(1, 0, |j| r[k + j][l]))
            }),
            2 => lag1_lanes(count, |k| {
                std::array::from_fn(|l| difference(2, 0, |j| r[k + j][l]))
            }),
            _ => lag1_lanes(count, |k| {
                std::array::from_fn(|l| difference(3, 0, |j| r[k + j][l]))
            }),
        };
        for l in 0..LANES {
            if found[l].is_some() {
                continue;
            }
            match r1[l] {
                None => found[l] = Some(None),
                Some(r1) => {
                    let rho = r1 / (1.0 + r1);
                    if rho < 0.25 || d >= dmax {
                        found[l] = Some(Some((alpha_of(rho, d), rho)));
                    }
                }
            }
        }
        if found.iter().all(Option::is_some) {
            break;
        }
    }
    found.map(Option::flatten)
}

/// [`lag1_autocorrelation`] in every lane.
#[inline(always)]
fn lag1_lanes(count: usize, x: impl Fn(usize) -> Lanes) -> [Option<f64>; LANES] {
    if count < 2 {
        return [None; LANES];
    }
    // The start of `Iterator::sum` of f64 (its sign of zero).
    let zero: f64 = std::iter::empty::<f64>().sum();
    let mut total = [zero; LANES];
    for k in 0..count {
        let v = x(k);
        for l in 0..LANES {
            total[l] += v[l];
        }
    }
    let mean: Lanes = std::array::from_fn(|l| total[l] / count as f64);
    let mut num = [0.0; LANES];
    let mut den = [0.0; LANES];
    let v = x(0);
    let mut previous: Lanes = std::array::from_fn(|l| v[l] - mean[l]);
    for l in 0..LANES {
        den[l] += previous[l] * previous[l];
    }
    for k in 1..count {
        let v = x(k);
        for l in 0..LANES {
            let a = v[l] - mean[l];
            den[l] += a * a;
            num[l] += previous[l] * a;
            previous[l] = a;
        }
    }
    std::array::from_fn(|l| {
        if den[l] > 0.0 && den[l].is_finite() {
            Some(num[l] / den[l])
        } else {
            None
        }
    })
}

/// The d-th forward difference Σ_j (−1)^(d−j) C(d, j) r_{k+j} (d ≤ 3).
#[inline(always)]
fn difference(d: u32, k: usize, r: impl Fn(usize) -> f64) -> f64 {
    match d {
        0 => r(k),
        1 => r(k + 1) - r(k),
        2 => r(k + 2) - 2.0 * r(k + 1) + r(k),
        _ => r(k + 3) - 3.0 * r(k + 2) + 3.0 * r(k + 1) - r(k),
    }
}

/// r1 = Σ (x_k − x̄)(x_{k+1} − x̄) / Σ (x_k − x̄)². `None` for a constant series.
fn lag1_autocorrelation(count: usize, x: impl Fn(usize) -> f64) -> Option<f64> {
    if count < 2 {
        return None;
    }
    let mean = (0..count).map(&x).sum::<f64>() / count as f64;
    let mut num = 0.0;
    let mut den = 0.0;
    let mut previous = x(0) - mean;
    den += previous * previous;
    for k in 1..count {
        let a = x(k) - mean;
        den += a * a;
        num += previous * a;
        previous = a;
    }
    if den > 0.0 && den.is_finite() {
        Some(num / den)
    } else {
        None
    }
}

/// Least-squares quadratic in t scaled to [−1, 1], where the normal equations of
/// 1, t, t² are well conditioned for any length.
struct QuadraticTrend {
    coef: [f64; 3],
    scale: f64,
}

impl QuadraticTrend {
    fn fit(len: usize, x: impl Fn(usize) -> f64) -> Option<Self> {
        let scale = 2.0 / (len - 1) as f64;
        let mut gram = [[0.0f64; 3]; 3];
        let mut rhs = [0.0f64; 3];
        for k in 0..len {
            let t = k as f64 * scale - 1.0;
            let basis = [1.0, t, t * t];
            let v = x(k);
            for p in 0..3 {
                rhs[p] += basis[p] * v;
                for q in p..3 {
                    gram[p][q] += basis[p] * basis[q];
                }
            }
        }
        for p in 0..3 {
            for q in 0..p {
                gram[p][q] = gram[q][p];
            }
        }
        Some(QuadraticTrend {
            coef: solve3(gram, rhs)?,
            scale,
        })
    }

    #[inline(always)]
    fn at(&self, k: usize) -> f64 {
        let t = k as f64 * self.scale - 1.0;
        self.coef[0] + t * (self.coef[1] + t * self.coef[2])
    }
}

/// Gaussian elimination with partial pivoting on a 3×3 system.
fn solve3(mut a: [[f64; 3]; 3], mut b: [f64; 3]) -> Option<[f64; 3]> {
    for col in 0..3 {
        let pivot = (col..3).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[pivot][col].abs() < 1e-300 {
            return None;
        }
        a.swap(col, pivot);
        b.swap(col, pivot);
        for row in col + 1..3 {
            let f = a[row][col] / a[col][col];
            for k in col..3 {
                a[row][k] -= f * a[col][k];
            }
            b[row] -= f * b[col];
        }
    }
    let mut x = [0.0; 3];
    for row in (0..3).rev() {
        let tail: f64 = (row + 1..3).map(|k| a[row][k] * x[k]).sum();
        x[row] = (b[row] - tail) / a[row][row];
    }
    Some(x)
}

/// Where a tau's series was too short to identify, use the median α of the (up
/// to) three nearest identified taus of the same channel; with none at all, white
/// FM (α = 0). The last identifiable taus rest on 30–60 points each, so one of
/// them is misidentified now and then; the median keeps a single outlier from
/// deciding the noise type (and so the EDF) of every longer tau.
pub fn fill_from_nearest(
    alpha: &mut [i32],
    known: &[bool],
    c: usize,
    channels: usize,
    taus: usize,
) {
    let idx = |t: usize| t * channels + c;
    let identified: Vec<usize> = (0..taus).filter(|&t| known[idx(t)]).collect();
    for t in 0..taus {
        if known[idx(t)] {
            continue;
        }
        let mut nearest = identified.clone();
        nearest.sort_by_key(|&k| (k.abs_diff(t), k));
        let mut votes: Vec<i32> = nearest.iter().take(3).map(|&k| alpha[idx(k)]).collect();
        alpha[idx(t)] = match votes.len() {
            0 => 0,
            1 | 2 => votes[0],
            _ => {
                votes.sort_unstable();
                votes[1]
            }
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small deterministic generator so the tests need no crate.
    fn white(n: usize, seed: u64) -> Vec<f64> {
        let mut s = seed;
        let mut uniform = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        (0..n)
            .map(|_| {
                // Box–Muller
                let (u1, u2) = (uniform().max(1e-300), uniform());
                (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
            })
            .collect()
    }

    fn cumsum(y: &[f64]) -> Vec<f64> {
        let mut c = vec![0.0];
        for v in y {
            c.push(c.last().unwrap() + v);
        }
        c
    }

    #[test]
    fn one_misidentified_tau_does_not_decide_the_longer_ones() {
        let mut alpha = vec![0, 0, 0, 1, 0, 0];
        let known = vec![true, true, true, true, false, false];
        fill_from_nearest(&mut alpha, &known, 0, 1, 6);
        assert_eq!(alpha, vec![0, 0, 0, 1, 0, 0]);
        let mut alpha = vec![-2, -2, -2, 0, 0];
        let known = vec![true, true, true, false, false];
        fill_from_nearest(&mut alpha, &known, 0, 1, 5);
        assert_eq!(alpha, vec![-2, -2, -2, -2, -2]);
    }

    #[test]
    fn white_frequency_noise_is_alpha_zero() {
        let c = cumsum(&white(4000, 7));
        assert_eq!(identify_alpha(&c, 1, 2), Some(0));
        assert_eq!(identify_alpha(&c, 10, 2), Some(0));
    }

    #[test]
    fn random_walk_frequency_is_alpha_minus_two() {
        let c = cumsum(&cumsum(&white(4000, 11)));
        assert_eq!(identify_alpha(&c, 1, 2), Some(-2));
    }

    #[test]
    fn white_phase_is_alpha_two() {
        let c = white(4000, 3);
        assert_eq!(identify_alpha(&c, 1, 2), Some(2));
    }

    #[test]
    fn quadratic_trend_is_removed_exactly() {
        let x = |k: usize| 3.0 + 0.5 * k as f64 - 0.01 * (k * k) as f64;
        let trend = QuadraticTrend::fit(100, x).unwrap();
        for k in [0, 17, 99] {
            assert!((trend.at(k) - x(k)).abs() < 1e-9);
        }
    }

    #[test]
    fn lanes_give_the_bits_of_one_factor_at_a_time() {
        // Long enough for factors 1..=12 to have the full MAX_POINTS points;
        // several noise types, so the lanes stop at different differences.
        let n = 12 * MAX_POINTS + 5;
        let w = white(n, 21);
        let walk = cumsum(&w);
        let mix: Vec<f64> = w
            .iter()
            .zip(cumsum(&cumsum(&white(n, 4))))
            .map(|(a, b)| 3e3 * a + 1e-3 * b)
            .collect();
        let ms: Vec<usize> = (1..=12).chain([20, 40, 1000, 9000, 20000]).collect();
        for c in [w, walk.clone(), cumsum(&walk), mix] {
            for dmax in [2, 3] {
                let batch = identify_alphas(&c, &ms, dmax);
                for (i, &m) in ms.iter().enumerate() {
                    assert_eq!(batch[i], identify_alpha(&c, m, dmax), "m {m} dmax {dmax}");
                }
                let lanes: [usize; LANES] = std::array::from_fn(|l| ms[l + 1]);
                for (l, got) in identify_lanes(&c, lanes, dmax).into_iter().enumerate() {
                    let want = identify(&c, lanes[l], dmax);
                    assert_eq!(
                        got.map(|(a, rho)| (a, rho.to_bits())),
                        want.map(|(a, rho)| (a, rho.to_bits())),
                        "m {} dmax {dmax}",
                        lanes[l]
                    );
                }
            }
        }
        assert!(identify_alphas(&[0.0; 50], &[1, 2], 2)
            .iter()
            .all(Option::is_none));
    }

    #[test]
    fn short_series_are_not_identified() {
        let c = cumsum(&white(100, 5));
        assert_eq!(identify_alpha(&c, 10, 2), None);
        assert_eq!(identify_alpha(&[0.0; 50], 1, 2), None);
    }
}
