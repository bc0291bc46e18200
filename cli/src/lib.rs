//! The `sonolube` command-line tool's building blocks (the binary is `src/main.rs`).
//!
//! Host only: the subcommands ([`commands`]: `eval`, `monitor`, `papers`, `scene`, `speed`),
//! the firmware monitor ([`monitor`]), SVG plots ([`plot`]), scene files loaded at run time
//! ([`scene_file`]) and the speed-versus-accuracy table ([`speed`]). The `f64` reference comes
//! from `sonolube-host`, the scene runs from `sonolube-sim`.

pub mod commands;
pub mod monitor;
pub mod plot;
pub mod scene_file;
pub mod speed;
