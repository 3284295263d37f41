//! Kernels that make the estimators fast, each checked against the direct
//! definition in its tests; none knows which statistic calls it.
//!
//! - `exact_phase`: the phase as exact integers with its autocorrelation at
//!   every lag (limb FFTs), for expansions that would cancel in double precision;
//! - `theo1_sweep`: the Theo1 sum at many averaging factors at once, exactly;
//! - `blocked`: the overlapping Allan and Hadamard sums at all taus in one sweep;
//! - `reflected`: the MTOT/HTOT sum in O(n) per tau;
//! - `theo1_fft`: the Theo1 sum in O(n log² m) per tau;
//! - `sliding`: sliding weighted sums (direct or by FFT) for `theo1_fft`.

pub mod blocked;
pub mod exact_phase;
pub mod limbs;
pub mod reflected;
pub mod sliding;
pub mod theo1_fft;
pub mod theo1_sweep;
