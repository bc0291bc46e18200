//! The speed-versus-accuracy measurement (issue 7): `sonolube speed`.
//!
//! From the QEMU benchmark build's instruction counts ([`qemu`]), the errors of every variant
//! against the independent `f64` reference over fixed grids ([`errors`], [`reference`]) and
//! host timings as ratios to `f64` ([`timing`]), it writes `docs/speed.md` ([`markdown`]),
//! `docs/speed.svg` ([`svg`]) and the firmware's `src/variant/table.rs` ([`table_rs`]), with
//! the Pareto analysis of [`fronts`]. `scripts/speed-table` runs the whole chain.

pub mod errors;
pub mod fronts;
pub mod markdown;
pub mod qemu;
pub mod reference;
pub mod svg;
pub mod table_rs;
pub mod timing;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The generated files, relative to the repository root.
pub const MARKDOWN: &str = "docs/speed.md";
/// The plot.
pub const SVG: &str = "docs/speed.svg";
/// The firmware's table.
pub const TABLE: &str = "src/variant/table.rs";
/// The QEMU log the counts come from (written by `scripts/speed-table`).
pub const QEMU_LOG: &str = "docs/speed-qemu.txt";

/// The repository root (the host crate's parent directory).
pub fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map_or_else(|| PathBuf::from(".."), Path::to_path_buf)
}

/// The three generated files.
#[derive(Debug, Clone, PartialEq)]
pub struct Outputs {
    /// `docs/speed.md`.
    pub markdown: String,
    /// `docs/speed.svg`.
    pub svg: String,
    /// `src/variant/table.rs`.
    pub table_rs: String,
}

impl Outputs {
    /// (relative path, contents) of each file.
    pub fn files(&self) -> [(&'static str, &str); 3] {
        [
            (MARKDOWN, &self.markdown),
            (SVG, &self.svg),
            (TABLE, &self.table_rs),
        ]
    }
}

/// Everything measured in one run but the host times.
#[derive(Debug, Clone)]
pub struct Run {
    /// Instruction counts from the QEMU log.
    pub counts: qemu::Counts,
    /// Errors against the reference.
    pub errors: errors::Errors,
    /// Pareto sets.
    pub sets: Vec<fronts::Set>,
    /// The selection's view of the measurements.
    pub measured: sonolube::variant::select::Measurements,
}

impl Run {
    /// Parses the QEMU log and measures the errors. Errors: a log without every count, or an
    /// error measurement that fails (messages).
    pub fn new(qemu_log: &str) -> Result<Self, String> {
        let counts = qemu::parse(qemu_log)?;
        let errors = errors::measure()?;
        Ok(Self {
            sets: fronts::sets(&errors, &counts),
            measured: table_rs::measurements(&errors, &counts),
            counts,
            errors,
        })
    }

    /// The files, with these host-time ratios (variant name to ratio).
    pub fn outputs(&self, host_ratios: &BTreeMap<String, f64>) -> Outputs {
        let markdown = markdown::Report {
            counts: &self.counts,
            host_ratios,
            errors: &self.errors,
            sets: &self.sets,
            measured: &self.measured,
        }
        .render();
        Outputs {
            markdown,
            svg: svg::render(&self.errors, &self.counts),
            table_rs: table_rs::render(&self.errors, &self.counts),
        }
    }
}

/// Generates every file from a QEMU log and host-time ratios (variant name to ratio).
/// Errors: as [`Run::new`].
pub fn generate(qemu_log: &str, host_ratios: &BTreeMap<String, f64>) -> Result<Outputs, String> {
    Ok(Run::new(qemu_log)?.outputs(host_ratios))
}
