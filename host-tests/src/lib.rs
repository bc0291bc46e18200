//! Host side of Sonolube.
//!
//! Everything here runs on the development machine only: the independent f64 reference
//! model (written from the papers, never calling the fixed-point code), and the
//! command-line tool's building blocks.

pub mod cli;
pub mod dahl_table;
pub mod fixed_eval;
pub mod monitor;
pub mod papers;
pub mod plot;
pub mod reference;
pub mod scene_file;
pub mod speed;
