//! Decimal numbers as VectorNav prints them (`+012.345`), correctly rounded.
//!
//! [`parse_f64`] takes any field; [`fast_number`] is the branch-light path for
//! plain numbers of at most 14 digits: eight bytes are loaded at once and their
//! digits found and combined with a few multiplications (SWAR, as in Lemire's
//! fast_float). Digits: both return the correctly rounded `f64` (an exact
//! integer divided by an exact power of ten is one rounding), bit-identical to
//! Python's `float()`. Cost: O(digits), about one 8-byte load per 7 digits on
//! the fast path.

/// Exact powers of ten (every one below 2^53 times a power of two).
pub(crate) const POW10: [f64; 23] = [
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
#[cfg(test)]
#[inline(always)]
pub(crate) fn fast_number(b: &[u8], j: &mut usize) -> Option<f64> {
    let (mant, frac, neg) = fast_digits(b, j)?;
    let v = mant as i64 as f64 / POW10[frac];
    Some(f64::from_bits(v.to_bits() | (neg as u64) << 63))
}

/// The pieces of [`fast_number`]'s value, `(mantissa, decimals, negative)`: the
/// value is `mantissa / 10^decimals` with the sign bit set when `negative`, so
/// that the divisions of a whole sentence can be made together ([`Quotients`]).
#[inline(always)]
pub(crate) fn fast_digits(b: &[u8], j: &mut usize) -> Option<(u64, usize, bool)> {
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
    Some((mant, frac, neg))
}

/// Up to [`LANES`] values `mantissa / 10^decimals`, sign bit or-ed in, divided
/// all at once (`divide`): a sentence's twelve divisions one after the other
/// were the parser's largest cost, and vector division is correctly rounded
/// like the scalar one, so every level gives the same bits.
pub(crate) struct Quotients {
    num: [f64; LANES],
    den: [f64; LANES],
    sign: [u64; LANES],
}

/// Values a [`Quotients`] holds (the most fields of a message).
pub(crate) const LANES: usize = crate::vn::messages::MAX_FIELDS;

impl Quotients {
    #[inline(always)]
    pub(crate) fn new() -> Quotients {
        Quotients {
            num: [0.0; LANES],
            den: [1.0; LANES],
            sign: [0; LANES],
        }
    }

    /// Lane `k` holds the value of [`fast_digits`]'s `(mant, frac, neg)`.
    #[inline(always)]
    pub(crate) fn set(&mut self, k: usize, (mant, frac, neg): (u64, usize, bool)) {
        // Below 2^53 the signed conversion is the same exact value, and one
        // instruction where the unsigned one takes several on x86-64.
        self.num[k] = mant as i64 as f64;
        self.den[k] = POW10[frac];
        self.sign[k] = (neg as u64) << 63;
    }

    /// Every lane's value (lanes never set are 0), at the instruction-set `level`.
    #[inline(always)]
    pub(crate) fn divide(&self, level: crate::simd::Level) -> [f64; LANES] {
        use crate::simd::Level;
        match level {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: the level is at most the CPU's (simd::level), which has AVX-512 F.
            Level::Avx512 | Level::Ifma => unsafe { x86::divide_avx512(self) },
            #[cfg(target_arch = "x86_64")]
            // SAFETY: as above, with AVX2.
            Level::Avx2 => unsafe { x86::divide_avx2(self) },
            _ => self.divide_scalar(),
        }
    }

    /// The portable path, one lane at a time (SSE2 pairs them).
    #[inline(always)]
    pub(crate) fn divide_scalar(&self) -> [f64; LANES] {
        std::array::from_fn(|k| {
            f64::from_bits((self.num[k] / self.den[k]).to_bits() | self.sign[k])
        })
    }
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    use std::arch::x86_64::*;

    use super::{Quotients, LANES};

    #[target_feature(enable = "avx512f")]
    pub(super) unsafe fn divide_avx512(q: &Quotients) -> [f64; LANES] {
        let mut out = [0.0f64; LANES];
        for k in (0..LANES).step_by(8) {
            // SAFETY: k + 8 <= LANES for every k of the loop (LANES is 16).
            let v = _mm512_div_pd(
                _mm512_loadu_pd(q.num.as_ptr().add(k)),
                _mm512_loadu_pd(q.den.as_ptr().add(k)),
            );
            let s = _mm512_loadu_si512(q.sign.as_ptr().add(k).cast());
            let v = _mm512_castsi512_pd(_mm512_or_si512(_mm512_castpd_si512(v), s));
            _mm512_storeu_pd(out.as_mut_ptr().add(k), v);
        }
        out
    }

    #[target_feature(enable = "avx2")]
    pub(super) unsafe fn divide_avx2(q: &Quotients) -> [f64; LANES] {
        let mut out = [0.0f64; LANES];
        for k in (0..LANES).step_by(4) {
            // SAFETY: k + 4 <= LANES for every k of the loop.
            let v = _mm256_div_pd(
                _mm256_loadu_pd(q.num.as_ptr().add(k)),
                _mm256_loadu_pd(q.den.as_ptr().add(k)),
            );
            let s = _mm256_loadu_si256(q.sign.as_ptr().add(k).cast());
            let v = _mm256_castsi256_pd(_mm256_or_si256(_mm256_castpd_si256(v), s));
            _mm256_storeu_pd(out.as_mut_ptr().add(k), v);
        }
        out
    }
}

const _: () = assert!(
    LANES.is_multiple_of(8),
    "the vector paths divide 8 lanes at a time"
);

#[cfg(test)]
mod tests {
    use super::*;

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
    fn quotients_are_the_same_bits_at_every_level() {
        let mut seed = 0x2545_F491_4F6C_DD1Du64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        let mut cases = Vec::new();
        for _ in 0..2000 {
            let mut q = Quotients::new();
            let mut want = [0.0f64; LANES];
            for (k, w) in want.iter_mut().enumerate().take((next() % 17) as usize) {
                // Up to 14 digits, 0..=7 of them decimals, either sign, zero too.
                let frac = (next() % 8) as usize;
                let digits = 1 + (next() % 14) as u32;
                let mant = next() % 10u64.pow(digits);
                let neg = next() % 2 == 1;
                q.set(k, (mant, frac, neg));
                let text = format!("{}{}e-{frac}", if neg { "-" } else { "" }, mant);
                *w = text.parse::<f64>().unwrap();
            }
            cases.push((q, want));
        }
        crate::simd::at_every_level(|level| {
            for (q, want) in &cases {
                let got = q.divide(level);
                for k in 0..LANES {
                    assert_eq!(got[k].to_bits(), want[k].to_bits(), "{level:?} lane {k}");
                }
                assert_eq!(got.map(f64::to_bits), q.divide_scalar().map(f64::to_bits));
            }
        });
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
