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

/// Noise integrated `order` times: white, random walk, random-walk FM phase, ….
pub fn integrated_noise(n: usize, seed: u64, order: usize) -> Vec<f64> {
    (0..order).fold(noise(n, seed), |v, _| integrate(&v))
}

/// `v + offset`, for a kernel, and the same values with the offset taken off
/// again (exactly, by Sterbenz), for a reference that ignores offsets.
pub fn offset_pair(v: &[f64], offset: f64) -> (Vec<f64>, Vec<f64>) {
    let shifted: Vec<f64> = v.iter().map(|x| x + offset).collect();
    let back = shifted.iter().map(|x| x - offset).collect();
    (shifted, back)
}

/// One MTOT/HTOT subsequence by the definition: the linear trend through the
/// means of its two halves removed, then extended by uninverted even reflection
/// to three times its length, [flip(z), z, flip(z)].
pub fn detrended_reflection(xs: &[f64]) -> Vec<f64> {
    let l = xs.len();
    let half = l / 2;
    let gap = l.div_ceil(2);
    let first: f64 = xs[..half].iter().sum::<f64>() / half as f64;
    let last: f64 = xs[gap..].iter().sum::<f64>() / half as f64;
    let slope = (last - first) / gap as f64;
    let z: Vec<f64> = xs
        .iter()
        .enumerate()
        .map(|(k, v)| v - slope * k as f64)
        .collect();
    let mut star: Vec<f64> = z.iter().rev().copied().collect();
    star.extend(&z);
    star.extend(z.iter().rev());
    star
}

/// Proptest input for the fast kernels: a factor pick in [0, 1) and a white,
/// random-walk or random-walk-FM signal of 3 to `max_len` points on an offset, as
/// (pick, shifted, unshifted) (see [`offset_pair`]).
pub fn kernel_case(
    max_len: usize,
) -> impl proptest::strategy::Strategy<Value = (f64, Vec<f64>, Vec<f64>)> {
    use proptest::strategy::Strategy;
    (
        3usize..max_len,
        0.0f64..1.0,
        0u64..1000,
        0usize..3,
        -1e4f64..1e4,
    )
        .prop_map(|(n, pick, seed, order, offset)| {
            let (shifted, back) = offset_pair(&integrated_noise(n, seed, order), offset);
            (pick, shifted, back)
        })
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
