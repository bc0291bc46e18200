//! The malformed lines of the acceptance test's flood, generated from a seed (the same seed
//! gives the same lines on every machine), each with the error its reply must carry.
//!
//! Every line is checked on the host with the firmware's own line handling,
//! [`LineAssembler`] then [`parse_command`], before it is used: it must be a line the firmware
//! answers (not blank) and must not be a valid command, so each one gets exactly one `err`
//! reply, and its code is known in advance. No line holds a `\n`.

use sonolube::protocol::{
    CAL_LOAD, DRIVE_FREQ, ErrorCode, KEYWORDS, LineAssembler, MAX_LINE_LEN, ProtocolError,
    Quantity, TARGET_COEF, TARGET_FORCE, TARGET_REDUCTION, TELEMETRY_RATE, parse_command,
};

use super::reports::fixed;

/// Candidates tried for one line before the generator gives up (it never needs more than a few).
const MAX_ATTEMPTS: usize = 10_000;

/// A small, seeded, portable random number generator (SplitMix64).
#[derive(Debug, Clone)]
pub struct Rng(u64);

impl Rng {
    /// A generator seeded with `seed`.
    pub fn new(seed: u64) -> Self {
        Rng(seed)
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// A number in `0..n` (0 when `n` is 0).
    pub fn below(&mut self, n: usize) -> usize {
        if n == 0 {
            return 0;
        }
        (self.next_u64() % n as u64) as usize
    }

    /// A number in `lo..=hi`.
    pub fn between(&mut self, lo: usize, hi: usize) -> usize {
        lo + self.below(hi.saturating_sub(lo) + 1)
    }

    /// True with probability `percent` / 100.
    pub fn percent(&mut self, percent: usize) -> bool {
        self.below(100) < percent
    }

    /// One element of a non-empty slice.
    pub fn pick<T: Copy>(&mut self, items: &[T]) -> T {
        items[self.below(items.len())]
    }
}

/// What kind of malformed line it is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum FloodKind {
    /// Random printable ASCII (and tabs), at most 48 bytes.
    Garbage,
    /// A near-miss or made-up first word (`Status`, `stopp`, `qzx`).
    UnknownKeyword,
    /// A real keyword with a bad, out-of-range, too-precise, missing or extra argument.
    BadArgument,
    /// More than [`MAX_LINE_LEN`] bytes: always `line-too-long`.
    Oversized,
    /// Control bytes, DEL or non-ASCII (UTF-8 or stray bytes): always `bad-encoding`.
    BadBytes,
}

impl FloodKind {
    /// Every kind, in report order.
    pub const ALL: [FloodKind; 5] = [
        FloodKind::Garbage,
        FloodKind::UnknownKeyword,
        FloodKind::BadArgument,
        FloodKind::Oversized,
        FloodKind::BadBytes,
    ];

    /// The kind's name in reports.
    pub fn name(self) -> &'static str {
        match self {
            FloodKind::Garbage => "garbage",
            FloodKind::UnknownKeyword => "unknown keyword",
            FloodKind::BadArgument => "bad argument",
            FloodKind::Oversized => "oversized",
            FloodKind::BadBytes => "non-ASCII/control",
        }
    }

    /// The one code every line of this kind must get, for the kinds that have one.
    pub fn required_code(self) -> Option<ErrorCode> {
        match self {
            FloodKind::Oversized => Some(ErrorCode::LineTooLong),
            FloodKind::BadBytes => Some(ErrorCode::BadEncoding),
            _ => None,
        }
    }

    /// Share of the flood, percent.
    fn weight(self) -> usize {
        match self {
            FloodKind::Garbage => 20,
            FloodKind::UnknownKeyword => 15,
            FloodKind::BadArgument => 40,
            FloodKind::Oversized => 10,
            FloodKind::BadBytes => 15,
        }
    }
}

/// One line of the flood.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FloodLine {
    /// The bytes to send, without the `\n`.
    pub bytes: Vec<u8>,
    /// How it was made.
    pub kind: FloodKind,
    /// The error the firmware must answer it with.
    pub expected: ProtocolError,
}

/// The error the firmware answers `line` (sent with a `\n`) with, computed with the firmware's
/// own assembler and parser; `None` when it is a valid command, gets no reply (blank) or holds
/// a line end inside it (`\n`, or a `\r` other than a trailing one: `line\r` sent with its
/// `\n` is the one line end `\r\n`).
pub fn expected_error(line: &[u8]) -> Option<ProtocolError> {
    let line = line.strip_suffix(b"\r").unwrap_or(line);
    if line.contains(&b'\n') || line.contains(&b'\r') {
        return None;
    }
    let mut assembler = LineAssembler::new();
    for &byte in line {
        // No line end in `line`, so nothing completes before the `\n` pushed below.
        let _ = assembler.push(byte);
    }
    match assembler.push(b'\n')? {
        Err(error) => Some(error),
        Ok(text) => parse_command(text).err(),
    }
}

/// `count` malformed lines from `seed`. Fails only if the generator cannot find a line of some
/// kind, which would be a bug in it.
pub fn flood(seed: u64, count: usize) -> Result<Vec<FloodLine>, String> {
    let mut rng = Rng::new(seed);
    let mut lines = Vec::with_capacity(count);
    for _ in 0..count {
        let mut roll = rng.below(100);
        let kind = FloodKind::ALL
            .into_iter()
            .find(|k| {
                let hit = roll < k.weight();
                roll = roll.saturating_sub(k.weight());
                hit
            })
            .unwrap_or(FloodKind::BadArgument);
        lines.push(one_line(&mut rng, kind)?);
    }
    Ok(lines)
}

fn one_line(rng: &mut Rng, kind: FloodKind) -> Result<FloodLine, String> {
    for _ in 0..MAX_ATTEMPTS {
        let bytes = match kind {
            FloodKind::Garbage => garbage(rng),
            FloodKind::UnknownKeyword => unknown_keyword(rng),
            FloodKind::BadArgument => {
                let words = bad_argument(rng);
                spaced(rng, &words)
            }
            FloodKind::Oversized => oversized(rng),
            FloodKind::BadBytes => bad_bytes(rng),
        };
        let Some(expected) = expected_error(&bytes) else {
            continue;
        };
        let code = expected.code();
        let fits = match kind.required_code() {
            Some(required) => code == required,
            None => code != ErrorCode::LineTooLong && code != ErrorCode::BadEncoding,
        };
        if fits && code != ErrorCode::EmptyLine {
            return Ok(FloodLine {
                bytes,
                kind,
                expected,
            });
        }
    }
    Err(format!(
        "no {} line found in {MAX_ATTEMPTS} attempts",
        kind.name()
    ))
}

fn printable(rng: &mut Rng) -> u8 {
    match rng.below(100) {
        0..=9 => b' ',
        10..=11 => b'\t',
        _ => rng.between(0x21, 0x7e) as u8,
    }
}

fn garbage(rng: &mut Rng) -> Vec<u8> {
    let len = rng.between(1, 48);
    (0..len).map(|_| printable(rng)).collect()
}

fn lowercase_word(rng: &mut Rng, lo: usize, hi: usize) -> String {
    let len = rng.between(lo, hi);
    (0..len)
        .map(|_| char::from(rng.between(usize::from(b'a'), usize::from(b'z')) as u8))
        .collect()
}

fn unknown_keyword(rng: &mut Rng) -> Vec<u8> {
    let keyword = rng.pick(&KEYWORDS);
    let mut word = match rng.below(6) {
        0 => {
            let mut chars = keyword.chars();
            let first = chars.next().map(|c| c.to_ascii_uppercase()).unwrap_or('X');
            std::iter::once(first).chain(chars).collect()
        }
        1 => keyword.to_ascii_uppercase(),
        2 => keyword[..keyword.len() - 1].to_string(),
        3 => format!(
            "{keyword}{}",
            rng.pick(&["s", "x", "1", "_", "-", "ed", "2"])
        ),
        4 => lowercase_word(rng, 2, 10),
        _ => format!("{}{keyword}", rng.pick(&["x", "re", "_", "un", "0"])),
    };
    if rng.percent(40) {
        word.push(' ');
        word.push_str(rng.pick(&["1", "list", "auto", "off", "0.15", "all", "normal 10"]));
    }
    word.into_bytes()
}

/// A number token that `quantity` rejects: not a number, glued garbage, too many digits or
/// decimals, or out of range.
fn bad_number(rng: &mut Rng, quantity: &Quantity) -> String {
    let valid = |rng: &mut Rng| {
        let lo = quantity.min_valid();
        let hi = quantity.max_valid().min(lo + 1_000_000_000);
        lo + rng.below(usize::try_from(hi - lo + 1).unwrap_or(1)) as i64
    };
    match rng.below(5) {
        0 => rng
            .pick(&[
                "abc", ".5", "5.", "1.2.3", "--1", "+-2", "1..2", "one", "-", "+", "x1", "_",
            ])
            .to_string(),
        1 => {
            let number = fixed(valid(rng), quantity.decimals);
            let glued = rng.pick(&["N", "e3", "x10", ",5", "%", "hz", "k", "e-3", "/2"]);
            format!("{number}{glued}")
        }
        2 => {
            let digits = rng.between(13, 20);
            (0..digits)
                .map(|i| {
                    let lo = if i == 0 { b'1' } else { b'0' };
                    char::from(rng.between(usize::from(lo), usize::from(b'9')) as u8)
                })
                .collect()
        }
        3 => {
            let number = fixed(valid(rng), quantity.decimals);
            let point = if quantity.decimals == 0 { "." } else { "" };
            let extra = rng.between(1, 3);
            let mut tail: String = (1..extra)
                .map(|_| char::from(b'0' + rng.below(10) as u8))
                .collect();
            tail.push(char::from(b'1' + rng.below(9) as u8));
            format!("{number}{point}{tail}")
        }
        _ => {
            let beyond = match rng.below(3) {
                0 => quantity.min_valid() - 1 - rng.below(1000) as i64,
                1 => quantity.max_valid() + 1 + rng.below(1000) as i64,
                _ => -valid(rng) - 1,
            };
            fixed(beyond, quantity.decimals)
        }
    }
}

/// The words of a line that starts with a real keyword and has a wrong argument.
fn bad_argument(rng: &mut Rng) -> Vec<String> {
    let targets: [(&str, &Quantity); 3] = [
        ("force", &TARGET_FORCE),
        ("coef", &TARGET_COEF),
        ("reduction", &TARGET_REDUCTION),
    ];
    let axes = ["normal", "tangential"];
    let words: Vec<String> = match rng.below(10) {
        0 | 1 => {
            let (kind, quantity) = rng.pick(&targets);
            vec!["target".into(), kind.into(), bad_number(rng, quantity)]
        }
        2 => {
            let arg = if rng.percent(70) {
                bad_number(rng, &DRIVE_FREQ)
            } else {
                rng.pick(&["fast", "Auto", "max", "on", "khz"]).to_string()
            };
            vec!["freq".into(), arg]
        }
        3 => {
            let arg = if rng.percent(70) {
                bad_number(rng, &TELEMETRY_RATE)
            } else {
                rng.pick(&["on", "Off", "fast", "max", "yes"]).to_string()
            };
            vec!["telemetry".into(), arg]
        }
        4 => {
            if rng.percent(60) {
                {
                    let axis = rng.pick(&axes).to_string();
                    vec!["cal".into(), axis, bad_number(rng, &CAL_LOAD)]
                }
            } else {
                let axis = rng.pick(&["all", "Normal", "x", "both", "z"]).to_string();
                vec!["cal".into(), axis, "10".into()]
            }
        }
        5 => {
            let choice = rng.pick(&["both", "none", "Normal", "x", "all2", "tangent"]);
            vec!["tare".into(), choice.to_string()]
        }
        6 => {
            let name = match rng.below(4) {
                0 => rng
                    .pick(&["Demo", "none", "REFERENCE", "a.b", "x!", "a/b"])
                    .to_string(),
                1 => lowercase_word(rng, 25, 40),
                2 => format!(
                    "{}{}",
                    lowercase_word(rng, 1, 6),
                    rng.pick(&["A", ".", "*", "?", "~"])
                ),
                _ => format!(
                    "{}:{}",
                    lowercase_word(rng, 1, 5),
                    lowercase_word(rng, 1, 5)
                ),
            };
            vec!["scene".into(), name]
        }
        7 => {
            let missing: &[&str] = rng.pick(&[
                &["target"][..],
                &["target", "force"],
                &["target", "coef"],
                &["target", "reduction"],
                &["scene"],
                &["freq"],
                &["tare"],
                &["cal"],
                &["cal", "normal"],
                &["cal", "tangential"],
                &["telemetry"],
            ]);
            missing.iter().map(|w| w.to_string()).collect()
        }
        8 => {
            let (kind, _) = rng.pick(&targets);
            let bad_kind = match rng.below(3) {
                0 => kind.to_ascii_uppercase(),
                1 => format!("{kind}s"),
                _ => rng.pick(&["speed", "mu", "friction", "ratio"]).to_string(),
            };
            vec!["target".into(), bad_kind, "0.15".into()]
        }
        _ => {
            let valid: &[&str] = rng.pick(&[
                &["version"][..],
                &["status"],
                &["faults"],
                &["start"],
                &["stop"],
                &["clear"],
                &["help"],
                &["scene", "list"],
                &["scene", "reference"],
                &["freq", "auto"],
                &["freq", "40000"],
                &["telemetry", "off"],
                &["telemetry", "100"],
                &["tare", "all"],
                &["tare", "normal"],
                &["target", "coef", "0.15"],
                &["target", "force", "10"],
                &["cal", "normal", "10"],
            ]);
            let mut words: Vec<String> = valid.iter().map(|w| w.to_string()).collect();
            let extra = match rng.below(3) {
                0 => lowercase_word(rng, 1, 8),
                1 => rng
                    .pick(&["now", "1", "0", "--force", "please", "list", "all"])
                    .to_string(),
                _ => rng.pick(valid).to_string(),
            };
            words.push(extra);
            words
        }
    };
    words
}

/// Joins words with random runs of spaces and tabs, sometimes with leading or trailing blanks
/// or a `\r\n`-style trailing `\r`.
fn spaced(rng: &mut Rng, words: &[String]) -> Vec<u8> {
    let mut line = String::new();
    if rng.percent(10) {
        line.push_str(rng.pick(&[" ", "\t", "  "]));
    }
    for (index, word) in words.iter().enumerate() {
        if index > 0 {
            line.push_str(rng.pick(&[" ", " ", " ", "  ", "\t", " \t "]));
        }
        line.push_str(word);
    }
    match rng.below(10) {
        0 => line.push(' '),
        1 => line.push('\r'),
        _ => {}
    }
    line.into_bytes()
}

fn oversized(rng: &mut Rng) -> Vec<u8> {
    let len = rng.between(MAX_LINE_LEN + 1, 300);
    let mut line: Vec<u8> = match rng.below(4) {
        0 => rng
            .pick(&["stop", "status", "target coef 0.15"])
            .as_bytes()
            .to_vec(),
        1 => (0..len).map(|_| printable(rng)).collect(),
        2 => {
            let mut line = b"target coef 0.15 ".repeat(len / 17 + 1);
            line.truncate(len);
            line
        }
        _ => {
            // A bad byte after the limit: the line was already too long, which is reported.
            let mut line: Vec<u8> = (0..=MAX_LINE_LEN).map(|_| printable(rng)).collect();
            line.push(bad_byte(rng));
            line
        }
    };
    while line.len() < len {
        line.push(b' ');
    }
    line
}

/// Bytes that are neither printable ASCII nor tab, without `\n` and `\r` (either ends the
/// line).
fn bad_byte(rng: &mut Rng) -> u8 {
    loop {
        let byte = match rng.below(3) {
            0 => rng.between(0x00, 0x1f) as u8,
            1 => 0x7f,
            _ => rng.between(0x80, 0xff) as u8,
        };
        if !matches!(byte, b'\t' | b'\n' | b'\r') {
            return byte;
        }
    }
}

fn bad_bytes(rng: &mut Rng) -> Vec<u8> {
    let mut line = match rng.below(3) {
        0 => rng
            .pick(&[
                "status",
                "start",
                "stop",
                "target coef 0.15",
                "scene list",
                "version",
            ])
            .as_bytes()
            .to_vec(),
        1 => {
            let words = bad_argument(rng);
            spaced(rng, &words)
        }
        _ => garbage(rng),
    };
    line.truncate(60);
    for _ in 0..rng.between(1, 3) {
        let at = rng.below(line.len() + 1);
        let insert: Vec<u8> = if rng.percent(30) {
            rng.pick(&[
                "\u{e9}", "\u{b5}", "\u{b0}C", "\u{2192}", "\u{3a9}", "\u{fc}",
            ])
            .as_bytes()
            .to_vec()
        } else {
            vec![bad_byte(rng)]
        };
        line.splice(at..at, insert);
    }
    line
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_same_seed_gives_the_same_lines() {
        let a = flood(7, 500).unwrap();
        assert_eq!(a, flood(7, 500).unwrap());
        assert_ne!(a, flood(8, 500).unwrap());
    }

    #[test]
    fn every_line_is_an_answered_parse_error_with_its_kind_code() {
        let lines = flood(0x5eed, 10_000).unwrap();
        assert_eq!(lines.len(), 10_000);
        let mut kinds = std::collections::BTreeMap::new();
        let mut codes = std::collections::BTreeSet::new();
        for line in &lines {
            assert!(!line.bytes.contains(&b'\n'), "{line:?}");
            assert_eq!(expected_error(&line.bytes), Some(line.expected));
            let code = line.expected.code();
            codes.insert(code.code());
            if let Some(required) = line.kind.required_code() {
                assert_eq!(code, required, "{line:?}");
            }
            if line.kind == FloodKind::Oversized {
                assert!(line.bytes.len() > MAX_LINE_LEN);
            }
            *kinds.entry(line.kind).or_insert(0) += 1;
        }
        for kind in FloodKind::ALL {
            assert!(kinds[&kind] >= 500, "{kind:?}: {kinds:?}");
        }
        // Every parse error the protocol has, except the empty line a blank line never gets.
        assert_eq!(
            codes.into_iter().collect::<Vec<_>>(),
            (1..=12).collect::<Vec<_>>()
        );
    }

    #[test]
    fn predictions_match_the_documented_examples() {
        let code = |line: &[u8]| expected_error(line).map(|e| e.code());
        assert_eq!(code(b"status"), None);
        assert_eq!(code(b"  \t "), None);
        assert_eq!(code(b"a\nb"), None);
        assert_eq!(code(b"jump"), Some(ErrorCode::UnknownCommand));
        assert_eq!(code(b"freq 60000.01"), Some(ErrorCode::OutOfRange));
        assert_eq!(code(&[b'x'; 97]), Some(ErrorCode::LineTooLong));
        assert_eq!(code(b"st\xc3\xa9"), Some(ErrorCode::BadEncoding));
        assert_eq!(code(b"stop\r"), None);
        assert_eq!(code(b"jump\r"), Some(ErrorCode::UnknownCommand));
        assert_eq!(code(b"stop\rjump"), None);
    }
}
