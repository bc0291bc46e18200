//! Whether a scene can work, judged before it runs (issue 26): the values of a scene file can
//! each be in range and still ask for what the physics or the controller cannot give.
//!
//! [`check`] weighs a scene against the controller's own model (the one the station runs) and
//! the controller's tuning ([`crate::control::controller_settings`]):
//!
//! - **target against reach**: the friction ratio each target asks for (1 - reduction, or the
//!   coefficient or force over the controller's natural friction at that load and speed),
//!   against the lowest ratio the model gives at the drive's ceiling (the actuator ratings'
//!   [`AmplitudeLimit`]), times the transducer's gain at the drive frequency
//!   `1 / sqrt(1 + (2 Q (f - f0) / f0)^2)` (a `freq auto` scene drives on the resonance). A
//!   target the full drive misses by more than the scene's band is refused; one it misses by
//!   less is a warning (the run holds the drive at its limit and passes only within the band).
//!   A target above the natural friction is out of reach the same way: vibration only lowers
//!   friction.
//! - **sliding speed against the sliding threshold**: the controller's sliding detector
//!   switches the loop on above `sliding_on_m_s` (1 mm/s); a scene that never slides faster
//!   never starts its loop, and a criterion window where it is slower judges a loop that is
//!   off.
//! - **cell noise against the accuracy**: the steady RMS friction error the cells' noise (and
//!   the converter's quantisation) alone predicts through the loop
//!   ([`crate::control::steady_noise_rms_error`]: the share of the measured ratio's noise the
//!   steady PI passes, and mu0's learning error over the time the scene slides before its drive
//!   starts), relative to the smallest friction the target asks for with the drive on. (The
//!   force filter's output noise, which this check compared before, is not what the friction
//!   carries: the loop averages it; at 1 % FS on the reference it predicted 1.51 % where
//!   `sonolube scene reference --noise --seeds 20` measures 0.77 % mean, 1.27 % worst.) Above the scene's band it is refused; above half the band it is a warning (the model
//!   error and the noise share the band).
//!
//! - **a reduction step against mu0's uncertainty**: a reduction target is relative to mu0,
//!   learned from the cells while the contact slides with the drive off before the first target
//!   asks for drive; its standard error `sqrt((sigma_t / (mu0 W))^2 + (sigma_n / W)^2) / sqrt(n)`
//!   (`n` samples) holds the friction off every later reduction target by that fraction of the
//!   target friction, a steady offset no feedback sees. Past the target it is overshoot, judged
//!   against the step: when one standard error of mu0 is more than half the scene's overshoot
//!   criterion, the step is near what the cells resolve and the run may fail by mu0's error
//!   alone (with probability `P(z > criterion / error)`, one-sided: more than 2.3 %, and up to
//!   one half for a step of which mu0's error is many times the criterion): a warning with that
//!   chance, never a refusal (the error is as likely to fall short of the target as past it).
//!   Coefficient and force targets are absolute: mu0's error does not move them.
//!
//! The control rate's range is the schema's (`sonolube_scene_types::CONTROL_RATE_RANGE_HZ`,
//! the one source the loader and the controller's gains share); its period budget is checked
//! with the model variant (`crate::variant`).
//!
//! Configuration only (`f64`, once per scene); no allocation, so a board runs it at `scene`.

use core::fmt;

use crate::control::{AmplitudeLimit, Settings, controller_settings};
use crate::fx::{Q1_31, Q8_24, Q16_16};
use crate::model::{FrictionModel, ModelError, OperatingPoint};
use crate::protocol::Target;
use crate::scene::{Criterion, Scene, interpolate, target_at};

/// Instants sampled per target segment and per criterion window.
const SAMPLES: u32 = 64;

/// How bad a finding is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Severity {
    /// The scene may work, with no margin: the run says so.
    Warn,
    /// The scene cannot work as written: it is refused.
    Refuse,
}

impl Severity {
    /// `warning` or `refused`.
    pub const fn word(self) -> &'static str {
        match self {
            Severity::Warn => "warning",
            Severity::Refuse => "refused",
        }
    }
}

/// What a finding is about, with the numbers that fail.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Cause {
    /// A target asks for a friction ratio the full drive does not reach (or one above the
    /// natural friction).
    TargetOutOfReach {
        /// Index of the target point in `profiles.target`.
        point: usize,
        /// The target.
        target: Target,
        /// Time of the worst instant, s.
        at_s: f64,
        /// Friction ratio F'/F the target asks for there.
        needed_ratio: f64,
        /// Lowest friction ratio the controller's model gives at the drive's ceiling there.
        reachable_ratio: f64,
        /// The drive's ceiling, fraction of full scale, times the transducer's gain at the
        /// drive frequency.
        drive: f64,
    },
    /// The sliding speed stays at or below the sliding threshold.
    NoSliding {
        /// Start of the span judged, s.
        from_s: f64,
        /// End of the span judged, s.
        to_s: f64,
        /// Fraction of the span below the threshold, [0, 1].
        fraction_below: f64,
        /// Highest speed in the span, m/s.
        top_speed_m_per_s: f64,
        /// The controller's sliding threshold, m/s.
        threshold_m_per_s: f64,
    },
    /// The cells' noise alone predicts an RMS friction error near or above the band.
    Noise {
        /// Predicted RMS error, % of the smallest target friction.
        predicted_pct: f64,
        /// The scene's band, `accuracy.friction_pct`.
        band_pct: f64,
        /// The smallest friction the target asks for with the drive on, N.
        friction_n: f64,
        /// The tangential cell's per-sample noise (and quantisation), N RMS.
        tangential_noise_n: f64,
    },
    /// A reduction step is near what the cells resolve: mu0's standard error holds the friction
    /// off the target by more than half the overshoot criterion.
    StepBelowResolution {
        /// Index of the target point in `profiles.target` that steps.
        point: usize,
        /// The step, % of the natural friction.
        step_pct: f64,
        /// mu0's standard error after its learning, % of mu0 (one sigma).
        natural_error_pct: f64,
        /// Samples mu0 is learned from.
        samples: f64,
        /// The friction's offset that error gives at the new target, % of the step.
        offset_pct_of_step: f64,
        /// The scene's overshoot criterion, % of the step.
        overshoot_pct: f64,
        /// The chance that mu0's error alone takes the friction past the criterion, [0, 1/2].
        chance_past: f64,
    },
    /// The controller's model could not be evaluated at the scene's operating points.
    Model(ModelError),
    /// `freq auto`: the resonance search may lock after the scene's first judged instant.
    SearchOutlastsStart {
        /// The stack's declared quality factor.
        quality_factor: f64,
        /// The search's time to lock by its rule, s.
        lock_bound_s: f64,
        /// The first target change after t = 0 or criterion window, s.
        first_step_s: f64,
    },
}

/// One thing that cannot, or may not, work, with the scene key it comes from.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Finding {
    /// Refused or a warning.
    pub severity: Severity,
    /// The scene file's key (for a target: the point's key is written with its index).
    pub field: &'static str,
    /// What fails, with its numbers.
    pub cause: Cause,
}

impl Finding {
    /// What fails, in a few words (at most [`crate::protocol::MAX_REASON_LEN`] bytes), for an
    /// `err` reply; the numbers are in the [`fmt::Display`] text.
    pub const fn summary(&self) -> &'static str {
        match self.cause {
            Cause::TargetOutOfReach { .. } => "the target is beyond the drive's reach",
            Cause::NoSliding { .. } => "the speed is below the sliding threshold",
            Cause::Noise { .. } => "the cells' noise exceeds the accuracy band",
            Cause::StepBelowResolution { .. } => "the step is near what the cells resolve",
            Cause::Model(_) => "the controller's model fails over the scene",
            Cause::SearchOutlastsStart { .. } => "the resonance search may outlast the first step",
        }
    }
}

impl fmt::Display for Finding {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: ", self.severity.word())?;
        match self.cause {
            Cause::TargetOutOfReach {
                point,
                target,
                at_s,
                needed_ratio,
                reachable_ratio,
                drive,
            } => {
                let (key, value) = match target {
                    Target::Reduction { reduction_mpct } => {
                        ("reduction_pct", f64::from(reduction_mpct) * 1e-3)
                    }
                    Target::Coef { coef_ppm } => ("coef", f64::from(coef_ppm) * 1e-6),
                    Target::Force { force_mn } => ("force_n", f64::from(force_mn) * 1e-3),
                    Target::NetForce { force_mn } => ("net_force_n", f64::from(force_mn) * 1e-3),
                };
                write!(
                    f,
                    "profiles.target[{point}].{key} = {value}: asks for {:.2} % of the natural \
                     friction at t = {at_s:.4} s; the controller's model reaches at best {:.2} % \
                     (reduction {:.2} %) with the drive at {:.3} of full scale",
                    100.0 * needed_ratio,
                    100.0 * reachable_ratio,
                    100.0 * (1.0 - reachable_ratio),
                    drive
                )?;
                if needed_ratio > 1.0 {
                    write!(f, " (vibration only lowers friction)")?;
                }
                Ok(())
            }
            Cause::NoSliding {
                from_s,
                to_s,
                fraction_below,
                top_speed_m_per_s,
                threshold_m_per_s,
            } => write!(
                f,
                "{}: from {from_s} s to {to_s} s the speed is at most {top_speed_m_per_s:.6} m/s, \
                 {:.0} % of the time below the sliding threshold {threshold_m_per_s} m/s: the \
                 loop does not run without sliding",
                self.field,
                100.0 * fraction_below
            ),
            Cause::Noise {
                predicted_pct,
                band_pct,
                friction_n,
                tangential_noise_n,
            } => write!(
                f,
                "{}: the cells' noise alone predicts {predicted_pct:.2} % RMS friction error \
                 through the loop (the steady PI and mu0's learning; {tangential_noise_n:.3e} N \
                 RMS per sample against {friction_n:.4} N of target friction), against \
                 accuracy.friction_pct = {band_pct} %",
                self.field
            ),
            Cause::StepBelowResolution {
                point,
                step_pct,
                natural_error_pct,
                samples,
                offset_pct_of_step,
                overshoot_pct,
                chance_past,
            } => write!(
                f,
                "profiles.target[{point}].reduction_pct: a step of {step_pct:.2} % of the natural \
                 friction; mu0, learned from {samples:.0} samples sliding with the drive off, is \
                 known to {natural_error_pct:.3} % (one standard error, the cells' noise), which \
                 holds the friction {offset_pct_of_step:.1} % of the step off the target: past \
                 the overshoot criterion of {overshoot_pct} % of the step by that alone in {:.0} % \
                 of runs",
                100.0 * chance_past
            ),
            Cause::Model(error) => write!(
                f,
                "{}: the controller's model cannot be evaluated over the scene: {error}",
                self.field
            ),
            Cause::SearchOutlastsStart {
                quality_factor,
                lock_bound_s,
                first_step_s,
            } => write!(
                f,
                "{} = true: the resonance search (f0 +- 10 %, Q {}) locks by its rule within \
                 {:.2} ms, f0 at the band's top (docs/resonance.md); the scene judges the loop \
                 from {:.2} ms, and the friction loop starts only at the lock",
                self.field,
                quality_factor,
                lock_bound_s * 1e3,
                first_step_s * 1e3
            ),
        }
    }
}

/// Most findings [`check`] returns: one per check.
pub const MAX_FINDINGS: usize = 6;

/// The findings of [`check`], worst of each check.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Feasibility {
    findings: heapless::Vec<Finding, MAX_FINDINGS>,
}

impl Feasibility {
    /// Every finding, refusals and warnings.
    pub fn findings(&self) -> &[Finding] {
        &self.findings
    }

    /// The first refusal, if any: the scene cannot work.
    pub fn refusal(&self) -> Option<&Finding> {
        self.findings
            .iter()
            .find(|f| f.severity == Severity::Refuse)
    }

    /// The warnings.
    pub fn warnings(&self) -> impl Iterator<Item = &Finding> {
        self.findings
            .iter()
            .filter(|f| f.severity == Severity::Warn)
    }

    fn push(&mut self, finding: Option<Finding>) {
        if let Some(finding) = finding {
            // At most one finding per check, MAX_FINDINGS checks.
            let _ = self.findings.push(finding);
        }
    }
}

/// Judges `scene` against `model`, the friction model its controller runs (the station's:
/// [`crate::station::Station::model`]). See the module documentation for the rules.
pub fn check<M: FrictionModel + ?Sized>(scene: &Scene<'_>, model: &M) -> Feasibility {
    let settings = controller_settings(scene);
    let mut result = Feasibility::default();
    result.push(sliding(scene, &settings));
    result.push(reach(scene, &settings, model));
    result.push(noise(scene, &settings));
    result.push(step_resolution(scene, &settings));
    result.push(search_timing(scene));
    result
}

/// `freq auto`: the resonance search's time by its rule
/// ([`crate::resonance::ResonanceSettings::search_lock_bound_s`], f0 anywhere in its band)
/// against the scene's first judged instant (the first target change after t = 0 or the
/// start of the first criterion window). The friction loop starts at the lock, so a step
/// before it is judged on a loop that is not running yet: a warning (f0 low in the band locks
/// sooner), with both times. `None` without `freq auto`, for a commissioned scene (it starts
/// at the measured f0) or a stack the resonance loop refuses (the station reports that).
pub fn search_timing(scene: &Scene<'_>) -> Option<Finding> {
    if !scene.transducer.shift.freq_auto || scene.commission {
        return None;
    }
    let settings = crate::resonance::ResonanceSettings::around(&crate::station::scene_stack(scene));
    let lock_bound_s = settings.search_lock_bound_s().ok()?;
    let first_step_s = first_judged_s(scene);
    (first_step_s < lock_bound_s).then_some(Finding {
        severity: Severity::Warn,
        field: "transducer.shift.freq_auto",
        cause: Cause::SearchOutlastsStart {
            quality_factor: scene.transducer.quality_factor,
            lock_bound_s,
            first_step_s,
        },
    })
}

/// The scene's first judged instant, s: its first target change after t = 0 or the start of
/// its first criterion window (the duration when it has neither).
pub fn first_judged_s(scene: &Scene<'_>) -> f64 {
    scene
        .target
        .iter()
        .skip(1)
        .map(|point| point.at_s)
        .chain(scene.criteria.iter().filter_map(|c| match *c {
            Criterion::SteadyRmsError { from_s, .. } | Criterion::TrackingError { from_s, .. } => {
                Some(from_s)
            }
            _ => None,
        }))
        .fold(scene.duration_s, f64::min)
}

/// The transducer's vibration gain at the drive frequency, at time `t_s` (1 on resonance).
pub fn drive_gain(scene: &Scene<'_>, t_s: f64) -> f64 {
    let transducer = &scene.transducer;
    if transducer.shift.freq_auto {
        return 1.0;
    }
    let f0 = transducer.resonance_hz + transducer.drift_hz_per_s * t_s;
    let detuning = 2.0 * transducer.quality_factor * (transducer.drive_hz - f0) / f0;
    1.0 / libm::sqrt(1.0 + detuning * detuning)
}

/// The friction ratio `target` asks of a contact whose natural coefficient is `mu` under
/// `load_n`.
fn needed_ratio(target: Target, mu: f64, load_n: f64) -> f64 {
    match target {
        Target::Reduction { reduction_mpct } => 1.0 - f64::from(reduction_mpct) * 1e-5,
        Target::Coef { coef_ppm } => f64::from(coef_ppm) * 1e-6 / mu,
        Target::Force { force_mn } => f64::from(force_mn) * 1e-3 / (mu * load_n),
        // Never asked (skipped above); as a friction force, its magnitude.
        Target::NetForce { force_mn } => f64::from(force_mn.unsigned_abs()) * 1e-3 / (mu * load_n),
    }
}

/// The instants `from_s + (to_s - from_s) k / SAMPLES`, k = 0 ..= SAMPLES.
fn instants(from_s: f64, to_s: f64) -> impl Iterator<Item = f64> {
    (0..=SAMPLES).map(move |k| from_s + (to_s - from_s) * f64::from(k) / f64::from(SAMPLES))
}

fn speed_at(scene: &Scene<'_>, t_s: f64) -> f64 {
    f64::from(libm::fabsf(interpolate(
        scene.sliding_velocity_m_per_s,
        t_s as f32,
    )))
}

fn sliding(scene: &Scene<'_>, settings: &Settings) -> Option<Finding> {
    let threshold = settings.sliding_on_m_s;
    let field = "profiles.sliding_velocity_m_per_s";
    let span = |from_s: f64, to_s: f64| {
        let (mut below, mut top) = (0u32, 0.0f64);
        for t in instants(from_s, to_s) {
            let speed = speed_at(scene, t);
            top = top.max(speed);
            below += u32::from(speed <= threshold);
        }
        Cause::NoSliding {
            from_s,
            to_s,
            fraction_below: f64::from(below) / f64::from(SAMPLES + 1),
            top_speed_m_per_s: top,
            threshold_m_per_s: threshold,
        }
    };
    let whole = span(0.0, scene.duration_s);
    if let Cause::NoSliding {
        top_speed_m_per_s, ..
    } = whole
        && top_speed_m_per_s <= threshold
    {
        return Some(Finding {
            severity: Severity::Refuse,
            field,
            cause: whole,
        });
    }
    // A window judged on a loop that is off there: refused when off throughout, a warning
    // when off for part of it (a reversal).
    let mut worst: Option<Finding> = None;
    for criterion in scene.criteria {
        let (from_s, to_s) = match *criterion {
            Criterion::SteadyRmsError { from_s, to_s, .. }
            | Criterion::TrackingError { from_s, to_s, .. } => (from_s, to_s),
            _ => continue,
        };
        let cause = span(from_s, to_s);
        let Cause::NoSliding {
            fraction_below,
            top_speed_m_per_s,
            ..
        } = cause
        else {
            continue;
        };
        let severity = if top_speed_m_per_s <= threshold {
            Severity::Refuse
        } else if fraction_below > 0.0 {
            Severity::Warn
        } else {
            continue;
        };
        if worst.is_none_or(|w| severity > w.severity) {
            worst = Some(Finding {
                severity,
                field,
                cause,
            });
        }
    }
    worst
}

/// One instant of a target point's span at which the friction loop runs (sliding faster than
/// the controller's `sliding_on_m_s`, under more than its `min_normal_force_n`), with what the
/// target asks for there.
struct TargetInstant {
    /// Index of the target point whose span this is.
    point: usize,
    /// The instant, s: a point's span is judged up to just before the next point, whose own
    /// target takes over at its time.
    t_s: f64,
    /// The target in force.
    target: Target,
    /// Sliding speed, m/s (magnitude).
    speed_m_s: f64,
    /// Normal load, N.
    load_n: f64,
    /// The natural friction coefficient at that speed.
    mu: f64,
    /// Friction ratio F'/F the target asks for ([`needed_ratio`]).
    needed: f64,
}

/// The `SAMPLES + 1` instants of every target point's span (from the point to the next, the
/// last to the scene's end) at which the loop runs: the one walk over the target spans that
/// the reach and the noise checks share.
fn loop_instants<'a>(
    scene: &'a Scene<'a>,
    settings: &'a Settings,
) -> impl Iterator<Item = TargetInstant> + 'a {
    scene
        .target
        .iter()
        .enumerate()
        .flat_map(move |(index, point)| {
            let end = scene
                .target
                .get(index + 1)
                .map_or(scene.duration_s, |next| next.at_s);
            instants(point.at_s, end.max(point.at_s)).map(move |t| {
                // Just before the next point its own target takes over.
                let t = if t >= end && end > point.at_s {
                    end - 1e-9
                } else {
                    t
                };
                (index, t)
            })
        })
        .filter_map(move |(point, t_s)| {
            let target = target_at(scene.target, t_s as f32)?;
            let speed_m_s = speed_at(scene, t_s);
            let load_n = f64::from(interpolate(scene.normal_load_n, t_s as f32));
            if speed_m_s <= settings.sliding_on_m_s || load_n <= settings.min_normal_force_n {
                return None;
            }
            let mu = scene.controller.natural_coefficient(speed_m_s);
            Some(TargetInstant {
                point,
                t_s,
                target,
                speed_m_s,
                load_n,
                mu,
                needed: needed_ratio(target, mu, load_n),
            })
        })
}

fn reach<M: FrictionModel + ?Sized>(
    scene: &Scene<'_>,
    settings: &Settings,
    model: &M,
) -> Option<Finding> {
    let ceiling = match AmplitudeLimit::new(&settings.actuator) {
        Ok(limit) => limit.max_amplitude.to_f64(),
        // No headroom is the controller's own refusal, with its own message.
        Err(_) => return None,
    };
    let band = scene.accuracy.friction_pct / 100.0;
    let mut worst: Option<(f64, Finding)> = None;
    for instant in loop_instants(scene, settings) {
        let TargetInstant {
            point: index,
            t_s: t,
            target,
            speed_m_s: speed,
            load_n: load,
            needed,
            ..
        } = instant;
        // A net-force target (issue 27) is not a friction ratio: its reach is the motor
        // hold's, which flags it while running (`crate::control::net_force`).
        if target == (Target::Reduction { reduction_mpct: 0 }) || target.is_signed() {
            continue;
        }
        let drive = ceiling * drive_gain(scene, t);
        let operating = OperatingPoint {
            normal_force: Q16_16::from_f64_saturating(load).value,
            sliding_velocity: Q8_24::from_f64_saturating(speed).value,
        };
        let amplitude = Q1_31::from_f64_saturating(drive).value;
        let reachable = match model.ratio(&operating, amplitude) {
            Ok(ratio) => ratio.to_f64(),
            Err(error) => {
                return Some(Finding {
                    severity: Severity::Refuse,
                    field: "controller",
                    cause: Cause::Model(error),
                });
            }
        };
        // Relative miss of the friction: below reach (needed < reachable) or above the
        // natural friction (needed > 1).
        let miss = if needed < reachable {
            (reachable - needed) / needed
        } else if needed > 1.0 {
            (needed - 1.0) / needed
        } else {
            continue;
        };
        let severity = if miss > band {
            Severity::Refuse
        } else {
            Severity::Warn
        };
        let field = match target {
            Target::Reduction { .. } => "profiles.target.reduction_pct",
            Target::Coef { .. } => "profiles.target.coef",
            Target::Force { .. } => "profiles.target.force_n",
            Target::NetForce { .. } => "profiles.target.net_force_n",
        };
        let finding = Finding {
            severity,
            field,
            cause: Cause::TargetOutOfReach {
                point: index,
                target,
                at_s: t,
                needed_ratio: needed,
                reachable_ratio: if needed > 1.0 { 1.0 } else { reachable },
                drive,
            },
        };
        if worst.is_none_or(|(m, _)| miss > m) {
            worst = Some((miss, finding));
        }
    }
    worst.map(|(_, finding)| finding)
}

/// Per-sample noise of a cell, N RMS: its Gaussian noise and its converter's quantisation
/// (one step over sqrt 12).
fn cell_noise_n(cell: &crate::scene::LoadCell) -> f64 {
    let gaussian = cell.noise_rms_pct_fs / 100.0 * cell.full_scale_n;
    let step = 2.0 * cell.full_scale_n / libm::ldexp(1.0, i32::from(cell.adc_bits));
    libm::sqrt(gaussian * gaussian + step * step / 12.0)
}

/// The share of a white noise's RMS that a first-order low-pass of `bandwidth_hz` sampled at
/// `rate_hz` passes: sqrt(alpha / (2 - alpha)), with the controller's alpha
/// ([`crate::control::low_pass_variance_share`]).
#[cfg(test)]
fn filter_rms_gain(bandwidth_hz: f64, rate_hz: f64) -> f64 {
    libm::sqrt(crate::control::low_pass_variance_share(
        bandwidth_hz,
        1.0 / rate_hz,
    ))
}

fn noise(scene: &Scene<'_>, settings: &Settings) -> Option<Finding> {
    let tangential = cell_noise_n(&scene.tangential_cell);
    let normal = cell_noise_n(&scene.normal_cell);
    let band = scene.accuracy.friction_pct;
    let mut worst: Option<(f64, Cause, &'static str)> = None;
    // mu0 is learned sliding with the drive off until the drive first starts.
    let (learn_s, _) = learning(scene, settings)?;
    for instant in loop_instants(scene, settings) {
        let TargetInstant {
            load_n: load,
            needed,
            mu,
            ..
        } = instant;
        // Natural friction is held with the drive off: the noise moves no drive.
        if needed >= 1.0 {
            continue;
        }
        let friction = needed * mu * load;
        // Through the loop: the steady PI's share of the measured ratio's noise and mu0's
        // learning error (`control::steady_noise_rms_error`).
        let predicted = 100.0
            * crate::control::steady_noise_rms_error(
                settings, tangential, normal, friction, load, learn_s,
            );
        let field = if tangential / friction >= normal / load {
            "sensors.tangential.noise_rms_pct_fs"
        } else {
            "sensors.normal.noise_rms_pct_fs"
        };
        if worst.is_none_or(|(p, _, _)| predicted > p) {
            worst = Some((
                predicted,
                Cause::Noise {
                    predicted_pct: predicted,
                    band_pct: band,
                    friction_n: friction,
                    tangential_noise_n: tangential,
                },
                field,
            ));
        }
    }
    let (predicted, cause, field) = worst?;
    let severity = if predicted > band {
        Severity::Refuse
    } else if predicted > band / 2.0 {
        Severity::Warn
    } else {
        return None;
    };
    Some(Finding {
        severity,
        field,
        cause,
    })
}

/// How long mu0 is learned before the drive first starts, s, and the instant the drive starts:
/// from the sliding debounce to the first instant the loop runs at which a target asks for
/// drive ([`loop_instants`]), at least the controller's `natural_learn_s` (the drive waits for
/// it). `None` when no target asks for drive.
fn learning(scene: &Scene<'_>, settings: &Settings) -> Option<(f64, TargetInstant)> {
    loop_instants(scene, settings)
        .find(|instant| instant.needed < 1.0)
        .map(|instant| {
            let learn_s = libm::fmax(
                instant.t_s - settings.sliding_debounce_s,
                settings.natural_learn_s,
            );
            (learn_s, instant)
        })
}

/// Every reduction step after the first drive against mu0's standard error (module docs):
/// the worst step, a warning when the error is above half the scene's overshoot criterion.
/// `None` without an overshoot criterion or a reduction step.
fn step_resolution(scene: &Scene<'_>, settings: &Settings) -> Option<Finding> {
    let overshoot = crate::control::overshoot_criterion(scene)?;
    let (learn_s, drive_start) = learning(scene, settings)?;
    let samples = crate::control::learning_samples(settings, learn_s);
    // mu0's relative standard error, at the load and speed where the drive starts.
    let natural_error = crate::control::natural_learning_error(
        cell_noise_n(&scene.tangential_cell),
        cell_noise_n(&scene.normal_cell),
        drive_start.mu,
        drive_start.load_n,
        samples,
    );
    let drive_start_s = settings.sliding_debounce_s + learn_s;
    let mut worst: Option<(f64, Cause)> = None;
    for (index, pair) in scene.target.windows(2).enumerate() {
        let [before, after] = pair else { continue };
        if !matches!(after.target, Target::Reduction { .. }) || after.at_s + 1e-9 < drive_start_s {
            continue;
        }
        let load = f64::from(interpolate(scene.normal_load_n, after.at_s as f32));
        let mu = scene
            .controller
            .natural_coefficient(speed_at(scene, after.at_s));
        let (from, to) = (
            needed_ratio(before.target, mu, load),
            needed_ratio(after.target, mu, load),
        );
        let step = libm::fabs(to - from);
        if step <= 0.0 || to >= 1.0 {
            continue;
        }
        let offset = to * natural_error / step;
        if worst.is_none_or(|(worst_offset, _)| offset > worst_offset) {
            let cause = Cause::StepBelowResolution {
                point: index + 1,
                step_pct: 100.0 * step,
                natural_error_pct: 100.0 * natural_error,
                samples,
                offset_pct_of_step: 100.0 * offset,
                overshoot_pct: 100.0 * overshoot,
                chance_past: 0.5 * libm::erfc(overshoot / offset / core::f64::consts::SQRT_2),
            };
            worst = Some((offset, cause));
        }
    }
    let (offset, cause) = worst?;
    (offset > overshoot / 2.0).then_some(Finding {
        severity: Severity::Warn,
        field: "profiles.target",
        cause,
    })
}

#[cfg(test)]
#[path = "feasibility_tests.rs"]
mod tests;
