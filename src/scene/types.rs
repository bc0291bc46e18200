//! The [`Scene`] type and which model families this build holds; a file of its own so that
//! the build script can compile it too (it builds the scenes' cube tables, `build.rs`).

use sonolube_scene_types::{
    Accuracy, Actuator, Breakpoint, Contents, Criterion, FaultEvent, Horn, LoadCell, Mismatch,
    ModelKind, ModelSpec, System, TargetPoint, Transducer,
};

/// Whether this build holds the model family of `kind`: Coulomb always; the others with the
/// core's cargo features `exp-coulomb`, `dahl` and `cube` (all on by default). The build script
/// compiles in only the scenes whose controller model is in the build (and no horn scene
/// without the cube family).
pub const fn in_build(kind: ModelKind) -> bool {
    match kind {
        ModelKind::Coulomb => true,
        ModelKind::ExpCoulomb => cfg!(feature = "exp-coulomb"),
        ModelKind::Dahl => cfg!(feature = "dahl"),
        ModelKind::CubeElastic | ModelKind::CubeElasticPlastic => cfg!(feature = "cube"),
    }
}

/// A named operating scenario. Field units are in the names (`_hz`, `_s`, `_n`, `_m_per_s`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scene<'a> {
    /// Name, the `scene <name>` of the protocol: 1 to 24 bytes of `[a-z0-9_-]`, unique.
    pub name: &'a str,
    /// One or two sentences for a person, printable ASCII, at most 200 bytes.
    pub description: &'a str,
    /// The system of the source papers.
    pub system: System,
    /// The materials in contact, in words (`"Al horn / SS block"`), at most 60 bytes.
    pub materials: &'a str,
    /// Control-loop rate, which is also the plant's step rate, Hz, within
    /// [`CONTROL_RATE_RANGE_HZ`](crate::scene::CONTROL_RATE_RANGE_HZ) (6e3 ..= 1e5; default 1e4).
    pub control_rate_hz: f64,
    /// Length of the run, s, (0, 60].
    pub duration_s: f64,
    /// Plant substeps per control step, 1 ..= 16 (default 4).
    pub plant_substeps: u8,
    /// Seed of the plant's sensor-noise generator (any value; default 1).
    pub noise_seed: u64,
    /// The model the controller uses.
    pub controller: ModelSpec,
    /// The model the plant uses: of higher fidelity than the controller's, own parameters.
    pub plant: ModelSpec,
    /// Plant over controller parameters, derived from the two specs.
    pub mismatch: Mismatch,
    /// Vibration source.
    pub actuator: Actuator,
    /// Horn geometry and contact position, for horn systems (required by the cube models).
    pub horn: Option<Horn>,
    /// Resonant transducer: envelope dynamics and electrical model.
    pub transducer: Transducer,
    /// The normal-load cell.
    pub normal_cell: LoadCell,
    /// The tangential (friction) cell.
    pub tangential_cell: LoadCell,
    /// Sensor faults to inject, in order of onset.
    pub faults: &'a [FaultEvent],
    /// Normal load over time, N, piecewise linear, values in [0, normal full scale).
    pub normal_load_n: &'a [Breakpoint],
    /// Sliding velocity over time, m/s (signed), piecewise linear, |v| < 10.
    pub sliding_velocity_m_per_s: &'a [Breakpoint],
    /// Target over time: steps and ramps of protocol targets.
    pub target: &'a [TargetPoint],
    /// Accuracy the scene needs.
    pub accuracy: Accuracy,
    /// Pass criteria for the closed-loop runner (at least one).
    pub criteria: &'a [Criterion],
    /// What the scene contains, for choosing the cheapest adequate model variant.
    pub contents: Contents,
    /// The run uses commissioned values (`commission = true`): before it, the firmware's
    /// `commission` (`crate::commission`) measures f0, Q and mu0 on the simulated rig, and the
    /// controller runs on them instead of the declared `transducer` and `controller` values.
    pub commission: bool,
    /// The model mismatch the user declares (`[controller] model_mismatch_pct` / 100), a
    /// fraction in [0, 1): the plant's friction reduction may differ from the controller
    /// model's by this share. The tuning ([`crate::control::controller_settings`]) designs the
    /// loop for it; `None` (no key) takes [`crate::control::DECLARED_MODEL_MISMATCH`].
    pub model_mismatch: Option<f64>,
}

impl Scene<'_> {
    /// Control period, s (1 / `control_rate_hz`).
    pub fn control_period_s(&self) -> f64 {
        1.0 / self.control_rate_hz
    }

    /// Number of control steps in the run: `duration_s * control_rate_hz`, rounded up.
    pub fn step_count(&self) -> u32 {
        let steps = libm::ceil(self.duration_s * self.control_rate_hz - 1e-9);
        // duration <= 60 s and rate <= 1e5 Hz bound this by 6e6.
        steps as u32
    }

    /// Vibration velocity amplitude at full command on resonance, m/s: 2 pi f0 x_a (seed 003
    /// eq 2), at the scene's starting drive frequency.
    pub fn full_scale_vibration_velocity_m_per_s(&self) -> f64 {
        core::f64::consts::TAU * self.transducer.drive_hz * self.actuator.full_scale_amplitude_m
    }
}
