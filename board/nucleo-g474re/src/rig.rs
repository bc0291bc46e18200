//! The board's control loop: the firmware's station on the real load cells and the real
//! half-bridge.
//!
//! Each period the newest load-cell pair from the sensing task ([`crate::cells`]) goes through
//! the station (sensing chain, controller, model) of the selected scene, and the controller's
//! output goes to the bridge ([`crate::bridge`]). The station's channels are the board's own
//! ([`cell_channel`]: the internal ADC's format, the board's fault limits, the cells' datasheet
//! calibration, then `tare` and `cal`); the controller runs the core's tuning for the scene
//! ([`sonolube::control::controller_settings`], computed by the build script: [`crate::scene_start`]),
//! whose plausible force ranges are the scene
//! cells' (1.1 x their full scale): a force beyond it is a sensor fault, drive safe. This is
//! the QEMU board's rig with hardware where the simulated plant was.
//!
//! # What the board cannot measure
//!
//! - **Sliding velocity**: the rig has no velocity sensor. The station is given the scene's
//!   set speed (the first breakpoint of its sliding-velocity profile: 0.038 m/s in
//!   `reference`) every period, so the controller always believes the contact slides at that
//!   speed. The operator must run the slide at that speed before `start`; with the slide
//!   stopped the controller would still drive (and learn a wrong natural friction).
//! - **Fresh samples every period**: the cells are converted at 833 pairs/s (40 kHz drive), so
//!   each pair is held for several periods; the station's stuck-reading check is widened by the
//!   longest hold in the drive band ([`hold_steps`]). A pair older than [`STALE_HOLDS`] holds
//!   (sensing has stopped) is given to the station as code 0, the converter's low rail, which
//!   it reads as a disconnected normal-force sensor: a sensor fault, drive safe.

use core::fmt::Write as _;

use cortex_m::peripheral::DWT;
use sonolube::control::{ExternalFault, Reason};
use sonolube::drive::Frequency;
use sonolube::protocol::{Axis, Command, DRIVE_FREQ, ProtocolError, SupervisorState, TokenText};
use sonolube::resonance::LockState;
use sonolube::sense::{AdcCode, Calibration, SenseError, SensorChannel};
use sonolube::station::{CellBench, MAX_CURRENT_SAMPLES, Sample, Station, StationError};
use sonolube_app::control::ControlLoop;
use sonolube_app::snapshot::Snapshot;

use crate::bridge::{Bridge, CONTROLS_BRIDGE, DriveRefusal};
use crate::cells::{CellFeed, RawPair};
use crate::current::RingReader;
use crate::scene_start::{BoardScene, SceneStart};
use crate::sensing::TRIGGERS_PER_TRIPLET;
use crate::{config, current, drive, scene_start};

/// A pair held for more than this many times the longest expected hold is stale.
pub const STALE_HOLDS: u32 = 8;

/// Why a scene cannot run on this board.
#[derive(Debug, Clone, Copy, PartialEq, defmt::Format)]
pub enum SceneRefusal {
    /// The station (model, controller, cells) cannot be built from the scene.
    Station(StationError),
    /// The bridge cannot run the scene's drive.
    Drive(DriveRefusal),
    /// The board's load-cell calibration ([`config::LOAD_CELL_INTERNAL`]) is unusable.
    Cells(SenseError),
    /// The scene's record, constants or model variant selection are not in flash
    /// ([`crate::scene_start`], `sonolube::scene::builtin::SELECTIONS`); the board does not link
    /// the selection.
    NotCompiled,
}

/// Everything that depends on the scene, built whole before it replaces the running one.
struct Setup {
    scene: &'static BoardScene,
    start: &'static SceneStart,
    station: Station,
    bridge: Bridge,
    sliding_velocity_m_per_s: f32,
    stale_after_steps: u32,
}

impl Setup {
    /// Configuration (the model variant's selection from the measured table, `f64`, the
    /// model's tables), between two steps; its duration on silicon is unmeasured (an overrun is
    /// counted if it exceeds a period).
    fn new(scene: &'static BoardScene) -> Result<Self, SceneRefusal> {
        let calibration = config::LOAD_CELL_INTERNAL
            .calibration()
            .map_err(SceneRefusal::Cells)?;
        // The cheap check first: a scene the bridge cannot drive builds no model.
        let bridge = Bridge::for_scene(scene.drive_hz, scene.full_scale_voltage_v)
            .map_err(SceneRefusal::Drive)?;
        // The record and the constants the build script wrote (scene_start.rs).
        let start = scene.start.ok_or(SceneRefusal::NotCompiled)?;
        let record = &start.record;
        let hold = hold_steps(record.control_rate_hz);
        let channel = cell_channel(calibration, hold);
        // The selection the build script made (the one `Station::new` would make, tested in
        // `scene::builtin`): the selection code and the measured table stay out of flash.
        let selection = scene.selection().ok_or(SceneRefusal::NotCompiled)?;
        // The settings the build script computed (`controller_settings`), on the scene the
        // record gives (the station reads nothing the record leaves out: build.rs checks it).
        let mut station = Station::with_selection(
            &record.scene(scene.name),
            start.settings,
            selection,
            channel,
            channel,
        )
        .map_err(SceneRefusal::Station)?;
        if current::running() {
            // ADC2 samples the drive current at the stepped phases: `freq auto` can run.
            station.enable_current_sense();
        }
        let sliding_velocity_m_per_s = record
            .sliding_velocity_m_per_s
            .first()
            .map_or(0.0, |point| point.value as f32);
        Ok(Self {
            scene,
            start,
            station,
            bridge,
            sliding_velocity_m_per_s,
            stale_after_steps: hold.saturating_mul(STALE_HOLDS),
        })
    }
}

/// Control periods a pair is held at most: the control rate over the pair rate at the lowest
/// drive frequency of the band (the ADC is triggered once per PWM period), rounded up (24 at
/// 10 kHz: 20 kHz / 48 triggers = 417 pairs/s).
pub fn hold_steps(control_rate_hz: f64) -> u32 {
    // Control periods times triggers per pair, rounded up (`as` saturates, NaN gives 0).
    let exact = control_rate_hz * f64::from(TRIGGERS_PER_TRIPLET);
    let truncated = exact as u64;
    let triggers = truncated + u64::from((truncated as f64) < exact);
    let band_min_hz = u64::from(Frequency::BAND_MIN.hz_rounded()).max(1);
    let hold = triggers.div_ceil(band_min_hz).max(1);
    u32::try_from(hold).unwrap_or(u32::MAX)
}

/// A load cell's channel for the station: the internal ADC's format ([`config::ADC_FORMAT`]),
/// the board's fault limits ([`config::LOAD_CELL_LIMITS`]) with the stuck check counting `hold`
/// times as many periods (a held pair repeats its code for `hold` periods, which is no sign of a
/// stuck cell), and `calibration` (the cells' datasheet calibration until `tare` and `cal`).
pub fn cell_channel(calibration: Calibration, hold: u32) -> SensorChannel {
    let mut limits = config::LOAD_CELL_LIMITS;
    limits.stuck_samples = limits.stuck_samples.saturating_mul(hold);
    SensorChannel::new(config::ADC_FORMAT, limits, calibration)
}

/// The board's control loop on one scene.
pub struct BoardRig {
    setup: Setup,
    feed: CellFeed,
    /// The drive current's ring (None when the stepped sampling did not start).
    current: Option<RingReader>,
    /// The ring stopped (logged once).
    current_stalled: bool,
}

impl BoardRig {
    /// The rig of `scene`, its first sample `first`, its drive timing written to TIM1.
    pub fn new(scene: &'static BoardScene, first: RawPair) -> Result<Self, SceneRefusal> {
        let mut setup = Setup::new(scene)?;
        setup.bridge.install();
        Ok(Self {
            setup,
            feed: CellFeed::new(first),
            current: RingReader::new(),
            current_stalled: false,
        })
    }

    /// The scene.
    pub fn scene(&self) -> &'static BoardScene {
        self.setup.scene
    }

    /// The scene's record and scene-start constants.
    pub fn start(&self) -> &'static SceneStart {
        self.setup.start
    }

    /// The station, for the settings store (`settings_flash.rs`).
    pub fn station(&self) -> &Station {
        &self.setup.station
    }

    /// The station, to put stored calibrations into (`settings_flash.rs`).
    pub fn station_mut(&mut self) -> &mut Station {
        &mut self.setup.station
    }

    /// Logs the model variant the controller runs and why ([`sonolube::variant::select`]), at
    /// scene start.
    pub fn log_model(&self) {
        let (scene, station) = (self.setup.scene, &self.setup.station);
        match station.selection() {
            Some(selection) => defmt::info!("scene {=str}: controller {}", scene.name, selection),
            None => defmt::info!(
                "scene {=str}: controller model {} (given, not selected)",
                scene.name,
                station.model().kind()
            ),
        }
    }

    /// `scene NAME`: the new scene's station replaces the old one (calibration, target and
    /// latched fault included), with the drive off.
    fn select_scene(&mut self, command: &Command) -> Result<(), ProtocolError> {
        let Command::Scene(name) = *command else {
            return Err(self.wrong_state(command));
        };
        let state = self.setup.station.state();
        if !matches!(
            state,
            SupervisorState::Idle | SupervisorState::Fault | SupervisorState::Boot
        ) {
            return Err(ProtocolError::WrongState {
                command: command.keyword(),
                state,
            });
        }
        let Some(scene) = scene_start::find(name.as_str()) else {
            return Err(ProtocolError::UnknownScene { name });
        };
        match Setup::new(scene) {
            Ok(setup) => {
                // What cannot work is refused before it runs (issue 26): the findings of
                // `Station::feasibility`, computed by the build script (scene_start.rs).
                let start = setup.start;
                for finding in start.findings {
                    defmt::warn!("scene {=str}: {}", scene.name, finding);
                }
                if let Some(refusal) = start.refusal() {
                    return Err(ProtocolError::Unavailable {
                        command: command.keyword(),
                        reason: refusal.summary(),
                    });
                }
                self.setup.bridge.off();
                self.setup = setup;
                self.setup.bridge.install();
                // The new station's lock-in starts at phase 0.
                if let Some(reader) = self.current.as_mut() {
                    reader.realign();
                }
                defmt::info!(
                    "scene {=str}: {=f64} Hz control, drive {=f64} Hz, set speed {=f32} m/s",
                    scene.name,
                    start.record.control_rate_hz,
                    scene.drive_hz,
                    self.setup.sliding_velocity_m_per_s
                );
                self.log_model();
                Ok(())
            }
            Err(refusal) => {
                defmt::error!(
                    "scene {=str} cannot run on this board: {}",
                    scene.name,
                    refusal
                );
                Err(ProtocolError::UnknownScene { name })
            }
        }
    }

    /// `freq`: the station takes the frequency (it checks the protocol's range) if TIM1 can run
    /// at it, then TIM1 switches to it.
    fn set_frequency(&mut self, command: &Command, freq_chz: u32) -> Result<(), ProtocolError> {
        let frequency = Frequency::from_millihertz(freq_chz.saturating_mul(10));
        let timing = match self.setup.bridge.timing_at(frequency) {
            Ok(timing) if frequency.in_band() => timing,
            // The protocol's range is the band, where every frequency has a timing (config.rs
            // checks the dead time at 60 kHz): only a command built by a program gets here.
            _ => {
                let mut token = Text::default();
                let _ = write!(token, "{}.{:02}", freq_chz / 100, freq_chz % 100);
                return Err(ProtocolError::OutOfRange {
                    token: TokenText::new(token.as_str()),
                    quantity: &DRIVE_FREQ,
                });
            }
        };
        let mut bench = Bench {
            feed: &self.feed,
            fresh: false,
        };
        self.setup.station.execute(command, &mut bench)?;
        self.setup.bridge.retune(timing);
        Ok(())
    }

    /// The drive current converted since the last step into the station (its resonance loop),
    /// then the drive moved to the frequency the loop chose (`freq auto`). A stopped ring is
    /// logged once; while `freq auto` runs it latches `resonance-lost` (drive safe).
    fn feed_current(&mut self) {
        let Some(reader) = self.current.as_mut() else {
            return;
        };
        let setup = &mut self.setup;
        let mut codes = [0u16; MAX_CURRENT_SAMPLES];
        match reader.drain(&mut codes) {
            Ok(count) => {
                if count > 0 {
                    setup
                        .station
                        .push_current(codes.get(..count).unwrap_or(&[]));
                }
            }
            Err(stalled) => {
                if !self.current_stalled {
                    self.current_stalled = true;
                    defmt::error!("current sense stopped ({}): no resonance tracking", stalled);
                }
                let auto = setup
                    .station
                    .resonance()
                    .is_some_and(|report| report.state != LockState::Pinned);
                if auto {
                    setup
                        .station
                        .controller_mut()
                        .trip(ExternalFault::ResonanceLost);
                }
                return;
            }
        }
        let Some(report) = setup.station.resonance() else {
            return;
        };
        if report.state == LockState::Pinned {
            return;
        }
        // The loop's frequency is on TIM1's grid (`Tuning`): the same period comes back.
        if let Ok(timing) = setup.bridge.timing_at(report.frequency)
            && timing.period() != setup.bridge.timing().period()
        {
            setup.bridge.retune(timing);
        }
    }

    fn wrong_state(&self, command: &Command) -> ProtocolError {
        ProtocolError::WrongState {
            command: command.keyword(),
            state: self.setup.station.state(),
        }
    }
}

/// A few bytes of text: the token of a refusal.
#[derive(Default)]
struct Text {
    bytes: [u8; 16],
    len: usize,
}

impl Text {
    fn as_str(&self) -> &str {
        self.bytes
            .get(..self.len)
            .and_then(|bytes| core::str::from_utf8(bytes).ok())
            .unwrap_or("?")
    }
}

impl core::fmt::Write for Text {
    fn write_str(&mut self, text: &str) -> core::fmt::Result {
        let end = self.len + text.len();
        let slot = self.bytes.get_mut(self.len..end).ok_or(core::fmt::Error)?;
        slot.copy_from_slice(text.as_bytes());
        self.len = end;
        Ok(())
    }
}

/// `tare` and `cal` on the real cells: the newest samples from the history (see
/// [`CellFeed::burst`]). `load_n` is ignored: the operator has put that load on the cell.
struct Bench<'a> {
    feed: &'a CellFeed,
    fresh: bool,
}

impl CellBench for Bench<'_> {
    fn burst(&mut self, axis: Axis, _load_n: f32, codes: &mut [AdcCode]) -> bool {
        self.feed.burst(axis, self.fresh, codes)
    }
}

impl ControlLoop for BoardRig {
    /// The DWT cycle counter counts the 170 MHz core clock.
    const CYCLE_HZ: u64 = 170_000_000;

    fn rate_hz(&self) -> u32 {
        // Scenes run at 1 to 100 kHz.
        self.setup.start.record.control_rate_hz as u32
    }

    fn step(&mut self) -> Option<Snapshot> {
        let start = DWT::cycle_count();
        self.feed_current();
        let setup = &mut self.setup;
        let (pair, held) = self.feed.take(drive::outputs_enabled());
        let (normal_code, tangential_code) = if held > setup.stale_after_steps {
            // No pair for too long: the converter reads as disconnected (low rail).
            (AdcCode::new(0), AdcCode::new(0))
        } else {
            (
                AdcCode::from_word(pair.normal),
                AdcCode::from_word(pair.tangential),
            )
        };
        let control = setup.station.control(&Sample {
            normal_code,
            tangential_code,
            sliding_velocity_m_per_s: setup.sliding_velocity_m_per_s,
        });
        // A search started by `start` drives its own amplitude before the friction loop runs.
        let searching = setup
            .station
            .resonance()
            .is_some_and(|report| report.state == LockState::Searching);
        let applied = setup.bridge.apply(&control.output, searching);
        let cycles = DWT::cycle_count().wrapping_sub(start);
        if let Err(cause) = applied {
            defmt::error!(
                "bridge stopped while driving ({}): overcurrent fault",
                cause
            );
            setup
                .station
                .controller_mut()
                .trip(ExternalFault::Overcurrent);
        }
        Some(
            Snapshot::new(
                &control.output,
                setup.station.controller().target(),
                setup.scene.name,
                setup.station.drive_freq_chz(),
                control
                    .sensor_fault
                    .map(|fault| Reason::SensorFault(fault).name()),
                cycles,
            )
            .with_resonance(setup.station.resonance())
            .with_reach(setup.station.run_reach())
            .with_commissioned(setup.station.commissioned().is_some()),
        )
    }

    fn target_warning(&self) -> Option<sonolube::protocol::Target> {
        self.setup.station.target_warning()
    }

    fn execute(&mut self, command: &Command) -> Result<(), ProtocolError> {
        if !CONTROLS_BRIDGE
            && matches!(
                command,
                Command::Start | Command::Freq { .. } | Command::Scene(_)
            )
        {
            defmt::warn!(
                "bring-up build: B1 owns the bridge, `{=str}` is refused",
                command.keyword()
            );
            return Err(self.wrong_state(command));
        }
        match *command {
            Command::Scene(_) => self.select_scene(command),
            Command::Freq { freq_chz } => self.set_frequency(command, freq_chz),
            _ => {
                let fresh = self.feed.is_fresh(self.setup.stale_after_steps);
                let result = self.setup.station.execute(
                    command,
                    &mut Bench {
                        feed: &self.feed,
                        fresh,
                    },
                );
                if result.is_ok() && matches!(command, Command::Clear) {
                    self.setup.bridge.acknowledge();
                }
                result
            }
        }
    }

    fn trip_overrun(&mut self) {
        self.setup
            .station
            .controller_mut()
            .trip(ExternalFault::Overrun);
        self.setup.bridge.off();
    }
}
