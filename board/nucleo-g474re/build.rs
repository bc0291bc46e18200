//! Puts the NUCLEO-G474RE `memory.x` (top of the repository) on the linker's search path and
//! links with cortex-m-rt and defmt.
use std::{env, fs, path::PathBuf};

/// The environment variable of a size-measurement build (see `main`).
const SIZE_PROBE: &str = "SONOLUBE_G474_SIZE_PROBE";

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    fs::copy("../../memory.x", out.join("memory.x")).expect("memory.x at the top is readable");
    // A size measurement of an image larger than flash bank 1 (`scripts/family-sizes`): the
    // FLASH region widened to the whole 512 KiB, so that the linker reports the size instead of
    // failing. Such an image overlaps the settings store in bank 2: never flash it.
    println!("cargo:rerun-if-env-changed={SIZE_PROBE}");
    if env::var_os(SIZE_PROBE).is_some() {
        let memory = fs::read_to_string("../../memory.x").expect("memory.x at the top is readable");
        let widened = memory.replace(
            "FLASH : ORIGIN = 0x08000000, LENGTH = 256K",
            "FLASH : ORIGIN = 0x08000000, LENGTH = 512K",
        );
        assert_ne!(
            widened, memory,
            "memory.x: the FLASH line to widen is not there"
        );
        fs::write(out.join("memory.x"), widened).expect("OUT_DIR is writable");
        println!(
            "cargo:warning={SIZE_PROBE} set: flash widened to 512 KiB for a size measurement; do not flash this image"
        );
    }
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed=../../memory.x");
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rustc-link-arg-bins=--nmagic");
    println!("cargo:rustc-link-arg-bins=-Tlink.x");
    println!("cargo:rustc-link-arg-bins=-Tdefmt.x");
}
