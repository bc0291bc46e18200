//! Horn kinematics (seed 000 eqs 16-17 and appendix A; seed 001 eqs 4-10) in fixed point.
//!
//! x is measured from the horn centre, the half-wavelength node (physics-notes §4):
//! u = A P_u(t) sin(pi x / L) along the sliding direction and v = B cos(2 pi f t) cos(pi x / L)
//! out of plane (v > 0 moves the surfaces apart). P_u(t) = cos(2 pi f t) (in phase with v,
//! eqs 16-17, default) or sin(2 pi f t) (quadrature: the elliptical locus seed 000 §3.1 and
//! seed 001 §2 describe). The Poisson amplitude is B = D A pi nu / (2 L) (eq A.9), or the
//! vibrometer value of Table 1.
//!
//! Hot path: amplitudes in um as Q8.24 ([0, 128) um, 6e-8 um resolution), the time phase and the
//! position as `u32` turn fractions (a phase accumulator wraps exactly like the angle), shape
//! factors from `fx::sin_cos` (error 1e-9).

use crate::fx::{Q1_31, Q2_30, Q8_24, Turns};

use super::ModelError;
use super::contact_constants::{finite, non_negative, poisson, positive};

/// Time dependence of the longitudinal projection u.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum UPhase {
    /// u in phase with v: cos(2 pi f t) (seed 000 eqs 16-17; default).
    #[default]
    InPhase,
    /// u in quadrature with v: sin(2 pi f t) (elliptical locus; variant).
    Quadrature,
}

/// Mode-shape factors sin(pi x / L) and cos(pi x / L) at one position on the horn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct HornShape {
    /// sin(pi x / L), Q1.31 in [-1, 1) (+1 comes out as `MAX`).
    pub sin_shape: Q1_31,
    /// cos(pi x / L), Q1.31 in [0, 1) for |x| <= L/2.
    pub cos_shape: Q1_31,
}

/// Displacements of the horn surface at one instant.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct HornDisplacement {
    /// Longitudinal (in-plane, along the sliding direction) u in um, Q8.24, |u| <= A.
    pub longitudinal_um: Q8_24,
    /// Vertical (out-of-plane, Poisson) v in um, Q8.24, |v| <= B; v > 0 opens the gap.
    pub vertical_um: Q8_24,
}

impl HornShape {
    /// Shape at `position_phase` = x / (2 L) turns (pi x / L = 2 pi phase; x in [-L/2, L/2]
    /// is the phase in [-1/4, 1/4] turn, wrapped). Cost: one `sin_cos`.
    pub fn from_phase(position_phase: Turns) -> Self {
        let (sin_shape, cos_shape) = position_phase.sin_cos();
        Self {
            sin_shape,
            cos_shape,
        }
    }

    /// Shape at position `x` (m) on a horn of length `length` (m) (scene set-up, f64). Errors:
    /// non-finite inputs, L <= 0, |x| > L/2. The position is rounded to 2L / 2^32 (59 pm for
    /// L = 0.127 m).
    pub fn new(position: f64, length: f64) -> Result<Self, ModelError> {
        let length = positive("L", length)?;
        let x = finite("x", position)?;
        if x.abs() > 0.5 * length {
            return Err(ModelError::OutOfDomain {
                input: "x",
                reason: "|x| must be <= L/2",
            });
        }
        // x / (2 L) in [-1/4, 1/4] turn, rounded to 2^-32 turn; a negative x is its wrap (the
        // two's-complement wrap of the rounded count: intended).
        let count = libm::round(x / (2.0 * length) * 4_294_967_296.0) as i64;
        Ok(Self::from_phase(Turns::from_bits(count as u32)))
    }

    /// u and v at the time phase `time_phase` (f t turns, 2 pi f t rad) for amplitudes
    /// A and B in um (Q8.24, any sign). Error <= 2 ulp of Q8.24 + 2e-9 relative. Cost: one
    /// `sin_cos` and four multiplications; never fails (|P_u S| < 1 cannot overflow).
    pub fn displacement(
        &self,
        longitudinal_amplitude_um: Q8_24,
        vertical_amplitude_um: Q8_24,
        time_phase: Turns,
        u_phase: UPhase,
    ) -> HornDisplacement {
        let (sin_t, cos_t) = time_phase.sin_cos();
        let u_time = match u_phase {
            UPhase::InPhase => cos_t,
            UPhase::Quadrature => sin_t,
        };
        // Q8.24 x Q1.31 -> Q8.24 with factors below 1 in magnitude: the clamp never engages.
        let scale = |amplitude: Q8_24, time: Q1_31, shape: Q1_31| {
            let in_time = amplitude.saturating_mul_to::<24, 31>(time).value;
            in_time.saturating_mul_to::<24, 31>(shape).value
        };
        HornDisplacement {
            longitudinal_um: scale(longitudinal_amplitude_um, u_time, self.sin_shape),
            vertical_um: scale(vertical_amplitude_um, cos_t, self.cos_shape),
        }
    }
}

/// Time phase f t turns (2 pi f t rad; tool level, f64): frac(f t), rounded to 2^-32 turn.
/// Errors: non-finite t, f <= 0. In firmware the phase comes from an accumulator instead.
pub fn time_phase(frequency: f64, time: f64) -> Result<Turns, ModelError> {
    let f = positive("f", frequency)?;
    let t = finite("t", time)?;
    // f t is finite here (both finite, f > 0 is checked; an overflow to infinity is refused).
    Turns::from_turns(f * t).ok_or(ModelError::OutOfDomain {
        input: "t",
        reason: "f t must be finite",
    })
}

/// An amplitude in m as um in Q8.24, for set-up and tools. Errors: non-finite, negative, or
/// >= 128 um.
pub fn amplitude_um(input: &'static str, amplitude: f64) -> Result<Q8_24, ModelError> {
    let a = non_negative(input, amplitude)?;
    Q8_24::from_f64(a * 1e6).map_err(|_| ModelError::OutOfDomain {
        input,
        reason: "amplitudes must be below 128 um",
    })
}

/// The Poisson-effect gain of seed 000 eq A.9: B = gain A with gain = D pi nu / (2 L).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PoissonGain {
    /// D pi nu / (2 L), Q2.30 in (-2, 2) (0.10 for the seed 000 aluminium horn).
    pub gain: Q2_30,
}

impl PoissonGain {
    /// From the horn thickness D (m, > 0), Poisson's ratio nu (in (-1, 0.5]) and length L
    /// (m, > 0). Error: `OutOfDomain` when |gain| >= 2 (D > 2.5 L).
    pub fn new(thickness: f64, poisson_ratio: f64, length: f64) -> Result<Self, ModelError> {
        let d = positive("D", thickness)?;
        let nu = poisson("nu", poisson_ratio)?;
        let l = positive("L", length)?;
        let gain = d * core::f64::consts::PI * nu / (2.0 * l);
        Q2_30::from_f64(gain)
            .map(|gain| Self { gain })
            .map_err(|_| ModelError::OutOfDomain {
                input: "D",
                reason: "D pi nu / (2 L) must be below 2 in magnitude",
            })
    }

    /// B in um (Q8.24) for A in um (Q8.24). Error: `Overflow` when |B| >= 128 um. Error
    /// 0.5 ulp. Cost: one multiplication.
    pub fn vertical_amplitude(&self, longitudinal_um: Q8_24) -> Result<Q8_24, ModelError> {
        longitudinal_um
            .checked_mul_to::<24, 30>(self.gain)
            .map_err(|_| ModelError::Overflow { quantity: "B" })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::f64::consts::PI;

    #[test]
    fn displacements_follow_eqs_16_17_with_x_from_the_node() {
        let length = 0.127;
        let (a, b) = (11.46, 1.1);
        let (aq, bq) = (Q8_24::from_f64(a).unwrap(), Q8_24::from_f64(b).unwrap());
        for &x in &[0.0, 0.01, -0.03, 0.0635, -0.0635] {
            let shape = HornShape::new(x, length).unwrap();
            for step in 0..64 {
                let t = step as f64 * 0.79e-6;
                let phase = time_phase(20e3, t).unwrap();
                let theta = 2.0 * PI * 20e3 * t;
                for (mode, time) in [
                    (UPhase::InPhase, theta.cos()),
                    (UPhase::Quadrature, theta.sin()),
                ] {
                    let out = shape.displacement(aq, bq, phase, mode);
                    let u = a * time * (PI * x / length).sin();
                    let v = b * theta.cos() * (PI * x / length).cos();
                    assert!(
                        (out.longitudinal_um.to_f64() - u).abs() < 2e-7,
                        "x {x} t {t}"
                    );
                    assert!((out.vertical_um.to_f64() - v).abs() < 2e-7, "x {x} t {t}");
                }
            }
        }
        // At the node there is no longitudinal motion at all.
        let node = HornShape::new(0.0, length).unwrap();
        assert_eq!(node.sin_shape, Q1_31::ZERO);
        assert!(HornShape::new(0.07, length).is_err());
        assert!(HornShape::new(0.0, -1.0).is_err());
        assert!(time_phase(0.0, 1.0).is_err() && time_phase(1.0, f64::INFINITY).is_err());
    }

    #[test]
    fn poisson_gain_gives_appendix_a9() {
        // Seed 000 test 1: D = 25.4 mm, nu = 0.33, L = 127 mm, A = 11.46 um -> B = 1.188 um.
        let gain = PoissonGain::new(25.4e-3, 0.33, 0.127).unwrap();
        let b = gain
            .vertical_amplitude(amplitude_um("A", 11.46e-6).unwrap())
            .unwrap();
        let want = 25.4e-3 * 11.46 * PI * 0.33 / (2.0 * 0.127);
        assert!((b.to_f64() - want).abs() < 1e-7);
        assert!(PoissonGain::new(1.0, 0.5, 0.1).is_err());
        assert!(amplitude_um("A", -1e-6).is_err() && amplitude_um("A", 2e-4).is_err());
        let big = PoissonGain::new(0.2, 0.5, 0.127).unwrap();
        assert!(
            big.vertical_amplitude(Q8_24::from_int(120).unwrap())
                .is_err()
        );
    }
}
