//! Host side of Sonolube: the independent `f64` reference.
//!
//! Everything here runs on the development machine only: the reference model written from the
//! papers, never calling the fixed-point code ([`reference`]), the paper numbers it must
//! reproduce ([`papers`]), and the fixed-point evaluation the property tests and the
//! `sonolube` tool (crate `sonolube-cli`) compare with it ([`fixed_eval`]).

pub mod dahl_table;
pub mod fixed_eval;
pub mod papers;
pub mod reference;
