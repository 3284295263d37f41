//! From rate samples to the cumulative sum every statistic works on.
//!
//! c_0 = 0, c_k = Σ_{i<k} (y_i − ȳ): n + 1 points, the phase in units of one
//! sample period (phase x = τ0·c). The mean is removed first so that a large
//! offset (9.81 m/s² on an accelerometer z axis) costs no digits, and both the
//! mean and the running sum use compensated summation.

use rayon::prelude::*;

use super::sum::Neumaier;
use crate::error::{CoreError, CoreResult};

/// Cumulative sum of mean-removed samples. `samples` may be strided (a column of
/// a C-ordered 2-D array); it is gathered once into the output vector, which is
/// then transformed in place (one allocation, three sequential passes).
pub fn cumulative_phase<I>(samples: I) -> CoreResult<Vec<f64>>
where
    I: Iterator<Item = f64>,
{
    into_cumulative_phase(gather(samples))
}

/// The samples behind one leading slot, the layout [`into_cumulative_phase`] takes.
pub fn gather<I>(samples: I) -> Vec<f64>
where
    I: Iterator<Item = f64>,
{
    let mut phase = Vec::with_capacity(samples.size_hint().0 + 1);
    crate::memory::advise_huge_pages(&phase);
    phase.push(0.0);
    phase.extend(samples);
    phase
}

/// Samples per chunk of the parallel passes. Fixed (not derived from the thread
/// count), so the result is the same on any machine; a record of one chunk is
/// transformed exactly as by a single sequential pass.
const CHUNK: usize = 1 << 16;

/// The same transformation for samples already gathered behind a leading slot:
/// `phase[0]` is overwritten with 0 and `phase[1..]` holds y_0 … y_{n−1}.
///
/// Long records use all cores: chunk totals of the mean-removed samples are
/// accumulated with two-sum in parallel, their prefix gives each chunk its
/// starting (sum, error) pair, and the chunks then run the same compensated
/// running sum in parallel.
pub fn into_cumulative_phase(mut phase: Vec<f64>) -> CoreResult<Vec<f64>> {
    let n = phase.len().saturating_sub(1);
    if n == 0 {
        return Err(CoreError::InvalidArgument("x must not be empty".into()));
    }
    if let Some(k) = phase[1..].iter().position(|v| !v.is_finite()) {
        return Err(CoreError::InvalidArgument(format!(
            "x must be finite; sample {k} is {}",
            phase[k + 1]
        )));
    }
    phase[0] = 0.0;
    let chunk_sums: Vec<f64> = phase[1..].par_chunks(CHUNK).map(compensated_sum).collect();
    let mut total = Neumaier::new();
    for s in chunk_sums {
        total.add(s);
    }
    let mean = total.value() / n as f64;
    // Each chunk's total as (sum, error), then the running pair at each chunk start.
    let totals: Vec<(f64, f64)> = phase[1..]
        .par_chunks(CHUNK)
        .map(|chunk| {
            chunk
                .iter()
                .fold((0.0, 0.0), |acc, &v| compensated_step(acc, v - mean))
        })
        .collect();
    let mut starts = Vec::with_capacity(totals.len());
    let mut at = (0.0f64, 0.0f64);
    for (sum, comp) in totals {
        starts.push(at);
        let (t, err) = two_sum(at.0, sum);
        at = (t, at.1 + err + comp);
    }
    phase[1..]
        .par_chunks_mut(CHUNK)
        .zip(starts)
        .for_each(|(chunk, start)| {
            let mut acc = start;
            for value in chunk.iter_mut() {
                acc = compensated_step(acc, *value - mean);
                *value = acc.0 + acc.1;
            }
        });
    Ok(phase)
}

/// Knuth's branch-free two-sum: a + b = t + err exactly.
#[inline(always)]
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let t = a + b;
    let bp = t - a;
    (t, (a - (t - bp)) + (b - bp))
}

/// One step of the compensated running sum: the sum and the accumulated rounding
/// errors form two independent dependency chains.
#[inline(always)]
fn compensated_step((sum, comp): (f64, f64), v: f64) -> (f64, f64) {
    let (t, err) = two_sum(sum, v);
    (t, comp + err)
}

/// Mean and least-squares slope of f(t), t < count (slope about t = (count − 1)/2).
/// The block expansions of the total family re-centre their data on this line.
pub fn least_squares_line(f: impl Fn(usize) -> f64, count: usize) -> (f64, f64) {
    let mut sum = Neumaier::new();
    for t in 0..count {
        sum.add(f(t));
    }
    let mean = sum.value() / count as f64;
    let centre = (count as f64 - 1.0) / 2.0;
    let (mut cov, mut var) = (Neumaier::new(), Neumaier::new());
    for t in 0..count {
        let dt = t as f64 - centre;
        cov.add(dt * (f(t) - mean));
        var.add(dt * dt);
    }
    let slope = if var.value() > 0.0 {
        cov.value() / var.value()
    } else {
        0.0
    };
    (mean, slope)
}

/// Sum of a slice: blocks of 256 in eight plain lanes, blocks added with compensation.
fn compensated_sum(values: &[f64]) -> f64 {
    let mut total = Neumaier::new();
    for block in values.chunks(256) {
        let (chunks, rest) = block.as_chunks::<8>();
        let mut lanes = [0.0f64; 8];
        for chunk in chunks {
            for (lane, v) in lanes.iter_mut().zip(chunk) {
                *lane += v;
            }
        }
        let block_sum: f64 = lanes.iter().sum::<f64>() + rest.iter().sum::<f64>();
        total.add(block_sum);
    }
    total.value()
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
