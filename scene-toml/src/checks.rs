//! The checks that need several sections of a scene at once: profiles against contents and
//! sensor ranges, vibration components against the hardware, criteria against faults and
//! targets, the accuracy against the criteria.

use crate::error::{Errors, SceneError};
use crate::types::{Breakpoint, Criterion, ModelKind, SceneDescription};

/// Natural (undriven) friction coefficient the plant can show at its most: mu_s for the
/// exponential law (seed 002 eq 10 at zero slip), mu otherwise.
pub fn plant_peak_coefficient(scene: &SceneDescription) -> f64 {
    match scene.plant.kind {
        ModelKind::ExpCoulomb => scene.plant.mu_static.unwrap_or(scene.plant.mu),
        _ => scene.plant.mu,
    }
}

pub(crate) fn cross_checks(errors: Errors<'_>, scene: &SceneDescription) -> Result<(), SceneError> {
    let extent = |points: &[Breakpoint]| {
        points
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p.value), hi.max(p.value))
            })
    };
    let contents = &scene.contents;
    let (load_lo, load_hi) = extent(&scene.normal_load_n);
    if load_lo < contents.load_min_n || load_hi > contents.load_max_n {
        return Err(errors.at(
            "contents.load_range_n",
            format!("does not contain the load profile's range [{load_lo}, {load_hi}] N"),
        ));
    }
    let (v_lo, v_hi) = extent(&scene.sliding_velocity_m_per_s);
    if v_lo < contents.velocity_min_m_per_s || v_hi > contents.velocity_max_m_per_s {
        return Err(errors.at(
            "contents.velocity_range_m_per_s",
            format!("does not contain the velocity profile's range [{v_lo}, {v_hi}] m/s"),
        ));
    }
    // Vibration components follow from the hardware: a horn adds the vertical (Poisson)
    // component and has a longitudinal one except exactly at its node (seed 000 eqs 16-17);
    // a stack vibrates along the sliding direction only (seed 003 eq 2).
    let (tangential, normal) = match &scene.horn {
        // A block travelling through the motor regions leaves the node (issue 27).
        Some(horn) => (horn.contact_position_m != 0.0 || horn.motor_regions, true),
        None => (true, false),
    };
    if contents.tangential_vibration != tangential || contents.normal_vibration != normal {
        return Err(errors.at(
            "contents.vibration",
            format!(
                "the hardware gives tangential = {tangential}, normal = {normal} \
                 (a horn adds normal vibration; at its node, x = 0, there is no tangential one)"
            ),
        ));
    }
    let friction_peak = plant_peak_coefficient(scene) * load_hi;
    if friction_peak >= scene.tangential_cell.full_scale_n {
        return Err(errors.at(
            "sensors.tangential.full_scale_n",
            format!("the natural friction reaches {friction_peak} N, beyond the cell's range"),
        ));
    }
    if scene.criteria.is_empty() {
        return Err(errors.at("criteria", "a scene needs at least one criterion"));
    }
    let has_reaction = scene
        .criteria
        .iter()
        .any(|c| matches!(c, Criterion::FaultReaction { .. }));
    let has_faults = !scene.faults.is_empty();
    if has_reaction != has_faults {
        return Err(errors.at(
            "criteria",
            "a scene has a fault-reaction criterion exactly when it injects faults",
        ));
    }
    let has_step = scene
        .target
        .windows(2)
        .any(|w| !w[1].ramp && w[1].target != w[0].target);
    let needs_step = scene
        .criteria
        .iter()
        .any(|c| matches!(c, Criterion::Settle { .. } | Criterion::Overshoot { .. }));
    if needs_step && !has_step {
        return Err(errors.at("criteria", "settle and overshoot need a target step"));
    }
    let tightest = scene
        .criteria
        .iter()
        .filter_map(|c| match *c {
            Criterion::Settle { band_pct, .. } => Some(band_pct),
            Criterion::SteadyRmsError { max_pct, .. }
            | Criterion::TrackingError { max_pct, .. } => Some(max_pct),
            _ => None,
        })
        .fold(f64::INFINITY, f64::min);
    if tightest.is_finite() && scene.accuracy.friction_pct != tightest {
        return Err(errors.at(
            "accuracy.friction_pct",
            format!("must equal the tightest band of the criteria, {tightest} %"),
        ));
    }
    Ok(())
}
