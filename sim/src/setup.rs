//! What a closed-loop run builds from its scene: the two load-cell channels of the scene's cells
//! (converter format, fault checks, the datasheet calibration that [`super::commission`] then
//! refines) and the firmware's station on them.
//!
//! Everything here is configuration, `f64`, once per run.

use sonolube::control::Settings;
use sonolube::fx::{Q1_31, Q16_16};
use sonolube::scene::{LoadCell, Scene};
use sonolube::sense::{AdcFormat, Calibration, FaultLimits, SensorChannel};
use sonolube::station::Station;

use super::SimError;

/// Consecutive identical readings that make a cell count as stuck: 2 ms at 10 kHz. A live
/// cell with at least one converter step of noise RMS repeats its code with a probability
/// below 0.3 per sample, so a run of 20 starts about once in 1e10 samples (0.3^19); the
/// scenes allow 50 periods for a stuck cell.
pub const STUCK_SAMPLES: u32 = 20;

/// Least noise, in converter steps RMS, for the stuck check: a quieter cell may hold one code
/// honestly, so the check is off (a scene with quiet cells cannot detect a stuck one).
pub const STUCK_MIN_NOISE_STEPS: f64 = 1.0;

/// Largest plausible change of a reading between two samples, fraction of the converter
/// span (a quarter: half the cell's full-scale force). A friction change is bounded by the
/// vibration envelope (a few % of full scale per period) and a load change by the profiles,
/// so a larger jump is a glitch (`scenes/sensor-spike.toml`: 1.5 N on a 2 N cell is 0.375).
pub const MAX_STEP_OF_SPAN: f64 = 0.25;

/// The converter format of `cell`: unipolar, `adc_bits` bits, zero force at mid-scale.
pub fn cell_format(cell: &LoadCell) -> Result<AdcFormat, SimError> {
    AdcFormat::unipolar(cell.adc_bits).map_err(SimError::Sense)
}

/// The fault checks of `cell`: a code within one step of either end is the rail, a jump of more
/// than [`MAX_STEP_OF_SPAN`] is a glitch, [`STUCK_SAMPLES`] identical codes are a stuck
/// reading (off below [`STUCK_MIN_NOISE_STEPS`] of noise).
pub fn fault_limits(cell: &LoadCell) -> FaultLimits {
    let step_bits = 1i32 << (31 - u32::from(cell.adc_bits.clamp(1, 31)));
    // Noise in converter steps: (pct / 100) FS / (FS / zero code).
    let noise_steps = cell.noise_rms_pct_fs / 100.0 * f64::from(cell.zero_code());
    FaultLimits {
        rail_margin: Q1_31::from_bits(step_bits),
        noise_band: Q1_31::ZERO,
        stuck_samples: if noise_steps >= STUCK_MIN_NOISE_STEPS {
            STUCK_SAMPLES
        } else {
            0
        },
        max_step: Q1_31::from_f64_saturating(MAX_STEP_OF_SPAN).value,
    }
}

/// The datasheet calibration of `cell`: zero at mid-scale, `2 x full_scale_n` newtons per
/// converter span. The cell's actual offset and gain error (which only the plant knows) stay
/// in the readings. Error `Calibration` when the span does not fit Q16.16 (full scale above
/// 16 383 N).
pub fn nominal_calibration(cell: &LoadCell) -> Result<Calibration, SimError> {
    let span = Q16_16::from_f64(2.0 * cell.full_scale_n).map_err(|_| SimError::Calibration)?;
    Ok(Calibration::new(Q1_31::from_bits(1 << 30), span))
}

/// The channel of `cell`: its format, fault checks and nominal calibration.
pub fn sensor_channel(cell: &LoadCell) -> Result<SensorChannel, SimError> {
    Ok(SensorChannel::new(
        cell_format(cell)?,
        fault_limits(cell),
        nominal_calibration(cell)?,
    ))
}

/// The firmware's station of `scene` on the scene's simulated cells ([`sensor_channel`]), with
/// the controller `settings` (normally [`sonolube::control::controller_settings`]).
pub fn scene_station(scene: &Scene<'_>, settings: &Settings) -> Result<Station, SimError> {
    let normal = sensor_channel(&scene.normal_cell)?;
    let tangential = sensor_channel(&scene.tangential_cell)?;
    Ok(Station::new(scene, settings, normal, tangential)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use sonolube::scene::find;

    #[test]
    fn the_nominal_calibration_reads_mid_scale_as_zero_and_the_top_code_as_full_scale() {
        let scene = find("reference").expect("built in");
        let mut channel = sensor_channel(&scene.tangential_cell).expect("channel");
        let zero = channel
            .process(sonolube::sense::AdcCode::new(2048))
            .expect("healthy")
            .value
            .to_f64();
        assert_eq!(zero, 0.0);
        let high = channel
            .process(sonolube::sense::AdcCode::new(3072))
            .expect("healthy")
            .value
            .to_f64();
        assert!((high - 1.0).abs() < 1e-4, "{high}");
        assert!(
            channel
                .process(sonolube::sense::AdcCode::new(4095))
                .is_err()
        );
        let huge = LoadCell {
            full_scale_n: 20_000.0,
            ..scene.tangential_cell
        };
        assert_eq!(nominal_calibration(&huge), Err(SimError::Calibration));
    }

    #[test]
    fn the_stuck_check_needs_a_noisy_cell() {
        let scene = find("reference").expect("built in");
        assert_eq!(
            fault_limits(&scene.normal_cell).stuck_samples,
            STUCK_SAMPLES
        );
        let quiet = LoadCell {
            noise_rms_pct_fs: 0.01,
            ..scene.normal_cell
        };
        assert_eq!(fault_limits(&quiet).stuck_samples, 0);
    }
}
