//! Sliding weighted sums, out[p] = Σ_k w[k]·x[p + k] for every p where the
//! kernel fits: directly for short kernels, otherwise by FFT convolution
//! (O((n + k) log n) instead of O(n·k)).

use std::cell::RefCell;

use rustfft::num_complex::Complex;

use crate::simd::FftPlans;

/// Below this many multiply-adds the direct loop beats three FFTs.
const DIRECT_WORK: usize = 1 << 14;

thread_local! {
    // Plans are cached per thread: the blocks of one tau reuse a few sizes.
    static PLANS: RefCell<FftPlans> = RefCell::new(FftPlans::new());
}

/// out[p] = Σ_k w[k]·x[p + k], p = 0 … x.len() − w.len() (empty when w is longer).
pub fn sliding_dot(x: &[f64], w: &[f64]) -> Vec<f64> {
    if w.is_empty() || w.len() > x.len() {
        return Vec::new();
    }
    let count = x.len() - w.len() + 1;
    if count * w.len() <= DIRECT_WORK || w.len() <= 8 {
        return (0..count)
            .map(|p| x[p..p + w.len()].iter().zip(w).map(|(a, b)| a * b).sum())
            .collect();
    }
    // Linear convolution of x with reversed w; a cyclic one of any length
    // ≥ x.len() is exact at the indices read (wrapped terms meet w's padding).
    let size = x.len().next_power_of_two();
    let (forward, inverse) = PLANS.with(|plans| {
        let mut plans = plans.borrow_mut();
        // A level forced since the plans were made: plan again at the new one.
        if !plans.is_current() {
            *plans = FftPlans::new();
        }
        (plans.forward(size), plans.inverse(size))
    });
    // Both real inputs go through one complex transform: z = x + i·g·rev(w).
    // Separating the two spectra again costs digits of the smaller one, so w
    // is scaled to x's norm first (g) and the result divided by g.
    let norm = |v: &[f64]| v.iter().map(|a| a * a).sum::<f64>().sqrt();
    let (nx, nw) = (norm(x), norm(w));
    let gain = if nx > 0.0 && nw > 0.0 { nx / nw } else { 1.0 };
    let mut z = vec![Complex::new(0.0, 0.0); size];
    for (zk, &v) in z.iter_mut().zip(x) {
        zk.re = v;
    }
    for (zk, &v) in z.iter_mut().zip(w.iter().rev()) {
        zk.im = v * gain;
    }
    forward.process(&mut z);
    // X_k = (Z_k + conj Z_{−k})/2, W_k = (Z_k − conj Z_{−k})/(2i); the product X·W
    // overwrites Z in place, the pair k, −k at a time.
    let product_at = |a: Complex<f64>, b: Complex<f64>| {
        let b = b.conj();
        ((a + b) * 0.5) * ((a - b) * Complex::new(0.0, -0.5))
    };
    for k in 0..=size / 2 {
        let j = (size - k) % size;
        let (zk, zj) = (z[k], z[j]);
        z[k] = product_at(zk, zj);
        z[j] = product_at(zj, zk);
    }
    let mut product = z;
    inverse.process(&mut product);
    let scale = 1.0 / (size as f64 * gain);
    (0..count)
        .map(|p| product[p + w.len() - 1].re * scale)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fft_path_equals_the_direct_sum() {
        let x: Vec<f64> = (0..5000)
            .map(|k| ((k * 7919 % 1013) as f64 - 506.0) / 100.0)
            .collect();
        let w: Vec<f64> = (1..=700).map(|k| 1.0 / k as f64).collect();
        let fast = sliding_dot(&x, &w);
        assert_eq!(fast.len(), 5000 - 700 + 1);
        // FFT rounding is bounded norm-wise: ε·log₂(size)·‖x‖·‖w‖ (a few times over).
        let norm = |v: &[f64]| v.iter().map(|a| a * a).sum::<f64>().sqrt();
        let bound = 1e-14 * norm(&x) * norm(&w);
        for (p, got) in fast.iter().enumerate() {
            let want: f64 = (0..w.len()).map(|k| w[k] * x[p + k]).sum();
            assert!((got - want).abs() <= bound, "p {p}: {got} vs {want}");
        }
        assert!(sliding_dot(&x[..10], &w).is_empty());
    }
}
