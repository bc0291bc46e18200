//! The loop's state after one step, in the protocol's integer units: what `status` and
//! telemetry report.

use sonolube::control::Output;
use sonolube::drive::Amplitude;
use sonolube::fx::{Q2_30, Q16_16};
use sonolube::protocol::{Lock, LoopReading, RunReach, StatusReport, Target, TelemetryRecord};

/// The loop after a step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, defmt::Format)]
pub struct Snapshot {
    /// State, target, friction estimate and drive: what `status` and telemetry share.
    pub reading: LoopReading,
    /// The scene in use (a protocol word).
    pub scene: Option<&'static str>,
    /// The latched fault's name, if any.
    pub latched_fault: Option<&'static str>,
    /// A sensor fault found in this step's sample (its name), if any.
    pub active_fault: Option<&'static str>,
    /// Board cycles the step's control part took (sense, estimate, model, control, drive
    /// command), in the board's cycle clock ([`crate::control::ControlLoop::CYCLE_HZ`]).
    pub control_cycles: u32,
    /// The resonance loop's state, if the station has a loop.
    pub lock: Option<Lock>,
    /// The motional current (its phase to the voltage is the tracker's phase error; turned
    /// into degrees only for `status`); `None` when undefined.
    pub motional: Option<sonolube::resonance::Phasor>,
    /// Whether the target is within reach, and the drive near the resonance (issue 26).
    pub reach: RunReach,
    /// The loop runs on commissioned values, not the scene's declared ones (`status`'s
    /// `values=`).
    pub commissioned: bool,
}

impl Snapshot {
    /// The snapshot before the first step.
    pub const BOOT: Snapshot = Snapshot {
        reading: LoopReading::BOOT,
        scene: None,
        latched_fault: None,
        active_fault: None,
        control_cycles: 0,
        lock: None,
        motional: None,
        reach: RunReach::UNKNOWN,
        commissioned: false,
    };

    /// The snapshot of a controller `output`, with the loop's other facts.
    pub fn new(
        output: &Output,
        target: Option<Target>,
        scene: &'static str,
        drive_freq_chz: u32,
        active_fault: Option<&'static str>,
        control_cycles: u32,
    ) -> Self {
        Snapshot {
            reading: LoopReading {
                state: output.state,
                target,
                friction_coef_ppm: coefficient_ppm(output.estimate.coefficient),
                normal_force_mn: newtons_to_mn(output.estimate.normal_force),
                tangential_force_mn: newtons_to_mn(output.estimate.tangential_force),
                drive_amplitude_ppm: amplitude_ppm(output.amplitude),
                drive_freq_chz,
            },
            scene: Some(scene),
            latched_fault: output.fault.map(|reason| reason.name()),
            active_fault,
            control_cycles,
            lock: None,
            motional: None,
            reach: RunReach::UNKNOWN,
            commissioned: false,
        }
    }

    /// This snapshot with whether the station runs on commissioned values
    /// (`sonolube::station::Station::commissioned`).
    pub fn with_commissioned(self, commissioned: bool) -> Self {
        Snapshot {
            commissioned,
            ..self
        }
    }

    /// This snapshot with the station's reach fields
    /// (`sonolube::station::Station::run_reach`).
    pub fn with_reach(self, reach: RunReach) -> Self {
        Snapshot { reach, ..self }
    }

    /// This snapshot with the station's resonance report (`None`: no loop).
    pub fn with_resonance(self, report: Option<sonolube::resonance::ResonanceReport>) -> Self {
        Snapshot {
            lock: report.map(|r| Lock::from(r.state)),
            motional: report.and_then(|r| r.motional),
            ..self
        }
    }

    /// The `status` reply's data, with the loop's counters.
    pub fn status(&self, overruns: u32, lost_telemetry: u32) -> StatusReport {
        StatusReport {
            reading: self.reading,
            scene: self.scene,
            overruns,
            lost_telemetry,
            latched_fault: self.latched_fault,
            lock: self.lock.map(Lock::name),
            phase_mdeg: self.phase_mdeg(),
            reach: self.reach,
            commissioned: self.commissioned,
        }
    }

    /// A telemetry record of this snapshot.
    pub fn record(&self, time_us: u64, seq: u32, overruns: u32, lost: u32) -> TelemetryRecord {
        TelemetryRecord {
            time_us,
            seq,
            reading: self.reading,
            overruns,
            lost_records: lost,
            lock: self.lock,
            phase_mdeg: self.phase_mdeg(),
            reach: self.reach,
        }
    }

    /// The phase error in mdeg (a CORDIC: for reports only, not per step).
    fn phase_mdeg(&self) -> Option<i32> {
        self.motional.map(|m| {
            // 360 000 mdeg per 2^32: |result| <= 180 000.
            ((i64::from(m.polar().phase.to_bits()) * 360_000 + (1 << 31)) >> 32) as i32
        })
    }
}

/// Q2.30 coefficient [0, 2) to ppm, rounded.
fn coefficient_ppm(coefficient: Q2_30) -> u32 {
    unsigned(coefficient.round_scaled(1_000_000))
}

/// Q16.16 newtons (+-32768 N) to mN, rounded: fits an i32.
fn newtons_to_mn(force: Q16_16) -> i32 {
    force.round_scaled(1_000) as i32
}

/// Q1.31 amplitude [0, 1) to ppm, rounded.
fn amplitude_ppm(amplitude: Amplitude) -> u32 {
    // Full scale is 1,000,000: fits.
    u32::try_from(amplitude.round_scaled(1_000_000)).unwrap_or(u32::MAX)
}

/// A non-negative scaled value as a `u32`; negative values (which these quantities never
/// take) as 0.
fn unsigned(scaled: i64) -> u32 {
    u32::try_from(scaled.max(0)).unwrap_or(u32::MAX)
}
