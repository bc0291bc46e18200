//! Whether a scene's drive can run on this board's half-bridge: its frequency in the stack's
//! band, its full-scale stack voltage within the bridge's full-scale fundamental
//! ([`config::FULL_SCALE_V`]), TIM1's timing and the stack ratings at that frequency. No
//! register is touched: [`crate::bridge::Bridge::for_scene`] runs it at `scene`, and the build
//! script runs the same code on every built-in scene for the board's scene list (`build.rs`,
//! docs/boards.md).

use sonolube::drive::{DriveError, DriveLimits, DriveTiming, Frequency};

use crate::config;

/// Why a scene's drive cannot run on this board.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum DriveRefusal {
    /// The scene's drive frequency is outside the stack's 20-60 kHz band.
    FrequencyOutOfBand {
        /// The scene's drive frequency, mHz.
        millihertz: u32,
    },
    /// The scene's full-scale stack voltage exceeds the bridge's full-scale fundamental.
    FullScaleVoltage {
        /// The scene's, V.
        scene_v: f64,
        /// The bridge's, V.
        bridge_v: f64,
    },
    /// TIM1 cannot make the timing, or the stack ratings are unusable.
    Drive(DriveError),
}

impl core::fmt::Display for DriveRefusal {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::FrequencyOutOfBand { millihertz } => write!(
                f,
                "drive frequency {} Hz outside the stack's 20-60 kHz band",
                millihertz / 1000
            ),
            Self::FullScaleVoltage { scene_v, bridge_v } => write!(
                f,
                "full-scale stack voltage {scene_v} V beyond the bridge's {bridge_v:.2} V \
                 fundamental"
            ),
            Self::Drive(error) => write!(f, "TIM1 timing or stack ratings: {error:?}"),
        }
    }
}

/// The drive of a scene that fits the bridge.
pub struct DriveFit {
    /// The drive frequency, rounded to the mHz.
    pub frequency: Frequency,
    /// The scene's full-scale stack voltage over the bridge's, in (0, 1].
    pub ratio: f64,
    /// TIM1's timing at the frequency.
    pub timing: DriveTiming,
    /// The stack ratings on this bridge.
    pub limits: DriveLimits,
}

/// The drive of a scene whose drive runs at `drive_hz` with `full_scale_voltage_v` on the stack
/// at full command, or why it cannot run here (`f64`, once per scene).
pub fn drive_fit(drive_hz: f64, full_scale_voltage_v: f64) -> Result<DriveFit, DriveRefusal> {
    // `as` saturates (and maps NaN to 0), which the band check then refuses.
    let frequency = Frequency::from_millihertz((drive_hz * 1000.0 + 0.5) as u32);
    if !frequency.in_band() {
        return Err(DriveRefusal::FrequencyOutOfBand {
            millihertz: frequency.millihertz(),
        });
    }
    let ratio = full_scale_voltage_v / config::FULL_SCALE_V;
    if !(ratio > 0.0 && ratio <= 1.0) {
        return Err(DriveRefusal::FullScaleVoltage {
            scene_v: full_scale_voltage_v,
            bridge_v: config::FULL_SCALE_V,
        });
    }
    let timing = config::TIMING
        .retune(frequency)
        .map_err(DriveRefusal::Drive)?;
    let limits =
        DriveLimits::new(&config::STACK, config::FULL_SCALE_V).map_err(DriveRefusal::Drive)?;
    Ok(DriveFit {
        frequency,
        ratio,
        timing,
        limits,
    })
}
