//! The run's arguments: QEMU's `-append` text, read over semihosting (SYS_GET_CMDLINE).
//!
//! `scripts/qemu-run ELF [WORD...]` passes the words after the ELF. Words:
//! - `scene=NAME`: the scene (default [`DEFAULT_SCENE`]);
//! - `serve`: operate the scene's plant from the console (the command interface on UART0) and
//!   run until stopped, instead of playing the scene's script and exiting with its verdict;
//! - `icount=N`: the `-icount shift` QEMU runs with (the runner adds it), so instruction
//!   counts and the CPU load can be printed in instructions as well as in time;
//! - `flash=PATH`: keep the settings in the host file PATH (the emulated flash, `flash.rs`;
//!   created erased when missing); without it there is no settings flash;
//! - `commission`: run the scene as if it had `commission = true` (the firmware's `commission`
//!   measures f0, Q and mu0 on the simulated rig first; the run uses them);
//! - `cut=N`: cut the power (exit at once, status 4) just before the N+1-th flash word
//!   program or page erase of this run, for the power-cut test.

use core::mem::MaybeUninit;

use static_cell::StaticCell;

/// The scene run when none is named.
pub const DEFAULT_SCENE: &str = "reference";

/// The parsed arguments.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Args {
    /// The scene's name (checked against the scenes later).
    pub scene: &'static str,
    /// Serve the console instead of playing the script.
    pub serve: bool,
    /// QEMU's `-icount shift`, if given.
    pub icount_shift: Option<u8>,
    /// The settings flash file, if any.
    pub flash: Option<&'static str>,
    /// Flash operations before the power is cut, if asked.
    pub cut: Option<u32>,
    /// Commission before the run (`commission = true`).
    pub commission: bool,
}

/// Reads and parses the arguments; an unknown word is an error naming it.
pub fn read() -> Result<Args, &'static str> {
    static BUF: StaticCell<[MaybeUninit<u8>; 256]> = StaticCell::new();
    let buf = BUF
        .try_init([MaybeUninit::uninit(); 256])
        .ok_or("arguments read twice")?;
    let text: &'static str = match semihosting::sys::arm_compat::sys_get_cmdline_uninit(buf) {
        Ok(bytes) => core::str::from_utf8(bytes).map_err(|_| "command line is not UTF-8")?,
        // No command line: the defaults.
        Err(_) => "",
    };
    parse(text)
}

fn parse(text: &'static str) -> Result<Args, &'static str> {
    let mut args = Args {
        scene: DEFAULT_SCENE,
        serve: false,
        icount_shift: None,
        flash: None,
        cut: None,
        commission: false,
    };
    // The first word is the kernel's file name.
    for word in text.split_ascii_whitespace().skip(1) {
        if word == "serve" {
            args.serve = true;
        } else if word == "commission" {
            args.commission = true;
        } else if let Some(name) = word.strip_prefix("scene=") {
            args.scene = name;
        } else if let Some(path) = word.strip_prefix("flash=") {
            if path.is_empty() || path.len() > crate::flash::MAX_PATH {
                return Err("flash= takes a path of 1 to 200 bytes");
            }
            args.flash = Some(path);
        } else if let Some(n) = word.strip_prefix("cut=") {
            args.cut = Some(n.parse::<u32>().map_err(|_| "cut= takes a count")?);
        } else if let Some(shift) = word.strip_prefix("icount=") {
            args.icount_shift = Some(
                shift
                    .parse::<u8>()
                    .ok()
                    .filter(|s| *s <= 10)
                    .ok_or("icount= takes a shift 0..=10")?,
            );
        } else {
            defmt::error!("unknown argument {=str}", word);
            return Err("unknown argument");
        }
    }
    Ok(args)
}
