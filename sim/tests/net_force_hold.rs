//! The net-force target through the station and the simulated horn (issue 27): the block on
//! the horn of `horn-al-ss`, travelling through seed 001 Table 1's regions.

use sonolube::model::motor::HornRegion;
use sonolube::protocol::{SupervisorState, Target};
use sonolube::scene::{Breakpoint, Scene, TargetPoint, find};
use sonolube_sim::ClosedLoop;

const INCH: f64 = 0.0254;

/// `horn-al-ss` with the block at `start_m`, sliding at `velocity` m/s under 120 N, holding
/// `target` from t = 0.
fn scene<'a>(
    start_m: f64,
    velocity: &'a [Breakpoint],
    load: &'a [Breakpoint],
    target: &'a [TargetPoint],
    duration_s: f64,
) -> Scene<'a> {
    let base = *find("horn-al-ss").expect("built in");
    let mut horn = base.horn.expect("a horn scene");
    horn.contact_position_m = start_m;
    horn.motor_regions = true;
    let mut transducer = base.transducer;
    // No drift: the hold alone is under test.
    transducer.drift_hz_per_s = 0.0;
    transducer.resonance_hz = transducer.drive_hz;
    Scene {
        horn: Some(horn),
        transducer,
        sliding_velocity_m_per_s: velocity,
        normal_load_n: load,
        target,
        duration_s,
        criteria: &[],
        ..base
    }
}

const LOAD_120: [Breakpoint; 1] = [Breakpoint {
    t_s: 0.0,
    value: 120.0,
}];

/// Runs `scene` to its end; returns the last (station's position, plant's truth).
fn run(scene: &Scene<'_>) -> Vec<(f64, sonolube_sim::plant::GroundTruth, SupervisorState)> {
    let mut run = ClosedLoop::new(scene).expect("runs");
    let mut out = Vec::new();
    while let Some(readings) = run.plant_phase() {
        let output = run.control_phase().expect("control");
        run.finish_step().expect("record");
        let position = run.station().block_position_m().expect("motor scene");
        out.push((position, readings.truth, output.state));
    }
    out
}

#[test]
fn the_loop_holds_a_net_force_on_a_block_in_the_motor_region() {
    // At -1 in moving towards the centre at 5 mm/s: the horn is to push +6 N (an external
    // load of -6 N held, net force zero); it reaches about 18 N at full drive there.
    let velocity = [Breakpoint {
        t_s: 0.0,
        value: 0.005,
    }];
    let target = [TargetPoint {
        at_s: 0.0,
        target: Target::NetForce { force_mn: 6_000 },
        ramp: false,
    }];
    let steps = run(&scene(-INCH, &velocity, &LOAD_120, &target, 0.2));
    let (position, truth, state) = *steps.last().expect("steps");
    assert_eq!(state, SupervisorState::Running);
    let motor = truth.motor.expect("a motor scene");
    assert_eq!(motor.region, HornRegion::Motor);
    // The station tracks the plant's block (same velocity, one sample per period).
    assert!((position - f64::from(motor.position_m)).abs() < 1e-6);
    assert!(
        (position - (-INCH + 0.005 * 0.2)).abs() < 1e-6,
        "{position}"
    );
    // Held over the last 0.1 s: within 3 % of the target on average, every step within the
    // cells' noise band (0.4 N rms on the tangential cell, 3 sigma).
    let late = &steps[steps.len() / 2..];
    let mean: f32 =
        late.iter().map(|s| s.1.motor.unwrap().force_n).sum::<f32>() / late.len() as f32;
    assert!((mean - 6.0).abs() < 0.18, "mean {mean} N");
    for (_, truth, _) in late {
        let force = truth.motor.unwrap().force_n;
        assert!((force - 6.0).abs() < 1.2, "{force} N");
    }
}

#[test]
fn a_friction_target_leaves_the_block_to_the_friction_loop() {
    // The same block and travel with a reduction target: the hold stays out of it, and the
    // horn's force (motor region) is whatever the friction loop's drive makes.
    let velocity = [Breakpoint {
        t_s: 0.0,
        value: 0.005,
    }];
    let target = [TargetPoint {
        at_s: 0.0,
        target: Target::Reduction {
            reduction_mpct: 20_000,
        },
        ramp: false,
    }];
    let steps = run(&scene(-INCH, &velocity, &LOAD_120, &target, 0.05));
    let (_, truth, _) = *steps.last().expect("steps");
    assert_eq!(truth.motor.expect("motor").region, HornRegion::Motor);
}
