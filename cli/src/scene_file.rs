//! Scene files loaded at run time into the firmware's `sonolube::scene::Scene`.
//!
//! `scene_toml` reads and validates a file (any file: the built-in `scenes/*.toml` or a
//! user's) into plain data; [`LoadedScene`] owns that data together with the tables in the
//! firmware's types and lends it out as a [`Scene`], the same type (and, for a built-in file,
//! the same values) as `sonolube::scene::builtin::SCENES`.

use std::path::{Path, PathBuf};

use scene_toml as toml_scene;
use scene_toml::{SceneDescription, SceneError};
use sonolube::fx::{Q1_31, Q8_24, Q16_16};
use sonolube::model::AnyModel;
use sonolube::model::{FrictionModel, ModelError, OperatingPoint};
use sonolube::protocol::Target;
use sonolube::scene::{
    Accuracy, Actuator, ActuatorKind, Breakpoint, Channel, Contents, Criterion, FaultEvent,
    FaultKind, Horn, LoadCell, Mismatch, ModelKind, ModelSpec, Rail, RoughSurface, Scene, Stack,
    System, TargetPoint, Transducer, interpolate, target_at,
};

/// The directory of the built-in scene files (`scenes/` at the repository root).
pub fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join("scenes")
}

/// A scene loaded from a file: the validated description and its tables in firmware types.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadedScene {
    description: SceneDescription,
    faults: Vec<FaultEvent>,
    normal_load_n: Vec<Breakpoint>,
    sliding_velocity_m_per_s: Vec<Breakpoint>,
    target: Vec<TargetPoint>,
    criteria: Vec<Criterion>,
}

impl LoadedScene {
    /// Reads and validates the scene file at `path`.
    pub fn load(path: &Path) -> Result<Self, SceneError> {
        toml_scene::load(path).map(Self::from_description)
    }

    /// Every scene file of `dir`, in file-name order (as the build script compiles them in).
    pub fn load_dir(dir: &Path) -> Result<Vec<Self>, SceneError> {
        Ok(toml_scene::load_dir(dir)?
            .into_iter()
            .map(Self::from_description)
            .collect())
    }

    /// The scene of a validated description.
    pub fn from_description(description: SceneDescription) -> Self {
        let breakpoints = |points: &[toml_scene::Breakpoint]| {
            points
                .iter()
                .map(|p| Breakpoint {
                    t_s: p.t_s,
                    value: p.value,
                })
                .collect()
        };
        Self {
            faults: description.faults.iter().map(fault).collect(),
            normal_load_n: breakpoints(&description.normal_load_n),
            sliding_velocity_m_per_s: breakpoints(&description.sliding_velocity_m_per_s),
            target: description.target.iter().map(target_point).collect(),
            criteria: description.criteria.iter().map(criterion).collect(),
            description,
        }
    }

    /// The validated description as read from the file.
    pub fn description(&self) -> &SceneDescription {
        &self.description
    }

    /// The scene, borrowing this value's strings and tables.
    pub fn scene(&self) -> Scene<'_> {
        let d = &self.description;
        Scene {
            name: &d.name,
            description: &d.description,
            system: match d.system {
                toml_scene::System::StackOnRail => System::StackOnRail,
                toml_scene::System::PoissonHorn => System::PoissonHorn,
                toml_scene::System::BeamOnTable => System::BeamOnTable,
                toml_scene::System::SeatBelt => System::SeatBelt,
            },
            materials: &d.materials,
            control_rate_hz: d.control_rate_hz,
            duration_s: d.duration_s,
            plant_substeps: d.plant_substeps,
            noise_seed: d.noise_seed,
            controller: model(&d.controller),
            plant: model(&d.plant),
            mismatch: Mismatch {
                mu_ratio: d.mismatch.mu_ratio,
                k_t_ratio: d.mismatch.k_t_ratio,
                rq_ratio: d.mismatch.rq_ratio,
            },
            actuator: actuator(&d.actuator),
            horn: d.horn.as_ref().map(horn),
            transducer: transducer(&d.transducer),
            normal_cell: cell(&d.normal_cell),
            tangential_cell: cell(&d.tangential_cell),
            faults: &self.faults,
            normal_load_n: &self.normal_load_n,
            sliding_velocity_m_per_s: &self.sliding_velocity_m_per_s,
            target: &self.target,
            accuracy: Accuracy {
                friction_pct: d.accuracy.friction_pct,
                model_pct: d.accuracy.model_pct,
            },
            criteria: &self.criteria,
            contents: Contents {
                tangential_vibration: d.contents.tangential_vibration,
                normal_vibration: d.contents.normal_vibration,
                load_min_n: d.contents.load_min_n,
                load_max_n: d.contents.load_max_n,
                velocity_min_m_per_s: d.contents.velocity_min_m_per_s,
                velocity_max_m_per_s: d.contents.velocity_max_m_per_s,
            },
        }
    }
}

/// The friction ratio F'/F that the scene's target asks of its plant at `t_s`: 1 - reduction,
/// or the target coefficient or force over the plant's natural friction there. `None` before
/// the first target point or without load.
pub fn target_ratio(scene: &Scene<'_>, t_s: f32) -> Option<f64> {
    let load = f64::from(interpolate(scene.normal_load_n, t_s));
    let speed = f64::from(interpolate(scene.sliding_velocity_m_per_s, t_s)).abs();
    let natural = scene.plant.natural_coefficient(speed) * load;
    let ratio = match target_at(scene.target, t_s)? {
        Target::Reduction { reduction_mpct } => 1.0 - f64::from(reduction_mpct) * 1e-5,
        Target::Coef { coef_ppm } => f64::from(coef_ppm) * 1e-6 * load / natural,
        Target::Force { force_mn } => f64::from(force_mn) * 1e-3 / natural,
    };
    (load > 0.0).then_some(ratio)
}

/// An instant at which the plant cannot reach the scene's target.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OutOfReach {
    /// Time, s.
    pub t_s: f32,
    /// F'/F the target asks for.
    pub needed: f64,
    /// The lowest F'/F the plant reaches with the allowed amplitude.
    pub reached: f64,
}

/// The instants, every `every_s` along the scene, where its plant model cannot bring the
/// friction down to the target with `amplitude` (fraction of full command, (0, 1]) times the
/// transducer's gain at the drive frequency then (the resonance may have drifted; a `freq
/// auto` scene drives on the resonance). Instants
/// where the sliding speed is below 2 % of the scene's largest (a reversal: the ratio is not
/// defined there) are skipped. Errors: the plant model cannot be built or evaluated.
pub fn out_of_reach(
    scene: &Scene<'_>,
    amplitude: f64,
    every_s: f64,
) -> Result<Vec<OutOfReach>, ModelError> {
    let model = AnyModel::new(scene, &scene.plant)?;
    let top_speed = scene
        .contents
        .velocity_min_m_per_s
        .abs()
        .max(scene.contents.velocity_max_m_per_s.abs());
    let mut misses = Vec::new();
    let instants = (scene.duration_s / every_s).ceil() as u32;
    for k in 0..=instants {
        let t_s = (f64::from(k) * every_s).min(scene.duration_s) as f32;
        let speed = interpolate(scene.sliding_velocity_m_per_s, t_s).abs();
        let Some(needed) = target_ratio(scene, t_s) else {
            continue;
        };
        if f64::from(speed) < 0.02 * top_speed {
            continue;
        }
        let transducer = &scene.transducer;
        let f0 = transducer.resonance_hz + transducer.drift_hz_per_s * f64::from(t_s);
        // A `freq auto` scene keeps the drive on the resonance (it is judged after the lock);
        // otherwise the drive stays at the scene's frequency. (The self-heating and load shifts
        // of `[transducer.shift]` are not modelled here: only the linear drift.)
        let drive_hz = if transducer.shift.freq_auto {
            f0
        } else {
            transducer.drive_hz
        };
        let detuning = 2.0 * transducer.quality_factor * (drive_hz - f0) / f0;
        let gain = 1.0 / (1.0 + detuning * detuning).sqrt();
        let point = OperatingPoint {
            normal_force: Q16_16::from_f32_saturating(interpolate(scene.normal_load_n, t_s)).value,
            sliding_velocity: Q8_24::from_f32_saturating(speed).value,
        };
        let reached = model
            .ratio(&point, Q1_31::from_f64_saturating(amplitude * gain).value)?
            .to_f64();
        if reached > needed {
            misses.push(OutOfReach {
                t_s,
                needed,
                reached,
            });
        }
    }
    Ok(misses)
}

fn model(m: &toml_scene::ModelSpec) -> ModelSpec {
    ModelSpec {
        kind: match m.kind {
            toml_scene::ModelKind::Coulomb => ModelKind::Coulomb,
            toml_scene::ModelKind::ExpCoulomb => ModelKind::ExpCoulomb,
            toml_scene::ModelKind::Dahl => ModelKind::Dahl,
            toml_scene::ModelKind::CubeElastic => ModelKind::CubeElastic,
            toml_scene::ModelKind::CubeElasticPlastic => ModelKind::CubeElasticPlastic,
        },
        mu: m.mu,
        mu_static: m.mu_static,
        decay_s_per_m: m.decay_s_per_m,
        k_t_n_per_m: m.k_t_n_per_m,
        dahl_alpha: m.dahl_alpha,
        surface: m.surface.as_ref().map(|s| RoughSurface {
            rq_m: s.rq_m,
            rs_m: s.rs_m,
            nominal_area_m2: s.nominal_area_m2,
            asperity_density_per_m2: s.asperity_density_per_m2,
            distribution_c: s.distribution_c,
            distribution_lambda: s.distribution_lambda,
            young_1_pa: s.young_1_pa,
            poisson_1: s.poisson_1,
            young_2_pa: s.young_2_pa,
            poisson_2: s.poisson_2,
            poisson_soft: s.poisson_soft,
            yield_strength_pa: s.yield_strength_pa,
        }),
    }
}

fn actuator(a: &toml_scene::Actuator) -> Actuator {
    Actuator {
        kind: match a.kind {
            toml_scene::ActuatorKind::PmnPtStack => ActuatorKind::PmnPtStack,
            toml_scene::ActuatorKind::WeldingConverter => ActuatorKind::WeldingConverter,
        },
        full_scale_voltage_v: a.full_scale_voltage_v,
        full_scale_amplitude_m: a.full_scale_amplitude_m,
        max_voltage_v: a.max_voltage_v,
        max_current_a: a.max_current_a,
        stack: a.stack.as_ref().map(|s| Stack {
            discs: s.discs,
            d33_m_per_v: s.d33_m_per_v,
            stiffness_n_per_m: s.stiffness_n_per_m,
            bolt_stiffness_n_per_m: s.bolt_stiffness_n_per_m,
        }),
    }
}

fn horn(h: &toml_scene::Horn) -> Horn {
    Horn {
        length_m: h.length_m,
        width_m: h.width_m,
        thickness_m: h.thickness_m,
        vertical_amplitude_m: h.vertical_amplitude_m,
        contact_position_m: h.contact_position_m,
    }
}

fn transducer(t: &toml_scene::Transducer) -> Transducer {
    Transducer {
        resonance_hz: t.resonance_hz,
        quality_factor: t.quality_factor,
        drift_hz_per_s: t.drift_hz_per_s,
        drive_hz: t.drive_hz,
        clamped_capacitance_f: t.clamped_capacitance_f,
        motional_resistance_ohm: t.motional_resistance_ohm,
        shift: sonolube::scene::ResonanceShift {
            thermal_per_k: t.shift.thermal_per_k,
            thermal_resistance_k_per_w: t.shift.thermal_resistance_k_per_w,
            thermal_time_constant_s: t.shift.thermal_time_constant_s,
            load_per_n: t.shift.load_per_n,
            bvd_envelope: t.shift.bvd_envelope,
            freq_auto: t.shift.freq_auto,
        },
    }
}

fn cell(c: &toml_scene::LoadCell) -> LoadCell {
    LoadCell {
        full_scale_n: c.full_scale_n,
        bandwidth_hz: c.bandwidth_hz,
        offset_n: c.offset_n,
        gain_error: c.gain_error,
        noise_rms_pct_fs: c.noise_rms_pct_fs,
        adc_bits: c.adc_bits,
    }
}

fn fault(f: &toml_scene::FaultEvent) -> FaultEvent {
    FaultEvent {
        at_s: f.at_s,
        channel: match f.channel {
            toml_scene::Channel::Normal => Channel::Normal,
            toml_scene::Channel::Tangential => Channel::Tangential,
        },
        kind: match f.kind {
            toml_scene::FaultKind::Disconnected { rail } => FaultKind::Disconnected {
                rail: match rail {
                    toml_scene::Rail::Low => Rail::Low,
                    toml_scene::Rail::High => Rail::High,
                },
            },
            toml_scene::FaultKind::Stuck => FaultKind::Stuck,
            toml_scene::FaultKind::Spike { force_n } => FaultKind::Spike { force_n },
        },
        duration_s: f.duration_s,
    }
}

fn target_point(p: &toml_scene::TargetPoint) -> TargetPoint {
    TargetPoint {
        at_s: p.at_s,
        target: match p.target {
            toml_scene::Target::Force { force_mn } => Target::Force { force_mn },
            toml_scene::Target::Coef { coef_ppm } => Target::Coef { coef_ppm },
            toml_scene::Target::Reduction { reduction_mpct } => {
                Target::Reduction { reduction_mpct }
            }
        },
        ramp: p.ramp,
    }
}

fn criterion(c: &toml_scene::Criterion) -> Criterion {
    match *c {
        toml_scene::Criterion::Settle { band_pct, within_s } => {
            Criterion::Settle { band_pct, within_s }
        }
        toml_scene::Criterion::Overshoot { max_pct } => Criterion::Overshoot { max_pct },
        toml_scene::Criterion::SteadyRmsError {
            max_pct,
            from_s,
            to_s,
        } => Criterion::SteadyRmsError {
            max_pct,
            from_s,
            to_s,
        },
        toml_scene::Criterion::TrackingError {
            max_pct,
            from_s,
            to_s,
        } => Criterion::TrackingError {
            max_pct,
            from_s,
            to_s,
        },
        toml_scene::Criterion::FaultReaction { within_periods } => {
            Criterion::FaultReaction { within_periods }
        }
    }
}
