//! Periodic steady state of Dahl friction under v_s + v_a cos(2 pi f t) (physics-notes §2, the
//! default reading of seed 003's Dahl model), and [`DahlModel`], its [`FrictionModel`].
//!
//! The velocity reverses at cos theta = -zeta (|zeta| < 1). Between the turning points the
//! gap relaxes in closed form, so the state at the start of the forward stretch, f_b, is the
//! fixed point of a one-dimensional map (`dahl_cycle`). The period average is then
//! F_avg / (mu W) = mu_i(zeta) - (G_f - G_b) / (2 pi),
//! G the integrals of the gap over the two stretches (`dahl_quadrature`, N/2 nodes
//! each), mu_i the Littmann law: the Coulomb part is exact and only the gap is integrated.
//!
//! Limits, exactly: |zeta| >= 1 gives 1, zeta = 0 gives 0 (odd symmetry, returned as such),
//! kappa x_a -> infinity gives mu_i(zeta) (every gap integral -> 0), kappa x_a -> 0 gives
//! (D_f - D_b) / (D_f + D_b) (the gap is constant, the fixed point is that limit).

use crate::fx::{Q, Q1_31, Q2_30};

use super::dahl::{DahlConstants, DahlDrive, DahlParams};
use super::dahl_cycle::{
    Geometry, bisected_fixed_point, exponential_fixed_point, force_ratio, gap,
};
use super::dahl_quadrature::{Exponent, Grid, integrate_stretch};
use super::dahl_relax::RelaxLaw;
use super::fx_error;
use super::{FrictionModel, ModelError, OperatingPoint};

/// 1 / (2 pi) in Q.31.
const INV_TAU_Q31: i64 = 341_782_638;

/// The Dahl model in its periodic steady state, with N nodes per period.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DahlModel {
    constants: DahlConstants,
    grid: Grid,
}

impl DahlModel {
    /// The model for a scene (f64, scene load; errors as [`DahlConstants::new`]).
    pub fn new(params: &DahlParams) -> Result<Self, ModelError> {
        let constants = DahlConstants::new(params)?;
        Ok(Self {
            constants,
            grid: Grid::new(constants.quadrature_points() / 2),
        })
    }

    /// The scene's constants.
    pub fn constants(&self) -> &DahlConstants {
        &self.constants
    }

    /// Steady-state ratio F_avg / (mu W sgn v) (sgn taken as +1 at v = 0), Q2.30 in [0, 1],
    /// for a drive from [`DahlConstants::drive`]. Cost, measured on the Cortex-M4 (seed 003
    /// parameters, drive included): alpha = 1, 49k instructions for N = 64 (about 750 per node),
    /// 26k for N = 32, 20k for a stiff contact (k_t = 1e9 N/m: g vanishes early in each
    /// stretch), 7k for k_t = 1e12 N/m; alpha = 2, 137k (bisected fixed point, `ln`/`exp` per
    /// node). Too slow for every step of a 10 kHz loop at N = 64: evaluate it at the envelope
    /// rate or tabulate it per scene.
    pub fn steady_ratio(&self, drive: &DahlDrive) -> Result<Q2_30, ModelError> {
        let (Some(zeta), Some(kxa)) = (
            drive.velocity_ratio.reversing_magnitude(),
            drive.stiffness_amplitude,
        ) else {
            return Ok(Q2_30::ONE); // no reversal: f relaxes to sgn v
        };
        if zeta >= Q2_30::ONE {
            return Ok(Q2_30::ONE);
        }
        if zeta == Q2_30::ZERO {
            return Ok(Q2_30::ZERO); // odd symmetry
        }
        let geometry = Geometry::new(zeta)?;
        let law = self.constants.law();
        let f_b = match law {
            RelaxLaw::Exponential => exponential_fixed_point(kxa, &geometry),
            RelaxLaw::Power { .. } => bisected_fixed_point(&law, kxa, &geometry),
        };
        let stretch = |travel, length, g0| {
            let exponent = Exponent::Travel {
                travel,
                stiffness_amplitude: kxa,
            };
            integrate_stretch(&exponent, length, g0, &law, &self.grid)
        };
        let forward = stretch(geometry.forward, geometry.forward_length, gap(f_b, true));
        let f_a = force_ratio(forward.end_gap, true);
        let backward = stretch(geometry.backward, geometry.backward_length, gap(f_a, false));
        // (G_f - G_b) / (2 pi): Q.57 -> Q.28 (|.| < 2^33) times 1/(2 pi) in Q.31 -> Q.30.
        let difference = (forward.gap_integral - backward.gap_integral + (1 << 28)) >> 29;
        let correction = (difference * INV_TAU_Q31 + (1 << 28)) >> 29;
        let average = (geometry.mu_i.to_bits() as i64 - correction).clamp(0, 1 << 30);
        Ok(Q2_30::from_bits(average as i32))
    }

    /// Steady state at the load `normal_force` (W in newtons, any format, > 0), sliding
    /// velocity `v` (m/s, any format) and `amplitude` (Q1.31 fraction of full scale).
    /// Errors as [`DahlConstants::drive`]; `Overflow` when mu W does not fit `Q<FW>`.
    pub fn steady<const FW: u32, const FV: u32>(
        &self,
        normal_force: Q<FW>,
        v: Q<FV>,
        amplitude: Q1_31,
    ) -> Result<DahlSteadyState<FW>, ModelError> {
        let drive = self.constants.drive(normal_force, v, amplitude)?;
        let ratio = self.steady_ratio(&drive)?;
        let level: Q<FW> = normal_force
            .checked_mul_to(self.constants.friction_coefficient())
            .map_err(fx_error("mu W"))?;
        let directed = if v.is_negative() {
            level.checked_neg().map_err(fx_error("mu W"))?
        } else {
            level
        };
        Ok(DahlSteadyState {
            drive,
            ratio,
            friction_without_vibration: if v == Q::<FV>::ZERO {
                Q::<FW>::ZERO
            } else {
                directed
            },
            average_friction: directed.checked_mul_to(ratio).map_err(fx_error("F_avg"))?,
        })
    }
}

/// Result of [`DahlModel::steady`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DahlSteadyState<const FW: u32> {
    /// The drive's dimensionless groups (zeta, x_a, kappa x_a).
    pub drive: DahlDrive,
    /// F_avg / (mu W sgn v), Q2.30 in [0, 1].
    pub ratio: Q2_30,
    /// mu W sgn(v) in newtons, in the load's format (0 at v = 0).
    pub friction_without_vibration: Q<FW>,
    /// Period-averaged friction in newtons, in the load's format.
    pub average_friction: Q<FW>,
}

impl FrictionModel for DahlModel {
    /// `kappa x_a = k_t x_a / (mu W)`: the load enters only through `mu W`.
    fn load_enters_as_coulomb_force(&self) -> bool {
        true
    }

    /// Steady-state ratio at the operating point (W Q16.16, v Q8.24). Errors as
    /// [`DahlConstants::drive`]. Cost: see [`DahlModel::steady_ratio`]; the default bisection
    /// inverse calls it 18 times.
    fn ratio(&self, point: &OperatingPoint, amplitude: Q1_31) -> Result<Q2_30, ModelError> {
        let drive = self
            .constants
            .drive(point.normal_force, point.sliding_velocity, amplitude)?;
        self.steady_ratio(&drive)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fx::{Q8_24, Q16_16};
    use core::f64::consts::{FRAC_2_PI, PI};

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

    /// An independent f64 steady state: the fixed point by 200 bisection steps of the exact
    /// period map, then a dense uniform trapezoid (4e5 points per stretch) of the exact gap.
    fn brute_force(zeta: f64, kxa: f64, alpha: f64) -> f64 {
        let sigma = (1.0 - zeta * zeta).sqrt();
        let theta = PI / 2.0 + zeta.asin();
        let phi = PI - theta;
        let travel = |h: f64, s: f64| sigma * (1.0 - h.cos()) + s * zeta * (h - h.sin());
        let (d_f, d_b) = (travel(2.0 * theta, 1.0), travel(2.0 * phi, -1.0));
        let map = |f: f64| {
            let f_a = 1.0 - relax_f64(1.0 - f, kxa * d_f, alpha);
            relax_f64(1.0 + f_a, kxa * d_b, alpha) - 1.0
        };
        let (mut lo, mut hi) = (-1.0f64, 1.0f64);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if map(mid) > mid { lo = mid } else { hi = mid }
        }
        let f_b = 0.5 * (lo + hi);
        let f_a = 1.0 - relax_f64(1.0 - f_b, kxa * d_f, alpha);
        let integral = |g0: f64, length: f64, s: f64| {
            let m = 400_000;
            let dh = length / m as f64;
            let mut sum = 0.0;
            for i in 0..=m {
                let w = if i == 0 || i == m { 0.5 } else { 1.0 };
                sum += w * relax_f64(g0, kxa * travel(i as f64 * dh, s), alpha);
            }
            sum * dh
        };
        let g_f = integral(1.0 - f_b, 2.0 * theta, 1.0);
        let g_b = integral(1.0 + f_a, 2.0 * phi, -1.0);
        FRAC_2_PI * zeta.asin() - (g_f - g_b) / (2.0 * PI)
    }

    /// A scene with x_a,max = 1 m, f = 1/(2 pi) Hz (omega = 1), mu = 1: at W = 1 N and
    /// amplitude 1/2, v_a = 1/2 m/s and kappa x_a = k_t / 2.
    fn model(alpha: f64, points: u32) -> DahlModel {
        DahlModel::new(&DahlParams {
            friction_coefficient: 1.0,
            tangential_stiffness: 1.0,
            frequency_hz: 1.0 / (2.0 * PI),
            full_scale_amplitude_m: 1.0,
            shape_exponent: alpha,
            quadrature_points: points,
        })
        .unwrap()
    }

    /// ratio at zeta and kappa x_a (built directly: the drive's arithmetic is tested in dahl).
    fn ratio(m: &DahlModel, zeta: f64, kxa: f64) -> f64 {
        let drive = DahlDrive {
            velocity_ratio: crate::model::littmann::VelocityRatio::Finite {
                negative: false,
                magnitude: crate::model::scaled_from_f64(zeta, "zeta").unwrap(),
            },
            vibration_amplitude: None,
            stiffness_amplitude: crate::model::scaled_from_f64(kxa, "kxa").ok(),
            travel_rate: None,
        };
        m.steady_ratio(&drive).unwrap().to_f64()
    }

    #[test]
    fn matches_an_independent_dense_integration() {
        let mut worst: f64 = 0.0;
        for alpha in [1.0, 0.5, 2.0] {
            let m = model(alpha, 64);
            for zeta in [0.2, 0.556_368_960_468_521, 0.9] {
                for kxa in [0.01, 0.141, 1.0, 10.0, 100.0, 1e4] {
                    let want = brute_force(zeta, kxa, alpha);
                    let got = ratio(&m, zeta, kxa);
                    worst = worst.max((got - want).abs());
                    assert!(
                        (got - want).abs() < 1e-3,
                        "alpha {alpha} zeta {zeta} kxa {kxa}: {got} vs {want}"
                    );
                }
            }
        }
        eprintln!("steady state vs dense f64: max error {worst:e} (N = 64)");
    }

    #[test]
    fn limits_hold() {
        let m = model(1.0, 64);
        for zeta in [0.1, 0.5, 0.9, 0.999] {
            let coulomb = FRAC_2_PI * f64::asin(zeta);
            assert!(
                (ratio(&m, zeta, 1e13) - coulomb).abs() < 1e-6,
                "stiff, zeta {zeta}"
            );
            let sigma = (1.0 - zeta * zeta).sqrt();
            let (theta, phi) = (PI / 2.0 + zeta.asin(), PI / 2.0 - zeta.asin());
            let (d_f, d_b) = (sigma + zeta * theta, sigma - zeta * phi);
            let soft = (d_f - d_b) / (d_f + d_b);
            assert!(
                (ratio(&m, zeta, 1e-9) - soft).abs() < 1e-6,
                "soft, zeta {zeta}"
            );
        }
        assert_eq!(ratio(&m, 1.0, 5.0), 1.0);
        assert_eq!(ratio(&m, 3.0, 5.0), 1.0);
        let stopped = m
            .constants()
            .drive(Q16_16::ONE, Q8_24::ZERO, Q1_31::MAX)
            .unwrap();
        assert_eq!(m.steady_ratio(&stopped), Ok(Q2_30::ZERO));
        let still = m
            .constants()
            .drive(Q16_16::ONE, Q8_24::ONE, Q1_31::ZERO)
            .unwrap();
        assert_eq!(m.steady_ratio(&still), Ok(Q2_30::ONE));
    }

    #[test]
    fn seed_003_steady_state_and_forces() {
        // Seed 003: mu 0.2, k_t 5.6e4 N/m, v_a 0.0683 m/s at 40 kHz (amplitude 1/2 of twice
        // that), v = 0.038 m/s; physics-notes §2: 24.87 % at 0.540 N, 24.61 % at 7.905 N.
        let m = DahlModel::new(&DahlParams {
            friction_coefficient: 0.2,
            tangential_stiffness: 5.6e4,
            frequency_hz: 40e3,
            full_scale_amplitude_m: 2.0 * 0.0683 / (2.0 * PI * 40e3),
            shape_exponent: 1.0,
            quadrature_points: 64,
        })
        .unwrap();
        let half = Q1_31::from_f64(0.5).unwrap();
        let v = Q8_24::from_f64(-0.038).unwrap();
        for (w, pct) in [(0.540, 24.871_124_359), (7.905, 24.609_283_537)] {
            let w = Q16_16::from_f64(w).unwrap();
            let s = m.steady(w, v, half).unwrap();
            let got = 100.0 * (1.0 - s.ratio.to_f64());
            assert!((got - pct).abs() < 0.05, "{got} vs {pct}");
            let level = 0.2 * w.to_f64();
            assert!((s.friction_without_vibration.to_f64() + level).abs() < 3e-5);
            assert!((s.average_friction.to_f64() + level * s.ratio.to_f64()).abs() < 3e-5);
        }
    }

    #[test]
    fn ratio_is_monotone_in_amplitude() {
        let m = model(1.0, 64);
        let point = OperatingPoint {
            normal_force: Q16_16::from_f64(0.5).unwrap(),
            sliding_velocity: Q8_24::from_f64(0.1).unwrap(),
        };
        let mut last = Q2_30::ONE;
        for k in 0..=400 {
            let a = Q1_31::from_bits((k as i64 * i32::MAX as i64 / 400) as i32);
            let r = m.ratio(&point, a).unwrap();
            assert!(r <= last, "amplitude step {k}: {r:?} after {last:?}");
            last = r;
        }
        let target = Q2_30::from_f64(0.4).unwrap();
        let inv = m.invert(&point, target).unwrap();
        assert_eq!(inv.reach, crate::model::Reach::Reached);
        assert!((inv.ratio.to_f64() - 0.4).abs() < 1e-3);
    }
}
