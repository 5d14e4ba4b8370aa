//! A recording's metadata as sweep variables, for `[sweep]` axes over files
//! (`recording = { files = "recordings/*.json" }`, see
//! [`evflow_engine::sweep_files`]): the sidecar's `rate` and every key of
//! its `condition` (`load_g`, `velocity_cm_s`, `material`, `gain` and any
//! other number, text or boolean kept there).

use super::format::Recording;
use evflow_engine::Value;
use std::path::Path;

/// The fields of the recording at `path` (NAME, NAME.wav or NAME.json):
/// `rate` in Hz, then the condition's keys. The recording's files are
/// checked as `recording.in` checks them (no channel is decoded).
pub fn sweep_fields(path: &Path) -> Result<Vec<(String, Value)>, String> {
    let rec = Recording::open_channels(path, &[] as &[&str]).map_err(|e| e.to_string())?;
    let meta = rec.meta();
    let mut out = vec![("rate".to_string(), Value::Float(meta.rate))];
    // The condition as its sidecar writes it: known keys, then the others.
    let condition = serde_json::to_value(&meta.condition).map_err(|e| e.to_string())?;
    for (k, v) in condition.as_object().into_iter().flatten() {
        let value = match v {
            serde_json::Value::Number(n) => n.as_f64().map(Value::Float),
            serde_json::Value::String(s) => Some(Value::Text(s.clone())),
            serde_json::Value::Bool(b) => Some(Value::Bool(*b)),
            _ => None,
        };
        if let Some(value) = value {
            out.push((k.clone(), value));
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::recording::format::{Channel, RecordingMeta, RecordingWriter};

    #[test]
    fn rate_and_condition_become_fields() {
        let dir = tempfile::tempdir().unwrap();
        let mut meta = RecordingMeta::new(10_000.0, vec![Channel::new("force", "N")]);
        meta.condition.load_g = Some(60.0);
        meta.condition.material = Some("felt".into());
        meta.condition.extra.insert("trial".into(), serde_json::json!(3));
        meta.condition.extra.insert("notes".into(), serde_json::json!(["not", "a", "scalar"]));
        let path = dir.path().join("r");
        let mut w = RecordingWriter::create(&path, meta).unwrap();
        w.write_frame(&[0.5]).unwrap();
        w.finish().unwrap();
        let f = sweep_fields(&dir.path().join("r.json")).unwrap();
        assert_eq!(
            f,
            vec![
                ("rate".into(), Value::Float(10_000.0)),
                ("load_g".into(), Value::Float(60.0)),
                ("material".into(), Value::Text("felt".into())),
                ("trial".into(), Value::Float(3.0)),
            ]
        );
        let e = sweep_fields(&dir.path().join("missing.json")).unwrap_err();
        assert!(e.contains("missing"), "{e}");
    }
}
