//! The Theo1 sum at many even averaging factors at once, exactly:
//!
//!   S(m) = Σ_{i<L} Σ_{k=1}^{h} (1/k)·T_k,  T_k = (q_i + q_{i+m} − q_{i+k} − q_{i+m−k})²,
//!
//! h = m/2, L = N − m, over the integer phase q of [`ExactPhase`]. (The route
//! of Lewis, IEEE Trans. UFFC 67(10), 2020, derived again here.) With
//! a, b, p, q = q_i, q_{i+m}, q_{i+k}, q_{i+m−k}, each T_k summed over i
//! expands into squares (prefix sums), ab (lag m, the whole autocorrelation
//! R(m)) and four lag sums that are R at their lag minus the products the
//! window leaves out at the ends:
//!
//!   ap + bq = 2R(k) − A(k) − A'(k),      aq + bp = 2R(m−k) − A(m−k) − A'(m−k),
//!   pq = R(m−2k) − C(m−2k) − C'(m−2k),
//!
//! where A_m(ℓ) = Σ_{j+ℓ<m} q_j q_{j+ℓ} (pairs in the first m points),
//! C_m(e) = Σ_{2j+e<m} q_j q_{j+e} (pairs whose midpoint is below m/2), and
//! A', C' the same on the reversed phase (the products left out at the far
//! end). Going from m to m + 2 adds two rows of pairs to A and one
//! anti-diagonal to C, so all even m up to M cost O(M²) products in all and
//! each requested m O(m) more: O(N log N + M²) instead of O(N·M) per factor.
//! Every quantity is an exact integer, so the sum of T_k over i is exact
//! before it is weighted by 1/k in double precision. The sums live in 52-bit
//! limbs (`limbs`), whose products AVX-512 IFMA adds eight at a time, and AVX2
//! with FMA four at a time (exactly, in double precision).

use super::exact_phase::ExactPhase;
use super::limbs::{self, LimbSlice, Limbs};
use crate::interrupt::Interrupt;

/// Lanes from which a kernel call is split in two halves for two threads (the
/// halves are fixed, so the result does not depend on the thread count).
const SPLIT_FROM: usize = 1 << 14;

/// [`limbs::add_scaled_rows`], in two halves on two threads when long.
fn scaled_rows<const R: usize>(lo: &mut [i64], hi: &mut [i64], rows: [(i64, &[i64]); R]) {
    if lo.len() < SPLIT_FROM {
        return limbs::add_scaled_rows(lo, hi, rows);
    }
    let mid = lo.len() / 16 * 8;
    let (lo_a, lo_b) = lo.split_at_mut(mid);
    let (hi_a, hi_b) = hi.split_at_mut(mid);
    let rows_b = rows.map(|(s, x)| (s, &x[mid..]));
    rayon::join(
        || limbs::add_scaled_rows(lo_a, hi_a, rows),
        || limbs::add_scaled_rows(lo_b, hi_b, rows_b),
    );
}

/// [`limbs::add_pair_products`], in two halves on two threads when long.
fn pair_products<const R: usize>(lo: &mut [i64], hi: &mut [i64], pairs: [(&[i64], &[i64]); R]) {
    if lo.len() < SPLIT_FROM {
        return limbs::add_pair_products(lo, hi, pairs);
    }
    let mid = lo.len() / 16 * 8;
    let (lo_a, lo_b) = lo.split_at_mut(mid);
    let (hi_a, hi_b) = hi.split_at_mut(mid);
    let pairs_b = pairs.map(|(a, b)| (&a[mid..], &b[mid..]));
    rayon::join(
        || limbs::add_pair_products(lo_a, hi_a, pairs),
        || limbs::add_pair_products(lo_b, hi_b, pairs_b),
    );
}

/// [`limbs::weighted_terms`], the terms in two halves on two threads when many
/// (the two partial sums added in a fixed order).
fn weighted_terms(f: [i64; 3], a: LimbSlice, b: LimbSlice, c: LimbSlice, w: &[f64]) -> f64 {
    let h = w.len();
    if h < SPLIT_FROM {
        return limbs::weighted_terms(f, a, b, c, w);
    }
    // Terms u < mid read a, c at u and b, w at h − 1 − u (their last mid lanes).
    let mid = h / 16 * 8;
    let (first, second) = rayon::join(
        || {
            limbs::weighted_terms(
                f,
                a.range(0..mid),
                b.range(h - mid..h),
                c.range(0..mid),
                &w[h - mid..],
            )
        },
        || {
            limbs::weighted_terms(
                f,
                a.range(mid..h),
                b.range(0..h - mid),
                c.range(mid..h),
                &w[..h - mid],
            )
        },
    );
    first + second
}

/// Four-row steps between normalisations of the limbs: each step adds at most
/// eight products to a lane, each less than 2⁵² in magnitude to l₀ and to l₁ on
/// every path (IFMA's and the portable high and low halves, non-negative; the
/// AVX2 path's rounded high part, and its remainder in [−2⁵¹, 2⁵¹]), so limbs
/// stay below 2⁶⁰ in magnitude and a term (four of them) below 2⁶³.
const STEPS_PER_NORMALISATION: usize = 16;

/// The pair sums of both directions of the phase, folded with the terms that
/// depend on one lag only, for the m reached:
///
///   W(ℓ) = Σ_{t<N−ℓ} q_t² − Σ_{t<ℓ} q_t² − 4R(ℓ) + 2A(ℓ) + 2A'(ℓ),
///   Z(e) = C(e) + C'(e) − R(e),
///
/// so that T(m, k) = F(m) + W(k) + W(m − k) − 2Z(m − 2k) with
/// F(m) = Σ_{t<N−m} q_t² + Σ_{t≥m} q_t² + 2R(m).
struct Sweep<'a> {
    q: &'a [i64],
    /// q reversed: the phase the primed sums run over.
    qr: Vec<i64>,
    /// W(ℓ) at index M − ℓ (so a row of products is contiguous).
    w: Limbs,
    /// Z(e) at index e/2.
    z: Limbs,
    max_m: usize,
    /// Rows (points) added so far: the sums describe m = rows.
    rows: usize,
    steps: usize,
}

impl<'a> Sweep<'a> {
    fn new(p: &'a ExactPhase, max_m: usize) -> Self {
        let n = p.q.len();
        let sq = |t: usize| p.squares[t];
        let w = Limbs::from_values((0..max_m + 1).map(|x| match max_m - x {
            0 => 0,
            lag => sq(n - lag) - sq(lag) - 4 * p.r[lag],
        }));
        let z = Limbs::from_values((0..max_m / 2 + 2).map(|i| match p.r.get(2 * i) {
            Some(&r) => -r,
            None => 0,
        }));
        Sweep {
            q: &p.q,
            qr: p.q.iter().rev().copied().collect(),
            w,
            z,
            max_m,
            rows: 0,
            steps: 0,
        }
    }

    /// Adds rows (and, at even rows, anti-diagonals) until the sums describe m.
    fn advance(&mut self, m: usize) {
        while self.rows + 4 <= m && self.rows.is_multiple_of(2) {
            self.add_four_rows(self.rows);
            self.rows += 4;
            self.count_step();
        }
        while self.rows < m {
            self.add_row(self.rows);
            self.rows += 1;
            self.count_step();
        }
    }

    fn count_step(&mut self) {
        self.steps += 1;
        if self.steps == STEPS_PER_NORMALISATION {
            self.w.normalise();
            self.z.normalise();
            self.steps = 0;
        }
    }

    /// Row l: W(l − j) += 2q_l q_j + 2q'_l q'_j for j < l; for even l the
    /// anti-diagonal l of Z.
    fn add_row(&mut self, l: usize) {
        let (q, qr) = (self.q, &self.qr[..]);
        let b = self.max_m - l;
        let m = self.max_m;
        scaled_rows(
            &mut self.w.l0[b..m],
            &mut self.w.l1[b..m],
            [(2 * q[l], &q[..l]), (2 * qr[l], &qr[..l])],
        );
        if l.is_multiple_of(2) {
            self.add_antidiagonals::<2>(l / 2);
        }
    }

    /// Rows l … l + 3 (l even) in one pass over W, and anti-diagonals l, l + 2
    /// in one pass over Z: the hot loop of the sweep.
    fn add_four_rows(&mut self, l: usize) {
        let (q, qr) = (self.q, &self.qr[..]);
        let m = self.max_m;
        let b = m - l;
        // Index x ≥ b gets all four rows: W[x] += Σ_t 2q_{l+t} q_{x−b+t}.
        scaled_rows(
            &mut self.w.l0[b..m],
            &mut self.w.l1[b..m],
            [
                (2 * q[l], q),
                (2 * q[l + 1], &q[1..]),
                (2 * q[l + 2], &q[2..]),
                (2 * q[l + 3], &q[3..]),
                (2 * qr[l], qr),
                (2 * qr[l + 1], &qr[1..]),
                (2 * qr[l + 2], &qr[2..]),
                (2 * qr[l + 3], &qr[3..]),
            ],
        );
        // Lags l + 1 … l + 3 (index b − s) only from the later rows.
        for s in 1..4 {
            for t in s..4 {
                self.w.add_product(b - s, 2 * q[l + t], q[t - s]);
                self.w.add_product(b - s, 2 * qr[l + t], qr[t - s]);
            }
        }
        self.add_antidiagonals::<4>(l / 2);
    }

    /// Z(i) += q_{c−i} q_{c+i} (+ the same at c + 1 when `ROWS` is 4) over
    /// both directions, i ≤ c: anti-diagonal 2c (and 2c + 2).
    fn add_antidiagonals<const ROWS: usize>(&mut self, c: usize) {
        let (q, qr) = (self.q, &self.qr[..]);
        let n = q.len();
        // q_{c−i} = q'_{N−1−c+i}: contiguous in i.
        let (back, back_r) = (&qr[n - 1 - c..], &q[n - 1 - c..]);
        let (lo, hi) = (&mut self.z.l0[..=c], &mut self.z.l1[..=c]);
        if ROWS == 2 {
            pair_products(lo, hi, [(back, &q[c..]), (back_r, &qr[c..])]);
            return;
        }
        let (next, next_r) = (&qr[n - 2 - c..], &q[n - 2 - c..]);
        pair_products(
            lo,
            hi,
            [
                (back, &q[c..]),
                (back_r, &qr[c..]),
                (next, &q[c + 1..]),
                (next_r, &qr[c + 1..]),
            ],
        );
        // i = c + 1 of anti-diagonal 2c + 2.
        self.z.add_product(c + 1, q[0], q[2 * c + 2]);
        self.z.add_product(c + 1, qr[0], qr[2 * c + 2]);
    }

    /// Σ_{k=1}^{m/2} T(m, k)/k in integer units (the sums must describe m).
    fn weighted_sum(&self, p: &ExactPhase, m: usize, weights: &[f64]) -> f64 {
        let n = self.q.len();
        let h = m / 2;
        let top = self.max_m;
        let f = p
            .squares_between(0, n - m)
            .wrapping_add(p.squares_between(m, n))
            .wrapping_add(p.r[m].wrapping_mul(2));
        // W(k) for k = h … 1 (index top − h … top − 1), W(m − k) for k = 1 … h
        // read backwards, Z((m − 2k)/2) = Z(h − k) for k = h … 1.
        weighted_terms(
            limbs::split(f),
            self.w.slice(top - h..top),
            self.w.slice(top + 1 - m..top + 1 - m + h),
            self.z.slice(0..h),
            &weights[..h],
        )
    }
}

/// S(m) in phase units² for every m of `ms` (even, 2 ≤ m < N, ascending), or
/// `None` when the exact phase could not be formed or the run was interrupted
/// (the caller tells them apart by `stop`).
pub fn theo1_sums(p: &ExactPhase, ms: &[usize], stop: &Interrupt) -> Option<Vec<f64>> {
    let n = p.q.len();
    let max_m = *ms.last()?;
    if ms.windows(2).any(|w| w[0] >= w[1]) || ms.iter().any(|&m| m % 2 == 1 || m < 2) {
        return None;
    }
    if max_m >= n || max_m > p.r.len() - 1 || p.q.iter().any(|&v| v > limbs::MAX_FACTOR / 2) {
        return None;
    }
    let mut sweep = Sweep::new(p, max_m);
    let weights: Vec<f64> = (1..=max_m / 2).map(|k| 1.0 / k as f64).collect();
    let mut sums = Vec::with_capacity(ms.len());
    for &m in ms {
        if stop.raised() {
            return None;
        }
        sweep.advance(m);
        sums.push(sweep.weighted_sum(p, m, &weights) * p.unit);
    }
    Some(sums)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::allan::test_signals::{integrated_noise, naive_theo1};

    #[test]
    fn every_factor_matches_the_definition() {
        let never = Interrupt::new();
        for order in 0..3 {
            let c = integrated_noise(900, 3, order);
            let p = ExactPhase::new(&c, 899).unwrap();
            // Steps of 2 (row by row), 4 (four rows at once) and 10 (both).
            let ms: Vec<usize> = (2..900)
                .step_by(2)
                .chain((12..900).step_by(4))
                .chain((4..900).step_by(10))
                .collect();
            let mut sums = Vec::new();
            for part in [&ms[..449], &ms[449..671], &ms[671..]] {
                sums.extend(theo1_sums(&p, part, &never).unwrap());
            }
            for (&m, s) in ms.iter().zip(&sums) {
                let got = s / (0.75 * (900 - m) as f64 * (m * m) as f64);
                let want = naive_theo1(&c, m);
                assert!(
                    (got - want).abs() <= 1e-10 * want,
                    "order {order} m {m}: {got} vs {want}"
                );
            }
        }
    }

    /// Every level's kernels give the same sums, to the bit (the limbs are
    /// exact integers, whatever redundant form each path leaves them in).
    #[test]
    fn every_level_gives_the_same_bits() {
        let never = Interrupt::new();
        let c = integrated_noise(1200, 7, 2);
        let p = ExactPhase::new(&c, 1199).unwrap();
        let ms: Vec<usize> = (2..40).step_by(2).chain((44..1200).step_by(4)).collect();
        let mut first: Option<Vec<u64>> = None;
        crate::simd::at_every_level(|level| {
            let bits: Vec<u64> = theo1_sums(&p, &ms, &never)
                .unwrap()
                .iter()
                .map(|s| s.to_bits())
                .collect();
            match &first {
                None => first = Some(bits),
                Some(want) => assert!(&bits == want, "{} differs", level.name()),
            }
        });
    }

    #[test]
    fn stops_when_interrupted() {
        let stop = Interrupt::new();
        stop.raise();
        let c = integrated_noise(300, 3, 1);
        let p = ExactPhase::new(&c, 299).unwrap();
        assert_eq!(theo1_sums(&p, &[12, 16], &stop), None);
    }
}
