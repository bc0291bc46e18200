//! From the raw file to a [`SceneDescription`]: choices resolved, units and ranges checked,
//! defaults filled in, the mismatch derived. Tables (profiles, target, faults, criteria and
//! contents) and the checks across sections are in [`crate::tables`].

use crate::error::{Errors, SceneError};
use crate::hardware;
use crate::raw::{RawModel, RawScene, RawSurface};
use crate::tables;
use crate::types::CONTROL_RATE_RANGE_HZ;
use crate::types::{Mismatch, ModelKind, ModelSpec, RoughSurface, SceneDescription, System};

/// Control rate when the file gives none, Hz (the 10 kHz loop).
pub const DEFAULT_CONTROL_RATE_HZ: f64 = 10_000.0;
/// Plant substeps when the file gives none.
pub const DEFAULT_PLANT_SUBSTEPS: u8 = 4;
/// Noise seed when the file gives none.
pub const DEFAULT_NOISE_SEED: u64 = 1;
/// Converter resolution when the file gives none, bits (the 12-bit ADC).
pub const DEFAULT_ADC_BITS: u8 = 12;
/// Drive frequency range of the firmware, Hz (the protocol's `freq` command range).
pub const DRIVE_RANGE_HZ: (f64, f64) = (20_000.0, 60_000.0);

/// The rank of a model in the project's fidelity order (the plant's must be higher).
pub fn fidelity(kind: ModelKind) -> u8 {
    match kind {
        ModelKind::Coulomb => 0,
        ModelKind::ExpCoulomb => 1,
        ModelKind::Dahl => 2,
        ModelKind::CubeElastic => 3,
        ModelKind::CubeElasticPlastic => 4,
    }
}

/// Whether a plant of kind `plant` is of strictly higher fidelity than a controller of kind
/// `controller` (issue 13): higher in the order of [`fidelity`], or both `dahl`, where the
/// plant integrates the Dahl law in time, transients included, while the controller evaluates
/// its periodic steady state (a strictly coarser description of the same contact). Equal cube
/// or Coulomb kinds are refused: there the plant evaluates the same average the controller does.
pub fn plant_outranks(plant: ModelKind, controller: ModelKind) -> bool {
    fidelity(plant) > fidelity(controller)
        || (plant == ModelKind::Dahl && controller == ModelKind::Dahl)
}

/// Whether `name` is a valid scene name: the rule of `sonolube::protocol::is_scene_name`.
pub fn is_scene_name(name: &str) -> bool {
    !name.is_empty()
        && name.len() <= 24
        && name != "list"
        && name != "none"
        && name
            .bytes()
            .all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'_' || b == b'-')
}

pub(crate) fn scene(raw: RawScene, errors: Errors<'_>) -> Result<SceneDescription, SceneError> {
    if !is_scene_name(&raw.name) {
        return Err(errors.at(
            "name",
            format!(
                "{:?} is not a scene name: 1 to 24 bytes of [a-z0-9_-], not list or none",
                raw.name
            ),
        ));
    }
    text(errors, "description", &raw.description, 200)?;
    text(errors, "materials", &raw.materials, 60)?;
    let system = errors.choose(
        "system",
        &raw.system,
        &[
            ("stack-on-rail", System::StackOnRail),
            ("poisson-horn", System::PoissonHorn),
            ("beam-on-table", System::BeamOnTable),
            ("seat-belt", System::SeatBelt),
        ],
    )?;
    let control_rate_hz = errors
        .within(
            "control_rate_hz",
            raw.control_rate_hz.unwrap_or(DEFAULT_CONTROL_RATE_HZ),
            CONTROL_RATE_RANGE_HZ.0,
            CONTROL_RATE_RANGE_HZ.1,
        )
        .map_err(|error| SceneError {
            reason: if raw
                .control_rate_hz
                .is_some_and(|r| r > CONTROL_RATE_RANGE_HZ.1)
            {
                format!(
                    "{}: a 60 s run must stay within 6e6 control steps",
                    error.reason
                )
            } else {
                format!(
                    "{}: below {} Hz the loop has not been shown to hold a scene's criteria \
                     (each period adds to the lag the model error is seen through)",
                    error.reason, CONTROL_RATE_RANGE_HZ.0
                )
            },
            ..error
        })?;
    let duration_s = errors.positive("duration_s", raw.duration_s, 60.0)?;
    let plant_substeps = match raw.plant_substeps {
        None => DEFAULT_PLANT_SUBSTEPS,
        Some(n) => u8::try_from(n)
            .ok()
            .filter(|n| (1..=16).contains(n))
            .ok_or_else(|| errors.at("plant_substeps", format!("{n} is outside 1 ..= 16")))?,
    };
    let noise_seed = match raw.noise_seed {
        None => DEFAULT_NOISE_SEED,
        Some(seed) => u64::try_from(seed)
            .map_err(|_| errors.at("noise_seed", format!("{seed} is negative")))?,
    };
    let controller = model(errors, "controller", &raw.controller)?;
    let plant = model(errors, "plant", &raw.plant)?;
    if !plant_outranks(plant.kind, controller.kind) {
        return Err(errors.at(
            "plant.model",
            "the plant's model must be of higher fidelity than the controller's \
             (order: coulomb < exp-coulomb < dahl < cube-elastic < cube-elastic-plastic; \
             dahl on both sides is allowed: the plant integrates the law in time)",
        ));
    }
    let model_mismatch = declared_mismatch(errors, &raw)?;
    let mismatch = Mismatch {
        mu_ratio: plant.mu / controller.mu,
        k_t_ratio: controller
            .k_t_n_per_m
            .zip(plant.k_t_n_per_m)
            .map(|(c, p)| p / c),
        rq_ratio: controller
            .surface
            .zip(plant.surface)
            .map(|(c, p)| p.rq_m / c.rq_m),
    };
    let transducer = hardware::transducer(errors, &raw.transducer, duration_s)?;
    let actuator = hardware::actuator(errors, &raw.actuator, &transducer)?;
    let horn = raw
        .horn
        .as_ref()
        .map(|h| hardware::horn(errors, h))
        .transpose()?;
    let is_cube = |kind| matches!(kind, ModelKind::CubeElastic | ModelKind::CubeElasticPlastic);
    if horn.is_none() && (is_cube(controller.kind) || is_cube(plant.kind)) {
        return Err(errors.at("horn", "missing: the cube models need the horn's geometry"));
    }
    let normal_cell = hardware::cell(errors, "sensors.normal", &raw.sensors.normal)?;
    let tangential_cell = hardware::cell(errors, "sensors.tangential", &raw.sensors.tangential)?;
    let description = SceneDescription {
        name: raw.name,
        description: raw.description,
        system,
        materials: raw.materials,
        control_rate_hz,
        duration_s,
        plant_substeps,
        noise_seed,
        controller,
        plant,
        mismatch,
        actuator,
        horn,
        transducer,
        normal_cell,
        tangential_cell,
        faults: Vec::new(),
        normal_load_n: Vec::new(),
        sliding_velocity_m_per_s: Vec::new(),
        target: Vec::new(),
        commission: raw.commission.unwrap_or(false),
        model_mismatch,
        accuracy: tables::accuracy(errors, &raw.accuracy)?,
        criteria: Vec::new(),
        contents: tables::contents(errors, &raw.contents)?,
    };
    tables::complete(
        errors,
        description,
        &raw.profiles,
        &raw.faults,
        &raw.criteria,
    )
}

/// `[controller] model_mismatch_pct` as a fraction: the share by which the user declares the
/// plant's friction reduction may differ from the controller model's, which the tuning designs
/// the loop for (`sonolube::control::controller_settings`). `None` without the key. Refused:
/// outside 0 <= m < 100 (at 100 % the model would predict nothing of the reduction: the tuning
/// divides by 1 - m), and in `[plant]`, whose parameters are the truth, not a belief.
fn declared_mismatch(errors: Errors<'_>, raw: &RawScene) -> Result<Option<f64>, SceneError> {
    if let Some(value) = raw.plant.model_mismatch_pct {
        return Err(errors.at(
            "plant.model_mismatch_pct",
            format!(
                "{value} given in [plant]: the mismatch is the user's declaration about the \
                 controller's model; write it in [controller]"
            ),
        ));
    }
    match raw.controller.model_mismatch_pct {
        None => Ok(None),
        Some(pct) if pct.is_finite() && (0.0..100.0).contains(&pct) => Ok(Some(pct / 100.0)),
        Some(pct) => Err(errors.at(
            "controller.model_mismatch_pct",
            format!(
                "{pct} is outside 0 <= m < 100: the tuning designs for a plant whose friction \
                 reduction is (1 - m) to (1 + m) times the model's, and at 100 % or more the \
                 model predicts none of it"
            ),
        )),
    }
}

fn text(errors: Errors<'_>, key: &str, value: &str, max: usize) -> Result<(), SceneError> {
    let printable = value.chars().all(|c| c == ' ' || c.is_ascii_graphic());
    if value.trim().is_empty() || value.len() > max || !printable {
        return Err(errors.at(
            key,
            format!("must be 1 to {max} bytes of printable ASCII on one line"),
        ));
    }
    Ok(())
}

fn model(errors: Errors<'_>, table: &str, raw: &RawModel) -> Result<ModelSpec, SceneError> {
    let key = |leaf: &str| format!("{table}.{leaf}");
    let kind = errors.choose(
        &key("model"),
        &raw.model,
        &[
            ("coulomb", ModelKind::Coulomb),
            ("exp-coulomb", ModelKind::ExpCoulomb),
            ("dahl", ModelKind::Dahl),
            ("cube-elastic", ModelKind::CubeElastic),
            ("cube-elastic-plastic", ModelKind::CubeElasticPlastic),
        ],
    )?;
    let mu = errors.positive(&key("mu"), raw.mu, 2.0)?;
    let exp = kind == ModelKind::ExpCoulomb;
    let dahl = kind == ModelKind::Dahl;
    let cube = matches!(kind, ModelKind::CubeElastic | ModelKind::CubeElasticPlastic);
    let mu_static = match raw.mu_static {
        Some(v) => Some(errors.within(&key("mu_static"), v, mu, 2.0)?),
        None if exp => return Err(errors.at(&key("mu_static"), "missing: exp-coulomb needs it")),
        None => None,
    };
    let decay_s_per_m = match raw.decay_s_per_m {
        Some(v) => Some(errors.within(&key("decay_s_per_m"), v, 0.0, 1e3)?),
        None if exp => {
            return Err(errors.at(&key("decay_s_per_m"), "missing: exp-coulomb needs it"));
        }
        None => None,
    };
    let k_t_n_per_m = match raw.k_t_n_per_m {
        Some(v) => Some(errors.positive(&key("k_t_n_per_m"), v, 1e13)?),
        None if dahl => return Err(errors.at(&key("k_t_n_per_m"), "missing: dahl needs it")),
        None => None,
    };
    let dahl_alpha = match raw.dahl_alpha {
        Some(_) if k_t_n_per_m.is_none() => {
            return Err(errors.at(&key("dahl_alpha"), "given without k_t_n_per_m"));
        }
        Some(v) => Some(errors.positive(&key("dahl_alpha"), v, 4.0)?),
        // Seed 003 takes alpha = 1 (ductile contact).
        None if dahl => Some(1.0),
        None => None,
    };
    let surface = match &raw.surface {
        Some(s) => Some(surface(errors, &key("surface"), s)?),
        None if cube => return Err(errors.at(&key("surface"), "missing: cube models need it")),
        None => None,
    };
    Ok(ModelSpec {
        kind,
        mu,
        mu_static,
        decay_s_per_m,
        k_t_n_per_m,
        dahl_alpha,
        surface,
    })
}

fn surface(errors: Errors<'_>, table: &str, raw: &RawSurface) -> Result<RoughSurface, SceneError> {
    let key = |leaf: &str| format!("{table}.{leaf}");
    let poisson = |leaf: &str, v: f64| {
        if v.is_finite() && v > -1.0 && v <= 0.5 {
            Ok(v)
        } else {
            Err(errors.at(&key(leaf), format!("{v} is outside -1 < nu <= 0.5")))
        }
    };
    Ok(RoughSurface {
        rq_m: errors.positive(&key("rq_m"), raw.rq_m, 1e-3)?,
        rs_m: errors.positive(&key("rs_m"), raw.rs_m, 1e-3)?,
        nominal_area_m2: errors.positive(&key("nominal_area_m2"), raw.nominal_area_m2, 1.0)?,
        asperity_density_per_m2: errors.positive(
            &key("asperity_density_per_m2"),
            raw.asperity_density_per_m2,
            1e15,
        )?,
        distribution_c: errors.positive(&key("distribution_c"), raw.distribution_c, 1e3)?,
        distribution_lambda: errors.positive(
            &key("distribution_lambda"),
            raw.distribution_lambda,
            1e2,
        )?,
        young_1_pa: errors.positive(&key("young_1_pa"), raw.young_1_pa, 1e13)?,
        poisson_1: poisson("poisson_1", raw.poisson_1)?,
        young_2_pa: errors.positive(&key("young_2_pa"), raw.young_2_pa, 1e13)?,
        poisson_2: poisson("poisson_2", raw.poisson_2)?,
        poisson_soft: poisson("poisson_soft", raw.poisson_soft)?,
        yield_strength_pa: errors.positive(
            &key("yield_strength_pa"),
            raw.yield_strength_pa,
            1e11,
        )?,
    })
}
