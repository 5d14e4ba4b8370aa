//! Floats saved as Rust's shortest exact text (`"0.1"`, `"-0.0"`, `"NaN"`,
//! `"inf"`) and read back bit for bit (a NaN's sign aside): a JSON number cannot hold NaN or an
//! infinity, and a study's scores may be either (`f64::NAN` marks what was
//! not computed). For `#[serde(with = "exact")]` on an `f64` field, and
//! [`triple`] on an `[f64; 3]`.

use serde::de::Error as _;
use serde::{Deserialize, Deserializer, Serializer};

/// Writes `v` as its exact text.
pub fn serialize<S: Serializer>(v: &f64, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(&format!("{v:?}"))
}

/// Reads a float written by [`serialize`] (or a plain JSON number).
pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    #[derive(Deserialize)]
    #[serde(untagged)]
    enum Either {
        Text(String),
        Number(f64),
    }
    match Either::deserialize(d)? {
        Either::Number(v) => Ok(v),
        Either::Text(t) => t.parse().map_err(|_| D::Error::custom(format!("`{t}` is not a number"))),
    }
}

/// `[f64; 3]` as three exact texts.
pub mod triple {
    use super::*;
    use serde::ser::SerializeTuple;

    /// Writes the three floats.
    pub fn serialize<S: Serializer>(v: &[f64; 3], s: S) -> Result<S::Ok, S::Error> {
        let mut t = s.serialize_tuple(3)?;
        for x in v {
            t.serialize_element(&format!("{x:?}"))?;
        }
        t.end()
    }

    /// Reads three floats written by [`serialize`].
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<[f64; 3], D::Error> {
        let t = <[String; 3]>::deserialize(d)?;
        let mut v = [0.0; 3];
        for (x, s) in v.iter_mut().zip(&t) {
            *x = s.parse().map_err(|_| D::Error::custom(format!("`{s}` is not a number")))?;
        }
        Ok(v)
    }
}

#[cfg(test)]
mod tests {
    use serde::{Deserialize, Serialize};

    #[derive(Serialize, Deserialize, Debug)]
    struct S {
        #[serde(with = "super")]
        x: f64,
        #[serde(with = "super::triple")]
        t: [f64; 3],
    }

    #[test]
    fn every_float_reads_back_bit_for_bit_nan_and_infinities_too() {
        for x in [0.1, -0.0, 0.0, f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e-310, f64::MAX, 1.0 / 3.0] {
            let s = S { x, t: [x, -x, 2.5] };
            let text = serde_json::to_string(&s).unwrap();
            let back: S = serde_json::from_str(&text).unwrap();
            // NaN's sign is not kept (Rust writes every NaN as `NaN`); every other bit is.
            let same = |a: f64, b: f64| a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan());
            assert!(same(back.x, x), "{text}");
            assert!(back.t.iter().zip(&s.t).all(|(a, b)| same(*a, *b)), "{text}");
        }
        // A plain JSON number is read too; text that is no number is named.
        let s: S = serde_json::from_str(r#"{"x": 2.5, "t": ["1", "2", "3"]}"#).unwrap();
        assert_eq!((s.x, s.t), (2.5, [1.0, 2.0, 3.0]));
        let e = serde_json::from_str::<S>(r#"{"x": "two", "t": ["1", "2", "3"]}"#).unwrap_err();
        assert!(e.to_string().contains("`two` is not a number"), "{e}");
    }
}
