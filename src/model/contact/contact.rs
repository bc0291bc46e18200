//! Rough contact in fixed point: elastic-plastic (seed 000 eqs 1-8, default) and purely elastic
//! (Greenwood-Williamson with exponential heights: the omega_c -> infinity limit of eqs 4 and 7,
//! equal to seed 001 eqs 13-14 as corrected in physics-notes §3).
//!
//! Every force and area term is a constant times e^(-lambda d / R_q) (physics-notes §3), so
//! with K_F = F_n e^(lambda d / R_q) and p_eff = F_n / A_r, both load independent:
//!
//! - d / R_q = (ln K_F - ln F_n) / lambda,
//! - ln(A_r / A_n) = ln F_n - ln(p_eff A_n),
//! - F_e / F_n, F_p / F_n, A_e / A_r and A_p / A_r are constants.
//!
//! [`ContactConstants::new`] computes these constants once per scene in f64 (eq 4's bracket by
//! its series, physics-notes §3) and keeps ln K_F, never K_F. The hot path works on the load's
//! logarithm ln(F_n / 1 N) in Q6.26 (1 mN to 50 kN and beyond at 1.5e-8 relative resolution) and
//! returns d / R_q and ln(A_r / A_n) in Q8.24. K_t = E* A_r^2 / d^3 (seed 000 eq 9,
//! up to 1e19 N/m) is never formed in fixed point: tools compute it in f64 from these results.
//!
//! Guards (physics-notes §5): F_n <= 0 (ln 0), A_r > A_n (F_n > p_eff A_n, about 6e4 N for
//! Al/SS), d <= 0 (F_n >= K_F, about 3.4e5 N) and d / R_q below its resolution give
//! [`ModelError::OutOfDomain`]; nothing saturates silently.

use crate::fx::{Q2_30, Q6_26, Q8_24, Q16_16, ln_scaled};

use super::ModelError;
use super::contact_constants::{self as k, SceneContact};
use super::fx_error;
use crate::fx::Scaled;

pub use super::contact_constants::{ContactKind, ContactParams, EStarRule};

/// Load-independent contact constants of one scene (material pair, surface, model variant).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactConstants {
    scene: SceneContact,
    ln_force_constant: Q6_26,
    ln_full_area_load: Q6_26,
    lambda: Factor,
    inv_lambda: Factor,
    ln_shares: [Option<Q6_26>; 4],
}

/// Contact state at one load, all in fixed point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ContactState {
    /// ln(F_n / 1 N), Q6.26 in [-32, ln(p_eff A_n)].
    pub ln_load: Q6_26,
    /// Cube height over roughness d / R_q, Q8.24 in (0, 128), resolution 6e-8 (0.36 pm for
    /// R_q = 6 um).
    pub separation_rq: Q8_24,
    /// ln(A_r / A_n), Q8.24 in [-128, 0] (A_r <= A_n is enforced; Q8.24 because it reaches
    /// -36 for 1e-11 N loads), absolute error 6e-8.
    pub ln_area_ratio: Q8_24,
}

/// Elastic / plastic split of a [`ContactState`] (seed 000 eqs 3-8), as wide values; `None`
/// for a part that is absent (the plastic part of the elastic model) or below e^-32 of its
/// total.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ContactSplit {
    /// F_e in N.
    pub elastic_force: Option<Scaled>,
    /// F_p in N.
    pub plastic_force: Option<Scaled>,
    /// A_e / A_n.
    pub elastic_area_ratio: Option<Scaled>,
    /// A_p / A_n.
    pub plastic_area_ratio: Option<Scaled>,
}

/// A positive scene constant `bits * 2^-shift` with `bits` in [2^31, 2^32): 32 significant bits
/// whatever its magnitude (lambda and 1 / lambda; a Q8.24 copy would carry only 26-28).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Factor {
    bits: u64,
    shift: u32,
}

impl Factor {
    /// `value` in (2^-30, 2^30), normalised.
    fn new(quantity: &'static str, value: f64) -> Result<Self, ModelError> {
        if !(value > 1.0 / (1u64 << 30) as f64 && value < (1u64 << 30) as f64) {
            return Err(ModelError::Overflow { quantity });
        }
        let exponent = libm::floor(libm::log2(value)) as i32; // value in [2^e, 2^(e+1))
        let shift = (31 - exponent) as u32;
        let bits = libm::round(libm::scalbn(value, shift as i32)) as u64;
        // Rounding can reach 2^32: renormalise.
        Ok(if bits >= 1 << 32 {
            Self {
                bits: bits >> 1,
                shift: shift - 1,
            }
        } else {
            Self { bits, shift }
        })
    }

    /// `round(x * factor * 2^-extra)` for `x` in [0, 2^32) and `extra` in [-2, 2] (the total
    /// shift stays in [0, 63]; the product is below 2^64).
    fn scale(self, x: u64, extra: i32) -> u64 {
        let total = (self.shift as i32 + extra) as u32;
        let product = x * self.bits;
        if total == 0 {
            product
        } else {
            (product >> (total - 1)).div_ceil(2)
        }
    }
}

fn q6_26(quantity: &'static str, value: f64) -> Result<Q6_26, ModelError> {
    Q6_26::from_f64(value).map_err(fx_error(quantity))
}

impl ContactConstants {
    /// Validates SI parameters and computes the scene's constants (f64, once per scene).
    ///
    /// Errors: [`ModelError::NonFinite`] / [`ModelError::OutOfDomain`] for a parameter that is
    /// not finite, not positive, or a Poisson ratio outside (-1, 0.5]; [`ModelError::Overflow`]
    /// when ln K_F or ln(p_eff A_n) is outside [-32, 32) (K_F outside 1e-14 N to 8e13 N) or
    /// lambda outside (2^-30, 2^30).
    pub fn new(
        params: &ContactParams,
        rule: EStarRule,
        kind: ContactKind,
    ) -> Result<Self, ModelError> {
        let scene = k::scene_contact(params, rule, kind)?;
        let lambda = params.distribution_lambda;
        let part = |value: f64, total: f64| -> Option<Q6_26> {
            // A part below e^-32 of its total (or absent) is reported as None.
            if value > 0.0 {
                Q6_26::from_f64(libm::log(value / total)).ok()
            } else {
                None
            }
        };
        let forces = scene.elastic_force + scene.plastic_force;
        let areas = scene.elastic_area + scene.plastic_area;
        Ok(Self {
            ln_force_constant: q6_26("ln K_F", scene.ln_force_constant)?,
            ln_full_area_load: q6_26("ln(p_eff A_n)", scene.ln_full_area_load)?,
            lambda: Factor::new("lambda", lambda)?,
            inv_lambda: Factor::new("1 / lambda", 1.0 / lambda)?,
            ln_shares: [
                part(scene.elastic_force, forces),
                part(scene.plastic_force, forces),
                part(scene.elastic_area, areas),
                part(scene.plastic_area, areas),
            ],
            scene,
        })
    }

    /// The f64 constants of the scene (E*, omega_c, X, p_eff, ...), for tools and reports.
    pub fn scene(&self) -> &SceneContact {
        &self.scene
    }

    /// ln(K_F / 1 N), Q6.26: the load at which d would reach 0.
    pub fn ln_force_constant(&self) -> Q6_26 {
        self.ln_force_constant
    }

    /// ln(p_eff A_n / 1 N), Q6.26: the largest load the model accepts (A_r = A_n).
    pub fn ln_full_area_load(&self) -> Q6_26 {
        self.ln_full_area_load
    }

    /// Contact state under the load `ln_load` = ln(F_n / 1 N) (Q6.26, from [`ln_load`] or
    /// [`ln_load_from_si`]). Errors: `OutOfDomain` when A_r would exceed A_n, when d <= 0, or
    /// when d / R_q rounds to 0; `Overflow` when d / R_q >= 128. Cost: about 15 instructions.
    pub fn state(&self, ln_load: Q6_26) -> Result<ContactState, ModelError> {
        if ln_load > self.ln_full_area_load {
            return Err(ModelError::OutOfDomain {
                input: "F_n",
                reason: "above p_eff A_n: the real contact area would exceed the nominal area",
            });
        }
        let gap = self.ln_force_constant.to_bits() as i64 - ln_load.to_bits() as i64; // Q.26
        if gap <= 0 {
            return Err(ModelError::OutOfDomain {
                input: "F_n",
                reason: "at or above K_F: the cube height d would be <= 0",
            });
        }
        // (ln K_F - ln F_n) / lambda from Q.26 to Q.24; 0 < gap < 2^32.
        let d_bits = self.inv_lambda.scale(gap as u64, 2);
        let separation_rq =
            Q8_24::from_bits(i32::try_from(d_bits).map_err(|_| ModelError::Overflow {
                quantity: "d / R_q",
            })?);
        if separation_rq <= Q8_24::ZERO {
            return Err(ModelError::OutOfDomain {
                input: "F_n",
                reason: "d / R_q below its resolution (d -> 0, K_t ~ 1/d^3)",
            });
        }
        // ln F_n - ln(p_eff A_n) in [-64, 0]: Q.26 -> Q8.24.
        let ln_area = ln_load.to_bits() as i64 - self.ln_full_area_load.to_bits() as i64;
        let ln_area_ratio = Q8_24::from_bits(((ln_area + 2) >> 2) as i32);
        Ok(ContactState {
            ln_load,
            separation_rq,
            ln_area_ratio,
        })
    }

    /// Contact state at the cube height `separation_rq` = d / R_q (Q8.24, > 0): the forward
    /// map F_n(d) of seed 000 eqs 3-5, ln F_n = ln K_F - lambda d / R_q. Errors: `OutOfDomain`
    /// for d <= 0, for F_n < e^-32 N, and when A_r would exceed A_n. Cost: about 15 instructions.
    pub fn state_at_separation(&self, separation_rq: Q8_24) -> Result<ContactState, ModelError> {
        if separation_rq <= Q8_24::ZERO {
            return Err(ModelError::OutOfDomain {
                input: "d",
                reason: "the cube height must be > 0",
            });
        }
        // lambda d / R_q from Q.24 to Q.26 (d / R_q > 0 was checked).
        let decay = self.lambda.scale(separation_rq.to_bits() as u64, -2);
        let ln_bits = self.ln_force_constant.to_bits() as i64 - decay as i64;
        let ln_load =
            Q6_26::from_bits(i32::try_from(ln_bits).map_err(|_| ModelError::OutOfDomain {
                input: "d",
                reason: "so large that F_n < e^-32 N",
            })?);
        let state = self.state(ln_load)?;
        Ok(ContactState {
            separation_rq,
            ..state
        })
    }

    /// Elastic / plastic split of `state`: each part is the total times a scene constant
    /// (seed 000 eqs 4-8 share the factor e^(-lambda d / R_q)); the logarithms are summed in
    /// Q8.24 (A_e / A_n reaches e^-36 at 1 mN). Cost: four `exp`.
    pub fn split(&self, state: &ContactState) -> ContactSplit {
        // Totals and shares as Q.26 logarithms; the sums (> -2^33) are rounded to Q8.24.
        let part = |total: i64, share: Option<Q6_26>| {
            share.map(|s| {
                let sum = total + s.to_bits() as i64;
                Scaled::from_ln(Q8_24::from_bits(((sum + 2) >> 2) as i32))
            })
        };
        let (ln_load, ln_area) = (
            state.ln_load.to_bits() as i64,
            4 * state.ln_area_ratio.to_bits() as i64,
        );
        ContactSplit {
            elastic_force: part(ln_load, self.ln_shares[0]),
            plastic_force: part(ln_load, self.ln_shares[1]),
            elastic_area_ratio: part(ln_area, self.ln_shares[2]),
            plastic_area_ratio: part(ln_area, self.ln_shares[3]),
        }
    }
}

impl ContactState {
    /// A_r / A_n, Q2.30 in [0, 1] (absolute error 1 ulp = 9.3e-10: use [`Self::area_scaled`]
    /// for full relative precision at small loads). Cost: one `exp`.
    pub fn area_ratio(&self) -> Q2_30 {
        // ln_area_ratio <= 0, so e^x <= 1 always fits Q2.30.
        self.ln_area_ratio.exp::<30>().unwrap_or(Q2_30::ONE)
    }

    /// A_r / A_n as a wide value (relative error ~1e-8 at every load).
    pub fn area_scaled(&self) -> Scaled {
        Scaled::from_ln(self.ln_area_ratio)
    }

    /// F_n in N as a wide value (for the forward map F_n(d)).
    pub fn load_scaled(&self) -> Scaled {
        Scaled::from_ln(self.ln_load)
    }
}

/// ln(F_n / 1 N) in Q6.26 from a load in N, Q16.16 (the [`super::OperatingPoint`] format).
/// Error: `OutOfDomain` for F_n <= 0 (ln 0). Error 8e-9 (fx `ln`); cost about 50 instructions.
pub fn ln_load(normal_force: Q16_16) -> Result<Q6_26, ModelError> {
    if normal_force <= Q16_16::ZERO {
        return Err(ModelError::OutOfDomain {
            input: "F_n",
            reason: "the normal load must be > 0 (ln 0)",
        });
    }
    normal_force.ln::<26>().map_err(fx_error("ln F_n"))
}

/// ln(F_n / 1 N) in Q6.26 from an SI load in N given as f64 (scene set-up and host tools): the
/// float is split exactly into a 53-bit integer and a power of two, and the logarithm is the
/// fixed-point one (`fx::ln_scaled`). Errors: `NonFinite`; `OutOfDomain` for F_n <= 0 or
/// outside [e^-32, e^32) N.
pub fn ln_load_from_si(normal_force: f64) -> Result<Q6_26, ModelError> {
    let load = k::positive("F_n", normal_force)?;
    let bits = load.to_bits();
    let biased = ((bits >> 52) & 0x7ff) as i32;
    let fraction = bits & ((1u64 << 52) - 1);
    let (mantissa, exp2) = if biased == 0 {
        (fraction, -1074) // subnormal
    } else {
        (fraction | (1u64 << 52), biased - 1075)
    };
    let exp2 = i16::try_from(exp2).unwrap_or(i16::MIN); // always fits: -1074..=971
    ln_scaled::<26>(mantissa, exp2).map_err(|_| ModelError::OutOfDomain {
        input: "F_n",
        reason: "outside [e^-32, e^32) N",
    })
}

#[cfg(test)]
#[path = "contact_tests.rs"]
mod tests;
