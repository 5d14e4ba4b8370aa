//! Sweep axes over files: `recording = { files = "recordings/*.json" }` in
//! `[sweep]` runs the graph once per matching file, the variable set to the
//! file's path — and, for every other graph variable named like a field of
//! the file's metadata (a recording's `rate` and the keys of its
//! `condition`: `load_g`, `velocity_cm_s`, `material`, …), that field's
//! value. One graph then trains a model per recording of a folder, each
//! at the rate and under the condition its sidecar states.
//!
//! The engine does not read metadata itself: the caller passes a reader
//! (`evflow run` passes the recording format's, in the nodes crate).
//!
//! Patterns: a path relative to the graph file's folder (or absolute) whose
//! last part may hold `*` (any run of characters) and `?` (one character);
//! the folders before it are taken as written, after `${name}` is replaced
//! by the graph variable's value (with `--set` applied), so that
//! `files = "${recordings}/*.json"` and `--set recordings=~/lab/prbs` point
//! one graph at any folder. Matches are sorted by name; a pattern
//! that matches nothing is an error naming the folder it looked in.

use crate::check::interpolate::{interpolate, InterpolateError};
use crate::check::Override;
use crate::graph::{Axis, Graph};
use crate::params::Value;
use std::path::{Path, PathBuf};

/// Why a files axis could not be expanded.
#[derive(Debug, thiserror::Error)]
pub enum FilesError {
    /// The pattern's folder part holds a wildcard, or the pattern is empty.
    #[error("sweep `{axis}`: `{pattern}`: wildcards (`*`, `?`) are allowed in the file name only, not in folders")]
    Pattern {
        /// The axis.
        axis: String,
        /// The pattern as written.
        pattern: String,
    },
    /// The folder could not be listed.
    #[error("sweep `{axis}`: cannot list {}: {source}", dir.display())]
    List {
        /// The axis.
        axis: String,
        /// The folder.
        dir: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// No file matched.
    #[error("sweep `{axis}`: no file in {} matches `{name}`", dir.display())]
    NoMatch {
        /// The axis.
        axis: String,
        /// The folder looked in.
        dir: PathBuf,
        /// The file-name pattern.
        name: String,
    },
    /// The pattern names a variable the graph does not declare, or leaves
    /// a `${` open.
    #[error("sweep `{axis}`: `{pattern}`: {message}")]
    Variable {
        /// The axis.
        axis: String,
        /// The pattern as written.
        pattern: String,
        /// What is wrong.
        message: String,
    },
    /// A matching file's metadata could not be read.
    #[error("sweep `{axis}`: {}: {message}", path.display())]
    Metadata {
        /// The axis.
        axis: String,
        /// The file.
        path: PathBuf,
        /// The reader's message.
        message: String,
    },
}

/// Reads a file's metadata fields as `(name, value)` pairs.
pub type MetadataReader<'a> = &'a dyn Fn(&Path) -> Result<Vec<(String, Value)>, String>;

/// The graph's sweep axes with every files axis expanded: its values the
/// matching paths (as the pattern writes them, relative to the graph's
/// folder), each linked to the metadata fields `read` gives for it that
/// name another declared variable of the graph. `overrides` (`--set`) apply
/// to the variables a pattern names. Axes of listed values are returned as
/// they are.
pub fn expand(graph: &Graph, overrides: &[Override], read: MetadataReader<'_>) -> Result<Vec<Axis>, FilesError> {
    let base = graph.file.parent().map(Path::to_path_buf).unwrap_or_default();
    let mut vars = graph.vars.clone();
    for o in overrides {
        if let Some(v) = vars.iter_mut().find(|v| v.name == o.key) {
            v.value = o.value.clone();
        }
    }
    let mut out = Vec::with_capacity(graph.sweep.len());
    for axis in &graph.sweep {
        let Some(written) = &axis.files else {
            out.push(axis.clone());
            continue;
        };
        let pattern = interpolate(written, &vars).map_err(|e| FilesError::Variable {
            axis: axis.name.clone(),
            pattern: written.clone(),
            message: match e {
                InterpolateError::Unknown(name) => format!("no graph variable `{name}`"),
                InterpolateError::Unclosed => "a `${` without its `}`".to_string(),
            },
        })?;
        let pattern = &pattern;
        let mut values = Vec::new();
        let mut linked = Vec::new();
        for shown in matches(&base, &axis.name, pattern)? {
            let fields = read(&base.join(&shown)).map_err(|message| FilesError::Metadata {
                axis: axis.name.clone(),
                path: base.join(&shown),
                message,
            })?;
            let fields: Vec<(String, Value)> = fields
                .into_iter()
                .filter(|(k, _)| *k != axis.name && graph.vars.iter().any(|v| v.name == *k))
                .collect();
            values.push(Value::Text(shown));
            linked.push(fields);
        }
        out.push(Axis { values, linked, ..axis.clone() });
    }
    Ok(out)
}

/// The paths matching `pattern` under `base`, as the pattern writes them
/// (folder part kept, `/`-separated), sorted.
pub fn matches(base: &Path, axis: &str, pattern: &str) -> Result<Vec<String>, FilesError> {
    let bad = || FilesError::Pattern { axis: axis.to_string(), pattern: pattern.to_string() };
    let (folder, name) = match pattern.rfind('/') {
        Some(i) => (&pattern[..i + 1], &pattern[i + 1..]),
        None => ("", pattern),
    };
    if name.is_empty() || folder.contains(['*', '?']) {
        return Err(bad());
    }
    let dir = base.join(folder);
    let entries = std::fs::read_dir(&dir).map_err(|source| FilesError::List {
        axis: axis.to_string(),
        dir: dir.clone(),
        source,
    })?;
    let mut found: Vec<String> = entries
        .filter_map(Result::ok)
        .filter(|e| e.file_type().map(|t| t.is_file()).unwrap_or(false))
        .filter_map(|e| e.file_name().to_str().map(str::to_string))
        .filter(|f| wildcard(name.as_bytes(), f.as_bytes()))
        .map(|f| format!("{folder}{f}"))
        .collect();
    found.sort();
    if found.is_empty() {
        return Err(FilesError::NoMatch { axis: axis.to_string(), dir, name: name.to_string() });
    }
    Ok(found)
}

/// Whether `text` matches `pat` (`*` any run, `?` one byte, else literal).
fn wildcard(pat: &[u8], text: &[u8]) -> bool {
    // Greedy with one backtrack point: linear for patterns of single stars.
    let (mut p, mut t) = (0, 0);
    let mut star: Option<(usize, usize)> = None;
    while t < text.len() {
        if p < pat.len() && (pat[p] == b'?' || pat[p] == text[t]) {
            p += 1;
            t += 1;
        } else if p < pat.len() && pat[p] == b'*' {
            star = Some((p, t));
            p += 1;
        } else if let Some((sp, st)) = star {
            p = sp + 1;
            t = st + 1;
            star = Some((sp, st + 1));
        } else {
            return false;
        }
    }
    pat[p..].iter().all(|&c| c == b'*')
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::graph::parse_graph;
    use crate::sweep::points;

    #[test]
    fn wildcards_match_as_a_shell_does() {
        for (p, t, want) in [
            ("*.json", "a.json", true),
            ("*.json", "a.wav", false),
            ("prbs-*-?cms.json", "prbs-85g-5cms.json", true),
            ("prbs-*-?cms.json", "prbs-85g-10cms.json", false),
            ("*", "", true),
            ("a*b*c", "aXbYbZc", true),
            ("a*b*c", "aXbYbZ", false),
            ("", "x", false),
            ("x", "x", true),
        ] {
            assert_eq!(wildcard(p.as_bytes(), t.as_bytes()), want, "{p} ~ {t}");
        }
    }

    fn graph(dir: &Path, sweep: &str) -> Graph {
        let text = format!(
            "[graph]\nformat = 1\nrate = 1000.0\n\n[vars]\nrecording = \"\"\nrate = 1000.0\nload_g = 85.0\n\n[sweep]\n{sweep}\n\n[nodes.c]\ntype = \"const\"\n"
        );
        parse_graph(&dir.join("g.toml"), &text).unwrap()
    }

    #[test]
    fn a_files_axis_runs_once_per_file_with_its_metadata() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join("recs")).unwrap();
        for f in ["b.json", "a.json", "a.wav", "notes.txt"] {
            std::fs::write(dir.path().join("recs").join(f), "").unwrap();
        }
        let g = graph(dir.path(), "recording = { files = \"recs/*.json\" }");
        assert_eq!(g.sweep[0].files.as_deref(), Some("recs/*.json"));
        let read = |p: &Path| -> Result<Vec<(String, Value)>, String> {
            let rate = if p.ends_with("a.json") { 10_000.0 } else { 1000.0 };
            // `velocity_cm_s` is not a graph variable: left out.
            Ok(vec![
                ("rate".into(), Value::Float(rate)),
                ("load_g".into(), Value::Float(60.0)),
                ("velocity_cm_s".into(), Value::Float(3.0)),
            ])
        };
        let axes = expand(&g, &[], &read).unwrap();
        let labels: Vec<String> = points(&axes, &[], &[]).iter().map(|p| p.label()).collect();
        assert_eq!(labels, ["recording=recs/a.json rate=10000 load_g=60", "recording=recs/b.json rate=1000 load_g=60"]);
        // Saved and parsed again, the axis is still a files axis.
        let again = parse_graph(&dir.path().join("g.toml"), &g.to_toml()).unwrap();
        assert_eq!(again.sweep[0].files.as_deref(), Some("recs/*.json"));
    }

    #[test]
    fn patterns_take_variables_and_overrides() {
        let dir = tempfile::tempdir().unwrap();
        for sub in ["one", "two"] {
            std::fs::create_dir(dir.path().join(sub)).unwrap();
            std::fs::write(dir.path().join(sub).join(format!("{sub}.json")), "").unwrap();
        }
        let ok = |_: &Path| -> Result<Vec<(String, Value)>, String> { Ok(vec![]) };
        let g = graph(dir.path(), "recording = { files = \"${recording}/*.json\" }");
        let with = |v: &str| {
            let o = [Override { key: "recording".into(), value: Value::Text(v.into()) }];
            expand(&g, &o, &ok).map(|a| a[0].values.clone())
        };
        assert_eq!(with("one").unwrap(), vec![Value::Text("one/one.json".into())]);
        assert_eq!(with("two").unwrap(), vec![Value::Text("two/two.json".into())]);
        let g = graph(dir.path(), "recording = { files = \"${nope}/*.json\" }");
        let e = expand(&g, &[], &ok).unwrap_err();
        assert!(e.to_string().contains("nope"), "{e}");
    }

    #[test]
    fn bad_patterns_and_empty_folders_are_errors_naming_them() {
        let dir = tempfile::tempdir().unwrap();
        let ok = |_: &Path| -> Result<Vec<(String, Value)>, String> { Ok(vec![]) };
        let e = expand(&graph(dir.path(), "recording = { files = \"*.json\" }"), &[], &ok).unwrap_err();
        assert!(e.to_string().contains("no file in") && e.to_string().contains("`*.json`"), "{e}");
        let e = expand(&graph(dir.path(), "recording = { files = \"r*/x.json\" }"), &[], &ok).unwrap_err();
        assert!(e.to_string().contains("file name only"), "{e}");
        let e = expand(&graph(dir.path(), "recording = { files = \"missing/*.json\" }"), &[], &ok).unwrap_err();
        assert!(e.to_string().contains("cannot list"), "{e}");
        std::fs::write(dir.path().join("x.json"), "").unwrap();
        let failing = |_: &Path| -> Result<Vec<(String, Value)>, String> { Err("sidecar is not valid JSON".into()) };
        let e = expand(&graph(dir.path(), "recording = { files = \"*.json\" }"), &[], &failing).unwrap_err();
        assert!(e.to_string().contains("x.json") && e.to_string().contains("not valid JSON"), "{e}");
        // A table with another key is refused when the graph is read.
        let text = "[graph]\nformat = 1\nrate = 1000.0\n[vars]\nr = \"\"\n[sweep]\nr = { glob = \"*.json\" }\n";
        let e = parse_graph(&dir.path().join("g.toml"), text).unwrap_err();
        assert!(e.to_string().contains("one key, `files`"), "{e}");
    }
}
