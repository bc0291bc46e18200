//! N-point Gauss-Legendre rules over the slip window of seed 000 eq 15, tabulated once per N at
//! scene load (f64), used in fixed point by the cube model.
//!
//! The window is a half period in the phase theta = 2 pi f t (physics-notes §4):
//! - [`SlipWindow::SurfacesApart`] (default): theta in [-pi/2, pi/2], where v = V cos theta >= 0.
//!   The integrand depends on theta through cos theta only (or is odd, for a quadrature-phase u),
//!   so the symmetric N-point rule is evaluated at its ceil(N/2) nodes with theta >= 0, weights
//!   of the +-theta pairs doubled: exactly the N-point rule at half the cost.
//! - [`SlipWindow::LiteralCos`] (variant): theta in [0, pi], eq 15 read literally with the cos
//!   phase of eqs 16-17 (the approach half: friction increases); all N nodes.
//!
//! Gauss-Legendre rather than the midpoint rule: the integrand is analytic on the window but not
//! periodic, so equally spaced rules converge as 1/N^2 while Gauss-Legendre converges
//! geometrically. Weights are normalised to a mean (they sum to exactly 2^30 in Q2.30, so a
//! constant integrand averages to itself exactly).

use core::f64::consts::{FRAC_PI_2, PI};

use crate::fx::{Q1_31, Q2_30};

use super::ModelError;

/// Largest supported number of quadrature points N.
pub const MAX_QUADRATURE_POINTS: usize = 64;

/// Which half-period is the slip phase of seed 000 eq 15.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SlipWindow {
    /// The half-period with v >= 0, surfaces apart (physics-notes §4; default).
    #[default]
    SurfacesApart,
    /// t in [0, T/2] with the cos phase of eqs 16-17, read literally: the approach half.
    LiteralCos,
}

/// Tabulated nodes and weights of an N-point Gauss-Legendre rule over a slip window.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Quadrature {
    window: SlipWindow,
    points: usize,
    len: usize,
    cos: [Q1_31; MAX_QUADRATURE_POINTS],
    sin: [Q1_31; MAX_QUADRATURE_POINTS],
    weight: [Q2_30; MAX_QUADRATURE_POINTS],
}

/// Positive Gauss-Legendre nodes on [-1, 1] (descending, the last is 0 for odd N) and weights,
/// by Newton's method on the Legendre recurrence (f64, 1e-15).
pub(crate) fn legendre_half(points: usize, nodes: &mut [f64], weights: &mut [f64]) -> usize {
    let n = points as f64;
    let half = points.div_ceil(2);
    for i in 0..half {
        let mut z = libm::cos(PI * (i as f64 + 0.75) / (n + 0.5));
        let mut derivative = 1.0;
        for _ in 0..100 {
            let (mut p1, mut p2) = (1.0, 0.0);
            for j in 1..=points {
                let p3 = p2;
                p2 = p1;
                let jf = j as f64;
                p1 = ((2.0 * jf - 1.0) * z * p2 - (jf - 1.0) * p3) / jf;
            }
            derivative = n * (z * p1 - p2) / (z * z - 1.0);
            let step = p1 / derivative;
            z -= step;
            if step.abs() < 1e-16 {
                break;
            }
        }
        nodes[i] = if 2 * i + 1 == points { 0.0 } else { z };
        weights[i] = 2.0 / ((1.0 - z * z) * derivative * derivative);
    }
    half
}

impl Quadrature {
    /// The N-point rule (`points` in 1..=64) over `window`. Error: `OutOfDomain` for N outside
    /// 1..=64. Scene-load cost (f64): O(N^2) multiply-adds.
    pub fn new(points: usize, window: SlipWindow) -> Result<Self, ModelError> {
        if !(1..=MAX_QUADRATURE_POINTS).contains(&points) {
            return Err(ModelError::OutOfDomain {
                input: "quadrature_points",
                reason: "must be in 1..=64",
            });
        }
        let mut x = [0.0; MAX_QUADRATURE_POINTS];
        let mut w = [0.0; MAX_QUADRATURE_POINTS];
        let half = legendre_half(points, &mut x, &mut w);
        // (theta, mean weight) per stored node.
        let mut nodes = [(0.0, 0.0); MAX_QUADRATURE_POINTS];
        let len = match window {
            SlipWindow::SurfacesApart => {
                for i in 0..half {
                    let paired = if x[i] > 0.0 { 2.0 } else { 1.0 };
                    nodes[i] = (FRAC_PI_2 * x[i], 0.5 * paired * w[i]);
                }
                half
            }
            SlipWindow::LiteralCos => {
                let mut n = 0;
                for i in 0..half {
                    nodes[n] = (FRAC_PI_2 + FRAC_PI_2 * x[i], 0.5 * w[i]);
                    n += 1;
                    if x[i] > 0.0 {
                        nodes[n] = (FRAC_PI_2 - FRAC_PI_2 * x[i], 0.5 * w[i]);
                        n += 1;
                    }
                }
                n
            }
        };
        let mut table = Self {
            window,
            points,
            len,
            cos: [Q1_31::ZERO; MAX_QUADRATURE_POINTS],
            sin: [Q1_31::ZERO; MAX_QUADRATURE_POINTS],
            weight: [Q2_30::ZERO; MAX_QUADRATURE_POINTS],
        };
        let mut total: i64 = 0;
        let mut largest = 0;
        for (i, &(theta, weight)) in nodes.iter().take(len).enumerate() {
            // cos 0 = 1 is stored as MAX (1 - 2^-31).
            table.cos[i] = Q1_31::from_f64_saturating(libm::cos(theta)).value;
            table.sin[i] = Q1_31::from_f64_saturating(libm::sin(theta)).value;
            table.weight[i] = Q2_30::from_f64_saturating(weight).value;
            total += table.weight[i].to_bits() as i64;
            if table.weight[i] > table.weight[largest] {
                largest = i;
            }
        }
        // Put the rounding residue (a few ulps) on the largest weight: the sum is exactly 1.
        let fixed = table.weight[largest].to_bits() as i64 + (1i64 << 30) - total;
        table.weight[largest] = Q2_30::from_bits(fixed as i32);
        Ok(table)
    }

    /// The window this rule covers.
    pub fn window(&self) -> SlipWindow {
        self.window
    }

    /// N, the number of points of the rule.
    pub fn points(&self) -> usize {
        self.points
    }

    /// Number of stored (evaluated) nodes: ceil(N/2) for `SurfacesApart`, N for `LiteralCos`.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Never true: a rule has at least one node.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// cos theta at the stored nodes, Q1.31 (error 0.5 ulp; cos 0 = 1 stored as `MAX`).
    pub fn cos(&self) -> &[Q1_31] {
        &self.cos[..self.len]
    }

    /// sin theta at the stored nodes, Q1.31.
    pub fn sin(&self) -> &[Q1_31] {
        &self.sin[..self.len]
    }

    /// Mean weights at the stored nodes, Q2.30, summing to exactly 1.0.
    pub fn weights(&self) -> &[Q2_30] {
        &self.weight[..self.len]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Mean of `f(theta)` over the window by the tabulated rule, in f64.
    fn mean(q: &Quadrature, f: impl Fn(f64, f64) -> f64) -> f64 {
        let mut sum = 0.0;
        for i in 0..q.len() {
            sum += q.weights()[i].to_f64() * f(q.cos()[i].to_f64(), q.sin()[i].to_f64());
        }
        sum
    }

    #[test]
    fn weights_sum_to_one_exactly_and_nodes_are_gauss_legendre() {
        for n in 1..=MAX_QUADRATURE_POINTS {
            for window in [SlipWindow::SurfacesApart, SlipWindow::LiteralCos] {
                let q = Quadrature::new(n, window).unwrap();
                let sum: i64 = q.weights().iter().map(|w| w.to_bits() as i64).sum();
                assert_eq!(sum, 1 << 30, "N = {n}");
                assert_eq!(q.points(), n);
            }
        }
        // Two points on [-pi/2, pi/2]: theta = +-pi / (2 sqrt 3), one stored node of weight 1.
        let q = Quadrature::new(2, SlipWindow::SurfacesApart).unwrap();
        assert_eq!(q.len(), 1);
        assert!((q.cos()[0].to_f64() - (FRAC_PI_2 / 3f64.sqrt()).cos()).abs() < 1e-9);
        assert!(Quadrature::new(0, SlipWindow::LiteralCos).is_err());
        assert!(Quadrature::new(65, SlipWindow::LiteralCos).is_err());
    }

    #[test]
    fn rules_integrate_smooth_functions() {
        // Mean of cos theta over [-pi/2, pi/2] is 2/pi; of cos^2 over [0, pi] is 1/2; of
        // sin theta over [0, pi] is 2/pi; of e^(-cos theta) over [-pi/2, pi/2] is
        // I0(1) - L0(1) = 0.5449... (checked against a fine midpoint sum).
        let apart = Quadrature::new(16, SlipWindow::SurfacesApart).unwrap();
        let literal = Quadrature::new(16, SlipWindow::LiteralCos).unwrap();
        assert!((mean(&apart, |c, _| c) - 2.0 / PI).abs() < 1e-8);
        assert!((mean(&literal, |c, _| c * c) - 0.5).abs() < 1e-8);
        assert!((mean(&literal, |_, s| s) - 2.0 / PI).abs() < 1e-8);
        let fine: f64 = (0..200_000)
            .map(|i| (-((i as f64 + 0.5) / 200_000.0 * PI - FRAC_PI_2).cos()).exp())
            .sum::<f64>()
            / 200_000.0;
        assert!((mean(&apart, |c, _| (-c).exp()) - fine).abs() < 1e-8);
    }
}
