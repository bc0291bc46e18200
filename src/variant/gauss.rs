//! Gauss-Legendre rules in `f64` (scene load) for the float forms of the cube model.
//!
//! The same rule as the fixed point's `crate::model::quadrature` (N points over the slip
//! half-period theta in [-pi/2, pi/2], evaluated at its ceil(N/2) nodes with theta >= 0 and
//! the weights of each +-theta pair summed, normalised to a mean), computed here in full
//! `f64` precision: the float forms must not inherit the fixed point's 31-bit tables.

use core::f64::consts::{FRAC_PI_2, PI};

/// Largest number of points N.
pub const MAX_POINTS: usize = 64;

/// Half of an N-point rule over [-pi/2, pi/2] as a mean: `cos` theta_i >= 0 and `weight`
/// w_i >= 0 for i < `len` = ceil(N/2), sum of weights 1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HalfRule {
    /// cos theta_i at the nodes theta_i >= 0.
    pub cos: [f64; MAX_POINTS / 2],
    /// Weights (pairs summed), summing to 1.
    pub weight: [f64; MAX_POINTS / 2],
    /// Nodes in use, ceil(N/2).
    pub len: usize,
}

/// The N-point rule, N in 1..=64 (`None` outside). Nodes by Newton's method on the
/// three-term Legendre recurrence from Tricomi's initial guesses, to 1e-15.
pub fn half_rule(points: usize) -> Option<HalfRule> {
    if !(1..=MAX_POINTS).contains(&points) {
        return None;
    }
    let n = points as f64;
    let len = points.div_ceil(2);
    let mut rule = HalfRule {
        cos: [0.0; MAX_POINTS / 2],
        weight: [0.0; MAX_POINTS / 2],
        len,
    };
    let mut total = 0.0;
    for i in 0..len {
        // The i-th largest root of P_N, refined by Newton; P_N' from the recurrence.
        let mut t = libm::cos(PI * (i as f64 + 0.75) / (n + 0.5));
        let mut slope = 1.0;
        for _ in 0..64 {
            let (mut p, mut previous) = (1.0, 0.0);
            for k in 1..=points {
                let kf = k as f64;
                let next = ((2.0 * kf - 1.0) * t * p - (kf - 1.0) * previous) / kf;
                previous = p;
                p = next;
            }
            slope = n * (t * p - previous) / (t * t - 1.0);
            let step = p / slope;
            t -= step;
            if step.abs() <= 1e-16 {
                break;
            }
        }
        let middle = 2 * i + 1 == points;
        if middle {
            t = 0.0;
        }
        // Weight on [-1, 1] is 2 / ((1 - t^2) P_N'(t)^2); a pair counts twice.
        let w = 2.0 / ((1.0 - t * t) * slope * slope);
        let w = if middle { w } else { 2.0 * w };
        rule.cos[i] = libm::cos(FRAC_PI_2 * t);
        rule.weight[i] = w;
        total += w;
    }
    for w in &mut rule.weight[..len] {
        *w /= total;
    }
    Some(rule)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Mean of f(cos theta) over [-pi/2, pi/2] by the half rule.
    fn mean(rule: &HalfRule, f: impl Fn(f64) -> f64) -> f64 {
        (0..rule.len).map(|i| rule.weight[i] * f(rule.cos[i])).sum()
    }

    #[test]
    fn rules_integrate_polynomials_and_known_means() {
        assert!(half_rule(0).is_none() && half_rule(65).is_none());
        for points in [1, 2, 3, 4, 7, 8, 16, 33, 64] {
            let rule = half_rule(points).unwrap();
            assert_eq!(rule.len, points.div_ceil(2));
            let sum: f64 = rule.weight[..rule.len].iter().sum();
            assert!((sum - 1.0).abs() < 1e-14, "N {points}: weights {sum}");
            assert!(
                rule.cos[..rule.len]
                    .iter()
                    .all(|&c| (0.0..=1.0).contains(&c))
            );
        }
        // <cos theta> = 2/pi, <e^(-cos theta)> (modified Bessel and Struve: 0.3863...);
        // Gauss-Legendre converges geometrically on these analytic integrands.
        let rule = half_rule(16).unwrap();
        assert!((mean(&rule, |c| c) - 2.0 / PI).abs() < 1e-14);
        let dense: f64 = {
            let m = 200_000;
            (0..m)
                .map(|k| {
                    let theta = -FRAC_PI_2 + PI * (k as f64 + 0.5) / m as f64;
                    (-theta.cos()).exp() * 1.0 / m as f64
                })
                .sum()
        };
        assert!((mean(&rule, |c| (-c).exp()) - dense).abs() < 1e-10);
        // Odd N has the node theta = 0 (cos = 1) last.
        assert_eq!(half_rule(7).unwrap().cos[3], 1.0);
    }
}
