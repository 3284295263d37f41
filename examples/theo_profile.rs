//! Time the exact ThêoBR/ThêoH sweep and its limb kernels at every SIMD level the
//! CPU has, without Python: `cargo run --release --no-default-features --example
//! theo_profile -- [N] [REPEATS] [LEVELS]`. White FM of N samples (default
//! 720,000), the default ratio ladder (Theo1 at m = 12, 16, …, ≈ 0.13·N), as
//! ThêoH's κ sweeps it; LEVELS is a comma-separated list (default: every level
//! the CPU has). Prints, per level, the least wall time over the repeats and the
//! mean CPU time of all threads, the kernels' nanoseconds per product, and
//! whether the sums equal the first level's to the bit.
use std::time::Instant;

use _core::allan::estimators::theobr::ratio_factors;
use _core::allan::fast::exact_phase::ExactPhase;
use _core::allan::fast::limbs::{self, Limbs, MAX_FACTOR};
use _core::allan::fast::theo1_sweep::theo1_sums;
use _core::interrupt::Interrupt;
use _core::simd::{self, Level};

mod common;
use common::cpu_seconds;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(720_000);
    let reps: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1);
    let levels: Vec<Level> = match args.get(3) {
        Some(list) => list.split(',').filter_map(Level::from_name).collect(),
        None => Level::ALL
            .into_iter()
            .filter(|&l| l <= simd::detected())
            .collect(),
    };
    // White FM: the phase is a random walk (xorshift noise, uniform).
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let mut walk = 0.0;
    let c: Vec<f64> = (0..n)
        .map(|_| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            walk += (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            walk
        })
        .collect();
    // The default ladder: n + 1 ratios, n = ⌊0.1·N/3⌋ − 3.
    let ratios = (n / 30).saturating_sub(3);
    let (avar_top, _) = ratio_factors(ratios);
    let ms: Vec<usize> = (0..=ratios).map(|i| ratio_factors(i).1).collect();
    let p = ExactPhase::new(&c, 2 * avar_top).expect("exact phase");
    println!(
        "n {n}, {} Theo1 factors up to m = {}, detected level {}; least wall s / mean CPU s",
        ms.len(),
        ms.last().unwrap(),
        simd::detected().name()
    );
    let never = Interrupt::new();
    let mut first: Option<Vec<u64>> = None;
    for &level in &levels {
        simd::force(Some(level));
        let mut bits = Vec::new();
        let (wall, cpu) = timed(reps, || {
            let sums = theo1_sums(&p, &ms, &never).expect("sweep");
            bits = sums.iter().map(|s| s.to_bits()).collect();
        });
        let same = match &first {
            None => {
                first = Some(bits);
                "reference".to_string()
            }
            Some(want) => format!("same bits: {}", &bits == want),
        };
        println!(
            "  {:7} sweep {wall:8.3} / {cpu:8.3}   {same}",
            simd::level().name()
        );
        kernels(reps.max(3));
    }
    simd::force(None);
}

/// Nanoseconds per product of the three kernels on cache-resident rows, one
/// thread, at the current level.
fn kernels(reps: usize) {
    let len = 4096;
    let calls = 400;
    let x: Vec<Vec<i64>> = (0..8)
        .map(|r| {
            let mut s = 77 + r as u64;
            (0..len + 8)
                .map(|_| {
                    s = s
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    ((s >> 12) as i64) & (MAX_FACTOR >> 1)
                })
                .collect()
        })
        .collect();
    let mut w = Limbs::from_values((0..len).map(|_| 0i128));
    let (scaled, _) = timed(reps, || {
        for call in 0..calls {
            let rows: [(i64, &[i64]); 8] =
                std::array::from_fn(|r| (x[r][call % 8] * 2, &x[r][r..]));
            limbs::add_scaled_rows(&mut w.l0, &mut w.l1, rows);
            if call % 16 == 15 {
                w.normalise();
            }
        }
    });
    let (pairs, _) = timed(reps, || {
        for call in 0..calls {
            let pairs: [(&[i64], &[i64]); 4] =
                std::array::from_fn(|r| (&x[2 * r][call % 8..], &x[2 * r + 1][..]));
            limbs::add_pair_products(&mut w.l0, &mut w.l1, pairs);
            if call % 16 == 15 {
                w.normalise();
            }
        }
    });
    let mut check = 0i128;
    let (dot, _) = timed(reps, || {
        for call in 0..calls {
            check = check.wrapping_add(limbs::dot(&x[call % 8], &x[(call + 1) % 8]));
        }
    });
    std::hint::black_box((check, w.get(0)));
    let ns = |t: f64, per_call: usize| t * 1e9 / (calls * per_call) as f64;
    println!(
        "          ns/product: scaled rows {:.3}, pair products {:.3}, dot {:.3}",
        ns(scaled, 8 * len),
        ns(pairs, 4 * len),
        ns(dot, len + 8)
    );
}

/// Least wall seconds over `reps` runs and mean CPU seconds of all threads.
fn timed(reps: usize, mut f: impl FnMut()) -> (f64, f64) {
    let mut best = f64::MAX;
    let cpu0 = cpu_seconds();
    for _ in 0..reps {
        let t = Instant::now();
        f();
        best = best.min(t.elapsed().as_secs_f64());
    }
    (best, (cpu_seconds() - cpu0) / reps as f64)
}
