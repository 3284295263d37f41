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
    fn sum_of_squares_matches_closed_form() {
        // Σ_{k=1}^{n} k² = n(n+1)(2n+1)/6, exact in f64 for this n.
        let n = 1000usize;
        let s = sum_of_squares(n, |k| (k + 1) as f64);
        assert_eq!(s, (n * (n + 1) * (2 * n + 1) / 6) as f64);
    }

    #[test]
    fn sum_of_squares_of_nothing_is_zero() {
        assert_eq!(sum_of_squares(0, |_| 1.0), 0.0);
    }
}
