//! `evflow merge OUT SHARD_DIRS...`: joins the outputs of the shards of a
//! sweep (`evflow run --shard K/N`) into what one run would have written.
//!
//! Each shard leaves `shard.json` in its output folder: which slice it ran,
//! of how many runs, and every run's variables and report in full (floats
//! as exact decimal text, times in nanoseconds). The merge checks that the
//! shards are one sweep's (same graph, same count, every K of N once),
//! copies the files the graphs wrote, and writes the CSV and JSON tables
//! with the same code as `evflow run`, from the runs in sweep order. With
//! `--no-times` on the shards the tables are byte for byte those of one
//! run; with times, only the measured times differ.
//!
//! Folders of a model library built in shards (`evflow library build
//! --shard K/N`) merge the same way: their files copied, their indexes
//! joined in the library's order.

use super::run_report::{report_json, sweep_csv, Timings};
use anyhow::{anyhow, bail, Context, Result};
use evflow_engine::batch::{Failures, Shard};
use evflow_engine::graph::parse_cli_value;
use evflow_engine::plan::NodeTime;
use evflow_engine::sweep::Point;
use evflow_engine::{RunReport, Summary};
use serde_json::{json, Value as Json};
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// The name of a shard's record in its output folder.
pub const RECORD: &str = "shard.json";

/// Arguments of `evflow merge`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The folder to merge into (created; files already there are replaced).
    out: PathBuf,
    /// The shards' output folders (`--out` of each `evflow run --shard`), in any order.
    #[arg(required = true)]
    shards: Vec<PathBuf>,
}

/// What a shard ran and found: written by `evflow run --shard`, read by `evflow merge`.
#[derive(Debug, Clone)]
pub struct ShardRecord {
    /// The graph file, as given.
    pub graph: String,
    /// Which slice.
    pub shard: Shard,
    /// Runs in the whole sweep.
    pub total: usize,
    /// The slice's runs among them.
    pub range: Range<usize>,
    /// The sweep index of each run that succeeded.
    pub indices: Vec<usize>,
    /// The runs that succeeded, in sweep order.
    pub runs: Vec<(Point, RunReport)>,
    /// The runs that failed: `(label, reason)`.
    pub failures: Vec<(String, String)>,
    /// Whether it is a sweep (several runs) or one run.
    pub sweep: bool,
    /// Whether the tables hold run times.
    pub timings: Timings,
    /// The CSV table's path relative to the output folder, if written.
    pub csv: Option<String>,
    /// The JSON results' path relative to the output folder, if written.
    pub json: Option<String>,
}

/// `path` relative to `dir` when it lies inside it, else as given.
pub fn relative_to(path: &Path, dir: &Path) -> String {
    let abs = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
    let (p, d) = (abs(path), abs(dir));
    p.strip_prefix(&d).map(Path::to_path_buf).unwrap_or(p).to_string_lossy().replace('\\', "/")
}

fn nanos(d: Duration) -> u64 {
    d.as_nanos().min(u64::MAX as u128) as u64
}

fn report_to_json(r: &RunReport) -> Json {
    let times: Vec<Json> = r
        .times
        .iter()
        .map(|t| {
            json!({ "node": t.node, "type": t.kind, "setup_ns": nanos(t.setup), "process_ns": nanos(t.process),
                    "finish_ns": nanos(t.finish), "elapsed_ns": nanos(t.elapsed) })
        })
        .collect();
    let summaries: Vec<Json> = r
        .summaries
        .iter()
        .map(|(node, s)| {
            // Floats as Rust's shortest exact text: they read back bit for bit.
            let values: Vec<Json> = s.values.iter().map(|(k, v, u)| json!([k, format!("{v:?}"), u])).collect();
            json!({ "node": node, "values": values, "lines": s.lines })
        })
        .collect();
    json!({ "ticks": r.ticks, "base_rate": format!("{:?}", r.base_rate), "elapsed_ns": nanos(r.elapsed),
            "times": times, "summaries": summaries })
}

impl ShardRecord {
    /// Writes the record into `dir` (through a temporary file).
    pub fn write(&self, dir: &Path) -> Result<()> {
        use evflow_engine::check::interpolate::text_of;
        let runs: Vec<Json> = self
            .runs
            .iter()
            .zip(&self.indices)
            .map(|((p, r), i)| {
                let vars: Vec<Json> = p.values.iter().map(|(k, v)| json!([k, text_of(v)])).collect();
                json!({ "index": i, "vars": vars, "report": report_to_json(r) })
            })
            .collect();
        let failures: Vec<Json> = self.failures.iter().map(|(l, r)| json!({ "run": l, "reason": r })).collect();
        let doc = json!({
            "graph": self.graph,
            "shard": self.shard.to_string(),
            "total": self.total,
            "range": [self.range.start, self.range.end],
            "sweep": self.sweep,
            "times": self.timings == Timings::Show,
            "csv": self.csv,
            "json": self.json,
            "runs": runs,
            "failures": failures,
        });
        let path = dir.join(RECORD);
        let tmp = dir.join(format!(".{RECORD}.tmp"));
        std::fs::write(&tmp, serde_json::to_string_pretty(&doc)?)
            .and_then(|_| std::fs::rename(&tmp, &path))
            .with_context(|| format!("{}: cannot write the shard's record", path.display()))
    }

    /// Reads the record in `dir`; errors name the file and what is wrong.
    pub fn read(dir: &Path) -> Result<ShardRecord> {
        let path = dir.join(RECORD);
        let text = std::fs::read_to_string(&path)
            .with_context(|| format!("{}: cannot read (is it the --out of `evflow run --shard`?)", path.display()))?;
        let doc: Json = serde_json::from_str(&text).map_err(|e| anyhow!("{}: {e}", path.display()))?;
        parse_record(&doc).map_err(|e| anyhow!("{}: {e}", path.display()))
    }
}

fn field<'a>(v: &'a Json, key: &str) -> Result<&'a Json> {
    v.get(key).ok_or_else(|| anyhow!("missing `{key}`"))
}
fn text<'a>(v: &'a Json, key: &str) -> Result<&'a str> {
    field(v, key)?.as_str().ok_or_else(|| anyhow!("`{key}` is not text"))
}
fn count(v: &Json, key: &str) -> Result<u64> {
    field(v, key)?.as_u64().ok_or_else(|| anyhow!("`{key}` is not a whole number"))
}
fn float(v: &Json, what: &str) -> Result<f64> {
    v.as_str().and_then(|s| s.parse().ok()).ok_or_else(|| anyhow!("{what}: not a number written as text"))
}
fn list<'a>(v: &'a Json, key: &str) -> Result<&'a Vec<Json>> {
    field(v, key)?.as_array().ok_or_else(|| anyhow!("`{key}` is not a list"))
}
fn optional_text(v: &Json, key: &str) -> Result<Option<String>> {
    match field(v, key)? {
        Json::Null => Ok(None),
        Json::String(s) => Ok(Some(s.clone())),
        _ => bail!("`{key}` is not text"),
    }
}

fn parse_report(v: &Json) -> Result<RunReport> {
    let registry = evflow_nodes::registry();
    let mut times = Vec::new();
    for t in list(v, "times")? {
        let kind = text(t, "type")?;
        // Node types are the registry's static names; one this build does
        // not know keeps its name for the life of the program.
        let kind: &'static str =
            registry.get(kind).map(|s| s.name).unwrap_or_else(|| Box::leak(kind.to_string().into_boxed_str()));
        times.push(NodeTime {
            node: text(t, "node")?.to_string(),
            kind,
            setup: Duration::from_nanos(count(t, "setup_ns")?),
            process: Duration::from_nanos(count(t, "process_ns")?),
            finish: Duration::from_nanos(count(t, "finish_ns")?),
            elapsed: Duration::from_nanos(count(t, "elapsed_ns")?),
        });
    }
    let mut summaries = Vec::new();
    for s in list(v, "summaries")? {
        let node = text(s, "node")?.to_string();
        let mut values = Vec::new();
        for x in list(s, "values")? {
            match x.as_array().map(Vec::as_slice) {
                Some([Json::String(k), v, Json::String(u)]) => {
                    values.push((k.clone(), float(v, &format!("`{node}.{k}`"))?, u.clone()))
                }
                _ => bail!("`{node}`: a value is not [name, \"number\", unit]"),
            }
        }
        let lines = list(s, "lines")?
            .iter()
            .map(|l| l.as_str().map(str::to_string).ok_or_else(|| anyhow!("`{node}`: a line is not text")))
            .collect::<Result<Vec<_>>>()?;
        summaries.push((node, Summary { values, lines }));
    }
    Ok(RunReport {
        ticks: count(v, "ticks")?,
        base_rate: float(field(v, "base_rate")?, "`base_rate`")?,
        elapsed: Duration::from_nanos(count(v, "elapsed_ns")?),
        times,
        summaries,
        left_out: Vec::new(),
    })
}

fn parse_record(doc: &Json) -> Result<ShardRecord> {
    let shard = Shard::parse(text(doc, "shard")?)?;
    let range = match list(doc, "range")?.as_slice() {
        [a, b] => a.as_u64().zip(b.as_u64()).map(|(a, b)| a as usize..b as usize),
        _ => None,
    }
    .ok_or_else(|| anyhow!("`range` is not [first, end]"))?;
    let mut runs = Vec::new();
    let mut indices = Vec::new();
    for (n, r) in list(doc, "runs")?.iter().enumerate() {
        let at = |e: anyhow::Error| anyhow!("run {}: {e}", n + 1);
        let mut values = Vec::new();
        for v in list(r, "vars").map_err(at)? {
            match v.as_array().map(Vec::as_slice) {
                Some([Json::String(k), Json::String(t)]) => values.push((k.clone(), parse_cli_value(t))),
                _ => return Err(at(anyhow!("a variable is not [name, text]"))),
            }
        }
        indices.push(count(r, "index").map_err(at)? as usize);
        runs.push((Point { values }, parse_report(field(r, "report").map_err(at)?).map_err(at)?));
    }
    let failures = list(doc, "failures")?
        .iter()
        .map(|f| Ok((text(f, "run")?.to_string(), text(f, "reason")?.to_string())))
        .collect::<Result<Vec<_>>>()?;
    let flag = |key: &str| field(doc, key)?.as_bool().ok_or_else(|| anyhow!("`{key}` is not true or false"));
    Ok(ShardRecord {
        graph: text(doc, "graph")?.to_string(),
        shard,
        total: count(doc, "total")? as usize,
        range,
        indices,
        runs,
        failures,
        sweep: flag("sweep")?,
        timings: if flag("times")? { Timings::Show } else { Timings::Leave },
        csv: optional_text(doc, "csv")?,
        json: optional_text(doc, "json")?,
    })
}

/// The shards in K order, checked to be the N slices of one sweep.
fn in_order(mut shards: Vec<(PathBuf, ShardRecord)>) -> Result<Vec<(PathBuf, ShardRecord)>> {
    shards.sort_by_key(|(_, r)| r.shard.k);
    let (first_dir, first) = &shards[0];
    let n = first.shard.n;
    for (dir, r) in &shards {
        let differs = |what: &str| {
            anyhow!("{} and {}: not shards of one sweep ({what} differ)", first_dir.display(), dir.display())
        };
        if r.shard.n != n {
            return Err(differs("the shard counts N"));
        }
        if r.graph != first.graph {
            return Err(differs("the graphs"));
        }
        if r.total != first.total || r.sweep != first.sweep {
            return Err(differs("the numbers of runs"));
        }
        if r.timings != first.timings || r.csv != first.csv || r.json != first.json {
            return Err(differs("--no-times, --csv or --json"));
        }
        if r.range != r.shard.range(r.total) {
            bail!("{}: shard {} should hold runs {:?} of {}", dir.display(), r.shard, r.shard.range(r.total), r.total);
        }
    }
    let shards = k_order(shards.into_iter().map(|(d, r)| (d, r.shard, r)).collect())?;
    let shards: Vec<(PathBuf, ShardRecord)> = shards.into_iter().map(|(d, _, r)| (d, r)).collect();
    Ok(shards)
}

/// Every file under `dir`, as paths relative to it, sorted.
fn files_under(dir: &Path) -> Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    let mut stack = vec![PathBuf::new()];
    while let Some(rel) = stack.pop() {
        let here = dir.join(&rel);
        for e in std::fs::read_dir(&here).with_context(|| format!("{}: cannot list", here.display()))? {
            let e = e.with_context(|| format!("{}: cannot list", here.display()))?;
            let p = rel.join(e.file_name());
            if e.file_type()?.is_dir() {
                stack.push(p);
            } else {
                out.push(p);
            }
        }
    }
    out.sort();
    Ok(out)
}

/// Copies `from` to `to` through a temporary file beside `to`.
fn copy(from: &Path, to: &Path) -> Result<()> {
    if let Some(parent) = to.parent() {
        std::fs::create_dir_all(parent).with_context(|| format!("{}: cannot create", parent.display()))?;
    }
    let name = to.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let tmp = to.with_file_name(format!(".{name}.merge-tmp"));
    std::fs::copy(from, &tmp)
        .and_then(|_| std::fs::rename(&tmp, to))
        .with_context(|| format!("{} → {}: cannot copy", from.display(), to.display()))?;
    Ok(())
}

fn write(path: &Path, text: &str) -> Result<()> {
    if let Some(parent) = path.parent() {
        std::fs::create_dir_all(parent).with_context(|| format!("{}: cannot create", parent.display()))?;
    }
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let tmp = path.with_file_name(format!(".{name}.merge-tmp"));
    std::fs::write(&tmp, text)
        .and_then(|_| std::fs::rename(&tmp, path))
        .with_context(|| format!("{}: cannot write", path.display()))
}

/// Copies every file under the shard folders into `out` (as relative
/// paths), leaving out `skip` and temporary files; two shards writing one
/// name must have written the same bytes. Returns how many were copied.
fn copy_files(out: &Path, dirs: &[&Path], skip: &[PathBuf]) -> Result<usize> {
    let mut copied: Vec<(PathBuf, PathBuf)> = Vec::new();
    for dir in dirs {
        for rel in files_under(dir)? {
            if skip.contains(&rel) || rel.file_name().is_some_and(|n| n.to_string_lossy().ends_with(".tmp")) {
                continue;
            }
            let from = dir.join(&rel);
            if let Some((_, earlier)) = copied.iter().find(|(r, _)| *r == rel) {
                let same = std::fs::read(earlier).ok() == std::fs::read(&from).ok();
                if !same {
                    bail!("{} and {}: two shards wrote different files of one name", earlier.display(), from.display());
                }
                continue;
            }
            copy(&from, &out.join(&rel))?;
            copied.push((rel, from));
        }
    }
    Ok(copied.len())
}

/// Checks that the shards' K are 1..=N, each once, and puts them in K order.
fn k_order<T>(mut shards: Vec<(PathBuf, Shard, T)>) -> Result<Vec<(PathBuf, Shard, T)>> {
    shards.sort_by_key(|(_, s, _)| s.k);
    let n = shards[0].1.n;
    for w in shards.windows(2) {
        if w[0].1.k == w[1].1.k {
            bail!("{} and {}: both are shard {}", w[0].0.display(), w[1].0.display(), w[0].1);
        }
    }
    let have: Vec<usize> = shards.iter().map(|(_, s, _)| s.k).collect();
    let missing: Vec<String> = (1..=n).filter(|k| !have.contains(k)).map(|k| format!("{k}/{n}")).collect();
    if !missing.is_empty() {
        bail!("shards missing: {} (given {} of {n})", missing.join(", "), shards.len());
    }
    Ok(shards)
}

/// Joins the shards of a model library (`evflow library build --shard`).
#[cfg(feature = "synth")]
fn merge_library(a: &Args) -> Result<()> {
    use evflow_nodes::synth::study::library::{merge_index, read_shard};
    let shards = a
        .shards
        .iter()
        .map(|d| read_shard(d).map(|s| (d.clone(), s.shard, s)).map_err(anyhow::Error::from))
        .collect::<Result<Vec<_>>>()?;
    let shards = k_order(shards)?;
    let n = shards.len();
    let indexes: Vec<_> = shards.into_iter().map(|(_, _, s)| s).collect();
    let dirs: Vec<&Path> = indexes.iter().map(|s| s.dir.as_path()).collect();
    let files = copy_files(&a.out, &dirs, &[PathBuf::from("index.json")])?;
    let entries = merge_index(&a.out, &indexes)?;
    println!(
        "merged {n} library shards: {entries} entries, {files} files; index {}",
        a.out.join("index.json").display()
    );
    Ok(())
}

/// Runs `evflow merge`.
pub fn main(a: Args) -> Result<()> {
    #[cfg(feature = "synth")]
    if a.shards.iter().all(|d| !d.join(RECORD).exists() && evflow_nodes::synth::study::library::is_library(d)) {
        return merge_library(&a);
    }
    let shards = a.shards.iter().map(|d| Ok((d.clone(), ShardRecord::read(d)?))).collect::<Result<Vec<_>>>()?;
    let shards = in_order(shards)?;
    let first = shards[0].1.clone();
    // The files the graphs wrote: each once; two shards writing the same
    // name must have written the same bytes.
    let skip: Vec<PathBuf> = [Some(RECORD.to_string()), first.csv.clone(), first.json.clone()]
        .into_iter()
        .flatten()
        .map(PathBuf::from)
        .collect();
    let dirs: Vec<&Path> = shards.iter().map(|(d, _)| d.as_path()).collect();
    let copied = copy_files(&a.out, &dirs, &skip)?;
    let mut runs = Vec::new();
    let mut failures = Failures::new();
    for (_, r) in &shards {
        runs.extend(r.runs.iter().cloned());
        for (l, why) in &r.failures {
            failures.push(format!("{l} (shard {})", r.shard), why);
        }
    }
    // A table the shards wrote outside their --out goes into OUT by its file name.
    let inside = |p: &str| {
        let p = Path::new(p);
        if p.is_absolute() {
            a.out.join(p.file_name().unwrap_or_default())
        } else {
            a.out.join(p)
        }
    };
    if let Some(csv) = &first.csv {
        write(&inside(csv), &sweep_csv(&runs, first.timings))?;
        println!("wrote {}", inside(csv).display());
    }
    if let Some(json) = &first.json {
        write(&inside(json), &report_json(&runs, first.sweep, first.timings))?;
        println!("wrote {}", inside(json).display());
    }
    println!(
        "merged {} shards of {}: {} of {} runs, {} files the graphs wrote",
        shards.len(),
        first.graph,
        runs.len(),
        first.total,
        copied
    );
    if !failures.is_empty() {
        bail!("{}", failures.summary(first.total, "sweep runs").trim_end());
    }
    Ok(())
}
