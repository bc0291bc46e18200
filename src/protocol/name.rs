//! Scene names as they travel in commands: a small owned, copyable string.
//!
//! The command must outlive the received line (the firmware passes it to another task through a
//! channel), so the name is copied into a fixed array rather than borrowed.

/// Longest scene name, in bytes.
pub const MAX_SCENE_NAME_LEN: usize = 24;

/// Names no scene may have: `scene list` is the listing command, and `none` is what a status
/// reply shows when no scene is selected.
pub const RESERVED_SCENE_NAMES: [&str; 2] = ["list", "none"];

/// Whether `name` is a valid scene name: 1 to [`MAX_SCENE_NAME_LEN`] bytes of `[a-z0-9_-]`,
/// and not one of [`RESERVED_SCENE_NAMES`].
pub fn is_scene_name(name: &str) -> bool {
    !name.is_empty()
        && name.len() <= MAX_SCENE_NAME_LEN
        && !RESERVED_SCENE_NAMES.contains(&name)
        && name
            .bytes()
            .all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'_' || b == b'-')
}

/// A valid scene name (see [`is_scene_name`]), stored inline.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct SceneName {
    /// The name's bytes, zero after `len` (so derived equality compares names).
    bytes: [u8; MAX_SCENE_NAME_LEN],
    /// Bytes in use, `1..=MAX_SCENE_NAME_LEN`.
    len: u8,
}

impl SceneName {
    /// The name, or `None` if `name` is not a valid scene name.
    pub fn new(name: &str) -> Option<Self> {
        if !is_scene_name(name) {
            return None;
        }
        let mut bytes = [0u8; MAX_SCENE_NAME_LEN];
        for (slot, byte) in bytes.iter_mut().zip(name.bytes()) {
            *slot = byte;
        }
        // is_scene_name bounds the length by 24, so it fits a u8.
        let len = u8::try_from(name.len()).ok()?;
        Some(Self { bytes, len })
    }

    /// The name as text.
    pub fn as_str(&self) -> &str {
        let used = self.bytes.get(..usize::from(self.len)).unwrap_or(&[]);
        // Only ASCII is ever stored, so this cannot fail; an empty name is the harmless fallback.
        core::str::from_utf8(used).unwrap_or("")
    }
}

#[cfg(feature = "defmt")]
impl defmt::Format for SceneName {
    fn format(&self, f: defmt::Formatter) {
        defmt::write!(f, "{=str}", self.as_str())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn valid_names() {
        for name in ["a", "ramp-up_2", "0", &"z".repeat(MAX_SCENE_NAME_LEN)] {
            assert_eq!(
                SceneName::new(name).map(|n| n.as_str().len()),
                Some(name.len())
            );
            assert_eq!(SceneName::new(name).unwrap().as_str(), name);
        }
    }

    #[test]
    fn invalid_names() {
        let too_long = "z".repeat(MAX_SCENE_NAME_LEN + 1);
        for name in [
            "",
            "list",
            "none",
            "Ramp",
            "a b",
            "a.b",
            "caf\u{e9}",
            too_long.as_str(),
        ] {
            assert_eq!(SceneName::new(name), None, "{name:?}");
        }
    }
}
