//! Time the overlapping Allan variance's stages without Python: `cargo run
//! --release --no-default-features --example allan_profile -- [N] [REPEATS]`.
//! White noise of N samples (default 10^7), octave taus. Prints, per stage, the
//! least wall time over the repeats (the least disturbed on a shared machine)
//! and the mean CPU time of all threads, beside the memory-bandwidth yardstick:
//! one plain read of the samples. `RAYON_NUM_THREADS=1` gives each stage's CPU
//! time on one core undisturbed by the other threads' share of the machine.
use std::time::Instant;

use _core::allan::fast::blocked::{sums_of_squares, Difference};
use _core::allan::running_sum;
use _core::allan::uncertainty::edf::{greenhall_edf, Estimator};
use _core::allan::uncertainty::noise_id::identify_alphas;
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
    // IMUNOISE_SIMD pins a lower level, as in Python.
    if let Ok(name) = std::env::var("IMUNOISE_SIMD") {
        let level = _core::simd::Level::from_name(name.trim()).expect("IMUNOISE_SIMD: a level");
        _core::simd::force(Some(level));
    }
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
    println!(
        "n {n}, {} octave taus, level {}; least wall s / mean CPU s",
        ms.len(),
        _core::simd::level().name()
    );
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
    let mean = y.iter().sum::<f64>() / n as f64;
    stage("phase: chunk totals", reps, || {
        let t = running_sum::chunk_totals(std::hint::black_box(&y), mean);
        check += t[0].0;
    });
    let mut run = y.clone();
    let starts = vec![(0.0, 0.0); n.div_ceil(running_sum::CHUNK)];
    stage("phase: running sums (in place)", reps, || {
        running_sum::run_chunks(std::hint::black_box(&mut run), &starts, mean);
        check += run[n / 2];
    });
    stage("octave sweep", reps, || {
        check += sums_of_squares(
            std::hint::black_box(&phases[0].c),
            &ms,
            Difference::Second,
            &_core::interrupt::NEVER,
        )[0];
    });
    for (name, part) in [
        ("octave sweep, m <= 64", &ms[..7]),
        ("octave sweep, 128 <= m <= 8192", &ms[7..14]),
        ("octave sweep, m >= 16384", &ms[14..]),
    ] {
        stage(name, reps, || {
            check += sums_of_squares(
                std::hint::black_box(&phases[0].c),
                part,
                Difference::Second,
                &_core::interrupt::NEVER,
            )[0];
        });
    }
    let oadev = Statistic::Allan { overlapping: true };
    stage("noise id (all taus)", reps, || {
        let alphas = identify_alphas(std::hint::black_box(&phases[0].c), &ms, 2);
        check += alphas.iter().map(|a| a.unwrap_or(9) as f64).sum::<f64>();
    });
    let est = Estimator {
        d: 2,
        overlapping: true,
        modified: false,
    };
    stage("edf (all taus, alpha 0)", reps, || {
        for &m in &ms {
            check += greenhall_edf(0, est, m, std::hint::black_box(n + 1));
        }
    });
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
