//! The hardware sections of a scene file: transducer, actuator, horn and load cells.

use crate::error::{Errors, SceneError};
use crate::raw::{RawActuator, RawCell, RawHorn, RawShift, RawTransducer};
use crate::types::{Actuator, ActuatorKind, Horn, LoadCell, ResonanceShift, Stack, Transducer};
use crate::validate::{DEFAULT_ADC_BITS, DRIVE_RANGE_HZ};

pub(crate) fn transducer(
    errors: Errors<'_>,
    raw: &RawTransducer,
    duration_s: f64,
) -> Result<Transducer, SceneError> {
    let (lo, hi) = DRIVE_RANGE_HZ;
    let resonance_hz = errors.within("transducer.resonance_hz", raw.resonance_hz, lo, hi)?;
    let drift_hz_per_s = errors.within(
        "transducer.drift_hz_per_s",
        raw.drift_hz_per_s.unwrap_or(0.0),
        -1e4,
        1e4,
    )?;
    let end_hz = resonance_hz + drift_hz_per_s * duration_s;
    if !(lo..=hi).contains(&end_hz) {
        return Err(errors.at(
            "transducer.drift_hz_per_s",
            format!("the resonance drifts to {end_hz} Hz, outside {lo} ..= {hi} Hz"),
        ));
    }
    Ok(Transducer {
        resonance_hz,
        quality_factor: errors.within("transducer.quality_factor", raw.quality_factor, 1.0, 1e4)?,
        drift_hz_per_s,
        drive_hz: errors.within(
            "transducer.drive_hz",
            raw.drive_hz.unwrap_or(resonance_hz),
            lo,
            hi,
        )?,
        clamped_capacitance_f: errors.positive(
            "transducer.clamped_capacitance_f",
            raw.clamped_capacitance_f,
            1e-3,
        )?,
        motional_resistance_ohm: errors.positive(
            "transducer.motional_resistance_ohm",
            raw.motional_resistance_ohm,
            1e5,
        )?,
        shift: shift(errors, raw.shift.as_ref())?,
    })
}

fn shift(errors: Errors<'_>, raw: Option<&RawShift>) -> Result<ResonanceShift, SceneError> {
    let Some(raw) = raw else {
        return Ok(ResonanceShift {
            thermal_per_k: 0.0,
            thermal_resistance_k_per_w: 0.0,
            thermal_time_constant_s: 1.0,
            load_per_n: 0.0,
            bvd_envelope: false,
            freq_auto: false,
        });
    };
    if raw.freq_auto == Some(true) && raw.bvd_envelope != Some(true) {
        return Err(errors.at(
            "transducer.shift.freq_auto",
            "freq_auto needs bvd_envelope = true (only that plant samples its drive current)",
        ));
    }
    Ok(ResonanceShift {
        thermal_per_k: errors.within(
            "transducer.shift.thermal_per_k",
            raw.thermal_per_k.unwrap_or(0.0),
            -1e-2,
            1e-2,
        )?,
        thermal_resistance_k_per_w: errors.within(
            "transducer.shift.thermal_resistance_k_per_w",
            raw.thermal_resistance_k_per_w.unwrap_or(0.0),
            0.0,
            1e3,
        )?,
        thermal_time_constant_s: errors.positive(
            "transducer.shift.thermal_time_constant_s",
            raw.thermal_time_constant_s.unwrap_or(1.0),
            1e4,
        )?,
        load_per_n: errors.within(
            "transducer.shift.load_per_n",
            raw.load_per_n.unwrap_or(0.0),
            -1e-2,
            1e-2,
        )?,
        bvd_envelope: raw.bvd_envelope.unwrap_or(false),
        freq_auto: raw.freq_auto.unwrap_or(false),
    })
}

pub(crate) fn actuator(
    errors: Errors<'_>,
    raw: &RawActuator,
    transducer: &Transducer,
) -> Result<Actuator, SceneError> {
    let kind = errors.choose(
        "actuator.kind",
        &raw.kind,
        &[
            ("pmn-pt-stack", ActuatorKind::PmnPtStack),
            ("welding-converter", ActuatorKind::WeldingConverter),
        ],
    )?;
    let max_voltage_v = errors.positive("actuator.max_voltage_v", raw.max_voltage_v, 1e4)?;
    let max_current_a = errors.positive("actuator.max_current_a", raw.max_current_a, 1e3)?;
    let full_scale_voltage_v = errors.positive(
        "actuator.full_scale_voltage_v",
        raw.full_scale_voltage_v,
        max_voltage_v,
    )?;
    // At resonance the motional branch is R1 alone: |Y| = |1/R1 + j w0 C0| (seed 003 Table 1
    // gives I_max; the drive must not exceed it at full command).
    let omega = std::f64::consts::TAU * transducer.resonance_hz;
    let conductance = 1.0 / transducer.motional_resistance_ohm;
    let susceptance = omega * transducer.clamped_capacitance_f;
    let current_a = full_scale_voltage_v * conductance.hypot(susceptance);
    if current_a > max_current_a {
        return Err(errors.at(
            "actuator.full_scale_voltage_v",
            format!("draws {current_a:.3} A at resonance, above max_current_a = {max_current_a} A"),
        ));
    }
    let stack = match &raw.stack {
        None if kind == ActuatorKind::PmnPtStack => {
            return Err(errors.at("actuator.stack", "missing: a pmn-pt-stack needs it"));
        }
        None => None,
        Some(stack) => Some(Stack {
            discs: u16::try_from(stack.discs)
                .ok()
                .filter(|n| *n >= 1)
                .ok_or_else(|| {
                    errors.at(
                        "actuator.stack.discs",
                        format!("{} is outside 1 ..= 65535", stack.discs),
                    )
                })?,
            d33_m_per_v: errors.positive("actuator.stack.d33_m_per_v", stack.d33_m_per_v, 1e-8)?,
            stiffness_n_per_m: errors.positive(
                "actuator.stack.stiffness_n_per_m",
                stack.stiffness_n_per_m,
                1e12,
            )?,
            bolt_stiffness_n_per_m: errors.within(
                "actuator.stack.bolt_stiffness_n_per_m",
                stack.bolt_stiffness_n_per_m,
                0.0,
                1e12,
            )?,
        }),
    };
    Ok(Actuator {
        kind,
        full_scale_voltage_v,
        full_scale_amplitude_m: errors.positive(
            "actuator.full_scale_amplitude_m",
            raw.full_scale_amplitude_m,
            1e-4,
        )?,
        max_voltage_v,
        max_current_a,
        stack,
    })
}

pub(crate) fn horn(errors: Errors<'_>, raw: &RawHorn) -> Result<Horn, SceneError> {
    let length_m = errors.positive("horn.length_m", raw.length_m, 1.0)?;
    Ok(Horn {
        length_m,
        width_m: errors.positive("horn.width_m", raw.width_m, 1.0)?,
        thickness_m: errors.positive("horn.thickness_m", raw.thickness_m, 1.0)?,
        vertical_amplitude_m: errors.positive(
            "horn.vertical_amplitude_m",
            raw.vertical_amplitude_m,
            1e-4,
        )?,
        contact_position_m: errors.within(
            "horn.contact_position_m",
            raw.contact_position_m,
            -0.5 * length_m,
            0.5 * length_m,
        )?,
        motor_regions: raw.motor_regions.unwrap_or(false),
    })
}

pub(crate) fn cell(errors: Errors<'_>, table: &str, raw: &RawCell) -> Result<LoadCell, SceneError> {
    let key = |leaf: &str| format!("{table}.{leaf}");
    let full_scale_n = errors.positive(&key("full_scale_n"), raw.full_scale_n, 5e4)?;
    let adc_bits = match raw.adc_bits {
        None => DEFAULT_ADC_BITS,
        Some(bits) => u8::try_from(bits)
            .ok()
            .filter(|b| (8..=16).contains(b))
            .ok_or_else(|| errors.at(&key("adc_bits"), format!("{bits} is outside 8 ..= 16")))?,
    };
    Ok(LoadCell {
        full_scale_n,
        bandwidth_hz: errors.positive(&key("bandwidth_hz"), raw.bandwidth_hz, 1e6)?,
        offset_n: errors.within(
            &key("offset_n"),
            raw.offset_n.unwrap_or(0.0),
            -0.1 * full_scale_n,
            0.1 * full_scale_n,
        )?,
        gain_error: errors.within(&key("gain_error"), raw.gain_error.unwrap_or(0.0), -0.2, 0.2)?,
        noise_rms_pct_fs: errors.within(
            &key("noise_rms_pct_fs"),
            raw.noise_rms_pct_fs,
            0.0,
            10.0,
        )?,
        adc_bits,
    })
}
