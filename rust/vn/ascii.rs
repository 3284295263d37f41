//! VN ASCII sentences: the message table (spec §3.1, §3.2) and field decoding.
//!
//! A sentence is `$VN<ID>,f1,...,fn[,T...][,S....]*hh` (spec §2). Framing and
//! checksums are handled by [`crate::vn::stream`]; this module turns the checked
//! body (the bytes between `$` and `*`) into values.

/// One asynchronous message type: header, backing register, field names in order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MsgSpec {
    /// Header without `$`, e.g. `"VNYMR"`.
    pub id: &'static str,
    /// The measurement register whose read response has the same fields (0 if none).
    pub register: u16,
    /// Async data output type (register 6 value).
    pub ador: u16,
    pub fields: &'static [&'static str],
}

macro_rules! xyz {
    ($p:literal) => {
        [concat!($p, "_x"), concat!($p, "_y"), concat!($p, "_z")]
    };
}

const fn cat<const A: usize, const B: usize, const C: usize>(
    a: [&'static str; A],
    b: [&'static str; B],
) -> [&'static str; C] {
    let mut out = [""; C];
    let mut i = 0;
    while i < A {
        out[i] = a[i];
        i += 1;
    }
    while i < C {
        out[i] = b[i - A];
        i += 1;
    }
    out
}

const YPR: [&str; 3] = ["yaw", "pitch", "roll"];
const QUAT: [&str; 4] = ["qx", "qy", "qz", "qw"];
const MAG: [&str; 3] = xyz!("mag");
const ACC: [&str; 3] = xyz!("accel");
const GYR: [&str; 3] = xyz!("gyro");
const MA: [&str; 6] = cat(MAG, ACC);
const MAR: [&str; 9] = cat(MA, GYR);
const YMR: [&str; 12] = cat(YPR, MAR);
const QMR: [&str; 13] = cat(QUAT, MAR);
const YBA: [&str; 9] = cat(cat::<3, 3, 6>(YPR, xyz!("lin_accel")), GYR);
const YIA: [&str; 9] = cat(
    cat::<3, 3, 6>(YPR, ["lin_accel_n", "lin_accel_e", "lin_accel_d"]),
    GYR,
);
const IMU: [&str; 11] = cat(MAR, ["temperature", "pressure"]);
const DTV: [&str; 7] = cat(
    cat::<1, 3, 4>(["delta_time"], xyz!("delta_theta")),
    xyz!("delta_vel"),
);
const HVE: [&str; 3] = ["heave", "heave_rate", "delayed_heave"];
const QTM: [&str; 7] = cat(QUAT, MAG);
const QTA: [&str; 7] = cat(QUAT, ACC);
const QTR: [&str; 7] = cat(QUAT, GYR);
const QMA: [&str; 10] = cat(QUAT, MA);
const QAR: [&str; 10] = cat(QUAT, cat::<3, 3, 6>(ACC, GYR));
const DCM: [&str; 9] = [
    "dcm_0", "dcm_1", "dcm_2", "dcm_3", "dcm_4", "dcm_5", "dcm_6", "dcm_7", "dcm_8",
];
const YCM: [&str; 13] = cat(YMR, ["temperature"]);
const ICM: [&str; 12] = cat(
    cat::<3, 3, 6>(YPR, MAG),
    cat::<3, 3, 6>(xyz!("inertial_accel"), GYR),
);
const RAW: [&str; 10] = cat(
    cat::<3, 3, 6>(xyz!("mag_volt"), xyz!("accel_volt")),
    cat::<3, 1, 4>(xyz!("gyro_volt"), ["temperature_volt"]),
);
const CMV: [&str; 10] = cat(MAR, ["temperature"]);
const STV: [&str; 7] = cat(QUAT, xyz!("gyro_bias"));
const COV: [&str; 6] = cat(xyz!("att_var"), xyz!("gyro_bias_var"));

/// Every decoded message type: spec tables 3.1 (current firmware) and 3.2 (legacy).
pub static MESSAGES: &[MsgSpec] = &[
    MsgSpec {
        id: "VNYPR",
        register: 8,
        ador: 1,
        fields: &YPR,
    },
    MsgSpec {
        id: "VNQTN",
        register: 9,
        ador: 2,
        fields: &QUAT,
    },
    MsgSpec {
        id: "VNQMR",
        register: 15,
        ador: 8,
        fields: &QMR,
    },
    MsgSpec {
        id: "VNMAG",
        register: 17,
        ador: 10,
        fields: &MAG,
    },
    MsgSpec {
        id: "VNACC",
        register: 18,
        ador: 11,
        fields: &ACC,
    },
    MsgSpec {
        id: "VNGYR",
        register: 19,
        ador: 12,
        fields: &GYR,
    },
    MsgSpec {
        id: "VNMAR",
        register: 20,
        ador: 13,
        fields: &MAR,
    },
    MsgSpec {
        id: "VNYMR",
        register: 27,
        ador: 14,
        fields: &YMR,
    },
    MsgSpec {
        id: "VNYBA",
        register: 239,
        ador: 16,
        fields: &YBA,
    },
    MsgSpec {
        id: "VNYIA",
        register: 240,
        ador: 17,
        fields: &YIA,
    },
    MsgSpec {
        id: "VNIMU",
        register: 54,
        ador: 19,
        fields: &IMU,
    },
    MsgSpec {
        id: "VNDTV",
        register: 80,
        ador: 30,
        fields: &DTV,
    },
    MsgSpec {
        id: "VNHVE",
        register: 115,
        ador: 34,
        fields: &HVE,
    },
    // Legacy / internal types (spec §3.2).
    MsgSpec {
        id: "VNQTM",
        register: 0,
        ador: 3,
        fields: &QTM,
    },
    MsgSpec {
        id: "VNQTA",
        register: 0,
        ador: 4,
        fields: &QTA,
    },
    MsgSpec {
        id: "VNQTR",
        register: 0,
        ador: 5,
        fields: &QTR,
    },
    MsgSpec {
        id: "VNQMA",
        register: 0,
        ador: 6,
        fields: &QMA,
    },
    MsgSpec {
        id: "VNQAR",
        register: 0,
        ador: 7,
        fields: &QAR,
    },
    MsgSpec {
        id: "VNDCM",
        register: 0,
        ador: 9,
        fields: &DCM,
    },
    MsgSpec {
        id: "VNYCM",
        register: 0,
        ador: 15,
        fields: &YCM,
    },
    MsgSpec {
        id: "VNICM",
        register: 0,
        ador: 18,
        fields: &ICM,
    },
    MsgSpec {
        id: "VNRAW",
        register: 0,
        ador: 252,
        fields: &RAW,
    },
    MsgSpec {
        id: "VNCMV",
        register: 0,
        ador: 253,
        fields: &CMV,
    },
    MsgSpec {
        id: "VNSTV",
        register: 0,
        ador: 254,
        fields: &STV,
    },
    MsgSpec {
        id: "VNCOV",
        register: 0,
        ador: 255,
        fields: &COV,
    },
];

/// Commands and their responses: well-formed, decoded as "seen" without a table.
const COMMANDS: &[&[u8]] = &[
    b"RRG", b"WRG", b"WNV", b"RFS", b"RST", b"TAR", b"KMD", b"KAD", b"SGB", b"ASY", b"BOM", b"FWU",
    b"CMD",
];

/// `$VNERR` codes defined by the manual (spec §4).
pub fn is_defined_error(code: u16) -> bool {
    (1..=0x0C).contains(&code) || code == 0xFF
}

pub fn spec_by_id(id: &[u8]) -> Option<&'static MsgSpec> {
    MESSAGES.iter().find(|m| m.id.as_bytes() == id)
}

fn spec_by_register(reg: u16) -> Option<&'static MsgSpec> {
    MESSAGES
        .iter()
        .find(|m| m.register == reg && m.register != 0)
}

/// Most fields any message has (13) plus slack.
pub const MAX_FIELDS: usize = 16;

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

const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// Parse a decimal number as VectorNav prints it (`+012.345`), correctly rounded.
///
/// Fast path: sign, digits, one dot, at most 15 significant digits — the value is
/// an exact integer divided by an exact power of ten, one correctly rounded
/// division, so the result equals Python's `float()`. Anything else goes through
/// the standard library parser; non-finite values are rejected.
#[inline]
pub fn parse_f64(s: &[u8]) -> Option<f64> {
    let (neg, digits) = match s.first() {
        Some(b'-') => (true, &s[1..]),
        Some(b'+') => (false, &s[1..]),
        _ => (false, s),
    };
    let n = digits.len();
    // At most 19 digits cannot overflow u64 (19 characters hold at most 19
    // digits); exactness is checked below.
    if n <= 19 {
        let mut mant: u64 = 0;
        let mut k = 0usize;
        while k < n && digits[k].is_ascii_digit() {
            mant = mant * 10 + (digits[k] - b'0') as u64;
            k += 1;
        }
        let int_digits = k;
        let mut frac = 0usize;
        if k < n && digits[k] == b'.' {
            k += 1;
            let from = k;
            while k < n && digits[k].is_ascii_digit() {
                mant = mant * 10 + (digits[k] - b'0') as u64;
                k += 1;
            }
            frac = k - from;
        }
        if k == n && int_digits + frac > 0 && mant <= (1u64 << 53) && frac < POW10.len() {
            // Exact integer / exact power of ten: one correctly rounded division.
            let v = mant as f64 / POW10[frac];
            return Some(if neg { -v } else { v });
        }
    }
    let text = std::str::from_utf8(s).ok()?;
    let first_ok = text
        .bytes()
        .all(|c| c.is_ascii_digit() || b"+-.eE".contains(&c));
    if !first_ok {
        return None;
    }
    let v: f64 = text.parse().ok()?;
    v.is_finite().then_some(v)
}

/// Largest mantissa for which `mant / 10^frac` is one correctly rounded division.
const EXACT_MANT: u64 = 1 << 53;

/// Eight bytes at `b[k..]`, little-endian (first byte lowest).
#[inline(always)]
fn load8(b: &[u8], k: usize) -> Option<u64> {
    let s: [u8; 8] = b.get(k..k + 8)?.try_into().ok()?;
    Some(u64::from_le_bytes(s))
}

/// Digit values of the bytes of `w` (byte − `'0'`) and how many of its first
/// bytes are decimal digits (0..=8), without a branch per byte.
#[inline(always)]
fn digit_run(w: u64) -> (u64, usize) {
    // x is 0..=9 in exactly the bytes that are '0'..='9'. A byte of x above 9
    // sets its high bit in x + 0x76 or in x; a carry out of such a byte only
    // disturbs later bytes, and only the first non-digit is wanted.
    let x = w ^ 0x3030_3030_3030_3030;
    let nondigit = (x.wrapping_add(0x7676_7676_7676_7676) | x) & 0x8080_8080_8080_8080;
    (x, (nondigit.trailing_zeros() / 8) as usize)
}

/// The value of the first `n` (1..=7) digit values of `x`, first most
/// significant: shifted to the top as if led by zeros, then combined pairwise
/// by multiplications (the eight-digit method of Lemire's fast_float).
#[inline(always)]
fn digits_value(x: u64, n: usize) -> u64 {
    if n == 0 {
        return 0;
    }
    let v = x << (8 * (8 - n));
    let v = v.wrapping_mul(10).wrapping_add(v >> 8);
    const MASK: u64 = 0x0000_00FF_0000_00FF;
    let v1 = (v & MASK).wrapping_mul(100 + (1_000_000 << 32));
    let v2 = ((v >> 16) & MASK).wrapping_mul(1 + (10_000 << 32));
    (v1.wrapping_add(v2) >> 32) as u32 as u64
}

const POW10_U64: [u64; 8] = [1, 10, 100, 1_000, 10_000, 100_000, 1_000_000, 10_000_000];

/// A plain decimal number at `b[*j..]`: `[+-]`, at most 7 digits, optionally
/// `.` and at most 7 digits, at least one digit in all; on success `*j` is the
/// first byte after it. At most 14 digits make a mantissa below 2^53, so the
/// value is one correctly rounded division, bit-identical to [`parse_f64`]
/// (whose fast path takes this grammar) and to Python's `float()`. `None`
/// for anything else, and near the end of `b` (8-byte loads).
#[inline(always)]
fn fast_number(b: &[u8], j: &mut usize) -> Option<f64> {
    // Signs are random in sensor data: no branch on them (a mispredicted
    // branch per field cost more than the rest of the field).
    let c = *b.get(*j)?;
    let neg = c == b'-';
    let mut k = *j + (neg | (c == b'+')) as usize;
    let (x, whole) = digit_run(load8(b, k)?);
    if whole == 8 {
        return None;
    }
    let mut mant = digits_value(x, whole);
    k += whole;
    let mut frac = 0usize;
    // `whole < 8`, so b[k] was loaded above and exists.
    if b.get(k) == Some(&b'.') {
        k += 1;
        let (y, n) = digit_run(load8(b, k)?);
        if n == 8 {
            return None;
        }
        mant = mant * POW10_U64[n] + digits_value(y, n);
        frac = n;
        k += n;
    }
    if whole + frac == 0 {
        return None;
    }
    debug_assert!(mant <= EXACT_MANT && frac < POW10.len());
    *j = k;
    let v = mant as f64 / POW10[frac];
    Some(f64::from_bits(v.to_bits() | (neg as u64) << 63))
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
    let mut values = [0.0f64; MAX_FIELDS];
    let n = spec.fields.len();
    let mut j = 7usize;
    for (k, v) in values.iter_mut().enumerate().take(n) {
        *v = fast_number(b, &mut j)?;
        let sep = *b.get(j)?;
        let want = if k + 1 == n { b'*' } else { b',' };
        if sep != want {
            return None;
        }
        j += 1;
    }
    let star = j - 1;
    // The scanner looks for '*' within MAX_SENTENCE bytes of '$'.
    if star >= crate::vn::stream::MAX_SENTENCE {
        return None;
    }
    // Two check digits, the byte after them, and one more (a possible LF after
    // CR) must be in the buffer, or the scanner would ask for more input.
    let field = b.get(star + 1..star + 5)?;
    let hex = |c: u8| crate::vn::checksum::parse_hex(&[c]);
    let check = (hex(field[0])? << 4) | hex(field[1])?;
    let x = crate::vn::checksum::xor8(&b[1..star]);
    if field[2].is_ascii_hexdigit() || field[2] == b'X' || check != x as u16 {
        return None;
    }
    Some((spec, values, star))
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
            return match (code.and_then(crate::vn::checksum::parse_hex), fields.next()) {
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
        other => {
            if let Some(spec) = spec_by_id(id) {
                spec
            } else if let Some(cmd) = COMMANDS.iter().find(|c| **c == other) {
                return Decoded::Command(match *cmd {
                    b"RRG" => "VNRRG",
                    b"WRG" => "VNWRG",
                    b"WNV" => "VNWNV",
                    b"RFS" => "VNRFS",
                    b"RST" => "VNRST",
                    b"TAR" => "VNTAR",
                    b"KMD" => "VNKMD",
                    b"KAD" => "VNKAD",
                    b"SGB" => "VNSGB",
                    b"ASY" => "VNASY",
                    b"BOM" => "VNBOM",
                    b"FWU" => "VNFWU",
                    _ => "VNCMD",
                });
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
                    crate::vn::checksum::parse_hex(&field[1..]).map(|v| status = Some(v as f64))
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
    fn field_counts_match_spec() {
        let expect = [
            ("VNYPR", 3),
            ("VNQTN", 4),
            ("VNQMR", 13),
            ("VNMAG", 3),
            ("VNACC", 3),
            ("VNGYR", 3),
            ("VNMAR", 9),
            ("VNYMR", 12),
            ("VNYBA", 9),
            ("VNYIA", 9),
            ("VNIMU", 11),
            ("VNDTV", 7),
            ("VNQTM", 7),
            ("VNQTA", 7),
            ("VNQTR", 7),
            ("VNQMA", 10),
            ("VNQAR", 10),
            ("VNDCM", 9),
            ("VNYCM", 13),
            ("VNICM", 12),
            ("VNRAW", 10),
            ("VNCMV", 10),
            ("VNSTV", 7),
            ("VNCOV", 6),
        ];
        for (id, n) in expect {
            assert_eq!(
                spec_by_id(id.as_bytes()).map(|s| s.fields.len()),
                Some(n),
                "{id}"
            );
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
        let (spec, v, star) = fast_sentence(a1, None).unwrap();
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
                fast_sentence(s, None).is_none(),
                "{}",
                String::from_utf8_lossy(s)
            );
        }
        let ok = b"$VNYPR,+010.071,+000.278,-002.026*60\r\n";
        assert!(fast_sentence(ok, None).is_some());
    }

    #[test]
    fn fast_number_matches_parse_f64() {
        let mut seed = 0x9E37_79B9_7F4A_7C15u64;
        let mut digit = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            b'0' + ((seed >> 33) % 10) as u8
        };
        let mut taken = 0;
        for sign in ["", "+", "-"] {
            for whole in 0..=9usize {
                for frac in 0..=9usize {
                    for dot in [false, true] {
                        for _ in 0..40 {
                            let mut t = sign.as_bytes().to_vec();
                            t.extend((0..whole).map(|_| digit()));
                            if dot {
                                t.push(b'.');
                                t.extend((0..frac).map(|_| digit()));
                            }
                            let len = t.len();
                            t.extend_from_slice(b",+1.0*00\r\n-----");
                            let mut j = 0;
                            match fast_number(&t, &mut j) {
                                Some(v) => {
                                    taken += 1;
                                    assert_eq!(j, len);
                                    let want = parse_f64(&t[..len]).unwrap();
                                    assert_eq!(v.to_bits(), want.to_bits(), "{t:?}");
                                }
                                None => assert!(
                                    whole >= 8
                                        || (dot && frac >= 8)
                                        || whole + frac * dot as usize == 0,
                                    "{t:?}"
                                ),
                            }
                        }
                    }
                }
            }
        }
        assert!(taken > 10_000);
    }

    #[test]
    fn floats_match_std() {
        for s in [
            "+100.949",
            "-00.000018",
            "0",
            "-0.0",
            "+084.322",
            "1e3",
            "12345678901234567.5",
            // 20 digits would wrap a u64 mantissa: must not come out as 1.0.
            "18446744073709551617",
            "+1844674407370955161.7",
            "9007199254740993",
            "0.1234567890123456789",
        ] {
            let want: f64 = s.parse().unwrap();
            assert_eq!(parse_f64(s.as_bytes()), Some(want), "{s}");
        }
        for s in ["", "+", ".", "-.", "1..2", "nan", "inf", "1,2", "0x1"] {
            assert_eq!(parse_f64(s.as_bytes()), None, "{s}");
        }
    }
}
