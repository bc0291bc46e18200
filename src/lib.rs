//! Sonolube pure logic: everything that does not touch hardware.
//!
//! `no_std`, no heap, no HAL imports. The same code runs in the firmware (boards in `board/`)
//! and on the host (unit tests here, integration tests and tools in `host-tests/`).
#![cfg_attr(not(test), no_std)]
#![forbid(unsafe_code)]
#![deny(missing_docs)]

pub mod commission;
pub mod control;
pub mod drive;
pub mod ext_adc;
pub mod fx;
pub mod model;
pub mod protocol;
pub mod resonance;
pub mod scene;
pub mod selfcheck;
pub mod sense;
pub mod settings;
pub mod stage;
pub mod station;
pub mod variant;
