//! The cube model as a [`FrictionModel`] for the controller: amplitude = fraction of the
//! scene's full-scale horn amplitude (A and B both scale with it), ratio F'/F in Q2.30. The
//! operating point's sliding velocity does not enter: seed 000 eq 15 is a ratio of steady Dahl
//! states (delta = F_t0 / K_t), independent of the sliding speed and of the frequency.
//!
//! Inversion. W0(a) = <e^(-a K c) (1 + a Y c)^-3> is a mean of log-convex functions of a, hence
//! convex and decreasing (physics-notes §4): Newton's method converges monotonically from any
//! point left of the root, and a step from the right lands left of it. [`CubeModel::invert`]
//! runs a bracketed Newton iteration with the exact derivative
//! dW0/da = `-<G c (K + 3 Y / (1 + a Y c))>` (a few multiplies more per node), from a = 0 or
//! from a previous solution ([`FrictionModel::invert_from`], which the controller calls with the
//! previous step's amplitude): about 5 evaluations cold and 3-4 warm,
//! instead of the 18 of the default bisection. From a = 0 the first step needs no evaluation:
//! W0(0) = 1 and W0'(0) = -(K + 3 Y) `<c>` exactly. It stops when |F'/F - target| <= 2^-22
//! (2.4e-7, above the fixed-point granularity of W0(a), about 5e-8) or when the bracket closes
//! to 1 ulp of Q2.30. Scenes whose u-term can act (off the node with an in-phase u, or the
//! literal window) are not monotone in general: they use the default bisection.

use crate::fx::{Q1_31, Q2_30};

use super::contact::ln_load;
use super::cube::{CubeOptions, CubeParams, CubePoint, CubeScene};
use super::cube_nodes::apart_node;
use super::fx_error;
use super::quadrature::SlipWindow;
use super::{BISECTION_STEPS, FrictionModel, Inversion, ModelError, OperatingPoint, Reach, invert};

/// Newton iterations before giving up (returning the best point found).
const MAX_ITERATIONS: usize = 16;
/// Convergence tolerance on F'/F, Q.30: 2^-22 = 2.4e-7, above the granularity of the
/// fixed-point W0(a) (K and Y move in Q8.24 steps: F'/F moves in steps of about 5e-8).
const RATIO_TOLERANCE: i64 = 1 << 8;
const ONE: i64 = 1 << 30;

/// The cube model of one scene, usable by the controller.
#[derive(Debug, Clone, PartialEq)]
pub struct CubeModel {
    scene: CubeScene,
}

impl CubeModel {
    /// Builds the scene (f64, once). Errors: see [`CubeScene::new`].
    pub fn new(params: &CubeParams, options: &CubeOptions) -> Result<Self, ModelError> {
        Ok(Self {
            scene: CubeScene::new(params, options)?,
        })
    }

    /// The scene constants.
    pub fn scene(&self) -> &CubeScene {
        &self.scene
    }

    /// Load-dependent precomputation (ln F_n, d, V/d, ln u/delta); reuse it for several
    /// amplitudes at the same load. Errors: F_n <= 0 and the contact guards.
    pub fn prepare(&self, point: &OperatingPoint) -> Result<CubePoint, ModelError> {
        self.scene.prepare(ln_load(point.normal_force)?)
    }

    /// F'/F (Q2.30) at `amplitude` (Q1.31 fraction of full scale) for a prepared load.
    pub fn ratio_prepared(&self, point: &CubePoint, amplitude: Q1_31) -> Result<Q2_30, ModelError> {
        let a = amplitude.convert::<30>().map_err(fx_error("amplitude"))?;
        self.scene.ratio_q2_30(point, a)
    }

    /// W0 (Q.30) and -dW0/da (Q.30 per unit amplitude) at amplitude `a` (Q.30 in [0, 1]):
    /// the default window's node kernel plus d phi / da = c (K + 3 Y / (1 + a Y c)), whose
    /// reciprocal the kernel already has (phi = a K c + 3 ln(1 + a Y c)).
    fn mean_and_slope(&self, point: &CubePoint, a: i64) -> Result<(i64, i64), ModelError> {
        let scale = |full: i64| ((full * a + (1 << 29)) >> 30) as i32; // as in `evaluate`
        let (decay_full, lift_full) = (
            self.scene.decay.to_bits() as i64,
            point.lift_over_separation.to_bits() as i64,
        );
        let (decay, lift) = (scale(decay_full), scale(lift_full));
        let q = &self.scene.quadrature;
        let (mut mean, mut slope) = (0i64, 0i64);
        for (&cos, &weight) in q.cos().iter().zip(q.weights()) {
            let c = cos.to_bits() as i64;
            let (g, inv_z) = apart_node(decay, lift, cos.to_bits())?;
            // The same Q.60 sum as `CubeScene::evaluate`, so the returned ratio is the model's.
            let wg60 = weight.to_bits() as i64 * g as i64;
            mean += wg60;
            let wg = (wg60 + (1 << 29)) >> 30;
            // K + 3 Y / z in Q.20 (< 2^29).
            let rate = (decay_full + 3 * ((lift_full * inv_z as i64 + (1 << 29)) >> 30)) >> 4;
            let wgc = (wg * c + (1 << 30)) >> 31;
            slope += (wgc * rate + (1 << 19)) >> 20;
        }
        Ok(((mean + (1 << 29)) >> 30, slope))
    }

    /// -dW0/da at a = 0 in Q.30: (K + 3 Y) <c> (G = 1 and z = 1 at every node).
    fn slope_at_zero(&self, point: &CubePoint) -> i64 {
        let q = &self.scene.quadrature;
        let mean_cos: i64 = q
            .cos()
            .iter()
            .zip(q.weights())
            .map(|(c, w)| (c.to_bits() as i64 * w.to_bits() as i64 + (1 << 30)) >> 31)
            .sum(); // Q.30
        let rate = (self.scene.decay.to_bits() as i64
            + 3 * point.lift_over_separation.to_bits() as i64)
            >> 4; // Q.20
        (mean_cos * rate + (1 << 19)) >> 20
    }

    /// Bracketed Newton iteration on the convex, decreasing W0(a) (see the module docs).
    fn newton(
        &self,
        point: &CubePoint,
        target: Q2_30,
        start: i64,
    ) -> Result<Inversion, ModelError> {
        let t = target.to_bits() as i64;
        let result = |a: i64, ratio: i64, reach| Inversion {
            // Q2.30 -> Q1.31; a = 1 becomes MAX (1 - 2^-31).
            amplitude: Q1_31::from_bits((a << 1).min(i32::MAX as i64) as i32),
            ratio: Q2_30::from_bits(ratio as i32),
            reach,
        };
        if t >= ONE {
            // W0(0) = 1 exactly (G = 1 at every node, weights summing to 2^30).
            return Ok(result(0, ONE, Reach::AboveNatural));
        }
        let (mut low, mut high, mut high_known) = (0i64, ONE, false);
        let mut a = start.clamp(0, ONE);
        let mut best = (a, ONE, i64::MAX); // (a, W0(a), |W0(a) - target|)
        for _ in 0..MAX_ITERATIONS {
            let (f, slope) = if a == 0 {
                (ONE, self.slope_at_zero(point))
            } else {
                self.mean_and_slope(point, a)?
            };
            if (f - t).abs() < best.2 {
                best = (a, f, (f - t).abs());
            }
            if f > t {
                low = a;
                if a == ONE {
                    return Ok(result(ONE, f, Reach::BelowMinimum));
                }
            } else {
                high = a;
                high_known = true;
            }
            if (f - t).abs() <= RATIO_TOLERANCE {
                return Ok(result(a, f, Reach::Reached));
            }
            let newton = if slope > 0 {
                a + ((f - t) << 30) / slope
            } else {
                i64::MAX
            };
            let next = if newton > low && newton < high {
                newton
            } else if newton >= high && !high_known {
                ONE // the root may lie beyond full scale: test it
            } else {
                (low + high) / 2
            };
            if next == a || (high_known && high - low <= 1) {
                break; // converged to the resolution of the amplitude
            }
            a = next;
        }
        let (a, f, _) = best;
        Ok(result(a, f, Reach::Reached))
    }
}

impl FrictionModel for CubeModel {
    /// F'/F (Q2.30) at `amplitude` (Q1.31 fraction of full scale): in (0, 1] at the node (the
    /// paper's configuration) and with a quadrature-phase u; above 1 (friction increase) or below
    /// 0 (x < 0) only off the node with an in-phase u, or in the literal window. Errors: F_n <= 0,
    /// contact guards, F'/F outside [-2, 2). Cost, elastic-plastic, N = 16, measured on
    /// the Cortex-M4 instruction set (QEMU mps2-an386, one instruction per translation block,
    /// opt-level "s", fat LTO): 1,511 instructions at the node, 1,914 off the node (u-term);
    /// N = 8: 911; N = 32: 2,711.
    fn ratio(&self, point: &OperatingPoint, amplitude: Q1_31) -> Result<Q2_30, ModelError> {
        let prepared = self.prepare(point)?;
        self.ratio_prepared(&prepared, amplitude)
    }

    /// Bracketed Newton from a = 0 (see the module docs); default bisection for scenes with
    /// an active u-term or the literal window. Measured (as for `ratio`, N = 16, 40 N, target
    /// 0.6): 8,960 instructions cold, 6,290 warm-started from the solution for 0.605
    /// ([`FrictionModel::invert_from`]), against 27,200 for the default 16-step bisection.
    fn invert(&self, point: &OperatingPoint, target: Q2_30) -> Result<Inversion, ModelError> {
        self.invert_from(point, target, Q1_31::ZERO)
    }

    /// The Newton iteration warm-started from `start` (the controller passes the previous
    /// step's amplitude): usually 2-3 evaluations when the load and the target moved little.
    /// Scenes with an active u-term or the literal window bisect and ignore `start`.
    fn invert_from(
        &self,
        point: &OperatingPoint,
        target: Q2_30,
        start: Q1_31,
    ) -> Result<Inversion, ModelError> {
        if self.scene.has_u_term() || self.scene.quadrature.window() != SlipWindow::SurfacesApart {
            return invert(self, point, target, BISECTION_STEPS);
        }
        let prepared = self.prepare(point)?;
        let start = start.convert::<30>().map_err(fx_error("amplitude"))?;
        self.newton(&prepared, target, start.to_bits() as i64)
    }
}

#[cfg(test)]
#[path = "cube_model_tests.rs"]
mod tests;
