//! Output clashes: runs of a batch that would write the same file.
//!
//! A sweep's runs share one output folder. When a sink's output name does
//! not vary with the swept variables (`path = "rec"` instead of
//! `path = "rec-${mass}g"`), every run writes the same file: in sequence
//! each overwrites the last, on several threads they race. Such a sweep is
//! refused before anything runs, naming the file and the runs (and nodes)
//! that would write it.
//!
//! The files a run writes: the `path` parameter of every sink that enters
//! its plan (`recording.out`, `narx.train`, `synth.train`, … — the
//! convention of the node library: a sink's output file is its `path`),
//! resolved against the output folder as the sink does
//! ([`crate::node::BuildContext::out_path`]). A recording's `NAME`,
//! `NAME.wav` and `NAME.json` are one output (it writes both files), so
//! those extensions are ignored when comparing.

use crate::check::Checked;
use crate::params::Value;
use crate::spec::Role;
use std::collections::BTreeMap;
use std::path::{Component, Path, PathBuf};

/// One file that several writers would write.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Clash {
    /// The file, as the first writer names it (resolved against the output folder).
    pub file: PathBuf,
    /// Every writer: (run label, node name), in run order.
    pub writers: Vec<(String, String)>,
}

/// Runs of a batch that would write the same files.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{}", describe(.0))]
pub struct ClashError(pub Vec<Clash>);

fn describe(clashes: &[Clash]) -> String {
    let mut s = format!(
        "{} output file{} would be written by more than one run (each would overwrite the other; \
         put a swept variable in the name, e.g. path = \"rec-${{mass}}g\"):",
        clashes.len(),
        if clashes.len() == 1 { "" } else { "s" }
    );
    for c in clashes {
        let who: Vec<String> = c.writers.iter().map(|(run, node)| format!("{run} (node `{node}`)")).collect();
        s.push_str(&format!("\n  {}: {}", c.file.display(), who.join(", ")));
    }
    s
}

/// The files a checked run writes: `(node, path)` for the `path` parameter
/// of every sink in its plan, resolved against `out_dir`.
pub fn output_files(run: &Checked, out_dir: &Path) -> Vec<(String, PathBuf)> {
    run.order
        .iter()
        .map(|&i| &run.nodes[i])
        .filter(|n| n.spec.role == Role::Sink)
        .filter_map(|n| match n.params.get("path") {
            Some(Value::Text(p)) if !p.is_empty() => Some((n.name.clone(), out_dir.join(p))),
            _ => None,
        })
        .collect()
}

/// The comparison key of an output path: lexically normalized (`.` and
/// `x/..` removed), a recording's `.wav` / `.json` extension dropped.
fn key(p: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in p.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir if matches!(out.components().next_back(), Some(Component::Normal(_))) => {
                out.pop();
            }
            c => out.push(c),
        }
    }
    if out.extension().is_some_and(|e| e == "wav" || e == "json") {
        out.set_extension("");
    }
    out
}

/// The clashes among runs given as `(label, files)` with files as
/// [`output_files`] lists them: every file more than one writer (another
/// run, or another node of the same run) would write, in order of first
/// appearance. `Ok` when every file has one writer.
pub fn check_outputs(runs: &[(String, Vec<(String, PathBuf)>)]) -> Result<(), ClashError> {
    let mut by_key: BTreeMap<PathBuf, (usize, Clash)> = BTreeMap::new();
    let mut order = 0;
    for (label, files) in runs {
        for (node, file) in files {
            let e = by_key.entry(key(file)).or_insert_with(|| {
                order += 1;
                (order, Clash { file: file.clone(), writers: Vec::new() })
            });
            e.1.writers.push((label.clone(), node.clone()));
        }
    }
    let mut clashes: Vec<(usize, Clash)> = by_key.into_values().filter(|(_, c)| c.writers.len() > 1).collect();
    clashes.sort_by_key(|(i, _)| *i);
    if clashes.is_empty() {
        Ok(())
    } else {
        Err(ClashError(clashes.into_iter().map(|(_, c)| c).collect()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(label: &str, files: &[(&str, &str)]) -> (String, Vec<(String, PathBuf)>) {
        (label.into(), files.iter().map(|(n, f)| (n.to_string(), PathBuf::from(f))).collect())
    }

    #[test]
    fn distinct_outputs_pass_and_shared_ones_name_file_runs_and_nodes() {
        let ok = [run("mass=60", &[("rec", "out/rec-60")]), run("mass=110", &[("rec", "out/rec-110")])];
        assert_eq!(check_outputs(&ok), Ok(()));
        let bad = [
            run("mass=60", &[("rec", "out/rec"), ("model", "out/m-60.json")]),
            run("mass=85", &[("rec", "out/./rec.wav"), ("model", "out/m-85.json")]),
            run("mass=110", &[("rec", "out/x/../rec.json"), ("model", "out/m-110.json")]),
        ];
        let e = check_outputs(&bad).unwrap_err();
        assert_eq!(e.0.len(), 1);
        assert_eq!(e.0[0].file, PathBuf::from("out/rec"));
        assert_eq!(e.0[0].writers.iter().map(|w| w.0.as_str()).collect::<Vec<_>>(), ["mass=60", "mass=85", "mass=110"]);
        let msg = e.to_string();
        assert!(msg.starts_with("1 output file would be written by more than one run"), "{msg}");
        assert!(msg.contains("out/rec: mass=60 (node `rec`), mass=85 (node `rec`), mass=110 (node `rec`)"), "{msg}");
    }

    #[test]
    fn two_nodes_of_one_run_on_one_file_clash_too() {
        let e = check_outputs(&[run("(defaults)", &[("a", "o/f.json"), ("b", "o/f"), ("c", "o/g")])]).unwrap_err();
        assert_eq!(
            e.0,
            vec![Clash {
                file: "o/f.json".into(),
                writers: vec![("(defaults)".into(), "a".into()), ("(defaults)".into(), "b".into())]
            }]
        );
        assert_eq!(check_outputs(&[]), Ok(()));
    }
}
