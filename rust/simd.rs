//! Which instruction set the CPU-dispatched kernels use: the best the CPU has,
//! or a lower one that a user or a test forces, so that every path can be run,
//! and compared with the others, on one machine.
//!
//! Every kernel that dispatches on the level gives the same bits on every level
//! (the vector kernels do the scalar kernels' operations in the same order), with
//! one exception: rustfft's AVX and SSE kernels round differently, so the FFT
//! sliding sums (Theo1 from m = 256 on) agree across [`Level::Scalar`] and the
//! other levels to a few ulps only. From [`Level::Avx2`] up they use the same
//! FFT kernels and so give the same bits.

use std::sync::atomic::{AtomicU8, Ordering};
use std::sync::{Arc, OnceLock};

use rustfft::{Fft, FftPlanner, FftPlannerScalar};

/// An instruction-set level, ordered: each implies the ones below it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Level {
    /// The portable build (SSE2 on x86-64).
    Scalar,
    /// AVX2 with FMA.
    Avx2,
    /// AVX-512 F, DQ and BW, on top of AVX2 (every CPU with DQ has BW).
    Avx512,
    /// AVX-512 IFMA (52-bit integer multiply-add) and VBMI (byte permutes), with
    /// BMI2, on top of AVX-512 (every CPU with IFMA has the other two).
    Ifma,
}

impl Level {
    pub const ALL: [Level; 4] = [Level::Scalar, Level::Avx2, Level::Avx512, Level::Ifma];

    pub fn name(self) -> &'static str {
        match self {
            Level::Scalar => "scalar",
            Level::Avx2 => "avx2",
            Level::Avx512 => "avx512",
            Level::Ifma => "ifma",
        }
    }

    pub fn from_name(name: &str) -> Option<Level> {
        Level::ALL.into_iter().find(|l| l.name() == name)
    }
}

/// No level forced: the CPU's own.
const UNFORCED: u8 = u8::MAX;

static FORCED: AtomicU8 = AtomicU8::new(UNFORCED);

/// The best level this CPU has.
pub fn detected() -> Level {
    static DETECTED: OnceLock<Level> = OnceLock::new();
    *DETECTED.get_or_init(detect)
}

#[cfg(target_arch = "x86_64")]
fn detect() -> Level {
    use std::arch::is_x86_feature_detected as has;
    if !(has!("avx2") && has!("fma")) {
        Level::Scalar
    } else if !(has!("avx512f") && has!("avx512dq") && has!("avx512bw")) {
        Level::Avx2
    } else if !(has!("avx512ifma") && has!("avx512vbmi") && has!("bmi2")) {
        Level::Avx512
    } else {
        Level::Ifma
    }
}

#[cfg(not(target_arch = "x86_64"))]
fn detect() -> Level {
    Level::Scalar
}

/// The level the kernels use now: the forced one, lowered to what the CPU has.
pub fn level() -> Level {
    let forced = FORCED.load(Ordering::Relaxed);
    let cpu = detected();
    Level::ALL
        .get(forced as usize)
        .map_or(cpu, |&wanted| wanted.min(cpu))
}

/// Forces the kernels down to `level` (`None`: the CPU's best again). A level
/// above the CPU's runs as the CPU's.
pub fn force(level: Option<Level>) {
    let code = level.map_or(UNFORCED, |l| l as u8);
    FORCED.store(code, Ordering::Relaxed);
}

/// FFT plans for the level they were made at: rustfft's AVX kernels from
/// [`Level::Avx2`] on (they need AVX and FMA, which that level implies), its
/// SSE or scalar kernels below it, never a kernel above the level.
pub struct FftPlans {
    level: Level,
    planner: Planner,
}

enum Planner {
    Chosen(FftPlanner<f64>),
    #[cfg(target_arch = "x86_64")]
    Sse(rustfft::FftPlannerSse<f64>),
    Scalar(FftPlannerScalar<f64>),
}

impl FftPlans {
    /// Plans for the current [`level`].
    pub fn new() -> Self {
        let level = level();
        FftPlans {
            level,
            planner: Self::planner(level),
        }
    }

    #[cfg(target_arch = "x86_64")]
    fn planner(level: Level) -> Planner {
        if level >= Level::Avx2 {
            Planner::Chosen(FftPlanner::new())
        } else if let Ok(sse) = rustfft::FftPlannerSse::new() {
            Planner::Sse(sse)
        } else {
            Planner::Scalar(FftPlannerScalar::new())
        }
    }

    #[cfg(not(target_arch = "x86_64"))]
    fn planner(_level: Level) -> Planner {
        Planner::Chosen(FftPlanner::new())
    }

    /// Whether these plans still belong to the current [`level`].
    pub fn is_current(&self) -> bool {
        self.level == level()
    }

    pub fn forward(&mut self, len: usize) -> Arc<dyn Fft<f64>> {
        match &mut self.planner {
            Planner::Chosen(p) => p.plan_fft_forward(len),
            #[cfg(target_arch = "x86_64")]
            Planner::Sse(p) => p.plan_fft_forward(len),
            Planner::Scalar(p) => p.plan_fft_forward(len),
        }
    }

    pub fn inverse(&mut self, len: usize) -> Arc<dyn Fft<f64>> {
        match &mut self.planner {
            Planner::Chosen(p) => p.plan_fft_inverse(len),
            #[cfg(target_arch = "x86_64")]
            Planner::Sse(p) => p.plan_fft_inverse(len),
            Planner::Scalar(p) => p.plan_fft_inverse(len),
        }
    }
}

impl Default for FftPlans {
    fn default() -> Self {
        Self::new()
    }
}

/// Runs `f` once at every level this CPU has, lowest first, and restores the
/// unforced level afterwards: for tests that compare the paths.
#[cfg(test)]
pub fn at_every_level(mut f: impl FnMut(Level)) {
    // Tests in one binary run on several threads and share the forced level.
    static LOCK: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _guard = LOCK.lock().unwrap_or_else(|e| e.into_inner());
    for l in Level::ALL.into_iter().filter(|&l| l <= detected()) {
        force(Some(l));
        assert_eq!(level(), l);
        f(l);
    }
    force(None);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for l in Level::ALL {
            assert_eq!(Level::from_name(l.name()), Some(l));
        }
        assert_eq!(Level::from_name("sse"), None);
    }

    #[test]
    fn a_forced_level_is_lowered_to_the_cpus() {
        at_every_level(|l| {
            assert!(l <= detected());
            force(Some(Level::Ifma));
            assert_eq!(level(), detected());
        });
        assert_eq!(level(), detected());
    }
}
