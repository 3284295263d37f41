//! From rate samples to the cumulative sum every statistic works on.
//!
//! c_0 = 0, c_k = Σ_{i<k} (y_i − ȳ): n + 1 points, the phase in units of one
//! sample period (phase x = τ0·c). The mean is removed first so that a large
//! offset (9.81 m/s² on an accelerometer z axis) costs no digits, and both the
//! mean and the running sum use compensated summation.
//!
//! Missing samples (NaN) contribute nothing: ȳ is the mean of the valid samples
//! and the running sum holds still across a gap, so a difference of c over a
//! stretch without gaps is exactly the sum of its mean-removed samples. The
//! gap-free runs are kept as [`Gaps::segments`]; the statistics use only terms
//! that lie inside one of them.

use std::ops::Range;

use rayon::prelude::*;

use super::running_sum::{self, two_sum, CHUNK};
use super::sum::Neumaier;
use crate::error::{CoreError, CoreResult};

/// The cumulative phase of one channel and where its samples are missing.
#[derive(Clone, Debug, PartialEq)]
pub struct Phase {
    /// c_0 … c_n.
    pub c: Vec<f64>,
    /// `None` when no sample is missing.
    pub gaps: Option<Gaps>,
}

/// The missing samples of a channel.
#[derive(Clone, Debug, PartialEq)]
pub struct Gaps {
    /// Number of missing samples.
    pub missing: usize,
    /// Maximal runs of valid samples, as sample index ranges [a, b), in order.
    /// The phase points of a run are c[a..=b].
    pub segments: Vec<Range<usize>>,
}

impl Gaps {
    /// The longest run of valid samples (the first of equally long ones).
    pub fn longest(&self) -> Option<&Range<usize>> {
        self.segments.iter().rev().max_by_key(|s| s.len())
    }
}

/// Cumulative phases of several channels, computed in parallel. Each item yields
/// one channel's samples.
pub fn column_phases<I>(columns: Vec<I>) -> CoreResult<Vec<Phase>>
where
    I: Iterator<Item = f64> + Send,
{
    let gathered = columns.into_par_iter().map(gather).collect();
    transform_in_parallel(gathered)
}

/// Cumulative phases of the columns of a C-ordered `(n, channels)` array given as
/// its row-major data: one pass over the rows scatters the samples into the
/// channels' phase vectors (each column gathered separately would stream the whole
/// array once per channel), then the channels are transformed in parallel.
pub fn row_major_phases(data: &[f64], channels: usize) -> CoreResult<Vec<Phase>> {
    if channels == 0 || !data.len().is_multiple_of(channels) {
        return Err(CoreError::InvalidArgument(format!(
            "x has {} values, not a whole number of rows of {channels} channels",
            data.len()
        )));
    }
    let n = data.len() / channels;
    let mut phases: Vec<Vec<f64>> = (0..channels)
        .map(|_| {
            let mut phase = Vec::with_capacity(n + 1);
            crate::memory::advise_huge_pages(&phase);
            phase.resize(n + 1, 0.0);
            phase
        })
        .collect();
    for (i, row) in data.chunks_exact(channels).enumerate() {
        for (phase, &value) in phases.iter_mut().zip(row) {
            phase[i + 1] = value;
        }
    }
    transform_in_parallel(phases)
}

/// Turns gathered samples (behind a leading slot) into cumulative phases, one
/// channel per task; errors name the channel when there are several.
fn transform_in_parallel(gathered: Vec<Vec<f64>>) -> CoreResult<Vec<Phase>> {
    let several = gathered.len() > 1;
    gathered
        .into_par_iter()
        .enumerate()
        .map(|(channel, phase)| {
            into_cumulative_phase(phase).map_err(|e| match e {
                CoreError::InvalidArgument(msg) if several => {
                    CoreError::InvalidArgument(format!("{msg} (channel {channel})"))
                }
                other => other,
            })
        })
        .collect()
}

/// Cumulative sum of mean-removed samples of a record without missing samples
/// (NaN is an error here). `samples` may be strided (a column of a C-ordered 2-D
/// array); it is gathered once into the output vector, which is then transformed
/// in place (one allocation, three sequential passes).
pub fn cumulative_phase<I>(samples: I) -> CoreResult<Vec<f64>>
where
    I: Iterator<Item = f64>,
{
    let phase = into_cumulative_phase(gather(samples))?;
    match phase.gaps {
        None => Ok(phase.c),
        Some(gaps) => Err(CoreError::InvalidArgument(format!(
            "x must be finite; sample {} is NaN",
            gaps.segments.first().map_or(0, |s| s.end)
        ))),
    }
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

/// The same transformation for samples already gathered behind a leading slot:
/// `phase[0]` is overwritten with 0 and `phase[1..]` holds y_0 … y_{n−1}, NaN
/// where a sample is missing (±∞ is an error).
///
/// Long records use all cores (see [`running_phase`]).
pub fn into_cumulative_phase(mut phase: Vec<f64>) -> CoreResult<Phase> {
    if phase.len() < 2 {
        return Err(CoreError::InvalidArgument("x must not be empty".into()));
    }
    phase[0] = 0.0;
    let chunk_sums: Vec<f64> = phase[1..].par_chunks(CHUNK).map(compensated_sum).collect();
    with_gaps_located(phase, chunk_sums)
}

/// [`into_cumulative_phase`] of one contiguous channel, with the same result.
/// The samples are summed (for the mean) and their chunks totalled where they
/// are; the phase is written once, by the running sum itself. A record whose sum
/// is not finite (missing samples, ±∞, overflow) is copied and goes the general
/// way.
pub fn contiguous_phase(samples: &[f64]) -> CoreResult<Phase> {
    let n = samples.len();
    if n == 0 {
        return Err(CoreError::InvalidArgument("x must not be empty".into()));
    }
    let chunk_sums: Vec<f64> = samples.par_chunks(CHUNK).map(compensated_sum).collect();
    let total = chunk_sums.iter().sum::<Neumaier>().value();
    if !total.is_finite() {
        return with_gaps_located(gather(samples.iter().copied()), chunk_sums);
    }
    // running_phase without gaps, from the samples into a fresh phase vector.
    let mean = total / n as f64;
    let starts = chunk_starts(samples, mean);
    let mut phase = Vec::with_capacity(n + 1);
    crate::memory::advise_huge_pages(&phase);
    phase.push(0.0);
    running_sum::run_chunks_into(samples, &mut phase.spare_capacity_mut()[..n], &starts, mean);
    // SAFETY: run_chunks_into wrote all n slots after the leading 0.
    unsafe { phase.set_len(n + 1) };
    Ok(Phase {
        c: phase,
        gaps: None,
    })
}

/// The cumulative phase of `phase[1..]` given the sums of its chunks. A finite
/// total stands for the scan for missing samples (a NaN or ±∞ anywhere makes
/// every sum that takes it non-finite); only a non-finite one (gaps, or a sum
/// that overflows) is followed by the scan, and with gaps the chunks are summed
/// again with the missing samples set to 0.
fn with_gaps_located(mut phase: Vec<f64>, mut chunk_sums: Vec<f64>) -> CoreResult<Phase> {
    let mut gaps = None;
    if !chunk_sums.iter().sum::<Neumaier>().value().is_finite() {
        if let Some(first) = phase[1..].iter().position(|v| !v.is_finite()) {
            gaps = Some(find_gaps(&mut phase[1..], first)?);
            chunk_sums = phase[1..].par_chunks(CHUNK).map(compensated_sum).collect();
        }
    }
    Ok(running_phase(phase, &chunk_sums, gaps))
}

/// The running compensated sum of the mean-removed samples in `phase[1..]`,
/// given the plain sums of its chunks of [`CHUNK`] samples (missing samples
/// set to 0 and located by `gaps`).
///
/// Each chunk's total as (sum, error) is accumulated in parallel, their prefix
/// gives each chunk its starting pair, and the chunks then run the same
/// compensated running sum in parallel (`running_sum.rs`).
fn running_phase(mut phase: Vec<f64>, chunk_sums: &[f64], gaps: Option<Gaps>) -> Phase {
    let n = phase.len() - 1;
    let total = chunk_sums.iter().sum::<Neumaier>().value();
    let valid = n - gaps.as_ref().map_or(0, |g| g.missing);
    let mean = total / valid as f64;
    if let Some(g) = &gaps {
        // A missing sample becomes the mean: it then adds exactly 0 below.
        let mut at = 0;
        for s in g.segments.iter().chain(std::iter::once(&(n..n))) {
            phase[1 + at..1 + s.start].fill(mean);
            at = s.end;
        }
    }
    let starts = chunk_starts(&phase[1..], mean);
    running_sum::run_chunks(&mut phase[1..], &starts, mean);
    Phase { c: phase, gaps }
}

/// The running pair (sum, error) at the start of each chunk of `values`: each
/// chunk's total of `v − mean` as (sum, error), then their prefix.
fn chunk_starts(values: &[f64], mean: f64) -> Vec<(f64, f64)> {
    let totals = running_sum::chunk_totals(values, mean);
    let mut starts = Vec::with_capacity(totals.len());
    let mut at = (0.0f64, 0.0f64);
    for (sum, comp) in totals {
        starts.push(at);
        let (t, err) = two_sum(at.0, sum);
        at = (t, at.1 + err + comp);
    }
    starts
}

/// The runs of valid samples of `y`, whose first non-finite value is at `first`;
/// missing samples are set to 0 (for the sum of the valid ones). ±∞ is an error,
/// and so is a record with no valid sample.
fn find_gaps(y: &mut [f64], first: usize) -> CoreResult<Gaps> {
    let mut segments = Vec::new();
    let mut missing = 0;
    let mut start = 0;
    for (k, v) in y.iter_mut().enumerate().skip(first) {
        if v.is_nan() {
            if start < k {
                segments.push(start..k);
            }
            start = k + 1;
            missing += 1;
            *v = 0.0;
        } else if v.is_infinite() {
            return Err(CoreError::InvalidArgument(format!(
                "x must be finite or NaN (a missing sample); sample {k} is {v}"
            )));
        }
    }
    if start < y.len() {
        segments.push(start..y.len());
    }
    if segments.is_empty() {
        return Err(CoreError::InvalidArgument(format!(
            "x has no valid samples: all {} are NaN",
            y.len()
        )));
    }
    Ok(Gaps { missing, segments })
}

/// Mean and least-squares slope of f(t), t < count (slope about t = (count − 1)/2).
/// The block expansions of the total family re-centre their data on this line.
pub fn least_squares_line(f: impl Fn(usize) -> f64, count: usize) -> (f64, f64) {
    let mean = (0..count).map(&f).sum::<Neumaier>().value() / count as f64;
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
    fn row_major_phases_equal_column_phases() {
        let data: Vec<f64> = (0..300).map(|k| ((k * 7919) % 101) as f64 - 50.0).collect();
        let rows = row_major_phases(&data, 3).unwrap();
        let columns = column_phases(
            (0..3)
                .map(|c| data.iter().skip(c).step_by(3).copied())
                .collect(),
        )
        .unwrap();
        assert_eq!(rows, columns);
        assert!(row_major_phases(&data, 7).is_err());
        let mut bad = data.clone();
        bad[4] = f64::INFINITY; // row 1, channel 1
        let err = row_major_phases(&bad, 3).unwrap_err().to_string();
        assert!(
            err.contains("sample 1") && err.contains("channel 1"),
            "{err}"
        );
    }

    #[test]
    fn contiguous_phase_equals_the_gathered_one() {
        // Several chunks (the parallel and vector paths), an offset, and records
        // that take the general way: gaps, ±∞, a sum that overflows.
        let n = 9 * CHUNK + 77;
        let y: Vec<f64> = (0..n)
            .map(|k| ((k * 7919) % 1009) as f64 * 1e-3 + 9.81)
            .collect();
        let mut gapped = y.clone();
        gapped[3] = f64::NAN;
        gapped[2 * CHUNK..2 * CHUNK + 500].fill(f64::NAN);
        let mut infinite = y.clone();
        infinite[CHUNK + 1] = f64::NEG_INFINITY;
        let overflowing = vec![1.5e308; 4];
        for samples in [&y[..], &y[..1], &gapped, &infinite, &overflowing] {
            let fast = contiguous_phase(samples);
            let gathered = into_cumulative_phase(gather(samples.iter().copied()));
            match (fast, gathered) {
                (Ok(a), Ok(b)) => {
                    assert_eq!(a.gaps, b.gaps);
                    assert!(a
                        .c
                        .iter()
                        .zip(&b.c)
                        .all(|(x, y)| x.to_bits() == y.to_bits()));
                    assert_eq!(a.c.len(), samples.len() + 1);
                }
                (Err(a), Err(b)) => assert_eq!(a.to_string(), b.to_string()),
                (a, b) => panic!("{a:?} vs {b:?}"),
            }
        }
        assert!(contiguous_phase(&[]).is_err());
    }

    #[test]
    fn non_finite_values_name_the_channel() {
        let a = [1.0, 2.0];
        let b = [1.0, f64::INFINITY];
        let err = column_phases(vec![a.iter().copied(), b.iter().copied()]).unwrap_err();
        assert!(err.to_string().contains("channel 1"), "{err}");
    }

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
        let err = into_cumulative_phase(gather([f64::NAN, f64::INFINITY].into_iter()));
        assert!(err.unwrap_err().to_string().contains("sample 1 is inf"));
        let err = into_cumulative_phase(gather([f64::NAN; 3].into_iter()));
        assert!(err.unwrap_err().to_string().contains("all 3 are NaN"));
    }

    #[test]
    fn missing_samples_add_nothing_and_are_located() {
        let nan = f64::NAN;
        let y = [nan, 1.0, 2.0, nan, nan, 3.0, 6.0, nan];
        let p = into_cumulative_phase(gather(y.iter().copied())).unwrap();
        // Mean of the valid samples is 3.
        assert_eq!(p.c, vec![0.0, 0.0, -2.0, -3.0, -3.0, -3.0, -3.0, 0.0, 0.0]);
        let gaps = p.gaps.unwrap();
        assert_eq!(gaps.missing, 4);
        assert_eq!(gaps.segments, vec![1..3, 5..7]);
        assert_eq!(gaps.longest(), Some(&(1..3)));
        let clean = into_cumulative_phase(gather([1.0, 2.0].into_iter())).unwrap();
        assert_eq!(clean.gaps, None);
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
