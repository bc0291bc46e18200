//! Scenes: named operating scenarios, compiled into the firmware and loadable on the host.
//!
//! A [`Scene`] holds everything a closed-loop run needs: the materials and surface, the
//! actuator, the horn geometry and contact position, the resonant transducer, the load cells,
//! the profiles of normal load, sliding velocity and target over time, the sensor faults to
//! inject, the controller's model and the plant's (higher-fidelity) model with their own
//! parameters, the mismatch between them, the accuracy it needs, its pass criteria and what it
//! contains (vibration components, load and velocity ranges).
//!
//! Scenes are written in `scenes/*.toml` (schema: `scenes/README.md`). The build script reads
//! them with the `scene-toml` crate and compiles every one in as `static` data
//! ([`builtin::SCENES`], [`find`]); the host loads any file into the same type. Every slice and
//! string is borrowed (`'static` for the built-in scenes), so a scene lives in flash and costs
//! no RAM.
//!
//! # Numbers
//!
//! Scalars and table entries are SI `f64`, exactly the values of the file: the model constants
//! are built from them in `f64` once per scene (see [`crate::model`]). The per-step evaluation
//! of the profiles ([`interpolate`], [`target_at`]) is in `f32`, the plant's format.

pub mod builtin;
pub mod feasibility;
mod table;
mod types;

pub use builtin::{SCENE_NAMES, SCENES, compiled, cube_table_nodes, find};
// The plain scene types, defined once in `sonolube-scene-types` and shared with the scene-file
// loader (`scene-toml`), which reads them on the host and writes them for the build script.
pub use sonolube_scene_types::CONTROL_RATE_RANGE_HZ;
pub use sonolube_scene_types::{
    Accuracy, Actuator, ActuatorKind, Breakpoint, Channel, Contents, Criterion, FaultEvent,
    FaultKind, Horn, LoadCell, Mismatch, ModelKind, ModelSpec, Rail, ResonanceShift, RoughSurface,
    Stack, System, TargetPoint, Transducer,
};
pub use table::{interpolate, target_at};
pub use types::{Scene, in_build};
