//! Dahl friction (seed 003 eqs 5-7, seed 000 eq 10; physics-notes §2): scene constants, the
//! drive's dimensionless groups, and the exact single-step update for a time-stepping plant.
//! The relaxation laws are in [`super::dahl_relax`], the periodic models in
//! [`super::dahl_steady`] and [`super::dahl_window`].
//!
//! dz/dt = v (1 - (k_t z / F_c) sgn v)^alpha, F = k_t z, F_c = mu W. With f = F / F_c in [-1, 1]
//! the model is rate independent: along a stretch travelled in one direction s, g = 1 - s f
//! obeys dg/dxi = -kappa g^alpha (kappa = k_t / F_c, xi the distance), whose exact solution
//! after a travel exponent y = kappa xi is
//! - alpha = 1: g = g0 e^(-y), i.e. f_new = s + (f_old - s) e^(-kappa |dx|) ([`update`]):
//!   unconditionally stable and bounded, unlike explicit Euler (physics-notes §2);
//! - alpha != 1 (p = 1 - alpha): g = g0 (1 - p y g0^(-p))^(1/p), clamped at g = 0 for
//!   alpha < 1 where the base reaches 0 (physics-notes §2: the right-hand side is not Lipschitz
//!   at g = 0), evaluated by [`RelaxLaw`] (closed form, no step-size limit).
//!
//! State formats: f in Q2.30 ([-1, 1] with an exact +-1), the gap g = 1 - s f in Q3.29
//! ([0, 2], exact 2; 1.9e-9 resolution). kappa and
//! k_t are never formed in a fixed format (k_t up to 1e10 N/m, kappa up to 1e13 1/m): the
//! scene keeps k_t / mu and k_t x_a,max / mu as [`Scaled`] values and the hot path forms the
//! dimensionless products kappa x_a and kappa |dx| (physics-notes §5).

use crate::fx::{Q, Q1_31, Q2_30, Q8_24};

use super::ModelError;
use super::coulomb::friction_coefficient_q;
use super::dahl_relax::RelaxLaw;
use super::littmann::{VelocityRatio, velocity_ratio};
use crate::fx::scaled::Scaled;
use crate::fx::wide;

/// Largest quadrature node count per period accepted by the periodic models.
pub const MAX_QUADRATURE_POINTS: u32 = 4096;

/// SI parameters of a Dahl scene (f64, scene load).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DahlParams {
    /// Friction coefficient mu, in (0, 128); F_c = mu W.
    pub friction_coefficient: f64,
    /// Tangential contact stiffness k_t in N/m (> 0; seed 003: 0.056 N/um = 5.6e4 N/m).
    pub tangential_stiffness: f64,
    /// Vibration frequency f in Hz (> 0).
    pub frequency_hz: f64,
    /// Full-scale vibration displacement amplitude x_a,max in m (> 0): amplitude 1.0.
    pub full_scale_amplitude_m: f64,
    /// Shape exponent alpha in (0, 20] (seed 003: 1).
    pub shape_exponent: f64,
    /// Quadrature nodes per period N, even, 4..=4096 (periodic models only).
    pub quadrature_points: u32,
}

/// The exact Dahl update for alpha = 1 (physics-notes §2): f_new = s + (f_old - s)
/// e^(-kappa |dx|), s = +1 for `forward` travel (v > 0), -1 otherwise.
///
/// Inputs: `f` = F / (mu W) in Q2.30: a Dahl state in [-1, 1], or any value in [-2, 2) (a
/// transient started beyond the Coulomb level, seed 000 eq 10 from |delta0| > F_t0 / K_t,
/// relaxes exactly too); `kappa_travel` = kappa |dx| >= 0 in any format (Q2.30 keeps 9.3e-10
/// resolution for per-step values below 2; pass a saturated Q8.24 for larger ones: e^-128 is
/// 0). Output Q2.30 between s and f by construction (never outside the range of its inputs),
/// rounded to nearest (no drift over 1e4 steps, physics-notes §5). Error `OutOfDomain` for
/// negative `kappa_travel`.
///
/// For |f| <= 1 it runs in the gap form g = 1 - s f in [0, 2] (an unsigned Q.30, exact),
/// g' = g e^-y, f' = s (1 - g'), with e^-y taken unrounded in Q.32 from `exp_neg`'s table and
/// polynomial (within [-1.7, +0.7] units of 2^-32 below y = 2) and one `UMLAL` that rounds
/// g' once: error < 1.05 ulp of Q2.30 (0.5 for the rounding, and |g| <= 2 times the decay's
/// error, within 1.1 units of 2^-32 once half a unit is added back for its floor; 1.02 ulp
/// measured on a dense grid; the previous form, which rounded the decay to Q2.30 first, was
/// bounded by 2 ulp), nothing can overflow.
/// States beyond the Coulomb level go through `lerp` with the rounded decay (<= 3 ulp).
/// Cost, measured in the QEMU bench build (`cargo build --release -p sonolube-qemu --target
/// thumbv7em-none-eabihf --features bench`, then `SONOLUBE_ICOUNT_SHIFT=0 scripts/qemu-run`
/// on the ELF), Q2.30 travels below 2: 44 instructions per call with the bench harness that
/// subtracts its own loop (call and return included), 48 with the first harness (commit
/// e22f5ba: about 8 more of `black_box` traffic; 85 there before the table form of
/// `exp_neg`). A Q8.24 travel that also needs the reduction beyond 2 costs about 74 (90).
pub fn update<const F: u32>(
    f: Q2_30,
    forward: bool,
    kappa_travel: Q<F>,
) -> Result<Q2_30, ModelError> {
    let Ok((decay, shift)) = kappa_travel.exp_neg_parts() else {
        return Err(ModelError::OutOfDomain {
            input: "kappa |dx|",
            reason: "travel must be >= 0",
        });
    };
    const ONE: i32 = 1 << 30;
    let bits = f.to_bits();
    let s = if forward { ONE } else { -ONE };
    if !(-ONE..=ONE).contains(&bits) {
        // Beyond the Coulomb level: s + (f - s) e^-y with a 64-bit product (weight in [0, 1]:
        // the interpolation stays between s and f and cannot fail). The weight is `exp_neg`'s
        // rounded e^-y.
        let weight = Q2_30::from_bits((((decay >> (shift + 1)) + 1) >> 1) as i32);
        return Ok(Q2_30::from_bits(s).lerp(f, weight).unwrap_or(f));
    }
    // e^-y in Q.32 (below 2^32; shift = 0 for every y < 2, the Q2.30 case).
    let decay = decay >> shift;
    let signed = if forward { bits } else { -bits };
    let gap = (ONE as u32).wrapping_sub(signed as u32); // 1 - s f: [0, 2^31], exact
    // round(g e^-y) in Q.30 from the floor-valued decay: adding g/2 (half a unit of the decay)
    // centres its error, 2^31 rounds. <= 2^31 (2^32 - 1/2) + 2^31: no overflow.
    let bias = (1u64 << 31) + (gap >> 1) as u64;
    let relaxed = ((gap as u64 * decay as u64 + bias) >> 32) as u32; // <= gap
    let value = (ONE as u32).wrapping_sub(relaxed) as i32; // [-2^30, 2^30]
    Ok(Q2_30::from_bits(if forward { value } else { -value }))
}

/// Dahl scene constants (physics-notes §2 and §5).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DahlConstants {
    mu: Q8_24,
    /// k_t x_a,max / mu in newtons: kappa x_a = this * amplitude / W.
    stiffness_amplitude_per_load: Scaled,
    /// k_t / mu in N/m: kappa = this / W.
    stiffness_per_mu: Scaled,
    /// k_t / (mu omega) in N s/m: kappa |v| / omega = this * |v| / W.
    travel_rate_per_load: Scaled,
    /// Full-scale vibration velocity omega x_a,max in m/s.
    full_scale_velocity: Scaled,
    /// Full-scale displacement amplitude x_a,max in m.
    full_scale_amplitude: Scaled,
    law: RelaxLaw,
    points: u32,
}

impl DahlConstants {
    /// Constants from SI parameters (f64, scene load). Errors: `NonFinite`; `OutOfDomain` for
    /// mu outside (0, 128), k_t, f or x_a,max <= 0, alpha outside (0, 20], N odd or outside
    /// 4..=4096.
    pub fn new(params: &DahlParams) -> Result<Self, ModelError> {
        let mu_f64 = params.friction_coefficient;
        let mu = friction_coefficient_q("mu", mu_f64)?;
        if mu_f64 <= 0.0 {
            return Err(ModelError::OutOfDomain {
                input: "mu",
                reason: "must be > 0 (F_c = mu W)",
            });
        }
        let k_t = crate::model::scaled_from_f64(params.tangential_stiffness, "k_t")?.to_f64();
        let f = crate::model::scaled_from_f64(params.frequency_hz, "f")?.to_f64();
        let x_a = crate::model::scaled_from_f64(params.full_scale_amplitude_m, "x_a")?.to_f64();
        let points = params.quadrature_points;
        if !points.is_multiple_of(2) || !(4..=MAX_QUADRATURE_POINTS).contains(&points) {
            return Err(ModelError::OutOfDomain {
                input: "quadrature_points",
                reason: "must be even, 4..=4096",
            });
        }
        let omega = core::f64::consts::TAU * f;
        Ok(Self {
            mu,
            stiffness_amplitude_per_load: crate::model::scaled_from_f64(k_t * x_a / mu_f64, "k_t")?,
            stiffness_per_mu: crate::model::scaled_from_f64(k_t / mu_f64, "k_t")?,
            travel_rate_per_load: crate::model::scaled_from_f64(k_t / (mu_f64 * omega), "k_t")?,
            full_scale_velocity: crate::model::scaled_from_f64(omega * x_a, "x_a")?,
            full_scale_amplitude: crate::model::scaled_from_f64(x_a, "x_a")?,
            law: RelaxLaw::new(params.shape_exponent)?,
            points,
        })
    }

    /// Friction coefficient mu, Q8.24.
    pub fn friction_coefficient(&self) -> Q8_24 {
        self.mu
    }

    /// The relaxation law (alpha).
    pub fn law(&self) -> RelaxLaw {
        self.law
    }

    /// Quadrature nodes per period N.
    pub fn quadrature_points(&self) -> u32 {
        self.points
    }

    /// kappa = k_t / (mu W) in 1/m at the load `normal_force` (W in newtons, any format, > 0),
    /// for a time-stepping plant: per step, kappa |dx| = `wide::mul_q::<30, _>(kappa, dx)`
    /// (dx in metres in a fine format; saturated means the step relaxes f fully) feeds
    /// [`update`]. Error `OutOfDomain` for W <= 0. Cost: one reciprocal and one product.
    pub fn kappa<const FW: u32>(&self, normal_force: Q<FW>) -> Result<Scaled, ModelError> {
        let load = wide::from_q(normal_force).ok_or(ModelError::OutOfDomain {
            input: "W",
            reason: "must be > 0 (F_c = mu W)",
        })?;
        Ok(wide::mul(self.stiffness_per_mu, wide::recip(load)))
    }

    /// The drive at load `normal_force` (W in newtons, any format, > 0), sliding velocity `v`
    /// (m/s, any format, any sign) and `amplitude` (Q1.31 fraction of full scale, [0, 1)).
    /// Errors `OutOfDomain`: W <= 0, amplitude < 0, v = 0 without vibration. Cost: one
    /// reciprocal of W, one of v_a, and five products.
    pub fn drive<const FW: u32, const FV: u32>(
        &self,
        normal_force: Q<FW>,
        v: Q<FV>,
        amplitude: Q1_31,
    ) -> Result<DahlDrive, ModelError> {
        let inv_load = wide::recip(wide::from_q(normal_force).ok_or(ModelError::OutOfDomain {
            input: "W",
            reason: "must be > 0 (F_c = mu W)",
        })?);
        if amplitude.is_negative() {
            return Err(ModelError::OutOfDomain {
                input: "amplitude",
                reason: "must be >= 0",
            });
        }
        let scale = wide::from_q(amplitude);
        let v_a = scale.map(|a| wide::mul(a, self.full_scale_velocity));
        let velocity_ratio = velocity_ratio(v, v_a)?;
        let per_load = |c: Scaled| wide::mul(c, inv_load);
        Ok(DahlDrive {
            velocity_ratio,
            vibration_amplitude: scale.map(|a| wide::mul(a, self.full_scale_amplitude)),
            stiffness_amplitude: scale
                .map(|a| wide::mul(a, per_load(self.stiffness_amplitude_per_load))),
            travel_rate: wide::from_q(v.saturating_abs().value)
                .map(|speed| wide::mul(speed, per_load(self.travel_rate_per_load))),
        })
    }
}

/// The vibration drive in the dimensionless groups the Dahl model needs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DahlDrive {
    /// zeta = v / v_a.
    pub velocity_ratio: VelocityRatio,
    /// x_a in m (`None` without vibration).
    pub vibration_amplitude: Option<Scaled>,
    /// kappa x_a = k_t x_a / (mu W), dimensionless (`None` without vibration).
    pub stiffness_amplitude: Option<Scaled>,
    /// kappa |v| / omega = k_t |v| / (mu W omega): travel exponent per radian of drive phase
    /// from the sliding alone (`None` for v = 0).
    pub travel_rate: Option<Scaled>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fx::Q16_16;

    const ULP: f64 = 1.0 / (1u64 << 30) as f64;

    #[test]
    fn exact_update_matches_f64_and_stays_bounded() {
        let mut worst: f64 = 0.0;
        for i in 0..=2000 {
            let f = Q2_30::from_f64(-1.0 + i as f64 / 1000.0).unwrap();
            // Per-step travels below 2 in Q2.30 (both ends of a table step at 1/32), larger
            // ones in Q8.24 (the reduction by k ln2), each against its quantized value.
            for y in [
                0.0, 1e-6, 1e-3, 0.03125, 0.3, 0.69, 1.9, 2.0, 3.3, 7.1, 20.0, 127.0,
            ] {
                for forward in [true, false] {
                    let s = if forward { 1.0 } else { -1.0 };
                    let (got, y) = if y < 2.0 {
                        let yq = Q2_30::from_f64(y).unwrap();
                        (update(f, forward, yq), yq.to_f64())
                    } else {
                        let yq = Q8_24::from_f64(y).unwrap();
                        (update(f, forward, yq), yq.to_f64())
                    };
                    let got = got.unwrap();
                    let want = s + (f.to_f64() - s) * (-y).exp();
                    worst = worst.max((got.to_f64() - want).abs());
                    assert!(got.to_f64().abs() <= 1.0);
                }
            }
        }
        eprintln!("Dahl update: max error {} ulp", worst / ULP);
        assert!(worst <= 1.05 * ULP, "update error {worst:e}");
        assert_eq!(update(Q2_30::ZERO, true, Q8_24::MAX), Ok(Q2_30::ONE));
        // No travel leaves every state exactly where it is, either direction.
        for bits in (-(1i32 << 30)..=1 << 30)
            .step_by(65_537)
            .chain([-(1 << 30), 1 << 30])
        {
            let f = Q2_30::from_bits(bits);
            assert_eq!(update(f, true, Q2_30::ZERO), Ok(f));
            assert_eq!(update(f, false, Q16_16::ZERO), Ok(f));
        }
        // States beyond the Coulomb level (a seed 000 transient from a large delta0) relax
        // exactly, and the extremes of the format stay in range.
        for (f, forward) in [(1.7, true), (-1.9, true), (1.5, false), (-2.0, false)] {
            let q = Q2_30::from_f64(f).unwrap();
            let s = if forward { 1.0 } else { -1.0 };
            for y in [0.0, 0.01, 0.5, 1.9] {
                let yq = Q2_30::from_f64(y).unwrap();
                let got = update(q, forward, yq).unwrap();
                let want = s + (q.to_f64() - s) * (-yq.to_f64()).exp();
                // e^-y to 0.75 ulp, times |f - s| up to 3, plus the final rounding.
                let err = (got.to_f64() - want).abs();
                assert!(err <= 3.0 * ULP, "{f} {forward} {y}: {err:e}");
            }
        }
        assert!(update(Q2_30::MIN, true, Q2_30::ONE).is_ok());
        assert!(update(Q2_30::MAX, false, Q2_30::ONE).is_ok());
        assert!(update(Q2_30::ZERO, true, Q2_30::from_bits(-1)).is_err());
    }

    /// 1e4 exact updates at constant velocity (per-step change ~1e-3 to 1e-4, physics-notes
    /// §5) stay on the closed-form solution. Round-to-nearest leaves no drift; what remains is
    /// the error of the one decay factor e^-y (<= 0.75 ulp, the same at every step), a
    /// relative rate error of 0.75 ulp / y: it peaks at |f0 - s| e^-1 0.75 ulp / y (2.6e-6
    /// for y = 2e-4) and then dies out with f - s.
    #[test]
    fn ten_thousand_steps_do_not_drift() {
        for y in [2e-4, 1e-3] {
            let step = Q2_30::from_f64(y).unwrap(); // kappa |dx| per step
            let bound = 2.0 * (-1.0f64).exp() * 1.25 * ULP / step.to_f64();
            let mut f = Q2_30::from_f64(-1.0).unwrap();
            let mut worst: f64 = 0.0;
            for k in 1..=10_000 {
                f = update(f, true, step).unwrap();
                let want = 1.0 - 2.0 * (-step.to_f64() * k as f64).exp();
                worst = worst.max((f.to_f64() - want).abs());
            }
            assert!(worst <= bound, "y {y}: {worst:e} > {bound:e}");
        }
        // After 1e4 steps of 1e-3 (e^-10) the error has died out with f - s.
        let step = Q2_30::from_f64(1e-3).unwrap();
        let mut f = Q2_30::from_f64(-1.0).unwrap();
        for _ in 0..10_000 {
            f = update(f, true, step).unwrap();
        }
        let want = 1.0 - 2.0 * (-step.to_f64() * 1e4).exp();
        assert!((f.to_f64() - want).abs() <= 4.0 * ULP);
    }

    fn seed003(points: u32) -> DahlConstants {
        DahlConstants::new(&DahlParams {
            friction_coefficient: 0.2,
            tangential_stiffness: 5.6e4,
            frequency_hz: 40e3,
            full_scale_amplitude_m: 2.0 * 0.0683 / (core::f64::consts::TAU * 40e3),
            shape_exponent: 1.0,
            quadrature_points: points,
        })
        .unwrap()
    }

    #[test]
    fn drive_forms_the_dimensionless_groups() {
        let c = seed003(64);
        let half = Q1_31::from_f64(0.5).unwrap();
        let w = Q16_16::from_f64(0.54).unwrap();
        let d = c.drive(w, Q8_24::from_f64(0.038).unwrap(), half).unwrap();
        let x_a = 0.0683 / (core::f64::consts::TAU * 40e3);
        let kxa = 5.6e4 * x_a / (0.2 * w.to_f64());
        assert!((d.stiffness_amplitude.unwrap().to_f64() / kxa - 1.0).abs() < 1e-8);
        assert!((d.vibration_amplitude.unwrap().to_f64() / x_a - 1.0).abs() < 1e-8);
        let rate = kxa * Q8_24::from_f64(0.038).unwrap().to_f64() / 0.0683;
        assert!((d.travel_rate.unwrap().to_f64() / rate - 1.0).abs() < 1e-8);
        let kappa = c.kappa(w).unwrap().to_f64();
        assert!((kappa / (5.6e4 / (0.2 * w.to_f64())) - 1.0).abs() < 1e-8);
        assert!(c.kappa(Q16_16::ZERO).is_err());
        assert!(c.drive(Q16_16::ZERO, Q8_24::ONE, half).is_err());
        assert!(c.drive(w, Q8_24::ONE, Q1_31::from_bits(-1)).is_err());
        assert!(c.drive(w, Q8_24::ZERO, Q1_31::ZERO).is_err());
        let bad = |points, alpha, mu| {
            DahlConstants::new(&DahlParams {
                quadrature_points: points,
                shape_exponent: alpha,
                friction_coefficient: mu,
                ..DahlParams {
                    friction_coefficient: 0.2,
                    tangential_stiffness: 5.6e4,
                    frequency_hz: 40e3,
                    full_scale_amplitude_m: 1e-6,
                    shape_exponent: 1.0,
                    quadrature_points: 64,
                }
            })
            .is_err()
        };
        assert!(bad(63, 1.0, 0.2) && bad(2, 1.0, 0.2) && bad(8192, 1.0, 0.2));
        assert!(bad(64, 0.0, 0.2) && bad(64, 1.0, 0.0) && bad(64, 1.0, f64::INFINITY));
        assert!(!bad(64, 1.0, 0.2));
    }
}
