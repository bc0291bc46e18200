//! The scene-start constants of the built-in scenes, computed by the build script (`build.rs`,
//! [`SCENE_START`]): the controller settings and the feasibility findings the board used to
//! compute in `f64` at `scene`, so that their soft-float code and `libm` calls stay out of
//! flash. The core computes them on the build host with the same code and the same bits.

#[allow(unused_imports)]
use sonolube::control::ActuatorRatings;
use sonolube::control::Settings;
use sonolube::scene::Scene;
#[allow(unused_imports)]
use sonolube::scene::feasibility::{Cause::*, Finding, Severity::*};
#[allow(unused_imports)]
use sonolube::{model::ModelError::*, protocol::Target::*};

/// What a built-in scene starts with.
pub struct SceneStart {
    /// The scene's name.
    pub name: &'static str,
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

/// The scene-start constants of the built-in scene `scene` (every scene the board can select
/// is one: `sonolube::scene::builtin::find`); `None` as well for a scene whose drive the bridge
/// refuses ([`crate::drive_fit`]), which `rig::Setup::new` refuses before it asks.
pub fn of(scene: &Scene<'_>) -> Option<&'static SceneStart> {
    SCENE_START.iter().find(|start| start.name == scene.name)
}
