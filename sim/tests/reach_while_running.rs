//! Feasibility while running (issue 26), on the operated reference scene through the station
//! the firmware runs: `target reduction 99.999` used to answer a bare `ok` and `status` to show
//! `amp=1.000000 fault=none`; `freq 20000` on the 40 kHz stack left the drive at full scale
//! with the friction natural, silently.

use sonolube::protocol::{Command, ReachState, ResonanceDistance, SupervisorState, Target};
use sonolube::scene::find;
use sonolube_sim::ClosedLoop;

fn operated() -> ClosedLoop<'static> {
    let mut run = ClosedLoop::operated(find("reference").expect("built in")).expect("runs");
    // Sliding, the natural friction learned, drive off.
    for _ in 0..100 {
        run.step().expect("never finishes");
    }
    run
}

/// The reference's Coulomb ratio at v / v_a = 0.038 / 0.1195 and full drive: 2/pi asin(0.318)
/// = 0.206 of the natural friction, a reduction of at most 79.4 % (the drive's ceiling is full
/// scale there: the current rating binds at 5.25 V).
const LITTMANN_REDUCTION_PCT: f64 = 79.4;

fn reduction_pct(target: Target) -> f64 {
    match target {
        Target::Reduction { reduction_mpct } => f64::from(reduction_mpct) * 1e-3,
        other => panic!("not a reduction: {other:?}"),
    }
}

#[test]
fn a_target_beyond_reach_is_accepted_with_the_reachable_value() {
    let mut run = operated();
    let beyond = Target::Reduction {
        reduction_mpct: 99_999,
    };
    assert_eq!(run.execute(&Command::Target(beyond)), Ok(()));
    let reachable = run.station().target_warning().expect("a warning");
    let pct = reduction_pct(reachable);
    assert!(
        (pct - LITTMANN_REDUCTION_PCT).abs() < 2.0,
        "reachable {pct} %"
    );
    // A reachable target gets no warning.
    let within = Target::Reduction {
        reduction_mpct: 50_000,
    };
    assert_eq!(run.execute(&Command::Target(within)), Ok(()));
    assert_eq!(run.station().target_warning(), None);
}

#[test]
fn status_says_target_unreachable_with_the_reachable_value_while_running() {
    let mut run = operated();
    let beyond = Target::Reduction {
        reduction_mpct: 99_000,
    };
    run.execute(&Command::Target(beyond)).expect("accepted");
    assert_eq!(run.station().run_reach().state, ReachState::Ok);
    run.execute(&Command::Start).expect("starts");
    let mut seen = None;
    for _ in 0..500 {
        let record = run.step().expect("never finishes");
        let reach = run.station().run_reach();
        if record.state == SupervisorState::Running && reach.state == ReachState::TargetUnreachable
        {
            seen = Some(reach);
            break;
        }
    }
    let reach = seen.expect("target-unreachable within 50 ms of drive at its limit");
    // And it stays so while the drive sits at its limit (no flicker from window to window).
    for _ in 0..300 {
        run.step();
        assert_eq!(
            run.station().run_reach().state,
            ReachState::TargetUnreachable
        );
    }
    let pct = reduction_pct(reach.reachable.expect("the reachable value"));
    assert!(
        (pct - LITTMANN_REDUCTION_PCT).abs() < 3.0,
        "reachable {pct} %"
    );
    assert_eq!(reach.resonance, Some(ResonanceDistance::Near));
    // Back within reach: the state clears once the drive leaves its limit.
    run.execute(&Command::Target(Target::Reduction {
        reduction_mpct: 40_000,
    }))
    .expect("accepted");
    for _ in 0..300 {
        run.step();
    }
    assert_eq!(run.station().run_reach().state, ReachState::Ok);
}

#[test]
fn a_reachable_target_is_never_reported_unreachable() {
    let mut run = operated();
    run.execute(&Command::Target(Target::Reduction {
        reduction_mpct: 50_000,
    }))
    .expect("accepted");
    run.execute(&Command::Start).expect("starts");
    for _ in 0..500 {
        run.step();
        assert_eq!(run.station().run_reach().state, ReachState::Ok);
    }
}

#[test]
fn a_drive_at_half_the_resonance_is_far() {
    let mut run = operated();
    assert_eq!(
        run.station().run_reach().resonance,
        Some(ResonanceDistance::Near)
    );
    run.execute(&Command::Freq {
        freq_chz: 2_000_000,
    })
    .expect("in the range");
    assert_eq!(
        run.station().run_reach().resonance,
        Some(ResonanceDistance::Far)
    );
    // And a target the 1 % vibration left cannot reach is warned about at once.
    run.step();
    run.execute(&Command::Target(Target::Reduction {
        reduction_mpct: 20_000,
    }))
    .expect("accepted");
    assert!(run.station().target_warning().is_some());
}
