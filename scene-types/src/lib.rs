//! The plain data of a Sonolube scene, defined once: the friction models and their parameters,
//! the hardware (actuator, horn, transducer, load cells), the sensor faults, the time tables,
//! the friction target, the accuracy, criteria and contents.
//!
//! `no_std`, every number in SI `f64` with its unit in the field name. Two crates build scenes
//! from them: the firmware core (`sonolube::scene::Scene`, borrowing its strings and tables, in
//! flash) and the scene-file loader (`scene-toml`, owning them, on the host and in the core's
//! build script, which writes the files as statics of the core's type). The ranges in the field
//! docs are those of `scenes/README.md`, checked by the loader.

#![no_std]

mod criteria;
mod fault;
mod hardware;
mod spec;
mod table;
mod target;

pub use criteria::{Accuracy, Contents, Criterion};
pub use fault::{Channel, FaultEvent, FaultKind, Rail};
pub use hardware::{Actuator, ActuatorKind, Horn, LoadCell, ResonanceShift, Stack, Transducer};
pub use spec::{Mismatch, ModelKind, ModelSpec, RoughSurface};
pub use table::{Breakpoint, TargetPoint};
pub use target::Target;

/// The control rates a scene may ask for, Hz, inclusive: the one source of the scene schema's
/// range (`scene-toml`) and of what the controller accepts (`sonolube::control`, whose tuning
/// is tested at both ends). The controller's gains are valid at any rate (its tuning rule keeps
/// the fast integral's `ki T <= 1 - m - kp`, `sonolube::control::sampled_ki_cap_per_s`); the
/// low end is where the loop has been measured to hold the reference rig's criteria: each
/// period adds to the lag the model error is seen through and mu0 is learned from fewer
/// samples, so the reference step settles later and holds more noise as the rate falls
/// (measured with the reference file at lower rates, `sonolube scene NAME --file`: 2.4 ms at
/// 5 kHz, 3.0 ms at 3 kHz, 4.0 ms against its 3 ms at 2 kHz; at 1 kHz the feasibility check
/// refuses it for the cells' noise). 6 kHz keeps a margin below which no scene has been run.
/// The high end keeps a 60 s run within 6e6 control steps.
pub const CONTROL_RATE_RANGE_HZ: (f64, f64) = (6_000.0, 100_000.0);

/// Which system of the source papers a scene belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum System {
    /// Seed 003: PMN-PT stack transducer sliding on an aluminium guide rail, 40 kHz, 0-10 N
    /// added load.
    StackOnRail,
    /// Seeds 000/001: Poisson-effect horn (waveguide) over a sliding block, 20 kHz, 40-240 N.
    PoissonHorn,
    /// Seed 002: flexible beam on a moving table (stick-slip rig), exponential Coulomb law,
    /// with an ultrasonic actuator added at the beam tip.
    BeamOnTable,
    /// Application: seat-belt webbing sliding over a vibrated D-ring (seed 003 names seat-belt
    /// systems as its future work).
    SeatBelt,
}
