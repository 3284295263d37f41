//! VN ASCII sentences: field decoding of a checked sentence body.
//!
//! A sentence is `$VN<ID>,f1,...,fn[,T...][,S....]*hh` (spec §2). Framing and
//! checksums are handled by [`crate::vn::stream`]; this module turns the checked
//! body (the bytes between `$` and `*`) into values, using the message table of
//! [`crate::vn::messages`] and the number parser of [`crate::vn::number`].
//! Cost: one pass over the body; no allocation for good sentences.

use crate::simd::Level;
use crate::vn::checksum;
use crate::vn::messages::{
    command_by_id, is_defined_error, spec_by_id, spec_by_register, MsgSpec, MAX_FIELDS,
};
use crate::vn::number::{fast_digits, parse_f64, Quotients};

/// The 2024 SDK rejects ASCII packets longer than this (spec §2.1).
pub const MAX_SENTENCE: usize = 320;

/// A decoded sentence body.
#[derive(Debug, Clone, PartialEq)]
pub enum Decoded {
    Data {
        spec: &'static MsgSpec,
        values: [f64; MAX_FIELDS],
        /// Appended `T` field (counter / time), if any.
        count: Option<f64>,
        /// Appended `S` field (status word), if any.
        status: Option<f64>,
    },
    /// A command or its response (`$VNRRG,05,115200`, `$VNWNV` ...): header id.
    Command(&'static str),
    /// `$VNERR,<code>` with a defined code.
    DeviceError(u16),
    /// Well-formed sentence of a type not decoded here.
    Unknown,
    Malformed(String),
}

/// Fast path for the common sentence: `$VN` + the id of a data message of
/// [`MESSAGES`] + exactly its fields as plain decimal numbers + `*` + two hex
/// digits matching the XOR-8 checksum, followed by a byte that is not a check
/// character (`\r`, `\n`, anything else but a hex digit or `X`).
///
/// `b` starts at the `$`. Returns the spec, the values and the offset of the
/// `*` (relative to `b`); the caller adds the line end. `None` means "not this
/// simple": the general scanner and [`decode`] then decide, so every sentence
/// this accepts is one they accept with the same values (checked by
/// `fast_path_agrees` and the fuzz target), and everything else goes their way.
#[inline]
pub fn fast_sentence(
    b: &[u8],
    hint: Option<&'static MsgSpec>,
    level: Level,
) -> Option<(&'static MsgSpec, [f64; MAX_FIELDS], usize)> {
    let head = b.get(..7)?;
    if head[1] != b'V' || head[2] != b'N' || head[6] != b',' {
        return None;
    }
    let id = &head[1..6];
    let spec = match hint {
        Some(h) if h.id.as_bytes() == id => h,
        _ => spec_by_id(id)?,
    };
    // The general decoder's header rule (three upper-case letters) holds for
    // every id of MESSAGES, so a match above implies it.
    let n = spec.fields.len();
    // Every field's bounds first, then the fields: each number starts where the
    // separators say, not where the one before it ended, so the numbers of a
    // sentence are parsed side by side instead of one after another.
    let mut sep = [0usize; MAX_FIELDS + 1];
    separators(b, &mut sep[..n + 1], level)?;
    let mut values = Quotients::new();
    let mut ok = sep[0] == 6;
    for k in 0..n {
        let mut j = sep[k] + 1;
        values.set(k, fast_digits(b, &mut j)?);
        ok &= (j == sep[k + 1]) & (b[sep[k]] == b',');
    }
    let star = sep[n];
    if !ok || b[star] != b'*' {
        return None;
    }
    // The scanner looks for '*' within MAX_SENTENCE bytes of '$'.
    if star >= MAX_SENTENCE {
        return None;
    }
    // Two check digits, the byte after them, and one more (a possible LF after
    // CR) must be in the buffer, or the scanner would ask for more input.
    let field = b.get(star + 1..star + 5)?;
    let hex = |c: u8| checksum::parse_hex(&[c]);
    let check = (hex(field[0])? << 4) | hex(field[1])?;
    let x = checksum::xor8(&b[1..star]);
    if field[2].is_ascii_hexdigit() || field[2] == b'X' || check != x as u16 {
        return None;
    }
    Some((spec, values.divide(level), star))
}

/// Fills `out` with the offsets of the first `out.len()` bytes of `b` that are `,`
/// or `*`, looked for 64 bytes at a time (vector compares into a bit mask, at
/// the instruction-set `level`; byte by byte in the last, shorter window);
/// `None` when they are not all in `b` within its first [`MAX_SENTENCE`] bytes.
#[inline(always)]
fn separators(b: &[u8], out: &mut [usize], level: Level) -> Option<()> {
    #[cfg(target_arch = "x86_64")]
    if level >= Level::Avx2 {
        // SAFETY: the level is at most the CPU's (simd::level), which has AVX2.
        return unsafe { x86::separators_avx2(b, out) };
    }
    let _ = level;
    separators_with!(b, out, window_mask)
}

/// The loop of [`separators`] with `$mask(&[u8; 64]) -> u64` (bit k: byte k is a
/// separator): one body for every level, compiled with each level's features.
macro_rules! separators_with {
    ($b:expr, $out:expr, $mask:path) => {{
        let (b, out): (&[u8], &mut [usize]) = ($b, $out);
        let mut found = 0;
        let mut base = 0;
        while found < out.len() {
            if base >= MAX_SENTENCE {
                return None;
            }
            let mask = match b.get(base..base + 64) {
                Some(window) => $mask(window.try_into().ok()?),
                None => {
                    let tail = b.get(base..)?;
                    let m = tail.iter().enumerate().fold(0u64, |m, (k, &c)| {
                        m | (((c == b',') | (c == b'*')) as u64) << k
                    });
                    if m.count_ones() < (out.len() - found) as u32 {
                        return None;
                    }
                    m
                }
            };
            let mut mask = mask;
            while mask != 0 && found < out.len() {
                out[found] = base + mask.trailing_zeros() as usize;
                found += 1;
                mask &= mask - 1;
            }
            base += 64;
        }
        Some(())
    }};
}
use separators_with;

/// Bit k set where `w[k]` is `,` or `*`: SSE2 compares on x86-64 (part of its
/// baseline, the scalar level), a byte loop elsewhere.
#[inline(always)]
fn window_mask(w: &[u8; 64]) -> u64 {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::*;
        let mut mask = 0u64;
        for k in 0..4 {
            // SAFETY: SSE2 is part of every x86-64 CPU; the load reads bytes
            // 16k..16k+16 of the 64-byte window.
            let bits = unsafe {
                let v = _mm_loadu_si128(w.as_ptr().add(16 * k).cast());
                let hit = _mm_or_si128(
                    _mm_cmpeq_epi8(v, _mm_set1_epi8(b',' as i8)),
                    _mm_cmpeq_epi8(v, _mm_set1_epi8(b'*' as i8)),
                );
                _mm_movemask_epi8(hit) as u32 as u64
            };
            mask |= bits << (16 * k);
        }
        mask
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        w.iter().enumerate().fold(0u64, |m, (k, &c)| {
            m | (((c == b',') | (c == b'*')) as u64) << k
        })
    }
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    use std::arch::x86_64::*;

    use super::MAX_SENTENCE;

    /// [`super::window_mask`] with two 32-byte compares.
    #[inline(always)]
    unsafe fn window_mask_avx2(w: &[u8; 64]) -> u64 {
        let mut mask = 0u64;
        for k in 0..2 {
            // SAFETY: bytes 32k..32k+32 of the 64-byte window; AVX2 is enabled
            // in the only caller.
            let v = _mm256_loadu_si256(w.as_ptr().add(32 * k).cast());
            let hit = _mm256_or_si256(
                _mm256_cmpeq_epi8(v, _mm256_set1_epi8(b',' as i8)),
                _mm256_cmpeq_epi8(v, _mm256_set1_epi8(b'*' as i8)),
            );
            mask |= (_mm256_movemask_epi8(hit) as u32 as u64) << (32 * k);
        }
        mask
    }

    #[target_feature(enable = "avx2")]
    pub(super) unsafe fn separators_avx2(b: &[u8], out: &mut [usize]) -> Option<()> {
        let mask = |w: &[u8; 64]| unsafe { window_mask_avx2(w) };
        separators_with!(b, out, mask)
    }
}

fn parse_uint(s: &[u8]) -> Option<u16> {
    if s.is_empty() || s.len() > 5 {
        return None;
    }
    let mut v: u32 = 0;
    for &c in s {
        if !c.is_ascii_digit() {
            return None;
        }
        v = v * 10 + (c - b'0') as u32;
    }
    u16::try_from(v).ok()
}

fn header_id(body: &[u8]) -> Option<&[u8]> {
    let h = body.get(..5)?;
    (h[0] == b'V'
        && h[1] == b'N'
        && h[2..].iter().all(|c| c.is_ascii_uppercase())
        && matches!(body.get(5), None | Some(b',')))
    .then_some(h)
}

/// Decode a checked body (`VNYMR,+1.0,...`, without `$` and `*hh`).
pub fn decode(body: &[u8]) -> Decoded {
    let Some(id) = header_id(body) else {
        return Decoded::Unknown;
    };
    let rest: &[u8] = if body.len() > 6 { &body[6..] } else { &[] };
    let has_fields = body.len() > 5;
    let mut fields = rest.split(|&c| c == b',');
    let spec = match &id[2..] {
        b"ERR" => {
            let code = if has_fields { fields.next() } else { None };
            return match (code.and_then(checksum::parse_hex), fields.next()) {
                (Some(c), None) if code.is_some_and(|f| f.len() <= 2) && is_defined_error(c) => {
                    Decoded::DeviceError(c)
                }
                _ => Decoded::Malformed(format!(
                    "VNERR carries no defined error code: {:?}",
                    String::from_utf8_lossy(rest)
                )),
            };
        }
        b"RRG" if has_fields => {
            let reg_field = fields.next().unwrap_or(b"");
            let Some(reg) = parse_uint(reg_field) else {
                return Decoded::Malformed(format!(
                    "VNRRG register number is not an integer: {:?}",
                    String::from_utf8_lossy(reg_field)
                ));
            };
            match spec_by_register(reg) {
                Some(spec) if rest.len() > reg_field.len() => spec,
                _ => return Decoded::Command("VNRRG"),
            }
        }
        _ => {
            if let Some(spec) = spec_by_id(id) {
                spec
            } else if let Some(command) = command_by_id(id) {
                return Decoded::Command(command);
            } else {
                return Decoded::Unknown;
            }
        }
    };
    if !has_fields {
        return Decoded::Malformed(format!("{} has no fields", spec.id));
    }
    let n = spec.fields.len();
    let mut values = [0.0f64; MAX_FIELDS];
    let mut count = None;
    let mut status = None;
    let mut k = 0usize;
    for field in fields {
        if k < n {
            match parse_f64(field) {
                Some(v) => values[k] = v,
                None => {
                    return Decoded::Malformed(format!(
                        "{} field {} ({}) is not a number: {:?}",
                        spec.id,
                        k + 1,
                        spec.fields[k],
                        String::from_utf8_lossy(field)
                    ))
                }
            }
        } else {
            // Appended fields (spec §2.5): T<decimal>, S<4 hex>, at most one each.
            let ok = match field.first() {
                Some(b'T') if count.is_none() => parse_f64(&field[1..]).map(|v| count = Some(v)),
                Some(b'S') if status.is_none() && field.len() == 5 => {
                    checksum::parse_hex(&field[1..]).map(|v| status = Some(v as f64))
                }
                _ => None,
            };
            if ok.is_none() {
                return Decoded::Malformed(format!(
                    "{} has {} or more fields; expected {} plus optional T/S fields, got {:?}",
                    spec.id,
                    k + 1,
                    n,
                    String::from_utf8_lossy(field)
                ));
            }
        }
        k += 1;
    }
    if k < n {
        return Decoded::Malformed(format!("{} has {} fields; expected {}", spec.id, k, n));
    }
    Decoded::Data {
        spec,
        values,
        count,
        status,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn data(body: &str) -> (&'static str, Vec<f64>, Option<f64>, Option<f64>) {
        match decode(body.as_bytes()) {
            Decoded::Data {
                spec,
                values,
                count,
                status,
            } => (spec.id, values[..spec.fields.len()].to_vec(), count, status),
            other => panic!("{body}: {other:?}"),
        }
    }

    #[test]
    fn a1_values() {
        let (id, v, c, s) = data("VNYMR,+100.949,-007.330,+000.715,-00.0049,-00.2449,+00.5397,-01.258,-00.100,-09.701,-00.000018,+00.001122,-00.000551");
        assert_eq!(id, "VNYMR");
        assert_eq!(v[0], 100.949);
        assert_eq!(v[1], -7.33);
        assert_eq!(v[5], 0.5397);
        assert_eq!(v[9], -0.000018);
        assert_eq!((c, s), (None, None));
    }

    #[test]
    fn appended_fields_and_registers() {
        let (_, _, c, s) = data("VNYPR,+010.071,+000.278,-002.026,T1162704");
        assert_eq!((c, s), (Some(1162704.0), None));
        let (_, _, c, s) = data("VNYPR,+010.071,+000.278,-002.026,S0010,T5");
        assert_eq!((c, s), (Some(5.0), Some(16.0)));
        let (id, v, _, _) = data("VNRRG,08,-114.314,+000.058,-001.773");
        assert_eq!((id, v[0]), ("VNYPR", -114.314));
        assert_eq!(decode(b"VNRRG,05,115200"), Decoded::Command("VNRRG"));
        assert_eq!(decode(b"VNRRG,8"), Decoded::Command("VNRRG"));
        assert_eq!(decode(b"VNWNV"), Decoded::Command("VNWNV"));
        assert_eq!(decode(b"VNERR,03"), Decoded::DeviceError(3));
        assert!(matches!(decode(b"VNERR,12"), Decoded::Malformed(_)));
        assert_eq!(decode(b"VNGPS,1,2"), Decoded::Unknown);
        assert!(matches!(decode(b"VNYPR,+1,+2"), Decoded::Malformed(_)));
        assert!(matches!(decode(b"VNYPR,+1,+2,3,4"), Decoded::Malformed(_)));
        assert!(matches!(decode(b"VNYPR,+1,+2,x"), Decoded::Malformed(_)));
        assert!(matches!(
            decode(b"VNMAR,1,2,3,4,5,6,-0.0.000840,1,2"),
            Decoded::Malformed(_)
        ));
    }

    #[test]
    fn fast_sentence_takes_the_common_case() {
        let a1 = b"$VNYMR,+100.949,-007.330,+000.715,-00.0049,-00.2449,+00.5397,-01.258,-00.100,-09.701,-00.000018,+00.001122,-00.000551*69\r\n";
        let (spec, v, star) = fast_sentence(a1, None, Level::Scalar).unwrap();
        assert_eq!((spec.id, star), ("VNYMR", a1.len() - 5));
        assert_eq!((v[0], v[1], v[9]), (100.949, -7.33, -0.000018));
        // Each of these leaves it to the general path.
        for s in [
            &b"$VNYMR,+100.949*69\r\n"[..],
            b"$VNYPR,+010.071,+000.278,-002.026,T1162704*2F\r\n",
            b"$VNYPR,+010.071,+000.278,-002.026*61\r\n",
            b"$VNYPR,+010.071,+000.278,-002.026*60",
            b"$VNYPR,+010.071,+000.278,-002.026*60A\r\n",
            b"$VNYPR,+010.071,+000.278,1e2*60\r\n",
            b"$VNRRG,08,-114.314,+000.058,-001.773*4F\r\n",
        ] {
            assert!(
                fast_sentence(s, None, Level::Scalar).is_none(),
                "{}",
                String::from_utf8_lossy(s)
            );
        }
        let ok = b"$VNYPR,+010.071,+000.278,-002.026*60\r\n";
        assert!(fast_sentence(ok, None, Level::Scalar).is_some());
    }
}
