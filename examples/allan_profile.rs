//! Time the overlapping Allan variance's stages without Python: `cargo run
//! --release --no-default-features --example allan_profile -- [N] [REPEATS]`.
//! White noise of N samples (default 10^7), octave taus. Prints, per stage, the
//! least wall time over the repeats (the least disturbed on a shared machine)
//! and the mean CPU time of all threads, beside the memory-bandwidth yardstick:
//! one plain read of the samples.
use std::time::Instant;

use _core::allan::fast::blocked::{sums_of_squares, Difference};
use _core::allan::{column_phases, contiguous_phase, Statistic};
use rayon::prelude::*;

mod common;
use common::cpu_seconds;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args
        .get(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(10_000_000);
    let reps: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(7);
    // A cheap deterministic noise (xorshift), uniform in [−0.5, 0.5).
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let y: Vec<f64> = (0..n)
        .map(|_| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        })
        .collect();
    let ms: Vec<usize> = (0..)
        .map(|e| 1usize << e)
        .take_while(|&m| 2 * m < n / 2)
        .collect();
    println!("n {n}, {} octave taus; least wall s / mean CPU s", ms.len());
    let mut check = 0.0;
    stage("read (one core)", reps, || {
        check += lanes_sum(std::hint::black_box(&y));
    });
    stage("read (all cores)", reps, || {
        check += std::hint::black_box(&y)
            .par_chunks(1 << 16)
            .map(lanes_sum)
            .sum::<f64>();
    });
    let phases = column_phases(vec![y.iter().copied()]).unwrap();
    stage("phase", reps, || {
        let p = column_phases(vec![std::hint::black_box(&y).iter().copied()]).unwrap();
        check += p[0].c[n / 2];
    });
    stage("phase (contiguous)", reps, || {
        let p = contiguous_phase(std::hint::black_box(&y)).unwrap();
        check += p.c[n / 2];
    });
    stage("octave sweep", reps, || {
        check += sums_of_squares(
            std::hint::black_box(&phases[0].c),
            &ms,
            Difference::Second,
            &_core::interrupt::NEVER,
        )[0];
    });
    let oadev = Statistic::Allan { overlapping: true };
    stage("analyse (sweep, noise id, edf)", reps, || {
        check += _core::allan::analyse(std::hint::black_box(&phases), oadev, &ms)
            .unwrap()
            .var[0];
    });
    println!("[{check:e}]");
}

/// Runs `f` `reps` times and prints the least wall time and the mean CPU time.
fn stage(name: &str, reps: usize, mut f: impl FnMut()) {
    let mut best = f64::MAX;
    let cpu0 = cpu_seconds();
    for _ in 0..reps {
        let t = Instant::now();
        f();
        best = best.min(t.elapsed().as_secs_f64());
    }
    let cpu = (cpu_seconds() - cpu0) / reps as f64;
    println!("  {name:32} {best:.4} / {cpu:.4}");
}

/// A vectorisable plain sum (eight lanes): a read at the speed of memory.
fn lanes_sum(v: &[f64]) -> f64 {
    let (chunks, rest) = v.as_chunks::<8>();
    let mut lanes = [0.0f64; 8];
    for chunk in chunks {
        for (lane, x) in lanes.iter_mut().zip(chunk) {
            *lane += x;
        }
    }
    lanes.iter().sum::<f64>() + rest.iter().sum::<f64>()
}
