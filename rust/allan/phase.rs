//! From rate samples to the cumulative sum every statistic works on.
//!
//! c_0 = 0, c_k = Σ_{i<k} (y_i − ȳ): n + 1 points, the phase in units of one
//! sample period (phase x = τ0·c). The mean is removed first so that a large
//! offset (9.81 m/s² on an accelerometer z axis) costs no digits, and both the
//! mean and the running sum use compensated summation.

use super::sum::Neumaier;
use crate::error::{CoreError, CoreResult};

/// Cumulative sum of mean-removed samples. `samples` may be strided (a column of
/// a C-ordered 2-D array); it is read twice and never copied.
pub fn cumulative_phase<I>(samples: I) -> CoreResult<Vec<f64>>
where
    I: Iterator<Item = f64> + Clone,
{
    let mut mean_acc = Neumaier::new();
    let mut n = 0usize;
    for v in samples.clone() {
        if !v.is_finite() {
            return Err(CoreError::InvalidArgument(format!(
                "x must be finite; sample {n} is {v}"
            )));
        }
        mean_acc.add(v);
        n += 1;
    }
    if n == 0 {
        return Err(CoreError::InvalidArgument("x must not be empty".into()));
    }
    let mean = mean_acc.value() / n as f64;
    let mut phase = Vec::with_capacity(n + 1);
    phase.push(0.0);
    let mut running = Neumaier::new();
    for v in samples {
        running.add(v - mean);
        phase.push(running.value());
    }
    Ok(phase)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn phase_starts_at_zero_and_ends_near_zero() {
        let y = [1.0, 2.0, 3.0, 6.0];
        let c = cumulative_phase(y.iter().copied()).unwrap();
        assert_eq!(c, vec![0.0, -2.0, -3.0, -3.0, 0.0]);
    }

    #[test]
    fn rejects_non_finite_and_empty() {
        let err = cumulative_phase([1.0, f64::NAN].iter().copied()).unwrap_err();
        assert!(err.to_string().contains("sample 1"));
        assert!(cumulative_phase(std::iter::empty()).is_err());
    }

    #[test]
    fn large_offset_costs_no_digits() {
        let base: Vec<f64> = (0..1000)
            .map(|k| ((k * 7919) % 101) as f64 * 1e-4)
            .collect();
        let shifted: Vec<f64> = base.iter().map(|v| v + 9.81).collect();
        let a = cumulative_phase(base.iter().copied()).unwrap();
        let b = cumulative_phase(shifted.iter().copied()).unwrap();
        for (x, y) in a.iter().zip(&b) {
            assert!((x - y).abs() < 1e-12, "{x} vs {y}");
        }
    }
}
