//! The net tangential force target and its hold (seed 001 §3.2, Fig. 4; issue 27): in a motor
//! region the vibration drives the block towards the centreline (`crate::model::motor`), so the
//! tangential force can be set, in either direction within the horn's reach, rather than only
//! reduced. Holding a block still against an external load is a net-force target.

use super::pi::{Clamp, Pi, PiGains};
use super::target::ForceQ;
use crate::fx::{Q1_31, Q2_30, Q16_16};
use crate::model::motor::{HornRegion, MotorPoint, MotorScene};
use crate::model::{ModelError, Reach};

/// A net tangential force target (seed 001 §3.2, Fig. 4): the force the horn exerts on a block
/// in a motor region, in newtons along +x as Q18.14, of either sign (|F| <= 50 kN, the force
/// targets' range). Holding a block still against an external load F_ext is the target
/// -F_ext: the net force on the block, horn plus load, is then zero.
///
/// Unlike the three friction targets this is not a friction ratio: the motor model
/// (`crate::model::motor`) maps it to a drive amplitude ([`NetForceHold`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct NetForceTarget(ForceQ);

/// The largest |net force| target, mN (the protocol's force range).
pub const NET_FORCE_MAX_MN: i32 = 50_000_000;

impl NetForceTarget {
    /// The target of `force_mn` millinewtons along +x, `None` beyond +-50 kN.
    pub fn from_millinewtons(force_mn: i32) -> Option<Self> {
        if force_mn.unsigned_abs() > NET_FORCE_MAX_MN as u32 {
            return None;
        }
        ForceQ::from_ratio(force_mn, 1_000).ok().map(Self)
    }

    /// The target force, N along +x, Q18.14.
    pub const fn newtons(&self) -> ForceQ {
        self.0
    }
}

/// What [`NetForceHold::step`] decided.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum HoldStep {
    /// The block is in a motor region: drive at `amplitude` (Q1.31 fraction of full scale).
    Motor {
        /// Drive amplitude.
        amplitude: Q1_31,
        /// Whether the corrected target was reachable (full drive or no drive when not).
        reach: Reach,
        /// The PI's correction in units of mu F_n (Q2.30), the model error it removes.
        correction: Q2_30,
    },
    /// The block is in the measured transition region (seed 001 Table 1): the motor model
    /// does not describe it; the friction controller and its cube model do. The hold's
    /// integral is reset so that it starts clean when the block comes back.
    Transition,
}

/// Holds a [`NetForceTarget`] on a block in a motor region: the motor model's inversion as the
/// feedforward, and the PI of the friction loop (`super::pi`) on the measured force error in
/// units of mu F_n, so that the PI's gains mean the same as in the friction loop (a correction
/// of 1 is the whole Coulomb force).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct NetForceHold {
    target: NetForceTarget,
    pi: Pi,
    /// The amplitude commanded last period (Q1.31 bits), where this period's step starts.
    commanded: i32,
    /// Last period's evaluation (amplitude bits, drive ratio towards the centre in Q.30 bits):
    /// with this period's it gives the secant slope of the Newton step ([`Self::step`]).
    previous: Option<(i32, i64)>,
}

impl NetForceHold {
    /// A hold of `target`, PI at rest.
    pub const fn new(target: NetForceTarget) -> Self {
        Self {
            target,
            pi: Pi::new(),
            commanded: 0,
            previous: None,
        }
    }

    /// The target held.
    pub const fn target(&self) -> NetForceTarget {
        self.target
    }

    /// One control step: the block is in `region` at `point` (position shape, normal load,
    /// velocity) and the tangential cell reads `measured` (N along +x, Q16.16). In the
    /// transition region the hold stands aside ([`HoldStep::Transition`]). Errors: no normal
    /// load (F_n <= 0: there is no force to hold), and the model's own errors.
    pub fn step(
        &mut self,
        gains: &PiGains,
        model: &MotorScene,
        region: HornRegion,
        point: &MotorPoint,
        measured: Q16_16,
    ) -> Result<HoldStep, ModelError> {
        if region == HornRegion::Transition {
            self.pi.reset();
            self.commanded = 0;
            self.previous = None;
            return Ok(HoldStep::Transition);
        }
        // mu F_n in Q16.16 (< 2 x 32768 N: i64).
        let coulomb = (model.friction_coefficient().to_bits() as i64
            * point.normal_force.to_bits() as i64
            + (1 << 29))
            >> 30;
        if coulomb <= 0 {
            return Err(ModelError::OutOfDomain {
                input: "F_n",
                reason: "no normal load: there is no tangential force to hold",
            });
        }
        let target_q16 = (self.target.0.to_bits() as i64) << 2; // Q18.14 -> Q16.16, i64
        // Error in units of mu F_n, Q2.30, saturated at +-2 (two Coulomb forces: the PI's
        // integral is bounded below that anyway).
        let error_q30 = (((target_q16 - measured.to_bits() as i64) << 30) / coulomb)
            .clamp(i32::MIN as i64, i32::MAX as i64);
        let candidate = self.pi.candidate(gains, Q2_30::from_bits(error_q30 as i32));
        // The centre direction decides which way a rising correction moves the drive.
        let centre_positive = point.shape.sin_shape.to_bits() <= 0;
        let s: i64 = if centre_positive { 1 } else { -1 };
        // One Newton step per period from the last amplitude instead of a whole inversion
        // (`MotorScene::amplitude_for_force`, about 18 to 50 evaluations): the block moves
        // 0.8 um and the load barely changes in a period, so the root moves little, and the
        // loop's next step corrects what one step leaves. One evaluation of the model, two when
        // the secant is unusable (first step, no movement, or the falling stretch of a block
        // moving away from the centre, which is then left by stepping up).
        let here = self.commanded;
        // In the drive ratio phi = F_t / (mu F_n) (Q2.30), which the measured load's noise does
        // not move between two periods: the secant stays clean.
        let towards = |amplitude: i32| -> Result<i64, ModelError> {
            Ok(s * model
                .force(point, Q1_31::from_bits(amplitude))?
                .drive_ratio
                .to_bits() as i64)
        };
        let g_here = towards(here)?;
        const PROBE: i32 = 1 << 21; // 1e-3 of full scale
        let secant = self.previous.and_then(|(a0, g0)| {
            let da = i64::from(here) - i64::from(a0);
            // Usable when the two points are apart and on a rising stretch.
            (da.abs() >= i64::from(PROBE) / 4 && (g_here - g0) * da.signum() > 0)
                .then_some((da, g_here - g0))
        });
        let (da, dg) = match secant {
            Some(slope) => slope,
            None => {
                let probe = if here > Q1_31::MAX.to_bits() - PROBE {
                    here - PROBE
                } else {
                    here + PROBE
                };
                let g_probe = towards(probe)?;
                (i64::from(probe) - i64::from(here), g_probe - g_here)
            }
        };
        let newton = |correction: Q2_30| -> (i32, Reach) {
            // The command in units of mu F_n, Q.30 (within a few Coulomb forces: fits i64).
            let wanted = s * (((target_q16 << 30) / coulomb) + correction.to_bits() as i64);
            let next = if dg * da.signum() <= 0 {
                // Falling or flat: the rising branch lies above.
                i64::from(here) + 16 * i64::from(PROBE)
            } else {
                i64::from(here) + ((wanted - g_here) as i128 * da as i128 / dg as i128) as i64
            };
            if next >= i64::from(Q1_31::MAX.to_bits()) {
                (Q1_31::MAX.to_bits(), Reach::BelowMinimum)
            } else if next <= 0 {
                (0, Reach::AboveNatural)
            } else {
                (next as i32, Reach::Reached)
            }
        };
        let (_, proposed_reach) = newton(candidate.correction());
        let clamp = match (proposed_reach, centre_positive) {
            (Reach::Reached, _) => Clamp::Free,
            // Full drive: pushing further towards the centre changes nothing.
            (Reach::BelowMinimum, true) | (Reach::AboveNatural, false) => Clamp::Upper,
            (Reach::BelowMinimum, false) | (Reach::AboveNatural, true) => Clamp::Lower,
        };
        let correction = self.pi.commit(gains, candidate, clamp);
        let (amplitude, reach) = newton(correction);
        self.previous = Some((here, g_here));
        self.commanded = amplitude;
        Ok(HoldStep::Motor {
            amplitude: Q1_31::from_bits(amplitude),
            reach,
            correction,
        })
    }
}

#[cfg(test)]
mod tests {

    use super::*;
    use crate::fx::Q8_24;
    use crate::model::horn::{HornShape, UPhase};
    use crate::model::motor::{ALUMINIUM_HORN_REGIONS, MotorParams};

    fn scene(mu: f64, b: f64) -> MotorScene {
        MotorScene::new(
            &MotorParams {
                friction_coefficient: mu,
                vertical_amplitude: b,
                ..MotorParams::SEED_001_AL_HORN_SS_BLOCK
            },
            UPhase::Quadrature,
        )
        .unwrap()
    }

    fn at(x: f64, load: f64) -> MotorPoint {
        MotorPoint {
            shape: HornShape::new(x, 0.127).unwrap(),
            normal_force: Q16_16::from_f64(load).unwrap(),
            block_velocity: Q8_24::ZERO,
        }
    }

    /// Runs the hold for `steps` control steps against a plant (another motor scene) and
    /// an external load; returns the net force on the block (horn + load) at the end.
    fn run(x: f64, external_n: f64, gains: &PiGains, steps: usize) -> f64 {
        // Model: seed values (mu 0.55, B 1.1 um). Plant: 10 % more friction and 10 % more
        // vertical amplitude, the model error the PI must find.
        let (model, plant) = (scene(0.55, 1.1e-6), scene(0.605, 1.21e-6));
        let point = at(x, 120.0);
        let target = NetForceTarget::from_millinewtons((-external_n * 1e3) as i32).unwrap();
        let mut hold = NetForceHold::new(target);
        let mut amplitude = Q1_31::ZERO;
        for _ in 0..steps {
            let measured = plant.force(&point, amplitude).unwrap().force;
            let region = ALUMINIUM_HORN_REGIONS.region(x).unwrap();
            match hold.step(gains, &model, region, &point, measured).unwrap() {
                HoldStep::Motor { amplitude: a, .. } => amplitude = a,
                HoldStep::Transition => panic!("x {x} is a motor point"),
            }
        }
        plant.force(&point, amplitude).unwrap().force.to_f64() + external_n
    }

    #[test]
    fn the_hold_keeps_a_block_still_against_an_external_load() {
        let gains = PiGains::new(0.2, 300.0, 1e-3, 1.0).unwrap();
        let open = PiGains::new(0.0, 0.0, 1e-3, 1.0).unwrap();
        // At -1 in the drive pushes towards +x; at +1 in towards -x. External pulls of 8 N
        // away from the centreline (below the 18 N the horn gives at full amplitude).
        for (x, external) in [(-0.0254, -8.0), (0.0254, 8.0), (-0.0381, -5.0)] {
            let closed = run(x, external, &gains, 400);
            assert!(closed.abs() < 5e-3, "x {x}: net {closed} N");
            // The feedforward alone leaves the model error standing: the PI is needed.
            let feedforward = run(x, external, &open, 400);
            assert!(
                feedforward.abs() > 0.3,
                "x {x}: open-loop net {feedforward} N"
            );
        }
    }

    #[test]
    fn the_hold_stands_aside_in_the_transition_region_and_refuses_no_load() {
        let gains = PiGains::new(0.2, 300.0, 1e-3, 1.0).unwrap();
        let model = scene(0.55, 1.1e-6);
        let mut hold = NetForceHold::new(NetForceTarget::from_millinewtons(-3_000).unwrap());
        let point = at(0.003, 120.0);
        let region = ALUMINIUM_HORN_REGIONS.region(0.003).unwrap();
        assert_eq!(
            hold.step(&gains, &model, region, &point, Q16_16::ZERO),
            Ok(HoldStep::Transition)
        );
        let unloaded = at(-0.0254, 0.0);
        assert!(
            hold.step(&gains, &model, HornRegion::Motor, &unloaded, Q16_16::ZERO)
                .is_err()
        );
        assert!(NetForceTarget::from_millinewtons(-50_000_000).is_some());
        assert!(NetForceTarget::from_millinewtons(50_000_001).is_none());
        assert!(NetForceTarget::from_millinewtons(i32::MIN).is_none());
    }

    #[test]
    fn an_unreachable_target_runs_full_drive_without_winding_up() {
        // 30 N at -1 in under 120 N: the horn gives at most about 20 N.
        let gains = PiGains::new(0.2, 300.0, 1e-3, 0.5).unwrap();
        let (model, plant) = (scene(0.55, 1.1e-6), scene(0.605, 1.21e-6));
        let point = at(-0.0254, 120.0);
        let mut hold = NetForceHold::new(NetForceTarget::from_millinewtons(30_000).unwrap());
        let mut amplitude = Q1_31::ZERO;
        let mut last = None;
        for _ in 0..200 {
            let measured = plant.force(&point, amplitude).unwrap().force;
            last = Some(
                hold.step(&gains, &model, HornRegion::Motor, &point, measured)
                    .unwrap(),
            );
            if let Some(HoldStep::Motor { amplitude: a, .. }) = last {
                amplitude = a;
            }
        }
        match last {
            Some(HoldStep::Motor {
                amplitude,
                reach,
                correction,
            }) => {
                assert_eq!(amplitude, Q1_31::MAX);
                assert_eq!(reach, Reach::BelowMinimum);
                // Frozen by the clamp from the first step on (the drive was at its
                // ceiling at once): no integral at all, only the proportional part.
                assert_eq!(hold.pi.integral(), Q2_30::ZERO);
                assert!(correction.to_f64() < 0.2 * 2.0 + 1e-6);
            }
            other => panic!("{other:?}"),
        }
    }
}
