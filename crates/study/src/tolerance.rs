//! Per-tooth spacing errors drawn from an accuracy grade of ISO 1328-1:2013.
//!
//! The standard: ISO 1328-1:2013 "Cylindrical gears -- ISO system of flank tolerance
//! classification -- Part 1", clause 5.3, tolerance of the single pitch deviation
//! `f_pT = (0.001 d + 0.4 m_n + 5) sqrt(2)^(A - 5)` in um, with the reference diameter `d` and
//! the normal module `m_n` in mm and the flank tolerance class `A` = 1 (finest) .. 11;
//! rounded as the standard says (to 0.1 um below 10 um, to 1 um above). A spline's teeth are
//! spaced like a gear's, so the same grades apply to the hub and shaft splines of a clutch
//! (DIN 5480 refers to the DIN 3962 gear qualities in the same way); the module is taken as
//! `2 R / n` (pitch diameter over teeth).
//!
//! The mapping to the scene's `tooth_spacing_errors_m` (the position error of each tooth at the
//! pitch circle) is ours, see docs/DECISIONS.md "Studies":
//! 1. single pitch deviations `f_p,k` (tooth k to tooth k + 1), k = 0..n, independent,
//!    normal with standard deviation `f_pT / 2` truncated to `+-f_pT` (every pitch within
//!    tolerance, the tolerance a 2-sigma limit), or uniform in `+-f_pT`;
//! 2. minus their mean: around a closed ring the pitch deviations sum to zero;
//! 3. the tooth positions are their running sum (`e_0 = 0`, `e_k = f_p,0 + ... + f_p,k-1`),
//!    less the mean position (a common rotation of all teeth is not an error: it is the
//!    disc's angle).

use crate::rng::Stream;

/// The tolerance classes ISO 1328-1:2013 defines.
pub const GRADES: std::ops::RangeInclusive<u32> = 1..=11;

/// How single pitch deviations are spread within the tolerance.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PitchDistribution {
    /// Normal, standard deviation `f_pT / 2`, truncated to `+-f_pT`.
    TruncatedNormal,
    /// Uniform in `+-f_pT`.
    Uniform,
}

/// ISO 1328-1:2013 single pitch tolerance `f_pT` in m for tolerance class `grade`, reference
/// diameter `d_m` (m) and module `module_m` (m).
pub fn single_pitch_tolerance_m(grade: u32, d_m: f64, module_m: f64) -> f64 {
    let (d_mm, m_mm) = (d_m * 1e3, module_m * 1e3);
    let um = (0.001 * d_mm + 0.4 * m_mm + 5.0) * 2f64.sqrt().powi(grade as i32 - 5);
    let rounded = if um < 10.0 {
        (um * 10.0).round() / 10.0
    } else {
        um.round()
    };
    rounded * 1e-6
}

/// The position errors (m) of the `teeth` teeth of a spline of pitch radius `pitch_radius_m`
/// made to tolerance class `grade`, drawn from `rng` as the module doc says.
pub fn spacing_errors_m(
    grade: u32,
    teeth: u32,
    pitch_radius_m: f64,
    dist: PitchDistribution,
    rng: &mut Stream,
) -> Vec<f64> {
    let n = teeth as usize;
    if n == 0 {
        return Vec::new();
    }
    let d = 2.0 * pitch_radius_m;
    let fpt = single_pitch_tolerance_m(grade, d, d / teeth as f64);
    let mut pitch: Vec<f64> = (0..n)
        .map(|_| match dist {
            PitchDistribution::TruncatedNormal => rng.truncated_normal(0.0, fpt / 2.0, -fpt, fpt),
            PitchDistribution::Uniform => rng.uniform(-fpt, fpt),
        })
        .collect();
    let mean = pitch.iter().sum::<f64>() / n as f64;
    pitch.iter_mut().for_each(|p| *p -= mean);
    let mut pos = Vec::with_capacity(n);
    let mut e = 0.0;
    for p in &pitch {
        pos.push(e);
        e += p;
    }
    let mean_pos = pos.iter().sum::<f64>() / n as f64;
    pos.iter_mut().for_each(|x| *x -= mean_pos);
    pos
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Worked value of the formula: d = 462 mm, m = 3 mm (the paper's spline), class 5:
    /// 0.462 + 1.2 + 5 = 6.662 -> 6.7 um; class 8: 6.662 * 2^1.5 = 18.84 -> 19 um.
    #[test]
    fn tolerance_formula_and_rounding() {
        let t5 = single_pitch_tolerance_m(5, 0.462, 3e-3);
        assert!((t5 - 6.7e-6).abs() < 1e-12, "{t5}");
        let t8 = single_pitch_tolerance_m(8, 0.462, 3e-3);
        assert!((t8 - 19e-6).abs() < 1e-12, "{t8}");
        // each class step is a factor sqrt(2) before rounding
        let t6 = single_pitch_tolerance_m(6, 0.462, 3e-3);
        assert!((t6 - 9.4e-6).abs() < 1e-12, "{t6}");
    }

    /// The pitches between neighbouring teeth (the differences of the positions, around the
    /// ring) are the drawn deviations less their mean: within f_pT plus that mean, and they sum
    /// to zero; the positions have zero mean.
    #[test]
    fn positions_close_the_ring_and_pitches_stay_in_tolerance() {
        let mut rng = Stream::new(3, 0, 0);
        let (grade, n, r) = (7, 154, 0.231);
        let fpt = single_pitch_tolerance_m(grade, 2.0 * r, 2.0 * r / n as f64);
        for dist in [
            PitchDistribution::TruncatedNormal,
            PitchDistribution::Uniform,
        ] {
            let e = spacing_errors_m(grade, n, r, dist, &mut rng);
            assert_eq!(e.len(), n as usize);
            assert!(e.iter().sum::<f64>().abs() < 1e-15);
            let pitches: Vec<f64> = (0..e.len()).map(|k| e[(k + 1) % e.len()] - e[k]).collect();
            assert!(pitches.iter().sum::<f64>().abs() < 1e-15);
            // the mean removed is at most f_pT (and in practice far smaller)
            let max = pitches.iter().fold(0f64, |m, p| m.max(p.abs()));
            assert!(
                max <= 1.2 * fpt,
                "largest pitch deviation {max} vs f_pT {fpt}"
            );
            assert!(max > 0.3 * fpt, "deviations drawn at all: {max}");
        }
    }
}
