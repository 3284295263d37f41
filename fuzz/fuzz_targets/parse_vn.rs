//! Any byte stream: no panic, no hang, every byte parsed or counted, and every
//! way of parsing it gives the same answer as the plain sequential parser
//! without the ASCII fast path: in memory, chunked from a reader, and with the
//! parallel block paths forced onto small inputs.
#![no_main]

use _core::vn::stream::{parse_bytes, parse_bytes_with, parse_reader, parse_reader_with, Parser};
use libfuzzer_sys::fuzz_target;

fn text<E: std::fmt::Display>(r: Result<_core::vn::VnData, E>) -> String {
    match r {
        Ok(d) => format!("{d:?}"),
        Err(e) => e.to_string(),
    }
}

fuzz_target!(|data: &[u8]| {
    let Ok(d) = parse_bytes(data, false) else { panic!("non-strict parse failed") };
    assert_eq!(d.bytes_total, data.len() as u64);
    assert_eq!(d.bytes_parsed + d.bytes_in_bad_records + d.bytes_skipped, d.bytes_total);
    let chunked = parse_reader(data, data.len() as u64, false, &mut |_, _| Ok(())).unwrap();
    assert_eq!(format!("{chunked:?}"), format!("{d:?}"));
    // The first byte picks a chunk size and a parallel threshold.
    let seed = data.first().copied().unwrap_or(0) as usize;
    for strict in [false, true] {
        let mut r = Parser::new(strict).without_fast_path();
        r.feed(data, true);
        let want = text(r.finish());
        let got = parse_bytes_with(Parser::new(strict).with_parallel_min(seed % 7 * 64), data);
        assert_eq!(text(got), want, "parallel, strict={strict}");
        let p = Parser::new(strict).with_parallel_min(seed % 5 * 100);
        let got = parse_reader_with(p, data, data.len() as u64, 1 + seed % 300, &mut |_, _| Ok(()));
        assert_eq!(text(got), want, "chunked, strict={strict}");
        if !strict {
            assert_eq!(format!("{d:?}"), want);
        }
    }
});
