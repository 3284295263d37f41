//! Exact integer sums held as three signed 52-bit limbs, v = l₀ + l₁·2⁵² + l₂·2¹⁰⁴,
//! each limb in its own `i64` array, so that the products of non-negative
//! integers below 2⁵² are added to l₀ and l₁ as two parts of at most 52 bits:
//!
//! - with AVX-512 IFMA ([`Level::Ifma`]), eight lanes at a time, as the low and
//!   high 52 bits of the product (p mod 2⁵², ⌊p/2⁵²⌋), and one lane at a time,
//!   the same two integers by a 128-bit product, in the portable kernels;
//! - with AVX2 and FMA ([`Level::Avx2`], [`Level::Avx512`]), four lanes at a
//!   time in double precision, exactly: the factors (below 2⁵³) are exact
//!   doubles; `fma(a, b, 2¹⁰⁴)` rounds 2¹⁰⁴ + p once to a multiple of 2⁵², so
//!   its mantissa field is H = p/2⁵² rounded to nearest; and p − H·2⁵², an
//!   integer in [−2⁵¹, 2⁵¹], is exact in a second FMA. H goes to l₁ and the
//!   signed remainder to l₀ (see `x86::two_product`).
//!
//! Limbs are redundant between normalisations: a lane may hold more than 52 bits
//! in l₀ and l₁, and l₀ may be negative (each product adds less than 2⁵² in
//! magnitude to both), which is exact as long as no limb leaves ±2⁶³;
//! [`Limbs::normalise`] carries them back to [0, 2⁵²). The two schemes give the
//! same integer in different redundant limbs, so readers join the limbs exactly
//! ([`Limbs::get`], [`Limbs::normalise`], [`weighted_terms`]) and never read l₀
//! or l₁ alone.
//!
//! Every kernel gives the same result on every [`Level`]: the integer kernels are
//! exact, and [`weighted_terms`] rounds in the same order on every path (scalar,
//! AVX2, AVX-512).

use crate::simd::{self, Level};

/// Bits of one limb.
const LIMB_BITS: u32 = 52;
const MASK: i64 = (1 << LIMB_BITS) - 1;
/// 2⁵² and 2¹⁰⁴ as f64.
const LIMB_1: f64 = 4503599627370496.0;
const LIMB_2: f64 = LIMB_1 * LIMB_1;

/// Terms summed side by side in [`weighted_terms`]: one accumulator per lane of
/// an AVX-512 register, and the same eight in the scalar kernel, so that both
/// round alike.
const LANES: usize = 8;

/// Largest factor a product may have: below 2⁵², where IFMA reads its inputs.
pub const MAX_FACTOR: i64 = MASK;

/// An array of exact integers in limbs.
pub struct Limbs {
    pub l0: Vec<i64>,
    pub l1: Vec<i64>,
    pub l2: Vec<i64>,
}

/// v as normalised limbs (l₀, l₁ in [0, 2⁵²)).
pub fn split(v: i128) -> [i64; 3] {
    [
        (v as i64) & MASK,
        ((v >> LIMB_BITS) as i64) & MASK,
        (v >> (2 * LIMB_BITS)) as i64,
    ]
}

/// The integer of (possibly redundant) limbs.
pub fn join(l: [i64; 3]) -> i128 {
    l[0] as i128 + ((l[1] as i128) << LIMB_BITS) + ((l[2] as i128) << (2 * LIMB_BITS))
}

/// Limbs carried: l₀, l₁ in [0, 2⁵²), the rest in l₂.
#[inline(always)]
fn carry(l: [i64; 3]) -> [i64; 3] {
    let c0 = l[0] >> LIMB_BITS;
    let l1 = l[1] + c0;
    [l[0] & MASK, l1 & MASK, l[2] + (l1 >> LIMB_BITS)]
}

/// A non-negative integer in limbs as f64 (within 1 ulp); NaN when negative,
/// which only a failed computation gives.
#[inline(always)]
fn to_f64(l: [i64; 3]) -> f64 {
    let [a, b, c] = carry(l);
    if c < 0 {
        return f64::NAN;
    }
    c as f64 * LIMB_2 + (b as f64 * LIMB_1 + a as f64)
}

impl Limbs {
    pub fn from_values(values: impl ExactSizeIterator<Item = i128>) -> Self {
        let n = values.len();
        let mut out = Limbs {
            l0: Vec::with_capacity(n),
            l1: Vec::with_capacity(n),
            l2: Vec::with_capacity(n),
        };
        for v in values {
            let [a, b, c] = split(v);
            out.l0.push(a);
            out.l1.push(b);
            out.l2.push(c);
        }
        out
    }

    pub fn len(&self) -> usize {
        self.l0.len()
    }

    pub fn is_empty(&self) -> bool {
        self.l0.is_empty()
    }

    /// The integer at `i`.
    pub fn get(&self, i: usize) -> i128 {
        join([self.l0[i], self.l1[i], self.l2[i]])
    }

    /// Adds a·b (0 ≤ a, b ≤ [`MAX_FACTOR`]) at `i`.
    #[inline(always)]
    pub fn add_product(&mut self, i: usize, a: i64, b: i64) {
        let p = a as u128 * b as u128;
        self.l0[i] += (p as i64) & MASK;
        self.l1[i] += (p >> LIMB_BITS) as i64;
    }

    /// Carries every lane back to l₀, l₁ < 2⁵².
    pub fn normalise(&mut self) {
        for ((a, b), c) in self.l0.iter_mut().zip(&mut self.l1).zip(&mut self.l2) {
            [*a, *b, *c] = carry([*a, *b, *c]);
        }
    }
}

/// For every lane i of `lo`, `hi` (the l₀, l₁ of one range of [`Limbs`]):
/// adds Σ_r s_r·x_r[i], where `rows` holds R pairs (s_r, x_r), x_r at least as
/// long as the range; every factor in [0, [`MAX_FACTOR`]].
pub fn add_scaled_rows<const R: usize>(lo: &mut [i64], hi: &mut [i64], rows: [(i64, &[i64]); R]) {
    #[cfg(target_arch = "x86_64")]
    if ifma() {
        // SAFETY: the CPU has the features the kernel is compiled for, and it
        // reads x_r[..lo.len()] only (asserted inside).
        unsafe { x86::scaled_rows(lo, hi, rows) };
        return;
    }
    #[cfg(target_arch = "x86_64")]
    if avx2() {
        // SAFETY: as above.
        unsafe { x86::scaled_rows_avx2(lo, hi, rows) };
        return;
    }
    scaled_rows_scalar(lo, hi, rows, 0);
}

/// For every lane i: adds Σ_r a_r[i]·b_r[i] (factors in [0, [`MAX_FACTOR`]]).
pub fn add_pair_products<const R: usize>(
    lo: &mut [i64],
    hi: &mut [i64],
    pairs: [(&[i64], &[i64]); R],
) {
    #[cfg(target_arch = "x86_64")]
    if ifma() {
        // SAFETY: as above.
        unsafe { x86::pair_products(lo, hi, pairs) };
        return;
    }
    #[cfg(target_arch = "x86_64")]
    if avx2() {
        // SAFETY: as above.
        unsafe { x86::pair_products_avx2(lo, hi, pairs) };
        return;
    }
    pair_products_scalar(lo, hi, pairs, 0);
}

/// Σ a[i]·b[i] exactly, over the shorter length (factors in [0, [`MAX_FACTOR`]]).
pub fn dot(a: &[i64], b: &[i64]) -> i128 {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    #[cfg(target_arch = "x86_64")]
    if ifma() {
        // SAFETY: the CPU has the features; the slices have equal lengths.
        return unsafe { x86::dot(a, b) };
    }
    #[cfg(target_arch = "x86_64")]
    if avx2() {
        // SAFETY: as above.
        return unsafe { x86::dot_avx2(a, b) };
    }
    dot_scalar(a, b, 0)
}

fn dot_scalar(a: &[i64], b: &[i64], from: usize) -> i128 {
    a[from..]
        .iter()
        .zip(&b[from..])
        .map(|(&x, &y)| x as i128 * y as i128)
        .sum()
}

/// The three limb arrays of one range (a view into [`Limbs`]).
#[derive(Clone, Copy)]
pub struct LimbSlice<'a> {
    pub l0: &'a [i64],
    pub l1: &'a [i64],
    pub l2: &'a [i64],
}

impl<'a> LimbSlice<'a> {
    pub fn range(&self, range: std::ops::Range<usize>) -> LimbSlice<'a> {
        LimbSlice {
            l0: &self.l0[range.clone()],
            l1: &self.l1[range.clone()],
            l2: &self.l2[range],
        }
    }
}

impl Limbs {
    pub fn slice(&self, range: std::ops::Range<usize>) -> LimbSlice<'_> {
        LimbSlice {
            l0: &self.l0[range.clone()],
            l1: &self.l1[range.clone()],
            l2: &self.l2[range],
        }
    }
}

/// Σ_u w[h−1−u]·(f + a[u] + b[h−1−u] − 2c[u]) over u < h = a.len(), each term
/// the exact integer rounded once (NaN if a term is negative). a, b, c and w
/// have length h; every limb of a, b, c below 2⁶⁰ in magnitude.
///
/// The rounding order is part of the result: term u goes to accumulator
/// u mod [`LANES`] while whole groups of eight remain, the accumulators are
/// added in order, and the remaining terms one by one.
pub fn weighted_terms(f: [i64; 3], a: LimbSlice, b: LimbSlice, c: LimbSlice, w: &[f64]) -> f64 {
    #[cfg(target_arch = "x86_64")]
    if avx512() {
        // SAFETY: the CPU has the features; lengths are asserted inside.
        return unsafe { x86::weighted_terms(f, a, b, c, w) };
    }
    #[cfg(target_arch = "x86_64")]
    if avx2() {
        // SAFETY: as above.
        return unsafe { x86::weighted_terms_avx2(f, a, b, c, w) };
    }
    weighted_terms_scalar(f, a, b, c, w)
}

fn scaled_rows_scalar<const R: usize>(
    lo: &mut [i64],
    hi: &mut [i64],
    rows: [(i64, &[i64]); R],
    from: usize,
) {
    for i in from..lo.len() {
        for &(s, x) in &rows {
            let p = s as u128 * x[i] as u128;
            lo[i] += (p as i64) & MASK;
            hi[i] += (p >> LIMB_BITS) as i64;
        }
    }
}

fn pair_products_scalar<const R: usize>(
    lo: &mut [i64],
    hi: &mut [i64],
    pairs: [(&[i64], &[i64]); R],
    from: usize,
) {
    for i in from..lo.len() {
        for &(a, b) in &pairs {
            let p = a[i] as u128 * b[i] as u128;
            lo[i] += (p as i64) & MASK;
            hi[i] += (p >> LIMB_BITS) as i64;
        }
    }
}

/// Term u of [`weighted_terms`], rounded once, times its weight.
#[inline(always)]
fn weighted_term(
    f: [i64; 3],
    a: LimbSlice,
    b: LimbSlice,
    c: LimbSlice,
    w: &[f64],
    u: usize,
) -> f64 {
    let v = a.l0.len() - 1 - u;
    let t = [
        f[0] + a.l0[u] + b.l0[v] - 2 * c.l0[u],
        f[1] + a.l1[u] + b.l1[v] - 2 * c.l1[u],
        f[2] + a.l2[u] + b.l2[v] - 2 * c.l2[u],
    ];
    to_f64(t) * w[v]
}

fn weighted_terms_scalar(f: [i64; 3], a: LimbSlice, b: LimbSlice, c: LimbSlice, w: &[f64]) -> f64 {
    let h = a.l0.len();
    let body = h - h % LANES;
    let mut lanes = [0.0f64; LANES];
    for group in (0..body).step_by(LANES) {
        for (lane, acc) in lanes.iter_mut().enumerate() {
            *acc += weighted_term(f, a, b, c, w, group + lane);
        }
    }
    weighted_tail(f, a, b, c, w, body, lanes)
}

/// The accumulators added in lane order, then the terms from `from` on.
fn weighted_tail(
    f: [i64; 3],
    a: LimbSlice,
    b: LimbSlice,
    c: LimbSlice,
    w: &[f64],
    from: usize,
    lanes: [f64; LANES],
) -> f64 {
    let mut total = lanes.iter().fold(0.0, |s, x| s + x);
    for u in from..a.l0.len() {
        total += weighted_term(f, a, b, c, w, u);
    }
    total
}

#[cfg(target_arch = "x86_64")]
fn ifma() -> bool {
    simd::level() >= Level::Ifma
}

#[cfg(target_arch = "x86_64")]
fn avx2() -> bool {
    simd::level() >= Level::Avx2
}

#[cfg(target_arch = "x86_64")]
fn avx512() -> bool {
    simd::level() >= Level::Avx512
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    use std::arch::x86_64::*;

    use super::*;

    #[target_feature(enable = "avx512f,avx512ifma")]
    pub unsafe fn scaled_rows<const R: usize>(
        lo: &mut [i64],
        hi: &mut [i64],
        rows: [(i64, &[i64]); R],
    ) {
        let n = lo.len();
        assert!(hi.len() == n && rows.iter().all(|(_, x)| x.len() >= n));
        let scale: [__m512i; R] = std::array::from_fn(|r| _mm512_set1_epi64(rows[r].0));
        let mut i = 0;
        while i + 8 <= n {
            // Two chains per limb, so that IFMA's latency overlaps.
            let mut l = _mm512_loadu_si512(lo.as_ptr().add(i).cast());
            let mut h = _mm512_loadu_si512(hi.as_ptr().add(i).cast());
            let mut l2 = _mm512_setzero_si512();
            let mut h2 = _mm512_setzero_si512();
            for r in 0..R {
                let x = _mm512_loadu_si512(rows[r].1.as_ptr().add(i).cast());
                if r % 2 == 0 {
                    l = _mm512_madd52lo_epu64(l, scale[r], x);
                    h = _mm512_madd52hi_epu64(h, scale[r], x);
                } else {
                    l2 = _mm512_madd52lo_epu64(l2, scale[r], x);
                    h2 = _mm512_madd52hi_epu64(h2, scale[r], x);
                }
            }
            _mm512_storeu_si512(lo.as_mut_ptr().add(i).cast(), _mm512_add_epi64(l, l2));
            _mm512_storeu_si512(hi.as_mut_ptr().add(i).cast(), _mm512_add_epi64(h, h2));
            i += 8;
        }
        scaled_rows_scalar(lo, hi, rows, i);
    }

    #[target_feature(enable = "avx512f,avx512ifma")]
    pub unsafe fn pair_products<const R: usize>(
        lo: &mut [i64],
        hi: &mut [i64],
        pairs: [(&[i64], &[i64]); R],
    ) {
        let n = lo.len();
        assert!(hi.len() == n && pairs.iter().all(|(a, b)| a.len() >= n && b.len() >= n));
        let mut i = 0;
        while i + 8 <= n {
            let mut l = _mm512_loadu_si512(lo.as_ptr().add(i).cast());
            let mut h = _mm512_loadu_si512(hi.as_ptr().add(i).cast());
            for (a, b) in pairs {
                let x = _mm512_loadu_si512(a.as_ptr().add(i).cast());
                let y = _mm512_loadu_si512(b.as_ptr().add(i).cast());
                l = _mm512_madd52lo_epu64(l, x, y);
                h = _mm512_madd52hi_epu64(h, x, y);
            }
            _mm512_storeu_si512(lo.as_mut_ptr().add(i).cast(), l);
            _mm512_storeu_si512(hi.as_mut_ptr().add(i).cast(), h);
            i += 8;
        }
        pair_products_scalar(lo, hi, pairs, i);
    }

    /// Eight lanes of low and high halves, folded into an i128 every 1024 steps
    /// (each adds below 2⁵² to a lane).
    #[target_feature(enable = "avx512f,avx512ifma")]
    pub unsafe fn dot(a: &[i64], b: &[i64]) -> i128 {
        let n = a.len();
        assert!(b.len() == n);
        let mut total: i128 = 0;
        let mut i = 0;
        while i + 8 <= n {
            let stop = (i + 8 * 1024).min(n - n % 8);
            let (mut l, mut h) = (_mm512_setzero_si512(), _mm512_setzero_si512());
            while i < stop {
                let x = _mm512_loadu_si512(a.as_ptr().add(i).cast());
                let y = _mm512_loadu_si512(b.as_ptr().add(i).cast());
                l = _mm512_madd52lo_epu64(l, x, y);
                h = _mm512_madd52hi_epu64(h, x, y);
                i += 8;
            }
            let (mut lo, mut hi) = ([0u64; 8], [0u64; 8]);
            _mm512_storeu_si512(lo.as_mut_ptr().cast(), l);
            _mm512_storeu_si512(hi.as_mut_ptr().cast(), h);
            for k in 0..8 {
                total += lo[k] as i128 + ((hi[k] as i128) << LIMB_BITS);
            }
        }
        total + dot_scalar(a, b, i)
    }

    /// 2¹⁰⁴: in its binade [2¹⁰⁴, 2¹⁰⁵) the ulp is 2⁵², and a double's bits are
    /// bits(2¹⁰⁴) + v/2⁵².
    const TOP: f64 = LIMB_2;
    /// 1.5·2⁵²: for an integer v in [−2⁵¹, 2⁵¹], v + ROUND lies in [2⁵², 2⁵³]
    /// (ulp 1, so exact) and its bits are bits(ROUND) + v (2⁵³ included).
    const ROUND: f64 = 1.5 * LIMB_1;

    /// An integer in [0, 2⁵²) as a double, exactly: it is the mantissa of 2⁵² + x.
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn to_double(x: __m256i) -> __m256d {
        let one = _mm256_set1_pd(LIMB_1);
        let biased = _mm256_or_si256(x, _mm256_castpd_si256(one));
        _mm256_sub_pd(_mm256_castsi256_pd(biased), one)
    }

    /// The exact product p = a·b of integers a, b in [0, 2⁵²) as two integers
    /// of at most 52 bits, p = H·2⁵² + L, given doubles x, y and an addend k
    /// with x·y + k = 2¹⁰⁴ + p exactly and k − 2¹⁰⁴ a multiple of 2⁵² below 2¹⁰⁵
    /// in magnitude (x = a, y = b, k = 2¹⁰⁴; or x = 2⁵² + a, y = b,
    /// k = 2¹⁰⁴ − b·2⁵²). Returned as bit patterns: bits(2¹⁰⁴) + H and
    /// bits(1.5·2⁵²) + L, to be added as integers and the biases taken out once.
    ///
    /// Exactness (round to nearest, the default mode): 2¹⁰⁴ + p lies in
    /// [2¹⁰⁴, 2¹⁰⁵) (p ≤ (2⁵² − 1)² rounds below 2¹⁰⁴ − 2⁵²), so the first FMA
    /// rounds it once to 2¹⁰⁴ + H·2⁵² with H = p/2⁵² to nearest, in [0, 2⁵²),
    /// the mantissa field. k − big = (k − 2¹⁰⁴) − H·2⁵² is a multiple of 2⁵² below
    /// 2¹⁰⁵ (53 significant bits at most), so exact; the second FMA's exact value
    /// x·y + k − big = p − H·2⁵² = L is an integer in [−2⁵¹, 2⁵¹], so exact; and
    /// L + 1.5·2⁵² is exact in [2⁵², 2⁵³].
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn two_product(x: __m256d, y: __m256d, k: __m256d) -> (__m256i, __m256i) {
        let big = _mm256_fmadd_pd(x, y, k);
        let low = _mm256_fmadd_pd(x, y, _mm256_sub_pd(k, big));
        let low = _mm256_add_pd(low, _mm256_set1_pd(ROUND));
        (_mm256_castpd_si256(big), _mm256_castpd_si256(low))
    }

    /// The biases of `count` results of [`two_product`] added together (as
    /// wrapping integers: the unbiased sums fit in an i64).
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn biases(count: i64) -> (__m256i, __m256i) {
        let bias = |v: f64| _mm256_set1_epi64x(count.wrapping_mul(v.to_bits() as i64));
        (bias(ROUND), bias(TOP))
    }

    #[target_feature(enable = "avx2,fma")]
    pub unsafe fn scaled_rows_avx2<const R: usize>(
        lo: &mut [i64],
        hi: &mut [i64],
        rows: [(i64, &[i64]); R],
    ) {
        let n = lo.len();
        assert!(hi.len() == n && rows.iter().all(|(_, x)| x.len() >= n));
        // x enters as 2⁵² + x (its bits under 2⁵²'s exponent, one OR), and the
        // addend 2¹⁰⁴ − s·2⁵² = (2⁵² − s)·2⁵² (exact) takes the extra s·2⁵² out.
        let scale: [__m256d; R] = std::array::from_fn(|r| _mm256_set1_pd(rows[r].0 as f64));
        let addend: [__m256d; R] = std::array::from_fn(|r| {
            _mm256_set1_pd(((1i64 << LIMB_BITS) - rows[r].0) as f64 * LIMB_1)
        });
        let exponent = _mm256_castpd_si256(_mm256_set1_pd(LIMB_1));
        let (bias_lo, bias_hi) = biases(R as i64);
        let mut i = 0;
        while i + 4 <= n {
            let mut l = _mm256_loadu_si256(lo.as_ptr().add(i).cast());
            let mut h = _mm256_loadu_si256(hi.as_ptr().add(i).cast());
            for r in 0..R {
                let x = _mm256_loadu_si256(rows[r].1.as_ptr().add(i).cast());
                let x = _mm256_castsi256_pd(_mm256_or_si256(x, exponent));
                let (high, low) = two_product(x, scale[r], addend[r]);
                l = _mm256_add_epi64(l, low);
                h = _mm256_add_epi64(h, high);
            }
            let l = _mm256_sub_epi64(l, bias_lo);
            let h = _mm256_sub_epi64(h, bias_hi);
            _mm256_storeu_si256(lo.as_mut_ptr().add(i).cast(), l);
            _mm256_storeu_si256(hi.as_mut_ptr().add(i).cast(), h);
            i += 4;
        }
        scaled_rows_scalar(lo, hi, rows, i);
    }

    #[target_feature(enable = "avx2,fma")]
    pub unsafe fn pair_products_avx2<const R: usize>(
        lo: &mut [i64],
        hi: &mut [i64],
        pairs: [(&[i64], &[i64]); R],
    ) {
        let n = lo.len();
        assert!(hi.len() == n && pairs.iter().all(|(a, b)| a.len() >= n && b.len() >= n));
        let top = _mm256_set1_pd(TOP);
        let (bias_lo, bias_hi) = biases(R as i64);
        let mut i = 0;
        while i + 4 <= n {
            let mut l = _mm256_loadu_si256(lo.as_ptr().add(i).cast());
            let mut h = _mm256_loadu_si256(hi.as_ptr().add(i).cast());
            for (a, b) in pairs {
                let x = to_double(_mm256_loadu_si256(a.as_ptr().add(i).cast()));
                let y = to_double(_mm256_loadu_si256(b.as_ptr().add(i).cast()));
                let (high, low) = two_product(x, y, top);
                l = _mm256_add_epi64(l, low);
                h = _mm256_add_epi64(h, high);
            }
            let l = _mm256_sub_epi64(l, bias_lo);
            let h = _mm256_sub_epi64(h, bias_hi);
            _mm256_storeu_si256(lo.as_mut_ptr().add(i).cast(), l);
            _mm256_storeu_si256(hi.as_mut_ptr().add(i).cast(), h);
            i += 4;
        }
        pair_products_scalar(lo, hi, pairs, i);
    }

    /// Four lanes of the two parts, folded into an i128 every 1024 steps (each
    /// adds less than 2⁵² in magnitude to a lane).
    #[target_feature(enable = "avx2,fma")]
    pub unsafe fn dot_avx2(a: &[i64], b: &[i64]) -> i128 {
        let n = a.len();
        assert!(b.len() == n);
        let top = _mm256_set1_pd(TOP);
        let mut total: i128 = 0;
        let mut i = 0;
        while i + 4 <= n {
            let stop = (i + 4 * 1024).min(n - n % 4);
            let (bias_lo, bias_hi) = biases(((stop - i) / 4) as i64);
            let (mut l, mut h) = (_mm256_setzero_si256(), _mm256_setzero_si256());
            while i < stop {
                let x = to_double(_mm256_loadu_si256(a.as_ptr().add(i).cast()));
                let y = to_double(_mm256_loadu_si256(b.as_ptr().add(i).cast()));
                let (high, low) = two_product(x, y, top);
                l = _mm256_add_epi64(l, low);
                h = _mm256_add_epi64(h, high);
                i += 4;
            }
            let (mut lo, mut hi) = ([0i64; 4], [0i64; 4]);
            _mm256_storeu_si256(lo.as_mut_ptr().cast(), _mm256_sub_epi64(l, bias_lo));
            _mm256_storeu_si256(hi.as_mut_ptr().cast(), _mm256_sub_epi64(h, bias_hi));
            for k in 0..4 {
                total += lo[k] as i128 + ((hi[k] as i128) << LIMB_BITS);
            }
        }
        total + dot_scalar(a, b, i)
    }

    /// The scalar kernel's operations, four terms at a time, its eight
    /// accumulators in two vectors. AVX2 has no 64-bit arithmetic shift nor
    /// conversion to double: the shift is a logical one between two flips of
    /// the sign, the carried l₀, l₁ (in [0, 2⁵²)) convert as mantissas, and l₂
    /// as the mantissa of 1.5·2⁵² + l₂, exact for l₂ in [0, 2⁵¹); outside that
    /// (a negative term, or one beyond 2¹⁵⁵, which the sweep never makes) the
    /// scalar kernel gives the result.
    #[target_feature(enable = "avx2,fma")]
    pub unsafe fn weighted_terms_avx2(
        f: [i64; 3],
        a: LimbSlice,
        b: LimbSlice,
        c: LimbSlice,
        w: &[f64],
    ) -> f64 {
        let h = a.l0.len();
        for s in [a, b, c] {
            assert!(s.l0.len() == h && s.l1.len() == h && s.l2.len() == h);
        }
        assert!(w.len() == h);
        const REVERSE: i32 = 0b00_01_10_11;
        let mask = _mm256_set1_epi64x(MASK);
        let fv = f.map(|v| _mm256_set1_epi64x(v));
        let (one, two) = (_mm256_set1_pd(LIMB_1), _mm256_set1_pd(LIMB_2));
        let round = _mm256_set1_pd(ROUND);
        let top_limit = _mm256_set1_epi64x((1 << 51) - 1);
        let zero = _mm256_setzero_si256();
        let mut acc = [_mm256_setzero_pd(); 2];
        let mut outside = _mm256_setzero_si256();
        // x >> 52, arithmetic (macros, not closures: the intrinsics inline into
        // this function's features).
        macro_rules! shift {
            ($x:expr) => {{
                let x = $x;
                let sign = _mm256_cmpgt_epi64(zero, x);
                _mm256_xor_si256(_mm256_srli_epi64::<52>(_mm256_xor_si256(x, sign)), sign)
            }};
        }
        // An integer t in [0, 2⁵²) under base's exponent, as a double.
        macro_rules! to_f64 {
            ($t:expr, $base:expr) => {{
                let biased = _mm256_add_epi64($t, _mm256_castpd_si256($base));
                _mm256_sub_pd(_mm256_castsi256_pd(biased), $base)
            }};
        }
        // One limb of four terms u..u + 4: f + a[u..] + b[v + 3 − j] − 2·c[u..].
        macro_rules! limb {
            ($k:expr, $sa:expr, $sb:expr, $sc:expr, $u:expr, $v:expr) => {{
                let bv = _mm256_permute4x64_epi64::<REVERSE>(_mm256_loadu_si256(
                    $sb.as_ptr().add($v).cast(),
                ));
                let av = _mm256_loadu_si256($sa.as_ptr().add($u).cast());
                let cv = _mm256_loadu_si256($sc.as_ptr().add($u).cast());
                _mm256_sub_epi64(
                    _mm256_add_epi64(_mm256_add_epi64(fv[$k], av), bv),
                    _mm256_add_epi64(cv, cv),
                )
            }};
        }
        let mut u = 0;
        while u + 8 <= h {
            for (half, acc) in acc.iter_mut().enumerate() {
                let u = u + 4 * half;
                let v = h - 4 - u; // b and w run backwards: lanes v + 3 … v
                let t0 = limb!(0, a.l0, b.l0, c.l0, u, v);
                let t1 = limb!(1, a.l1, b.l1, c.l1, u, v);
                let t2 = limb!(2, a.l2, b.l2, c.l2, u, v);
                let t1 = _mm256_add_epi64(t1, shift!(t0));
                let t0 = _mm256_and_si256(t0, mask);
                let t2 = _mm256_add_epi64(t2, shift!(t1));
                let t1 = _mm256_and_si256(t1, mask);
                // Negative (sign bit) or above the exact conversion's range.
                outside = _mm256_or_si256(
                    outside,
                    _mm256_or_si256(t2, _mm256_cmpgt_epi64(t2, top_limit)),
                );
                let value = _mm256_add_pd(
                    _mm256_mul_pd(to_f64!(t2, round), two),
                    _mm256_add_pd(_mm256_mul_pd(to_f64!(t1, one), one), to_f64!(t0, one)),
                );
                let wv = _mm256_permute4x64_pd::<REVERSE>(_mm256_loadu_pd(w.as_ptr().add(v)));
                *acc = _mm256_add_pd(*acc, _mm256_mul_pd(value, wv));
            }
            u += 8;
        }
        if _mm256_movemask_pd(_mm256_castsi256_pd(outside)) != 0 {
            return weighted_terms_scalar(f, a, b, c, w);
        }
        let mut lanes = [0.0f64; LANES];
        _mm256_storeu_pd(lanes.as_mut_ptr(), acc[0]);
        _mm256_storeu_pd(lanes.as_mut_ptr().add(4), acc[1]);
        weighted_tail(f, a, b, c, w, u, lanes)
    }

    #[target_feature(enable = "avx512f,avx512dq")]
    pub unsafe fn weighted_terms(
        f: [i64; 3],
        a: LimbSlice,
        b: LimbSlice,
        c: LimbSlice,
        w: &[f64],
    ) -> f64 {
        let h = a.l0.len();
        for s in [a, b, c] {
            assert!(s.l0.len() == h && s.l1.len() == h && s.l2.len() == h);
        }
        assert!(w.len() == h);
        let reverse = _mm512_set_epi64(0, 1, 2, 3, 4, 5, 6, 7);
        let mask = _mm512_set1_epi64(MASK);
        let fv = f.map(|v| _mm512_set1_epi64(v));
        let (one, two) = (_mm512_set1_pd(LIMB_1), _mm512_set1_pd(LIMB_2));
        let mut acc = _mm512_setzero_pd();
        let mut lowest = _mm512_setzero_si512();
        // One limb of eight terms: f + a[u..] + reversed b[v..] − 2·c[u..].
        macro_rules! limb {
            ($k:expr, $sa:expr, $sb:expr, $sc:expr, $u:expr, $v:expr) => {{
                let bv = _mm512_permutexvar_epi64(
                    reverse,
                    _mm512_loadu_si512($sb.as_ptr().add($v).cast()),
                );
                let av = _mm512_loadu_si512($sa.as_ptr().add($u).cast());
                let cv = _mm512_loadu_si512($sc.as_ptr().add($u).cast());
                _mm512_sub_epi64(
                    _mm512_add_epi64(_mm512_add_epi64(fv[$k], av), bv),
                    _mm512_add_epi64(cv, cv),
                )
            }};
        }
        let mut u = 0;
        while u + 8 <= h {
            let v = h - 8 - u; // b and w run backwards: lanes v + 7 … v
            let t0 = limb!(0, a.l0, b.l0, c.l0, u, v);
            let t1 = limb!(1, a.l1, b.l1, c.l1, u, v);
            let t2 = limb!(2, a.l2, b.l2, c.l2, u, v);
            // Carry: t0, t1 into [0, 2⁵²), the rest into t2.
            let t1 = _mm512_add_epi64(t1, _mm512_srai_epi64::<52>(t0));
            let t0 = _mm512_and_si512(t0, mask);
            let t2 = _mm512_add_epi64(t2, _mm512_srai_epi64::<52>(t1));
            let t1 = _mm512_and_si512(t1, mask);
            lowest = _mm512_min_epi64(lowest, t2);
            // The scalar kernel's operations, unfused: c·2¹⁰⁴ + (b·2⁵² + a), then
            // one product and one sum per lane.
            let value = _mm512_add_pd(
                _mm512_mul_pd(_mm512_cvtepi64_pd(t2), two),
                _mm512_add_pd(
                    _mm512_mul_pd(_mm512_cvtepi64_pd(t1), one),
                    _mm512_cvtepi64_pd(t0),
                ),
            );
            let wv = _mm512_permutexvar_pd(reverse, _mm512_loadu_pd(w.as_ptr().add(v)));
            acc = _mm512_add_pd(acc, _mm512_mul_pd(value, wv));
            u += 8;
        }
        if _mm512_reduce_min_epi64(lowest) < 0 {
            return f64::NAN;
        }
        let mut lanes = [0.0f64; LANES];
        _mm512_storeu_pd(lanes.as_mut_ptr(), acc);
        weighted_tail(f, a, b, c, w, u, lanes)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pseudo(n: usize, seed: u64, bits: u32) -> Vec<i64> {
        let mut s = seed;
        (0..n)
            .map(|_| {
                s = s
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                ((s >> 11) & ((1 << bits) - 1)) as i64
            })
            .collect()
    }

    #[test]
    fn split_and_join_round_trip() {
        for v in [0i128, 1, -1, 1 << 52, -(1 << 110) + 12345, (1 << 120) - 7] {
            assert_eq!(join(split(v)), v);
            let l = split(v);
            assert!((0..1 << 52).contains(&l[0]) && (0..1 << 52).contains(&l[1]));
        }
    }

    #[test]
    fn kernels_add_exact_products() {
        // 37 lanes: eight-lane blocks and a scalar tail.
        let n = 37;
        let x: Vec<Vec<i64>> = (0..4).map(|s| pseudo(n, s, 51)).collect();
        let start: Vec<i128> = pseudo(n, 9, 60)
            .iter()
            .map(|&v| (v as i128) << 50)
            .collect();
        let mut limbs = Limbs::from_values(start.iter().copied());
        let s = [(1i64 << 51) - 3, 12345, MAX_FACTOR, 0];
        add_scaled_rows(
            &mut limbs.l0,
            &mut limbs.l1,
            [
                (s[0], &x[0][..]),
                (s[1], &x[1]),
                (s[2], &x[2]),
                (s[3], &x[3]),
            ],
        );
        add_pair_products(&mut limbs.l0, &mut limbs.l1, [(&x[0][..], &x[1][..])]);
        // The portable kernels (what a CPU without IFMA runs) give the same limbs.
        let mut portable = Limbs::from_values(start.iter().copied());
        scaled_rows_scalar(
            &mut portable.l0,
            &mut portable.l1,
            [
                (s[0], &x[0][..]),
                (s[1], &x[1]),
                (s[2], &x[2]),
                (s[3], &x[3]),
            ],
            0,
        );
        pair_products_scalar(
            &mut portable.l0,
            &mut portable.l1,
            [(&x[0][..], &x[1][..])],
            0,
        );
        // Paths may leave different redundant limbs: compare them normalised.
        limbs.normalise();
        portable.normalise();
        assert_eq!((&portable.l0, &portable.l1), (&limbs.l0, &limbs.l1));
        assert_eq!(&portable.l2, &limbs.l2);
        for i in 0..n {
            let want = start[i]
                + (0..4).map(|r| s[r] as i128 * x[r][i] as i128).sum::<i128>()
                + x[0][i] as i128 * x[1][i] as i128;
            assert_eq!(limbs.get(i), want, "lane {i}");
        }
    }

    /// Factors below 2⁵² with the extremes 0 and [`MAX_FACTOR`] at some lanes.
    fn factors(n: usize, seed: u64) -> Vec<i64> {
        let mut x = pseudo(n, seed, LIMB_BITS);
        for (i, v) in x.iter_mut().enumerate() {
            match (i as u64 + seed) % 7 {
                0 => *v = MAX_FACTOR,
                3 => *v = 0,
                _ => {}
            }
        }
        x
    }

    /// Lengths covering empty, tail-only, whole vectors (4 and 8 lanes) and tails.
    const LENGTHS: [usize; 14] = [0, 1, 3, 4, 5, 7, 8, 9, 11, 12, 15, 16, 17, 37];

    /// Start values of both signs, normalised.
    fn start(n: usize, seed: u64) -> Vec<i128> {
        pseudo(n, seed, 62)
            .iter()
            .map(|&v| ((v as i128) << 48) - (1 << 109))
            .collect()
    }

    /// Checks the limbs against the exact sums, joined as they are and then
    /// normalised.
    fn check(mut limbs: Limbs, want: &[i128], what: &str) {
        for (i, &w) in want.iter().enumerate() {
            assert_eq!(limbs.get(i), w, "{what}: lane {i} (redundant)");
            for l in [limbs.l0[i], limbs.l1[i]] {
                assert!(l.abs() < 1 << 60, "{what}: lane {i} limb {l}");
            }
        }
        limbs.normalise();
        let normal = Limbs::from_values(want.iter().copied());
        assert_eq!(limbs.l0, normal.l0, "{what}");
        assert_eq!(limbs.l1, normal.l1, "{what}");
        assert_eq!(limbs.l2, normal.l2, "{what}");
    }

    /// 16 calls of eight products (the sweep's cadence between normalisations),
    /// at every level, give the exact sums, all-extreme factors included.
    #[test]
    fn scaled_rows_are_exact_at_every_level() {
        simd::at_every_level(|level| {
            for n in LENGTHS {
                for all_max in [false, true] {
                    let x: Vec<Vec<i64>> = (0..8)
                        .map(|r| match all_max {
                            true => vec![MAX_FACTOR; n + r],
                            false => factors(n + r, 10 + r as u64),
                        })
                        .collect();
                    let s0 = [
                        MAX_FACTOR,
                        0,
                        1,
                        12345,
                        (1 << 51) - 3,
                        MAX_FACTOR - 1,
                        7,
                        1 << 51,
                    ];
                    let mut want = start(n, 1);
                    let mut limbs = Limbs::from_values(want.iter().copied());
                    for call in 0..16u64 {
                        let s: [i64; 8] = std::array::from_fn(|r| match (all_max, call) {
                            (true, _) => MAX_FACTOR,
                            (false, 0) => s0[r],
                            _ => pseudo(1, 100 * call + r as u64, LIMB_BITS)[0],
                        });
                        let rows: [(i64, &[i64]); 8] = std::array::from_fn(|r| (s[r], &x[r][r..]));
                        add_scaled_rows(&mut limbs.l0, &mut limbs.l1, rows);
                        for (i, w) in want.iter_mut().enumerate() {
                            *w += (0..8)
                                .map(|r| s[r] as i128 * x[r][r + i] as i128)
                                .sum::<i128>();
                        }
                    }
                    // Two rows (the sweep's single row) on top.
                    add_scaled_rows(
                        &mut limbs.l0,
                        &mut limbs.l1,
                        [(s0[0], &x[0][..]), (s0[4], &x[1][..])],
                    );
                    for (i, w) in want.iter_mut().enumerate() {
                        *w += s0[0] as i128 * x[0][i] as i128 + s0[4] as i128 * x[1][i] as i128;
                    }
                    check(
                        limbs,
                        &want,
                        &format!("{} n {n} all_max {all_max}", level.name()),
                    );
                }
            }
        });
    }

    #[test]
    fn pair_products_are_exact_at_every_level() {
        simd::at_every_level(|level| {
            for n in LENGTHS {
                for all_max in [false, true] {
                    let x: Vec<Vec<i64>> = (0..8)
                        .map(|r| match all_max {
                            true => vec![MAX_FACTOR; n + 1],
                            false => factors(n + 1, 20 + r as u64),
                        })
                        .collect();
                    let mut want = start(n, 2);
                    let mut limbs = Limbs::from_values(want.iter().copied());
                    for call in 0..16 {
                        let shift = call % 2;
                        let pairs: [(&[i64], &[i64]); 4] =
                            std::array::from_fn(|r| (&x[2 * r][shift..], &x[2 * r + 1][..]));
                        add_pair_products(&mut limbs.l0, &mut limbs.l1, pairs);
                        for (i, w) in want.iter_mut().enumerate() {
                            *w += pairs
                                .iter()
                                .map(|(a, b)| a[i] as i128 * b[i] as i128)
                                .sum::<i128>();
                        }
                    }
                    add_pair_products(
                        &mut limbs.l0,
                        &mut limbs.l1,
                        [(&x[0][..], &x[1][..]), (&x[2][..], &x[3][..])],
                    );
                    for (i, w) in want.iter_mut().enumerate() {
                        *w += x[0][i] as i128 * x[1][i] as i128 + x[2][i] as i128 * x[3][i] as i128;
                    }
                    check(
                        limbs,
                        &want,
                        &format!("{} n {n} all_max {all_max}", level.name()),
                    );
                }
            }
        });
    }

    #[test]
    fn dot_is_exact_at_every_level() {
        simd::at_every_level(|level| {
            // Tails, and more than one fold of 1024 vectors (4 or 8 lanes).
            for n in LENGTHS.into_iter().chain([4096, 4099, 8192, 8197, 20_001]) {
                for all_max in [false, true] {
                    let (a, b) = match all_max {
                        true => (vec![MAX_FACTOR; n], vec![MAX_FACTOR; n + 3]),
                        false => (factors(n, 5), factors(n + 3, 6)),
                    };
                    let want: i128 = a.iter().zip(&b).map(|(&x, &y)| x as i128 * y as i128).sum();
                    assert_eq!(
                        dot(&a, &b),
                        want,
                        "{} n {n} all_max {all_max}",
                        level.name()
                    );
                }
            }
        });
    }

    #[test]
    fn dot_is_exact() {
        for n in [0, 7, 8, 9000, 20_001] {
            let (a, b) = (pseudo(n, 5, 51), pseudo(n + 3, 6, 51));
            let want: i128 = a.iter().zip(&b).map(|(&x, &y)| x as i128 * y as i128).sum();
            assert_eq!(dot(&a, &b), want, "n {n}");
            assert_eq!(dot_scalar(&a, &b[..n], 0), want, "n {n}");
        }
    }

    /// The same integers in redundant limbs: l₀ − k·2⁵², l₁ + k.
    fn redundant(mut l: Limbs, seed: u64) -> Limbs {
        let k = pseudo(l.len(), seed, 8);
        for i in 0..l.len() {
            let k = k[i] - 128;
            l.l0[i] -= k << LIMB_BITS;
            l.l1[i] += k;
        }
        l
    }

    /// Every level rounds as the scalar kernel does, to the bit, on redundant
    /// limbs, at lengths with and without whole groups of eight; a negative term
    /// gives NaN, and terms beyond the vector conversion's range (l₂ ≥ 2⁵¹)
    /// still the scalar kernel's bits.
    #[test]
    fn weighted_terms_agree_at_every_level() {
        for h in [0, 1, 3, 4, 7, 8, 9, 15, 16, 17, 29, 64, 67] {
            let big = |s| -> Vec<i128> {
                pseudo(h, s, 62)
                    .iter()
                    .map(|&v| ((v as i128) << 55) - (1 << 115))
                    .collect()
            };
            let (a, b) = (big(1), big(2));
            // Terms up to 2¹¹², so that all three carried limbs vary.
            let small = pseudo(h, 3, 62);
            let f: i128 = 1 << 116;
            let c: Vec<i128> = (0..h)
                .map(|u| (f + a[u] + b[h - 1 - u] - ((small[u] as i128) << 50)) >> 1)
                .collect();
            let w: Vec<f64> = (1..=h).map(|k| 1.0 / k as f64).collect();
            let limbs = |v: &[i128], s| redundant(Limbs::from_values(v.iter().copied()), s);
            let (la, lb, lc) = (limbs(&a, 4), limbs(&b, 5), limbs(&c, 6));
            let (sa, sb, sc) = (la.slice(0..h), lb.slice(0..h), lc.slice(0..h));
            let mut c_neg = c.clone();
            if h > 5 {
                c_neg[5] += 1 << 113;
            }
            let lc_neg = limbs(&c_neg, 7);
            let huge = {
                let [f0, f1, f2] = split(f);
                [f0, f1, f2 + (1 << 52)]
            };
            let cases = [(split(f), sc), (huge, sc), (split(f), lc_neg.slice(0..h))];
            let want: Vec<f64> = cases
                .iter()
                .map(|&(f, c)| weighted_terms_scalar(f, sa, sb, c, &w))
                .collect();
            assert_eq!(want[2].is_nan(), h > 5);
            simd::at_every_level(|level| {
                for (k, &(f, c)) in cases.iter().enumerate() {
                    let got = weighted_terms(f, sa, sb, c, &w);
                    assert!(
                        got.to_bits() == want[k].to_bits() || got.is_nan() && want[k].is_nan(),
                        "{} h {h} case {k}: {got} vs {}",
                        level.name(),
                        want[k]
                    );
                }
            });
        }
    }

    #[test]
    fn weighted_terms_round_each_exact_term() {
        let h = 29;
        let big = |s| -> Vec<i128> {
            pseudo(h, s, 62)
                .iter()
                .map(|&v| ((v as i128) << 55) - (1 << 115))
                .collect()
        };
        let (a, b) = (big(1), big(2));
        // c chosen so that every term is a small positive integer after cancelling.
        let small = pseudo(h, 3, 20);
        let f: i128 = 1 << 100;
        let c: Vec<i128> = (0..h)
            .map(|u| (f + a[u] + b[h - 1 - u] - small[u] as i128) >> 1)
            .collect();
        let w: Vec<f64> = (1..=h).map(|k| 1.0 / k as f64).collect();
        let (la, lb, lc) = (
            Limbs::from_values(a.iter().copied()),
            Limbs::from_values(b.iter().copied()),
            Limbs::from_values(c.iter().copied()),
        );
        let got = weighted_terms(split(f), la.slice(0..h), lb.slice(0..h), lc.slice(0..h), &w);
        let want: f64 = (0..h)
            .map(|u| (f + a[u] + b[h - 1 - u] - 2 * c[u]) as f64 * w[h - 1 - u])
            .sum();
        assert!((got - want).abs() <= 1e-14 * want, "{got} vs {want}");
        let (sa, sb, sc) = (la.slice(0..h), lb.slice(0..h), lc.slice(0..h));
        let portable = weighted_terms_scalar(split(f), sa, sb, sc, &w);
        assert_eq!(portable.to_bits(), got.to_bits());
        // A negative term is a failed computation.
        let mut c2 = c.clone();
        c2[5] += 1 << 30;
        let lc2 = Limbs::from_values(c2.iter().copied());
        let neg = weighted_terms(
            split(f),
            la.slice(0..h),
            lb.slice(0..h),
            lc2.slice(0..h),
            &w,
        );
        assert!(neg.is_nan(), "{neg}");
    }
}
