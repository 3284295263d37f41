//! The sum that MTOT and HTOT are made of, in O(n) per averaging factor:
//!
//!   Σ_i Σ_{j<6m} D_j(i)²,
//!
//! where, for every subsequence i of l = 3m values v_i … v_{i+l−1}, the values
//! are detrended (the slope between the means of the first and last halves is
//! removed), extended by uninverted even reflection to 9m values x*, and
//! D_j = S(j) − 2S(j+m) + S(j+2m) with S(a) = Σ x*[a..a+m). MTOT takes v = phase,
//! HTOT v = rate (`estimators/mtot_htot.rs` has the definitions, the direct
//! O(n·m) form and the threshold between the two).
//!
//! How. With P the prefix sum of v, every D_j(i) is a fixed combination of a few
//! P values. Split j = k·m + j' (k < 6, j' < m): inside one of those six classes
//! each of the four prefix values that make D_j is either unreflected, at
//! i + j' + c, or reflected, at i − j' + c, and the detrending adds terms that
//! depend on i alone times a quadratic in j'. So
//!
//!   D = F₊(i + j') + F₋(i − j') + G₀(i) + G₁(i)·j' + G₂(i)·j'²,
//!
//! with F₊, F₋, G sequences built from P. Summed over a rectangle of (i, j'),
//! the square expands into sums along diagonals (F₊², F₋²: one weight per index),
//! an anti-diagonal sum of F₊·F₋ (for each u = i + j', the v = i − j' form a
//! range of one parity: a stride-2 prefix sum), and polynomial-weighted window
//! sums of F± against G (prefix moments). Each is O(length).
//!
//! Digits. The expansion cancels: its terms are products of prefix sums, much
//! larger than D². Every D is unchanged when a linear function is added to v
//! (a quadratic to P), so each block of subsequences builds P from v minus a
//! local reference line; the block spans only a few times l values, which keeps
//! the terms within a small factor of their sum. Short averaging factors go the
//! direct way (`mtot_htot::REFLECTED_FROM`), where blocks would be too short for that.

use rayon::prelude::*;

use crate::allan::phase::least_squares_line;
use crate::allan::sum::{blocked_sum, Neumaier};
use crate::interrupt::Interrupt;

/// Subsequences per block, in units of m: the block's values span (this + 3)·m,
/// so the expansion's terms stay within ~ (span / m)^5 of the result even for
/// random-walk FM.
const BLOCK_IN_M: usize = 2;

/// One of the six classes of j: D = F₊(i + j') + F₋(i − j') + G(i, j').
#[derive(Clone, Debug)]
struct Class {
    /// (coefficient, offset c) of P(i + j' + c) terms.
    plus: Vec<(f64, usize)>,
    /// (coefficient, offset c) of P(i − j' + c) terms.
    minus: Vec<(f64, usize)>,
    /// Coefficient of Z(l) = P(i+l) − P(i) − slope·l(l−1)/2.
    z_end: f64,
    /// Coefficient of P(i).
    p_start: f64,
    /// slope · (poly[0] + poly[1]·j' + poly[2]·j'²).
    poly: [f64; 3],
}

fn push_atom(atoms: &mut Vec<(f64, usize)>, coef: f64, offset: usize) {
    match atoms.iter_mut().find(|(_, c)| *c == offset) {
        Some(atom) => atom.0 += coef,
        None => atoms.push((coef, offset)),
    }
}

/// The six classes for averaging factor m. D_j is the third difference
/// −P*(j) + 3P*(j+m) − 3P*(j+2m) + P*(j+3m) of the prefix sum P* of the extended
/// sequence, and with Z the prefix sum of the detrended subsequence,
/// P*(τ) = Z(l) − Z(l−τ) (τ ≤ l), Z(l) + Z(τ−l) (τ ≤ 2l), 3Z(l) − Z(3l−τ).
fn classes(m: usize) -> Vec<Class> {
    const THIRD_DIFFERENCE: [f64; 4] = [-1.0, 3.0, -3.0, 1.0];
    (0..6)
        .map(|k| {
            let mut class = Class {
                plus: Vec::new(),
                minus: Vec::new(),
                z_end: 0.0,
                p_start: 0.0,
                poly: [0.0; 3],
            };
            for (q, &coef) in THIRD_DIFFERENCE.iter().enumerate() {
                // τ = r·m + j'; φ = c + σ·j' is where Z is read.
                let r = k + q;
                let (times_z_end, sign, c, sigma) = match r / 3 {
                    0 => (1.0, -1.0, (3 - r) * m, -1.0),
                    1 => (1.0, 1.0, (r - 3) * m, 1.0),
                    _ => (3.0, -1.0, (9 - r) * m, -1.0),
                };
                let w = coef * sign;
                class.z_end += coef * times_z_end;
                // Z(φ) = P(i+φ) − P(i) − slope·φ(φ−1)/2.
                if sigma > 0.0 {
                    push_atom(&mut class.plus, w, c);
                } else {
                    push_atom(&mut class.minus, w, c);
                }
                class.p_start -= w;
                let cf = c as f64;
                class.poly[0] -= w * cf * (cf - 1.0) / 2.0;
                class.poly[1] -= w * sigma * (2.0 * cf - 1.0) / 2.0;
                class.poly[2] -= w / 2.0;
            }
            class.plus.retain(|&(w, _)| w != 0.0);
            class.minus.retain(|&(w, _)| w != 0.0);
            class
        })
        .collect()
}

/// Σ_{e<m} e^d·F(p + e) for d = 0, 1, 2, from prefix moments of F.
struct WindowMoments {
    prefix: Vec<[f64; 3]>,
}

impl WindowMoments {
    fn new(f: &[f64]) -> Self {
        let mut prefix = vec![[0.0f64; 3]; f.len() + 1];
        let mut acc = [0.0f64; 3];
        for (t, (&v, slot)) in f.iter().zip(prefix[1..].iter_mut()).enumerate() {
            let tf = t as f64;
            acc[0] += v;
            acc[1] += tf * v;
            acc[2] += tf * tf * v;
            *slot = acc;
        }
        Self { prefix }
    }

    #[inline]
    fn at(&self, p: usize, m: usize) -> [f64; 3] {
        let (hi, lo) = (self.prefix[p + m], self.prefix[p]);
        let (m0, m1, m2) = (hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
        let pf = p as f64;
        [m0, m1 - pf * m0, m2 - 2.0 * pf * m1 + pf * pf * m0]
    }
}

/// Per-subsequence quantities of one block: the slope removed and Z(l).
struct BlockStarts {
    slope: Vec<f64>,
    z_end: Vec<f64>,
    p_start: Vec<f64>,
}

/// Σ over subsequences i0 ≤ i < i0 + windows and j' < m of the class's D².
/// `p` holds P(i0 + t) for t ≤ windows − 1 + 3m.
fn class_sum(
    p: &[f64],
    starts: &BlockStarts,
    windows: usize,
    m: usize,
    class: &Class,
    power_sums: &[f64; 5],
) -> f64 {
    let b = windows;
    let len = b + m - 1;
    // F₊ at u = i0 + a; F₋ at v = i0 − (m − 1) + a.
    let f_plus: Vec<f64> = (0..len)
        .map(|a| class.plus.iter().map(|&(w, c)| w * p[a + c]).sum())
        .collect();
    let f_minus: Vec<f64> = (0..len)
        .map(|a| class.minus.iter().map(|&(w, c)| w * p[a + c + 1 - m]).sum())
        .collect();

    let (m_i, b_i) = (m as isize, b as isize);
    let count = |lo: isize, hi: isize| (hi - lo + 1).max(0) as f64;
    // Σ F₊(u)²·#{j' : i0 ≤ u − j' < i0 + b} and the same for F₋.
    let squares = blocked_sum(len, |a| {
        let (fp, fm) = (f_plus[a], f_minus[a]);
        let a = a as isize;
        let plus = count((a - b_i + 1).max(0), (m_i - 1).min(a));
        let minus = count((m_i - 1 - a).max(0), (m_i - 1).min(b_i + m_i - 2 - a));
        fp * fp * plus + fm * fm * minus
    });

    // Σ F₊(u)·F₋(v) over u = i + j', v = i − j': for each u, v runs over one
    // parity between max(u − 2m + 2, 2i0 − u) and min(u, 2(i0 + b − 1) − u);
    // in F₋'s local index (v − i0 + m − 1) all four bounds share that parity.
    let mut stride2 = vec![0.0; len + 2];
    for (k, &fm) in f_minus.iter().enumerate() {
        stride2[k + 2] = stride2[k] + fm;
    }
    let cross = blocked_sum(len, |a| {
        let fp = f_plus[a];
        let a = a as isize;
        let lo = (a - m_i + 1).max(m_i - 1 - a);
        let hi = (a + m_i - 1).min(2 * b_i + m_i - 3 - a);
        if hi >= lo {
            fp * (stride2[hi as usize + 2] - stride2[lo as usize])
        } else {
            0.0
        }
    });

    // 2·Σ_i Σ_d G_d(i)·Σ_j' j'^d (F₊(i + j') + F₋(i − j')) and Σ_i (Σ_d G_d j'^d)².
    let plus_moments = WindowMoments::new(&f_plus);
    let minus_moments = WindowMoments::new(&f_minus);
    let mf = m as f64 - 1.0;
    let mixed = blocked_sum(b, |i| {
        let slope = starts.slope[i];
        let g = [
            class.z_end * starts.z_end[i]
                + class.p_start * starts.p_start[i]
                + class.poly[0] * slope,
            class.poly[1] * slope,
            class.poly[2] * slope,
        ];
        let r = plus_moments.at(i, m);
        // F₋(i − j') sits at local index i + m − 1 − j' = i + e with j' = m − 1 − e.
        let w = minus_moments.at(i, m);
        let s = [
            w[0],
            mf * w[0] - w[1],
            mf * mf * w[0] - 2.0 * mf * w[1] + w[2],
        ];
        let mut term = 0.0;
        for d in 0..3 {
            term += 2.0 * g[d] * (r[d] + s[d]);
            for e in 0..3 {
                term += g[d] * g[e] * power_sums[d + e];
            }
        }
        term
    });
    squares + 2.0 * cross + mixed
}

/// Σ_i Σ_{j<6m} D_j(i)² over the `len − 3m + 1` subsequences of `values(k)`,
/// k < len. Needs m ≥ 1 and 3m ≤ len. Blocks started after `stop` is raised
/// are skipped (the sum is then meaningless).
pub fn reflected_sum<V>(values: V, len: usize, m: usize, stop: &Interrupt) -> f64
where
    V: Fn(usize) -> f64 + Sync,
{
    let l = 3 * m;
    let windows = len + 1 - l;
    let half = l / 2;
    let gap = l.div_ceil(2) as f64;
    let block = (BLOCK_IN_M * m).max(1);
    let blocks = windows.div_ceil(block);
    let classes = classes(m);
    let mut power_sums = [0.0; 5];
    for j in 0..m {
        let jf = j as f64;
        let mut pw = 1.0;
        for s in power_sums.iter_mut() {
            *s += pw;
            pw *= jf;
        }
    }
    let parts: Vec<f64> = (0..blocks)
        .into_par_iter()
        .map(|bk| {
            if stop.raised() {
                return 0.0;
            }
            let i0 = bk * block;
            let b = block.min(windows - i0);
            // P(i0 + t) of v minus the block's least-squares line, t ≤ b − 1 + l.
            let span = b - 1 + l;
            let v0 = values(i0);
            let local = |t: usize| values(i0 + t) - v0;
            let (mean, slope) = least_squares_line(local, span);
            let centre = (span as f64 - 1.0) / 2.0;
            let mut p = Vec::with_capacity(span + 1);
            let mut run = Neumaier::new();
            p.push(0.0);
            for t in 0..span {
                run.add((local(t) - mean) - slope * (t as f64 - centre));
                p.push(run.value());
            }
            let mut starts = BlockStarts {
                slope: Vec::with_capacity(b),
                z_end: Vec::with_capacity(b),
                p_start: Vec::with_capacity(b),
            };
            let lf = l as f64;
            for i in 0..b {
                let slope =
                    ((p[i + l] - p[i + l - half]) - (p[i + half] - p[i])) / half as f64 / gap;
                starts.slope.push(slope);
                starts
                    .z_end
                    .push(p[i + l] - p[i] - slope * lf * (lf - 1.0) / 2.0);
                starts.p_start.push(p[i]);
            }
            let per_class: Vec<f64> = classes
                .par_iter()
                .map(|class| class_sum(&p, &starts, b, m, class, &power_sums))
                .collect();
            per_class.into_iter().sum::<Neumaier>().value()
        })
        .collect();
    parts.into_iter().sum::<Neumaier>().value()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::allan::test_signals::{
        detrended_reflection, integrate, kernel_case, noise, offset_pair,
    };
    use crate::interrupt::NEVER;

    /// The definition, transcribed: detrend, reflect, sum D².
    fn direct(v: &[f64], m: usize) -> f64 {
        let l = 3 * m;
        let mut total = 0.0;
        for i in 0..=v.len() - l {
            let star = detrended_reflection(&v[i..i + l]);
            for j in 0..6 * m {
                let s = |a: usize| star[a..a + m].iter().sum::<f64>();
                let d = s(j) - 2.0 * s(j + m) + s(j + 2 * m);
                total += d * d;
            }
        }
        total
    }

    #[test]
    fn matches_the_definition_for_every_class_and_block_split() {
        let white = noise(400, 7);
        let walk = integrate(&white);
        let walk2 = integrate(&walk);
        for v in [&white, &walk, &walk2] {
            for m in [1, 2, 3, 4, 5, 7, 10, 16, 33, 60, 133] {
                let (fast, slow) = (reflected_sum(|k| v[k], v.len(), m, &NEVER), direct(v, m));
                assert!(
                    (fast - slow).abs() <= 1e-10 * slow,
                    "m {m}: {fast} vs {slow}"
                );
            }
        }
    }

    #[test]
    fn keeps_its_digits_on_offset_random_walks_of_phase_and_rate() {
        // Random-walk FM phase (a double integral) far from zero, and white
        // noise on a large offset: the expansion's terms dwarf the sum unless
        // each block is re-centred.
        // The reference is the direct sum without the offset (D ignores it).
        let rate = integrate(&noise(1500, 3));
        let phase = integrate(&rate);
        let white = noise(1500, 4);
        for (v, offset) in [(&phase, 1e7), (&white, 9.81e3)] {
            let (shifted, v) = offset_pair(v, offset);
            for m in [16, 100, 250, 499] {
                let fast = reflected_sum(|k| shifted[k], v.len(), m, &NEVER);
                let slow = direct(&v, m);
                assert!(
                    (fast - slow).abs() <= 1e-11 * slow,
                    "m {m}: {fast} vs {slow}"
                );
            }
        }
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig { cases: 200, ..Default::default() })]
        #[test]
        fn any_length_and_factor_matches_the_definition(
            (m_pick, shifted, v) in kernel_case(260)
        ) {
            let n = v.len();
            let m = 1 + (m_pick * (n / 3 - 1) as f64) as usize;
            let (fast, slow) = (reflected_sum(|k| shifted[k], n, m, &NEVER), direct(&v, m));
            proptest::prop_assert!((fast - slow).abs() <= 1e-10 * slow + 1e-300, "n {} m {}: {} vs {}", n, m, fast, slow);
        }
    }
}
