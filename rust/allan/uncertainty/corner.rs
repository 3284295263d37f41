//! Phase noise that begins beyond the first tau.
//!
//! The EDF of white and flicker phase noise (α = 2, 1) grows with the number of
//! independent phase points, N, not with N/m: at white PM every phase point is
//! its own draw. That holds when the phase is white from one sample on. A
//! bounded process — a mount that rocks and comes back, a temperature that
//! cycles — makes the phase look white only beyond its correlation time τc:
//! shorter taus identify frequency noise, longer ones phase noise, and the phase
//! points within τc of each other are one draw, not many. Greenhall's EDF at
//! α = 2 then counts N where there are N·τ₀/τc draws, and overstates the EDF by
//! as much as τc/τ₀, which is thousands for a slow correlation time at a high
//! sample rate.
//!
//! So where a channel's phase noise begins at a tau beyond the first (the
//! corner), its phase points are counted at that spacing: the EDF is the one
//! of the phase decimated by the corner, m/corner and N/corner, and never more
//! than the undecimated one. Phase noise identified from the first tau on is
//! left as Greenhall has it.

/// Per element of one channel's series of one statistic (`ms` the averaging
/// factors, `alpha` the noise types, both in the same order): the averaging
/// factor at which the run of phase noise (α ≥ 1) that holds it began, or 1
/// where its noise is frequency noise or its run began at the smallest factor.
pub fn phase_noise_corners(ms: &[usize], alpha: &[i32]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..ms.len()).collect();
    order.sort_by_key(|&k| ms[k]);
    let mut corners = vec![1; ms.len()];
    let mut start: Option<usize> = None;
    for (rank, &k) in order.iter().enumerate() {
        if alpha[k] < 1 {
            start = None;
            continue;
        }
        let begin = *start.get_or_insert(if rank == 0 { 1 } else { ms[k] });
        corners[k] = begin;
    }
    corners
}

/// `edf_of(m, n_phase)` counted with the phase points `corner` apart: the
/// smaller of it at (m, n_phase) and at (m/corner, n_phase/corner).
pub fn edf_beyond_corner(
    edf_of: impl Fn(usize, usize) -> f64,
    m: usize,
    n_phase: usize,
    corner: usize,
) -> f64 {
    let full = edf_of(m, n_phase);
    if corner <= 1 {
        return full;
    }
    let c = corner as f64;
    let m_coarse = ((m as f64 / c).round() as usize).max(1);
    let n_coarse = ((n_phase as f64 / c) as usize).max(2 * m_coarse + 1);
    let coarse = edf_of(m_coarse, n_coarse);
    if coarse.is_finite() && coarse > 0.0 && (full.is_nan() || coarse < full) {
        coarse
    } else {
        full
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::allan::uncertainty::edf::{greenhall_edf, Estimator};

    #[test]
    fn corners_start_where_phase_noise_starts() {
        let ms = [1, 2, 4, 8, 16, 32];
        assert_eq!(
            phase_noise_corners(&ms, &[0, 0, 1, 2, 2, 2]),
            vec![1, 1, 4, 4, 4, 4]
        );
        // Phase noise from the first tau on keeps Greenhall's count.
        assert_eq!(
            phase_noise_corners(&ms, &[2, 2, 0, 2, 2, 0]),
            vec![1, 1, 1, 8, 8, 1]
        );
        // Order of the series does not matter.
        assert_eq!(phase_noise_corners(&[8, 1, 4], &[2, 0, 2]), vec![4, 1, 4]);
    }

    #[test]
    fn a_late_corner_lowers_the_white_phase_edf_and_never_raises_it() {
        let est = Estimator {
            d: 2,
            overlapping: true,
            modified: false,
        };
        let edf = |m, n| greenhall_edf(2, est, m, n);
        let n = 184_800;
        let full = edf(4000, n);
        let late = edf_beyond_corner(edf, 4000, n, 2500);
        assert!(full > 50_000.0, "{full}");
        assert!(late > 10.0 && late < 100.0, "{late}");
        assert_eq!(edf_beyond_corner(edf, 4000, n, 1), full);
        // Frequency noise: the decimated count is not smaller, so nothing changes.
        let white_fm = |m, n| greenhall_edf(0, est, m, n);
        let kept = edf_beyond_corner(white_fm, 4000, n, 2500);
        assert!(kept <= white_fm(4000, n));
    }
}
