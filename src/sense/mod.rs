//! Sensing: ADC codes to newtons and amperes, with calibration and sensor fault detection.
//!
//! The chain for every channel, internal or external converter alike:
//! 1. [`AdcFormat::normalize`]: the raw code (a 16-bit word from the G4 ADC's hardware
//!    oversampler, a 24-bit word from the ADS131M02) becomes a Q1.31 fraction of full scale, so
//!    nothing downstream depends on word width or oversampling;
//! 2. [`FaultMonitor::check`]: rail (disconnected), stuck and jump checks on that fraction;
//! 3. [`Calibration::apply`]: `(reading - offset) * span`, Q16.16 newtons or amperes, with the
//!    offset from a tare and the span from a known load ([`Calibration::with_known_load`]) or
//!    from the front end's data ([`ShuntAmplifier`], [`BridgeAmplifier`]).
//!
//! [`SensorChannel`] bundles the three. Everything per sample is integer arithmetic.

mod calibration;
mod channel;
mod error;
mod fault;
mod format;
mod front_end;

pub use calibration::{Calibration, mean};
pub use channel::{SampleError, SensorChannel};
pub use error::SenseError;
pub use fault::{FaultLimits, FaultMonitor, SensorFault};
pub use format::{AdcCode, AdcFormat, Oversampling};
pub use front_end::{BridgeAmplifier, ShuntAmplifier};
