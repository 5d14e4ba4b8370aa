//! A number case of `tests/fuzz_numbers.rs` and of the cargo-fuzz target
//! `fuzz/fuzz_targets/numbers.rs`: a graph with edits and the command
//! line's numbers, its text format (`tests/fuzz_corpus/numbers/`), and
//! what `evflow check` and `evflow run` do with it.
#![allow(dead_code)]

use evflow_engine::sweep::{check_axes, count, parse_axis, points, validate};
use evflow_engine::{check_duration, graph::parse_graph, run_offline, Override, Plan, PlanOptions, RunOptions};
use std::path::{Path, PathBuf};

/// Sweeps with more runs than this are counted and validated but not
/// built (each build of a shipped graph costs milliseconds).
pub const MAX_BUILT: usize = 24;

/// One change to a graph file's text.
#[derive(Debug, Clone, PartialEq)]
pub enum Edit {
    /// The first occurrence of the text, replaced.
    Replace(String, String),
    /// `[graph] rate = …`.
    GraphRate(String),
    /// The value of the i-th line of `[vars]` (modulo their number).
    Var(usize, String),
    /// The values of the i-th `[sweep]` axis (modulo their number), TOML.
    Sweep(usize, String),
}

/// The numbers of one command: a graph (file name under `graphs/`) with
/// its edits, and the command line's numbers.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Case {
    pub graph: String,
    pub edits: Vec<Edit>,
    pub block: Option<String>,
    pub duration: Option<String>,
    pub sweep: Vec<String>,
    pub set: Vec<String>,
    pub import_rate: Option<String>,
}

impl Case {
    /// The case in the corpus format (for saving a failure).
    pub fn to_text(&self) -> String {
        let mut s = format!("graph = {}\n", self.graph);
        for e in &self.edits {
            match e {
                Edit::Replace(a, b) => s += &format!("replace = {a} => {b}\n"),
                Edit::GraphRate(r) => s += &format!("graph_rate = {r}\n"),
                Edit::Var(i, v) => s += &format!("var = {i} {v}\n"),
                Edit::Sweep(i, v) => s += &format!("sweep_values = {i} {v}\n"),
            }
        }
        for (k, v) in [("block", &self.block), ("duration", &self.duration), ("import_rate", &self.import_rate)] {
            if let Some(v) = v {
                s += &format!("{k} = {v}\n");
            }
        }
        for v in &self.sweep {
            s += &format!("sweep = {v}\n");
        }
        for v in &self.set {
            s += &format!("set = {v}\n");
        }
        s
    }

    /// Reads the corpus format: `key = value` lines; `#` lines are comments.
    pub fn parse(text: &str) -> Result<Case, String> {
        let mut c = Case::default();
        for line in text.lines().map(str::trim).filter(|l| !l.is_empty() && !l.starts_with('#')) {
            let (k, v) = line.split_once(" = ").ok_or_else(|| format!("`{line}`: expected `key = value`"))?;
            let (k, v) = (k.trim(), v.to_string());
            let indexed = |v: &str| -> Result<(usize, String), String> {
                let (i, rest) = v.split_once(' ').ok_or_else(|| format!("`{line}`: expected `INDEX VALUE`"))?;
                Ok((i.parse().map_err(|_| format!("`{line}`: bad index"))?, rest.to_string()))
            };
            match k {
                "graph" => c.graph = v,
                "replace" => {
                    let (a, b) = v.split_once(" => ").ok_or_else(|| format!("`{line}`: expected `OLD => NEW`"))?;
                    c.edits.push(Edit::Replace(a.to_string(), b.to_string()));
                }
                "graph_rate" => c.edits.push(Edit::GraphRate(v)),
                "var" => c.edits.push(indexed(&v).map(|(i, v)| Edit::Var(i, v))?),
                "sweep_values" => c.edits.push(indexed(&v).map(|(i, v)| Edit::Sweep(i, v))?),
                "block" => c.block = Some(v),
                "duration" => c.duration = Some(v),
                "import_rate" => c.import_rate = Some(v),
                "sweep" => c.sweep.push(v),
                "set" => c.set.push(v),
                _ => return Err(format!("`{line}`: unknown key `{k}`")),
            }
        }
        Ok(c)
    }
}

/// The lines of `text` in table `[table]`, as (line index, key, value).
fn table_lines(text: &str, table: &str) -> Vec<(usize, String)> {
    let mut inside = false;
    let mut out = Vec::new();
    for (i, l) in text.lines().enumerate() {
        let t = l.trim();
        if t.starts_with('[') {
            inside = t == format!("[{table}]");
            continue;
        }
        if inside {
            if let Some((k, _)) = t.split_once('=') {
                if !k.trim().is_empty() && !t.starts_with('#') {
                    out.push((i, k.trim().to_string()));
                }
            }
        }
    }
    out
}

/// `text` with the line of table `table` at position `i` (modulo their
/// number) set to `key = value`.
fn set_line(text: &str, table: &str, i: usize, value: &str) -> String {
    let lines = table_lines(text, table);
    if lines.is_empty() {
        return text.to_string();
    }
    let (at, key) = &lines[i % lines.len()];
    text.lines()
        .enumerate()
        .map(|(k, l)| if k == *at { format!("{key} = {value}") } else { l.to_string() })
        .collect::<Vec<_>>()
        .join("\n")
}

fn apply(text: &str, e: &Edit) -> String {
    match e {
        Edit::Replace(a, b) => text.replacen(a.as_str(), b, 1),
        Edit::GraphRate(r) => {
            let i = table_lines(text, "graph").iter().position(|(_, k)| k == "rate").unwrap_or(0);
            set_line(text, "graph", i, r)
        }
        Edit::Var(i, v) => set_line(text, "vars", *i, v),
        Edit::Sweep(i, v) => set_line(text, "sweep", *i, v),
    }
}

/// The graph `name` under `root` (the repository): shipped (`graphs/`),
/// else one of the corpus' (`tests/fuzz_corpus/numbers/graphs/`); its
/// path (so relative files resolve) and text.
fn shipped(root: &Path, name: &str) -> Option<(PathBuf, String)> {
    if name.contains(['/', '\\']) || name.starts_with('.') {
        return None;
    }
    let mut path = root.join("graphs").join(name);
    if !path.is_file() {
        path = root.join("tests/fuzz_corpus/numbers/graphs").join(name);
    }
    let text = std::fs::read_to_string(&path).ok()?;
    Some((path, text))
}

/// How far a case got.
#[derive(Debug, Default)]
pub struct Reached {
    /// Every refusal's message, in order.
    pub errors: Vec<String>,
    /// Runs whose plans were built (as `check` and as `run` builds them).
    pub built: usize,
    /// Runs run.
    pub ran: usize,
}

/// What `evflow check` and `evflow run` do with the case's numbers, in
/// their order, the graph found under `root` (the repository). A panic is
/// the bug.
pub fn exercise(root: &Path, case: &Case) -> Reached {
    let mut errors = Vec::new();
    let (mut built, mut ran) = (0, 0);
    let Some((path, base)) = shipped(root, &case.graph) else {
        errors.push(format!("no graph `{}` in graphs/ or tests/fuzz_corpus/numbers/graphs/", case.graph));
        return Reached { errors, built, ran };
    };
    let text = case.edits.iter().fold(base, |t, e| apply(&t, e));
    // The command line, as clap and the CLI's parsers read it.
    let block = match &case.block {
        None => 4096,
        Some(s) => s.trim().parse::<usize>().unwrap_or_else(|e| {
            errors.push(format!("--block {s}: {e}"));
            4096
        }),
    };
    let duration = case.duration.as_ref().and_then(|s| match s.trim().parse::<f64>() {
        Ok(d) => check_duration(d).map_err(|e| errors.push(format!("--duration {e}"))).ok(),
        Err(_) => {
            errors.push(format!("--duration `{s}` is not a number of seconds"));
            None
        }
    });
    let sets: Vec<Override> = case
        .set
        .iter()
        .filter_map(|s| Override::parse(s).map_err(|e| errors.push(format!("--set {e}"))).ok())
        .collect();
    let axes: Vec<_> =
        case.sweep.iter().filter_map(|s| parse_axis(s).map_err(|e| errors.push(format!("--sweep {e}"))).ok()).collect();
    if let Some(rate) = &case.import_rate {
        import_rate(rate, &mut errors);
    }
    let g = match parse_graph(&path, &text) {
        Ok(g) => g,
        Err(e) => {
            errors.push(e.to_string());
            return Reached { errors, built, ran };
        }
    };
    if let Err(e) = check_axes(&g, &axes) {
        errors.push(e);
        return Reached { errors, built, ran };
    }
    let sweep =
        match evflow_engine::sweep_files::expand(&g, &sets, &evflow_nodes::recording::sweep_fields::sweep_fields) {
            Ok(s) => s,
            Err(e) => {
                errors.push(e.to_string());
                return Reached { errors, built, ran };
            }
        };
    let total = match count(&sweep, &axes, &sets) {
        Ok(n) => n,
        Err(e) => {
            errors.push(e);
            return Reached { errors, built, ran };
        }
    };
    let all = points(&sweep, &axes, &sets);
    assert_eq!(all.len(), total, "count() and points() agree");
    let out = tempfile::tempdir().expect("temp dir");
    let registry = evflow_nodes::registry();
    for (k, v) in validate(&g, &registry, &sets, all, 0..total).into_iter().enumerate() {
        let c = match v.checked {
            Ok(c) => c,
            Err(e) => {
                errors.push(e.to_string());
                continue;
            }
        };
        if k >= MAX_BUILT {
            continue;
        }
        let opts = |check_only| PlanOptions {
            max_block: block,
            out_dir: Some(out.path().to_path_buf()),
            check_only,
            ..PlanOptions::default()
        };
        if let Err(e) = Plan::build(&c, &opts(true)) {
            errors.push(e.to_string());
            continue;
        }
        match Plan::build(&c, &opts(false)) {
            Err(e) => errors.push(e.to_string()),
            // Ten milliseconds of signal, or nothing when a base tick is
            // longer than a second (a test cannot run hours of signal).
            Ok(mut plan) if c.graph.rate >= 1.0 => {
                built += 1;
                let d = duration.unwrap_or(0.01).min(0.01);
                ran += 1;
                if let Err(e) = run_offline(&mut plan, RunOptions { duration: Some(d), progress: None }) {
                    errors.push(e.to_string());
                }
            }
            Ok(_) => built += 1,
        }
    }
    Reached { errors, built, ran }
}

/// `evflow import --rate R` of a three-row CSV.
fn import_rate(r: &str, errors: &mut Vec<String>) {
    let Ok(rate) = r.trim().parse::<f64>() else {
        errors.push(format!("--rate `{r}` is not a number"));
        return;
    };
    let dir = tempfile::tempdir().expect("temp dir");
    let src = dir.path().join("s.csv");
    std::fs::write(&src, "force\n1\n2\n3\n").expect("write");
    let opts = evflow_nodes::recording::import::ImportOptions { rate: Some(rate), ..Default::default() };
    match evflow_nodes::recording::import::read(&src, &opts) {
        Ok(i) => {
            if let Err(e) = i.write(&dir.path().join("out"), false) {
                errors.push(e.to_string());
            }
        }
        Err(e) => errors.push(e.to_string()),
    }
}
