//! A validated scene as the loader owns it: owned strings and vectors of the plain scene types
//! (`sonolube-scene-types`, defined once and shared with the firmware core's
//! `sonolube::scene::Scene`, which borrows `&'a str` and `&'a [T]` instead), so that
//! [`crate::generate_rust`] can write a description as a Rust literal of the firmware type and
//! the host can convert one into the other without loss. Units and ranges are those of
//! `scenes/README.md`; the loader has checked them.

pub use sonolube_scene_types::CONTROL_RATE_RANGE_HZ;
pub use sonolube_scene_types::{
    Accuracy, Actuator, ActuatorKind, Breakpoint, Channel, Contents, Criterion, FaultEvent,
    FaultKind, Horn, LoadCell, Mismatch, ModelKind, ModelSpec, Rail, ResonanceShift, RoughSurface,
    Stack, System, Target, TargetPoint, Transducer,
};

/// A validated scene.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneDescription {
    /// Name: `[a-z0-9_-]`, 1 to 24 bytes, not `list` or `none`.
    pub name: String,
    /// One or two sentences for a person.
    pub description: String,
    /// The system of the source papers.
    pub system: System,
    /// The materials in contact, in words.
    pub materials: String,
    /// Control (and plant step) rate, Hz.
    pub control_rate_hz: f64,
    /// Length of the run, s.
    pub duration_s: f64,
    /// Plant substeps per control step.
    pub plant_substeps: u8,
    /// Seed of the sensor-noise generator.
    pub noise_seed: u64,
    /// The controller's model.
    pub controller: ModelSpec,
    /// The plant's model (higher fidelity).
    pub plant: ModelSpec,
    /// Plant over controller parameters.
    pub mismatch: Mismatch,
    /// Vibration source.
    pub actuator: Actuator,
    /// Horn, for horn systems.
    pub horn: Option<Horn>,
    /// Resonant transducer.
    pub transducer: Transducer,
    /// Normal-load cell.
    pub normal_cell: LoadCell,
    /// Tangential (friction) cell.
    pub tangential_cell: LoadCell,
    /// Injected sensor faults, by onset.
    pub faults: Vec<FaultEvent>,
    /// Normal load profile, N.
    pub normal_load_n: Vec<Breakpoint>,
    /// Sliding velocity profile, m/s.
    pub sliding_velocity_m_per_s: Vec<Breakpoint>,
    /// Target table.
    pub target: Vec<TargetPoint>,
    /// The run uses commissioned f0, Q and mu0 (`commission = true`; default false).
    pub commission: bool,
    /// The declared model mismatch, fraction in [0, 1) (`[controller] model_mismatch_pct` /
    /// 100); `None` without the key (the tuning's default then).
    pub model_mismatch: Option<f64>,
    /// Accuracy needs.
    pub accuracy: Accuracy,
    /// Pass criteria.
    pub criteria: Vec<Criterion>,
    /// What the scene contains.
    pub contents: Contents,
}
