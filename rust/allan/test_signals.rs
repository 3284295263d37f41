//! Deterministic test signals and reference transcriptions for the Allan kernels'
//! unit tests.

/// Uniform noise in [−0.5, 0.5) from a 64-bit LCG (reproducible, no dependency).
pub fn noise(n: usize, seed: u64) -> Vec<f64> {
    let mut state = seed;
    (0..n)
        .map(|_| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        })
        .collect()
}

/// Running sum (white → random walk → random-walk FM).
pub fn integrate(v: &[f64]) -> Vec<f64> {
    let mut run = 0.0;
    v.iter()
        .map(|x| {
            run += x;
            run
        })
        .collect()
}

/// Theo1 variance by its definition (SP 1065 eq. 30) on phase values x, as
/// allantools computes it: the reference the kernels are checked against.
pub fn naive_theo1(x: &[f64], m: usize) -> f64 {
    let n = x.len();
    let h = m / 2;
    let mut s = 0.0;
    for i in 0..n - m {
        for d in 0..h {
            let a = x[i] - x[i + h - d] + x[i + m] - x[i + d + h];
            s += a * a / (h - d) as f64;
        }
    }
    s / (0.75 * (n - m) as f64 * (m * m) as f64)
}
