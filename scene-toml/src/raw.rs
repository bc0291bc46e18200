//! The file as serde reads it: every table and key of `scenes/README.md`, unknown keys
//! rejected. Names of choices stay strings here so that the validator can report a bad value
//! with its key and the allowed words; units and ranges are checked by the validator too.

use serde::Deserialize;

/// The whole file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawScene {
    pub name: String,
    pub description: String,
    pub system: String,
    pub materials: String,
    pub control_rate_hz: Option<f64>,
    pub duration_s: f64,
    pub plant_substeps: Option<i64>,
    pub noise_seed: Option<i64>,
    pub commission: Option<bool>,
    pub controller: RawModel,
    pub plant: RawModel,
    pub actuator: RawActuator,
    pub horn: Option<RawHorn>,
    pub transducer: RawTransducer,
    pub sensors: RawSensors,
    #[serde(default)]
    pub faults: Vec<RawFault>,
    pub profiles: RawProfiles,
    pub accuracy: RawAccuracy,
    pub contents: RawContents,
    pub criteria: Vec<RawCriterion>,
}

/// `[controller]` and `[plant]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawModel {
    pub model: String,
    pub mu: f64,
    pub mu_static: Option<f64>,
    pub decay_s_per_m: Option<f64>,
    pub k_t_n_per_m: Option<f64>,
    pub dahl_alpha: Option<f64>,
    pub surface: Option<RawSurface>,
    /// `[controller]` only: the mismatch the user declares, %.
    pub model_mismatch_pct: Option<f64>,
}

/// `[controller.surface]` and `[plant.surface]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawSurface {
    pub rq_m: f64,
    pub rs_m: f64,
    pub nominal_area_m2: f64,
    pub asperity_density_per_m2: f64,
    pub distribution_c: f64,
    pub distribution_lambda: f64,
    pub young_1_pa: f64,
    pub poisson_1: f64,
    pub young_2_pa: f64,
    pub poisson_2: f64,
    pub poisson_soft: f64,
    pub yield_strength_pa: f64,
}

/// `[actuator]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawActuator {
    pub kind: String,
    pub full_scale_voltage_v: f64,
    pub full_scale_amplitude_m: f64,
    pub max_voltage_v: f64,
    pub max_current_a: f64,
    pub stack: Option<RawStack>,
}

/// `[actuator.stack]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawStack {
    pub discs: i64,
    pub d33_m_per_v: f64,
    pub stiffness_n_per_m: f64,
    pub bolt_stiffness_n_per_m: f64,
}

/// `[horn]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawHorn {
    pub length_m: f64,
    pub width_m: f64,
    pub thickness_m: f64,
    pub vertical_amplitude_m: f64,
    pub contact_position_m: f64,
    pub motor_regions: Option<bool>,
}

/// `[transducer]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawTransducer {
    pub resonance_hz: f64,
    pub quality_factor: f64,
    pub drift_hz_per_s: Option<f64>,
    pub drive_hz: Option<f64>,
    pub clamped_capacitance_f: f64,
    pub motional_resistance_ohm: f64,
    pub shift: Option<RawShift>,
}

/// `[transducer.shift]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawShift {
    pub thermal_per_k: Option<f64>,
    pub thermal_resistance_k_per_w: Option<f64>,
    pub thermal_time_constant_s: Option<f64>,
    pub load_per_n: Option<f64>,
    pub bvd_envelope: Option<bool>,
    pub freq_auto: Option<bool>,
}

/// `[sensors]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawSensors {
    pub normal: RawCell,
    pub tangential: RawCell,
}

/// `[sensors.normal]` and `[sensors.tangential]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawCell {
    pub full_scale_n: f64,
    pub bandwidth_hz: f64,
    pub offset_n: Option<f64>,
    pub gain_error: Option<f64>,
    pub noise_rms_pct_fs: f64,
    pub adc_bits: Option<i64>,
}

/// `[[faults]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawFault {
    pub at_s: f64,
    pub channel: String,
    pub kind: String,
    pub rail: Option<String>,
    pub force_n: Option<f64>,
    pub duration_s: Option<f64>,
}

/// `[profiles]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawProfiles {
    pub normal_load_n: Vec<Vec<f64>>,
    pub sliding_velocity_m_per_s: Vec<Vec<f64>>,
    pub target: Vec<RawTargetPoint>,
}

/// `[[profiles.target]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawTargetPoint {
    pub at_s: f64,
    pub force_n: Option<f64>,
    pub coef: Option<f64>,
    pub reduction_pct: Option<f64>,
    pub net_force_n: Option<f64>,
    pub ramp: Option<bool>,
}

/// `[accuracy]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawAccuracy {
    pub friction_pct: f64,
    pub model_pct: f64,
}

/// `[contents]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawContents {
    pub vibration: Vec<String>,
    pub load_range_n: Vec<f64>,
    pub velocity_range_m_per_s: Vec<f64>,
}

/// `[[criteria]]`: the keys of every kind; the validator checks which a kind takes.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawCriterion {
    pub kind: String,
    pub band_pct: Option<f64>,
    pub within_s: Option<f64>,
    pub max_pct: Option<f64>,
    pub from_s: Option<f64>,
    pub to_s: Option<f64>,
    pub within_periods: Option<i64>,
}
