//! The store on the library's own mock flash (`sequential_storage::mock_flash`), with the
//! G474's geometry in single-bank mode: 4 KiB pages, 8-byte (double-word) writes, each word
//! written once between erases.

use core::ops::Range;

use sequential_storage::mock_flash::{MockFlashBase, WriteCountCheck};

use super::record::tests::{known, sample};
use super::*;
use crate::control::Reason;
use crate::protocol::Target;

/// Four 4 KiB pages of 8-byte words.
type Flash = MockFlashBase<4, 8, 512>;
const RANGE: Range<u32> = 0..4 * 4096;

fn new_flash() -> Flash {
    Flash::new(WriteCountCheck::OnceOnly, None, true)
}

fn run<T>(future: impl core::future::Future<Output = T>) -> T {
    embassy_futures::block_on(future)
}

fn store(flash: Flash) -> Store<Flash> {
    Store::new(flash, RANGE).expect("whole pages")
}

#[test]
fn a_saved_record_is_found_by_a_new_store_on_the_same_flash() {
    let mut s = store(new_flash());
    assert_eq!(run(s.load(known)), Err(Invalid::Empty));
    run(s.save(&sample(1))).unwrap();
    run(s.save(&sample(2))).unwrap();
    // A reset: the RAM state (the library's cache, our buffers) is gone, the flash is not.
    let mut s = store(s.into_flash());
    assert_eq!(run(s.load(known)), Ok(sample(2)));
}

#[test]
fn the_range_must_be_whole_pages_and_at_least_two() {
    assert!(matches!(
        Store::new(new_flash(), 0..4096),
        Err(StoreError::Config)
    ));
    assert!(matches!(
        Store::new(new_flash(), 100..8192),
        Err(StoreError::Config)
    ));
}

#[test]
fn boot_falls_back_to_the_defaults_and_says_why() {
    let mut s = store(new_flash());
    let first = run(boot(&mut s, false, known));
    assert_eq!(first.record, Record::DEFAULTS);
    assert_eq!(first.source, Source::Defaults(Invalid::Empty));
    assert_eq!((first.log.boots, first.log.watchdog_resets), (1, 0));
    assert_eq!(first.log_write, None);

    // Valid CRC, but a drive frequency out of range.
    let mut bytes = sample(1).encode();
    bytes[56..60].copy_from_slice(&7_000_000u32.to_le_bytes());
    let crc = crc32(&bytes[..60]);
    bytes[60..64].copy_from_slice(&crc.to_le_bytes());
    run(s.store(1, &bytes)).unwrap();
    let second = run(boot(&mut s, true, known));
    assert_eq!(second.source, Source::Defaults(Invalid::Freq));
    assert_eq!(second.record, Record::DEFAULTS);
    assert_eq!((second.log.boots, second.log.watchdog_resets), (2, 1));
    assert_eq!(
        second.log.events().collect::<Vec<_>>(),
        [Event::WatchdogReset]
    );

    // A flipped bit under a valid item: the record's own CRC finds it.
    let mut bytes = sample(1).encode();
    bytes[20] ^= 4;
    run(s.store(1, &bytes)).unwrap();
    assert_eq!(
        run(boot(&mut s, false, known)).source,
        Source::Defaults(Invalid::Crc)
    );

    // Another version, a scene this firmware does not have.
    let mut bytes = sample(1).encode();
    bytes[4] = 9;
    run(s.store(1, &bytes)).unwrap();
    assert_eq!(
        run(boot(&mut s, false, known)).source,
        Source::Defaults(Invalid::Version(9))
    );
    run(s.save(&sample(1))).unwrap();
    assert_eq!(
        run(boot(&mut s, false, |name| name == "demo")).source,
        Source::Defaults(Invalid::UnknownScene)
    );

    // A good record again.
    let good = run(boot(&mut s, false, known));
    assert_eq!((good.source, good.record), (Source::Stored, sample(1)));
    assert_eq!(good.log.boots, 6);
}

#[test]
fn a_bad_log_is_replaced_and_reported() {
    let mut s = store(new_flash());
    run(s.store(2, &[0x55; LOG_BYTES])).unwrap();
    let boot = run(boot(&mut s, false, known));
    assert_eq!(boot.log_invalid, Some(Invalid::Magic));
    assert_eq!(boot.log.boots, 1);
    assert_eq!(run(s.load_log()), Ok(boot.log));
}

#[test]
fn faults_and_resets_survive_in_the_log() {
    let mut s = store(new_flash());
    let mut log = run(boot(&mut s, false, known)).log;
    log.push(Event::Fault(Reason::Overcurrent));
    run(s.save_log(&log)).unwrap();
    let mut s = store(s.into_flash());
    let after = run(boot(&mut s, true, known)).log;
    assert_eq!(
        after.events().collect::<Vec<_>>(),
        [Event::Fault(Reason::Overcurrent), Event::WatchdogReset]
    );
    assert_eq!((after.boots, after.watchdog_resets), (2, 1));
}

/// Marks every page of the mock's range closed (both its start and end markers programmed):
/// a map the library cannot repair (it needs one open page), the state a stray write or a
/// flash bit error leaves, not a power cut.
fn close_every_page(flash: &mut Flash) {
    let bytes = flash.as_bytes_mut();
    for page in bytes.chunks_mut(4096) {
        let end = page.len() - 8;
        page[..8].fill(0);
        page[end..].fill(0);
    }
}

/// A store found corrupted beyond the library's repair is started afresh by the save, and
/// then holds the record that save wrote (and the next saves): `save` must not answer `ok`
/// for a record that is not there.
#[test]
fn a_store_found_corrupted_holds_the_new_record_after_its_repair() {
    let mut s = store(new_flash());
    run(s.save(&sample(1))).unwrap();
    let mut flash = s.into_flash();
    close_every_page(&mut flash);
    let mut s = store(flash);
    // The damage is real: the library itself reports it on a read.
    assert_eq!(run(s.load(known)), Err(Invalid::Storage));
    run(s.save(&sample(2))).expect("the save repairs the store");
    assert_eq!(run(s.load(known)), Ok(sample(2)));
    // After a reset too, and the repaired store takes further saves.
    let mut s = store(s.into_flash());
    assert_eq!(run(s.load(known)), Ok(sample(2)));
    run(s.save(&sample(3))).unwrap();
    let mut s = store(s.into_flash());
    assert_eq!(run(s.load(known)), Ok(sample(3)));
}

/// The longest scene name the protocol allows (24 bytes) survives `save` and `load`.
#[test]
fn a_scene_name_of_the_longest_length_survives_save_and_load() {
    use crate::protocol::{MAX_SCENE_NAME_LEN, SceneName};
    let name = "a-scene-name-of-24-bytes";
    assert_eq!(name.len(), MAX_SCENE_NAME_LEN);
    let mut record = sample(7);
    record.scene = Some(SceneName::new(name).expect("a valid name"));
    let known_long = |n: &str| n == name;
    let mut s = store(new_flash());
    run(s.save(&record)).unwrap();
    let mut s = store(s.into_flash());
    assert_eq!(run(s.load(known_long)), Ok(record));
}

/// Writes spread over every page: after many saves each page has been erased several times
/// and none much more than the others (the item size over the page size sets the rate).
#[test]
fn saves_are_spread_over_all_pages() {
    let fresh = new_flash();
    let start = fresh.stats_snapshot();
    let mut s = store(fresh);
    let saves = 2_000u32;
    for n in 0..saves {
        run(s.save(&sample(n))).unwrap();
    }
    let flash = s.into_flash();
    let erases = start.compare_to(flash.stats_snapshot()).erases;
    // An item is 64 bytes of value, 1 of key and a header, rounded to 8-byte words: 80 bytes
    // (`cost` below), so 51 fit a 4 KiB page and 2,000 saves fill 39 pages: about 36 erases
    // (the first pages are blank), all four pages in turn.
    assert!((30..=45).contains(&erases), "{erases} erases");
    let mut s = store(flash);
    assert_eq!(run(s.load(known)), Ok(sample(saves - 1)));
}

/// Flash operations (in bytes written or erased, the mock's unit of a power cut) of saving
/// `record` on `flash`.
fn cost(flash: &Flash, record: &Record) -> u32 {
    let mut probe = flash.clone();
    probe.bytes_until_shutoff = Some(u32::MAX);
    let mut s = store(probe);
    run(s.save(record)).unwrap();
    let probe = s.into_flash();
    u32::MAX - probe.bytes_until_shutoff.unwrap_or(u32::MAX)
}

/// The power-cut test: the store holds `old`; a save of `new` is cut after every byte it
/// writes or erases (every one of them for most saves, 400 evenly spread for the saves that
/// also erase a page), over 150 saves in a row so that the cuts also fall into page
/// reclaims. After each cut a new store (a reset) must load exactly `old` or exactly `new`,
/// never anything else, and must then save and load a third record.
#[test]
fn a_power_cut_at_any_byte_of_a_save_leaves_the_old_or_the_new_settings() {
    let mut base = store(new_flash());
    run(base.save(&sample(0))).unwrap();
    let mut base = base.into_flash();
    let mut old = sample(0);
    let (mut cuts, mut kept_old, mut got_new, mut with_erase) = (0u32, 0u32, 0u32, 0u32);
    for n in 1..=150u32 {
        let mut new = sample(n);
        new.target = Some(Target::Force { force_mn: n });
        new.scene = if n % 2 == 0 { None } else { old.scene };
        let units = cost(&base, &new);
        let step = if units > 400 { units / 400 } else { 1 };
        let erases_page = units > 4096;
        for cut in (0..units).step_by(step as usize) {
            let mut flash = base.clone();
            flash.bytes_until_shutoff = Some(cut);
            let mut s = store(flash);
            assert_eq!(
                run(s.save(&new)),
                Err(StoreError::Flash),
                "save {n} cut {cut}"
            );
            let mut flash = s.into_flash();
            flash.bytes_until_shutoff = None;
            let mut s = store(flash);
            let loaded = run(s.load(known));
            match loaded {
                Ok(r) if r == old => kept_old += 1,
                Ok(r) if r == new => got_new += 1,
                other => panic!("save {n} cut at {cut} of {units}: loaded {other:?}"),
            }
            let third = sample(1_000 + n);
            run(s.save(&third)).unwrap_or_else(|e| panic!("save {n} cut {cut}: {e:?}"));
            assert_eq!(run(s.load(known)), Ok(third));
            cuts += 1;
            with_erase += u32::from(erases_page);
        }
        let mut s = store(base);
        run(s.save(&new)).unwrap();
        if n % 7 == 0 {
            let mut log = Log::EMPTY;
            log.boot(n % 14 == 0);
            run(s.save_log(&log)).unwrap();
        }
        base = s.into_flash();
        old = new;
    }
    println!(
        "power cut: {cuts} cut points, {kept_old} kept the old settings, {got_new} the new, \
         {with_erase} in saves that reclaim a page"
    );
    assert!(cuts > 10_000, "{cuts}");
    assert!(kept_old > 0 && got_new > 0);
    assert!(with_erase > 0);
}

/// What `save` captures from a station is what `load` puts back: a record applied to a fresh
/// station of its scene captures as the same record; a record the station refuses changes
/// nothing.
#[test]
fn capture_returns_what_apply_put_in_and_a_refused_apply_changes_nothing() {
    use crate::protocol::SceneName;
    let scene = crate::scene::builtin::find("reference").expect("built in");
    let mut station = station_of(scene);
    let fresh = capture(&station, "reference", 0);
    assert_eq!(fresh.target, None);
    let record = Record {
        scene: SceneName::new("reference"),
        normal: Some(AxisCal {
            offset_q31: 12_345,
            span_q16: 7 << 16,
        }),
        tangential: Some(AxisCal {
            offset_q31: -1 << 30,
            span_q16: -(3 << 16),
        }),
        cal_count: 0,
        target: Some(Target::Coef { coef_ppm: 200_000 }),
        freq_chz: Some(4_100_000),
    };
    apply(&mut station, &record, None).expect("applies");
    assert_eq!(capture(&station, "reference", 0), record);
    assert_eq!(station.drive_freq_chz(), 4_100_000);

    // A frequency outside the range (a record that skipped its checks): refused whole.
    let mut bad = record;
    bad.normal = Some(AxisCal {
        offset_q31: 1,
        span_q16: 1,
    });
    bad.freq_chz = Some(7_000_000);
    assert!(apply(&mut station, &bad, None).is_err());
    assert_eq!(capture(&station, "reference", 0), record);

    // The defaults leave a fresh station as it is.
    let mut other = station_of(scene);
    apply(&mut other, &Record::DEFAULTS, None).expect("applies");
    assert_eq!(capture(&other, "reference", 0), fresh);
}

/// A station of `scene` on 12-bit unipolar channels with the nominal calibration (what the
/// simulation's `scene_station` builds, without depending on it).
fn station_of(scene: &crate::scene::Scene<'_>) -> crate::station::Station {
    use crate::fx::{Q1_31, Q16_16};
    use crate::sense::{AdcFormat, Calibration, FaultLimits, SensorChannel};
    let channel = |cell: &crate::scene::LoadCell| {
        let span = Q16_16::from_f64(2.0 * cell.full_scale_n).expect("span in range");
        SensorChannel::new(
            AdcFormat::unipolar(cell.adc_bits).expect("format"),
            FaultLimits {
                rail_margin: Q1_31::from_bits(1 << 19),
                noise_band: Q1_31::ZERO,
                stuck_samples: 0,
                max_step: Q1_31::MAX,
            },
            Calibration::new(Q1_31::from_bits(1 << 30), span),
        )
    };
    crate::station::Station::new(
        scene,
        &crate::control::controller_settings(scene),
        channel(&scene.normal_cell),
        channel(&scene.tangential_cell),
    )
    .expect("builds")
}

/// A commissioning as the sequence leaves it (Q = pi f0 tau), both cells tared.
fn commissioned_sample() -> crate::commission::CommissionResult {
    use crate::commission::{CellZero, CommissionResult, Measured};
    let m = |value, standard_error| Measured {
        value,
        standard_error,
    };
    let (f0, tau) = (39_987.654_321, 0.000_817_3);
    CommissionResult {
        resonance_hz: m(f0, 0.52),
        time_constant_s: m(tau, 4.95e-6),
        quality_factor: m(core::f64::consts::PI * f0 * tau, 0.62),
        natural_coefficient: m(0.263_1, 0.000_119),
        ring_down_points: 25,
        normal: CellZero {
            zero_n: 0.0167,
            noise_rms_n: Some(0.031),
        },
        tangential: CellZero {
            zero_n: -0.0034,
            noise_rms_n: Some(0.017),
        },
    }
}

/// `save` then a reset then `load`: the commissioned values come back bit for bit with the
/// settings they were saved with, and are not used with other settings (a later save of
/// declared values, or a power cut between the two writes).
#[test]
fn commissioned_values_survive_a_reset_with_their_settings_only() {
    let result = commissioned_sample();
    let mut s = store(new_flash());
    assert_eq!(run(s.load_commissioned(&sample(1))), Ok(None));
    run(s.save(&sample(1))).unwrap();
    run(s.save_commissioned(&result, &sample(1))).unwrap();
    let mut s = store(s.into_flash());
    let booted = run(boot(&mut s, false, known));
    assert_eq!(booted.record, sample(1));
    assert_eq!(booted.commissioned, Ok(Some(result)));
    // Without noise measured the noise fields read back as none.
    let mut untared = result;
    untared.tangential.noise_rms_n = None;
    run(s.save_commissioned(&untared, &sample(1))).unwrap();
    assert_eq!(run(s.load_commissioned(&sample(1))), Ok(Some(untared)));
    // New settings saved without commissioning: the old commissioning is not theirs.
    run(s.save(&sample(2))).unwrap();
    let mut s = store(s.into_flash());
    let booted = run(boot(&mut s, false, known));
    assert_eq!((booted.record, booted.commissioned), (sample(2), Ok(None)));
    // Defaults (nothing valid stored): no commissioning looked at.
    run(s.store(1, &[0u8; 3])).unwrap();
    let booted = run(boot(&mut s, false, known));
    assert_eq!(booted.source, Source::Defaults(Invalid::Length));
    assert_eq!(booted.commissioned, Ok(None));
}

/// A damaged commissioning is refused with the reason, never read as values; one with a
/// valid CRC but a value outside its range is refused naming the check.
#[test]
fn a_corrupted_commissioning_is_refused_with_its_reason() {
    let record = sample(1);
    let good = encode_commissioned(&commissioned_sample(), &record);
    let recrc = |mut bytes: [u8; COMMISSIONED_LEN]| {
        let crc = crc32(&bytes[..112]);
        bytes[112..].copy_from_slice(&crc.to_le_bytes());
        bytes
    };
    let decode = |bytes: &[u8]| decode_commissioned(bytes, &record);
    assert_eq!(decode(&good), Ok(Some(commissioned_sample())));
    assert_eq!(decode(&good[..115]), Err(CommissionedInvalid::Length));
    assert_eq!(
        decode(&[0xFF; COMMISSIONED_LEN]),
        Err(CommissionedInvalid::Magic)
    );
    let mut bad = good;
    bad[4] = 2;
    assert_eq!(decode(&bad), Err(CommissionedInvalid::Version(2)));
    for at in [5, 9, 12, 20, 70, 111, 113] {
        let mut bad = good;
        bad[at] ^= 0x20;
        assert_eq!(decode(&bad), Err(CommissionedInvalid::Crc), "byte {at}");
    }
    let mut bad = good;
    bad[5] |= 0x40;
    assert_eq!(decode(&recrc(bad)), Err(CommissionedInvalid::Flags));
    // A noise behind a cleared flag.
    let mut bad = good;
    bad[5] &= !1;
    assert_eq!(decode(&recrc(bad)), Err(CommissionedInvalid::Flags));
    // mu0 of 2.5 with a valid CRC: the range check.
    let mut bad = good;
    bad[64..72].copy_from_slice(&2.5f64.to_le_bytes());
    assert_eq!(
        decode(&recrc(bad)),
        Err(CommissionedInvalid::Range {
            step: crate::commission::Step::Natural,
            reason: "mu0 outside (0, 2]",
        })
    );
    assert_eq!(
        CommissionedInvalid::Range {
            step: crate::commission::Step::Natural,
            reason: "",
        }
        .reason(),
        "commissioning-out-of-range"
    );
    // Through the store and the boot: the settings are used, the commissioning is not, and
    // the boot says why.
    let mut s = store(new_flash());
    run(s.save(&record)).unwrap();
    let mut damaged = good;
    damaged[30] ^= 1;
    run(s.store(3, &damaged)).unwrap();
    let booted = run(boot(&mut s, false, known));
    assert_eq!(booted.source, Source::Stored);
    assert_eq!(booted.commissioned, Err(CommissionedInvalid::Crc));
    assert_eq!(
        booted.commissioned.unwrap_err().reason(),
        "commissioning-crc-mismatch"
    );
}

/// What `load` puts into a fresh station: the loop runs on the commissioned values, as the
/// console's `commission` left it (`commissioned_settings`), the noise included (which a
/// fresh station has not measured: the declared noise until then); `capture` and
/// `Station::commissioned` give them back for the next `save`.
#[test]
fn applied_commissioned_values_are_what_the_loop_runs_on() {
    let scene = crate::scene::builtin::find("reference").expect("built in");
    let mut station = station_of(scene);
    let declared = *station.settings();
    let result = commissioned_sample();
    let record = capture(&station, "reference", 0);
    apply(&mut station, &record, Some(&result)).expect("applies");
    let s = *station.settings();
    assert_eq!(station.commissioned(), Some(result));
    assert_eq!(
        s,
        crate::station::commissioned_settings(
            &declared,
            &result,
            crate::control::overshoot_criterion(scene)
        )
        .expect("tuned")
    );
    assert_eq!(s.envelope_time_constant_s, result.time_constant_s.value);
    assert_eq!(s.natural_prior, result.natural_coefficient.value);
    assert_eq!(s.actuator.drive_frequency_hz, result.resonance_hz.value);
    assert_eq!(s.normal_noise_n, 0.031);
    assert_eq!(s.tangential_noise_n, 0.017);
    assert_eq!(station.drive_freq_chz(), 3_998_765);
    assert_eq!(
        station.commission_report(),
        crate::station::CommissionReport::Restored(result)
    );
    // Refused whole: a result out of range leaves the station as it was.
    let mut fresh = station_of(scene);
    let mut bad = result;
    bad.natural_coefficient.value = 0.0;
    assert!(apply(&mut fresh, &record, Some(&bad)).is_err());
    assert_eq!(fresh.commissioned(), None);
    assert_eq!(*fresh.settings(), declared);
}
