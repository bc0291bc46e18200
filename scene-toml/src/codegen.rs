//! Writes scene descriptions as Rust source: one `static` slice of `sonolube::scene::Scene`
//! literals, for the firmware crate's build script.
//!
//! The generated file names the scene types unqualified (`Scene`, `ModelSpec`, `Target`, ...);
//! the module that includes it brings them into scope. Numbers are written with Rust's
//! shortest round-trip formatting, so the compiled-in values are bit-identical to the values
//! the host loader returns.

use std::fmt::Write;

use crate::types::{
    Accuracy, Actuator, Breakpoint, Channel, Contents, Criterion, FaultEvent, FaultKind, Horn,
    LoadCell, Mismatch, ModelSpec, Rail, RoughSurface, SceneDescription, Stack, Target,
    TargetPoint, Transducer,
};

/// Rust source defining `pub static SCENES: &[Scene<'static>]` with `scenes` in order, and
/// `pub const SCENE_NAMES: [&str; N]`, their names in the same order (a constant, so that a
/// board lists every compiled scene and the protocol sizes its `scene list` reply for them).
pub fn generate_rust(scenes: &[SceneDescription]) -> String {
    let mut out = String::from(
        "// Generated from scenes/*.toml by the sonolube build script (scene-toml): do not edit.\n\
         /// Every scene of `scenes/*.toml`, in file-name order.\n\
         pub static SCENES: &[Scene<'static>] = &[\n",
    );
    for scene in scenes {
        out.push_str("    ");
        out.push_str(&scene_literal(scene));
        out.push_str(",\n");
    }
    out.push_str("];\n");
    out.push_str(
        "/// The name of every scene of [`SCENES`], in the same order (`scene list`).\n\
         pub const SCENE_NAMES: [&str; ",
    );
    out.push_str(&scenes.len().to_string());
    out.push_str("] = [");
    for scene in scenes {
        out.push_str(&format!("{:?}, ", scene.name));
    }
    out.push_str("];\n");
    out
}

fn scene_literal(s: &SceneDescription) -> String {
    let mut out = String::from("Scene {");
    let mut field = |name: &str, value: String| {
        let _ = write!(out, " {name}: {value},");
    };
    field("name", format!("{:?}", s.name));
    field("description", format!("{:?}", s.description));
    field("system", format!("System::{:?}", s.system));
    field("materials", format!("{:?}", s.materials));
    field("control_rate_hz", num(s.control_rate_hz));
    field("duration_s", num(s.duration_s));
    field("plant_substeps", s.plant_substeps.to_string());
    field("noise_seed", s.noise_seed.to_string());
    field("controller", model(&s.controller));
    field("plant", model(&s.plant));
    field("mismatch", mismatch(&s.mismatch));
    field("actuator", actuator(&s.actuator));
    field("horn", option(s.horn.as_ref(), horn));
    field("transducer", transducer(&s.transducer));
    field("normal_cell", cell(&s.normal_cell));
    field("tangential_cell", cell(&s.tangential_cell));
    field("faults", slice(&s.faults, fault));
    field("normal_load_n", slice(&s.normal_load_n, breakpoint));
    field(
        "sliding_velocity_m_per_s",
        slice(&s.sliding_velocity_m_per_s, breakpoint),
    );
    field("target", slice(&s.target, target_point));
    field("accuracy", accuracy(&s.accuracy));
    field("criteria", slice(&s.criteria, criterion));
    field("contents", contents(&s.contents));
    field("commission", s.commission.to_string());
    field("model_mismatch", option_num(s.model_mismatch));
    out.push_str(" }");
    out
}

/// Shortest round-trip decimal of a finite `f64` as a float literal.
fn num(value: f64) -> String {
    let text = format!("{value:?}");
    if text.contains(['.', 'e']) {
        text
    } else {
        format!("{text}.0")
    }
}

fn option<T>(value: Option<&T>, write: impl Fn(&T) -> String) -> String {
    value.map_or_else(|| "None".to_string(), |v| format!("Some({})", write(v)))
}

fn option_num(value: Option<f64>) -> String {
    option(value.as_ref(), |v| num(*v))
}

fn slice<T>(items: &[T], write: impl Fn(&T) -> String) -> String {
    let inner: Vec<String> = items.iter().map(write).collect();
    format!("&[{}]", inner.join(", "))
}

fn model(m: &ModelSpec) -> String {
    format!(
        "ModelSpec {{ kind: ModelKind::{:?}, mu: {}, mu_static: {}, decay_s_per_m: {}, \
         k_t_n_per_m: {}, dahl_alpha: {}, surface: {} }}",
        m.kind,
        num(m.mu),
        option_num(m.mu_static),
        option_num(m.decay_s_per_m),
        option_num(m.k_t_n_per_m),
        option_num(m.dahl_alpha),
        option(m.surface.as_ref(), surface),
    )
}

fn surface(s: &RoughSurface) -> String {
    format!(
        "RoughSurface {{ rq_m: {}, rs_m: {}, nominal_area_m2: {}, asperity_density_per_m2: {}, \
         distribution_c: {}, distribution_lambda: {}, young_1_pa: {}, poisson_1: {}, \
         young_2_pa: {}, poisson_2: {}, poisson_soft: {}, yield_strength_pa: {} }}",
        num(s.rq_m),
        num(s.rs_m),
        num(s.nominal_area_m2),
        num(s.asperity_density_per_m2),
        num(s.distribution_c),
        num(s.distribution_lambda),
        num(s.young_1_pa),
        num(s.poisson_1),
        num(s.young_2_pa),
        num(s.poisson_2),
        num(s.poisson_soft),
        num(s.yield_strength_pa),
    )
}

fn mismatch(m: &Mismatch) -> String {
    format!(
        "Mismatch {{ mu_ratio: {}, k_t_ratio: {}, rq_ratio: {} }}",
        num(m.mu_ratio),
        option_num(m.k_t_ratio),
        option_num(m.rq_ratio),
    )
}

fn actuator(a: &Actuator) -> String {
    format!(
        "Actuator {{ kind: ActuatorKind::{:?}, full_scale_voltage_v: {}, \
         full_scale_amplitude_m: {}, max_voltage_v: {}, max_current_a: {}, stack: {} }}",
        a.kind,
        num(a.full_scale_voltage_v),
        num(a.full_scale_amplitude_m),
        num(a.max_voltage_v),
        num(a.max_current_a),
        option(a.stack.as_ref(), stack),
    )
}

fn stack(s: &Stack) -> String {
    format!(
        "Stack {{ discs: {}, d33_m_per_v: {}, stiffness_n_per_m: {}, bolt_stiffness_n_per_m: {} }}",
        s.discs,
        num(s.d33_m_per_v),
        num(s.stiffness_n_per_m),
        num(s.bolt_stiffness_n_per_m),
    )
}

fn horn(h: &Horn) -> String {
    format!(
        "Horn {{ length_m: {}, width_m: {}, thickness_m: {}, vertical_amplitude_m: {}, \
         contact_position_m: {}, motor_regions: {} }}",
        num(h.length_m),
        num(h.width_m),
        num(h.thickness_m),
        num(h.vertical_amplitude_m),
        num(h.contact_position_m),
        h.motor_regions,
    )
}

fn transducer(t: &Transducer) -> String {
    format!(
        "Transducer {{ resonance_hz: {}, quality_factor: {}, drift_hz_per_s: {}, drive_hz: {}, \
         clamped_capacitance_f: {}, motional_resistance_ohm: {}, shift: ResonanceShift {{ \
         thermal_per_k: {}, thermal_resistance_k_per_w: {}, thermal_time_constant_s: {}, \
         load_per_n: {}, bvd_envelope: {}, freq_auto: {} }} }}",
        num(t.resonance_hz),
        num(t.quality_factor),
        num(t.drift_hz_per_s),
        num(t.drive_hz),
        num(t.clamped_capacitance_f),
        num(t.motional_resistance_ohm),
        num(t.shift.thermal_per_k),
        num(t.shift.thermal_resistance_k_per_w),
        num(t.shift.thermal_time_constant_s),
        num(t.shift.load_per_n),
        t.shift.bvd_envelope,
        t.shift.freq_auto,
    )
}

fn cell(c: &LoadCell) -> String {
    format!(
        "LoadCell {{ full_scale_n: {}, bandwidth_hz: {}, offset_n: {}, gain_error: {}, \
         noise_rms_pct_fs: {}, adc_bits: {} }}",
        num(c.full_scale_n),
        num(c.bandwidth_hz),
        num(c.offset_n),
        num(c.gain_error),
        num(c.noise_rms_pct_fs),
        c.adc_bits,
    )
}

fn fault(f: &FaultEvent) -> String {
    let channel = match f.channel {
        Channel::Normal => "Channel::Normal",
        Channel::Tangential => "Channel::Tangential",
    };
    let kind = match f.kind {
        FaultKind::Disconnected { rail: Rail::Low } => {
            "FaultKind::Disconnected { rail: Rail::Low }".to_string()
        }
        FaultKind::Disconnected { rail: Rail::High } => {
            "FaultKind::Disconnected { rail: Rail::High }".to_string()
        }
        FaultKind::Stuck => "FaultKind::Stuck".to_string(),
        FaultKind::Spike { force_n } => format!("FaultKind::Spike {{ force_n: {} }}", num(force_n)),
    };
    format!(
        "FaultEvent {{ at_s: {}, channel: {channel}, kind: {kind}, duration_s: {} }}",
        num(f.at_s),
        option_num(f.duration_s),
    )
}

fn breakpoint(b: &Breakpoint) -> String {
    format!(
        "Breakpoint {{ t_s: {}, value: {} }}",
        num(b.t_s),
        num(b.value)
    )
}

fn target_point(p: &TargetPoint) -> String {
    let target = match p.target {
        Target::Force { force_mn } => format!("Target::Force {{ force_mn: {force_mn} }}"),
        Target::Coef { coef_ppm } => format!("Target::Coef {{ coef_ppm: {coef_ppm} }}"),
        Target::Reduction { reduction_mpct } => {
            format!("Target::Reduction {{ reduction_mpct: {reduction_mpct} }}")
        }
        Target::NetForce { force_mn } => format!("Target::NetForce {{ force_mn: {force_mn} }}"),
    };
    format!(
        "TargetPoint {{ at_s: {}, target: {target}, ramp: {} }}",
        num(p.at_s),
        p.ramp
    )
}

fn accuracy(a: &Accuracy) -> String {
    format!(
        "Accuracy {{ friction_pct: {}, model_pct: {} }}",
        num(a.friction_pct),
        num(a.model_pct)
    )
}

fn criterion(c: &Criterion) -> String {
    match *c {
        Criterion::Settle { band_pct, within_s } => format!(
            "Criterion::Settle {{ band_pct: {}, within_s: {} }}",
            num(band_pct),
            num(within_s)
        ),
        Criterion::Overshoot { max_pct } => {
            format!("Criterion::Overshoot {{ max_pct: {} }}", num(max_pct))
        }
        Criterion::SteadyRmsError {
            max_pct,
            from_s,
            to_s,
        } => format!(
            "Criterion::SteadyRmsError {{ max_pct: {}, from_s: {}, to_s: {} }}",
            num(max_pct),
            num(from_s),
            num(to_s)
        ),
        Criterion::TrackingError {
            max_pct,
            from_s,
            to_s,
        } => format!(
            "Criterion::TrackingError {{ max_pct: {}, from_s: {}, to_s: {} }}",
            num(max_pct),
            num(from_s),
            num(to_s)
        ),
        Criterion::FaultReaction { within_periods } => {
            format!("Criterion::FaultReaction {{ within_periods: {within_periods} }}")
        }
    }
}

fn contents(c: &Contents) -> String {
    format!(
        "Contents {{ tangential_vibration: {}, normal_vibration: {}, load_min_n: {}, \
         load_max_n: {}, velocity_min_m_per_s: {}, velocity_max_m_per_s: {} }}",
        c.tangential_vibration,
        c.normal_vibration,
        num(c.load_min_n),
        num(c.load_max_n),
        num(c.velocity_min_m_per_s),
        num(c.velocity_max_m_per_s),
    )
}
