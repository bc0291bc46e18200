//! The time tables of a scene (profiles, target, faults), its criteria, accuracy and contents,
//! and the checks that need several sections at once.

use crate::checks;
use crate::error::{Errors, SceneError};
use crate::raw::{RawAccuracy, RawContents, RawCriterion, RawFault, RawProfiles, RawTargetPoint};
use crate::types::{
    Accuracy, Breakpoint, Channel, Contents, Criterion, FaultEvent, FaultKind, Rail,
    SceneDescription, Target, TargetPoint,
};

/// Most breakpoints or target points in one table (keeps the firmware's tables small).
pub const MAX_TABLE_POINTS: usize = 64;

pub(crate) fn accuracy(errors: Errors<'_>, raw: &RawAccuracy) -> Result<Accuracy, SceneError> {
    let friction_pct = errors.positive("accuracy.friction_pct", raw.friction_pct, 100.0)?;
    let model_pct = errors.positive("accuracy.model_pct", raw.model_pct, friction_pct)?;
    Ok(Accuracy {
        friction_pct,
        model_pct,
    })
}

pub(crate) fn contents(errors: Errors<'_>, raw: &RawContents) -> Result<Contents, SceneError> {
    let mut tangential_vibration = false;
    let mut normal_vibration = false;
    if raw.vibration.is_empty() {
        return Err(errors.at("contents.vibration", "must name at least one component"));
    }
    for (index, word) in raw.vibration.iter().enumerate() {
        let key = format!("contents.vibration[{index}]");
        let is_normal = errors.choose(&key, word, &[("tangential", false), ("normal", true)])?;
        let seen = if is_normal {
            &mut normal_vibration
        } else {
            &mut tangential_vibration
        };
        if *seen {
            return Err(errors.at(&key, format!("{word:?} is listed twice")));
        }
        *seen = true;
    }
    let range = |key: &str, values: &[f64]| -> Result<(f64, f64), SceneError> {
        match values {
            [lo, hi] if lo.is_finite() && hi.is_finite() && lo <= hi => Ok((*lo, *hi)),
            _ => Err(errors.at(key, "must be [min, max] with finite min <= max")),
        }
    };
    let (load_min_n, load_max_n) = range("contents.load_range_n", &raw.load_range_n)?;
    let (velocity_min_m_per_s, velocity_max_m_per_s) = range(
        "contents.velocity_range_m_per_s",
        &raw.velocity_range_m_per_s,
    )?;
    Ok(Contents {
        tangential_vibration,
        normal_vibration,
        load_min_n,
        load_max_n,
        velocity_min_m_per_s,
        velocity_max_m_per_s,
    })
}

/// Fills the tables into `scene` and runs the checks across sections.
pub(crate) fn complete(
    errors: Errors<'_>,
    mut scene: SceneDescription,
    profiles: &RawProfiles,
    faults: &[RawFault],
    criteria: &[RawCriterion],
) -> Result<SceneDescription, SceneError> {
    let duration = scene.duration_s;
    scene.normal_load_n = profile(
        errors,
        "profiles.normal_load_n",
        &profiles.normal_load_n,
        duration,
        (0.0, scene.normal_cell.full_scale_n),
    )?;
    scene.sliding_velocity_m_per_s = profile(
        errors,
        "profiles.sliding_velocity_m_per_s",
        &profiles.sliding_velocity_m_per_s,
        duration,
        (-10.0, 10.0),
    )?;
    scene.target = target(errors, &profiles.target, duration)?;
    scene.faults = faults
        .iter()
        .enumerate()
        .map(|(index, raw)| fault(errors, index, raw, &scene))
        .collect::<Result<_, _>>()?;
    if scene.faults.windows(2).any(|w| w[1].at_s < w[0].at_s) {
        return Err(errors.at("faults", "must be in order of at_s"));
    }
    scene.criteria = criteria
        .iter()
        .enumerate()
        .map(|(index, raw)| criterion(errors, index, raw, duration))
        .collect::<Result<_, _>>()?;
    checks::cross_checks(errors, &scene)?;
    Ok(scene)
}

fn profile(
    errors: Errors<'_>,
    key: &str,
    raw: &[Vec<f64>],
    duration_s: f64,
    (lo, hi): (f64, f64),
) -> Result<Vec<Breakpoint>, SceneError> {
    if raw.is_empty() || raw.len() > MAX_TABLE_POINTS {
        return Err(errors.at(key, format!("needs 1 to {MAX_TABLE_POINTS} points")));
    }
    let mut points = Vec::with_capacity(raw.len());
    for (index, pair) in raw.iter().enumerate() {
        let at = format!("{key}[{index}]");
        let &[t_s, value] = pair.as_slice() else {
            return Err(errors.at(&at, "must be a pair [t_s, value]"));
        };
        let t_s = errors.within(&at, t_s, 0.0, duration_s)?;
        if index == 0 && t_s != 0.0 {
            return Err(errors.at(&at, "the first point must be at t = 0"));
        }
        if points.last().is_some_and(|p: &Breakpoint| t_s <= p.t_s) {
            return Err(errors.at(&at, "times must increase strictly"));
        }
        if !(value.is_finite() && value >= lo && value < hi) {
            return Err(errors.at(&at, format!("value {value} is outside {lo} ..< {hi}")));
        }
        points.push(Breakpoint { t_s, value });
    }
    Ok(points)
}

fn target(
    errors: Errors<'_>,
    raw: &[RawTargetPoint],
    duration_s: f64,
) -> Result<Vec<TargetPoint>, SceneError> {
    let key = "profiles.target";
    if raw.is_empty() || raw.len() > MAX_TABLE_POINTS {
        return Err(errors.at(key, format!("needs 1 to {MAX_TABLE_POINTS} points")));
    }
    let mut points: Vec<TargetPoint> = Vec::with_capacity(raw.len());
    for (index, point) in raw.iter().enumerate() {
        let at = format!("{key}[{index}]");
        let at_s = errors.within(&format!("{at}.at_s"), point.at_s, 0.0, duration_s)?;
        let ramp = point.ramp.unwrap_or(false);
        if index == 0 && (at_s != 0.0 || ramp) {
            return Err(errors.at(&at, "the first point must be a step at t = 0"));
        }
        if points.last().is_some_and(|p| at_s <= p.at_s) {
            return Err(errors.at(&format!("{at}.at_s"), "times must increase strictly"));
        }
        // The ranges are the `target` command's (sonolube::protocol::quantity), each bound
        // fitting its field: the conversions below cannot fail.
        let unsigned = |units: i64| u32::try_from(units).unwrap_or(u32::MAX);
        let target = match (
            point.force_n,
            point.coef,
            point.reduction_pct,
            point.net_force_n,
        ) {
            (Some(v), None, None, None) => Target::Force {
                force_mn: unsigned(scaled(
                    errors,
                    &format!("{at}.force_n"),
                    v,
                    1e3,
                    (1, 50_000_000),
                )?),
            },
            (None, Some(v), None, None) => Target::Coef {
                coef_ppm: unsigned(scaled(
                    errors,
                    &format!("{at}.coef"),
                    v,
                    1e6,
                    (1, 2_000_000),
                )?),
            },
            (None, None, Some(v), None) => Target::Reduction {
                reduction_mpct: unsigned(scaled(
                    errors,
                    &format!("{at}.reduction_pct"),
                    v,
                    1e3,
                    (0, 99_999),
                )?),
            },
            (None, None, None, Some(v)) => Target::NetForce {
                force_mn: i32::try_from(scaled(
                    errors,
                    &format!("{at}.net_force_n"),
                    v,
                    1e3,
                    (-50_000_000, 50_000_000),
                )?)
                .unwrap_or(i32::MAX),
            },
            _ => {
                return Err(errors.at(
                    &at,
                    "needs exactly one of force_n, coef, reduction_pct, net_force_n",
                ));
            }
        };
        let same_kind = |p: &TargetPoint| {
            core::mem::discriminant(&p.target) == core::mem::discriminant(&target)
        };
        if ramp && !points.last().is_some_and(same_kind) {
            return Err(errors.at(
                &format!("{at}.ramp"),
                "a ramp must go between two targets of the same kind",
            ));
        }
        points.push(TargetPoint { at_s, target, ramp });
    }
    Ok(points)
}

/// `value * scale` as an exact whole number in `lo ..= hi` (the protocol's resolution).
fn scaled(
    errors: Errors<'_>,
    key: &str,
    value: f64,
    scale: f64,
    (lo, hi): (i64, i64),
) -> Result<i64, SceneError> {
    let units = value * scale;
    let rounded = units.round();
    if !units.is_finite() || (units - rounded).abs() > 1e-6 * rounded.abs().max(1.0) {
        return Err(errors.at(
            key,
            format!("{value} is finer than the resolution 1/{scale}"),
        ));
    }
    // The bounds are at most 5e7 in magnitude: exact in f64.
    if rounded < lo as f64 || rounded > hi as f64 {
        return Err(errors.at(
            key,
            format!(
                "{value} is outside {} ..= {}",
                lo as f64 / scale,
                hi as f64 / scale
            ),
        ));
    }
    // Within lo ..= hi by the check above.
    Ok(rounded as i64)
}

fn fault(
    errors: Errors<'_>,
    index: usize,
    raw: &RawFault,
    scene: &SceneDescription,
) -> Result<FaultEvent, SceneError> {
    let key = |leaf: &str| format!("faults[{index}].{leaf}");
    let at_s = errors.within(&key("at_s"), raw.at_s, 0.0, scene.duration_s)?;
    if at_s >= scene.duration_s {
        return Err(errors.at(&key("at_s"), "must be before the end of the scene"));
    }
    let channel = errors.choose(
        &key("channel"),
        &raw.channel,
        &[
            ("normal", Channel::Normal),
            ("tangential", Channel::Tangential),
        ],
    )?;
    let word = errors.choose(
        &key("kind"),
        &raw.kind,
        &[("disconnected", 0), ("stuck", 1), ("spike", 2)],
    )?;
    if word != 0 && raw.rail.is_some() {
        return Err(errors.at(&key("rail"), "only a disconnected cell has a rail"));
    }
    if word != 2 && raw.force_n.is_some() {
        return Err(errors.at(&key("force_n"), "only a spike has a force"));
    }
    let kind = match word {
        0 => FaultKind::Disconnected {
            rail: errors.choose(
                &key("rail"),
                raw.rail.as_deref().unwrap_or("high"),
                &[("low", Rail::Low), ("high", Rail::High)],
            )?,
        },
        1 => FaultKind::Stuck,
        _ => {
            let full_scale = match channel {
                Channel::Normal => scene.normal_cell.full_scale_n,
                Channel::Tangential => scene.tangential_cell.full_scale_n,
            };
            let force_n = errors.required(&key("force_n"), raw.force_n, "a spike needs it")?;
            let force_n = errors.within(
                &key("force_n"),
                force_n,
                -2.0 * full_scale,
                2.0 * full_scale,
            )?;
            if force_n == 0.0 {
                return Err(errors.at(&key("force_n"), "a spike of 0 N is no fault"));
            }
            FaultKind::Spike { force_n }
        }
    };
    let duration_s = raw
        .duration_s
        .map(|d| errors.positive(&key("duration_s"), d, scene.duration_s - at_s))
        .transpose()?;
    Ok(FaultEvent {
        at_s,
        channel,
        kind,
        duration_s,
    })
}

fn criterion(
    errors: Errors<'_>,
    index: usize,
    raw: &RawCriterion,
    duration_s: f64,
) -> Result<Criterion, SceneError> {
    let key = |leaf: &str| format!("criteria[{index}].{leaf}");
    let kinds = [
        "settle",
        "overshoot",
        "steady-rms-error",
        "tracking-error",
        "fault-reaction",
    ];
    let kind = errors.choose(&key("kind"), &raw.kind, &kinds.map(|k| (k, k)))?;
    let takes: &[&str] = match kind {
        "settle" => &["band_pct", "within_s"],
        "overshoot" => &["max_pct"],
        "fault-reaction" => &["within_periods"],
        _ => &["max_pct", "from_s", "to_s"],
    };
    let given = [
        ("band_pct", raw.band_pct.is_some()),
        ("within_s", raw.within_s.is_some()),
        ("max_pct", raw.max_pct.is_some()),
        ("from_s", raw.from_s.is_some()),
        ("to_s", raw.to_s.is_some()),
        ("within_periods", raw.within_periods.is_some()),
    ];
    for (leaf, present) in given {
        if present != takes.contains(&leaf) {
            let reason = if present {
                "not used by"
            } else {
                "missing: needed by"
            };
            return Err(errors.at(&key(leaf), format!("{reason} kind {kind}")));
        }
    }
    let pct = |leaf: &str, v: Option<f64>| errors.positive(&key(leaf), v.unwrap_or(0.0), 100.0);
    let window = || -> Result<(f64, f64), SceneError> {
        let from_s = errors.within(&key("from_s"), raw.from_s.unwrap_or(0.0), 0.0, duration_s)?;
        let to_s = errors.within(&key("to_s"), raw.to_s.unwrap_or(0.0), 0.0, duration_s)?;
        if to_s <= from_s {
            return Err(errors.at(&key("to_s"), "must be after from_s"));
        }
        Ok((from_s, to_s))
    };
    Ok(match kind {
        "settle" => Criterion::Settle {
            band_pct: pct("band_pct", raw.band_pct)?,
            within_s: errors.positive(&key("within_s"), raw.within_s.unwrap_or(0.0), duration_s)?,
        },
        "overshoot" => Criterion::Overshoot {
            max_pct: pct("max_pct", raw.max_pct)?,
        },
        "fault-reaction" => Criterion::FaultReaction {
            within_periods: raw
                .within_periods
                .and_then(|n| u32::try_from(n).ok())
                .filter(|n| (1..=100_000).contains(n))
                .ok_or_else(|| errors.at(&key("within_periods"), "must be in 1 ..= 100000"))?,
        },
        "steady-rms-error" => {
            let (from_s, to_s) = window()?;
            Criterion::SteadyRmsError {
                max_pct: pct("max_pct", raw.max_pct)?,
                from_s,
                to_s,
            }
        }
        _ => {
            let (from_s, to_s) = window()?;
            Criterion::TrackingError {
                max_pct: pct("max_pct", raw.max_pct)?,
                from_s,
                to_s,
            }
        }
    })
}
