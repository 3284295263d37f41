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
//! before it is weighted by 1/k in double precision.

use rayon::prelude::*;

use super::exact_phase::{to_f64, ExactPhase};
use crate::interrupt::Interrupt;

/// The pair sums A_m and C_m of one direction of the phase, for the m reached.
struct Triangles<'a> {
    q: &'a [i64],
    /// A(ℓ) for ℓ < m (index ℓ).
    a: Vec<i128>,
    /// C(e) for even e < m (index e/2).
    c: Vec<i128>,
    /// Rows (points) added so far: A and C describe m = rows.
    rows: usize,
}

impl<'a> Triangles<'a> {
    fn new(q: &'a [i64], max_m: usize) -> Self {
        Triangles {
            q,
            a: vec![0; max_m + 1],
            c: vec![0; max_m / 2 + 1],
            rows: 0,
        }
    }

    /// Adds rows (and, at even rows, anti-diagonals) until A, C describe m.
    fn advance(&mut self, m: usize) {
        while self.rows + 4 <= m && self.rows.is_multiple_of(2) {
            self.add_four_rows(self.rows);
            self.rows += 4;
        }
        while self.rows < m {
            self.add_row(self.rows);
            self.rows += 1;
        }
    }

    /// Row l of A (pairs ending at l) and, for even l, anti-diagonal l of C.
    fn add_row(&mut self, l: usize) {
        let q = self.q;
        let ql = q[l] as i128;
        for (a, &x) in self.a[1..=l].iter_mut().rev().zip(&q[..l]) {
            *a = a.wrapping_add(x as i128 * ql);
        }
        if l.is_multiple_of(2) {
            // Pairs (j, l − j), j ≤ l/2, at lag e = l − 2j: C index l/2 − j.
            let c = l / 2;
            for (i, slot) in self.c[..=c].iter_mut().enumerate() {
                *slot = slot.wrapping_add(q[c - i] as i128 * q[c + i] as i128);
            }
        }
    }

    /// Rows l … l + 3 (l even) in one pass over A, and anti-diagonals l, l + 2
    /// in one pass over C: the hot loop of the sweep, so A and C are read and
    /// written once per four rows.
    fn add_four_rows(&mut self, l: usize) {
        let q = self.q;
        let last = [
            q[l] as i128,
            q[l + 1] as i128,
            q[l + 2] as i128,
            q[l + 3] as i128,
        ];
        // Lags 1..=l get all four rows: A[l − j] += Σ_t q[j + t]·q[l + t], j < l.
        for (a, w) in self.a[1..=l].iter_mut().rev().zip(q[..l + 3].windows(4)) {
            let add = (w[0] as i128 * last[0])
                .wrapping_add(w[1] as i128 * last[1])
                .wrapping_add(w[2] as i128 * last[2])
                .wrapping_add(w[3] as i128 * last[3]);
            *a = a.wrapping_add(add);
        }
        // Lags l + 1 … l + 3 only from the later rows.
        for t in 1..4 {
            for lag in l + 1..=l + t {
                self.a[lag] = self.a[lag].wrapping_add(q[l + t - lag] as i128 * last[t]);
            }
        }
        // C[i] += q[c − i]·q[c + i] + q[c + 1 − i]·q[c + 1 + i], c = l/2.
        let c = l / 2;
        for i in 0..=c {
            let add = (q[c - i] as i128 * q[c + i] as i128)
                .wrapping_add(q[c + 1 - i] as i128 * q[c + 1 + i] as i128);
            self.c[i] = self.c[i].wrapping_add(add);
        }
        self.c[c + 1] = self.c[c + 1].wrapping_add(q[0] as i128 * q[l + 2] as i128);
    }

    /// A(k) + A(m − k) − C(m − 2k) for k = 1..=m/2, into `out[k − 1]`.
    fn edges(&self, m: usize, out: &mut [i128]) {
        for (i, slot) in out.iter_mut().enumerate() {
            let k = i + 1;
            *slot = self.a[k]
                .wrapping_add(self.a[m - k])
                .wrapping_sub(self.c[(m - 2 * k) / 2]);
        }
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
    if max_m >= n || max_m > p.r.len() - 1 {
        return None;
    }
    let reversed: Vec<i64> = p.q.iter().rev().copied().collect();
    let mut fwd = Triangles::new(&p.q, max_m);
    let mut rev = Triangles::new(&reversed, max_m);
    let (mut ef, mut er) = (vec![0i128; max_m / 2], vec![0i128; max_m / 2]);
    let weights: Vec<f64> = (1..=max_m / 2).map(|k| 1.0 / k as f64).collect();
    let r = &p.r;
    let mut sums = Vec::with_capacity(ms.len());
    for &m in ms {
        if stop.raised() {
            return None;
        }
        let h = m / 2;
        rayon::join(
            || {
                fwd.advance(m);
                fwd.edges(m, &mut ef[..h]);
            },
            || {
                rev.advance(m);
                rev.edges(m, &mut er[..h]);
            },
        );
        let l = n - m;
        // The k-free part: Σa² + Σb² + 2·ab.
        let fixed = p
            .squares_between(0, l)
            .wrapping_add(p.squares_between(m, n))
            .wrapping_add(r[m].wrapping_mul(2));
        let term = |k: usize| -> f64 {
            let t = fixed
                .wrapping_add(p.squares_between(k, k + l))
                .wrapping_add(p.squares_between(m - k, m - k + l))
                .wrapping_sub(r[k].wrapping_add(r[m - k]).wrapping_mul(4))
                .wrapping_add(r[m - 2 * k].wrapping_mul(2))
                .wrapping_add(ef[k - 1].wrapping_add(er[k - 1]).wrapping_mul(2));
            to_f64(t) * weights[k - 1]
        };
        // The terms are positive: a plain sum in four lanes loses < h·ε.
        let total: f64 = if h >= 4096 {
            (1..h + 1)
                .into_par_iter()
                .with_min_len(2048)
                .map(term)
                .sum()
        } else {
            (1..=h).map(term).sum()
        };
        sums.push(total * p.unit);
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

    #[test]
    fn stops_when_interrupted() {
        let stop = Interrupt::new();
        stop.raise();
        let c = integrated_noise(300, 3, 1);
        let p = ExactPhase::new(&c, 299).unwrap();
        assert_eq!(theo1_sums(&p, &[12, 16], &stop), None);
    }
}
