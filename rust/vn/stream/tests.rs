//! Tests of the stream reader: spec examples, damage and accounting, and the
//! equivalence of every path (fast path or not, sequential, parallel, chunked).

use std::collections::BTreeMap;

use proptest::prelude::*;

use crate::error::CoreResult;
use crate::vn::stream::{
    parse_bytes, parse_bytes_with, parse_reader, parse_reader_with, Parser, Pieces,
};
use crate::vn::{checksum, messages, IssueKind, VnData};

const A1: &[u8] = b"$VNYMR,+100.949,-007.330,+000.715,-00.0049,-00.2449,+00.5397,-01.258,-00.100,-09.701,-00.000018,+00.001122,-00.000551*69\r\n";
const B1: [u8; 26] = [
    0xFA, 0x01, 0x09, 0x00, 0x70, 0x05, 0x00, 0x03, 0x0A, 0x00, 0x00, 0x00, 0x48, 0x0E, 0x2C, 0x42,
    0x08, 0x4C, 0x37, 0xC1, 0x10, 0x38, 0x8B, 0xC2, 0xD4, 0xCB,
];

/// Test vector B2 of the spec: a second binary configuration.
fn binary_b2() -> Vec<u8> {
    let hex = "FA0128 05A802C33FE789B0423DA96AC1D083543A923E0BBB1C2530BA047D1C413BB2833D4EEA9CBEF1BD93BEA4558CBD26C7773EF428E641 57CEC142C0E9";
    let h: String = hex.chars().filter(|c| !c.is_whitespace()).collect();
    (0..h.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&h[i..i + 2], 16).unwrap_or(0))
        .collect()
}

fn accounted(d: &VnData, n: usize) -> bool {
    d.bytes_total == n as u64
        && d.bytes_parsed + d.bytes_in_bad_records + d.bytes_skipped == n as u64
        && d.issues.count(IssueKind::BytesSkipped) == d.bytes_skipped
}

#[test]
fn spec_sentences() {
    let text = b"$VNYPR,+010.071,+000.278,-002.026*60\r\n\
$VNYPR,+010.071,+000.278,-002.026,T1162704*2F\r\n\
$VNYPR,+010.071,+000.278,-002.026,S0000*1F\n\
$VNRRG,27,+006.380,+000.023,-001.953,+1.0640,-0.2531,+3.0614,+00.005,+00.344,-09.758,-0.001222,-0.000450,-0.001218*4F\r\n\
$VNERR,03*72\r\n$VNWNV*57\r\n$VNRRG,15*92EA\r\n\
$VNQMR,-0.017057,-0.000767,+0.056534,+0.998255,+1.0670,-0.2568,+3.0696,-00.019,+00.320,-09.802,-0.002801,-0.001186,-0.001582*65\r\n\
$VNERR,12*72\r\n";
    let d = parse_bytes(text, false).unwrap();
    assert!(accounted(&d, text.len()));
    let ypr = &d.tables["VNYPR"];
    assert_eq!(ypr.len, 3);
    assert_eq!(ypr.column(0), vec![10.071; 3]);
    let t = &ypr
        .extra
        .iter()
        .find(|(n, _)| n == "serial_count")
        .unwrap()
        .1;
    assert!(t[0].is_nan() && t[1] == 1162704.0 && t[2].is_nan());
    assert_eq!(d.tables["VNYMR"].column(0), vec![6.380]);
    assert_eq!(d.issues.count(IssueKind::DeviceError), 1);
    assert_eq!(d.issues.count(IssueKind::BadChecksum), 1);
    assert_eq!(d.issues.count(IssueKind::MalformedField), 1);
    assert_eq!(d.messages["VNWNV"], 1);
    assert_eq!(d.messages["VNRRG"], 1);
    assert_eq!(d.issues.first[IssueKind::BadChecksum as usize][0].line, 8);
    let err = parse_bytes(text, true).unwrap_err();
    assert!(err.to_string().starts_with("line 8 "), "{err}");
}

#[test]
fn interleaved_and_truncated() {
    let mut s = Vec::new();
    s.extend_from_slice(b"noise");
    s.extend_from_slice(&B1);
    s.extend_from_slice(A1);
    s.extend_from_slice(&B1);
    s.extend_from_slice(&A1[..50]);
    s.extend_from_slice(&B1);
    s.extend_from_slice(&B1[..20]);
    let d = parse_bytes(&s, false).unwrap();
    assert!(accounted(&d, s.len()));
    assert_eq!(d.binary_records, 3);
    assert_eq!(d.ascii_records, 1);
    assert_eq!(d.issues.count(IssueKind::TruncatedRecord), 2);
    assert_eq!(d.issues.count(IssueKind::BytesSkipped), 5);
    // Corrupt the CRC of the second packet: counted, neighbours kept.
    let mut bad = s.clone();
    bad[5 + 26 + A1.len() + 25] ^= 1;
    let d = parse_bytes(&bad, false).unwrap();
    assert_eq!(d.binary_records, 2);
    assert_eq!(d.issues.count(IssueKind::BadChecksum), 1);
    assert!(accounted(&d, s.len()));
}

#[test]
fn damaged_records_mark_missing_rows() {
    // Good, bad checksum, good, truncated, malformed, good, unknown type, good:
    // three samples of the $VNYMR stream lost, after rows 1, 2 and 2.
    let mut bad_sum = A1.to_vec();
    bad_sum[10] = b'9';
    let malformed = b"$VNYMR,1,2*XX\r\n";
    let parts: [&[u8]; 9] = [
        A1,
        &bad_sum,
        A1,
        &A1[..40],
        b"\r\n",
        malformed,
        A1,
        b"$VNXYZ,1*00\r\n",
        A1,
    ];
    let s = parts.concat();
    let whole = parse_bytes(&s, false).unwrap();
    let ymr = &whole.tables["VNYMR"];
    assert_eq!(ymr.len, 4);
    assert_eq!(ymr.missing, vec![1, 2, 2]);
    // The same in pieces on all cores.
    let par = parse_bytes_with(Parser::new(false).with_parallel_min(64), &s).unwrap();
    assert_eq!(par.tables["VNYMR"].missing, ymr.missing);
    // A binary packet with a bad CRC between good ones of its configuration.
    let mut b = Vec::new();
    b.extend_from_slice(&B1);
    let mut broken = B1;
    broken[20] ^= 1;
    b.extend_from_slice(&broken);
    b.extend_from_slice(&B1);
    let d = parse_bytes(&b, false).unwrap();
    let table = d.tables.values().find(|t| t.len == 2).unwrap();
    assert_eq!(table.missing, vec![1]);
}

/// Mutates `s` by (position, byte, operation) edits: 0 inserts the byte, 1
/// removes one, 2 overwrites one (positions wrap around the current length).
fn apply_edits(s: &mut Vec<u8>, edits: &[(u16, u8, u8)]) {
    for &(pos, byte, op) in edits {
        let i = pos as usize % (s.len() + 1);
        match op {
            0 => s.insert(i, byte),
            1 if i < s.len() => {
                s.remove(i);
            }
            _ if i < s.len() => s[i] = byte,
            _ => {}
        }
    }
}

/// `records` ASCII sentences with a binary packet before every `every`-th one.
fn interleaved(records: usize, every: usize) -> Vec<u8> {
    let mut s = Vec::new();
    for k in 0..records {
        if k % every == 0 {
            s.extend_from_slice(&B1);
        }
        s.extend_from_slice(A1);
    }
    s
}

#[test]
fn chunked_reader_equals_whole() {
    let s = interleaved(5000, 7);
    let whole = parse_bytes(&s, false).unwrap();
    struct Slow<'a>(&'a [u8], usize);
    impl std::io::Read for Slow<'_> {
        fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
            let n = buf.len().min(self.1).min(self.0.len());
            buf[..n].copy_from_slice(&self.0[..n]);
            self.0 = &self.0[n..];
            Ok(n)
        }
    }
    let mut calls = 0;
    let chunked = parse_reader(Slow(&s, 977), s.len() as u64, false, &mut |_, _| {
        calls += 1;
        Ok(())
    })
    .unwrap();
    assert_eq!(whole, chunked);
    assert_eq!(whole.tables["VNYMR"].len, 5000);
    assert!(calls >= 1);
}

#[test]
fn pieces_add_up_to_the_whole() {
    let mut s = interleaved(3000, 5);
    s[1000] ^= 0x20; // one damaged record: its location runs on across pieces
    let whole = parse_bytes(&s, false).unwrap();
    for piece in [7usize, 61, 1000, 4096] {
        let mut stream = Pieces::new(false);
        let mut rows: BTreeMap<String, usize> = BTreeMap::new();
        let mut add = |tables: BTreeMap<String, crate::vn::Table>| {
            for (name, t) in tables {
                *rows.entry(name).or_insert(0) += t.len;
            }
        };
        for part in s.chunks(piece) {
            add(stream.feed(part).unwrap());
        }
        let mut summary = stream.finish().unwrap();
        add(std::mem::take(&mut summary.tables));
        for (name, t) in &whole.tables {
            assert_eq!(rows.get(name).copied().unwrap_or(0), t.len, "{name}");
        }
        let mut want = whole.clone();
        want.tables.clear();
        assert_eq!(summary, want);
    }
}

#[test]
fn buffers_given_back_hold_the_next_rows() {
    // Each piece's rows land in the buffer of the piece before, given back, and
    // add up to the whole parse as without the give-back.
    let s = interleaved(3000, 5);
    let whole = parse_bytes(&s, false).unwrap();
    let mut stream = Pieces::new(false);
    let mut values: BTreeMap<String, Vec<f64>> = BTreeMap::new();
    let mut reused = 0;
    let mut given: Vec<*const f64> = Vec::new();
    for part in s.chunks(40_000) {
        let mut now = Vec::new();
        for (name, mut t) in stream.feed(part).unwrap() {
            values.entry(name).or_default().extend_from_slice(&t.values);
            if t.len > 0 && given.contains(&t.values.as_ptr()) {
                reused += 1;
            }
            now.push(t.values.as_ptr());
            stream.give_back(std::mem::take(&mut t.values));
        }
        given = now;
    }
    for (name, t) in stream.finish().unwrap().tables {
        values.entry(name).or_default().extend_from_slice(&t.values);
    }
    for (name, t) in &whole.tables {
        assert_eq!(values[name], t.values, "{name}");
    }
    assert!(reused > 0, "no buffer was reused");
}

#[test]
fn parallel_binary_takes_clean_pieces() {
    let b2 = binary_b2();
    let mut s = Vec::new();
    for k in 0..30_000 {
        s.extend_from_slice(if k % 3 == 0 { &b2 } else { &B1 });
        if k % 1000 == 0 {
            s.extend_from_slice(A1);
        }
    }
    let want = format!("{:?}", reference(&s, false).unwrap());
    let mut p = Parser::with_size_hint(false, s.len() as u64);
    let used = p.feed_block(&s, true);
    assert_eq!(used, s.len());
    assert!(p.merged_pieces >= 2, "{}", p.merged_pieces);
    assert_eq!(format!("{:?}", p.finish().unwrap()), want);
    // Damage in the middle: pieces before it are merged, the rest is sequential.
    let half = s.len() / 2;
    let mid = half + s[half..].iter().position(|&c| c == 0xFA).unwrap_or(0) + 6;
    s[mid] ^= 0x55;
    let want = format!("{:?}", reference(&s, false).unwrap());
    let mut p = Parser::with_size_hint(false, s.len() as u64);
    p.feed_block(&s, true);
    assert!(p.merged_pieces >= 1);
    let got = p.finish().unwrap();
    assert_eq!(got.issues.count(IssueKind::BadChecksum), 1);
    assert_eq!(format!("{got:?}"), want);
}

#[test]
fn parallel_equals_sequential() {
    let mut s = Vec::new();
    for k in 0..40_000u32 {
        if k % 1000 == 3 {
            s.extend_from_slice(&A1[..60]);
            s.push(b'\n');
        }
        s.extend_from_slice(A1);
    }
    let par = parse_bytes(&s, false).unwrap();
    let mut p = Parser::new(false);
    p.feed(&s, true);
    let seq = p.finish().unwrap();
    assert_eq!(par, seq);
    assert_eq!(par.tables["VNYMR"].len, 40_000);
    assert_eq!(par.issues.count(IssueKind::TruncatedRecord), 40);
    let err = parse_bytes(&s, true).unwrap_err().to_string();
    assert!(err.starts_with("line 4 "), "{err}");
}

/// Sequential parse without the ASCII fast path: the reference behaviour.
fn reference(data: &[u8], strict: bool) -> CoreResult<VnData> {
    let mut p = Parser::new(strict).without_fast_path();
    p.feed(data, true);
    p.finish()
}

/// A number as text: sign, digits, dot, digits, in every combination the
/// grammar allows and some it does not (empty, 20+ digits, stray bytes).
fn number() -> impl Strategy<Value = String> {
    (
        prop_oneof![Just(""), Just("+"), Just("-")],
        "[0-9]{0,21}",
        prop_oneof![Just(""), Just(".")],
        "[0-9]{0,24}",
        prop_oneof![8 => Just(""), 1 => Just("e3"), 1 => Just("x")],
    )
        .prop_map(|(s, a, d, b, t)| format!("{s}{a}{d}{b}{t}"))
}

/// Sentences of random message types with random fields, then checksum or
/// CRC (right, wrong or `XX`), appended T/S fields and line ends.
fn sentences() -> impl Strategy<Value = Vec<u8>> {
    let one = (
        0..messages::MESSAGES.len() + 2,
        proptest::collection::vec(number(), 0..15),
        0u8..6,
        prop_oneof![Just(""), Just(",T123"), Just(",S00A1"), Just(",T1,S0001")],
        prop_oneof![
            Just("\r\n"),
            Just("\n"),
            Just(""),
            Just("\r"),
            Just("7"),
            Just("X")
        ],
        any::<bool>(),
    )
        .prop_map(|(m, fields, check, tail, eol, exact)| {
            let id = match messages::MESSAGES.get(m) {
                Some(spec) => spec.id,
                None if m == messages::MESSAGES.len() => "VNRRG",
                None => "VNGPS",
            };
            let mut body = id.to_string();
            let n = messages::MESSAGES
                .get(m)
                .map_or(fields.len(), |s| s.fields.len());
            let take = if exact {
                n.min(fields.len())
            } else {
                fields.len()
            };
            for f in fields.iter().take(take) {
                body.push(',');
                body.push_str(f);
            }
            if exact {
                for _ in take..n {
                    body.push_str(",+1.5");
                }
            }
            body.push_str(tail);
            let x = checksum::xor8(body.as_bytes());
            let c = checksum::crc16(body.as_bytes());
            let field = match check {
                0 | 1 => format!("{x:02X}"),
                2 => format!("{x:02x}"),
                3 => format!("{c:04X}"),
                4 => format!("{:02X}", x ^ 1),
                _ => "XX".to_string(),
            };
            format!("${body}*{field}{eol}").into_bytes()
        });
    proptest::collection::vec(one, 1..40).prop_map(|v| v.concat())
}

/// A stream of ASCII and binary records (and a truncated one, a command reply)
/// in the order `kinds` picks, with one bit flipped at `flip`.
fn damaged_stream(kinds: &[u8], flip: u16) -> Vec<u8> {
    let b2 = binary_b2();
    let mut s = Vec::new();
    for k in kinds {
        match k {
            0 => s.extend_from_slice(&B1),
            1 => s.extend_from_slice(&b2),
            2 | 3 => s.extend_from_slice(A1),
            4 => s.extend_from_slice(&A1[..40]),
            _ => s.extend_from_slice(b"$VNRRG,05,115200*5C\n"),
        }
    }
    let at = flip as usize % s.len();
    s[at] ^= 0x20;
    s
}

/// Field widths of a fixed-width message: sign, whole digits, dot, decimals
/// (cycled over the fields; some outside the fast path's grammar).
type Widths = Vec<(bool, usize, bool, usize)>;

/// `count` sentences of message `m`, every field at its width of `widths`,
/// digits and signs from `seed`, XOR-8 in either case, ended by `eol`.
fn fixed_width(m: usize, widths: &Widths, seed: u64, count: usize, eol: &str) -> Vec<u8> {
    let spec = &messages::MESSAGES[m % messages::MESSAGES.len()];
    let mut r = seed | 1;
    let mut next = move || {
        r ^= r << 13;
        r ^= r >> 7;
        r ^= r << 17;
        r
    };
    let mut out = Vec::new();
    for _ in 0..count {
        let mut body = spec.id.to_string();
        for k in 0..spec.fields.len() {
            let (sign, whole, dot, frac) = widths[k % widths.len()];
            body.push(',');
            if sign {
                body.push(if next() % 2 == 0 { '+' } else { '-' });
            }
            let digits = whole + if dot { frac } else { 0 };
            for d in 0..digits {
                if dot && d == whole {
                    body.push('.');
                }
                body.push((b'0' + (next() % 10) as u8) as char);
            }
            if dot && frac == 0 {
                body.push('.');
            }
        }
        let x = checksum::xor8(body.as_bytes());
        let check = match next() % 4 {
            0 => format!("{x:02x}"),
            _ => format!("{x:02X}"),
        };
        out.extend_from_slice(format!("${body}*{check}{eol}").as_bytes());
    }
    out
}

#[test]
fn shapes_take_fixed_width_sentences_from_avx2_on() {
    // The sensor's widths, with a width change, a bad checksum and two
    // message types interleaved: the shapes take all but the sentences after
    // a change, and the values are the reference's.
    let w = |whole, frac| vec![(true, whole, true, frac)];
    let mut s = fixed_width(0, &w(3, 3), 7, 200, "\r\n");
    s.extend(fixed_width(0, &w(2, 4), 8, 100, "\n"));
    let bad = s.len() - 40;
    s[bad] ^= 1;
    for k in 0..50 {
        s.extend(fixed_width(0, &w(3, 3), k, 1, "\r\n"));
        s.extend(fixed_width(1, &w(1, 2), k, 1, "\r\n"));
    }
    let want = format!("{:?}", reference(&s, false));
    crate::simd::at_every_level(|level| {
        let mut p = Parser::with_size_hint(false, s.len() as u64);
        p.feed(&s, true);
        let hits = p.shape_hits;
        assert_eq!(format!("{:?}", p.finish()), want, "{level:?}");
        let expect = if level >= crate::simd::Level::Avx2 {
            390
        } else {
            0
        };
        assert!(hits >= expect, "{level:?}: {hits} sentences by shape");
    });
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]

    #[test]
    fn fast_path_agrees(s in sentences(), cut in any::<u16>()) {
        // Debug text compares NaN padding and the sign of zero exactly.
        let text = |d: CoreResult<VnData>| match d {
            Ok(d) => format!("{d:?}"),
            Err(e) => e.to_string(),
        };
        let want = text(reference(&s, false));
        prop_assert_eq!(text(parse_bytes(&s, false)), want.clone());
        let mut p = Parser::new(false);
        p.feed(&s, true);
        prop_assert_eq!(text(p.finish()), want);
        // Cut anywhere: what is consumed and decoded agrees too.
        let cut = cut as usize % (s.len() + 1);
        let (mut a, mut b) = (Parser::new(false), Parser::new(false).without_fast_path());
        prop_assert_eq!(a.feed(&s[..cut], false), b.feed(&s[..cut], false));
        prop_assert_eq!(text(a.finish()), text(b.finish()));
        prop_assert_eq!(text(parse_bytes(&s, true)), text(reference(&s, true)));
    }

    #[test]
    fn fast_path_agrees_at_every_level(
        s in sentences(),
        flips in proptest::collection::vec((any::<u16>(), 0u8..8), 0..4),
    ) {
        // The vector divisions of the fast path against the general path, on
        // sentences with corrupt bytes too, at every instruction-set level.
        let mut s = s;
        for (at, bit) in flips {
            let at = at as usize % s.len();
            s[at] ^= 1 << bit;
        }
        let text = |d: CoreResult<VnData>| match d {
            Ok(d) => format!("{d:?}"),
            Err(e) => e.to_string(),
        };
        let want = text(reference(&s, false));
        crate::simd::at_every_level(|level| {
            assert_eq!(text(parse_bytes(&s, false)), want, "{level:?}");
            let p = Parser::with_size_hint(false, s.len() as u64).with_parallel_min(64);
            assert_eq!(text(parse_bytes_with(p, &s)), want, "{level:?} parallel");
        });
    }

    #[test]
    fn fixed_width_streams_agree_at_every_level(
        parts in proptest::collection::vec(
            (
                0usize..64,
                proptest::collection::vec((any::<bool>(), 0usize..9, any::<bool>(), 0usize..9), 1..5),
                any::<u64>(),
                1usize..14,
                0u8..7,
            ),
            1..6,
        ),
        edits in proptest::collection::vec(
            (any::<u16>(), proptest::sample::select(b"$*,.+-07aX\r\n\xfa ".to_vec()), 0u8..3),
            0..6,
        ),
        chunk in 50usize..400,
    ) {
        // Streams of sentences whose fields keep their widths (the sensor's
        // output, which the shapes of the vector levels take), with the width
        // changing between runs, checksums wrong, line ends LF, CRLF or none,
        // '$' in noise, lines longer than a shape's window, binary packets
        // (in any piece of a parallel block), then damage; cut
        // into parallel pieces and chunks. Every level gives the reference's
        // rows, counts and first locations.
        let mut s = Vec::new();
        for (m, widths, seed, count, kind) in parts {
            let eol = ["\r\n", "\n", "", "\r\n", "\r\n", "\n", "\r\n"][kind as usize];
            let mut run = fixed_width(m, &widths, seed, count, eol);
            match kind {
                3 => run.extend_from_slice(b"noise $ $VN $VNYMR,+1*00 garbage\r\n"),
                4 => {
                    // A wrong checksum in the middle of the run.
                    if let Some(p) = run.iter().rposition(|&c| c == b'*') {
                        run[p + 1] = if run[p + 1] == b'0' { b'1' } else { b'0' };
                    }
                }
                5 => {
                    run.extend_from_slice(b"$VNYMR");
                    run.extend(std::iter::repeat_n(b",+0.5", 80).flatten());
                    run.extend_from_slice(b"*00\r\n");
                }
                6 => {
                    // A binary packet inside a run of sentences.
                    let at = run.len() / 2;
                    run.splice(at..at, B1);
                }
                _ => {}
            }
            s.extend(run);
        }
        apply_edits(&mut s, &edits);
        let text = |d: CoreResult<VnData>| match d {
            Ok(d) => format!("{d:?}"),
            Err(e) => e.to_string(),
        };
        let want = text(reference(&s, false));
        let want_strict = text(reference(&s, true));
        crate::simd::at_every_level(|level| {
            assert_eq!(text(parse_bytes(&s, false)), want, "{level:?}");
            assert_eq!(text(parse_bytes(&s, true)), want_strict, "{level:?} strict");
            let p = Parser::with_size_hint(false, s.len() as u64).with_parallel_min(64);
            assert_eq!(text(parse_bytes_with(p, &s)), want, "{level:?} parallel");
            let p = Parser::with_size_hint(false, s.len() as u64).with_parallel_min(0);
            let got = parse_reader_with(p, &s[..], s.len() as u64, chunk, &mut |_, _| Ok(()));
            assert_eq!(text(got), want, "{level:?} chunks of {chunk}");
        });
    }

    #[test]
    fn parallel_binary_equals_sequential(
        kinds in proptest::collection::vec(0u8..5, 20..200),
        edits in proptest::collection::vec((any::<u16>(), any::<u8>(), 0u8..3), 0..8),
        min in 0usize..3000,
    ) {
        // Packets of two configurations, sentences and noise, then damage.
        let b2 = binary_b2();
        let mut s = Vec::new();
        for k in kinds {
            match k {
                0 | 1 => s.extend_from_slice(&B1),
                2 => s.extend_from_slice(&b2),
                3 => s.extend_from_slice(A1),
                _ => s.extend_from_slice(b"\xfa\x01noise\n"),
            }
        }
        apply_edits(&mut s, &edits);
        let text = |d: CoreResult<VnData>| match d {
            Ok(d) => format!("{d:?}"),
            Err(e) => e.to_string(),
        };
        for strict in [false, true] {
            let par = parse_bytes_with(Parser::new(strict).with_parallel_min(min), &s);
            prop_assert_eq!(text(par), text(reference(&s, strict)));
        }
        // In pieces too, as the file reader feeds them.
        let mut r = Parser::new(false).with_parallel_min(min);
        let mut pos = 0;
        while pos < s.len() {
            let end = (pos + 700).min(s.len());
            let used = r.feed_block(&s[pos..end], end == s.len());
            pos += if used == 0 && end < s.len() {
                r.feed_block(&s[pos..s.len()], true)
            } else {
                used
            };
        }
        prop_assert_eq!(text(r.finish()), text(reference(&s, false)));
    }

    #[test]
    fn small_chunks_equal_whole(
        kinds in proptest::collection::vec(0u8..6, 1..300),
        chunk in 1usize..400,
        flip in any::<u16>(),
    ) {
        let s = damaged_stream(&kinds, flip);
        let want = format!("{:?}", reference(&s, false));
        for min in [0usize, 1 << 20] {
            let p = Parser::with_size_hint(false, s.len() as u64).with_parallel_min(min);
            let mut calls = 0u64;
            let got = parse_reader_with(p, &s[..], s.len() as u64, chunk, &mut |d, t| {
                calls += 1;
                assert!(d <= t);
                Ok(())
            });
            let got = format!("{got:?}");
            if got != want {
                let k = got.bytes().zip(want.bytes()).take_while(|(a, b)| a == b).count();
                panic!("min {min}: got {} want {}", &got[k.saturating_sub(200)..(k + 300).min(got.len())], &want[k.saturating_sub(200)..(k + 300).min(want.len())]);
            }
            prop_assert!(calls >= (s.len() / chunk) as u64);
        }
    }

    #[test]
    fn pieces_equal_whole(
        kinds in proptest::collection::vec(0u8..6, 1..200),
        piece in 1usize..300,
        flip in any::<u16>(),
    ) {
        // Damaged streams too: counts, first locations and rows do not depend on
        // where the pieces end.
        let s = damaged_stream(&kinds, flip);
        let whole = parse_bytes(&s, false).unwrap();
        let mut stream = Pieces::new(false);
        let mut rows: BTreeMap<String, Vec<f64>> = BTreeMap::new();
        let mut add = |tables: BTreeMap<String, crate::vn::Table>| {
            for (name, t) in tables {
                rows.entry(name).or_default().extend_from_slice(&t.values);
            }
        };
        for part in s.chunks(piece) {
            add(stream.feed(part).unwrap());
        }
        let mut summary = stream.finish().unwrap();
        add(std::mem::take(&mut summary.tables));
        for (name, t) in &whole.tables {
            let got = rows.get(name).map_or(&[][..], |v| v.as_slice());
            prop_assert_eq!(format!("{got:?}"), format!("{:?}", t.values), "{}", name);
        }
        let mut want = whole.clone();
        want.tables.clear();
        prop_assert_eq!(format!("{summary:?}"), format!("{want:?}"));
    }

    #[test]
    fn random_bytes_are_accounted(data in proptest::collection::vec(any::<u8>(), 0..3000)) {
        let d = parse_bytes(&data, false).unwrap();
        prop_assert!(accounted(&d, data.len()));
    }

    #[test]
    fn mutated_streams_are_accounted(
        edits in proptest::collection::vec((any::<u16>(), any::<u8>(), 0u8..3), 0..20)
    ) {
        let mut s = Vec::new();
        for _ in 0..10 {
            s.extend_from_slice(A1);
            s.extend_from_slice(&B1);
        }
        apply_edits(&mut s, &edits);
        let d = parse_bytes(&s, false).unwrap();
        prop_assert!(accounted(&d, s.len()));
        let _ = parse_bytes(&s, true);
    }
}
