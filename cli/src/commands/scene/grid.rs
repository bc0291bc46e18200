//! The scenes of the robustness sweeps, made from a shipped scene: the mismatch grid, the
//! operating envelope (as scene files a user would write) and the noise levels.

use sonolube::fx::{Q1_31, Q8_24, Q16_16};
use sonolube::model::{AnyModel, FrictionModel, OperatingPoint};
use sonolube::scene::{LoadCell, Scene};
use sonolube_sim::{COMMISSIONED, CellCalibration, ClosedLoop};

use super::sweep::Run;
use crate::scene_file::LoadedScene;

/// Plant mu over the controller's, the grid's levels (+-30 %).
pub const MU_LEVELS: [f64; 3] = [0.7, 1.0, 1.3];
/// Plant k_t over the controller's (x0.5 to x2).
pub const K_T_LEVELS: [f64; 3] = [0.5, 1.0, 2.0];
/// Gain error of the load cells left after calibration (+-2 %): the tangential cell reads
/// `1 + g` times its force, the normal cell `1 - g` (the signs that add in the coefficient).
pub const GAIN_LEVELS: [f64; 3] = [-0.02, 0.0, 0.02];
/// Transducer resonance over the drive frequency, minus one (+-0.5 % of f0).
pub const DETUNE_LEVELS: [f64; 3] = [-0.005, 0.0, 0.005];

/// How the grid's runs drive the transducer whose resonance is off the scene's.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GridDrive {
    /// `freq auto` before `start`, as an operator who does not know f0 to 0.5 % runs it: the
    /// search, then the tracker, on the transducer's complex (Butterworth-Van Dyke) envelope,
    /// which samples its current for them. The default.
    FreqAuto,
    /// The drive held at the scene's frequency (`--pinned`): the real envelope with the
    /// settled gain `1 / sqrt(1 + x^2)` at the detuning `x`.
    Pinned,
}

impl GridDrive {
    /// The words of the sweep's header.
    pub const fn text(self) -> &'static str {
        match self {
            GridDrive::FreqAuto => "drive freq auto (search, then track)",
            GridDrive::Pinned => "drive pinned at the scene's frequency",
        }
    }
}

/// One point of the mismatch grid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mismatch {
    /// Plant mu over the controller's.
    pub mu: f64,
    /// Plant k_t over the controller's.
    pub k_t: f64,
    /// Cell gain error after calibration (tangential `+g`, normal `-g`).
    pub gain: f64,
    /// Resonance detuning, fraction of f0.
    pub detune: f64,
}

impl Mismatch {
    /// Every point of the grid (3^4 = 81).
    pub fn grid() -> Vec<Mismatch> {
        let mut points = Vec::new();
        for mu in MU_LEVELS {
            for k_t in K_T_LEVELS {
                for gain in GAIN_LEVELS {
                    for detune in DETUNE_LEVELS {
                        points.push(Mismatch {
                            mu,
                            k_t,
                            gain,
                            detune,
                        });
                    }
                }
            }
        }
        points
    }

    /// The label of this point in a sweep's worst-case column.
    pub fn label(&self) -> String {
        format!(
            "mu x{} k_t x{} gain {:+}% detune {:+}%",
            self.mu,
            self.k_t,
            self.gain * 100.0,
            self.detune * 100.0
        )
    }

    /// `scene` with this mismatch: the plant's mu (and mu_s) and k_t set to the controller's
    /// times the levels, the resonance moved by `detune` f0 (the scene's drive frequency
    /// kept as the nominal one), driven as `drive` says, and cells whose offset and gain
    /// error were calibrated away except the gain error `gain` (so the run uses the datasheet
    /// calibration on cells with exactly that error).
    pub fn apply<'a>(&self, scene: &Scene<'a>, drive: GridDrive) -> (Scene<'a>, CellCalibration) {
        let mut s = *scene;
        let mu_scale = self.mu * scene.controller.mu / scene.plant.mu;
        s.plant.mu = scene.plant.mu * mu_scale;
        s.plant.mu_static = scene.plant.mu_static.map(|m| m * mu_scale);
        s.mismatch.mu_ratio = self.mu;
        if let (Some(controller), Some(_)) = (scene.controller.k_t_n_per_m, scene.plant.k_t_n_per_m)
        {
            s.plant.k_t_n_per_m = Some(controller * self.k_t);
            s.mismatch.k_t_ratio = Some(self.k_t);
        }
        s.transducer.resonance_hz = scene.transducer.drive_hz * (1.0 + self.detune);
        if drive == GridDrive::FreqAuto {
            s.transducer.shift.bvd_envelope = true;
            s.transducer.shift.freq_auto = true;
        }
        let exact = |cell: &LoadCell, gain: f64| LoadCell {
            offset_n: 0.0,
            gain_error: gain,
            ..*cell
        };
        s.tangential_cell = exact(&scene.tangential_cell, self.gain);
        s.normal_cell = exact(&scene.normal_cell, -self.gain);
        (s, CellCalibration::Nominal)
    }
}

/// The runs of the mismatch grid on `scene` driven as `drive` says, each on every seed of
/// `seeds`.
pub fn mismatch_runs<'a>(scene: &Scene<'a>, seeds: &[u64], drive: GridDrive) -> Vec<Run<'a>> {
    let mut runs = Vec::new();
    for point in Mismatch::grid() {
        let (changed, calibration) = point.apply(scene, drive);
        for &seed in seeds {
            runs.push(Run {
                label: if seeds.len() > 1 {
                    format!("{}, seed {seed}", point.label())
                } else {
                    point.label()
                },
                scene: Scene {
                    noise_seed: seed,
                    ..changed
                },
                calibration,
            });
        }
    }
    runs
}

/// Normal loads of the envelope, N.
pub const ENVELOPE_LOADS_N: [f64; 5] = [0.5, 1.0, 2.0, 4.0, 8.0];
/// Sliding speeds of the envelope, m/s.
pub const ENVELOPE_SPEEDS: [f64; 4] = [0.01, 0.02, 0.04, 0.08];
/// Target reductions of the envelope, fraction of the reachable reduction.
pub const ENVELOPE_SHARES: [f64; 3] = [0.1, 0.35, 0.6];

/// One operating point of the envelope and the scene file written for it.
#[derive(Debug, Clone)]
pub struct EnvelopePoint {
    /// Normal load, N.
    pub load_n: f64,
    /// Sliding speed, m/s.
    pub speed_m_per_s: f64,
    /// The most the plant's friction can be reduced there (at the actuator's ceiling), %.
    pub reachable_pct: f64,
    /// The target reduction, %.
    pub reduction_pct: f64,
    /// The scene file's text.
    pub toml: String,
}

/// The largest reduction of natural friction (%) the plant of `scene` reaches at `load_n` and
/// `speed`, with the drive at the controller's amplitude ceiling times the transducer's gain.
pub fn reachable_pct(scene: &Scene<'_>, load_n: f64, speed: f64) -> Result<f64, String> {
    let sim = ClosedLoop::new(scene).map_err(|e| format!("cannot build the run: {e:?}"))?;
    let ceiling = sim.controller().config().limit().max_amplitude.to_f64();
    let model = AnyModel::new(scene, &scene.plant).map_err(|e| format!("plant model: {e:?}"))?;
    let t = &scene.transducer;
    let detuning = 2.0 * t.quality_factor * (t.drive_hz - t.resonance_hz) / t.resonance_hz;
    let gain = 1.0 / (1.0 + detuning * detuning).sqrt();
    let point = OperatingPoint {
        normal_force: Q16_16::from_f64(load_n).map_err(|e| format!("{e:?}"))?,
        sliding_velocity: Q8_24::from_f64(speed).map_err(|e| format!("{e:?}"))?,
    };
    let ratio = model
        .ratio(&point, Q1_31::from_f64_saturating(ceiling * gain).value)
        .map_err(|e| format!("plant model: {e:?}"))?
        .to_f64();
    Ok((1.0 - ratio) * 100.0)
}

/// The text of `template` (a scene file) with the lines that start with `key =` in section
/// `section` replaced by `key = value`; `None` if a key is missing.
fn set_keys(template: &str, section: &str, values: &[(&str, String)]) -> Option<String> {
    let mut out = String::new();
    let mut current = String::new();
    let mut found = vec![false; values.len()];
    for line in template.lines() {
        let trimmed = line.trim();
        if trimmed.starts_with('[') {
            current = trimmed.to_string();
        }
        let key = trimmed.split('=').next().unwrap_or("").trim();
        match values.iter().position(|(k, _)| *k == key) {
            Some(i) if current == section && !trimmed.starts_with('#') => {
                out.push_str(&format!("{key} = {}\n", values[i].1));
                found[i] = true;
            }
            _ => {
                out.push_str(line);
                out.push('\n');
            }
        }
    }
    found.iter().all(|&f| f).then_some(out)
}

/// The scene file a user would write for one envelope point, from the `reference` file: its
/// name, the load and speed profiles, the contents' ranges and the target step changed, and
/// nothing else (same rig, cells, controller, criteria).
pub fn envelope_file(
    reference_toml: &str,
    load_n: f64,
    speed: f64,
    reduction_pct: f64,
) -> Option<String> {
    let name = format!(
        "env-{}n-{}mms-{}pct",
        load_n,
        (speed * 1e3).round(),
        reduction_pct.round()
    )
    .replace('.', "p");
    let text = set_keys(
        reference_toml,
        "",
        &[
            ("name", format!("\"{name}\"")),
            (
                "description",
                format!(
                    "\"Envelope point: the reference rig at {load_n} N and {speed} m/s, friction reduced by {reduction_pct:.1} % at 5 ms.\""
                ),
            ),
        ],
    )?;
    let text = set_keys(
        &text,
        "[profiles]",
        &[
            ("normal_load_n", format!("[[0.0, {load_n}]]")),
            ("sliding_velocity_m_per_s", format!("[[0.0, {speed}]]")),
        ],
    )?;
    let text = set_keys(
        &text,
        "[contents]",
        &[
            ("load_range_n", format!("[{load_n}, {load_n}]")),
            ("velocity_range_m_per_s", format!("[{speed}, {speed}]")),
        ],
    )?;
    // The second target point is the step.
    let mut out = String::new();
    let mut targets = 0;
    for line in text.lines() {
        if line.trim() == "[[profiles.target]]" {
            targets += 1;
        }
        if targets == 2 && line.trim_start().starts_with("reduction_pct") {
            out.push_str(&format!("reduction_pct = {reduction_pct:.1}\n"));
        } else {
            out.push_str(line);
            out.push('\n');
        }
    }
    (targets == 2).then_some(out)
}

/// Every envelope point of the `reference` scene file `reference_toml` (its scene loaded as
/// `reference`): the reachable reduction at each load and speed and the files for the target
/// shares.
pub fn envelope_points(
    reference_toml: &str,
    reference: &Scene<'_>,
) -> Result<Vec<EnvelopePoint>, String> {
    let mut points = Vec::new();
    for load_n in ENVELOPE_LOADS_N {
        for speed in ENVELOPE_SPEEDS {
            let reachable = reachable_pct(reference, load_n, speed)?;
            for share in ENVELOPE_SHARES {
                let reduction_pct = share * reachable;
                let toml = envelope_file(reference_toml, load_n, speed, reduction_pct)
                    .ok_or("the reference file lacks a key the envelope changes")?;
                points.push(EnvelopePoint {
                    load_n,
                    speed_m_per_s: speed,
                    reachable_pct: reachable,
                    reduction_pct,
                    toml,
                });
            }
        }
    }
    Ok(points)
}

/// Loads the text of a scene file (as `sonolube scene --file` does).
pub fn load_text(text: &str, name: &str) -> Result<LoadedScene, String> {
    scene_toml::parse(text, name)
        .map(LoadedScene::from_description)
        .map_err(|e| e.to_string())
}

/// Sensor noise levels of the noise sweep, % of full scale (both cells).
pub const NOISE_LEVELS_PCT: [f64; 6] = [0.1, 0.2, 0.5, 1.0, 1.5, 2.0];

/// `scene` with both cells' noise at `pct` % FS, on noise seed `seed`, commissioned.
pub fn with_noise<'a>(scene: &Scene<'a>, pct: f64, seed: u64) -> Run<'a> {
    let mut s = *scene;
    s.normal_cell.noise_rms_pct_fs = pct;
    s.tangential_cell.noise_rms_pct_fs = pct;
    s.noise_seed = seed;
    Run {
        label: format!("noise {pct} % FS, seed {seed}"),
        scene: s,
        calibration: COMMISSIONED,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene_file::scenes_dir;
    use sonolube::scene::find;

    #[test]
    fn the_grid_spans_every_level_and_changes_the_plant_only() {
        let scene = find("reference").expect("built in");
        let grid = Mismatch::grid();
        assert_eq!(grid.len(), 81);
        let corner = Mismatch {
            mu: 1.3,
            k_t: 0.5,
            gain: 0.02,
            detune: -0.005,
        };
        assert!(grid.contains(&corner));
        let (s, calibration) = corner.apply(scene, GridDrive::Pinned);
        assert!(!s.transducer.shift.freq_auto && !s.transducer.shift.bvd_envelope);
        let (tracked, _) = corner.apply(scene, GridDrive::FreqAuto);
        assert!(tracked.transducer.shift.freq_auto && tracked.transducer.shift.bvd_envelope);
        assert_eq!(tracked.plant, s.plant);
        assert!((s.plant.mu - 0.26).abs() < 1e-12);
        assert_eq!(s.plant.k_t_n_per_m, Some(1.25e7));
        assert_eq!(s.controller, scene.controller);
        assert_eq!(s.transducer.drive_hz, 40_000.0);
        assert!((s.transducer.resonance_hz - 39_800.0).abs() < 1e-9);
        assert_eq!(s.tangential_cell.gain_error, 0.02);
        assert_eq!(s.normal_cell.gain_error, -0.02);
        assert_eq!(calibration, CellCalibration::Nominal);
    }

    #[test]
    fn an_envelope_file_loads_with_the_point_changed_and_the_rig_kept() {
        let path = scenes_dir().join("reference.toml");
        let text = std::fs::read_to_string(path).expect("reference.toml");
        let file = envelope_file(&text, 0.5, 0.08, 21.3).expect("keys present");
        let loaded = load_text(&file, "envelope.toml").expect("a valid scene");
        let s = loaded.scene();
        let reference = find("reference").expect("built in");
        assert_eq!(s.name, "env-0p5n-80mms-21pct");
        assert_eq!(s.normal_load_n[0].value, 0.5);
        assert_eq!(s.sliding_velocity_m_per_s[0].value, 0.08);
        assert_eq!(s.contents.load_max_n, 0.5);
        assert_eq!(s.criteria, reference.criteria);
        assert_eq!(s.plant, reference.plant);
        assert_eq!(s.tangential_cell, reference.tangential_cell);
        assert_eq!(s.target.len(), 2);
        assert_ne!(s.target[1], reference.target[1]);
    }

    #[test]
    fn more_speed_leaves_less_to_reduce() {
        let reference = find("reference").expect("built in");
        let slow = reachable_pct(reference, 4.0, 0.01).expect("reachable");
        let fast = reachable_pct(reference, 4.0, 0.08).expect("reachable");
        assert!(slow > fast && fast > 0.0 && slow < 100.0, "{slow} {fast}");
    }
}
