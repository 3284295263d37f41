//! Any byte stream: no panic, no hang, every byte parsed or counted, and the
//! chunked reader agrees with the in-memory parse.
#![no_main]

use _core::vn::stream::{parse_bytes, parse_reader};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(d) = parse_bytes(data, false) else { panic!("non-strict parse failed") };
    assert_eq!(d.bytes_total, data.len() as u64);
    assert_eq!(d.bytes_parsed + d.bytes_in_bad_records + d.bytes_skipped, d.bytes_total);
    let _ = parse_bytes(data, true);
    let chunked = parse_reader(data, data.len() as u64, false, &mut |_, _| Ok(())).unwrap();
    assert_eq!(chunked, d);
});
