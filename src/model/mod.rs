//! The friction model in fixed point: the hot-path half of every model in the papers.
//!
//! Each model is split the same way (physics-notes §5):
//! - a *constants* type built once per scene from SI inputs in `f64` (materials, surface, geometry,
//!   actuator): every overflow- or underflow-prone quantity (E*, K_F, omega_c, K_t, ...) is folded
//!   into dimensionless groups there, and its logarithm is carried instead where needed;
//! - a *hot path* in fixed point (`crate::fx`), called per control step, whose inputs and outputs
//!   state their Q format and range in the type or the doc comment.
//!
//! Inputs outside a model's validity give a [`ModelError`] or a documented, flagged saturation,
//! never a panic, a wrap or a NaN.
//!
//! # Example
//!
//! The Coulomb model of seed 003 (mu 0.3, 40 kHz, 0.3 um full-scale amplitude: v_a,max =
//! 2 pi f x_a = 0.0754 m/s) at half that sliding speed: zeta = 1/2 at full amplitude, where
//! the Littmann law gives F'/F = (2/pi) asin(1/2) = 1/3. Inverting it gives the amplitude for
//! a target ratio.
//!
//! ```
//! use sonolube::fx::{Q1_31, Q2_30, Q8_24, Q16_16};
//! use sonolube::model::coulomb::{CoulombConstants, CoulombModel};
//! use sonolube::model::{FrictionModel, OperatingPoint, Reach};
//!
//! let model = CoulombModel {
//!     constants: CoulombConstants::new(0.3, 40_000.0, 0.3e-6)?,
//! };
//! let v_a_max = core::f64::consts::TAU * 40_000.0 * 0.3e-6;
//! let point = OperatingPoint {
//!     normal_force: Q16_16::from_f64(10.0)?,
//!     sliding_velocity: Q8_24::from_f64(0.5 * v_a_max)?,
//! };
//! // No vibration: the natural friction, exactly.
//! assert_eq!(model.ratio(&point, Q1_31::ZERO)?, Q2_30::ONE);
//! // Full amplitude: 1/3 (the velocity's Q8.24 rounding moves it by 1e-7).
//! let full = model.ratio(&point, Q1_31::MAX)?.to_f64();
//! assert!((full - 1.0 / 3.0).abs() < 1e-6, "{full}");
//! // Half the friction is reachable; a fifth is not (below 1/3): full drive, flagged.
//! let half = model.invert(&point, Q2_30::from_ratio(1, 2)?)?;
//! assert_eq!(half.reach, Reach::Reached);
//! assert!((half.ratio.to_f64() - 0.5).abs() < 1e-4);
//! let fifth = model.invert(&point, Q2_30::from_ratio(1, 5)?)?;
//! assert_eq!(fifth.reach, Reach::BelowMinimum);
//! # Ok::<(), Box<dyn core::error::Error>>(())
//! ```

use core::fmt;

// One folder per model family (dahl/, cube/, contact/, coulomb/, exp_coulomb/); the modules
// keep their flat names (`model::dahl_steady`), so every path into them is unchanged.
pub mod actuator;
pub mod any_model;
#[path = "contact/contact.rs"]
pub mod contact;
#[path = "contact/contact_constants.rs"]
pub mod contact_constants;
#[path = "coulomb/coulomb.rs"]
pub mod coulomb;
#[path = "coulomb/coulomb_sampled.rs"]
pub mod coulomb_sampled;
#[path = "cube/cube.rs"]
pub mod cube;
#[path = "cube/cube_model.rs"]
pub mod cube_model;
#[path = "cube/cube_nodes.rs"]
mod cube_nodes;
#[path = "cube/cube_table.rs"]
pub mod cube_table;
#[path = "dahl/dahl.rs"]
pub mod dahl;
#[path = "dahl/dahl_table.rs"]
pub mod dahl_table;
#[path = "dahl/dahl_table_nodes.rs"]
#[rustfmt::skip]
pub mod dahl_table_nodes;
#[path = "dahl/dahl_cycle.rs"]
pub(crate) mod dahl_cycle;
#[path = "dahl/dahl_quadrature.rs"]
pub(crate) mod dahl_quadrature;
#[path = "dahl/dahl_relax.rs"]
pub mod dahl_relax;
#[path = "dahl/dahl_steady.rs"]
pub mod dahl_steady;
#[cfg(test)]
#[path = "dahl/dahl_tests.rs"]
mod dahl_tests;
#[path = "dahl/dahl_travel.rs"]
pub(crate) mod dahl_travel;
#[path = "dahl/dahl_window.rs"]
pub mod dahl_window;
#[path = "exp_coulomb/exp_average.rs"]
pub mod exp_average;
#[path = "exp_coulomb/exp_coulomb.rs"]
pub mod exp_coulomb;
pub mod horn;
#[path = "coulomb/littmann.rs"]
pub mod littmann;
#[path = "motor/motor.rs"]
pub mod motor;
#[path = "motor/motor_regions.rs"]
pub mod motor_regions;
#[cfg(test)]
#[path = "motor/motor_tests.rs"]
mod motor_tests;
pub mod quadrature;

pub use any_model::AnyModel;

use crate::fx::{FxError, Q1_31, Q2_30, Q8_24, Q16_16, Scaled, wide};

/// Why a model could not be evaluated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ModelError {
    /// An SI input is NaN or infinite.
    NonFinite {
        /// Name of the input, as in the evaluation tool's key table.
        input: &'static str,
    },
    /// An input is outside the model's domain of validity.
    OutOfDomain {
        /// Name of the input.
        input: &'static str,
        /// Which bound it breaks, in words.
        reason: &'static str,
    },
    /// A value does not fit the fixed-point format that carries it.
    Overflow {
        /// Name of the quantity.
        quantity: &'static str,
    },
}

impl fmt::Display for ModelError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NonFinite { input } => write!(f, "input {input} is not a finite number"),
            Self::OutOfDomain { input, reason } => {
                write!(f, "input {input} is out of domain: {reason}")
            }
            Self::Overflow { quantity } => {
                write!(f, "{quantity} does not fit its fixed-point format")
            }
        }
    }
}

impl core::error::Error for ModelError {}

/// Operating point of the sliding contact, in the units the control step carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct OperatingPoint {
    /// Normal load F_n in newtons, Q16.16: 0 < F_n < 32768 N, resolution 15 uN.
    pub normal_force: Q16_16,
    /// Sliding velocity in m/s, Q8.24: |v| < 128 m/s, resolution 6e-8 m/s.
    pub sliding_velocity: Q8_24,
}

/// Whether a requested friction ratio can be reached by some vibration amplitude.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Reach {
    /// The returned amplitude achieves the target (within the inversion's tolerance).
    Reached,
    /// The target is below the lowest friction the model gives at full amplitude: the returned
    /// amplitude is the full amplitude, the nearest reachable point.
    BelowMinimum,
    /// The target is above the natural (no-vibration) friction: the returned amplitude is zero.
    AboveNatural,
}

/// Result of inverting a model: the vibration amplitude for a target friction ratio.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Inversion {
    /// Vibration amplitude as a fraction of the scene's full-scale amplitude, Q1.31 in [0, 1).
    pub amplitude: Q1_31,
    /// Friction ratio F'/F that the model gives at `amplitude`, Q2.30 in [0, 1].
    pub ratio: Q2_30,
    /// Whether the target was reachable.
    pub reach: Reach,
}

/// A friction model the controller can evaluate and invert at an operating point.
///
/// The model's amplitude is dimensionless: a fraction of the scene's full-scale vibration
/// amplitude (how a drive voltage becomes a vibration amplitude is the actuator's business).
/// Physics makes every model here monotone non-increasing in amplitude, which [`invert`] relies
/// on.
pub trait FrictionModel {
    /// Friction ratio F'/F (with vibration over without), Q2.30 in [0, 1], at `amplitude`
    /// (Q1.31 fraction of full scale, in [0, 1)).
    fn ratio(&self, point: &OperatingPoint, amplitude: Q1_31) -> Result<Q2_30, ModelError>;

    /// The amplitude that gives `target` (Q2.30, F'/F). The default bisects [`Self::ratio`];
    /// models with a closed-form inverse override it.
    fn invert(&self, point: &OperatingPoint, target: Q2_30) -> Result<Inversion, ModelError> {
        invert(self, point, target, BISECTION_STEPS)
    }

    /// [`Self::invert`] with a hint: `start` (Q1.31 fraction of full scale, [0, 1)) is where
    /// the answer probably is, e.g. the previous control step's amplitude. Iterative inverses
    /// start there (the cube model's Newton iteration: fewer evaluations when the load and the
    /// target moved little); the result meets the same tolerance as [`Self::invert`]'s, from
    /// any `start`. The default ignores the hint.
    fn invert_from(
        &self,
        point: &OperatingPoint,
        target: Q2_30,
        start: Q1_31,
    ) -> Result<Inversion, ModelError> {
        let _ = start;
        self.invert(point, target)
    }

    /// Whether the load enters the model only through the Coulomb force `F_c = mu W` with the
    /// model's own `mu` (the Dahl steady state: `kappa x_a = k_t x_a / (mu W)`). For such a
    /// model the controller passes the load scaled by `mu0 / mu` (learned natural friction
    /// over the model's), so that the model sees the measured Coulomb force `mu0 W`. The
    /// default, `false`, is right for models whose ratio does not depend on `mu` (the
    /// Coulomb ratio depends on neither `mu` nor `W`; the cube's load is a normal contact's).
    fn load_enters_as_coulomb_force(&self) -> bool {
        false
    }
}

/// Bisection steps of the default inversion: 2^-16 of full scale, finer than the drive's
/// amplitude resolution.
pub const BISECTION_STEPS: u32 = 16;

/// Inverts a monotone non-increasing model by bisection over the amplitude, with `steps`
/// halvings (the amplitude is then within 2^-steps of full scale of the exact inverse).
pub fn invert<M: FrictionModel + ?Sized>(
    model: &M,
    point: &OperatingPoint,
    target: Q2_30,
    steps: u32,
) -> Result<Inversion, ModelError> {
    let natural = model.ratio(point, Q1_31::ZERO)?;
    if target >= natural {
        return Ok(Inversion {
            amplitude: Q1_31::ZERO,
            ratio: natural,
            reach: Reach::AboveNatural,
        });
    }
    let full = model.ratio(point, Q1_31::MAX)?;
    if target <= full {
        return Ok(Inversion {
            amplitude: Q1_31::MAX,
            ratio: full,
            reach: Reach::BelowMinimum,
        });
    }
    // Invariant: ratio(low) > target > ratio(high).
    let (mut low, mut high) = (0i32, Q1_31::MAX.to_bits());
    let mut ratio_high = full;
    for _ in 0..steps.min(31) {
        let mid = low + (high - low) / 2;
        let ratio = model.ratio(point, Q1_31::from_bits(mid))?;
        if ratio > target {
            low = mid;
        } else {
            high = mid;
            ratio_high = ratio;
        }
    }
    Ok(Inversion {
        amplitude: Q1_31::from_bits(high),
        ratio: ratio_high,
        reach: Reach::Reached,
    })
}

/// A finite, strictly positive SI value (scene load only: f64). `input` names it in the error:
/// `NonFinite` for NaN and infinities, `OutOfDomain` for values <= 0.
pub fn scaled_from_f64(x: f64, input: &'static str) -> Result<Scaled, ModelError> {
    if !x.is_finite() {
        return Err(ModelError::NonFinite { input });
    }
    if x <= 0.0 {
        return Err(ModelError::OutOfDomain {
            input,
            reason: "must be > 0",
        });
    }
    let (fraction, exponent) = libm::frexp(x); // x = fraction 2^exponent, fraction in [0.5, 1)
    let bits = libm::round(fraction * 2_147_483_648.0) as u64; // [2^30, 2^31]
    Ok(if bits >> 31 != 0 {
        wide::make(wide::ONE_BITS, exponent)
    } else {
        wide::make(bits, exponent - 1)
    })
}

/// Maps an [`FxError`] of a fixed-point step to the [`ModelError`] naming `quantity`.
pub(crate) fn fx_error(quantity: &'static str) -> impl Fn(FxError) -> ModelError {
    move |error| match error {
        FxError::Overflow => ModelError::Overflow { quantity },
        FxError::NotFinite => ModelError::NonFinite { input: quantity },
        FxError::DivisionByZero | FxError::Domain => ModelError::OutOfDomain {
            input: quantity,
            reason: "outside the domain of a fixed-point function (ln of 0, division by 0)",
        },
    }
}

#[cfg(test)]
mod tests {
    use super::ModelError;

    /// Each error's text is a sentence that names the input or quantity at fault, and the
    /// bound it breaks.
    #[test]
    fn model_errors_name_what_is_wrong() {
        let cases = [
            (
                ModelError::NonFinite { input: "F_n" },
                "input F_n is not a finite number",
            ),
            (
                ModelError::OutOfDomain {
                    input: "v",
                    reason: "must be below 128 m/s",
                },
                "input v is out of domain: must be below 128 m/s",
            ),
            (
                ModelError::Overflow { quantity: "K_t" },
                "K_t does not fit its fixed-point format",
            ),
        ];
        for (error, text) in cases {
            assert_eq!(format!("{error}"), text);
        }
    }
}
