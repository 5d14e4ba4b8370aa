//! Network settings of the NARX study: `NAME=HIDDEN/FEEDBACK/INPUT/TRAINER`.

use crate::graphs::Sets;
use crate::StudyError;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// The settings compared by default; the first is evflow's default network.
pub const DEFAULT_SETTINGS: &[&str] = &[
    "default=15-10-5/1/10/lm",
    "one-layer-5=5/1/10/lm",
    "one-layer-15=15/1/10/lm",
    "wide=30-20-10/1/10/lm",
    "input-5=15-10-5/1/5/lm",
    "input-20=15-10-5/1/20/lm",
    "feedback-2=15-10-5/2/10/lm",
    "adam=15-10-5/1/10/adam",
    "adam-one-layer-5=5/1/10/adam",
];

/// One network setting: `NAME=HIDDEN/FEEDBACK/INPUT/TRAINER`.
#[derive(Debug, Clone, PartialEq)]
pub struct Setting {
    /// Its name (the folder of its models, the table's first column).
    pub name: String,
    /// Hidden layer sizes.
    pub hidden: Vec<usize>,
    /// Feedback taps k_y.
    pub feedback: usize,
    /// Input taps k_x.
    pub input: usize,
    /// The trainer: `lm` or `adam`.
    pub algorithm: String,
}

impl Setting {
    /// Parses `NAME=HIDDEN/FEEDBACK/INPUT/TRAINER`, hidden layers joined by
    /// `-` (e.g. `small=5/1/10/lm`).
    pub fn parse(s: &str) -> Result<Self, StudyError> {
        let bad = |m: &str| StudyError::Config(format!("setting `{s}`: {m}"));
        let (name, rest) = s.split_once('=').ok_or_else(|| bad("not NAME=HIDDEN/FEEDBACK/INPUT/TRAINER"))?;
        let parts: Vec<&str> = rest.split('/').collect();
        if parts.len() != 4 {
            return Err(bad("give HIDDEN/FEEDBACK/INPUT/TRAINER, e.g. 15-10-5/1/10/lm"));
        }
        let hidden = parts[0]
            .split('-')
            .map(|h| h.trim().parse::<usize>().ok().filter(|&h| h > 0))
            .collect::<Option<Vec<_>>>()
            .ok_or_else(|| bad("hidden layers are sizes ≥ 1 joined by `-`"))?;
        let num = |x: &str, what: &str| {
            x.trim().parse::<usize>().map_err(|_| bad(&format!("{what} `{x}` is not a whole number")))
        };
        let algorithm = parts[3].trim().to_string();
        if algorithm != "lm" && algorithm != "adam" {
            return Err(bad("the trainer is lm or adam"));
        }
        let name = name.trim();
        if name.is_empty() || name.contains(['/', '\\']) || name == "." || name == ".." || name == "base" {
            return Err(bad("the name is a folder name: not empty, no `/`, not `base`"));
        }
        Ok(Self {
            name: name.into(),
            hidden,
            feedback: num(parts[1], "feedback")?,
            input: num(parts[2], "input")?,
            algorithm,
        })
    }

    /// The setting as [`Setting::parse`] reads it.
    pub fn spec(&self) -> String {
        let h: Vec<String> = self.hidden.iter().map(|h| h.to_string()).collect();
        format!("{}={}/{}/{}/{}", self.name, h.join("-"), self.feedback, self.input, self.algorithm)
    }

    /// The values of graphs/model-build.toml that select it.
    pub fn overrides(&self) -> Sets {
        let hidden: Vec<f64> = self.hidden.iter().map(|&h| h as f64).collect();
        Sets::new()
            .nums("train.hidden", &hidden)
            .int("train.feedback", self.feedback as i64)
            .int("train.input", self.input as i64)
            .text("train.algorithm", &self.algorithm)
    }

    /// "15-10-5, k_y 1, k_x 10, LM".
    pub fn describe(&self) -> String {
        let h: Vec<String> = self.hidden.iter().map(|h| h.to_string()).collect();
        format!("{}, k_y {}, k_x {}, {}", h.join("-"), self.feedback, self.input, self.algorithm.to_uppercase())
    }
}

/// A setting is saved as the text [`Setting::parse`] reads.
impl Serialize for Setting {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&self.spec())
    }
}

impl<'de> Deserialize<'de> for Setting {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let text = String::deserialize(d)?;
        Setting::parse(&text).map_err(serde::de::Error::custom)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use evflow_engine::Value;

    #[test]
    fn settings_parse_into_model_build_overrides() {
        let s = Setting::parse("wide=30-20-10/2/15/adam").unwrap();
        assert_eq!((s.hidden.clone(), s.feedback, s.input, s.algorithm.as_str()), (vec![30, 20, 10], 2, 15, "adam"));
        let o = s.overrides();
        assert_eq!(o.get("train.hidden"), Some(&Value::FloatList(vec![30.0, 20.0, 10.0])));
        assert_eq!(o.get("train.feedback"), Some(&Value::Int(2)));
        assert_eq!(o.get("train.input"), Some(&Value::Int(15)));
        assert_eq!(o.get("train.algorithm"), Some(&Value::Text("adam".into())));
        assert_eq!(Setting::parse(&s.spec()).unwrap(), s);
        for bad in
            ["x", "x=15/1/10", "x=15-0/1/10/lm", "x=15/a/10/lm", "x=15/1/10/sgd", "a/b=5/1/10/lm", "base=5/1/1/lm"]
        {
            assert!(Setting::parse(bad).is_err(), "{bad}");
        }
        for d in DEFAULT_SETTINGS {
            Setting::parse(d).unwrap();
        }
    }

    #[test]
    fn a_setting_is_saved_as_its_text() {
        let s = Setting::parse("wide=30-20-10/2/15/adam").unwrap();
        let json = serde_json::to_string(&s).unwrap();
        assert_eq!(json, "\"wide=30-20-10/2/15/adam\"");
        assert_eq!(serde_json::from_str::<Setting>(&json).unwrap(), s);
        let e = serde_json::from_str::<Setting>("\"x=15/1/10/sgd\"").unwrap_err().to_string();
        assert!(e.contains("the trainer is lm or adam"), "{e}");
    }
}
