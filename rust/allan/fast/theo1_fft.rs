//! The Theo1 sum in O(n log² m) per averaging factor instead of O(n·m):
//!
//!   S = Σ_{i<N−m} Σ_{k=1}^{m/2} (1/k)·(c_i + c_{i+m} − c_{i+k} − c_{i+m−k})²
//!
//! over the N phase points c (`estimators/theo1.rs` has the definition, the
//! direct form and the threshold between the two). With G(i) = c_i + c_{i+m} the square expands into
//!
//!   H·ΣG² + Σ w_k c_{i+k}² + Σ w_k c_{i+m−k}² − 2Σ G(i)·A(i) − 2Σ G(i)·B(i)
//!   + 2 Σ_k w_k Σ_i c_{i+k}·c_{i+m−k},
//!
//! (w_k = 1/k, H = Σ w_k): the squares are one pass with harmonic-number
//! prefix sums; A(i) = Σ w_k c_{i+k} and B(i) = Σ w_k c_{i+m−k} are sliding
//! weighted sums (FFT); in the last sum, u = i + k runs over a range that moves
//! with k, which is a rectangle of (u, k) — again a sliding sum, of c at stride 2
//! — plus a triangle at each end, split recursively into rectangles.
//!
//! Digits: as for MTOT (`reflected.rs`), every term is unchanged by adding a
//! linear function to c, and the expansion only keeps its digits if the phase
//! is small where it is used, so each block of start points works on c minus
//! its own least-squares line, over a span of a few m.

use rayon::prelude::*;

use super::sliding::sliding_dot;
use crate::allan::phase::least_squares_line;
use crate::allan::sum::Neumaier;
use crate::interrupt::Interrupt;

/// Start points per block, in units of m.
const BLOCK_IN_M: usize = 4;

/// Triangles this small (in k) are summed directly.
const TRIANGLE_DIRECT: usize = 48;

/// Σ_s X(s)·Σ_{κ ∈ pairs(s)} w(κ)·Y(s − 2κ) over parts of the (s, κ) plane,
/// with X(s) = x[s], Y(j) = f[y0 + j] and w(κ) = w[κ − 1].
struct StrideTwo<'a> {
    x: &'a [f64],
    f: &'a [f64],
    y0: usize,
    w: &'a [f64],
}

impl StrideTwo<'_> {
    fn y(&self, s: usize, kappa: usize) -> f64 {
        self.f[self.y0 + s - 2 * kappa]
    }

    /// s ∈ [s0, s1), κ ∈ [k0, k1].
    fn rectangle(&self, s0: usize, s1: usize, k0: usize, k1: usize) -> f64 {
        if s1 <= s0 || k1 < k0 {
            return 0.0;
        }
        // r(s) = Σ_κ w(κ)·f[y0 + s − 2κ] = Σ_j v_j·f[y0 + s − 2k1 + j], v_{2q} = w(k1 − q).
        let span = 2 * (k1 - k0) + 1;
        let mut v = vec![0.0; span];
        for q in 0..=(k1 - k0) {
            v[2 * q] = self.w[k1 - q - 1];
        }
        let start = self.y0 + s0 - 2 * k1;
        let r = sliding_dot(&self.f[start..start + (s1 - s0) + span - 1], &v);
        self.x[s0..s1]
            .iter()
            .zip(&r)
            .map(|(xs, rs)| xs * rs)
            .sum::<Neumaier>()
            .value()
    }

    /// Σ_{a ≤ s < b} X(s)·Σ_{κ ∈ kappas(s)} w(κ)·Y(s − 2κ), term by term.
    fn direct_triangle(
        &self,
        a: usize,
        b: usize,
        kappas: impl Fn(usize) -> std::ops::RangeInclusive<usize>,
    ) -> f64 {
        (a..b)
            .map(|s| {
                let inner: f64 = kappas(s).map(|k| self.w[k - 1] * self.y(s, k)).sum();
                self.x[s] * inner
            })
            .sum::<Neumaier>()
            .value()
    }

    /// Pairs a ≤ κ ≤ s < b.
    fn lower(&self, a: usize, b: usize) -> f64 {
        if b <= a {
            return 0.0;
        }
        if b - a <= TRIANGLE_DIRECT {
            return self.direct_triangle(a, b, |s| a..=s);
        }
        let mid = a + (b - a) / 2;
        self.lower(a, mid) + self.lower(mid, b) + self.rectangle(mid, b, a, mid - 1)
    }

    /// Pairs a ≤ s < κ ≤ b.
    fn upper(&self, a: usize, b: usize) -> f64 {
        if b <= a {
            return 0.0;
        }
        if b - a <= TRIANGLE_DIRECT {
            return self.direct_triangle(a, b, |s| s + 1..=b);
        }
        let mid = a + (b - a) / 2;
        self.upper(a, mid) + self.upper(mid, b) + self.rectangle(a, mid, mid + 1, b)
    }
}

/// Σ_{κ=1}^{H} w(κ)·Σ_{u=o+κ}^{o+b−1+κ} f[u]·f[u + mm − 2κ], H = w.len() ≤ b.
fn moving_window_products(f: &[f64], o: usize, b: usize, mm: usize, w: &[f64]) -> f64 {
    let h = w.len();
    // Core, u ∈ [o + H, o + b], every κ: Σ_u f[u]·Σ_κ w(κ) f[u + mm − 2κ].
    let core_part = StrideTwo { x: f, f, y0: mm, w };
    let core = core_part.rectangle(o + h, o + b + 1, 1, h);
    // Left end, u = o + s with κ ≤ s ≤ H − 1; right end, u = o + b + s with s < κ.
    let left = StrideTwo {
        x: &f[o..],
        f,
        y0: o + mm,
        w,
    };
    let right = StrideTwo {
        x: &f[o + b..],
        f,
        y0: o + b + mm,
        w,
    };
    core + left.lower(1, h) + right.upper(1, h)
}

/// Σ over the start points i0 ≤ i < i0 + b, from f[t] = c[i0 + t] − line(t).
fn block_sum(f: &[f64], b: usize, m: usize, w: &[f64], harmonic: &[f64]) -> f64 {
    let h = m / 2;
    let (mut squares, mut mixed) = (Neumaier::new(), Neumaier::new());
    // H·Σ G² and Σ_k w_k (f[i+k]² + f[i+m−k]²) through harmonic-number ranges.
    let g: Vec<f64> = (0..b).map(|i| f[i] + f[i + m]).collect();
    for gi in &g {
        squares.add(harmonic[h] * gi * gi);
    }
    let range = |lo: usize, hi: usize| {
        if hi >= lo {
            harmonic[hi] - harmonic[lo - 1]
        } else {
            0.0
        }
    };
    for (t, ft) in f.iter().enumerate() {
        // k with i = t − k in the block; k with i = t − m + k in the block.
        let near = range(t.saturating_sub(b - 1).max(1), h.min(t));
        let far = range(
            m.saturating_sub(t).max(1),
            h.min((b - 1 + m).saturating_sub(t)),
        );
        squares.add(ft * ft * (near + far));
    }
    // A(i) = Σ_k w_k f[i+k]; B(i) = Σ_k w_k f[i+m−k] = Σ_j w_{h−j} f[i+m−h+j].
    let a = sliding_dot(&f[1..b + h], w);
    let reversed: Vec<f64> = w.iter().rev().copied().collect();
    let bb = sliding_dot(&f[m - h..b - 1 + m], &reversed);
    for i in 0..b {
        mixed.add(g[i] * (a[i] + bb[i]));
    }
    // Σ_k w_k Σ_i f[i+k]·f[i+m−k], k in chunks no longer than the block.
    let mut products = Neumaier::new();
    let mut k_lo = 1;
    while k_lo <= h {
        let k_hi = (k_lo + b - 1).min(h);
        let o = k_lo - 1;
        products.add(moving_window_products(
            f,
            o,
            b,
            m - 2 * o,
            &w[k_lo - 1..k_hi],
        ));
        k_lo = k_hi + 1;
    }
    squares.value() - 2.0 * mixed.value() + 2.0 * products.value()
}

/// Σ_{i<N−m} Σ_{k=1}^{m/2} (1/k)·(c_i + c_{i+m} − c_{i+k} − c_{i+m−k})² for even
/// m ≥ 2, N = c.len() > m. Blocks started after `stop` is raised are skipped
/// (the sum is then meaningless).
pub fn theo1_sum(c: &[f64], m: usize, stop: &Interrupt) -> f64 {
    let h = m / 2;
    let starts = c.len() - m;
    let w: Vec<f64> = (1..=h).map(|k| 1.0 / k as f64).collect();
    let mut harmonic = vec![0.0; h + 1];
    let mut run = Neumaier::new();
    for k in 1..=h {
        run.add(w[k - 1]);
        harmonic[k] = run.value();
    }
    let block = BLOCK_IN_M * m;
    let blocks = starts.div_ceil(block);
    let parts: Vec<f64> = (0..blocks)
        .into_par_iter()
        .map(|bk| {
            if stop.raised() {
                return 0.0;
            }
            let i0 = bk * block;
            let b = block.min(starts - i0);
            let span = b + m;
            let f = local_phase(&c[i0..i0 + span]);
            block_sum(&f, b, m, &w, &harmonic)
        })
        .collect();
    parts.into_iter().sum::<Neumaier>().value()
}

/// c minus its least-squares line (about the middle of the span).
fn local_phase(c: &[f64]) -> Vec<f64> {
    let c0 = c[0];
    let (mean, slope) = least_squares_line(|t| c[t] - c0, c.len());
    let centre = (c.len() as f64 - 1.0) / 2.0;
    c.iter()
        .enumerate()
        .map(|(t, v)| (v - c0 - mean) - slope * (t as f64 - centre))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::allan::test_signals::{integrate, kernel_case, noise, offset_pair};
    use crate::interrupt::NEVER;

    fn direct(c: &[f64], m: usize) -> f64 {
        let h = m / 2;
        let mut s = 0.0;
        for i in 0..c.len() - m {
            for k in 1..=h {
                let a = c[i] + c[i + m] - c[i + k] - c[i + m - k];
                s += a * a / k as f64;
            }
        }
        s
    }

    #[test]
    fn matches_the_definition() {
        // Random-walk FM phase far from zero is the hard case for the expansion;
        // the reference is the direct sum of the same values with the offset
        // taken off again (exactly, by Sterbenz), as Theo1 ignores it.
        let white = noise(1200, 1);
        let walk = integrate(&white);
        let walk2 = integrate(&walk);
        for c in [&white, &walk, &walk2] {
            let (shifted, c) = offset_pair(c, 1e6);
            for m in [2, 4, 10, 64, 98, 200, 400, 600, 800, 1000, 1198] {
                let (fast, slow) = (theo1_sum(&shifted, m, &NEVER), direct(&c, m));
                assert!(
                    (fast - slow).abs() <= 1e-12 * slow,
                    "m {m}: {fast} vs {slow} ({:e})",
                    (fast - slow).abs() / slow
                );
            }
        }
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig { cases: 200, ..Default::default() })]
        #[test]
        fn any_length_and_factor_matches_the_definition(
            (m_pick, shifted, c) in kernel_case(700)
        ) {
            // Even m from 2 to n − 1.
            let n = c.len();
            let m = 2 * (1 + (m_pick * ((n - 1) / 2 - 1) as f64) as usize);
            let (fast, slow) = (theo1_sum(&shifted, m, &NEVER), direct(&c, m));
            proptest::prop_assert!((fast - slow).abs() <= 1e-10 * slow + 1e-300, "n {} m {}: {} vs {}", n, m, fast, slow);
        }
    }
}
