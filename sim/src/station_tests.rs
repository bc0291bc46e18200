//! The firmware's station (`sonolube::station`) run through the simulation: operated and
//! scripted loops, `tare` and `cal`, the drive frequency and its current ceiling.

use crate::{ClosedLoop, Mode};
use sonolube::protocol::{Axis, Command, ErrorCode, SupervisorState, TareAxes, Target};
use sonolube::scene::find;

fn operated() -> ClosedLoop<'static> {
    ClosedLoop::operated(find("reference").expect("built in")).expect("runs")
}

fn code(result: Result<(), sonolube::protocol::ProtocolError>) -> Option<ErrorCode> {
    result.err().map(|e| e.code())
}

#[test]
fn an_operated_loop_holds_the_commanded_coefficient_and_stops_on_command() {
    let mut run = operated();
    assert_eq!(run.mode(), Mode::Operated);
    // Idle, no target: the drive stays off.
    for _ in 0..20 {
        let record = run.step().expect("never finishes");
        assert_eq!(record.drive_amplitude, 0.0);
    }
    assert_eq!(
        code(run.execute(&Command::Start)),
        Some(ErrorCode::NoTarget)
    );
    let target = Target::Coef { coef_ppm: 150_000 };
    assert_eq!(run.execute(&Command::Target(target)), Ok(()));
    assert_eq!(run.execute(&Command::Start), Ok(()));
    let mut last = None;
    for _ in 0..200 {
        last = run.step();
    }
    let record = last.expect("never finishes");
    assert_eq!(record.state, SupervisorState::Running);
    let mu = record.estimated_friction_n / record.normal_load_n;
    assert!((mu - 0.15).abs() < 0.15 * 0.03, "mu {mu}");
    assert_eq!(run.execute(&Command::Stop), Ok(()));
    for _ in 0..200 {
        last = run.step();
    }
    let record = last.expect("never finishes");
    assert_eq!(record.drive_amplitude, 0.0);
    assert_eq!(record.state, SupervisorState::Idle);
}

#[test]
fn a_scripted_loop_refuses_the_operators_commands_and_keeps_its_state() {
    let mut run = ClosedLoop::new(find("reference").expect("built in")).expect("runs");
    run.step().expect("first step");
    let before = run.controller().target();
    let refused = run.execute(&Command::Target(Target::Coef { coef_ppm: 100_000 }));
    assert_eq!(code(refused), Some(ErrorCode::WrongState));
    assert_eq!(
        code(run.execute(&Command::Stop)),
        Some(ErrorCode::WrongState)
    );
    assert_eq!(run.controller().target(), before);
}

#[test]
fn tare_and_cal_need_the_drive_off_and_change_nothing_when_refused() {
    let mut run = operated();
    assert_eq!(run.execute(&Command::Tare(TareAxes::All)), Ok(()));
    let cal = Command::Cal {
        axis: Axis::Normal,
        load_mn: 5_000,
    };
    assert_eq!(run.execute(&cal), Ok(()));
    run.execute(&Command::Target(Target::Reduction {
        reduction_mpct: 30_000,
    }))
    .expect("target");
    run.execute(&Command::Start).expect("start");
    for _ in 0..50 {
        run.step();
    }
    let state = run.controller().state();
    assert_ne!(state, SupervisorState::Idle);
    assert_eq!(
        code(run.execute(&Command::Tare(TareAxes::One(Axis::Tangential)))),
        Some(ErrorCode::WrongState)
    );
    assert_eq!(code(run.execute(&cal)), Some(ErrorCode::WrongState));
}

/// The current a ceiling lets through at the configured drive frequency, A.
fn current_at_ceiling(run: &ClosedLoop<'_>) -> (f64, sonolube::control::Binding) {
    let config = run.station().controller().config();
    let r = config.actuator();
    let a = config.limit().max_amplitude.to_f64();
    let current = core::f64::consts::TAU
        * r.drive_frequency_hz
        * r.capacitance_f
        * a
        * r.full_scale_voltage_v;
    (current, config.limit().binding)
}

#[test]
fn the_amplitude_ceiling_follows_the_drive_frequency() {
    use sonolube::control::Binding;
    // The welding converter of horn-al-ss: 1 kV at full scale into 20 nF, 6 A rating.
    let mut run = ClosedLoop::operated(find("horn-al-ss").expect("built in")).expect("runs");
    let rating = run.station().controller().config().actuator().max_current_a;
    let (current, binding) = current_at_ceiling(&run);
    assert_ne!(
        binding,
        Binding::Current,
        "{current} A at the scene's 20.03 kHz"
    );
    assert!(current < rating);
    // At 60 kHz, 2 pi f C V_fs = 7.5 A at full scale: the 6 A rating binds.
    assert_eq!(
        run.execute(&Command::Freq {
            freq_chz: 6_000_000
        }),
        Ok(())
    );
    let (current, binding) = current_at_ceiling(&run);
    assert_eq!(binding, Binding::Current);
    assert!(
        current <= rating && current > rating * (1.0 - 1e-6),
        "{current} A"
    );
    // Back down: the ceiling rises again.
    assert_eq!(
        run.execute(&Command::Freq {
            freq_chz: 2_003_000
        }),
        Ok(())
    );
    let (_, binding) = current_at_ceiling(&run);
    assert_ne!(binding, Binding::Current);
}

#[test]
fn a_drive_frequency_outside_the_range_is_refused_and_kept() {
    let mut run = operated();
    let before = run.station().drive_hz();
    let refused = run.execute(&Command::Freq {
        freq_chz: 6_000_001,
    });
    assert_eq!(code(refused), Some(ErrorCode::OutOfRange));
    assert_eq!(run.station().drive_hz(), before);
    assert_eq!(
        run.execute(&Command::Freq {
            freq_chz: 3_950_050
        }),
        Ok(())
    );
    assert_eq!(run.station().drive_hz(), 39_500.5);
    assert_eq!(run.station().drive_freq_chz(), 3_950_050);
    // Not the loop's commands.
    assert_eq!(
        code(run.execute(&Command::Version)),
        Some(ErrorCode::WrongState)
    );
}

/// `freq auto` on a plant without a sampled current is refused as `unavailable` with the
/// reason, in every state (no longer the misleading `wrong-state ... in state idle`); the
/// reason names the scene, the cause, not the board (issue 26: the same board accepts it in
/// `resonance-drift`).
#[test]
fn freq_auto_without_current_samples_is_unavailable_and_says_why() {
    let mut run = operated();
    let error = run.execute(&Command::FreqAuto).unwrap_err();
    assert_eq!(error.code(), ErrorCode::Unavailable);
    let mut text: heapless::String<128> = heapless::String::new();
    sonolube::protocol::format_error(&error, &mut text).unwrap();
    assert!(
        text.contains("freq is unavailable: the scene has no current sensing"),
        "{text}"
    );
}

/// `freq auto` in idle arms the search; `start` runs it at its own amplitude with the friction
/// loop waiting, the loop starts at the lock and the tracker keeps the drive on f0; `freq HZ`
/// pins again.
#[test]
fn freq_auto_searches_at_start_then_tracks_and_freq_pins() {
    let scene = find("resonance-search").expect("built in");
    let mut run = ClosedLoop::operated(scene).expect("runs");
    assert_eq!(run.execute(&Command::FreqAuto), Ok(()));
    let lock = |run: &ClosedLoop<'_>| run.station().resonance().expect("a loop").state;
    assert_eq!(lock(&run), sonolube::resonance::LockState::Pinned);
    assert_eq!(
        run.execute(&Command::Target(Target::Reduction {
            reduction_mpct: 40_000
        })),
        Ok(())
    );
    assert_eq!(run.execute(&Command::Start), Ok(()));
    let mut searched = 0;
    let mut record = run.step().expect("never finishes");
    while lock(&run) == sonolube::resonance::LockState::Searching {
        // The friction loop waits, the search drives a tenth of full scale.
        assert_eq!(record.state, SupervisorState::Idle);
        assert!((record.drive_amplitude - 0.1).abs() < 1e-6);
        searched += 1;
        assert!(searched < 150, "no lock in 15 ms");
        record = run.step().expect("never finishes");
    }
    for _ in 0..300 {
        record = run.step().expect("never finishes");
    }
    assert_eq!(record.state, SupervisorState::Running);
    assert_eq!(lock(&run), sonolube::resonance::LockState::Locked);
    let offset = (record.drive_hz - record.resonance_hz).abs() / record.resonance_hz;
    assert!(
        offset < 5e-4,
        "drive {} f0 {}",
        record.drive_hz,
        record.resonance_hz
    );
    assert!(
        run.station().resonance().expect("a loop").phase().is_some(),
        "a phase error is reported"
    );
    assert_eq!(
        run.execute(&Command::Freq {
            freq_chz: 3_900_000
        }),
        Ok(())
    );
    record = run.step().expect("never finishes");
    assert_eq!(lock(&run), sonolube::resonance::LockState::Pinned);
    assert_eq!(record.drive_hz, 39_000.0);
}

/// A tracker that loses the resonance latches `resonance-lost` (reason 23): the supervisor
/// goes to `fault` and the drive to zero. Here the resonance leaves the tracker's band
/// (+-10 % of nominal) at 1 %/s x 20: the tracker pins at its limit and faults.
#[test]
fn losing_the_resonance_latches_a_fault() {
    let mut scene = *find("resonance-drift").expect("built in");
    scene.transducer.drift_hz_per_s = 8_000.0;
    scene.duration_s = 1.0;
    let scene: &'static sonolube::scene::Scene<'static> = Box::leak(Box::new(scene));
    let mut run = ClosedLoop::new(scene).expect("runs");
    let mut fault = None;
    while let Some(record) = run.step() {
        if record.state == SupervisorState::Fault {
            fault = Some(record);
            break;
        }
    }
    let record = fault.expect("the resonance left the band: a fault");
    assert_eq!(record.reason, sonolube::control::Reason::ResonanceLost);
    assert_eq!(record.reason.code(), 23);
    assert_eq!(record.drive_amplitude, 0.0);
    // The tracker's upper limit is 44 kHz (+10 %): the fault comes after f0 passes it.
    assert!(record.resonance_hz > 44_000.0, "f0 {}", record.resonance_hz);
}
