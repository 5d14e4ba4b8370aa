//! Whole graphs with every output of every node watched: one case per
//! shipped graph family (the graphs of `graphs/` grouped by the first word
//! of their file name), and the runner the stiff cases share.

use super::bounds::{bound, from_params};
use super::invariant::{Invariant, Observed};
use super::{Body, Case, Env, Group, Work};
use evflow_engine::graph::parse_graph;
use evflow_engine::{check, Checked, Plan, PlanOptions, Registry};
use std::path::{Path, PathBuf};

/// The node library's registry plus the harness' `harness.feed` source
/// (a list of values) and `harness.tap` sink.
pub fn registry() -> Registry {
    let mut reg = evflow_nodes::registry();
    reg.add(&evflow_engine::harness::FEED);
    reg.add(&evflow_engine::harness::TAP);
    reg
}

/// Checks graph `text` (as if read from `file`) against [`registry`].
pub fn check_text(file: &Path, text: &str) -> Result<Checked, String> {
    let g = parse_graph(file, text).map_err(|e| e.to_string())?;
    check(&g, &registry(), &[]).map_err(|e| e.to_string())
}

/// How to run a graph for a case.
#[derive(Debug, Clone)]
pub struct Running {
    /// Folder relative input paths are read from.
    pub base_dir: PathBuf,
    /// Folder relative output paths are written to.
    pub out_dir: PathBuf,
    /// Seconds to run at most (the graph's own end comes first).
    pub seconds: f64,
    /// Base ticks per step.
    pub block: usize,
}

/// Builds and runs a checked graph, watching every output of every node
/// after every step (and each node whose type declares a bound that holds
/// whatever its inputs, [`super::bounds::bound`], against that bound: a
/// breach is a violation), then every value the nodes report.
pub fn run_checked(checked: &Checked, r: &Running) -> Observed {
    let mut o = Observed::default();
    let opts = PlanOptions {
        max_block: r.block,
        base_dir: Some(r.base_dir.clone()),
        out_dir: Some(r.out_dir.clone()),
        timing: false,
        ..PlanOptions::default()
    };
    let mut plan = match Plan::build(checked, &opts) {
        Ok(p) => p,
        Err(e) => {
            o.error = Some(e.to_string());
            return o;
        }
    };
    let by_time = (r.seconds * plan.base_rate()).round() as u64;
    let total = plan.remaining_ticks().map_or(by_time, |t| t.min(by_time));
    // (node index, output index, name, bound)
    let mut watched = Vec::new();
    for k in 0..plan.len() {
        let name = plan.node_name(k).to_string();
        let spec = plan.spec(k);
        let b = checked.index(&name).and_then(|i| bound(spec, &from_params(&checked.nodes[i].params), f64::INFINITY));
        for (j, port) in plan.output_names(k).iter().enumerate() {
            let limit = b.as_ref().filter(|(p, _, _)| p == port).map(|(_, v, _)| *v);
            watched.push((k, j, format!("{name}.{port}"), limit));
        }
    }
    let mut done = 0;
    while done < total {
        let n = (plan.max_block() as u64).min(total - done) as usize;
        if let Err(e) = plan.step(n) {
            o.error = Some(e.to_string());
            return o;
        }
        for (k, j, name, limit) in &watched {
            if plan.output_dropped(*k, *j) {
                continue;
            }
            let values = plan.output_at(*k, *j);
            o.watch(name, values);
            if let Some(b) = limit {
                let m = values.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                if m > *b {
                    o.violations.push(format!("{name}: |{m:e}| above its bound {b}"));
                }
            }
        }
        done += n as u64;
    }
    match plan.finish() {
        Ok(summaries) => {
            for (node, s) in summaries {
                for (name, v, _) in &s.values {
                    o.watch(&format!("{node} {name}"), &[*v]);
                }
            }
        }
        Err(e) => o.error = Some(e.to_string()),
    }
    o.notes.insert(0, format!("{done} ticks"));
    o
}

/// The shipped graphs, by family: `(family, files)`, sorted.
pub fn families(graphs: &Path) -> Vec<(String, Vec<PathBuf>)> {
    let mut files: Vec<PathBuf> =
        std::fs::read_dir(graphs).map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect()).unwrap_or_default();
    files.retain(|p| p.extension().is_some_and(|e| e == "toml"));
    files.sort();
    let mut out: Vec<(String, Vec<PathBuf>)> = Vec::new();
    for f in files {
        let stem = f.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        let family = stem.split('-').next().unwrap_or(&stem).to_string();
        match out.iter_mut().find(|(n, _)| *n == family) {
            Some((_, v)) => v.push(f),
            None => out.push((family, vec![f])),
        }
    }
    out
}

/// The family of a shipped graph file name (`texture-live.toml` → `texture`).
pub fn family_of(file: &str) -> &str {
    file.split(['-', '.']).next().unwrap_or(file)
}

/// One case per shipped graph family: each of its graphs run as shipped
/// (its variables' defaults, no sweep) for at most the size's seconds,
/// every output of every node watched.
pub fn cases(env: &Env) -> Vec<Case> {
    families(&env.graphs)
        .into_iter()
        .map(|(family, files)| {
            let names: Vec<String> =
                files.iter().filter_map(|f| f.file_name().map(|n| n.to_string_lossy().into_owned())).collect();
            let mut covers: Vec<&'static str> = Vec::new();
            for f in &files {
                if let Ok(c) = evflow_engine::load_file(f, &registry(), &[]) {
                    for n in &c.nodes {
                        if !covers.contains(&n.spec.name) {
                            covers.push(n.spec.name);
                        }
                    }
                }
            }
            let seconds = env.size.graph_seconds();
            // One piece per graph: a graph that does not load ends the case.
            let pieces = files
                .iter()
                .map(|f| {
                    let f = f.clone();
                    let body = move |env: &Env| {
                        let name = f.display().to_string();
                        let checked = match evflow_engine::load_file(&f, &registry(), &[]) {
                            Ok(c) => c,
                            Err(e) => {
                                return Observed {
                                    error: Some(format!("{name}: {e}")),
                                    ends_case: true,
                                    ..Observed::default()
                                }
                            }
                        };
                        let base = f.parent().map(Path::to_path_buf).unwrap_or_default();
                        let run = Running { base_dir: base, out_dir: env.dir.join("graph-out"), seconds, block: 4096 };
                        let mut g = run_checked(&checked, &run);
                        if let Some(e) = g.error.take() {
                            g.error = Some(format!("{name}: {e}"));
                        }
                        // A graph that stopped before its first step has no count of ticks.
                        let ran = g.notes.first().cloned().unwrap_or_else(|| "did not start".into());
                        g.notes = vec![format!("{}: {ran}", f.file_name().unwrap_or_default().to_string_lossy())];
                        g
                    };
                    Box::new(body) as Body
                })
                .collect();
            Case {
                name: format!("graphs · {family}"),
                group: Group::Graph,
                covers,
                family: Some(family.clone()),
                extreme: format!(
                    "{} as shipped, every node's every output watched, ≤ {seconds} s each",
                    names.join(", ")
                ),
                invariant: Invariant::Finite { refusal_ok: false },
                work: Work::Pieces(pieces),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn families_are_the_first_word() {
        assert_eq!(family_of("texture-live-play.toml"), "texture");
        assert_eq!(family_of("characterize.toml"), "characterize");
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../graphs");
        let f = families(&root);
        assert!(f.iter().any(|(n, v)| n == "texture" && v.len() > 3), "{f:?}");
    }

    #[test]
    fn a_graph_that_does_not_load_or_start_fails_its_family_naming_it() {
        let dir = tempfile::tempdir().unwrap();
        // Loads, but its recording is missing: the plan cannot start.
        let start = "[graph]\nformat = 1\nname = \"t\"\nrate = 1000\nconnections = [\"r.force -> t.in\"]\n\
                     [nodes.r]\ntype = \"recording.in\"\npath = \"missing\"\nchannels = [\"force\"]\nrate = 1000\n\
                     [nodes.t]\ntype = \"harness.tap\"\n";
        std::fs::write(dir.path().join("start-missing.toml"), start).unwrap();
        std::fs::write(dir.path().join("start-zz.toml"), "[graph]\nformat = 1\n").unwrap();
        std::fs::write(dir.path().join("load-broken.toml"), "[graph]\nformat = 1\n").unwrap();
        let env = Env { dir: dir.path().join("fixtures"), graphs: dir.path().into(), size: super::super::Size::Ci };
        let rows: Vec<_> = cases(&env).iter().map(|c| super::super::run_case(c, &env)).collect();
        assert_eq!(rows.len(), 2);
        for r in &rows {
            assert!(!r.verdict.passed(), "{}: {}", r.case, r.detail);
            assert!(!r.detail.contains("panicked"), "{}: {}", r.case, r.detail);
        }
        assert!(rows[0].detail.contains("load-broken.toml"), "{}", rows[0].detail);
        // The missing recording is named, and the graph after it, which
        // does not load, is the case's error.
        let d = &rows[1].detail;
        assert!(d.contains("start-missing.toml: did not start") && d.contains("missing"), "{d}");
        assert!(d.contains("start-zz.toml"), "{d}");
    }

    #[test]
    fn a_limit_above_its_bound_is_caught_in_a_graph() {
        // A sine of amplitude 2 through a limit of amplitude 1: the limit's
        // output stays within 1; a bound of 0.5 would not hold (checked via
        // the bound table's rule for `limit`).
        let text =
            "[graph]\nformat = 1\nname = \"t\"\nrate = 1000\nconnections = [\"s.out -> l.in\", \"l.out -> t.in\"]\n\
                    [nodes.s]\ntype = \"sine\"\namplitude = 2.0\nfrequency = 5.0\n\
                    [nodes.l]\ntype = \"limit\"\namplitude = 1.0\nslew = 1e12\nramp = 0.0\n\
                    [nodes.t]\ntype = \"harness.tap\"\n";
        let checked = check_text(Path::new("t.toml"), text).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let r = Running { base_dir: dir.path().into(), out_dir: dir.path().into(), seconds: 1.0, block: 64 };
        let o = run_checked(&checked, &r);
        assert_eq!(o.error, None);
        assert_eq!(o.non_finite, 0, "{o:?}");
        let lim = o.ports.iter().find(|(n, _)| n == "l.out").unwrap().1;
        assert!(lim <= 1.0 && lim > 0.99, "{lim}");
        let s = o.ports.iter().find(|(n, _)| n == "s.out").unwrap().1;
        assert!(s > 1.9, "{s}");
    }
}
