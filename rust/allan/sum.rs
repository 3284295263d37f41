//! Compensated summation. The Allan family works on long running sums, where a
//! plain `+=` loses the low digits that the statistics are made of.

/// Neumaier's improved Kahan–Babuška summation: the running error term `comp`
/// captures what each addition rounds away, whichever operand is larger.
#[derive(Clone, Copy, Debug, Default)]
pub struct Neumaier {
    sum: f64,
    comp: f64,
}

impl Neumaier {
    pub fn new() -> Self {
        Self::default()
    }

    #[inline(always)]
    pub fn add(&mut self, value: f64) {
        let t = self.sum + value;
        if self.sum.abs() >= value.abs() {
            self.comp += (self.sum - t) + value;
        } else {
            self.comp += (value - t) + self.sum;
        }
        self.sum = t;
    }

    #[inline(always)]
    pub fn value(&self) -> f64 {
        self.sum + self.comp
    }
}

/// Adds the values in iteration order: `parts.into_iter().sum::<Neumaier>().value()`
/// is the ordered compensated sum that makes parallel reductions independent of
/// the thread count.
impl std::iter::Sum<f64> for Neumaier {
    fn sum<I: Iterator<Item = f64>>(values: I) -> Self {
        let mut total = Neumaier::new();
        for v in values {
            total.add(v);
        }
        total
    }
}

impl<'a> std::iter::Sum<&'a f64> for Neumaier {
    fn sum<I: Iterator<Item = &'a f64>>(values: I) -> Self {
        values.copied().sum()
    }
}

/// Column-wise compensated totals of rows of partial sums (one row per parallel
/// task, `width` columns), each column added in row order.
pub fn column_totals(rows: &[Vec<f64>], width: usize) -> Vec<f64> {
    let mut totals = vec![Neumaier::new(); width];
    for row in rows {
        for (total, value) in totals.iter_mut().zip(row) {
            total.add(*value);
        }
    }
    totals.iter().map(Neumaier::value).collect()
}

/// Sum of squares of `f(k)` for `k` in `range` (stepping by `step`). Terms are
/// non-negative, so a plain sum over a block of 256 has relative error below
/// 256·ε; blocks are then added with compensation. Eight independent lanes let
/// the compiler vectorise the inner loop.
#[inline(always)]
pub fn sum_of_squares(count: usize, mut term: impl FnMut(usize) -> f64) -> f64 {
    const BLOCK: usize = 256;
    const LANES: usize = 8;
    let mut total = Neumaier::new();
    let mut start = 0;
    while start < count {
        let end = (start + BLOCK).min(count);
        let mut lanes = [0.0f64; LANES];
        let mut i = start;
        while i + LANES <= end {
            for (lane, acc) in lanes.iter_mut().enumerate() {
                let v = term(i + lane);
                *acc += v * v;
            }
            i += LANES;
        }
        while i < end {
            let v = term(i);
            lanes[0] += v * v;
            i += 1;
        }
        total.add(lanes.iter().sum());
        start = end;
    }
    total.value()
}

/// Σ term(k) for k < count: blocks of 256 in four plain lanes, blocks added with
/// compensation (per-term compensation would cost more than the terms).
#[inline(always)]
pub fn blocked_sum(count: usize, mut term: impl FnMut(usize) -> f64) -> f64 {
    const BLOCK: usize = 256;
    let mut total = Neumaier::new();
    let mut start = 0;
    while start < count {
        let end = (start + BLOCK).min(count);
        let mut lanes = [0.0f64; 4];
        let mut k = start;
        while k + 4 <= end {
            for (lane, acc) in lanes.iter_mut().enumerate() {
                *acc += term(k + lane);
            }
            k += 4;
        }
        while k < end {
            lanes[0] += term(k);
            k += 1;
        }
        total.add((lanes[0] + lanes[1]) + (lanes[2] + lanes[3]));
        start = end;
    }
    total.value()
}

/// Σ_i (Σ_s w_s·x_s[i])² over `S` equally long streams: the overlapping
/// estimators' sum of squared differences, c[i+2m] − 2c[i+m] + c[i] and the like.
/// Slices of fixed-size chunks let the compiler drop bounds checks and vectorise;
/// blocks of 256 squares are summed plainly and then added with compensation.
#[inline(always)]
pub fn sum_of_squared_combinations<const S: usize>(streams: [&[f64]; S], weights: [f64; S]) -> f64 {
    const BLOCK: usize = 256;
    let len = streams.iter().map(|s| s.len()).min().unwrap_or(0);
    let mut total = Neumaier::new();
    let mut start = 0;
    while start < len {
        let end = (start + BLOCK).min(len);
        let blocks: [&[f64]; S] = std::array::from_fn(|s| &streams[s][start..end]);
        let chunked: [(&[[f64; 8]], &[f64]); S] =
            std::array::from_fn(|s| blocks[s].as_chunks::<8>());
        let mut lanes = [0.0f64; 8];
        for k in 0..chunked[0].0.len() {
            let mut v = [0.0f64; 8];
            for s in 0..S {
                let chunk = &chunked[s].0[k];
                for lane in 0..8 {
                    v[lane] += weights[s] * chunk[lane];
                }
            }
            for lane in 0..8 {
                lanes[lane] += v[lane] * v[lane];
            }
        }
        for r in 0..chunked[0].1.len() {
            let v: f64 = (0..S).map(|s| weights[s] * chunked[s].1[r]).sum();
            lanes[0] += v * v;
        }
        total.add(lanes.iter().sum());
        start = end;
    }
    total.value()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn neumaier_keeps_small_terms_next_to_large_ones() {
        let mut acc = Neumaier::new();
        for v in [1.0, 1e100, 1.0, -1e100] {
            acc.add(v);
        }
        assert_eq!(acc.value(), 2.0);
    }

    #[test]
    fn sum_trait_adds_in_order_with_compensation() {
        let values = [1.0, 1e100, 1.0, -1e100];
        assert_eq!(values.iter().sum::<Neumaier>().value(), 2.0);
        let rows = vec![vec![1.0, 1e100], vec![1e100, 1.0], vec![-1e100, -1e100]];
        assert_eq!(column_totals(&rows, 2), vec![1.0, 1.0]);
    }

    #[test]
    fn sum_of_squares_matches_closed_form() {
        // Σ_{k=1}^{n} k² = n(n+1)(2n+1)/6, exact in f64 for this n.
        let n = 1000usize;
        let s = sum_of_squares(n, |k| (k + 1) as f64);
        assert_eq!(s, (n * (n + 1) * (2 * n + 1) / 6) as f64);
    }

    #[test]
    fn combinations_match_the_closure_form() {
        let c: Vec<f64> = (0..1000)
            .map(|k| ((k * 7919) % 113) as f64 - 50.0)
            .collect();
        let m = 7;
        let terms = c.len() - 2 * m;
        let fast = sum_of_squared_combinations(
            [&c[2 * m..2 * m + terms], &c[m..m + terms], &c[..terms]],
            [1.0, -2.0, 1.0],
        );
        let slow = sum_of_squares(terms, |k| c[k + 2 * m] - 2.0 * c[k + m] + c[k]);
        assert_eq!(fast, slow);
    }

    #[test]
    fn sum_of_squares_of_nothing_is_zero() {
        assert_eq!(sum_of_squares(0, |_| 1.0), 0.0);
    }
}
