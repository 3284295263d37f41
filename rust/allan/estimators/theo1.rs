//! Theo1 (SP 1065 eq. 30; Howe & Peppler 2003) over the cumulative phase `c`
//! (N = n + 1 points, in units of one sample period), even m only:
//!
//!   σ² = Σ_i Σ_{δ<m/2} [(x_i − x_{i−δ+m/2}) + (x_{i+m} − x_{i+δ+m/2})]²
//!        / (m/2 − δ) / (0.75 (N − m) m²),
//!
//! as allantools and Stable32 compute it; the estimate belongs to the effective
//! averaging time 0.75·m·τ0.
//!
//! Cost. The direct double sum costs (N − m)·m/2 multiply-adds per tau; from
//! [`FFT_FROM`] on, `fast::theo1_fft` expands it in O(N log² m). [`theo1_work`]
//! counts both, for ThêoBR's cost estimate.

use super::sum_over_subsequences;
use crate::allan::fast::theo1_fft::theo1_sum;
use crate::interrupt::Interrupt;

/// Averaging factors from here on use the O(N log² m) expansion, which is
/// cheaper than the direct sum there.
pub const FFT_FROM: usize = 256;

/// Terms as allantools counts them: (N − m) outer × m/2 inner, for even m < N.
pub fn terms(n_phase: usize, m: usize) -> usize {
    if m >= 1 && m.is_multiple_of(2) && m < n_phase {
        (n_phase - m) * (m / 2)
    } else {
        0
    }
}

/// Theo1 variance at even averaging factor m (needs m < N = c.len());
/// meaningless once `stop` is raised.
pub fn theo1_var(c: &[f64], m: usize, stop: &Interrupt) -> f64 {
    let n = c.len();
    let h = m / 2;
    let outer = n - m;
    let weights: Vec<f64> = (1..=h).map(|k| 1.0 / k as f64).collect();
    // With k = m/2 − δ: term = (c_i + c_{i+m} − c_{i+k} − c_{i+m−k})² / k.
    let inner = |i: usize, _zp: &mut [f64], _p: &mut [f64]| {
        let ends = c[i] + c[i + m];
        let fwd = &c[i + 1..=i + h];
        let mut lanes = [0.0f64; 4];
        let mut k = 0;
        while k + 4 <= h {
            for (lane, acc) in lanes.iter_mut().enumerate() {
                let q = k + lane;
                let a = ends - fwd[q] - c[i + m - 1 - q];
                *acc += weights[q] * a * a;
            }
            k += 4;
        }
        while k < h {
            let a = ends - fwd[k] - c[i + m - 1 - k];
            lanes[0] += weights[k] * a * a;
            k += 1;
        }
        lanes.iter().sum::<f64>()
    };
    let total = if m < FFT_FROM {
        // Scratch buffers are unused here: ask for the smallest.
        sum_over_subsequences(outer, 0, h.max(1), inner, stop)
    } else {
        theo1_sum(c, m, stop)
    };
    let mf = m as f64;
    total / (0.75 * outer as f64 * mf * mf)
}

/// Work of one Theo1 evaluation at (N, m) in the kernel's two regimes:
/// (direct steps, fast units). Below [`FFT_FROM`] the direct sum costs
/// (N − m)·m/2 multiply-adds; above, the expansion costs ∝ N·log²(m) (FFT
/// sliding sums, recursive triangles), counted as N·log₂(m)² units.
pub fn theo1_work(n_phase: usize, m: usize) -> (f64, f64) {
    if m >= n_phase || m < 2 {
        (0.0, 0.0)
    } else if m < FFT_FROM {
        ((n_phase - m) as f64 * (m / 2) as f64, 0.0)
    } else {
        let l = (m as f64).log2();
        (0.0, n_phase as f64 * l * l)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::allan::phase::cumulative_phase;
    use crate::allan::test_signals::naive_theo1;
    use crate::interrupt::NEVER;

    #[test]
    fn theo1_matches_the_definition() {
        let y: Vec<f64> = (0..300)
            .map(|k| ((k * 7919 + 13) % 101) as f64 - 50.0)
            .collect();
        let c = cumulative_phase(y.into_iter()).unwrap();
        for m in [2, 4, 10, 100, 300] {
            let (a, b) = (theo1_var(&c, m, &NEVER), naive_theo1(&c, m));
            assert!((a - b).abs() <= 1e-12 * b, "m {m}: {a} vs {b}");
        }
    }
}
