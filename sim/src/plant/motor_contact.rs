//! The block on the horn's bottom face (seed 001 §3.1, Figs 3-4): where it is along the horn,
//! and the net tangential force the vibrating horn exerts on it there.
//!
//! Seed 001 slides a block under the horn at 5 mm/s within +-1 in of the centreline; which
//! physics acts depends on where it is (Table 1): friction reduction in the transition region
//! around the node, a net drive towards the centreline in the motor regions. The plant tracks
//! the position by integrating the scene's sliding velocity, and evaluates, in the motor
//! regions, the motor model (`sonolube::model::motor`) at the plant's own parameters. In the
//! transition region the plant's friction contact (`super::contact`) applies instead: this
//! type says which ([`BlockOnHorn::region`]) and gives the motor force; the friction contact is
//! untouched.
//!
//! The position is an `f64` accumulator: 5 mm/s steps of 0.5 um (at 10 kHz) added to
//! centimetres in `f32` would drift by about 1 nm a step, and `f64` additions are IEEE, the same
//! bits on the host and on the Cortex-M4 (soft-float), like the rest of the plant's physics.

use sonolube::fx::{Q1_31, Q8_24, Q16_16};
use sonolube::model::ModelError;
use sonolube::model::horn::HornShape;
use sonolube::model::motor::{HornRegion, MeasuredRegions, MotorPoint, MotorScene};

/// The block's position along the horn and the horn's motor model.
#[derive(Debug, Clone, PartialEq)]
pub struct BlockOnHorn {
    motor: MotorScene,
    regions: MeasuredRegions,
    /// x from the horn centre, m, |x| <= L/2.
    position_m: f64,
}

/// The motor force at one instant (ground truth).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct MotorTruth {
    /// x from the horn centre, m.
    pub position_m: f32,
    /// Seed 001 Table 1's region at that position.
    pub region: HornRegion,
    /// Net tangential force of the horn on the block along +x, N (towards the centreline in
    /// the motor regions).
    pub force_n: f32,
}

impl BlockOnHorn {
    /// The block at `start_m` (m from the centre) on the horn of `motor`, with the measured
    /// regions `regions`. Error: `OutOfDomain` unless |start| <= L/2.
    pub fn new(
        motor: MotorScene,
        regions: MeasuredRegions,
        start_m: f64,
    ) -> Result<Self, ModelError> {
        HornShape::new(start_m, motor.horn_length())?;
        Ok(Self {
            motor,
            regions,
            position_m: start_m,
        })
    }

    /// Position now, m from the centre.
    pub fn position_m(&self) -> f64 {
        self.position_m
    }

    /// Table 1's region at the present position.
    pub fn region(&self) -> HornRegion {
        // The position is finite by construction (checked in `new` and `advance`).
        self.regions
            .region(self.position_m)
            .unwrap_or(HornRegion::BeyondMeasured)
    }

    /// Moves the block at `velocity_m_per_s` for `dt_s` seconds. Error: `OutOfDomain` when the
    /// block would leave the horn face (|x| > L/2) or the step is not finite; the position is
    /// then unchanged.
    pub fn advance(&mut self, velocity_m_per_s: f32, dt_s: f32) -> Result<(), ModelError> {
        let next = self.position_m + f64::from(velocity_m_per_s) * f64::from(dt_s);
        HornShape::new(next, self.motor.horn_length()).map_err(|_| ModelError::OutOfDomain {
            input: "x",
            reason: "the block left the horn's face (|x| > L/2)",
        })?;
        self.position_m = next;
        Ok(())
    }

    /// The motor force at normal load `normal_n` (N, >= 0, below 32768 N), block velocity
    /// `velocity_m_per_s` (m/s, below 128 m/s) and drive amplitude `amplitude` (fraction of
    /// full scale; [0, 1], 1 meaning the model's full scale 1 - 2^-31). Out-of-range inputs are
    /// errors, never saturated.
    pub fn motor_force(
        &self,
        normal_n: f32,
        velocity_m_per_s: f32,
        amplitude: f32,
    ) -> Result<MotorTruth, ModelError> {
        let point = MotorPoint {
            shape: HornShape::new(self.position_m, self.motor.horn_length())?,
            normal_force: Q16_16::from_f32(normal_n).map_err(|_| ModelError::OutOfDomain {
                input: "F_n",
                reason: "the normal load must be below 32768 N",
            })?,
            block_velocity: Q8_24::from_f32(velocity_m_per_s).map_err(|_| {
                ModelError::OutOfDomain {
                    input: "v_b",
                    reason: "the block speed must be below 128 m/s",
                }
            })?,
        };
        if !(0.0..=1.0).contains(&amplitude) {
            return Err(ModelError::OutOfDomain {
                input: "amplitude",
                reason: "the drive amplitude is a fraction of full scale in [0, 1]",
            });
        }
        // 1.0 is the drive's full scale, which Q1.31 carries as its largest value.
        let amplitude = Q1_31::from_f32(amplitude).unwrap_or(Q1_31::MAX);
        let out = self.motor.force(&point, amplitude)?;
        Ok(MotorTruth {
            position_m: self.position_m as f32,
            region: self.region(),
            force_n: out.force.to_f32(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sonolube::model::horn::UPhase;
    use sonolube::model::motor::{ALUMINIUM_HORN_REGIONS, MotorParams};

    /// Seed 000 Tables 1-2 (Al horn, SS block), mu 0.55 (seed 001 §3.3).
    fn block(start_m: f64) -> BlockOnHorn {
        let motor =
            MotorScene::new(&MotorParams::SEED_001_AL_HORN_SS_BLOCK, UPhase::Quadrature).unwrap();
        BlockOnHorn::new(motor, ALUMINIUM_HORN_REGIONS, start_m).unwrap()
    }

    #[test]
    fn the_position_integrates_the_sliding_velocity_into_the_motor_region_and_back() {
        // From the node out to -1 in at 5 mm/s (5.08 s) and back, 10 kHz steps.
        let mut b = block(0.0);
        let dt = 1e-4f32;
        let steps = (0.0254 / 0.005 / 1e-4) as u32;
        assert_eq!(b.region(), HornRegion::Transition);
        for _ in 0..steps {
            b.advance(-0.005, dt).unwrap();
        }
        let expected = -0.005 * f64::from(dt) * f64::from(steps);
        assert!(
            (b.position_m() - expected).abs() < 1e-9,
            "{}",
            b.position_m()
        );
        assert_eq!(b.region(), HornRegion::Motor);
        let out = b.motor_force(120.0, 0.0, 1.0).unwrap();
        assert!(out.force_n > 18.0 && out.force_n < 18.4, "{out:?}"); // 18.2 N, docs/models.md
        for _ in 0..steps {
            b.advance(0.005, dt).unwrap();
        }
        assert!(b.position_m().abs() < 1e-9);
        assert_eq!(b.region(), HornRegion::Transition);
    }

    #[test]
    fn leaving_the_face_and_bad_inputs_are_errors() {
        let mut b = block(0.063);
        assert!(b.advance(0.01, 0.1).is_err());
        assert_eq!(b.position_m(), 0.063);
        assert!(b.advance(f32::NAN, 1e-4).is_err());
        assert!(block(0.0).motor_force(-1.0, 0.0, 0.5).is_err());
        assert!(block(0.0).motor_force(40_000.0, 0.0, 0.5).is_err());
        assert!(block(0.0).motor_force(10.0, 0.0, 1.5).is_err());
        assert!(BlockOnHorn::new(block(0.0).motor, ALUMINIUM_HORN_REGIONS, 0.07).is_err());
    }
}
