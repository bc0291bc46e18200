//! Between a [`Station`] and a [`Record`]: what to save from a running station, and how to put
//! a record into one, whole or not at all.

use super::record::{AxisCal, Record};
use crate::commission::CommissionResult;
use crate::fx::{Q1_31, Q16_16};
use crate::protocol::{Axis, Command, ProtocolError};
use crate::sense::Calibration;
use crate::station::{CellBench, Station};

fn axis_cal(calibration: Calibration) -> AxisCal {
    AxisCal {
        offset_q31: calibration.offset().to_bits(),
        span_q16: calibration.span().to_bits(),
    }
}

/// The record of `station` running `scene`: both cells' calibrations, the target and the
/// drive frequency as they are now; `cal_count` as given (the board counts calibrations).
pub fn capture(station: &Station, scene: &str, cal_count: u32) -> Record {
    let (normal, tangential) = station.calibrations();
    Record {
        scene: crate::protocol::SceneName::new(scene),
        normal: Some(axis_cal(normal)),
        tangential: Some(axis_cal(tangential)),
        cal_count,
        target: station.controller().target(),
        freq_chz: Some(station.drive_freq_chz()),
    }
}

/// A bench that is never read: `freq` takes no samples.
struct NoBench;

impl CellBench for NoBench {
    fn burst(&mut self, _axis: Axis, _load_n: f32, _codes: &mut [crate::sense::AdcCode]) -> bool {
        false
    }
}

/// Puts `record`'s calibrations, drive frequency and target into `station`, which the caller
/// has just built for the record's scene (so its fields at `None` are already the scene's
/// own), then the `commissioned` values saved with it
/// ([`Station::apply_commissioned`]: the loop runs on them, f0 replacing the record's drive
/// frequency). All or nothing: on an error `station` is unchanged.
pub fn apply(
    station: &mut Station,
    record: &Record,
    commissioned: Option<&CommissionResult>,
) -> Result<(), ProtocolError> {
    let mut next = station.clone();
    let (normal, tangential) = next.channels_mut();
    for (channel, cal) in [(normal, record.normal), (tangential, record.tangential)] {
        if let Some(cal) = cal {
            channel.set_calibration(Calibration::new(
                Q1_31::from_bits(cal.offset_q31),
                Q16_16::from_bits(cal.span_q16),
            ));
        }
    }
    if let Some(freq_chz) = record.freq_chz {
        next.execute(&Command::Freq { freq_chz }, &mut NoBench)?;
    }
    if let Some(result) = commissioned {
        next.apply_commissioned(result)
            .map_err(|_| ProtocolError::SettingsInvalid {
                reason: "commissioning-refused-by-controller",
            })?;
    }
    if let Some(target) = record.target {
        next.execute(&Command::Target(target), &mut NoBench)?;
    }
    *station = next;
    Ok(())
}
