//! Reading a model's inputs and variant choices by key, shared by every fixed-point evaluator:
//! every key read is remembered, so that [`Keys::finish`] can refuse the unknown ones, and the
//! values the fixed-point path really used can be recorded next to the inputs.

use std::collections::{BTreeMap, BTreeSet};

use super::Inputs;

/// Inputs and variants of one evaluation, read by key.
pub(super) struct Keys<'a> {
    /// Model name, for error messages.
    pub(super) model: &'static str,
    inputs: &'a BTreeMap<String, f64>,
    variant: &'a BTreeMap<String, String>,
    read_inputs: BTreeSet<&'static str>,
    read_variants: BTreeSet<&'static str>,
    quantized: Inputs,
}

impl<'a> Keys<'a> {
    /// Starts reading `inputs` and `variant` for `model`.
    pub(super) fn new(
        model: &'static str,
        inputs: &'a BTreeMap<String, f64>,
        variant: &'a BTreeMap<String, String>,
    ) -> Self {
        Self {
            model,
            inputs,
            variant,
            read_inputs: BTreeSet::new(),
            read_variants: BTreeSet::new(),
            quantized: inputs.clone(),
        }
    }

    /// An optional input; error if present but not finite.
    pub(super) fn optional(&mut self, key: &'static str) -> Result<Option<f64>, String> {
        self.read_inputs.insert(key);
        match self.inputs.get(key) {
            Some(value) if !value.is_finite() => {
                Err(format!("{}: input {key} is not finite", self.model))
            }
            other => Ok(other.copied()),
        }
    }

    /// A required finite input.
    pub(super) fn get(&mut self, key: &'static str) -> Result<f64, String> {
        self.optional(key)?
            .ok_or_else(|| format!("{}: missing input {key}", self.model))
    }

    /// An input with a default when absent.
    pub(super) fn get_or(&mut self, key: &'static str, default: f64) -> Result<f64, String> {
        Ok(self.optional(key)?.unwrap_or(default))
    }

    /// Records the value the fixed-point path used for input `key` (if the caller gave it).
    pub(super) fn record(&mut self, key: &'static str, value: f64) {
        if self.inputs.contains_key(key) {
            self.quantized.insert(key.to_string(), value);
        }
    }

    /// A variant among `choices`; the first choice is the default.
    pub(super) fn choose<T: Copy>(
        &mut self,
        key: &'static str,
        choices: &[(&str, T)],
    ) -> Result<T, String> {
        self.read_variants.insert(key);
        match self.variant.get(key) {
            None => Ok(choices[0].1),
            Some(text) => choices
                .iter()
                .find(|(name, _)| name == text)
                .map(|&(_, value)| value)
                .ok_or_else(|| format!("{}: unknown value {text:?} of variant {key}", self.model)),
        }
    }

    /// `quadrature_points`: a whole number >= 1 (the reference's rule), `default` when absent.
    pub(super) fn quadrature_points(&mut self, default: u32) -> Result<u32, String> {
        self.read_variants.insert("quadrature_points");
        match self.variant.get("quadrature_points") {
            None => Ok(default),
            Some(text) => match text.trim().parse::<u32>() {
                Ok(n) if n >= 1 => Ok(n),
                _ => Err(format!(
                    "{}: quadrature_points must be a whole number >= 1",
                    self.model
                )),
            },
        }
    }

    /// Refuses inputs and variants that were never read; returns the inputs with the values
    /// the fixed-point path recorded.
    pub(super) fn finish(self) -> Result<Inputs, String> {
        if let Some(key) = self
            .inputs
            .keys()
            .find(|k| !self.read_inputs.contains(k.as_str()))
        {
            return Err(format!("{}: unknown input {key}", self.model));
        }
        if let Some(key) = self
            .variant
            .keys()
            .find(|k| !self.read_variants.contains(k.as_str()))
        {
            return Err(format!("{}: unknown variant {key}", self.model));
        }
        Ok(self.quantized)
    }
}
