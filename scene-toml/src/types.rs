//! The plain-data description of a scene: owned strings and vectors, every number in SI `f64`.
//!
//! Each type mirrors, field by field and variant by variant, the `no_std` type of the same name
//! in `sonolube::scene` (which borrows `&'a str` and `&'a [T]` instead of owning them), so that
//! [`crate::generate_rust`] can write a description as a Rust literal of the firmware type and
//! the host can convert one into the other without loss. Units and ranges are those of
//! `scenes/README.md`; the loader has checked them.

/// Which system of the source papers a scene belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum System {
    /// Seed 003: PMN-PT stack transducer sliding on a guide rail, 40 kHz, 0-10 N.
    StackOnRail,
    /// Seeds 000/001: Poisson-effect horn (waveguide) on a sliding block, 20 kHz, 40-240 N.
    PoissonHorn,
    /// Seed 002: flexible beam on a moving table (stick-slip rig), exponential Coulomb law.
    BeamOnTable,
    /// Application: seat-belt webbing sliding over a vibrated D-ring (seed 003, "future work").
    SeatBelt,
}

/// A friction model, in the order of fidelity the project uses (lowest first).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModelKind {
    /// Littmann velocity-ratio law on a rigid Coulomb contact (seed 003 eqs 1-4).
    Coulomb,
    /// Exponential (Stribeck-like) Coulomb law under vibration (seed 002 eq 10).
    ExpCoulomb,
    /// Dahl compliant contact under vibration, steady state (seed 003 eqs 5-7).
    Dahl,
    /// Cube model on a purely elastic rough contact (seed 001 eqs 11-14).
    CubeElastic,
    /// Cube model on the elastic-plastic rough contact (seed 000 eqs 1-17).
    CubeElasticPlastic,
}

/// Rough-surface and material parameters of the cube model (seed 000 Table 2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RoughSurface {
    /// Standard deviation of asperity heights R_q, m.
    pub rq_m: f64,
    /// Asperity summit radius R_s, m.
    pub rs_m: f64,
    /// Nominal contact area A_n, m^2.
    pub nominal_area_m2: f64,
    /// Areal asperity density eta, 1/m^2.
    pub asperity_density_per_m2: f64,
    /// Height-distribution constant c (dimensionless).
    pub distribution_c: f64,
    /// Height-distribution constant lambda (dimensionless).
    pub distribution_lambda: f64,
    /// Young's modulus of body 1 (the horn), Pa.
    pub young_1_pa: f64,
    /// Poisson's ratio of body 1.
    pub poisson_1: f64,
    /// Young's modulus of body 2 (the block), Pa.
    pub young_2_pa: f64,
    /// Poisson's ratio of body 2.
    pub poisson_2: f64,
    /// Poisson's ratio of the softer material.
    pub poisson_soft: f64,
    /// Failure strength Y0 of the softer material, Pa.
    pub yield_strength_pa: f64,
}

/// A friction model and its own parameters (controller or plant).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModelSpec {
    /// Which model.
    pub kind: ModelKind,
    /// Kinetic (dynamic) friction coefficient mu.
    pub mu: f64,
    /// Static coefficient mu_s of the exponential law.
    pub mu_static: Option<f64>,
    /// Exponential decay coefficient alpha_dc, s/m.
    pub decay_s_per_m: Option<f64>,
    /// Tangential contact stiffness k_t, N/m.
    pub k_t_n_per_m: Option<f64>,
    /// Dahl shape exponent alpha.
    pub dahl_alpha: Option<f64>,
    /// Rough contact of the cube models.
    pub surface: Option<RoughSurface>,
}

/// Plant parameters over controller parameters (derived by the loader).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mismatch {
    /// mu_plant / mu_controller.
    pub mu_ratio: f64,
    /// k_t plant / k_t controller, when both give k_t.
    pub k_t_ratio: Option<f64>,
    /// R_q plant / R_q controller, when both give a surface.
    pub rq_ratio: Option<f64>,
}

/// Kind of vibration source.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ActuatorKind {
    /// Piezoelectric stack (seed 003 Table 1).
    PmnPtStack,
    /// Ultrasonic welding converter driving a horn (seeds 000/001: Dukane 220).
    WeldingConverter,
}

/// Stack data of seed 003 Table 1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stack {
    /// Number of discs n.
    pub discs: u16,
    /// Piezoelectric coefficient d33, m/V.
    pub d33_m_per_v: f64,
    /// Stack stiffness, N/m.
    pub stiffness_n_per_m: f64,
    /// Preload bolt stiffness, N/m.
    pub bolt_stiffness_n_per_m: f64,
}

/// The vibration source and its limits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Actuator {
    /// Kind of source.
    pub kind: ActuatorKind,
    /// Drive voltage amplitude at full command, V.
    pub full_scale_voltage_v: f64,
    /// Vibration displacement amplitude at full command on resonance, m.
    pub full_scale_amplitude_m: f64,
    /// Voltage rating, V.
    pub max_voltage_v: f64,
    /// Current rating, A.
    pub max_current_a: f64,
    /// Stack data, for stacks.
    pub stack: Option<Stack>,
}

/// Horn (waveguide) geometry and contact position (seeds 000/001).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Horn {
    /// Length L, m.
    pub length_m: f64,
    /// Width, m.
    pub width_m: f64,
    /// Thickness D, m.
    pub thickness_m: f64,
    /// Vertical (Poisson) amplitude B at full command, m.
    pub vertical_amplitude_m: f64,
    /// Contact position x from the vibration node, m.
    pub contact_position_m: f64,
}

/// Resonant transducer: envelope dynamics and Butterworth-Van Dyke electrical model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transducer {
    /// Resonance f0 at t = 0, Hz.
    pub resonance_hz: f64,
    /// Quality factor Q.
    pub quality_factor: f64,
    /// Drift of f0, Hz/s.
    pub drift_hz_per_s: f64,
    /// Drive frequency the scene starts with, Hz.
    pub drive_hz: f64,
    /// Clamped (parallel) capacitance C0, F.
    pub clamped_capacitance_f: f64,
    /// Motional resistance R1, ohm.
    pub motional_resistance_ohm: f64,
    /// Resonance shift and loop (`[transducer.shift]`).
    pub shift: ResonanceShift,
}

/// `[transducer.shift]`: see `sonolube::scene::ResonanceShift`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ResonanceShift {
    /// Relative f0 change per kelvin, 1/K.
    pub thermal_per_k: f64,
    /// Thermal resistance, K/W.
    pub thermal_resistance_k_per_w: f64,
    /// Thermal time constant, s.
    pub thermal_time_constant_s: f64,
    /// Relative f0 change per newton of normal load above the initial load, 1/N.
    pub load_per_n: f64,
    /// Complex (BVD) envelope and PWM-synchronous current samples.
    pub bvd_envelope: bool,
    /// `freq auto` before the start.
    pub freq_auto: bool,
}

/// A load cell and its converter channel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoadCell {
    /// Force at either end of the converter span (zero at mid-scale), N.
    pub full_scale_n: f64,
    /// First-order bandwidth, Hz.
    pub bandwidth_hz: f64,
    /// Actual offset from the nominal calibration, N.
    pub offset_n: f64,
    /// Actual relative gain error from the nominal calibration (0.01 = +1 %).
    pub gain_error: f64,
    /// Gaussian noise, RMS, % of full scale.
    pub noise_rms_pct_fs: f64,
    /// Converter resolution, bits.
    pub adc_bits: u8,
}

/// Which load cell.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Channel {
    /// The normal-load cell.
    Normal,
    /// The tangential (friction) cell.
    Tangential,
}

/// Which end of the converter range.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Rail {
    /// Code 0.
    Low,
    /// Code 2^bits - 1.
    High,
}

/// What goes wrong with a cell.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FaultKind {
    /// The cell is disconnected: the converter reads a rail.
    Disconnected {
        /// Which rail.
        rail: Rail,
    },
    /// The reading freezes at its value at the onset.
    Stuck,
    /// A force is added to the reading.
    Spike {
        /// Added force, N.
        force_n: f64,
    },
}

/// A fault injected at a given time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FaultEvent {
    /// Onset, s from the scene start.
    pub at_s: f64,
    /// Which cell.
    pub channel: Channel,
    /// What happens.
    pub kind: FaultKind,
    /// How long it lasts, s; `None`: to the end (a spike: one control period).
    pub duration_s: Option<f64>,
}

/// A breakpoint of a piecewise-linear profile.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Breakpoint {
    /// Time, s from the scene start.
    pub t_s: f64,
    /// Value in the profile's unit.
    pub value: f64,
}

/// A friction target in the protocol's scaled units (`sonolube::protocol::Target`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    /// Friction force, mN.
    Force {
        /// mN.
        force_mn: u32,
    },
    /// Friction coefficient, ppm.
    Coef {
        /// ppm.
        coef_ppm: u32,
    },
    /// Reduction of the natural friction, milli-percent.
    Reduction {
        /// milli-percent.
        reduction_mpct: u32,
    },
}

/// A point of the target table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TargetPoint {
    /// Time, s from the scene start.
    pub at_s: f64,
    /// The target from this time on.
    pub target: Target,
    /// `true`: reached by a linear ramp from the previous point; `false`: a step at `at_s`.
    pub ramp: bool,
}

/// What the scene needs in accuracy.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Accuracy {
    /// Closed-loop friction accuracy, % of target.
    pub friction_pct: f64,
    /// Error budget of the controller model's evaluation, % of natural friction.
    pub model_pct: f64,
}

/// What the scene contains.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Contents {
    /// Vibration along the sliding direction is present.
    pub tangential_vibration: bool,
    /// Vibration normal to the contact is present.
    pub normal_vibration: bool,
    /// Lowest normal load, N.
    pub load_min_n: f64,
    /// Highest normal load, N.
    pub load_max_n: f64,
    /// Lowest sliding velocity (signed), m/s.
    pub velocity_min_m_per_s: f64,
    /// Highest sliding velocity (signed), m/s.
    pub velocity_max_m_per_s: f64,
}

/// A pass criterion for the closed-loop runner.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Criterion {
    /// After each target step, the error enters and stays in +-`band_pct` % within `within_s`.
    Settle {
        /// Band, % of target.
        band_pct: f64,
        /// Time allowed, s.
        within_s: f64,
    },
    /// Overshoot past each target step, % of the step size.
    Overshoot {
        /// Limit, %.
        max_pct: f64,
    },
    /// RMS error over a window, % of target.
    SteadyRmsError {
        /// Limit, %.
        max_pct: f64,
        /// Window start, s.
        from_s: f64,
        /// Window end, s.
        to_s: f64,
    },
    /// Largest error over a window, % of target.
    TrackingError {
        /// Limit, %.
        max_pct: f64,
        /// Window start, s.
        from_s: f64,
        /// Window end, s.
        to_s: f64,
    },
    /// After each fault onset: supervisor in fault and drive at zero within this many periods.
    FaultReaction {
        /// Control periods.
        within_periods: u32,
    },
}

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
    /// Accuracy needs.
    pub accuracy: Accuracy,
    /// Pass criteria.
    pub criteria: Vec<Criterion>,
    /// What the scene contains.
    pub contents: Contents,
}
