//! Sentences laid out like one seen before. The VN-100 prints every field of a
//! message at a fixed width (`+012.345`), so the byte classes of a sentence
//! (exact characters, digits, signs) nearly always repeat those of the last
//! sentence of its type. A [`Shape`] learnt from a sentence that
//! [`crate::vn::ascii::fast_sentence`] accepted checks a new sentence's first
//! [`WINDOW`] bytes against those classes, its XOR-8 checksum and its numbers
//! in vector registers (AVX2, AVX-512 BW), with no search for separators or
//! digit runs.
//!
//! A sentence a shape accepts has, up to its check digits, the byte classes of
//! one `fast_sentence` accepted, so `fast_sentence` accepts it too, with the
//! same fields and digits: the values are the same bits (an exact mantissa
//! below 2^53 divided by an exact power of ten, one correctly rounded
//! division). Anything a shape rejects goes to `fast_sentence`. Below AVX2
//! there are no shapes (the scalar level is the reference path).
//!
//! Cost: two (AVX-512) or four (AVX2) 64/32-byte windows compared, plus one
//! byte permute (VBMI, at the IFMA level) or four loads and a shuffle, and four
//! multiply-adds, per four (AVX2: two) fields.

use crate::simd::Level;
use crate::vn::messages::{MsgSpec, MAX_FIELDS};
use crate::vn::number::POW10;

/// Bytes of a sentence a shape covers, from `$` on: the `*`, its two check
/// digits and the byte after them must lie inside.
pub(crate) const WINDOW: usize = 128;

/// The byte classes and field layout of one sentence (see the module text).
pub(crate) struct Shape {
    pub(crate) spec: &'static MsgSpec,
    /// Offset of the `*`.
    pub(crate) star: usize,
    /// The bytes at the exact positions (0 elsewhere).
    template: [u8; WINDOW],
    /// Bit p: byte p must equal `template[p]`, be a digit, be `+` or `-`.
    exact: u128,
    digit: u128,
    sign: u128,
    /// 0xFF on the bytes the checksum covers (between `$` and `*`).
    body: [u8; WINDOW],
    /// First byte of each field (0 for lanes past the message's fields).
    start: [u32; MAX_FIELDS],
    /// Per field, the byte shuffle that moves its digits, right-aligned, into
    /// 16 bytes loaded from `start` (0x80: a zero byte).
    shuffle: [[u8; 16]; MAX_FIELDS],
    /// Per field, 10^(digits after the dot).
    den: [f64; MAX_FIELDS],
    /// The same digits as window offsets, four fields per 64 bytes (for a
    /// two-register byte permute), and which of those bytes are digits.
    gather: [[u8; 64]; MAX_FIELDS / 4],
    gathered: [u64; MAX_FIELDS / 4],
    /// Bit k: field k starts with a sign.
    signed: u32,
}

impl Shape {
    /// The shape of `b`, a sentence of `spec` with its `*` at `star` that
    /// `fast_sentence` accepted; `None` below AVX2, or when the sentence does
    /// not fit the window.
    pub(crate) fn learn(
        b: &[u8],
        spec: &'static MsgSpec,
        star: usize,
        level: Level,
    ) -> Option<Shape> {
        if level < Level::Avx2 || !cfg!(target_arch = "x86_64") {
            return None;
        }
        if star + 5 > WINDOW || b.len() < WINDOW {
            return None;
        }
        let mut s = Shape {
            spec,
            star,
            template: [0; WINDOW],
            exact: 0,
            digit: 0,
            sign: 0,
            body: [0; WINDOW],
            start: [0; MAX_FIELDS],
            shuffle: [[0x80; 16]; MAX_FIELDS],
            den: [1.0; MAX_FIELDS],
            gather: [[0; 64]; MAX_FIELDS / 4],
            gathered: [0; MAX_FIELDS / 4],
            signed: 0,
        };
        // The header `$VNxxx,` is exact: a digit class there would let another
        // message type through.
        for (p, &c) in b.iter().enumerate().take(star + 1) {
            let bit = 1u128 << p;
            if p >= 7 && p < star && c.is_ascii_digit() {
                s.digit |= bit;
            } else if p >= 7 && p < star && (c == b'+' || c == b'-') {
                s.sign |= bit;
            } else {
                s.exact |= bit;
                s.template[p] = c;
            }
            if p >= 1 && p < star {
                s.body[p] = 0xFF;
            }
        }
        let n = spec.fields.len();
        let mut k = 0;
        let mut from = 7;
        for p in 7..=star {
            if b[p] != b',' && b[p] != b'*' {
                continue;
            }
            let field = &b[from..p];
            if k >= n || field.len() > 16 || from + 16 > WINDOW {
                return None;
            }
            let digits = field.iter().filter(|c| c.is_ascii_digit()).count();
            let frac = field
                .iter()
                .position(|&c| c == b'.')
                .map_or(0, |d| field.len() - d - 1);
            let mut slot = 16 - digits.min(16);
            for (q, c) in field.iter().enumerate() {
                if c.is_ascii_digit() {
                    s.shuffle[k][slot] = q as u8;
                    s.gather[k / 4][16 * (k % 4) + slot] = (from + q) as u8;
                    s.gathered[k / 4] |= 1 << (16 * (k % 4) + slot);
                    slot += 1;
                }
            }
            s.start[k] = from as u32;
            s.signed |= (((s.sign >> from) & 1) as u32) << k;
            s.den[k] = *POW10.get(frac)?;
            k += 1;
            from = p + 1;
        }
        (k == n).then_some(s)
    }

    /// Writes the values of the sentence at `b[0] == b'$'` at `out` (lanes
    /// past the message's fields too) if it has this shape and a matching
    /// XOR-8 checksum (the conditions of `fast_sentence`); `false` with nothing
    /// written otherwise.
    ///
    /// # Safety
    /// `out` is valid for writes of [`MAX_FIELDS`] values.
    #[inline]
    pub(crate) unsafe fn parse_into(&self, b: &[u8], level: Level, out: *mut f64) -> bool {
        if b.len() < WINDOW {
            return false;
        }
        #[cfg(target_arch = "x86_64")]
        match level {
            // SAFETY: the level is at most the CPU's (simd::level), which then
            // has AVX-512 F, DQ, BW and VBMI and BMI2; `b` holds the WINDOW bytes
            // read; `out` as the caller promises.
            Level::Ifma => unsafe { x86::parse_vbmi(self, b, out) },
            // SAFETY: as above, with AVX-512 F, DQ and BW.
            Level::Avx512 => unsafe { x86::parse_avx512(self, b, out) },
            // SAFETY: as above, with AVX2.
            Level::Avx2 => unsafe { x86::parse_avx2(self, b, out) },
            Level::Scalar => false,
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            let _ = (level, out);
            false
        }
    }

    /// [`Shape::parse_into`] into an array.
    #[cfg(test)]
    pub(crate) fn parse(&self, b: &[u8], level: Level) -> Option<[f64; MAX_FIELDS]> {
        let mut out = [0.0; MAX_FIELDS];
        // SAFETY: `out` holds MAX_FIELDS values.
        unsafe { self.parse_into(b, level, out.as_mut_ptr()) }.then_some(out)
    }

    /// Whether the check field after the `*` holds the two hex digits of `x`
    /// and is followed by a byte that is no check character (as in
    /// `fast_sentence`).
    #[inline(always)]
    fn check_ok(&self, b: &[u8], x: u8) -> bool {
        let hex = |c: u8| HEX[c as usize];
        let (hi, lo, after) = (
            hex(b[self.star + 1]),
            hex(b[self.star + 2]),
            b[self.star + 3],
        );
        (hi | lo) < 16 && (hi << 4 | lo) == x && hex(after) >= 16 && after != b'X'
    }
}

/// Hex digit values (either case); 0xFF for other bytes.
static HEX: [u8; 256] = {
    let mut t = [0xFFu8; 256];
    let mut c = 0;
    while c < 256 {
        t[c] = match c as u8 {
            b'0'..=b'9' => c as u8 - b'0',
            b'a'..=b'f' => c as u8 - b'a' + 10,
            b'A'..=b'F' => c as u8 - b'A' + 10,
            _ => 0xFF,
        };
        c += 1;
    }
    t
};

/// The bytes of a 64-bit word XOR-ed together.
#[inline(always)]
fn fold_bytes(x: u64) -> u8 {
    let x = x ^ (x >> 32);
    let x = x ^ (x >> 16);
    (x ^ (x >> 8)) as u8
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    use std::arch::x86_64::*;

    use super::{fold_bytes, Shape, MAX_FIELDS};

    /// Bits 0, 16, 32 and 48 of `m` as bits 0..4 (each product term lands on
    /// its own bit, so no carries reach bits 48..52).
    #[inline(always)]
    fn lane_bits(m: u64) -> u32 {
        const GATHER: u64 = (1 << 48) | (1 << 33) | (1 << 18) | (1 << 3);
        (((m & 0x0001_0001_0001_0001).wrapping_mul(GATHER) >> 48) & 0xF) as u32
    }

    /// The XOR of a 512-bit register's eight 64-bit words.
    #[target_feature(enable = "avx512f,avx512dq,avx512bw")]
    #[inline]
    unsafe fn fold_words(x: __m512i) -> u64 {
        let x = _mm256_xor_si256(_mm512_castsi512_si256(x), _mm512_extracti64x4_epi64(x, 1));
        let x = _mm_xor_si128(_mm256_castsi256_si128(x), _mm256_extracti128_si256(x, 1));
        _mm_cvtsi128_si64(x) as u64 ^ _mm_extract_epi64(x, 1) as u64
    }

    /// Each 128-bit lane's 16 digit values (most significant first) as one u64 in
    /// the lane's low word: pairs, fours, eights, then the two eights.
    #[target_feature(enable = "avx512f,avx512dq,avx512bw")]
    #[inline]
    unsafe fn mantissas(digits: __m512i) -> __m512i {
        let v = _mm512_maddubs_epi16(digits, _mm512_set1_epi16(0x010A));
        let v = _mm512_madd_epi16(v, _mm512_set1_epi32(0x0001_0064));
        let v = _mm512_packus_epi32(v, v);
        let v = _mm512_madd_epi16(v, _mm512_set1_epi32(0x0001_2710));
        let hi = _mm512_mul_epu32(v, _mm512_set1_epi64(100_000_000));
        _mm512_add_epi64(hi, _mm512_srli_epi64(v, 32))
    }

    /// The `n` fields' values, mantissa over the shape's denominator with the
    /// sign bit of each field set in `neg`, stored at `out`.
    #[target_feature(enable = "avx512f,avx512dq,avx512bw")]
    #[inline]
    unsafe fn store_values(s: &Shape, mant: &[__m512i], neg: u32, n: usize, out: *mut f64) {
        // Each 128-bit lane holds its field's mantissa in its low word.
        let pick = _mm512_set_epi64(14, 12, 10, 8, 6, 4, 2, 0);
        let sign = _mm512_set1_epi64(i64::MIN);
        for h in 0..n.div_ceil(8) {
            let m = _mm512_permutex2var_epi64(mant[2 * h], pick, mant[2 * h + 1]);
            let v = _mm512_div_pd(
                _mm512_cvtepu64_pd(m),
                _mm512_loadu_pd(s.den.as_ptr().add(8 * h)),
            );
            let v = _mm512_castpd_si512(v);
            let v = _mm512_mask_or_epi64(v, (neg >> (8 * h)) as u8, v, sign);
            // SAFETY: 8h + 8 <= MAX_FIELDS values at `out` (the caller's promise).
            _mm512_storeu_pd(out.add(8 * h), _mm512_castsi512_pd(v));
        }
    }

    #[target_feature(enable = "avx512f,avx512dq,avx512bw")]
    pub(super) unsafe fn parse_avx512(s: &Shape, b: &[u8], out: *mut f64) -> bool {
        let p = b.as_ptr();
        // SAFETY (all loads): b holds WINDOW = 128 bytes (the caller checks), and
        // every field's 16 bytes lie inside them (Shape::learn).
        let c = [
            _mm512_loadu_si512(p.cast()),
            _mm512_loadu_si512(p.add(64).cast()),
        ];
        let (zero, nine) = (_mm512_set1_epi8(b'0' as i8), _mm512_set1_epi8(9));
        let (plus, minus) = (_mm512_set1_epi8(b'+' as i8), _mm512_set1_epi8(b'-' as i8));
        let (mut e, mut d, mut g) = (0u128, 0u128, 0u128);
        let mut x = _mm512_setzero_si512();
        for (h, &v) in c.iter().enumerate() {
            let t = _mm512_loadu_si512(s.template.as_ptr().add(64 * h).cast());
            e |= (_mm512_cmpeq_epi8_mask(v, t) as u128) << (64 * h);
            let z = _mm512_sub_epi8(v, zero);
            d |= (_mm512_cmple_epu8_mask(z, nine) as u128) << (64 * h);
            let sg = _mm512_cmpeq_epi8_mask(v, plus) | _mm512_cmpeq_epi8_mask(v, minus);
            g |= (sg as u128) << (64 * h);
            let m = _mm512_loadu_si512(s.body.as_ptr().add(64 * h).cast());
            x = _mm512_xor_si512(x, _mm512_and_si512(v, m));
        }
        if (e & s.exact != s.exact) | (d & s.digit != s.digit) | (g & s.sign != s.sign) {
            return false;
        }
        if !s.check_ok(b, fold_bytes(fold_words(x))) {
            return false;
        }
        let n = s.spec.fields.len();
        let mut mant = [_mm512_setzero_si512(); MAX_FIELDS / 4];
        let mut neg = 0u32;
        for (q, m) in mant.iter_mut().enumerate().take(n.div_ceil(4)) {
            let f = 4 * q;
            let ld = |k: usize| _mm_loadu_si128(p.add(s.start[k] as usize).cast());
            let v = _mm512_castsi128_si512(ld(f));
            let v = _mm512_inserti32x4::<1>(v, ld(f + 1));
            let v = _mm512_inserti32x4::<2>(v, ld(f + 2));
            let v = _mm512_inserti32x4::<3>(v, ld(f + 3));
            neg |= lane_bits(_mm512_cmpeq_epi8_mask(v, minus)) << f;
            let ctrl = _mm512_loadu_si512(s.shuffle[f].as_ptr().cast());
            let digits = _mm512_shuffle_epi8(_mm512_sub_epi8(v, zero), ctrl);
            *m = mantissas(digits);
        }
        store_values(s, &mant, neg, n, out);
        true
    }

    /// [`parse_avx512`] with every field's digits gathered from the two window
    /// registers by one byte permute per four fields, and the signs by bit
    /// extraction from the window's `-` mask.
    #[target_feature(enable = "avx512f,avx512dq,avx512bw,avx512vbmi,bmi2")]
    pub(super) unsafe fn parse_vbmi(s: &Shape, b: &[u8], out: *mut f64) -> bool {
        let p = b.as_ptr();
        // SAFETY (all loads): b holds WINDOW = 128 bytes (the caller checks).
        let c = [
            _mm512_loadu_si512(p.cast()),
            _mm512_loadu_si512(p.add(64).cast()),
        ];
        let (zero, nine) = (_mm512_set1_epi8(b'0' as i8), _mm512_set1_epi8(9));
        let (plus, minus) = (_mm512_set1_epi8(b'+' as i8), _mm512_set1_epi8(b'-' as i8));
        let (mut e, mut d, mut g, mut m) = (0u128, 0u128, 0u128, [0u64; 2]);
        let mut x = _mm512_setzero_si512();
        let mut z = [_mm512_setzero_si512(); 2];
        for (h, &v) in c.iter().enumerate() {
            let t = _mm512_loadu_si512(s.template.as_ptr().add(64 * h).cast());
            e |= (_mm512_cmpeq_epi8_mask(v, t) as u128) << (64 * h);
            z[h] = _mm512_sub_epi8(v, zero);
            d |= (_mm512_cmple_epu8_mask(z[h], nine) as u128) << (64 * h);
            m[h] = _mm512_cmpeq_epi8_mask(v, minus);
            g |= ((_mm512_cmpeq_epi8_mask(v, plus) | m[h]) as u128) << (64 * h);
            let body = _mm512_loadu_si512(s.body.as_ptr().add(64 * h).cast());
            x = _mm512_xor_si512(x, _mm512_and_si512(v, body));
        }
        if (e & s.exact != s.exact) | (d & s.digit != s.digit) | (g & s.sign != s.sign) {
            return false;
        }
        if !s.check_ok(b, fold_bytes(fold_words(x))) {
            return false;
        }
        // The signed fields' `-` bits, in field order, then spread to the fields.
        let (lo, hi) = (s.sign as u64, (s.sign >> 64) as u64);
        let packed = _pext_u64(m[0], lo) | (_pext_u64(m[1], hi) << (lo.count_ones() & 63));
        let neg = _pdep_u32(packed as u32, s.signed);
        let n = s.spec.fields.len();
        let mut mant = [_mm512_setzero_si512(); MAX_FIELDS / 4];
        for (q, mq) in mant.iter_mut().enumerate().take(n.div_ceil(4)) {
            let idx = _mm512_loadu_si512(s.gather[q].as_ptr().cast());
            let digits = _mm512_maskz_permutex2var_epi8(s.gathered[q], z[0], idx, z[1]);
            *mq = mantissas(digits);
        }
        store_values(s, &mant, neg, n, out);
        true
    }

    #[target_feature(enable = "avx2")]
    pub(super) unsafe fn parse_avx2(s: &Shape, b: &[u8], out: *mut f64) -> bool {
        let p = b.as_ptr();
        let (zero, nine) = (_mm256_set1_epi8(b'0' as i8), _mm256_set1_epi8(9));
        let (plus, minus) = (_mm256_set1_epi8(b'+' as i8), _mm256_set1_epi8(b'-' as i8));
        let (mut e, mut d, mut g) = (0u128, 0u128, 0u128);
        let mut x = _mm256_setzero_si256();
        let bits = |m: __m256i| _mm256_movemask_epi8(m) as u32 as u128;
        for h in 0..4 {
            // SAFETY (all loads): as in parse_avx512.
            let v = _mm256_loadu_si256(p.add(32 * h).cast());
            let t = _mm256_loadu_si256(s.template.as_ptr().add(32 * h).cast());
            e |= bits(_mm256_cmpeq_epi8(v, t)) << (32 * h);
            let z = _mm256_sub_epi8(v, zero);
            d |= bits(_mm256_cmpeq_epi8(_mm256_min_epu8(z, nine), z)) << (32 * h);
            let sg = _mm256_or_si256(_mm256_cmpeq_epi8(v, plus), _mm256_cmpeq_epi8(v, minus));
            g |= bits(sg) << (32 * h);
            let m = _mm256_loadu_si256(s.body.as_ptr().add(32 * h).cast());
            x = _mm256_xor_si256(x, _mm256_and_si256(v, m));
        }
        if (e & s.exact != s.exact) | (d & s.digit != s.digit) | (g & s.sign != s.sign) {
            return false;
        }
        let x = _mm_xor_si128(_mm256_castsi256_si128(x), _mm256_extracti128_si256(x, 1));
        let x = _mm_cvtsi128_si64(x) as u64 ^ _mm_extract_epi64(x, 1) as u64;
        if !s.check_ok(b, fold_bytes(x)) {
            return false;
        }
        let n = s.spec.fields.len();
        let mut mant = [_mm256_setzero_si256(); MAX_FIELDS / 2];
        let mut neg = 0u32;
        for (q, m) in mant.iter_mut().enumerate().take(n.div_ceil(2)) {
            let f = 2 * q;
            let ld = |k: usize| _mm_loadu_si128(p.add(s.start[k] as usize).cast());
            let v = _mm256_inserti128_si256::<1>(_mm256_castsi128_si256(ld(f)), ld(f + 1));
            let signs = _mm256_movemask_epi8(_mm256_cmpeq_epi8(v, minus)) as u32;
            neg |= ((signs & 1) | ((signs >> 15) & 2)) << f;
            let ctrl = _mm256_loadu_si256(s.shuffle[f].as_ptr().cast());
            let digits = _mm256_shuffle_epi8(_mm256_sub_epi8(v, zero), ctrl);
            let v = _mm256_maddubs_epi16(digits, _mm256_set1_epi16(0x010A));
            let v = _mm256_madd_epi16(v, _mm256_set1_epi32(0x0001_0064));
            let v = _mm256_packus_epi32(v, v);
            let v = _mm256_madd_epi16(v, _mm256_set1_epi32(0x0001_2710));
            let hi = _mm256_mul_epu32(v, _mm256_set1_epi64x(100_000_000));
            *m = _mm256_add_epi64(hi, _mm256_srli_epi64(v, 32));
        }
        // Below 2^52 a mantissa is exact as the low bits of 2^52's significand.
        let magic = _mm256_set1_epi64x(0x4330_0000_0000_0000);
        let two52 = _mm256_set1_pd(4_503_599_627_370_496.0);
        let lane = _mm256_set_epi64x(8, 4, 2, 1);
        let sign = _mm256_set1_epi64x(i64::MIN);
        for h in 0..n.div_ceil(4) {
            // Words 0 and 2 hold the two fields of a register.
            let m = _mm256_unpacklo_epi64(mant[2 * h], mant[2 * h + 1]);
            let m = _mm256_permute4x64_epi64::<0xD8>(m);
            let v = _mm256_sub_pd(_mm256_castsi256_pd(_mm256_or_si256(m, magic)), two52);
            let v = _mm256_div_pd(v, _mm256_loadu_pd(s.den.as_ptr().add(4 * h)));
            let k = _mm256_set1_epi64x(((neg >> (4 * h)) & 0xF) as i64);
            let k = _mm256_cmpeq_epi64(_mm256_and_si256(k, lane), lane);
            let v = _mm256_or_si256(_mm256_castpd_si256(v), _mm256_and_si256(k, sign));
            // SAFETY: 4h + 4 <= MAX_FIELDS values at `out` (the caller's promise).
            _mm256_storeu_pd(out.add(4 * h), _mm256_castsi256_pd(v));
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vn::ascii::fast_sentence;
    use crate::vn::checksum::xor8;
    use crate::vn::messages::spec_by_id;

    /// A `$VNYMR` sentence of the sensor's widths, digits and signs from `seed`.
    fn ymr(seed: u64) -> Vec<u8> {
        let mut r = seed | 1;
        let mut next = move || {
            r ^= r << 13;
            r ^= r >> 7;
            r ^= r << 17;
            r
        };
        let mut body = "VNYMR".to_string();
        for (whole, frac) in [(3, 3), (3, 3), (3, 3), (2, 4), (2, 4), (2, 4)]
            .into_iter()
            .chain([(2, 3); 3])
            .chain([(2, 6); 3])
        {
            body.push(',');
            body.push(if next() % 2 == 0 { '+' } else { '-' });
            for k in 0..whole + frac {
                if k == whole {
                    body.push('.');
                }
                body.push((b'0' + (next() % 10) as u8) as char);
            }
        }
        let x = xor8(body.as_bytes());
        format!("${body}*{x:02X}\r\n$VNYMR,+000.000").into_bytes()
    }

    /// Whether the shape's answer for `b` is the fast path's (a shape may
    /// decline what the fast path takes, never the reverse).
    fn agrees(shape: &Shape, b: &[u8], level: Level) -> bool {
        let fast = fast_sentence(b, None, level);
        match shape.parse(b, level) {
            None => true,
            Some(v) => fast.is_some_and(|(spec, want, star)| {
                let n = spec.fields.len();
                spec.id == shape.spec.id
                    && star == shape.star
                    && v[..n]
                        .iter()
                        .zip(&want[..n])
                        .all(|(a, b)| a.to_bits() == b.to_bits())
            }),
        }
    }

    #[test]
    fn a_shape_takes_sentences_like_its_own_and_nothing_else() {
        let spec = spec_by_id(b"VNYMR").unwrap();
        crate::simd::at_every_level(|level| {
            let first = ymr(1);
            let star = first.iter().position(|&c| c == b'*').unwrap();
            let Some(shape) = Shape::learn(&first, spec, star, level) else {
                assert_eq!(level, Level::Scalar);
                return;
            };
            for seed in 2..300 {
                let s = ymr(seed);
                // Clean sentences of the same widths: all taken, same bits.
                assert!(shape.parse(&s, level).is_some(), "{level:?} {seed}");
                assert!(agrees(&shape, &s, level), "{level:?} {seed}");
                if seed > 40 {
                    continue;
                }
                // Every byte up to the one after the check digits replaced.
                for p in 0..star + 4 {
                    for c in *b"$*,.+-09aAXx\r\n \0\xff" {
                        let mut t = s.clone();
                        t[p] = c;
                        assert!(agrees(&shape, &t, level), "{level:?} {seed} {p} {c}");
                    }
                }
                // Cut short of the window: declined.
                assert!(shape.parse(&s[..WINDOW - 1], level).is_none());
            }
        });
    }
}
