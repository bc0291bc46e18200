//! Reason codes: why the supervisor changed state, and which faults it latches.
//!
//! Every transition records a [`Reason`]. Its [`code`](Reason::code) is stable (a host may
//! act on the number; a code never changes meaning and is never reused) and its
//! [`name`](Reason::name) is a short kebab-case word for logs and for the protocol's `fault=`
//! field (it satisfies `protocol::is_word`).
//!
//! | code | name | transition |
//! |---|---|---|
//! | 0 | `power-on` | initial state (idle) |
//! | 1 | `start-command` | idle -> ramp-up |
//! | 2 | `stop-command` | ramp-up, running -> ramp-down |
//! | 3 | `clear-command` | fault -> idle |
//! | 4 | `ramp-done` | ramp-up -> running, ramp-down -> idle |
//! | 5 | `not-sliding` | ramp-up, running -> ramp-down (run stays armed) |
//! | 6 | `no-load` | ramp-up, running -> ramp-down: `F_n < F_n_min` (run stays armed) |
//! | 7 | `sliding-resumed` | idle, ramp-down -> ramp-up (armed run, contact back) |
//! | 20 | `overcurrent` | any -> fault (reported by the drive) |
//! | 21 | `overrun` | any -> fault (the control step missed its period) |
//! | 22 | `model-error` | any -> fault (the model could not be evaluated) |
//! | 23 | `resonance-lost` | any -> fault (`freq auto`: the search failed, or the tracker lost the resonance; see `crate::resonance::ResonanceLoop`) |
//! | 40-51 | `<sensor>-<kind>` | any -> fault: `40 + 4 sensor + kind`, sensor normal 0, tangential 1, velocity 2; kind disconnected 0, stuck 1, jump 2, out-of-range 3 (e.g. 41 `normal-stuck`, 47 `tangential-out-of-range`) |

/// A sensor the controller reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Sensor {
    /// The normal-force load cell.
    NormalForce = 0,
    /// The tangential-force (friction) load cell.
    TangentialForce = 1,
    /// The sliding-velocity sensor.
    SlidingVelocity = 2,
}

/// What is wrong with a sensor.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SensorFaultKind {
    /// At a converter rail: open wire or unplugged (`crate::sense` detects it).
    Disconnected = 0,
    /// The reading does not move (`crate::sense`).
    Stuck = 1,
    /// An implausible jump between two samples (`crate::sense`).
    Jump = 2,
    /// The value is beyond the sensor's configured range (the controller detects it).
    OutOfRange = 3,
}

/// A sensor fault: which sensor and what.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SensorFault {
    /// The sensor.
    pub sensor: Sensor,
    /// What is wrong.
    pub kind: SensorFaultKind,
}

/// A fault found outside the controller, reported with `Controller::trip`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ExternalFault {
    /// The drive current exceeded its limit (the hardware trip fired).
    Overcurrent,
    /// The control step did not finish within its period.
    Overrun,
    /// The resonance loop (`freq auto`) failed its search or lost the resonance.
    ResonanceLost,
}

/// Why the supervisor is in its present state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Reason {
    /// The controller was created.
    PowerOn,
    /// `start` command.
    StartCommand,
    /// `stop` command.
    StopCommand,
    /// `clear` command.
    ClearCommand,
    /// A soft start or a ramp-down finished.
    RampDone,
    /// Sliding stopped: no friction to reduce.
    NotSliding,
    /// The normal load fell below its minimum: no friction coefficient to control.
    NoLoad,
    /// Sliding (and load) came back while a run was armed.
    SlidingResumed,
    /// Drive overcurrent.
    Overcurrent,
    /// Control-step overrun.
    Overrun,
    /// The friction model returned an error.
    ModelError,
    /// The resonance search failed or tracking lost the resonance.
    ResonanceLost,
    /// A sensor fault.
    SensorFault(SensorFault),
}

/// Names of the sensor faults, indexed by `4 sensor + kind`.
const SENSOR_FAULT_NAMES: [&str; 12] = [
    "normal-disconnected",
    "normal-stuck",
    "normal-jump",
    "normal-out-of-range",
    "tangential-disconnected",
    "tangential-stuck",
    "tangential-jump",
    "tangential-out-of-range",
    "velocity-disconnected",
    "velocity-stuck",
    "velocity-jump",
    "velocity-out-of-range",
];

impl Reason {
    /// The stable numeric code (table in the module docs).
    pub const fn code(self) -> u16 {
        match self {
            Reason::PowerOn => 0,
            Reason::StartCommand => 1,
            Reason::StopCommand => 2,
            Reason::ClearCommand => 3,
            Reason::RampDone => 4,
            Reason::NotSliding => 5,
            Reason::NoLoad => 6,
            Reason::SlidingResumed => 7,
            Reason::Overcurrent => 20,
            Reason::Overrun => 21,
            Reason::ModelError => 22,
            Reason::ResonanceLost => 23,
            Reason::SensorFault(f) => 40 + 4 * f.sensor as u16 + f.kind as u16,
        }
    }

    /// The short kebab-case name, at most 23 bytes.
    pub const fn name(self) -> &'static str {
        match self {
            Reason::PowerOn => "power-on",
            Reason::StartCommand => "start-command",
            Reason::StopCommand => "stop-command",
            Reason::ClearCommand => "clear-command",
            Reason::RampDone => "ramp-done",
            Reason::NotSliding => "not-sliding",
            Reason::NoLoad => "no-load",
            Reason::SlidingResumed => "sliding-resumed",
            Reason::Overcurrent => "overcurrent",
            Reason::Overrun => "overrun",
            Reason::ModelError => "model-error",
            Reason::ResonanceLost => "resonance-lost",
            Reason::SensorFault(f) => SENSOR_FAULT_NAMES[4 * f.sensor as usize + f.kind as usize],
        }
    }

    /// Whether this reason latches a fault.
    pub const fn is_fault(self) -> bool {
        matches!(
            self,
            Reason::Overcurrent
                | Reason::Overrun
                | Reason::ModelError
                | Reason::ResonanceLost
                | Reason::SensorFault(_)
        )
    }

    /// Every reason, for tables and tests.
    pub fn all() -> impl Iterator<Item = Reason> {
        const SENSORS: [Sensor; 3] = [
            Sensor::NormalForce,
            Sensor::TangentialForce,
            Sensor::SlidingVelocity,
        ];
        const KINDS: [SensorFaultKind; 4] = [
            SensorFaultKind::Disconnected,
            SensorFaultKind::Stuck,
            SensorFaultKind::Jump,
            SensorFaultKind::OutOfRange,
        ];
        [
            Reason::PowerOn,
            Reason::StartCommand,
            Reason::StopCommand,
            Reason::ClearCommand,
            Reason::RampDone,
            Reason::NotSliding,
            Reason::NoLoad,
            Reason::SlidingResumed,
            Reason::Overcurrent,
            Reason::Overrun,
            Reason::ModelError,
            Reason::ResonanceLost,
        ]
        .into_iter()
        .chain(SENSORS.into_iter().flat_map(|sensor| {
            KINDS
                .into_iter()
                .map(move |kind| Reason::SensorFault(SensorFault { sensor, kind }))
        }))
    }
}

impl From<ExternalFault> for Reason {
    fn from(fault: ExternalFault) -> Self {
        match fault {
            ExternalFault::Overcurrent => Reason::Overcurrent,
            ExternalFault::Overrun => Reason::Overrun,
            ExternalFault::ResonanceLost => Reason::ResonanceLost,
        }
    }
}

impl From<SensorFault> for Reason {
    fn from(fault: SensorFault) -> Self {
        Reason::SensorFault(fault)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::protocol::is_word;

    #[test]
    fn codes_and_names_are_unique_stable_words() {
        let all: Vec<Reason> = Reason::all().collect();
        assert_eq!(all.len(), 24);
        for (i, a) in all.iter().enumerate() {
            assert!(is_word(a.name()) && a.name().len() <= 23, "{}", a.name());
            assert!(
                a.name()
                    .bytes()
                    .all(|b| b.is_ascii_lowercase() || b == b'-')
            );
            for b in &all[i + 1..] {
                assert_ne!(a.code(), b.code());
                assert_ne!(a.name(), b.name());
            }
        }
        // Pinned: these numbers are the protocol's, they must not move.
        let tangential_range = Reason::SensorFault(SensorFault {
            sensor: Sensor::TangentialForce,
            kind: SensorFaultKind::OutOfRange,
        });
        assert_eq!(
            (tangential_range.code(), tangential_range.name()),
            (47, "tangential-out-of-range")
        );
        assert_eq!(Reason::from(ExternalFault::Overrun).code(), 21);
        assert_eq!(Reason::RampDone.code(), 4);
        assert!(tangential_range.is_fault() && Reason::ModelError.is_fault());
        assert!(!Reason::NotSliding.is_fault());
    }
}
