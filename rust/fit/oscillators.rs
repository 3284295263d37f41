//! The oscillating components of a structure as the search handles them: the
//! tones' frequencies and the resonance's frequency, damping time and whether
//! it has a quadrature part (its skew), with the design columns each takes.

use super::basis;

/// Most tones in a structure. Two lines are common where one sensor sits on
/// something that moves (a parked vehicle's two modes, a dither line beside a
/// building's sway), and each leaves the other's misfit: with one of them
/// undescribed, the discrepancy it keeps hides what describing the other gains
/// (a simulated 100 Hz gyro with lines at 3.3 and 0.2 Hz: no tone was kept on
/// two of three axes, covering 29–48 % of taus).
pub const MAX_TONES: usize = 2;

/// The tones' frequencies (Hz) of a structure, in the order they were found.
#[derive(Debug, Clone, Copy, Default)]
pub struct Tones {
    freq: [f64; MAX_TONES],
    len: usize,
}

impl PartialEq for Tones {
    /// The same frequencies (the unused slots do not count).
    fn eq(&self, other: &Self) -> bool {
        self.as_slice() == other.as_slice()
    }
}

impl Tones {
    /// No tone.
    pub const NONE: Self = Self {
        freq: [0.0; MAX_TONES],
        len: 0,
    };

    /// The first [`MAX_TONES`] of `freqs`.
    pub fn from_slice(freqs: &[f64]) -> Self {
        freqs.iter().fold(Self::NONE, |t, &f| t.with(f))
    }

    pub fn as_slice(&self) -> &[f64] {
        &self.freq[..self.len]
    }

    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    pub fn is_full(&self) -> bool {
        self.len == MAX_TONES
    }

    /// These tones and `f` (unchanged when already full).
    pub fn with(mut self, f: f64) -> Self {
        if self.len < MAX_TONES {
            self.freq[self.len] = f;
            self.len += 1;
        }
        self
    }

    /// These tones without the `k`-th.
    pub fn without(self, k: usize) -> Self {
        let mut out = Self::NONE;
        for (j, &f) in self.as_slice().iter().enumerate() {
            if j != k {
                out = out.with(f);
            }
        }
        out
    }

    /// These tones with the `k`-th at `f`.
    pub fn replaced(mut self, k: usize, f: f64) -> Self {
        if k < self.len {
            self.freq[k] = f;
        }
        self
    }
}

/// A resonance: its frequency f_r (Hz), its damping time τr (s) and whether it
/// has a quadrature part (`basis::skewed_resonance`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Resonance {
    pub freq: f64,
    pub tau: f64,
    /// With a quadrature part: two columns, the edges skew = ±1 of its cone, so
    /// that NNLS keeps the spectrum non-negative (a coefficient on each: r² their
    /// sum, the skew their difference over it). Without: one column, skew 0.
    pub skewed: bool,
}

impl Resonance {
    /// Columns of the design the resonance takes.
    pub fn columns(self) -> usize {
        1 + usize::from(self.skewed)
    }

    /// Quality factor Q = πf_rτr.
    pub fn quality(self) -> f64 {
        std::f64::consts::PI * self.freq * self.tau
    }

    /// (u, θ) at rate `fs` (`basis::resonance_rates`).
    pub fn rates(self, fs: f64) -> (f64, f64) {
        basis::resonance_rates(self.freq, self.tau, fs)
    }

    /// Whether the quadrature part vanishes (θ = π: the resonance at fs/2).
    fn at_nyquist(self, fs: f64) -> bool {
        let (u, theta) = self.rates(fs);
        !basis::quadrature_bound(u, theta).is_finite()
    }

    /// Allan variance of column `which` (< [`Self::columns`]) at cluster size
    /// `m`: the plain form, or the cone's edge skew = +1 (0) or −1 (1). At fs/2
    /// the quadrature part vanishes and the second edge is a zero column.
    pub fn column(self, m: f64, fs: f64, which: usize) -> f64 {
        let (u, theta) = self.rates(fs);
        match (self.skewed, which) {
            (false, _) => basis::resonance(m, u, theta),
            (true, 0) => basis::skewed_resonance(m, u, theta, 1.0),
            (true, _) if self.at_nyquist(fs) => 0.0,
            (true, _) => basis::skewed_resonance(m, u, theta, -1.0),
        }
    }

    /// Variance r² and skew from the coefficients of its columns.
    pub fn variance_and_skew(self, coef: &[f64], fs: f64) -> (f64, f64) {
        if !self.skewed {
            return (coef[0], 0.0);
        }
        let r2 = coef[0] + coef[1];
        if r2 <= 0.0 || self.at_nyquist(fs) {
            return (r2, 0.0);
        }
        (r2, (coef[0] - coef[1]) / r2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tones_add_remove_and_replace_by_slot() {
        let two = Tones::NONE.with(1.0).with(2.0);
        assert_eq!(two.as_slice(), &[1.0, 2.0]);
        assert!(two.is_full());
        assert_eq!(two.with(3.0), two, "a full set takes no more");
        assert_eq!(two.without(0).as_slice(), &[2.0]);
        assert_eq!(two.replaced(1, 5.0).as_slice(), &[1.0, 5.0]);
        assert_eq!(Tones::from_slice(&[4.0, 5.0, 6.0]).as_slice(), &[4.0, 5.0]);
        // Equal frequencies are equal whatever an unused slot held before.
        assert_eq!(two.without(1), Tones::NONE.with(1.0));
        assert_eq!(Tones::NONE.with(1.0).with(2.0).without(1).len(), 1);
    }
}
