//! Seed 003's windowed Dahl protocol (physics-notes §2): the vibration is switched on at t = 0
//! from F = f0 mu W (f0 = 1: steady sliding) and F is averaged over a window Tw. This start-up
//! transient is what reproduces seed 003's printed Dahl columns (23.92, 21.15, 17.57, 13.11 %
//! with Tw = 1 ms); it is a variant, not the steady state ([`super::dahl_steady`], the
//! default), and the two must not be confused.
//!
//! alpha = 1 only (as seed 003 and the reference). The window is cut at the turning points
//! into stretches, each integrated exactly like the steady state's (`dahl_quadrature`,
//! N/2 nodes per stretch): from the crest theta = 0 to the first turning point, then whole
//! backward and forward stretches, the last one cut at the window's end. Without velocity
//! reversal (|v| >= v_a) the window is cut into whole periods of N nodes. A stretch that starts
//! from the same state as the previous one in its direction is not recomputed (its result is
//! the same to the bit): once the state has settled, each period costs nothing. Not a control-
//! loop function: up to 1e5 periods.

use crate::fx::{Q, Q1_31, Q2_30, Q3_29};

use super::ModelError;
use super::dahl::{DahlConstants, DahlParams};
use super::dahl_cycle::{Geometry, force_ratio, gap};
use super::dahl_quadrature::{Exponent, Grid, StretchOutcome, integrate_stretch};
use super::dahl_relax::RelaxLaw;
use super::dahl_travel::{PI_Q28, Travel};
use super::fx_error;
use crate::fx::Scaled;
use crate::fx::wide;

/// Largest number of drive periods a window may span (as the reference).
pub const MAX_WINDOW_PERIODS: f64 = 1e5;

/// The windowed protocol of one scene.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DahlWindow {
    constants: DahlConstants,
    stretch_grid: Grid,
    period_grid: Grid,
    /// Window length 2 pi f Tw in Q4.28 radians, as an i64.
    window_angle: i64,
    /// 1 / (2 pi f Tw).
    inv_window_angle: Scaled,
}

impl DahlWindow {
    /// The protocol for a scene (`params.shape_exponent` must be 1) and a window `window_s`
    /// in seconds (> 0, at most 1e5 periods). f64, scene load. Errors as
    /// [`DahlConstants::new`], and `OutOfDomain` for alpha != 1 or a bad window.
    pub fn new(params: &DahlParams, window_s: f64) -> Result<Self, ModelError> {
        let constants = DahlConstants::new(params)?;
        if constants.law() != RelaxLaw::Exponential {
            return Err(ModelError::OutOfDomain {
                input: "alpha",
                reason: "the switch-on window is implemented for alpha = 1 (seed 003)",
            });
        }
        let window = crate::model::scaled_from_f64(window_s, "Tw")?.to_f64();
        let periods = params.frequency_hz * window;
        if periods.is_nan() || periods > MAX_WINDOW_PERIODS {
            return Err(ModelError::OutOfDomain {
                input: "Tw",
                reason: "window must span at most 1e5 drive periods",
            });
        }
        let whole = libm::floor(periods);
        let rest = libm::round((periods - whole) * 2.0 * PI_Q28 as f64) as i64;
        let window_angle = whole as i64 * 2 * PI_Q28 as i64 + rest;
        if window_angle <= 0 {
            return Err(ModelError::OutOfDomain {
                input: "Tw",
                reason: "window shorter than the phase resolution",
            });
        }
        let points = constants.quadrature_points();
        Ok(Self {
            constants,
            stretch_grid: Grid::new(points / 2),
            period_grid: Grid::new(points),
            window_angle,
            inv_window_angle: crate::model::scaled_from_f64(
                1.0 / (core::f64::consts::TAU * periods),
                "Tw",
            )?,
        })
    }

    /// The scene's constants.
    pub fn constants(&self) -> &DahlConstants {
        &self.constants
    }

    /// Time average of F over the window, started from F = `initial_force_ratio` mu W
    /// (Q2.30 in [-1, 1]), at load `normal_force` (W in newtons, any format, > 0), sliding
    /// velocity `v` (m/s, any format) and `amplitude` (Q1.31 fraction of full scale).
    ///
    /// Errors: as [`DahlConstants::drive`]; `OutOfDomain` for |f0| > 1; `Overflow` when mu W
    /// does not fit `Q<FW>`.
    pub fn average<const FW: u32, const FV: u32>(
        &self,
        normal_force: Q<FW>,
        v: Q<FV>,
        amplitude: Q1_31,
        initial_force_ratio: Q2_30,
    ) -> Result<DahlWindowAverage<FW>, ModelError> {
        if initial_force_ratio.saturating_abs().value > Q2_30::ONE {
            return Err(ModelError::OutOfDomain {
                input: "f0",
                reason: "must be in [-1, 1]",
            });
        }
        let drive = self.constants.drive(normal_force, v, amplitude)?;
        // The model is odd in (v, f): work with v >= 0 and mirror back.
        let negative = drive.velocity_ratio.is_negative();
        let f0 = if negative {
            Q2_30::from_bits(-initial_force_ratio.to_bits())
        } else {
            initial_force_ratio
        };
        let reversing = drive.velocity_ratio.reversing_magnitude();
        // Mirroring v also moves the phase by pi: v_s + v_a cos(theta) = -(|v_s| + v_a
        // cos(theta + pi)), so the mirrored window starts at the trough.
        let total = match (reversing, drive.stiffness_amplitude) {
            (Some(zeta), Some(kxa)) if zeta < Q2_30::ONE => {
                self.reversing(zeta, kxa, f0, negative)?
            }
            _ => self.sliding(drive.travel_rate, drive.stiffness_amplitude, f0, negative)?,
        };
        let magnitude = wide::from_q24(total.unsigned_abs() as i64 >> 8).map_or(0, |t| {
            wide::to_q::<30>(wide::mul(t, self.inv_window_angle))
                .value
                .to_bits()
                .min(1 << 30)
        });
        let mirrored = (total < 0) != negative;
        let average = Q2_30::from_bits(if mirrored { -magnitude } else { magnitude });
        let level: Q<FW> = normal_force
            .checked_mul_to(self.constants.friction_coefficient())
            .map_err(fx_error("mu W"))?;
        Ok(DahlWindowAverage {
            average,
            average_friction: level.checked_mul_to(average).map_err(fx_error("F_avg"))?,
            direction_negative: negative,
        })
    }

    /// Integral of f over the window (Q.32 radians) for a reversing drive, v >= 0, starting at
    /// the crest (forward) or at the trough (backward).
    fn reversing(
        &self,
        zeta: Q2_30,
        kxa: Scaled,
        f0: Q2_30,
        from_trough: bool,
    ) -> Result<i64, ModelError> {
        let geometry = Geometry::new(zeta)?;
        let law = RelaxLaw::Exponential;
        let exponent = |travel| Exponent::Travel {
            travel,
            stiffness_amplitude: kxa,
        };
        let backward = (exponent(geometry.backward), geometry.backward_length, false);
        let forward = (exponent(geometry.forward), geometry.forward_length, true);
        let one_minus_zeta = wide::from_q(Q2_30::ONE.saturating_sub(zeta).value);
        let zeta = wide::from_q(zeta);
        // From the crest to the first turning point forward, or from the trough backward.
        let (start, first, first_forward, stretches) = if from_trough {
            let trough = match one_minus_zeta {
                Some(one_minus_zeta) => exponent(Travel::Trough { one_minus_zeta }),
                None => {
                    return Err(ModelError::OutOfDomain {
                        input: "v",
                        reason: "a reversing drive needs |v| < v_a",
                    });
                }
            };
            (
                trough,
                geometry.backward_length / 2,
                false,
                [forward, backward],
            )
        } else {
            let crest = exponent(Travel::Crest { zeta });
            (
                crest,
                geometry.forward_length / 2,
                true,
                [backward, forward],
            )
        };
        let first = first.min(self.remaining(0));
        let g0 = gap(f0, first_forward);
        let piece = integrate_stretch(&start, first, g0, &law, &self.stretch_grid);
        let mut total = contribution(first, &piece, first_forward);
        let mut f = force_ratio(piece.end_gap, first_forward);
        let mut position = first as i64;
        let mut memo: [Option<(Q3_29, StretchOutcome)>; 2] = [None, None];
        let mut k = 0;
        while position < self.window_angle {
            let (exponent, full, forward) = &stretches[k % 2];
            let length = (*full).min(self.remaining(position));
            let g0 = gap(f, *forward);
            let piece = match memo[k % 2] {
                Some((seen, outcome)) if seen == g0 && length == *full => outcome,
                _ => {
                    let outcome = integrate_stretch(exponent, length, g0, &law, &self.stretch_grid);
                    if length == *full {
                        memo[k % 2] = Some((g0, outcome));
                    }
                    outcome
                }
            };
            total += contribution(length, &piece, *forward);
            f = force_ratio(piece.end_gap, *forward);
            position += length as i64;
            k += 1;
        }
        Ok(total)
    }

    /// Integral of f over the window (Q.32 radians) without velocity reversal, v > 0: whole
    /// periods from the crest, lambda = R h + kappa x_a sin h (from the trough: - sin h).
    fn sliding(
        &self,
        rate: Option<Scaled>,
        stiffness_amplitude: Option<Scaled>,
        f0: Q2_30,
        trough: bool,
    ) -> Result<i64, ModelError> {
        let Some(rate) = rate else {
            return Err(ModelError::OutOfDomain {
                input: "v",
                reason: "no relative motion (v = 0 and no vibration): static friction",
            });
        };
        let exponent = Exponent::Sliding {
            rate,
            stiffness_amplitude,
            trough,
        };
        let law = RelaxLaw::Exponential;
        let period = 2 * PI_Q28;
        let mut total = 0i64;
        let mut position = 0i64;
        let mut f = f0;
        let mut memo: Option<(Q3_29, StretchOutcome)> = None;
        while position < self.window_angle {
            let length = period.min(self.remaining(position));
            let g0 = gap(f, true);
            let piece = match memo {
                Some((seen, outcome)) if seen == g0 && length == period => outcome,
                _ => {
                    let outcome = integrate_stretch(&exponent, length, g0, &law, &self.period_grid);
                    if length == period {
                        memo = Some((g0, outcome));
                    }
                    outcome
                }
            };
            total += contribution(length, &piece, true);
            f = force_ratio(piece.end_gap, true);
            position += length as i64;
        }
        Ok(total)
    }

    /// Angle left in the window after `position` (Q4.28), capped at i32::MAX.
    fn remaining(&self, position: i64) -> i32 {
        (self.window_angle - position).clamp(0, i32::MAX as i64) as i32
    }
}

/// The integral of f = s (1 - g) over a stretch of `length` (Q4.28), in Q.32.
fn contribution(length: i32, piece: &StretchOutcome, forward: bool) -> i64 {
    let value = ((length as i64) << 4) - ((piece.gap_integral + (1 << 24)) >> 25);
    if forward { value } else { -value }
}

/// Result of [`DahlWindow::average`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DahlWindowAverage<const FW: u32> {
    /// Time average of F / (mu W) over the window, Q2.30 in [-1, 1] (signed).
    pub average: Q2_30,
    /// Time-averaged friction in newtons, in the load's format (signed).
    pub average_friction: Q<FW>,
    /// True when v < 0.
    direction_negative: bool,
}

impl<const FW: u32> DahlWindowAverage<FW> {
    /// Relative reduction 1 - average sgn(v) (sgn taken as +1 at v = 0), Q3.29 in [0, 2]
    /// (times 100: seed 003's "%Reduction (Dahl)").
    pub fn reduction(&self) -> Q3_29 {
        let directed = if self.direction_negative {
            -(self.average.to_bits() as i64)
        } else {
            self.average.to_bits() as i64
        };
        Q3_29::from_bits((((1i64 << 30) - directed + 1) >> 1) as i32)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fx::{Q8_24, Q16_16};
    use core::f64::consts::TAU;

    fn seed003(points: u32) -> DahlWindow {
        DahlWindow::new(
            &DahlParams {
                friction_coefficient: 0.2,
                tangential_stiffness: 5.6e4,
                frequency_hz: 40e3,
                full_scale_amplitude_m: 2.0 * 0.0683 / (TAU * 40e3),
                shape_exponent: 1.0,
                quadrature_points: points,
            },
            1e-3,
        )
        .unwrap()
    }

    /// The reduction 1 - average sgn(v) is the exact half-ulp rounding of its Q2.30 input into
    /// Q3.29: no friction left is 1 exactly, full friction 0 exactly, reversed full friction 2,
    /// and an odd difference rounds half up.
    #[test]
    fn reduction_is_one_minus_the_directed_average_rounded() {
        let window = |average: f64, negative: bool| DahlWindowAverage::<16> {
            average: Q2_30::from_f64(average).unwrap(),
            average_friction: Q16_16::ZERO,
            direction_negative: negative,
        };
        for (average, negative, want) in [
            (0.0, false, 1.0),
            (1.0 - 2f64.powi(-30), false, 2f64.powi(-30)),
            (0.25, false, 0.75),
            (0.25, true, 1.25),
            (-1.0, false, 2.0),
            (-1.0, true, 0.0),
        ] {
            let got = window(average, negative).reduction();
            // want is a multiple of 2^-30: the Q3.29 value is want rounded, ties up.
            let bits = libm::floor(want * 2f64.powi(29) + 0.5) as i32;
            assert_eq!(got.to_bits(), bits, "{average} {negative}");
        }
    }

    fn reduction_pct(w: &DahlWindow, load: f64, v: f64, f0: f64) -> f64 {
        let out = w
            .average(
                Q16_16::from_f64(load).unwrap(),
                Q8_24::from_f64(v).unwrap(),
                Q1_31::from_f64(0.5).unwrap(),
                Q2_30::from_f64(f0).unwrap(),
            )
            .unwrap();
        100.0 * out.reduction().to_f64()
    }

    /// Seed 003 Tables 2-3, "Dahl" columns, 1 ms from F = mu W (reference values of the
    /// project's paper table; printed 23.92, 21.15, 17.57, 13.11 and 0.01, -0.15, 0.00, 0.00).
    #[test]
    fn reproduces_seed_003_dahl_columns() {
        let w = seed003(64);
        let cases = [
            (0.540, 0.038, 23.953_354_791),
            (1.902, 0.038, 21.321_857_036),
            (4.155, 0.038, 17.613_293_671),
            (7.905, 0.038, 13.139_189_212),
            (0.540, 0.068, 0.017_503_027),
            (7.905, 0.068, 0.010_923_547),
        ];
        for (load, v, want) in cases {
            let got = reduction_pct(&w, load, v, 1.0);
            assert!((got - want).abs() < 0.02, "W {load} v {v}: {got} vs {want}");
            // Sliding the other way from F = -mu W is the mirror image shifted by half a
            // period (the drive starts at its trough): close after 40 periods, not equal.
            let mirrored = reduction_pct(&w, load, -v, -1.0);
            assert!((mirrored - got).abs() < 0.5, "mirror: {mirrored} vs {got}");
        }
    }

    /// Without vibration f relaxes exponentially in the travel kappa v t: the window average
    /// is 1 - (1 - f0)(1 - e^-Y)/Y, Y = kappa v Tw.
    #[test]
    fn no_vibration_matches_the_closed_form() {
        let w = seed003(64);
        for (load, f0) in [(0.54, -1.0), (7.9, 0.0), (100.0, 0.5)] {
            let load_q = Q16_16::from_f64(load).unwrap();
            let v = Q8_24::from_f64(0.001).unwrap();
            let f0q = Q2_30::from_f64(f0).unwrap();
            let out = w.average(load_q, v, Q1_31::ZERO, f0q).unwrap();
            let y = 5.6e4 / (0.2 * load_q.to_f64()) * v.to_f64() * 1e-3;
            let want = 1.0 - (1.0 - f0) * (1.0 - (-y).exp()) / y;
            assert!(
                (out.average.to_f64() - want).abs() < 1e-4,
                "{load}: {:?} vs {want}",
                out.average
            );
        }
    }

    #[test]
    fn errors() {
        let w = seed003(64);
        let one = Q16_16::ONE;
        let v = Q8_24::from_f64(0.01).unwrap();
        let half = Q1_31::from_f64(0.5).unwrap();
        assert!(
            w.average(one, v, half, Q2_30::from_f64(1.5).unwrap())
                .is_err()
        );
        assert!(
            w.average(one, Q8_24::ZERO, Q1_31::ZERO, Q2_30::ONE)
                .is_err()
        );
        let params = DahlParams {
            friction_coefficient: 0.2,
            tangential_stiffness: 5.6e4,
            frequency_hz: 40e3,
            full_scale_amplitude_m: 1e-6,
            shape_exponent: 1.0,
            quadrature_points: 64,
        };
        assert!(DahlWindow::new(&params, 3.0).is_err()); // 1.2e5 periods
        assert!(DahlWindow::new(&params, 0.0).is_err());
        let soft = DahlParams {
            shape_exponent: 0.5,
            ..params
        };
        assert!(DahlWindow::new(&soft, 1e-3).is_err());
    }
}
