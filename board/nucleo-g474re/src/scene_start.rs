//! The built-in scenes as the board holds them, written by the build script (`build.rs`,
//! [`BOARD_SCENES`]): for each, what the bridge's check reads and, for a scene the bridge can
//! drive, the scene's record ([`SceneRecord`]: what the station reads, not the simulation's
//! parts) and its scene-start constants, the controller settings and the feasibility findings
//! the board used to compute in `f64` at `scene`, so that their soft-float code and `libm`
//! calls stay out of flash. The core computes them on the build host with the same code and the
//! same bits. The board links neither the core's scene table nor its lookup.

#[allow(unused_imports)]
use sonolube::control::ActuatorRatings;
use sonolube::control::Settings;
#[allow(unused_imports)]
use sonolube::scene::feasibility::{Cause::*, Finding, Severity::*};
#[allow(unused_imports)]
use sonolube::scene::{
    Accuracy, Actuator, ActuatorKind::*, Breakpoint, Contents, Criterion, Horn, LoadCell,
    ModelKind::*, ModelSpec, ResonanceShift, RoughSurface, Stack, System::*, Transducer,
};
use sonolube::variant::Selection;
#[allow(unused_imports)]
use sonolube::{model::ModelError::*, protocol::Target::*};

use crate::scene_record::SceneRecord;

/// A built-in scene on the board.
pub struct BoardScene {
    /// The scene's name.
    pub name: &'static str,
    /// The transducer's drive frequency, Hz (the bridge's check).
    pub drive_hz: f64,
    /// The actuator's full-scale stack voltage, V (the bridge's check).
    pub full_scale_voltage_v: f64,
    /// What `scene` starts with; `None` for a scene whose drive the bridge refuses
    /// ([`crate::drive_fit`]), which `rig::Setup::new` refuses before it asks.
    pub start: Option<&'static SceneStart>,
}

/// What a built-in scene the bridge can drive starts with.
pub struct SceneStart {
    /// The scene as the station reads it.
    pub record: SceneRecord,
    /// `sonolube::control::controller_settings` of the scene (shared by the scenes whose
    /// settings are the same).
    pub settings: &'static Settings,
    /// `sonolube::scene::feasibility::check` of the scene on its selected model: every finding,
    /// warnings and refusals (none for the shipped scenes today).
    pub findings: &'static [Finding],
}

impl SceneStart {
    /// The first refusal among the findings, if any: the scene cannot work.
    pub fn refusal(&self) -> Option<&'static Finding> {
        self.findings
            .iter()
            .find(|finding| finding.severity == sonolube::scene::feasibility::Severity::Refuse)
    }
}

include!(concat!(env!("OUT_DIR"), "/scene_start.rs"));

/// The built-in scene named `name` (the `scene NAME` command), if any.
pub fn find(name: &str) -> Option<&'static BoardScene> {
    BOARD_SCENES.iter().find(|scene| scene.name == name)
}

impl BoardScene {
    /// The model variant selection the core's build script made for this scene
    /// (`sonolube::scene::builtin::SELECTIONS`, the one `Station::new` would make, tested in
    /// `scene::builtin`): the selection code and the measured table stay out of flash.
    pub fn selection(&self) -> Option<Selection> {
        sonolube::scene::builtin::SELECTIONS
            .iter()
            .find(|(name, _)| *name == self.name)
            .map(|(_, selection)| *selection)
    }
}
