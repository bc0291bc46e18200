//! The bench calibration of the two load cells before a run: the protocol's `tare` (no load on
//! the cell) and `cal <axis> <newtons>` (a known load on it), done on simulated cells.
//!
//! A scene's cells read with an offset and a gain error that only the plant knows
//! (`sonolube::scene::LoadCell`): the datasheet calibration leaves them in every reading, so a
//! coefficient or force target would be held off by them (the `load-ramp` cells, 0.3 N and
//! 0.5 % on the normal cell, -0.2 N and -0.5 % on the tangential one, make 2.5 % at 40 N).
//! Commissioning removes them the way an operator does: a burst of samples with the cell
//! unloaded sets the zero, a burst under a known weight sets the span. The samples come from
//! the scene's own cell model ([`LoadCellSim`]: gain and offset error, noise, quantisation)
//! with a noise generator of their own, so a run stays deterministic and its plant noise is
//! untouched.

use crate::plant::{Gaussian, LoadCellSim};
use sonolube::fx::Q16_16;
use sonolube::scene::LoadCell;
use sonolube::sense::{AdcCode, SensorChannel};

use super::SimError;

/// How the cells are calibrated before a run.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum CellCalibration {
    /// Datasheet calibration only: the cells' offsets and gain errors stay in the readings.
    Nominal,
    /// `tare`, then `cal` with a known load, each averaging [`COMMISSIONING_SAMPLES`] samples.
    Commissioned {
        /// The known load, fraction of the cell's full scale, (0, 1).
        known_load_of_full_scale: f64,
    },
}

/// The runs' default: commissioned with a weight of half the cell's full scale.
pub const COMMISSIONED: CellCalibration = CellCalibration::Commissioned {
    known_load_of_full_scale: 0.5,
};

/// Samples averaged by the tare and by the known-load calibration: the station's.
pub use sonolube::station::COMMISSIONING_SAMPLES;

/// Seed offset of the commissioning noise from the scene's plant noise seed.
const SEED_OFFSET: u64 = 0xCA1B_0000_0000_0001;

/// Calibrates `channel` of `cell` per `calibration`; `channel_index` (0 normal, 1 tangential)
/// separates the two cells' noise. Errors: `Calibration` if the known load does not fit a
/// `cal` command or moves the reading too little.
pub fn commission(
    channel: &mut SensorChannel,
    cell: &LoadCell,
    calibration: CellCalibration,
    noise_seed: u64,
    channel_index: u64,
) -> Result<(), SimError> {
    let CellCalibration::Commissioned {
        known_load_of_full_scale,
    } = calibration
    else {
        return Ok(());
    };
    if !(known_load_of_full_scale > 0.0 && known_load_of_full_scale < 1.0) {
        return Err(SimError::Calibration);
    }
    let mut noise = Gaussian::from_seed(
        noise_seed
            .wrapping_add(SEED_OFFSET)
            .wrapping_add(channel_index.wrapping_mul(0x9E37_79B9_7F4A_7C15)),
    );
    // A cell settled on its load: the substep only sets the filter, which does not move.
    let mut burst = |force_n: f32| {
        let mut cell_sim = LoadCellSim::new(cell, 1e-4, force_n);
        let mut codes = [AdcCode::default(); COMMISSIONING_SAMPLES];
        for code in &mut codes {
            *code = cell_sim.sample(&mut noise, None);
        }
        codes
    };
    channel
        .tare(&burst(0.0))
        .map_err(|_| SimError::Calibration)?;
    // The `cal` command's resolution is 1 mN.
    let load_n = libm::round(known_load_of_full_scale * cell.full_scale_n * 1e3) / 1e3;
    let load = Q16_16::from_f64(load_n).map_err(|_| SimError::Calibration)?;
    channel
        .calibrate_gain(&burst(load_n as f32), load)
        .map_err(|_| SimError::Calibration)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sensor_channel;
    use sonolube::scene::{LoadCell, find};

    /// Mean force over 2000 samples of a cell settled at `force_n` through `channel`.
    fn mean_reading(channel: &mut SensorChannel, cell: &LoadCell, force_n: f32) -> f64 {
        let mut sim = LoadCellSim::new(cell, 1e-4, force_n);
        let mut noise = Gaussian::from_seed(77);
        let n = 2000;
        let sum: f64 = (0..n)
            .map(|_| {
                let code = sim.sample(&mut noise, None);
                channel.process(code).expect("healthy").value.to_f64()
            })
            .sum();
        sum / f64::from(n)
    }

    #[test]
    fn commissioning_removes_the_cells_offset_and_gain_error() {
        let scene = find("load-ramp").expect("built in");
        let cell = scene.normal_cell;
        let mut nominal = sensor_channel(&cell).expect("channel");
        commission(&mut nominal, &cell, CellCalibration::Nominal, 1, 0).expect("nominal");
        let mut calibrated = sensor_channel(&cell).expect("channel");
        commission(&mut calibrated, &cell, COMMISSIONED, 1, 0).expect("commissioned");
        // The cell reads 1.005 x F + 0.3 N with the datasheet calibration.
        let raw = mean_reading(&mut nominal, &cell, 40.0);
        assert!((raw - 40.5).abs() < 0.05, "{raw}");
        for force in [40.0, 140.0, 240.0] {
            let read = mean_reading(&mut calibrated, &cell, force);
            // 0.03 % of 300 N from each burst's noise, 0.02 N from the test's own.
            assert!((read - f64::from(force)).abs() < 0.2, "{force}: {read}");
        }
    }

    #[test]
    fn the_tare_measures_the_noise_the_scene_declares() {
        let scene = find("reference").expect("built in");
        for (index, cell) in [scene.normal_cell, scene.tangential_cell]
            .iter()
            .enumerate()
        {
            for factor in [1.0, 4.0] {
                let noisy = LoadCell {
                    noise_rms_pct_fs: cell.noise_rms_pct_fs * factor,
                    ..*cell
                };
                let mut channel = sensor_channel(&noisy).expect("channel");
                commission(&mut channel, &noisy, COMMISSIONED, 7, index as u64)
                    .expect("commissioned");
                let measured = channel.noise().expect("tared").to_f64();
                let declared = noisy.noise_rms_pct_fs / 100.0 * noisy.full_scale_n;
                // 256 samples: the RMS of a burst is within 3 standard errors,
                // 3 / sqrt(2 x 256) = 13 %, of the cell's (quantisation adds lsb^2 / 12).
                assert!(
                    (measured / declared - 1.0).abs() < 0.13,
                    "cell {index} x{factor}: {measured} against {declared}"
                );
            }
        }
    }

    #[test]
    fn an_impossible_known_load_is_refused() {
        let scene = find("reference").expect("built in");
        let cell = scene.tangential_cell;
        let mut channel = sensor_channel(&cell).expect("channel");
        let heavy = CellCalibration::Commissioned {
            known_load_of_full_scale: 1.5,
        };
        assert_eq!(
            commission(&mut channel, &cell, heavy, 1, 1),
            Err(SimError::Calibration)
        );
    }
}
