//! Friction targets as a friction ratio `F'/F` (with vibration over without), and back.
//!
//! The loop controls the ratio `r = mu / mu0` (Q2.30, 1.0 = natural friction), because that
//! is what the friction model maps to an amplitude. The three protocol targets become:
//! - `Force { force_mn }`: `r = F / (mu0 F_n)`, per step (the normal load moves);
//! - `Coef { coef_ppm }`: `r = coef / mu0`;
//! - `Reduction { reduction_mpct }`: `r = 1 - reduction`;
//! - `NetForce { force_mn }` (issue 27): in the horn's transition region the horn's force on
//!   a sliding block is friction, so the friction path holds its magnitude as a force target;
//!   in a motor region the station's net-force hold (`super::net_force`) drives instead.
//!
//! [`PreparedTarget::new`] does the decimal scaling (one integer division each) when the target
//! is set; [`PreparedTarget::ratio`] then needs only reciprocal multiplies per step. A ratio
//! that does not fit Q2.30 (a force far above the natural friction) is clamped to just below
//! 2.0 and flagged: it is above natural friction either way.

use super::recip::Reciprocal;
use crate::fx::{Q, Q2_30, Q16_16, Sat};
use crate::protocol::{Target, TargetRange};

/// Force targets are kept in newtons as Q18.14: up to 131072 N (the protocol allows 50 kN),
/// resolution 6.1e-5 N (the protocol's is 1 mN).
pub type ForceQ = Q<14>;

/// A target converted once to fixed point, ready for [`Self::ratio`] every step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum PreparedTarget {
    /// Hold this friction force, newtons, Q18.14, positive.
    Force(ForceQ),
    /// Hold this friction coefficient, Q2.30 in (0, 2].
    Coef(Q2_30),
    /// Hold this friction ratio `1 - reduction`, Q2.30 in (0, 1].
    Reduction(Q2_30),
}

impl PreparedTarget {
    /// Converts a protocol target. `None` unless [`Target::is_valid`] (its command range).
    pub fn new(target: &Target) -> Option<Self> {
        if !target.is_valid() {
            return None;
        }
        // Valid values are below 2^31; from_ratio rounds to nearest and cannot fail here.
        let scaled = target.scaled_value() as i32;
        let prepared = match target {
            Target::Force { .. } => Self::Force(ForceQ::from_ratio(scaled, 1_000).ok()?),
            Target::NetForce { force_mn } => {
                // |F| <= 50 kN by the range check: fits i32 and Q18.14.
                let magnitude = force_mn.unsigned_abs() as i32;
                Self::Force(ForceQ::from_ratio(magnitude, 1_000).ok()?)
            }
            Target::Coef { .. } => {
                // 2.0 itself (2_000_000 ppm) does not fit Q2.30: take the largest value.
                let coef = Q2_30::from_ratio(scaled, 1_000_000).unwrap_or(Q2_30::MAX);
                Self::Coef(coef)
            }
            Target::Reduction { .. } => {
                Self::Reduction(Q2_30::from_ratio(100_000 - scaled, 100_000).ok()?)
            }
        };
        Some(prepared)
    }

    /// The friction ratio to hold, given the reciprocals of the natural friction coefficient
    /// `mu0` and of the (filtered, guarded) normal force in newtons. Clamped to [0, 2) and
    /// flagged when clamped.
    pub fn ratio(
        &self,
        natural_reciprocal: Reciprocal,
        normal_reciprocal: Reciprocal,
    ) -> Sat<Q2_30> {
        match *self {
            Self::Force(force) => {
                let coef: Sat<Q2_30> = normal_reciprocal.times(force);
                let ratio: Sat<Q2_30> = natural_reciprocal.times(coef.value);
                Sat {
                    value: ratio.value,
                    saturated: coef.saturated || ratio.saturated,
                }
            }
            Self::Coef(coef) => natural_reciprocal.times(coef),
            Self::Reduction(ratio) => Sat::exact(ratio),
        }
    }

    /// The protocol target of the same kind that a friction `ratio` amounts to, for reports:
    /// `force = ratio mu0 F_n`, `coef = ratio mu0`, `reduction = 1 - ratio`. Values are
    /// rounded to the protocol's resolution and clamped to `u32` (a negative reduction, i.e.
    /// a ratio above 1, reports 0).
    pub fn report(&self, ratio: Q2_30, natural: Q2_30, normal_force: Q16_16) -> Target {
        let coef = ratio.saturating_mul(natural).value; // Q2.30
        match self {
            Self::Force(_) => {
                // coef (Q.30) * F_n (Q.16): |product| < 2^62, force in Q.16 below 2^32 N.
                let product = coef.to_bits() as i64 * normal_force.to_bits() as i64;
                let force_q16 = (product.max(0) + (1 << 29)) >> 30;
                let mn = (force_q16 * 1_000 + (1 << 15)) >> 16; // < 2^42: no overflow
                Target::Force {
                    force_mn: mn.min(u32::MAX as i64) as u32,
                }
            }
            Self::Coef(_) => Target::Coef {
                coef_ppm: scale_unit(coef, 1_000_000),
            },
            Self::Reduction(_) => {
                let reduction = Q2_30::ONE.saturating_sub(ratio).value;
                Target::Reduction {
                    reduction_mpct: scale_unit(reduction, 100_000),
                }
            }
        }
    }
}

/// `value * unit`, rounded, negative values as 0.
fn scale_unit(value: Q2_30, unit: u32) -> u32 {
    // < 2 unit <= 2e6: fits.
    value.round_scaled(unit).clamp(0, u32::MAX as i64) as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    fn recip_n(newtons: f64) -> Reciprocal {
        Reciprocal::of(Q16_16::from_f64(newtons).unwrap()).unwrap()
    }

    fn recip_mu(mu: f64) -> Reciprocal {
        Reciprocal::of(Q2_30::from_f64(mu).unwrap()).unwrap()
    }

    #[test]
    fn the_three_kinds_become_ratios() {
        let (mu0, fn_n) = (0.3, 40.0);
        let cases = [
            (Target::Force { force_mn: 6_000 }, 0.5f64), // 6 N / (0.3 * 40 N)
            (Target::Coef { coef_ppm: 150_000 }, 0.5),
            (
                Target::Reduction {
                    reduction_mpct: 50_000,
                },
                0.5,
            ),
            (Target::Reduction { reduction_mpct: 0 }, 1.0),
            (Target::Force { force_mn: 24_000 }, 2.0), // twice natural: clamped
        ];
        for (target, want) in cases {
            let prepared = PreparedTarget::new(&target).unwrap();
            let r = prepared.ratio(recip_mu(mu0), recip_n(fn_n));
            assert_eq!(r.saturated, want >= 2.0, "{target:?}");
            let want = want.min(Q2_30::MAX.to_f64());
            assert!((r.value.to_f64() - want).abs() < 1e-6, "{target:?}: {r:?}");
        }
        // 50 kN on 1 N of load: far above natural, clamped, no overflow.
        let huge = PreparedTarget::new(&Target::Force {
            force_mn: 50_000_000,
        })
        .unwrap();
        assert!(huge.ratio(recip_mu(0.001), recip_n(0.001)).saturated);
    }

    #[test]
    fn invalid_targets_are_refused() {
        assert_eq!(PreparedTarget::new(&Target::Force { force_mn: 0 }), None);
        assert_eq!(
            PreparedTarget::new(&Target::Coef {
                coef_ppm: 2_000_001
            }),
            None
        );
        assert_eq!(
            PreparedTarget::new(&Target::Reduction {
                reduction_mpct: 100_000
            }),
            None
        );
        assert!(
            PreparedTarget::new(&Target::Coef {
                coef_ppm: 2_000_000
            })
            .is_some()
        );
    }

    #[test]
    fn reports_round_trip_to_the_protocol_resolution() {
        let mu0 = Q2_30::from_f64(0.3).unwrap();
        let fn_n = Q16_16::from_int(40).unwrap();
        for target in [
            Target::Force { force_mn: 6_000 },
            Target::Force { force_mn: 1 },
            Target::Coef { coef_ppm: 123_456 },
            Target::Reduction {
                reduction_mpct: 37_500,
            },
            Target::Reduction {
                reduction_mpct: 99_999,
            },
        ] {
            let prepared = PreparedTarget::new(&target).unwrap();
            let recip_mu0 = Reciprocal::of(mu0).unwrap();
            let recip_fn = Reciprocal::of(fn_n).unwrap();
            let ratio = prepared.ratio(recip_mu0, recip_fn).value;
            assert_eq!(prepared.report(ratio, mu0, fn_n), target);
        }
        // A ratio above natural reports a reduction of 0, not a wrapped number.
        let r = PreparedTarget::Reduction(Q2_30::ONE);
        assert_eq!(
            r.report(Q2_30::from_f64(1.5).unwrap(), mu0, fn_n),
            Target::Reduction { reduction_mpct: 0 }
        );
    }
}
