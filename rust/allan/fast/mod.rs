//! Kernels that make the estimators fast, each checked against the direct
//! definition in its tests; none knows which statistic calls it.
//!
//! - `blocked`: the overlapping Allan and Hadamard sums at all taus in one sweep;
//! - `reflected`: the MTOT/HTOT sum in O(n) per tau;
//! - `theo1_fft`: the Theo1 sum in O(n log² m) per tau;
//! - `sliding`: sliding weighted sums (direct or by FFT) for `theo1_fft`.

pub mod blocked;
pub mod reflected;
pub mod sliding;
pub mod theo1_fft;
