//! Time the VN parser on a file without Python: `cargo run --release
//! --no-default-features --example parse_profile -- FILE [REPEATS]`
//! (`IMUNOISE_SIMD=scalar|avx2|avx512|ifma` pins the level, as in Python).
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let path = std::path::Path::new(&args[1]);
    let reps: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(5);
    let bytes = std::fs::read(path).unwrap();
    if let Ok(name) = std::env::var("IMUNOISE_SIMD") {
        _core::simd::force(_core::simd::Level::from_name(&name));
    }
    println!("level {}", _core::simd::level().name());
    for mode in ["file", "bytes"] {
        let mut times = Vec::new();
        for _ in 0..reps {
            let t = Instant::now();
            let d = if mode == "file" {
                _core::vn::stream::parse_file(path, false, &mut |_, _| Ok(())).unwrap()
            } else {
                _core::vn::stream::parse_bytes(&bytes, false).unwrap()
            };
            times.push(t.elapsed().as_secs_f64());
            assert_eq!(d.bytes_total, bytes.len() as u64);
        }
        times.sort_by(f64::total_cmp);
        println!(
            "{mode}: median {:.4} s min {:.4} s",
            times[reps / 2],
            times[0]
        );
    }
}
