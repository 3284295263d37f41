//! The phase as exact integers, with its autocorrelation at every lag, for
//! sums that expand squares into products and so cancel: on random-walk FM the
//! expanded products of a 10⁵-point record are ~10¹⁴ times the result, which
//! leaves no digit in double precision. Here every product and sum is an exact
//! integer (i128), so the expansion loses nothing; only the final, positive
//! sums are rounded to f64.
//!
//! The phase c is first detrended (every statistic built on it ignores a linear
//! function of c) and quantised to q_i = round((c_i − min)·2^e) < 2^B with B
//! about 50 bits: a perturbation of 2^−B of the range, below the rounding of
//! c_i + c_{i+m} in double precision that the direct sums make.
//!
//! The autocorrelation R(d) = Σ_i q_i q_{i+d} for every lag d ≤ D comes from
//! double-precision FFTs made exact by splitting q into 11-bit limbs: each limb
//! correlation is an integer below 2^45 whose FFT error stays far below ½
//! (checked on every value: a larger distance to the nearest integer refuses
//! the whole computation), so rounding recovers it exactly.

use rustfft::num_complex::Complex;

use crate::simd::FftPlans;

use crate::allan::phase::least_squares_line;

/// Bits of one limb of q.
const LIMB_BITS: u32 = 11;

/// Largest distance to an integer an FFT result may have before the
/// computation is refused (the error bound of a correct one is far smaller).
const ROUNDING_SLACK: f64 = 0.25;

/// The phase as integers with its prefix sums of squares and autocorrelation.
pub struct ExactPhase {
    /// q_i = round((f_i − min f)·2^e), f the detrended phase.
    pub q: Vec<i64>,
    /// Σ_{i<t} q_i², t = 0..=N.
    pub squares: Vec<i128>,
    /// R(d) = Σ_i q_i q_{i+d}, d = 0..=max_lag.
    pub r: Vec<i128>,
    /// 2^(−2e): turns a sum of squared integer combinations into phase units².
    pub unit: f64,
}

/// Bits of q for N points, so that every sum of up to N squares of a
/// combination of four q values (< 16·2^(2B)·N) fits in i128.
fn quantisation_bits(n: usize) -> i32 {
    let log_n = (usize::BITS - n.leading_zeros()) as i32;
    ((122 - log_n) / 2).min(50)
}

impl ExactPhase {
    /// The exact phase of `c` with its autocorrelation up to `max_lag` (< N), or
    /// `None` when an FFT result was not close enough to an integer.
    pub fn new(c: &[f64], max_lag: usize) -> Option<Self> {
        let n = c.len();
        let (mean, slope) = least_squares_line(|t| c[t], n);
        let centre = (n as f64 - 1.0) / 2.0;
        let f: Vec<f64> = c
            .iter()
            .enumerate()
            .map(|(t, v)| (v - mean) - slope * (t as f64 - centre))
            .collect();
        let lo = f.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = f.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let bits = quantisation_bits(n);
        let range = hi - lo;
        // range·2^e < 2^bits, with 2^e exact.
        let e = if range > 0.0 {
            bits - 1 - range.log2().floor() as i32
        } else {
            0
        };
        let scale = 2f64.powi(e);
        let q: Vec<i64> = f
            .iter()
            .map(|v| ((v - lo) * scale).round() as i64)
            .collect();
        let mut squares = Vec::with_capacity(n + 1);
        let mut run: i128 = 0;
        squares.push(0);
        for &v in &q {
            run += (v as i128) * (v as i128);
            squares.push(run);
        }
        let r = autocorrelation(&q, bits as u32 + 1, max_lag.min(n - 1))?;
        Some(ExactPhase {
            q,
            squares,
            r,
            unit: 2f64.powi(-2 * e),
        })
    }

    /// Σ_{i<t} q_i² over i in [a, b).
    pub fn squares_between(&self, a: usize, b: usize) -> i128 {
        self.squares[b].wrapping_sub(self.squares[a])
    }

    /// Σ_{j<count} q_j q_{j+d} (the first `count` products at lag d).
    pub fn head(&self, d: usize, count: usize) -> i128 {
        lag_products(&self.q[..count], &self.q[d..d + count])
    }

    /// The last `count` products at lag d.
    pub fn tail(&self, d: usize, count: usize) -> i128 {
        let n = self.q.len();
        let j0 = n - d - count;
        lag_products(&self.q[j0..j0 + count], &self.q[j0 + d..n])
    }

    /// Σ_{i<N−2m} (q_i − 2q_{i+m} + q_{i+2m})² in phase units² (the overlapping
    /// Allan sum), from R(m), R(2m) (needs 2m ≤ max_lag) and the edges at lag m.
    pub fn allan_sum(&self, m: usize) -> f64 {
        let n = self.q.len();
        let l = n - 2 * m;
        let w = |v: i128, k: i128| v.wrapping_mul(k);
        let total = self
            .squares_between(0, l)
            .wrapping_add(w(self.squares_between(m, l + m), 4))
            .wrapping_add(self.squares_between(2 * m, n))
            .wrapping_sub(w(self.r[m], 8))
            .wrapping_add(w(self.tail(m, m).wrapping_add(self.head(m, m)), 4))
            .wrapping_add(w(self.r[2 * m], 2));
        to_f64(total) * self.unit
    }
}

/// Σ a_j b_j exactly (q < 2⁵¹, so the limb kernel's factors).
fn lag_products(a: &[i64], b: &[i64]) -> i128 {
    super::limbs::dot(a, b)
}

/// A non-negative i128 as f64 (within 2 ulp; negative values, which only a
/// failed computation gives, become NaN).
pub fn to_f64(v: i128) -> f64 {
    if v < 0 {
        return f64::NAN;
    }
    let hi = (v >> 64) as u64;
    let lo = v as u64;
    hi as f64 * 18446744073709551616.0 + lo as f64
}

/// R(d) for d = 0..=max_lag of non-negative q < 2^bits, by limb FFTs.
fn autocorrelation(q: &[i64], bits: u32, max_lag: usize) -> Option<Vec<i128>> {
    let n = q.len();
    let limbs = bits.div_ceil(LIMB_BITS) as usize;
    let size = (n + max_lag + 1).next_power_of_two();
    let mut plans = FftPlans::new();
    let forward = plans.forward(size);
    let inverse = plans.inverse(size);
    let mask = (1i64 << LIMB_BITS) - 1;
    let spectra: Vec<Vec<Complex<f64>>> = (0..limbs)
        .map(|a| {
            let mut v = vec![Complex::new(0.0, 0.0); size];
            for (slot, &x) in v.iter_mut().zip(q) {
                slot.re = ((x >> (a as u32 * LIMB_BITS)) & mask) as f64;
            }
            forward.process(&mut v);
            v
        })
        .collect();
    let mut r = vec![0i128; max_lag + 1];
    let norm = 1.0 / size as f64;
    // Limb pairs (a, b) with a + b = s share a shift: one inverse FFT per s.
    for s in 0..(2 * limbs - 1) {
        let mut z = vec![Complex::new(0.0, 0.0); size];
        for a in 0..limbs {
            let Some(b) = s.checked_sub(a).filter(|&b| b < limbs) else {
                continue;
            };
            for (zi, (fa, fb)) in z.iter_mut().zip(spectra[a].iter().zip(&spectra[b])) {
                *zi += fa.conj() * fb;
            }
        }
        inverse.process(&mut z);
        for (rd, zd) in r.iter_mut().zip(&z) {
            let v = zd.re * norm;
            let k = v.round();
            if (v - k).abs() > ROUNDING_SLACK {
                return None;
            }
            *rd = rd.wrapping_add((k as i128) << (s as u32 * LIMB_BITS));
        }
    }
    Some(r)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::allan::estimators::difference::oavar;
    use crate::allan::test_signals::integrated_noise;

    #[test]
    fn autocorrelation_is_exact() {
        let c = integrated_noise(3000, 4, 2);
        let p = ExactPhase::new(&c, 2999).unwrap();
        for d in [0, 1, 2, 17, 1000, 2999] {
            let want = p.head(d, 3000 - d);
            assert_eq!(p.r[d], want, "lag {d}");
        }
        assert_eq!(p.head(5, 10) + p.tail(5, 2985), p.r[5]);
    }

    #[test]
    fn allan_sums_match_the_direct_ones() {
        for order in 0..3 {
            let c = integrated_noise(2000, 7, order);
            let p = ExactPhase::new(&c, 1998).unwrap();
            for m in [1, 2, 9, 100, 999] {
                let got = p.allan_sum(m) / (2.0 * (m * m) as f64 * (2000 - 2 * m) as f64);
                let want = oavar(&c, m);
                assert!((got - want).abs() <= 1e-10 * want, "m {m}: {got} vs {want}");
            }
        }
    }

    #[test]
    fn a_flat_phase_has_no_variance() {
        let p = ExactPhase::new(&[3.0; 100], 50).unwrap();
        assert_eq!(p.allan_sum(10), 0.0);
    }
}
