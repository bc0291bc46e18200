//! Cube friction-reduction model (seed 000 eqs 9, 12-15; physics-notes §4) in fixed point.
//!
//! With d' = d + v, A_r' = A_r e^(-lambda v / R_q) (every contact term scales with
//! e^(-lambda d / R_q)) and delta' = delta + u, eq 15 over eq 11 is the dimensionless average
//! F'/F = < G (1 + u / delta) > over the slip half-period, G = e^(-2 lambda v / R_q) (d / d')^3.
//! At amplitude fraction a (v = a V cos theta, u = a U P_u(theta), V = B cos(pi x/L),
//! U = A sin(pi x/L)):
//!
//! - G = e^(-K c) (1 + Y c)^-3, c = cos theta, with K = 2 lambda a V / R_q and Y = a V / d,
//!   the only groups of v that enter (kernels in `cube_nodes`);
//! - u / delta = a (u/delta)_max P_u with (u/delta)_max = U E* F_n / (mu p_eff^2 d^3)
//!   (physics-notes §5): it reaches 1e11 away from the node, so it is formed once per load from
//!   its logarithm (Q8.24) as a wide `mantissa * 2^exp2` value ([`Scaled`]);
//! - F'/F = W0 + a (u/delta)_max W1, W0 = `<G>`, W1 = `<G P_u>` (N-point Gauss-Legendre,
//!   [`Quadrature`]).
//!
//! K_t and delta themselves (up to 1e19 N/m, down to 1e-15 m) are never formed. The frequency
//! is validated and never used: 20 and 60 kHz give bit-identical results. For the default window
//! and a quadrature-phase u, W1 = 0 exactly (odd integrand, symmetric rule).
//!
//! Ranges: K and Y are Q8.24 (scene error when 2 lambda B / R_q >= 128, point error when
//! B cos(pi x/L) / d >= 127: v would exceed 127 cube heights). The ratio is returned in Q8.24;
//! ratios outside [-128, 128) (off the node, where u / delta is huge) saturate with a flag.

use core::f64::consts::PI;

use crate::fx::{Q2_30, Q6_26, Q8_24, Sat};

use super::ModelError;
use super::contact::{ContactConstants, ContactKind, ContactParams, ContactState, EStarRule};
use super::contact_constants::{finite, non_negative, positive};
use super::cube_nodes::{apart_sums, literal_sums, quotient_q8_24};
use super::fx_error;
use super::horn::UPhase;
use super::quadrature::{Quadrature, SlipWindow};
use crate::fx::Scaled;

/// Default number of quadrature points N.
pub const DEFAULT_QUADRATURE_POINTS: usize = 16;

/// Scene inputs of the cube model, SI units (seed 000 Tables 1-2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CubeParams {
    /// Materials and surface.
    pub contact: ContactParams,
    /// Friction coefficient mu (> 0): F_t0 = mu F_n (0.54 and 0.26 in seed 000 §4.2).
    pub friction_coefficient: f64,
    /// Full-scale longitudinal amplitude A in m (>= 0; 11.46 um in Table 1).
    pub longitudinal_amplitude: f64,
    /// Full-scale vertical amplitude B in m (>= 0; Table 1, or eq A.9 via `horn::PoissonGain`).
    pub vertical_amplitude: f64,
    /// Contact position from the horn centre x in m, |x| <= L/2.
    pub position: f64,
    /// Horn length L in m (> 0).
    pub horn_length: f64,
    /// Frequency f in Hz (> 0; validated, does not enter the result).
    pub frequency: f64,
}

/// Variant choices of the cube model.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CubeOptions {
    /// E* rule (seed 000 default).
    pub e_star_rule: EStarRule,
    /// Contact model for d and A_r (elastic-plastic default).
    pub contact_kind: ContactKind,
    /// Slip half-period (v >= 0 default).
    pub window: SlipWindow,
    /// Phase of u (in phase default).
    pub u_phase: UPhase,
    /// Quadrature points N, 1..=64 (16 default).
    pub quadrature_points: usize,
}

impl Default for CubeOptions {
    fn default() -> Self {
        Self {
            e_star_rule: EStarRule::default(),
            contact_kind: ContactKind::default(),
            window: SlipWindow::default(),
            u_phase: UPhase::default(),
            quadrature_points: DEFAULT_QUADRATURE_POINTS,
        }
    }
}

/// Per-scene constants of the cube model.
#[derive(Debug, Clone, PartialEq)]
pub struct CubeScene {
    pub(crate) contact: ContactConstants,
    pub(crate) quadrature: Quadrature,
    u_phase: UPhase,
    /// V / R_q at full scale, Q8.24.
    lift_rq: Q8_24,
    /// K at full scale, 2 lambda V / R_q, Q8.24.
    pub(crate) decay: Q8_24,
    /// ln |U E* / (mu p_eff^2 R_q^3)| (SI), Q8.24; `None` when U = 0 (at the node).
    ln_u_prefactor: Option<Q8_24>,
    u_negative: bool,
    friction_coefficient: f64,
}

/// What the cube model needs at one load, independent of amplitude and quadrature node.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CubePoint {
    /// Contact state (d / R_q, ln(A_r / A_n)).
    pub contact: ContactState,
    /// Y at full scale, V / d, Q8.24 in [0, 127).
    pub lift_over_separation: Q8_24,
    /// |u / delta| at full scale, (u/delta)_max = U E* F_n / (mu p_eff^2 d^3), as a wide value
    /// (up to about 1e11; physics-notes §5); `None` when u = 0 (at the node or A = 0). Its sign
    /// is [`CubeScene::u_negative`].
    pub u_over_delta: Option<Scaled>,
}

impl CubeScene {
    /// Validates the SI inputs and precomputes the scene constants (f64, once per scene).
    /// Errors: invalid inputs (as named in the evaluation tool), 2 lambda B cos(pi x/L) / R_q
    /// >= 128, or a quadrature N outside 1..=64.
    pub fn new(params: &CubeParams, options: &CubeOptions) -> Result<Self, ModelError> {
        let mu = positive("mu", params.friction_coefficient)?;
        let a = non_negative("A", params.longitudinal_amplitude)?;
        let b = non_negative("B", params.vertical_amplitude)?;
        let length = positive("L", params.horn_length)?;
        let x = finite("x", params.position)?;
        if x.abs() > 0.5 * length {
            return Err(ModelError::OutOfDomain {
                input: "x",
                reason: "|x| must be <= L/2",
            });
        }
        positive("f", params.frequency)?;
        let contact =
            ContactConstants::new(&params.contact, options.e_star_rule, options.contact_kind)?;
        let quadrature = Quadrature::new(options.quadrature_points, options.window)?;
        let s = *contact.scene();
        // The shape factors are scene constants: f64 here, so that a contact 1 nm from the node
        // keeps its exact sin(pi x / L) (the u32 position phase of `horn` would round it).
        let shape = PI * x / length;
        let lift = b * libm::cos(shape) / s.roughness_rq;
        let too_large = |_| ModelError::OutOfDomain {
            input: "B",
            reason: "2 lambda B cos(pi x/L) / R_q must be below 128",
        };
        let u_amplitude = a * libm::sin(shape);
        let ln_u_prefactor = if u_amplitude == 0.0 {
            None
        } else {
            let ln = libm::log(u_amplitude.abs()) + libm::log(s.e_star)
                - libm::log(mu)
                - 2.0 * libm::log(s.mean_pressure)
                - 3.0 * libm::log(s.roughness_rq);
            Some(Q8_24::from_f64(ln).map_err(fx_error("ln(u/delta) prefactor"))?)
        };
        Ok(Self {
            lift_rq: Q8_24::from_f64(lift).map_err(too_large)?,
            decay: Q8_24::from_f64(2.0 * s.distribution_lambda * lift).map_err(too_large)?,
            contact,
            quadrature,
            u_phase: options.u_phase,
            ln_u_prefactor,
            u_negative: u_amplitude < 0.0,
            friction_coefficient: mu,
        })
    }

    /// Contact constants of the scene.
    pub fn contact(&self) -> &ContactConstants {
        &self.contact
    }

    /// The quadrature rule.
    pub fn quadrature(&self) -> &Quadrature {
        &self.quadrature
    }

    /// Friction coefficient mu (f64, for tool-level outputs F_t0 = mu F_n).
    pub fn friction_coefficient(&self) -> f64 {
        self.friction_coefficient
    }

    /// Whether the u-term can contribute (u not identically 0 and W1 not 0 by symmetry).
    pub(crate) fn has_u_term(&self) -> bool {
        self.ln_u_prefactor.is_some()
            && !(self.quadrature.window() == SlipWindow::SurfacesApart
                && self.u_phase == UPhase::Quadrature)
    }

    /// Precomputes what depends on the load only: the contact state, Y = V / d and
    /// ln (u/delta)_max. `ln_load` = ln(F_n / 1 N), Q6.26. Errors: contact guards
    /// ([`ContactConstants::state`]); `OutOfDomain` when V / d >= 127. Cost: about 60
    /// instructions (plus one `ln` and one `exp` when u is not 0); measured with the `ln` of a
    /// Q16.16 load in `CubeModel::prepare`: 190 Cortex-M4 instructions at the node.
    pub fn prepare(&self, ln_load: Q6_26) -> Result<CubePoint, ModelError> {
        let contact = self.contact.state(ln_load)?;
        let lift_error = ModelError::OutOfDomain {
            input: "B",
            reason: "B cos(pi x/L) must be below 127 cube heights d",
        };
        // Y = (V / R_q) / (d / R_q) by a Newton reciprocal (no library division).
        let lift_over_separation = quotient_q8_24(
            self.lift_rq.to_bits() as u32,
            contact.separation_rq.to_bits() as u32,
        )
        .map(|bits| Q8_24::from_bits(bits as i32))
        .ok_or(lift_error)?;
        if lift_over_separation >= Q8_24::from_int_const(127) {
            return Err(lift_error);
        }
        let u_over_delta = match self.ln_u_prefactor {
            None => None,
            Some(prefactor) => {
                // ln (u/delta)_max = ln prefactor + ln F_n - 3 ln(d / R_q), summed in Q.26.
                let ln_d = contact.separation_rq.ln::<26>().map_err(fx_error("ln d"))?;
                let sum = 4 * prefactor.to_bits() as i64 + ln_load.to_bits() as i64
                    - 3 * ln_d.to_bits() as i64;
                let bits = i32::try_from((sum + 2) >> 2).map_err(|_| ModelError::Overflow {
                    quantity: "ln(u/delta)",
                })?;
                Some(Scaled::from_ln(Q8_24::from_bits(bits)))
            }
        };
        Ok(CubePoint {
            contact,
            lift_over_separation,
            u_over_delta,
        })
    }

    /// F'/F at amplitude fraction `amplitude` (Q2.30 in [0, 1] of full scale; B and A both
    /// scale with it), in Q8.24 with a saturation flag (set when F'/F is outside [-128, 128),
    /// which happens only off the node). Errors: amplitude outside [0, 1]; literal window with
    /// v >= d (interpenetration). Cost in the default window: ceil(N/2) nodes of one `exp_neg`
    /// and one Newton reciprocal each; 1,300 Cortex-M4 instructions measured at N = 16 at the
    /// node (see `CubeModel::ratio` for the whole call).
    pub fn evaluate(&self, point: &CubePoint, amplitude: Q2_30) -> Result<Sat<Q8_24>, ModelError> {
        let (wide, saturated) = self.ratio_wide(point, amplitude)?;
        let bits = (wide + 32) >> 6; // Q.30 -> Q.24
        Ok(match i32::try_from(bits) {
            Ok(b) if !saturated => Sat::exact(Q8_24::from_bits(b)),
            _ if wide < 0 => Sat::clamped(Q8_24::MIN),
            _ => Sat::clamped(Q8_24::MAX),
        })
    }

    /// F'/F in Q2.30 for the controller. Error: `Overflow` when F'/F is outside [-2, 2).
    pub fn ratio_q2_30(&self, point: &CubePoint, amplitude: Q2_30) -> Result<Q2_30, ModelError> {
        let (wide, saturated) = self.ratio_wide(point, amplitude)?;
        match i32::try_from(wide) {
            Ok(bits) if !saturated => Ok(Q2_30::from_bits(bits)),
            _ => Err(ModelError::Overflow {
                quantity: "F'/F (Q2.30: friction more than doubled off the node)",
            }),
        }
    }

    /// Whether u / delta is negative (x < 0: u points against the sliding direction).
    pub fn u_negative(&self) -> bool {
        self.u_negative
    }

    /// F'/F in Q.30 as an `i64`, and whether it saturated.
    fn ratio_wide(&self, point: &CubePoint, amplitude: Q2_30) -> Result<(i64, bool), ModelError> {
        if amplitude.is_negative() || amplitude > Q2_30::ONE {
            return Err(ModelError::OutOfDomain {
                input: "amplitude",
                reason: "must be in [0, 1] of full scale",
            });
        }
        let scale = |full: Q8_24| full.saturating_mul_to::<24, 30>(amplitude).value; // <= full
        let decay = scale(self.decay).to_bits();
        let lift = scale(point.lift_over_separation).to_bits();
        let with_u = self.has_u_term() && amplitude.is_positive();
        let q = &self.quadrature;
        let sums = match (q.window(), with_u) {
            (SlipWindow::SurfacesApart, false) => apart_sums::<false>(q, decay, lift)?,
            (SlipWindow::SurfacesApart, true) => apart_sums::<true>(q, decay, lift)?,
            (SlipWindow::LiteralCos, _) => {
                if lift >= 1 << 24 {
                    return Err(ModelError::OutOfDomain {
                        input: "B",
                        reason: "B cos(pi x/L) >= d: the surfaces would interpenetrate",
                    });
                }
                literal_sums(q, self.u_phase, decay, lift)?
            }
        };
        let (u_term, u_saturated) = match point.u_over_delta {
            Some(u) if with_u => self.u_term(u, amplitude, sums.u_mean),
            _ => (0, false),
        };
        Ok((
            sums.mean.saturating_add(u_term),
            sums.saturated || u_saturated,
        ))
    }

    /// a (u/delta)_max W1 in Q.30 (signed), saturated beyond 2^22: a W1 in Q.30 times the
    /// wide (u/delta)_max, no logarithm. `i64` while |W1| < 2^31 (always in the default window),
    /// `i128` otherwise (the literal window's W1 can reach 2^62).
    fn u_term(&self, u: Scaled, amplitude: Q2_30, u_mean: i64) -> (i64, bool) {
        let (a, mantissa, exp2) = (
            amplitude.to_bits() as i64,
            u.mantissa.to_bits() as i64,
            u.exp2 as i64,
        );
        // T in Q.30 = product 2^-shift; `None` when |T| >= 2^22 for sure.
        let term: Option<i128> = if u_mean.unsigned_abs() < 1 << 31 {
            let aw = (a * u_mean + (1 << 29)) >> 30; // a W1 in Q.30, |aw| < 2^31
            let product = aw * mantissa; // |product| < 2^62
            let shift = 30 - exp2;
            match shift {
                _ if product == 0 => Some(0),
                1..=62 => Some(((product + (1 << (shift - 1))) >> shift) as i128),
                63.. => Some(0),
                -60..=0 => Some((product as i128) << -shift),
                _ => None,
            }
        } else {
            // |product| >= 2^61 here, so shift <= 0 means |T| >= 2^61 ulps.
            let product = a as i128 * u_mean as i128 * mantissa as i128; // < 2^123
            match 60 - exp2 {
                shift @ 1..=126 => Some((product + (1 << (shift - 1))) >> shift),
                127.. => Some(0),
                _ => None,
            }
        };
        match term {
            Some(t) if t.abs() <= 1 << 52 => {
                let t = t as i64;
                (if self.u_negative { -t } else { t }, false)
            }
            _ => (0, true),
        }
    }
}

#[cfg(test)]
#[path = "cube_tests.rs"]
pub(crate) mod tests;
