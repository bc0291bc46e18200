//! Errors that name the file, the key and the reason.

use std::fmt;

/// Why a scene file could not be read: `file: key: reason`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SceneError {
    /// The file, as given to the loader.
    pub file: String,
    /// Dotted path of the offending key (`plant.k_t_n_per_m`, `criteria[2].band_pct`), or the
    /// table for a missing key, or `(file)` when the file as a whole is at fault.
    pub key: String,
    /// What is wrong, with the rule that was broken.
    pub reason: String,
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}: {}", self.file, self.key, self.reason)
    }
}

impl std::error::Error for SceneError {}

/// Builds errors for one file.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Errors<'a> {
    pub file: &'a str,
}

impl Errors<'_> {
    /// An error at `key`.
    pub fn at(&self, key: &str, reason: impl Into<String>) -> SceneError {
        SceneError {
            file: self.file.to_string(),
            key: key.to_string(),
            reason: reason.into(),
        }
    }

    /// `value` if finite and `lo <= value <= hi`.
    pub fn within(&self, key: &str, value: f64, lo: f64, hi: f64) -> Result<f64, SceneError> {
        if value.is_finite() && (lo..=hi).contains(&value) {
            Ok(value)
        } else {
            Err(self.at(key, format!("{value} is outside {lo} ..= {hi}")))
        }
    }

    /// `value` if finite and `0 < value <= hi`.
    pub fn positive(&self, key: &str, value: f64, hi: f64) -> Result<f64, SceneError> {
        if value.is_finite() && value > 0.0 && value <= hi {
            Ok(value)
        } else {
            Err(self.at(key, format!("{value} is outside 0 < value <= {hi}")))
        }
    }

    /// The value of `key` when present, else an error saying why it is needed.
    pub fn required<T>(&self, key: &str, value: Option<T>, why: &str) -> Result<T, SceneError> {
        value.ok_or_else(|| self.at(key, format!("missing: {why}")))
    }

    /// One of `choices` (word, value) for a string key.
    pub fn choose<T: Copy>(
        &self,
        key: &str,
        text: &str,
        choices: &[(&str, T)],
    ) -> Result<T, SceneError> {
        choices
            .iter()
            .find(|(word, _)| *word == text)
            .map(|&(_, value)| value)
            .ok_or_else(|| {
                let allowed: Vec<&str> = choices.iter().map(|(word, _)| *word).collect();
                self.at(
                    key,
                    format!(
                        "unknown value {text:?}, expected one of {}",
                        allowed.join(", ")
                    ),
                )
            })
    }
}

/// The dotted key of a serde error, found from the error's position in `text`: the table
/// header in force at that line (`[a.b]`, or `[[a]]` with its index) and the key on the line.
pub(crate) fn key_of_parse_error(text: &str, error: &toml::de::Error) -> String {
    let message = error.message();
    let missing = message
        .strip_prefix("missing field `")
        .and_then(|rest| rest.split('`').next());
    let Some(span) = error.span() else {
        return missing.unwrap_or("(file)").to_string();
    };
    let mut header = String::new();
    let mut array_counts: Vec<(String, usize)> = Vec::new();
    let mut offset = 0;
    let mut key_on_line = None;
    for line in text.split_inclusive('\n') {
        let end = offset + line.len();
        let trimmed = line.trim();
        let is_header = trimmed.starts_with('[');
        if is_header {
            let inner = trimmed.trim_start_matches('[');
            let name = inner.split(']').next().unwrap_or("").trim().to_string();
            header = if trimmed.starts_with("[[") {
                let index = match array_counts.iter_mut().find(|(n, _)| *n == name) {
                    Some((_, count)) => {
                        *count += 1;
                        *count - 1
                    }
                    None => {
                        array_counts.push((name.clone(), 1));
                        0
                    }
                };
                format!("{name}[{index}]")
            } else {
                name
            };
        }
        if span.start < end {
            if !is_header && !trimmed.starts_with('#') {
                key_on_line = line.split_once('=').map(|(key, _)| key.trim().to_string());
            }
            break;
        }
        offset = end;
    }
    let leaf = missing.map(str::to_string).or(key_on_line);
    match (header.is_empty(), leaf) {
        (true, Some(leaf)) => leaf,
        (false, Some(leaf)) => format!("{header}.{leaf}"),
        (_, None) if header.is_empty() => "(file)".to_string(),
        (_, None) => header,
    }
}
