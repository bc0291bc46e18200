//! The `ok` replies of `save`, `load`, `defaults` and `log` (see the protocol's command table).

use heapless::string::StringView;

use super::log::{LOG_LEN, Log};
use super::record::Record;
use super::store::Source;
use crate::protocol::{DRIVE_FREQ, FormatError, NONE, OkReply};

/// `ok settings=<what> scene=.. cal_count=.. normal_offset_q31=.. normal_span_q16=..
/// tangential_offset_q31=.. tangential_span_q16=.. target=.. freq_hz=..`: the record, with
/// `none` for each field that is the scene's own. Offsets and spans are the raw fixed-point
/// values (Q1.31 fraction of full scale, Q16.16 newtons per full scale), exact.
pub fn format_settings(
    what: &str,
    record: &Record,
    out: &mut StringView,
) -> Result<(), FormatError> {
    let mut reply = OkReply::new(out).word("settings", what).word(
        "scene",
        record.scene.as_ref().map_or(NONE, |name| name.as_str()),
    );
    reply = reply.uint("cal_count", u64::from(record.cal_count));
    for (offset_key, span_key, cal) in [
        ("normal_offset_q31", "normal_span_q16", record.normal),
        (
            "tangential_offset_q31",
            "tangential_span_q16",
            record.tangential,
        ),
    ] {
        reply = match cal {
            Some(cal) => reply.fixed(offset_key, i64::from(cal.offset_q31), 0).fixed(
                span_key,
                i64::from(cal.span_q16),
                0,
            ),
            None => reply.word(offset_key, NONE).word(span_key, NONE),
        };
    }
    reply = reply.target("target", record.target.as_ref());
    match record.freq_chz {
        Some(freq) => reply.fixed("freq_hz", i64::from(freq), DRIVE_FREQ.decimals),
        None => reply.word("freq_hz", NONE),
    }
    .finish()
}

/// `ok boots=.. watchdog_resets=.. boot_settings=stored|defaults boot_reason=.. events=..`:
/// the counters, where this boot's settings came from (and why not the stored ones), and the
/// last events, oldest first.
pub fn format_log(log: &Log, source: Source, out: &mut StringView) -> Result<(), FormatError> {
    let mut names: heapless::Vec<&str, LOG_LEN> = heapless::Vec::new();
    for event in log.events() {
        // The log holds at most LOG_LEN events.
        let _ = names.push(event.name());
    }
    OkReply::new(out)
        .uint("boots", u64::from(log.boots))
        .uint("watchdog_resets", u64::from(log.watchdog_resets))
        .word("boot_settings", source.name())
        .word(
            "boot_reason",
            match source {
                Source::Stored => NONE,
                Source::Defaults(why) => why.reason(),
            },
        )
        .list("events", &names)
        .finish()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::control::Reason;
    use crate::protocol::{REPLY_CAPACITY, Reply, parse_reply};
    use crate::settings::log::Event;
    use crate::settings::record::{Invalid, tests::sample};
    use heapless::String;

    #[test]
    fn replies_are_valid_protocol_lines() {
        let mut out: String<REPLY_CAPACITY> = String::new();
        format_settings("saved", &sample(2), &mut out).unwrap();
        assert_eq!(
            out.as_str(),
            "ok settings=saved scene=reference cal_count=2 normal_offset_q31=-123456789 \
             normal_span_q16=6553600 tangential_offset_q31=-2147483648 \
             tangential_span_q16=-3276807 target=coef:0.150002 freq_hz=39500.50\n"
        );
        assert!(matches!(parse_reply(&out), Ok(Reply::Ok(_))));
        format_settings("defaults", &Record::DEFAULTS, &mut out).unwrap();
        assert_eq!(
            out.as_str(),
            "ok settings=defaults scene=none cal_count=0 normal_offset_q31=none \
             normal_span_q16=none tangential_offset_q31=none tangential_span_q16=none \
             target=none freq_hz=none\n"
        );
        let mut log = Log::EMPTY;
        log.boot(true);
        log.push(Event::Fault(Reason::Overcurrent));
        format_log(&log, Source::Defaults(Invalid::Crc), &mut out).unwrap();
        assert_eq!(
            out.as_str(),
            "ok boots=1 watchdog_resets=1 boot_settings=defaults boot_reason=crc-mismatch \
             events=watchdog-reset,overcurrent\n"
        );
        assert!(matches!(parse_reply(&out), Ok(Reply::Ok(_))));
        // The longest log fits the reply buffer.
        for reason in Reason::all().filter(|r| r.is_fault()) {
            log.push(Event::Fault(reason));
        }
        format_log(&log, Source::Stored, &mut out).unwrap();
        assert!(matches!(parse_reply(&out), Ok(Reply::Ok(_))));
    }
}
