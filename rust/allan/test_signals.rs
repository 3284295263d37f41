//! Deterministic test signals for the Allan kernels' unit tests.

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
