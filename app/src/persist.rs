//! Settings that survive a reset, for every board: a [`ControlLoop`] wrapper that answers
//! `save`, `load`, `defaults` and `log` from a [`Store`] on the board's flash, counts the
//! calibrations, loads and applies the stored settings at boot (the defaults, with the reason,
//! when they are missing or invalid) and logs each latched fault.
//!
//! The board gives a [`Persistent`] loop (capture and apply its settings) and its flash as an
//! async `NorFlash`; both boards' flash drivers are blocking underneath, so the store's futures
//! are run to completion with `block_on` inside the control task, between two steps. A save
//! costs one item write (about 80 bytes), sometimes a page erase when the store reclaims a
//! page: `save`, `load` and `defaults` therefore need the drive off (state `idle`, `fault` or
//! `boot`), like `tare` and `cal`. A latched fault is written to the log in the step that
//! latched it (the drive is already off).
//!
//! The data replies are made here, where the settings are, and handed to the console through
//! [`REPLY`]; the console sends them instead of its plain acknowledgement
//! ([`take_reply`]).

use core::cell::{Cell, RefCell};

use embassy_futures::block_on;
use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embedded_storage_async::nor_flash::NorFlash;
use heapless::String;
use sonolube::commission::CommissionResult;
use sonolube::control::Reason;
use sonolube::protocol::{Command, ProtocolError, REPLY_CAPACITY, SupervisorState};
use sonolube::settings::{
    Boot, CommissionedInvalid, Event, Invalid, Log, Record, Source, Store, format_log,
    format_settings,
};
use sonolube::station::CommissionReport;

use crate::control::ControlLoop;
use crate::snapshot::Snapshot;

/// The reply line of the latest `save`, `load`, `defaults` or `log`, for the console.
pub static REPLY: Mutex<CriticalSectionRawMutex, RefCell<String<REPLY_CAPACITY>>> =
    Mutex::new(RefCell::new(String::new()));

/// Whether `command` is answered with a line from [`REPLY`].
pub fn has_reply(command: &Command) -> bool {
    matches!(
        command,
        Command::Save
            | Command::Load
            | Command::Defaults
            | Command::Log
            | Command::CommissionStatus
    )
}

/// The report of the latest `commission status`, for the console to format. Its values are
/// `f64` (f0, Q, tau, mu0 and each one's standard error, the cells' zeros and noise): their
/// decimal formatting in the control task, between two steps, made every `commission status`
/// after a finished commissioning overrun its control period by about 30 us at 10 kHz in the
/// QEMU serve mode. The control task only copies the report here; [`take_reply`] formats it
/// in the console's task, which the control task preempts.
static COMMISSION_REPORT: Mutex<CriticalSectionRawMutex, Cell<Option<CommissionReport>>> =
    Mutex::new(Cell::new(None));

/// Moves the latest reply line into `out` (empty if there is none): a `commission status`
/// report formatted here ([`COMMISSION_REPORT`]), or the line the control task wrote.
pub fn take_reply(out: &mut String<REPLY_CAPACITY>) {
    if let Some(report) = COMMISSION_REPORT.lock(Cell::take) {
        out.clear();
        if sonolube::protocol::format_commission(&report, out.as_mut_view()).is_err() {
            out.clear();
        }
        return;
    }
    REPLY.lock(|reply| {
        let mut reply = reply.borrow_mut();
        out.clear();
        let _ = out.push_str(reply.as_str());
        reply.clear();
    });
}

fn set_reply(write: impl FnOnce(&mut String<REPLY_CAPACITY>) -> bool) {
    REPLY.lock(|reply| {
        let mut reply = reply.borrow_mut();
        if !write(&mut reply) {
            reply.clear();
        }
    });
}

/// What a board's loop gives the settings store.
pub trait Persistent {
    /// The settings of the loop as it runs (`cal_count` is filled in by [`Persisted`]).
    fn capture(&self) -> Record;
    /// The commissioned values the loop runs on (`None`: the scene's declared ones), saved
    /// beside the record.
    fn commissioned(&self) -> Option<CommissionResult>;
    /// Puts `record` into the loop (its scene, calibrations, drive frequency, target; fields
    /// at `None` the scene's own) and the `commissioned` values saved with it
    /// ([`sonolube::settings::apply`]; `None`: the declared values), whole or not at all.
    fn apply(
        &mut self,
        record: &Record,
        commissioned: Option<&CommissionResult>,
    ) -> Result<(), ProtocolError>;
    /// The supervisor's state.
    fn state(&self) -> SupervisorState;
    /// The latched fault, if any.
    fn latched_fault(&self) -> Option<Reason>;
    /// The last `commission` (`commission status`); a loop that cannot commission says
    /// `none`.
    fn commission(&self) -> sonolube::station::CommissionReport {
        sonolube::station::CommissionReport::Never
    }
}

/// Logs why a stored commissioning is not used.
fn warn_commissioning(why: CommissionedInvalid) {
    match why {
        CommissionedInvalid::Range { step, reason } => defmt::warn!(
            "settings: stored commissioning not usable: {=str} ({=str} step): declared values",
            reason,
            step.name()
        ),
        _ => defmt::warn!(
            "settings: stored commissioning not usable ({=str}): declared values",
            why.reason()
        ),
    }
}

/// A board's loop with its settings store. Without a store (a run given no flash) `save` and
/// `load` are refused as `storage-failed`, and the log is kept in RAM only.
pub struct Persisted<L, F: NorFlash> {
    inner: L,
    store: Option<Store<F>>,
    known_scene: fn(&str) -> bool,
    cal_count: u32,
    log: Log,
    source: Source,
    last_fault: Option<Reason>,
}

impl<L: ControlLoop + Persistent, F: NorFlash> Persisted<L, F> {
    /// The loop with its store after the boot sequence ([`sonolube::settings::boot`], which
    /// the board has run to choose the scene `inner` was built for): applies the stored
    /// record to `inner` (or keeps the defaults, and logs why). `booted` is `None` exactly
    /// when there is no store.
    pub fn new(
        mut inner: L,
        store: Option<Store<F>>,
        booted: Option<Boot>,
        after_watchdog_reset: bool,
        known_scene: fn(&str) -> bool,
    ) -> Self {
        let mut this = match (store, booted) {
            (Some(store), Some(booted)) => {
                if let Some(why) = booted.log_invalid {
                    defmt::warn!(
                        "settings: stored log not usable ({=str}), started afresh",
                        why.reason()
                    );
                }
                if let Some(error) = booted.log_write {
                    defmt::error!(
                        "settings: this boot could not be logged ({=str})",
                        error.name()
                    );
                }
                let mut source = booted.source;
                let mut cal_count = booted.record.cal_count;
                let commissioned = match booted.commissioned {
                    Ok(commissioned) => commissioned,
                    Err(why) => {
                        warn_commissioning(why);
                        None
                    }
                };
                if source == Source::Stored
                    && inner.apply(&booted.record, commissioned.as_ref()).is_err()
                {
                    // The settings without the commissioning, else the defaults.
                    let alone = commissioned.is_some() && inner.apply(&booted.record, None).is_ok();
                    if alone {
                        defmt::warn!(
                            "settings: the stored commissioning was refused: declared values"
                        );
                    } else {
                        source = Source::Defaults(Invalid::Refused);
                        cal_count = 0;
                    }
                }
                Self {
                    inner,
                    store: Some(store),
                    known_scene,
                    cal_count,
                    log: booted.log,
                    source,
                    last_fault: None,
                }
            }
            (store, _) => {
                let mut log = Log::EMPTY;
                log.boot(after_watchdog_reset);
                Self {
                    inner,
                    store,
                    known_scene,
                    cal_count: 0,
                    log,
                    source: Source::Defaults(Invalid::Storage),
                    last_fault: None,
                }
            }
        };
        this.last_fault = this.inner.latched_fault();
        this.report_boot();
        this
    }

    fn report_boot(&self) {
        match self.source {
            Source::Stored => {
                let mut record = self.inner.capture();
                record.cal_count = self.cal_count;
                defmt::info!(
                    "settings: stored ones loaded: {}, boot {=u32}",
                    record,
                    self.log.boots
                );
            }
            Source::Defaults(_) if self.store.is_none() => defmt::info!(
                "settings: no settings flash on this run: the scene's defaults (boot {=u32})",
                self.log.boots
            ),
            Source::Defaults(why) => defmt::warn!(
                "settings: defaults, because {=str} (boot {=u32})",
                why.reason(),
                self.log.boots
            ),
        }
    }

    /// The wrapped loop.
    pub fn inner(&self) -> &L {
        &self.inner
    }

    /// The wrapped loop, mutable.
    pub fn inner_mut(&mut self) -> &mut L {
        &mut self.inner
    }

    fn require_drive_off(&self, command: &Command) -> Result<(), ProtocolError> {
        match self.inner.state() {
            SupervisorState::Idle | SupervisorState::Fault | SupervisorState::Boot => Ok(()),
            state => Err(ProtocolError::WrongState {
                command: command.keyword(),
                state,
            }),
        }
    }

    fn store(&mut self) -> Result<&mut Store<F>, ProtocolError> {
        self.store
            .as_mut()
            .ok_or(ProtocolError::StorageFailed { reason: "no-flash" })
    }

    fn settings_command(&mut self, command: &Command) -> Result<(), ProtocolError> {
        match command {
            Command::Save => {
                self.require_drive_off(command)?;
                let mut record = self.inner.capture();
                record.cal_count = self.cal_count;
                let failed = |error: sonolube::settings::StoreError| {
                    defmt::error!("settings: save failed ({=str})", error.name());
                    ProtocolError::StorageFailed {
                        reason: error.name(),
                    }
                };
                // The record first: a cut before the commissioning is written leaves the
                // record with no commissioning of its own (the declared values).
                block_on(self.store()?.save(&record)).map_err(failed)?;
                if let Some(result) = self.inner.commissioned() {
                    block_on(self.store()?.save_commissioned(&result, &record)).map_err(failed)?;
                    defmt::info!("settings: saved the commissioned values {}", result);
                }
                defmt::info!("settings: saved {}", record);
                set_reply(|out| format_settings("saved", &record, out.as_mut_view()).is_ok());
                Ok(())
            }
            Command::Load => {
                self.require_drive_off(command)?;
                let known = self.known_scene;
                let record = block_on(self.store()?.load(known)).map_err(|why| match why {
                    Invalid::Storage => ProtocolError::StorageFailed {
                        reason: why.reason(),
                    },
                    _ => ProtocolError::SettingsInvalid {
                        reason: why.reason(),
                    },
                })?;
                // A damaged commissioning refuses the whole `load` with its reason; one saved
                // with other settings is not theirs (the declared values).
                let commissioned =
                    block_on(self.store()?.load_commissioned(&record)).map_err(|why| {
                        warn_commissioning(why);
                        match why {
                            CommissionedInvalid::Storage => ProtocolError::StorageFailed {
                                reason: why.reason(),
                            },
                            _ => ProtocolError::SettingsInvalid {
                                reason: why.reason(),
                            },
                        }
                    })?;
                self.inner.apply(&record, commissioned.as_ref())?;
                self.cal_count = record.cal_count;
                defmt::info!("settings: loaded {}", record);
                set_reply(|out| format_settings("loaded", &record, out.as_mut_view()).is_ok());
                Ok(())
            }
            Command::Defaults => {
                self.require_drive_off(command)?;
                self.inner.apply(&Record::DEFAULTS, None)?;
                self.cal_count = 0;
                set_reply(|out| {
                    format_settings("defaults", &Record::DEFAULTS, out.as_mut_view()).is_ok()
                });
                Ok(())
            }
            _ => {
                let (log, source) = (self.log, self.source);
                set_reply(|out| format_log(&log, source, out.as_mut_view()).is_ok());
                Ok(())
            }
        }
    }
}

impl<L: ControlLoop + Persistent, F: NorFlash> ControlLoop for Persisted<L, F> {
    const CYCLE_HZ: u64 = L::CYCLE_HZ;

    fn rate_hz(&self) -> u32 {
        self.inner.rate_hz()
    }

    fn step(&mut self) -> Option<Snapshot> {
        let snapshot = self.inner.step();
        let fault = self.inner.latched_fault();
        if fault != self.last_fault {
            self.last_fault = fault;
            if let Some(reason) = fault {
                self.log.push(Event::Fault(reason));
                if let Some(store) = self.store.as_mut()
                    && let Err(error) = block_on(store.save_log(&self.log))
                {
                    defmt::error!(
                        "settings: fault {=str} could not be logged ({=str})",
                        reason.name(),
                        error.name()
                    );
                }
            }
        }
        snapshot
    }

    fn execute(&mut self, command: &Command) -> Result<(), ProtocolError> {
        match command {
            Command::Save | Command::Load | Command::Defaults | Command::Log => {
                self.settings_command(command)
            }
            Command::CommissionStatus => {
                // Formatted by the console ([`take_reply`]), not in the control task.
                let report = self.inner.commission();
                COMMISSION_REPORT.lock(|cell| cell.set(Some(report)));
                Ok(())
            }
            Command::Tare(_) | Command::Cal { .. } => {
                self.inner.execute(command)?;
                self.cal_count = self.cal_count.saturating_add(1);
                Ok(())
            }
            _ => self.inner.execute(command),
        }
    }

    fn trip_overrun(&mut self) {
        self.inner.trip_overrun();
    }

    fn target_warning(&self) -> Option<sonolube::protocol::Target> {
        self.inner.target_warning()
    }
}
