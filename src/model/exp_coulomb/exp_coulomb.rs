//! The exponential (Stribeck-like) Coulomb law of seed 002 eq 10 in fixed point:
//! F_f = (mu_d + (mu_s - mu_d) e^(-alpha_dc |V_s|)) F_N, the magnitude of the friction force
//! (its direction is -sgn V_s). Table 1 of seed 002: mu_s = 0.42, mu_d = 0.32,
//! alpha_dc = 0.01 s/m, F_N = 15 N, V_s = 0.11 m/s (F_f = 6.2984 N).
//!
//! alpha_dc |V_s| is formed as a wide product and handed to `exp_neg` in Q2.30 below 2 (9.3e-10
//! resolution) or Q8.24 above, saturated at 128 (e^-128 is 0 in Q2.30: saturation there is
//! exact, not an error). The coefficient is mu_d + (mu_s - mu_d) e^-y by one rounded `lerp`.

use crate::fx::{Q, Q2_30, Q8_24};

use super::ModelError;
use super::coulomb::friction_coefficient_q;
use super::fx_error;
use crate::fx::Scaled;
use crate::fx::wide;

/// Scene constants of seed 002 eq 10.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ExpCoulombConstants {
    static_coefficient: Q8_24,
    dynamic_coefficient: Q8_24,
    decay: Option<Scaled>,
}

impl ExpCoulombConstants {
    /// From the static and dynamic friction coefficients mu_s, mu_d (dimensionless, [0, 128))
    /// and the decay coefficient alpha_dc in s/m (>= 0). f64, scene load. Errors: `NonFinite`,
    /// `OutOfDomain` for values outside those ranges.
    pub fn new(
        static_coefficient: f64,
        dynamic_coefficient: f64,
        decay_s_per_m: f64,
    ) -> Result<Self, ModelError> {
        let decay = if decay_s_per_m == 0.0 {
            None
        } else {
            Some(crate::model::scaled_from_f64(decay_s_per_m, "alpha_dc")?)
        };
        Ok(Self {
            static_coefficient: friction_coefficient_q("mu_s", static_coefficient)?,
            dynamic_coefficient: friction_coefficient_q("mu_d", dynamic_coefficient)?,
            decay,
        })
    }

    /// mu(V_s) = mu_d + (mu_s - mu_d) e^(-alpha_dc |V_s|), Q8.24 between mu_d and mu_s, for a
    /// slip velocity `slip_velocity` in m/s (any format, any sign). Error <= 1 ulp of Q8.24
    /// (6e-8) plus |mu_s - mu_d| 7e-10. Never fails in practice (the `Result` carries fx
    /// errors that the ranges exclude). Cost: a product, one `exp_neg`, one `lerp`; with the
    /// product by F_N ([`Self::friction`]) 206 instructions on the Cortex-M4 (measured).
    pub fn coefficient<const FV: u32>(&self, slip_velocity: Q<FV>) -> Result<Q8_24, ModelError> {
        let speed = wide::from_q(slip_velocity.saturating_abs().value);
        let decay = match (self.decay, speed) {
            (Some(alpha), Some(speed)) => {
                let y = wide::mul(alpha, speed);
                let fine = wide::to_q::<30>(y);
                if fine.saturated {
                    wide::to_q::<24>(y).value.exp_neg()
                } else {
                    fine.value.exp_neg()
                }
                .map_err(fx_error("alpha_dc |V_s|"))?
            }
            _ => Q2_30::ONE, // no decay or no slip: the static coefficient
        };
        self.dynamic_coefficient
            .lerp(self.static_coefficient, decay)
            .map_err(fx_error("mu"))
    }

    /// F_f = mu(V_s) F_N in newtons, in the format of `normal_force` (F_N in newtons, >= 0).
    /// Errors: `OutOfDomain` for F_N < 0; `Overflow` when F_f does not fit `Q<FN>` (pick a
    /// format with room for mu_s F_N).
    pub fn friction<const FN: u32, const FV: u32>(
        &self,
        slip_velocity: Q<FV>,
        normal_force: Q<FN>,
    ) -> Result<Q<FN>, ModelError> {
        if normal_force.is_negative() {
            return Err(ModelError::OutOfDomain {
                input: "F_N",
                reason: "must be >= 0",
            });
        }
        let mu = self.coefficient(slip_velocity)?;
        normal_force.checked_mul_to(mu).map_err(fx_error("F_f"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fx::Q16_16;

    fn exact(mu_s: f64, mu_d: f64, alpha: f64, vs: f64, f_n: f64) -> f64 {
        (mu_d + (mu_s - mu_d) * (-alpha * vs.abs()).exp()) * f_n
    }

    #[test]
    fn seed_002_table_1() {
        let c = ExpCoulombConstants::new(0.42, 0.32, 0.01).unwrap();
        let f = c
            .friction(
                Q8_24::from_f64(0.11).unwrap(),
                Q16_16::from_int(15).unwrap(),
            )
            .unwrap();
        assert!((f.to_f64() - 6.298_350_907_167).abs() < 2e-5, "{f:?}");
        let back = c
            .friction(
                Q8_24::from_f64(-0.11).unwrap(),
                Q16_16::from_int(15).unwrap(),
            )
            .unwrap();
        assert_eq!(back, f);
    }

    #[test]
    fn sweep_against_f64_and_limits() {
        let mut worst: f64 = 0.0;
        for (mu_s, mu_d, alpha) in [(0.42, 0.32, 0.01), (0.3, 0.6, 5.0), (1.2, 0.1, 300.0)] {
            let c = ExpCoulombConstants::new(mu_s, mu_d, alpha).unwrap();
            for k in 0..=2000 {
                let vs = Q8_24::from_f64(-50.0 + k as f64 * 0.05).unwrap();
                let mu = c.coefficient(vs).unwrap().to_f64();
                let want = exact(mu_s, mu_d, alpha, vs.to_f64(), 1.0);
                worst = worst.max((mu - want).abs());
            }
        }
        assert!(worst < 2e-7, "coefficient error {worst:e}");
        let c = ExpCoulombConstants::new(0.42, 0.32, 0.0).unwrap();
        // alpha_dc = 0 (or V_s = 0): the static coefficient, exactly.
        let mu_s = Q8_24::from_f64(0.42).unwrap();
        assert_eq!(c.coefficient(Q8_24::from_int(100).unwrap()), Ok(mu_s));
        let static_case = ExpCoulombConstants::new(0.42, 0.32, 0.01).unwrap();
        assert_eq!(static_case.coefficient(Q8_24::ZERO), Ok(mu_s));
        let stiff = ExpCoulombConstants::new(0.42, 0.32, 1e9).unwrap();
        assert_eq!(
            stiff.coefficient(Q8_24::ONE),
            Ok(Q8_24::from_f64(0.32).unwrap())
        );
        assert!(stiff.friction(Q8_24::ONE, Q16_16::from_bits(-1)).is_err());
        assert!(
            stiff
                .friction(Q8_24::ONE, Q16_16::from_int(30_000).unwrap())
                .is_ok()
        );
        let big = ExpCoulombConstants::new(2.0, 2.0, 1.0).unwrap();
        assert!(matches!(
            big.friction(Q8_24::ONE, Q16_16::from_int(30_000).unwrap()),
            Err(ModelError::Overflow { .. })
        ));
        assert!(ExpCoulombConstants::new(-0.1, 0.3, 1.0).is_err());
        assert!(ExpCoulombConstants::new(0.1, 0.3, -1.0).is_err());
        assert!(ExpCoulombConstants::new(0.1, f64::NAN, 1.0).is_err());
    }
}
