//! Property test of the controller: arbitrary sensor bits and command sequences.

use proptest::prelude::*;

use super::config::{Config, Settings};
use super::controller::Controller;
use super::io::Inputs;
use super::pi::PiGains;
use super::reason::{ExternalFault, Sensor, SensorFault, SensorFaultKind};
use super::schedule::GainSchedule;
use super::testkit::{LinearModel, LittmannModel};
use crate::fx::{Q2_30, Q8_24, Q16_16};
use crate::protocol::{SupervisorState as S, Target, TargetRange};

const T: f64 = 1e-4;

#[derive(Debug, Clone)]
enum Command {
    Step(i32, i32, i32, Option<u8>),
    Start,
    Stop,
    Clear,
    Target(u8, u32),
    Gains(f64, f64),
    Trip,
}

fn command() -> impl Strategy<Value = Command> {
    prop_oneof![
        8 => (any::<i32>(), any::<i32>(), any::<i32>(), proptest::option::weighted(0.05, 0u8..12))
            .prop_map(|(n, t, v, f)| Command::Step(n, t, v, f)),
        // Plausible readings too, so that the loop actually closes sometimes.
        8 => (0i32..200 << 16, -(60 << 16)..60i32 << 16, -(1i32 << 22)..1 << 22)
            .prop_map(|(n, t, v)| Command::Step(n, t, v, None)),
        1 => Just(Command::Start),
        1 => Just(Command::Stop),
        1 => Just(Command::Clear),
        1 => (0u8..3, any::<u32>()).prop_map(|(k, v)| Command::Target(k, v)),
        1 => (0.0f64..50.0, 0.0f64..10_000.0).prop_map(|(kp, ki)| Command::Gains(kp, ki)),
        1 => Just(Command::Trip),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]
    /// Any sensor bits, any commands, both test models: no panic, no overflow (overflow checks
    /// are on in tests), the drive always within [0, limit] and zero whenever it must be.
    #[test]
    fn no_panic_and_a_safe_drive_for_any_inputs(
        commands in proptest::collection::vec(command(), 1..300),
        linear in any::<bool>(),
    ) {
        let mut ctl = Controller::new(Config::new(&Settings::REFERENCE).unwrap());
        let littmann = LittmannModel::new(0.0754);
        let straight = LinearModel { slope: Q2_30::from_f64(0.7).unwrap() };
        let max = ctl.config().limit().max_amplitude;
        for c in commands {
            match c {
                Command::Step(n, t, v, fault) => {
                    let sensor_fault = fault.map(|f| SensorFault {
                        sensor: [Sensor::NormalForce, Sensor::TangentialForce, Sensor::SlidingVelocity][(f % 3) as usize],
                        kind: [SensorFaultKind::Disconnected, SensorFaultKind::Stuck, SensorFaultKind::Jump, SensorFaultKind::OutOfRange][(f / 3) as usize],
                    });
                    let inputs = Inputs {
                        normal_force: Q16_16::from_bits(n),
                        tangential_force: Q16_16::from_bits(t),
                        sliding_velocity: Q8_24::from_bits(v),
                        sensor_fault,
                    };
                    let out = if linear { ctl.step(&inputs, &straight) } else { ctl.step(&inputs, &littmann) };
                    prop_assert!(out.amplitude.command().value <= max);
                    if sensor_fault.is_some() || matches!(out.state, S::Fault | S::Idle) {
                        prop_assert_eq!(out.amplitude, crate::drive::Amplitude::ZERO);
                    }
                    prop_assert_eq!(out.state == S::Fault, out.fault.is_some());
                    prop_assert!(out.integral.to_bits().unsigned_abs() <= 1 << 29);
                }
                Command::Start => { let _ = ctl.start(); }
                Command::Stop => prop_assert!(ctl.stop().is_ok()),
                Command::Clear => { let _ = ctl.clear_fault(); }
                Command::Target(kind, value) => {
                    let target = Target::from_kind(["force", "coef", "reduction"][kind as usize], i64::from(value)).unwrap();
                    prop_assert_eq!(ctl.set_target(target).is_ok(), target.is_valid());
                }
                Command::Gains(kp, ki) => {
                    let gains = PiGains::new(kp, ki, T, 0.5).unwrap();
                    prop_assert!(ctl.set_gains(GainSchedule::constant(gains)).is_ok());
                }
                Command::Trip => ctl.trip(ExternalFault::Overcurrent),
            }
        }
    }
}
