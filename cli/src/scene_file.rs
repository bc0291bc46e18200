//! Scene files loaded at run time into the firmware's `sonolube::scene::Scene`.
//!
//! `scene_toml` reads and validates a file (any file: the built-in `scenes/*.toml` or a
//! user's) into the firmware's plain scene types (`sonolube-scene-types`); [`LoadedScene`] owns
//! that data and lends it out as a [`Scene`], the same type (and, for a built-in file, the same
//! values) as `sonolube::scene::builtin::SCENES`.

use std::path::{Path, PathBuf};

use scene_toml as toml_scene;
use scene_toml::{SceneDescription, SceneError};
use sonolube::fx::{Q1_31, Q8_24, Q16_16};
use sonolube::model::AnyModel;
use sonolube::model::{FrictionModel, ModelError, OperatingPoint};
use sonolube::protocol::Target;
use sonolube::scene::{Scene, interpolate, target_at};

/// The directory of the built-in scene files (`scenes/` at the repository root).
pub fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join("scenes")
}

/// A scene loaded from a file: the validated description, whose plain types are the firmware's
/// own (`sonolube-scene-types`), lent out as a [`Scene`].
#[derive(Debug, Clone, PartialEq)]
pub struct LoadedScene {
    description: SceneDescription,
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
        Self { description }
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
            system: d.system,
            materials: &d.materials,
            control_rate_hz: d.control_rate_hz,
            duration_s: d.duration_s,
            plant_substeps: d.plant_substeps,
            noise_seed: d.noise_seed,
            controller: d.controller,
            plant: d.plant,
            mismatch: d.mismatch,
            actuator: d.actuator,
            horn: d.horn,
            transducer: d.transducer,
            normal_cell: d.normal_cell,
            tangential_cell: d.tangential_cell,
            faults: &d.faults,
            normal_load_n: &d.normal_load_n,
            sliding_velocity_m_per_s: &d.sliding_velocity_m_per_s,
            target: &d.target,
            accuracy: d.accuracy,
            criteria: &d.criteria,
            contents: d.contents,
            commission: d.commission,
            model_mismatch: d.model_mismatch,
        }
    }
}

/// The friction ratio F'/F that the scene's target asks of its plant at `t_s`: 1 - reduction,
/// or the target coefficient or force over the plant's natural friction there. `None` before
/// the first target point or without load, and for a net-force target (issue 27), which is
/// no friction ratio (the motor hold reports its own reach while running).
pub fn target_ratio(scene: &Scene<'_>, t_s: f32) -> Option<f64> {
    let load = f64::from(interpolate(scene.normal_load_n, t_s));
    let speed = f64::from(interpolate(scene.sliding_velocity_m_per_s, t_s)).abs();
    let natural = scene.plant.natural_coefficient(speed) * load;
    let ratio = match target_at(scene.target, t_s)? {
        Target::Reduction { reduction_mpct } => 1.0 - f64::from(reduction_mpct) * 1e-5,
        Target::Coef { coef_ppm } => f64::from(coef_ppm) * 1e-6 * load / natural,
        Target::Force { force_mn } => f64::from(force_mn) * 1e-3 / natural,
        Target::NetForce { .. } => return None,
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
