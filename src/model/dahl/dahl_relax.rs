//! Exact relaxation of the Dahl gap g = 1 - s f along a stretch travelled in one direction
//! (seed 003 eq 7, physics-notes §2): dg/dxi = -kappa g^alpha, solved in closed form after a
//! travel exponent y = kappa xi:
//! - alpha = 1: g = g0 e^(-y);
//! - alpha != 1 (p = 1 - alpha): g = g0 (1 - p y g0^(-p))^(1/p), clamped at g = 0 for
//!   alpha < 1 where the base reaches 0 (the right-hand side is not Lipschitz at g = 0).
//!
//! Method for alpha != 1: the decay exponent lambda = ln(g0 / g) = -ln(1 - w) / p with
//! w = p y g0^(-p), by its series z sum_k w^k / (k + 1) for |w| <= 1/8 (8 terms, 7e-10
//! relative truncation; no loss of precision as alpha -> 1) and by `fx` ln otherwise (in the
//! finest of Q2.30, Q6.26, Q8.24 that holds it), then g = g0 e^(-lambda). g0^(-p) comes from
//! `ln` and [`Scaled::from_ln`]. Accuracy: g to 1e-8 absolute (7.4e-9 measured over alpha in
//! [0.2, 20], g0 in [1e-6, 2], y in [1e-9, 1e9]). It is the exact solution, not a
//! time-stepping scheme: there is no step-size limit however stiff the contact.
//!
//! Formats: g in Q3.29 ([0, 2] with an exact 2, 1.9e-9 resolution); y and lambda as
//! [`Scaled`] (kappa xi runs to 1e13 for stiff contacts).

use crate::fx::{Q2_30, Q3_29, Q6_26, Q8_24};

use super::ModelError;
use super::fx_error;
use crate::fx::Scaled;
use crate::fx::wide;

/// Largest shape exponent alpha accepted (as the reference).
pub const MAX_SHAPE_EXPONENT: f64 = 20.0;

/// |1 - alpha| below this is treated as alpha = 1 (the laws differ by < 1e-6 in g).
const EXPONENTIAL_BAND: f64 = 1.0 / (1u64 << 24) as f64;

/// 1.0 as a [`Scaled`].
const ONE: Scaled = Scaled {
    mantissa: Q2_30::ONE,
    exp2: 0,
};

/// Relaxation law of g = 1 - s f along a one-direction stretch (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum RelaxLaw {
    /// alpha = 1: g = g0 e^(-y).
    Exponential,
    /// alpha != 1: g = g0 (1 - p y g0^(-p))^(1/p), p = 1 - alpha.
    Power {
        /// p = 1 - alpha, Q8.24 in [-19, 1).
        p: Q8_24,
        /// |p|.
        abs_p: Scaled,
        /// 1 / |p|.
        inv_abs_p: Scaled,
        /// p / (1 + p) for alpha < 1 (0 otherwise), Q2.30: the mean of g over the part of an
        /// interval where it falls to 0, relative to its start (g^p linear in the travel).
        clamp_share: Q2_30,
    },
}

/// Result of relaxing g from g0 along a travel exponent y.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Decay {
    /// No travel: g = g0.
    None,
    /// lambda = ln(g0 / g) > 0.
    Exponent(Scaled),
    /// alpha < 1 and g reached 0 (clamped).
    Vanished,
}

impl RelaxLaw {
    /// The law for `alpha` in (0, 20] (f64, scene load).
    pub fn new(alpha: f64) -> Result<Self, ModelError> {
        if !alpha.is_finite() {
            return Err(ModelError::NonFinite { input: "alpha" });
        }
        if !(alpha > 0.0 && alpha <= MAX_SHAPE_EXPONENT) {
            return Err(ModelError::OutOfDomain {
                input: "alpha",
                reason: "must be in (0, 20]",
            });
        }
        let p = 1.0 - alpha;
        if p.abs() < EXPONENTIAL_BAND {
            return Ok(Self::Exponential);
        }
        Ok(Self::Power {
            p: Q8_24::from_f64(p).map_err(fx_error("alpha"))?,
            abs_p: crate::model::scaled_from_f64(p.abs(), "alpha")?,
            inv_abs_p: crate::model::scaled_from_f64(1.0 / p.abs(), "alpha")?,
            clamp_share: Q2_30::from_f64(if p > 0.0 { p / (1.0 + p) } else { 0.0 })
                .map_err(fx_error("alpha"))?,
        })
    }

    /// g0^(-p) for the power law (1 for the exponential law), `None` for g0 = 0. The exponent
    /// -p ln g0 is clamped to +-127 (only for alpha > 1 and g0 < e^-6.7: the clamp leaves
    /// g0^(-p) below 1e-55, where the relaxation is nil either way).
    pub fn stretch_factor(&self, g0: Q3_29) -> Option<Scaled> {
        if !g0.is_positive() {
            return None;
        }
        match *self {
            Self::Exponential => Some(ONE),
            Self::Power { p, abs_p, .. } => {
                let ln_g0: Q6_26 = g0.ln().ok()?; // g0 > 0: in [-20.8, 0.7]
                // -p ln g0 in Q6.26 when it fits (|.| < 32), else Q8.24 clamped to +-127.
                let signed = if p.is_negative() {
                    ln_g0
                } else {
                    ln_g0.saturating_neg().value
                };
                let fine = wide::mul_q::<26, 26>(abs_p, signed);
                if !fine.saturated {
                    return Some(Scaled::from_ln(fine.value));
                }
                let coarse = wide::mul_q::<24, 26>(abs_p, signed).value;
                let limit = Q8_24::from_int(127).ok()?;
                let clamped = coarse.max(limit.saturating_neg().value).min(limit);
                Some(Scaled::from_ln(clamped))
            }
        }
    }

    /// The decay after a travel exponent `y` = kappa xi (`None` = 0) from a state whose
    /// [`Self::stretch_factor`] is `factor`. Cost: exponential law, nothing; power law, one
    /// product and either an 8-term series or one `ln` and one product.
    pub fn decay(&self, y: Option<Scaled>, factor: Scaled) -> Decay {
        let Some(y) = y else { return Decay::None };
        match *self {
            Self::Exponential => Decay::Exponent(y),
            Self::Power {
                p,
                abs_p,
                inv_abs_p,
                ..
            } => {
                let z = wide::mul(y, factor);
                let w = wide::mul(z, abs_p); // |w|
                let lambda = if w.exp2 < -3 {
                    // -ln(1 - w)/p = z sum_k (sgn(p) w)^k / (k + 1), |w| < 1/8: 8 terms.
                    let signed_w = wide::to_q::<31>(w).value.to_bits() as i64;
                    let signed_w = if p.is_negative() { -signed_w } else { signed_w };
                    let mut sum: i64 = (1 << 31) / 9;
                    for k in (1..=8).rev() {
                        sum = (1i64 << 31) / k + ((sum * signed_w) >> 31);
                    }
                    wide::mul(z, series_factor(sum))
                } else if !p.is_negative() {
                    if wide::at_least_one(w) {
                        return Decay::Vanished;
                    }
                    let base = Q2_30::ONE.saturating_sub(wide::to_q::<30>(w).value).value;
                    match wide::from_q(base) {
                        // ln(base) < 0: -ln(base) / p > 0.
                        Some(base) => match fine_ln(wide::recip(base)) {
                            Some(minus_ln) => wide::mul(minus_ln, inv_abs_p),
                            None => return Decay::Vanished,
                        },
                        None => return Decay::Vanished,
                    }
                } else {
                    match fine_ln(wide::add(ONE, w)) {
                        Some(ln_base) => wide::mul(ln_base, inv_abs_p),
                        None => return Decay::Exponent(Scaled::from_ln(Q8_24::MAX)),
                    }
                };
                Decay::Exponent(lambda)
            }
        }
    }
}

/// ln(x) for x > 1 as a [`Scaled`], in the finest of Q2.30, Q6.26 and Q8.24 that holds it
/// (error 0.5 ulp + 8e-10); `None` when ln(x) >= 128.
fn fine_ln(x: Scaled) -> Option<Scaled> {
    match wide::ln::<30>(x) {
        Ok(l) => wide::from_q(l),
        Err(_) => match wide::ln::<26>(x) {
            Ok(l) => wide::from_q(l),
            Err(_) => wide::ln::<24>(x).ok().and_then(wide::from_q),
        },
    }
}

/// The series sum (Q1.31 bits in an i64, value in [0.9, 1.1]) as a [`Scaled`].
fn series_factor(sum: i64) -> Scaled {
    // sum / 2^31 in [0.93, 1.07]: as Q2.30 bits, exact to 1 ulp.
    wide::from_q(Q2_30::from_bits(((sum + 1) >> 1) as i32)).unwrap_or(ONE)
}

/// g0 e^(-lambda) for a decay: the gap g = 1 - s f, Q3.29 in [0, g0] (g0 in [0, 2]).
pub fn relaxed(g0: Q3_29, decay: Decay) -> Result<Q3_29, ModelError> {
    match decay {
        Decay::None => Ok(g0),
        Decay::Vanished => Ok(Q3_29::ZERO),
        Decay::Exponent(lambda) => {
            // Q2.30 below 2 (9.3e-10 resolution), else Q8.24 saturated at 128 (e^-128 = 0).
            let fine = wide::to_q::<30>(lambda);
            let factor = if fine.saturated {
                wide::to_q::<24>(lambda).value.exp_neg()
            } else {
                fine.value.exp_neg()
            };
            g0.checked_mul_to(factor.map_err(fx_error("lambda"))?)
                .map_err(fx_error("g"))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The exact relaxation in f64, as the reference computes it.
    fn relax_f64(g0: f64, y: f64, alpha: f64) -> f64 {
        let p = 1.0 - alpha;
        if p == 0.0 {
            return g0 * (-y).exp();
        }
        let base = 1.0 - p * y * g0.powf(-p);
        if base <= 0.0 {
            0.0
        } else {
            g0 * base.powf(1.0 / p)
        }
    }

    #[test]
    fn power_law_matches_the_closed_form() {
        let mut worst: f64 = 0.0;
        for alpha in [0.2, 0.5, 0.9, 0.999, 1.001, 1.5, 2.0, 3.0, 8.0, 20.0] {
            let law = RelaxLaw::new(alpha).unwrap();
            assert!(matches!(law, RelaxLaw::Power { .. }));
            for g0 in [1e-6, 0.01, 0.3, 1.0, 1.7, 2.0] {
                let g0q = Q3_29::from_f64(g0).unwrap();
                let factor = law.stretch_factor(g0q).unwrap();
                for y in [1e-9, 1e-5, 0.01, 0.1, 0.5, 1.0, 3.0, 30.0, 1e4, 1e9] {
                    let decay = law.decay(crate::model::scaled_from_f64(y, "y").ok(), factor);
                    let got = relaxed(g0q, decay).unwrap().to_f64();
                    let want = relax_f64(g0q.to_f64(), y, alpha);
                    let err = (got - want).abs();
                    worst = worst.max(err);
                    assert!(err < 2e-8, "alpha {alpha} g0 {g0} y {y}: {got} vs {want}");
                }
            }
        }
        eprintln!("power law max abs error {worst:e}");
        assert_eq!(RelaxLaw::new(1.0), Ok(RelaxLaw::Exponential));
        assert_eq!(RelaxLaw::new(1.0 + 1e-9), Ok(RelaxLaw::Exponential));
        assert!(RelaxLaw::new(0.0).is_err() && RelaxLaw::new(20.5).is_err());
        assert!(RelaxLaw::new(f64::NAN).is_err());
        let law = RelaxLaw::new(0.5).unwrap();
        let factor = law.stretch_factor(Q3_29::ONE).unwrap();
        assert_eq!(
            law.decay(crate::model::scaled_from_f64(2.0, "y").ok(), factor),
            Decay::Vanished
        );
        assert_eq!(law.stretch_factor(Q3_29::ZERO), None);
    }
}
