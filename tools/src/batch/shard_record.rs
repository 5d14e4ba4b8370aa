//! A shard's record (`shard.json` in its output folder): which slice of a
//! sweep `evflow run --shard K/N` ran, of how many runs, and every run's
//! variables and report in full (floats as exact decimal text, times in
//! nanoseconds), so that `evflow merge` can rebuild the sweep's tables.
//! Written and read here, in one place.

pub use super::record_json::RecordError;
use super::record_json::{count, field, list, read_doc, text, write_doc, Fault};
use super::tables::Timings;
use evflow_engine::batch::Shard;
use evflow_engine::graph::parse_cli_value;
use evflow_engine::params::Value;
use evflow_engine::plan::NodeTime;
use evflow_engine::sweep::Point;
use evflow_engine::{Override, RunReport, Summary};
use serde_json::{json, Value as Json};
use std::ops::Range;
use std::path::Path;
use std::time::Duration;

/// The name of a shard's record in its output folder.
pub const RECORD: &str = "shard.json";

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
    /// The `--set` values the runs took (the plots read variables through them).
    pub sets: Vec<Override>,
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

/// A swept value as text that [`parse_cli_value`] reads back as the same
/// value: floats in Rust's shortest exact form with a decimal point or an
/// exponent (so `-0.0` stays a float and `60.0` stays `60.0`), lists of
/// floats as TOML arrays of them; other values as a graph's text shows them.
fn exact_text(v: &Value) -> String {
    fn float(x: f64) -> String {
        if x.is_nan() {
            "nan".into()
        } else {
            format!("{x:?}")
        }
    }
    match v {
        Value::Float(x) => float(*x),
        Value::FloatList(l) => format!("[{}]", l.iter().map(|x| float(*x)).collect::<Vec<_>>().join(", ")),
        other => evflow_engine::check::interpolate::text_of(other),
    }
}

impl ShardRecord {
    /// Writes the record into `dir` (through a temporary file).
    pub fn write(&self, dir: &Path) -> Result<(), RecordError> {
        let runs: Vec<Json> = self
            .runs
            .iter()
            .zip(&self.indices)
            .map(|((p, r), i)| {
                let vars: Vec<Json> = p.values.iter().map(|(k, v)| json!([k, exact_text(v)])).collect();
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
            "sets": self.sets.iter().map(|o| json!([o.key, exact_text(&o.value)])).collect::<Vec<_>>(),
            "runs": runs,
            "failures": failures,
        });
        write_doc(dir, RECORD, &doc)
    }

    /// Reads the record in `dir`; errors name the file and what is wrong.
    pub fn read(dir: &Path) -> Result<ShardRecord, RecordError> {
        read_doc(dir, RECORD, parse_record)
    }
}

fn float(v: &Json, what: &str) -> Fault<f64> {
    v.as_str().and_then(|s| s.parse().ok()).ok_or_else(|| format!("{what}: not a number written as text"))
}
fn optional_text(v: &Json, key: &str) -> Fault<Option<String>> {
    match field(v, key)? {
        Json::Null => Ok(None),
        Json::String(s) => Ok(Some(s.clone())),
        _ => Err(format!("`{key}` is not text")),
    }
}

fn parse_report(v: &Json) -> Fault<RunReport> {
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
                _ => return Err(format!("`{node}`: a value is not [name, \"number\", unit]")),
            }
        }
        let lines = list(s, "lines")?
            .iter()
            .map(|l| l.as_str().map(str::to_string).ok_or_else(|| format!("`{node}`: a line is not text")))
            .collect::<Fault<Vec<_>>>()?;
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

fn parse_record(doc: &Json) -> Fault<ShardRecord> {
    let shard = Shard::parse(text(doc, "shard")?).map_err(|e| e.to_string())?;
    let range = match list(doc, "range")?.as_slice() {
        [a, b] => a.as_u64().zip(b.as_u64()).map(|(a, b)| a as usize..b as usize),
        _ => None,
    }
    .ok_or_else(|| "`range` is not [first, end]".to_string())?;
    let mut runs = Vec::new();
    let mut indices = Vec::new();
    for (n, r) in list(doc, "runs")?.iter().enumerate() {
        let at = |e: String| format!("run {}: {e}", n + 1);
        let mut values = Vec::new();
        for v in list(r, "vars").map_err(at)? {
            match v.as_array().map(Vec::as_slice) {
                Some([Json::String(k), Json::String(t)]) => values.push((k.clone(), parse_cli_value(t))),
                _ => return Err(at("a variable is not [name, text]".to_string())),
            }
        }
        indices.push(count(r, "index").map_err(at)? as usize);
        runs.push((Point { values }, parse_report(field(r, "report").map_err(at)?).map_err(at)?));
    }
    let failures = list(doc, "failures")?
        .iter()
        .map(|f| Ok((text(f, "run")?.to_string(), text(f, "reason")?.to_string())))
        .collect::<Fault<Vec<_>>>()?;
    let flag = |key: &str| field(doc, key)?.as_bool().ok_or_else(|| format!("`{key}` is not true or false"));
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
        sets: match doc.get("sets") {
            // Records written before `sets` was: no --set to read.
            None => Vec::new(),
            Some(_) => list(doc, "sets")?
                .iter()
                .map(|v| match v.as_array().map(Vec::as_slice) {
                    Some([Json::String(k), Json::String(t)]) => {
                        Ok(Override { key: k.clone(), value: parse_cli_value(t) })
                    }
                    _ => Err("a `sets` entry is not [name, text]".to_string()),
                })
                .collect::<Fault<Vec<_>>>()?,
        },
    })
}

/// Records for tests here and in the merge's.
#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use evflow_engine::graph::parse_cli_value;

    /// A run with awkward floats and a node type no build knows.
    pub(crate) fn run(x: f64, elapsed_ns: u64) -> (Point, RunReport) {
        let point = Point { values: vec![("gain".into(), parse_cli_value(&format!("{x:?}")))] };
        let report = RunReport {
            ticks: 1000,
            base_rate: 1000.0 / 3.0,
            elapsed: Duration::from_nanos(elapsed_ns),
            times: vec![NodeTime {
                node: "src".into(),
                kind: "no.such.type",
                setup: Duration::from_nanos(1),
                process: Duration::from_nanos(u64::MAX),
                finish: Duration::ZERO,
                elapsed: Duration::from_nanos(elapsed_ns),
            }],
            summaries: vec![(
                "probe".into(),
                Summary {
                    values: vec![("rms".into(), x * (0.1 + 0.2), "V".into()), ("tiny".into(), 5e-324, "".into())],
                    lines: vec!["a line, with \"quotes\"".into()],
                },
            )],
            left_out: Vec::new(),
        };
        (point, report)
    }

    /// A record of shard `shard` of `total` runs holding `runs`.
    pub(crate) fn record(shard: Shard, total: usize, runs: Vec<(Point, RunReport)>) -> ShardRecord {
        let range = shard.range(total);
        ShardRecord {
            graph: "graphs/g.toml".into(),
            shard,
            total,
            indices: range.clone().take(runs.len()).collect(),
            range,
            runs,
            failures: vec![("gain=9".into(), "it broke".into())],
            sweep: true,
            timings: Timings::Show,
            csv: Some("t.csv".into()),
            json: None,
            sets: vec![Override::parse("mass=85.5").unwrap(), Override::parse("sample=\"felt\"").unwrap()],
        }
    }

    #[test]
    fn a_record_reads_back_bit_for_bit() {
        let dir = tempfile::tempdir().unwrap();
        let rec = record(Shard { k: 2, n: 3 }, 7, vec![run(1.0 / 7.0, 123_456_789), run(1e300, 0)]);
        rec.write(dir.path()).unwrap();
        assert!(!dir.path().join(format!(".{RECORD}.tmp")).exists());
        let back = ShardRecord::read(dir.path()).unwrap();
        assert_eq!(
            (back.graph.as_str(), back.shard, back.total, back.range.clone()),
            ("graphs/g.toml", rec.shard, 7, 3..5)
        );
        assert_eq!(back.indices, rec.indices);
        assert_eq!(back.failures, rec.failures);
        assert_eq!(
            (back.sweep, back.timings, back.csv.clone(), back.json.clone()),
            (true, Timings::Show, rec.csv, None)
        );
        assert_eq!(back.sets, rec.sets);
        for ((p, r), (q, s)) in rec.runs.iter().zip(&back.runs) {
            assert_eq!(p.label(), q.label());
            assert_eq!(r.base_rate.to_bits(), s.base_rate.to_bits());
            assert_eq!((r.ticks, r.elapsed), (s.ticks, s.elapsed));
            assert_eq!(s.times[0].kind, "no.such.type");
            assert_eq!((s.times[0].process, s.times[0].setup), (r.times[0].process, r.times[0].setup));
            let bits = |x: &RunReport| -> Vec<u64> { x.summaries[0].1.values.iter().map(|v| v.1.to_bits()).collect() };
            assert_eq!(bits(r), bits(s));
            assert_eq!(r.summaries[0].1.lines, s.summaries[0].1.lines);
        }
    }

    #[test]
    fn swept_values_read_back_as_the_same_values() {
        let values = [
            Value::Float(-0.0),
            Value::Float(60.0),
            Value::Float(0.1),
            Value::Float(1e300),
            Value::Float(5e-324),
            Value::Float(f64::INFINITY),
            Value::Float(f64::NEG_INFINITY),
            Value::Int(-3),
            Value::Bool(true),
            Value::Text("felt-fabric".into()),
            Value::FloatList(vec![-0.0, 2.0, 0.3]),
        ];
        let dir = tempfile::tempdir().unwrap();
        let mut rec = record(Shard { k: 1, n: 1 }, 1, vec![run(1.0, 1)]);
        rec.runs[0].0.values = values.iter().enumerate().map(|(i, v)| (format!("v{i}"), v.clone())).collect();
        rec.write(dir.path()).unwrap();
        let back = ShardRecord::read(dir.path()).unwrap();
        assert_eq!(back.runs[0].0.label(), rec.runs[0].0.label());
        for ((_, v), (_, w)) in rec.runs[0].0.values.iter().zip(&back.runs[0].0.values) {
            match (v, w) {
                (Value::Float(a), Value::Float(b)) => assert_eq!(a.to_bits(), b.to_bits(), "{a:?} read back as {b:?}"),
                (Value::FloatList(a), Value::FloatList(b)) => {
                    assert_eq!(
                        a.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
                        b.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
                    )
                }
                _ => assert_eq!(v, w),
            }
        }
        // NaN reads back as NaN.
        rec.runs[0].0.values = vec![("x".into(), Value::Float(f64::NAN))];
        rec.write(dir.path()).unwrap();
        let back = ShardRecord::read(dir.path()).unwrap();
        assert!(matches!(back.runs[0].0.values[0].1, Value::Float(x) if x.is_nan()));
    }

    #[test]
    fn bad_records_name_the_file_and_the_fault() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(RECORD);
        let e = ShardRecord::read(dir.path()).unwrap_err();
        assert!(matches!(e, RecordError::Read { .. }));
        assert_eq!(
            e.to_string(),
            format!("{}: cannot read (is it the --out of a run with `--shard`?)", path.display())
        );

        std::fs::write(&path, "{ not json").unwrap();
        let e = ShardRecord::read(dir.path()).unwrap_err();
        assert!(matches!(e, RecordError::Json { .. }), "{e}");
        assert!(e.to_string().starts_with(&format!("{}: ", path.display())), "{e}");

        record(Shard { k: 1, n: 1 }, 1, vec![run(2.0, 5)]).write(dir.path()).unwrap();
        let good: Json = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        /// Spoils one field of a good record.
        type Spoil = fn(&mut Json);
        let cases: [(Spoil, &str); 6] = [
            (|d| d["shard"] = json!("4/3"), "shard `4/3`: expected K/N with 1 ≤ K ≤ N (e.g. 3/8)"),
            (|d| _ = d.as_object_mut().unwrap().remove("graph"), "missing `graph`"),
            (|d| d["range"] = json!([0]), "`range` is not [first, end]"),
            (|d| d["runs"][0]["vars"][0] = json!([1, 2]), "run 1: a variable is not [name, text]"),
            (
                |d| d["runs"][0]["report"]["summaries"][0]["values"][0][1] = json!(0.5),
                "run 1: `probe.rms`: not a number written as text",
            ),
            (|d| d["times"] = json!("yes"), "`times` is not true or false"),
        ];
        for (spoil, what) in cases {
            let mut doc = good.clone();
            spoil(&mut doc);
            std::fs::write(&path, doc.to_string()).unwrap();
            let e = ShardRecord::read(dir.path()).unwrap_err();
            assert!(matches!(e, RecordError::Invalid { .. }), "{e}");
            assert_eq!(e.to_string(), format!("{}: {what}", path.display()));
        }
    }

    #[test]
    fn paths_inside_the_folder_are_relative() {
        assert_eq!(relative_to(Path::new("out/sub/t.csv"), Path::new("out")), "sub/t.csv");
        let outside = relative_to(Path::new("elsewhere/t.csv"), Path::new("out"));
        assert!(outside.ends_with("elsewhere/t.csv") && Path::new(&outside).is_absolute(), "{outside}");
    }
}
