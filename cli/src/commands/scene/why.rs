//! Why a scene whose values are each within the schema's range still cannot build a run, in
//! words that name the scene file's keys and values: the controller settings are made from
//! several of them at once ([`controller_settings`]), so a combination can break a rule that
//! no single range check sees (a very high quality factor makes the envelope too slow for the
//! lead; a low control rate makes the PI's integral step too large).

use sonolube::control::{ConfigError, FilterError, GainsError, LimitsError, Settings, ShaperError};
use sonolube::control::{FORCE_FILTER_HZ, controller_settings};
use sonolube::scene::Scene;
use sonolube_sim::SimError;

/// The largest lead gain the drive shaper's Q8.24 format holds.
const MAX_LEAD_GAIN: f64 = 128.0;

/// One low-pass step's coefficient, 1 - e^(-T / tau), as the controller computes it.
fn alpha(time_constant_s: f64, period_s: f64) -> f64 {
    -(-period_s / time_constant_s).exp_m1()
}

/// Why `scene` cannot run, naming the scene values that led to `error` where they are known.
pub fn cannot_run(scene: &Scene<'_>, error: &SimError) -> String {
    let settings = controller_settings(scene);
    let detail = match error {
        SimError::Config(ConfigError::Shaper(ShaperError::OutOfRange)) => lead(scene, &settings),
        SimError::Config(ConfigError::Shaper(ShaperError::Filter(filter))) => {
            Some(envelope_filter(scene, &settings, *filter))
        }
        SimError::Config(ConfigError::Gains(GainsError::OutOfRange)) => gains(scene, &settings),
        SimError::Config(ConfigError::Filter { setting, error }) => Some(format!(
            "the controller's {setting} ({} Hz, fixed) at control_rate_hz = {} Hz: {error}; \
             raise control_rate_hz above {} Hz",
            FORCE_FILTER_HZ,
            scene.control_rate_hz,
            2.0 * FORCE_FILTER_HZ
        )),
        SimError::Config(ConfigError::OutOfRange { setting }) => {
            scene_key(setting).map(|key| format!("{key}: {error}"))
        }
        SimError::Config(ConfigError::Limits(LimitsError::NoHeadroom)) => Some(headroom(scene)),
        _ => None,
    };
    match detail {
        Some(words) => format!("cannot build the run: {words}"),
        None => format!("cannot build the run: {error}"),
    }
}

/// The scene keys a controller setting comes from.
fn scene_key(setting: &str) -> Option<&'static str> {
    Some(match setting {
        "period_s" => "control_rate_hz",
        "normal_force_range_n" => "sensors.normal.full_scale_n",
        "tangential_force_range_n" => "sensors.tangential.full_scale_n",
        "velocity_range_m_s" => "profiles.sliding_velocity_m_per_s",
        "natural_prior" => "controller.mu (the natural friction coefficient at the start speed)",
        _ => return None,
    })
}

/// The envelope the controller assumes: the transducer's plus the tangential cell's lag.
fn envelope_words(scene: &Scene<'_>) -> String {
    let t = &scene.transducer;
    let cell_lag = 1.0 / (std::f64::consts::TAU * scene.tangential_cell.bandwidth_hz);
    format!(
        "transducer.quality_factor = {} at transducer.resonance_hz = {} Hz gives an envelope time \
         constant 2 Q / (2 pi f0) = {:.4} ms, plus {:.4} ms of lag from \
         sensors.tangential.bandwidth_hz = {} Hz",
        t.quality_factor,
        t.resonance_hz,
        1e3 * t.envelope_time_constant_s(),
        1e3 * cell_lag,
        scene.tangential_cell.bandwidth_hz
    )
}

fn lead(scene: &Scene<'_>, s: &Settings) -> Option<String> {
    let period = s.period_s;
    if !(s.slew_full_scale_s.is_finite() && s.slew_full_scale_s > 0.0) {
        return None;
    }
    let (envelope, response) = (s.envelope_time_constant_s, s.response_time_constant_s);
    let gain = alpha(response, period) / alpha(envelope, period);
    // Longest envelope the lead still reaches: alpha(tau) = alpha(response) / 128.
    let longest = -period / (-alpha(response, period) / MAX_LEAD_GAIN).ln_1p();
    let cell_lag = envelope - scene.transducer.envelope_time_constant_s();
    let top_q = (longest - cell_lag) * std::f64::consts::PI * scene.transducer.resonance_hz;
    Some(format!(
        "{}: {:.4} ms in all. The controller's lead speeds the envelope up to its response time \
         constant {:.4} ms; from {:.4} ms that takes a gain of {gain:.1}, and the lead gain's \
         Q8.24 format stops below {MAX_LEAD_GAIN}. Lower transducer.quality_factor to at most \
         about {:.0} at this resonance and cell bandwidth",
        envelope_words(scene),
        1e3 * envelope,
        1e3 * response,
        1e3 * envelope,
        top_q.floor().max(1.0)
    ))
}

fn envelope_filter(scene: &Scene<'_>, s: &Settings, error: FilterError) -> String {
    format!(
        "{}: {:.4} ms in all, at control_rate_hz = {} Hz: the envelope model's filter: {error}",
        envelope_words(scene),
        1e3 * s.envelope_time_constant_s,
        scene.control_rate_hz
    )
}

fn gains(scene: &Scene<'_>, s: &Settings) -> Option<String> {
    let period = s.period_s;
    let (name, ki) = [("fast", s.ki_fast_per_s), ("steady", s.ki_per_s)]
        .into_iter()
        .find(|&(_, ki)| ki * period > 1.0)?;
    Some(format!(
        "control_rate_hz = {} Hz: the correction PI's {name} integral gain {ki} /s times the \
         control period {:.4} ms is {:.3} > 1: each step's integral correction would overshoot \
         and the loop would oscillate. The controller's gains need control_rate_hz >= {ki} Hz",
        scene.control_rate_hz,
        1e3 * period,
        ki * period
    ))
}

fn headroom(scene: &Scene<'_>) -> String {
    let a = &scene.actuator;
    let t = &scene.transducer;
    let by_voltage = a.max_voltage_v / a.full_scale_voltage_v;
    let by_current = a.max_current_a
        / (std::f64::consts::TAU * t.drive_hz * t.clamped_capacitance_f * a.full_scale_voltage_v);
    format!(
        "the amplitude ceiling is below 2^-20 of full scale: actuator.max_voltage_v / \
         actuator.full_scale_voltage_v = {by_voltage:.3e}, and actuator.max_current_a / (2 pi \
         transducer.drive_hz transducer.clamped_capacitance_f actuator.full_scale_voltage_v) = \
         {by_current:.3e}"
    )
}

/// Why the host could not measure the model variants over a scene file's contents, naming the
/// scene key behind `error` where it is known (issue 26: a velocity range through zero was
/// reported as `reference DahlSteady: no sliding (v = 0)`, naming no key).
pub fn cannot_select(scene: &Scene<'_>, error: &str) -> String {
    let c = &scene.contents;
    if error.contains("no sliding") || error.contains("v = 0") {
        format!(
            "contents.velocity_range_m_per_s = [{}, {}]: the model variants are measured over \
             this range, and at v = 0 there is no sliding, so the friction ratio is undefined \
             ({error}); a scene file measured on the host needs a range of one sign",
            c.velocity_min_m_per_s, c.velocity_max_m_per_s
        )
    } else {
        format!("the model variants cannot be measured over the scene's contents: {error}")
    }
}
