//! A shard's record (`shard.json` in its output folder): which slice of a
//! sweep `evflow run --shard K/N` ran, of how many runs, and every run's
//! variables and report in full (floats as exact decimal text, times in
//! nanoseconds), so that `evflow merge` can rebuild the sweep's tables.
//! Written and read here, in one place.

pub use super::record_json::RecordError;
use super::record_json::{read_doc, write_doc};
use super::tables::Timings;
use evflow_engine::batch::Shard;
use evflow_engine::graph::parse_cli_value;
use evflow_engine::params::Value;
use evflow_engine::plan::NodeTime;
use evflow_engine::sweep::Point;
use evflow_engine::{Override, RunReport, Summary};
use serde::{Deserialize, Serialize};
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
    /// The shard's command line after `evflow` (`run GRAPH … --shard K/N
    /// --out DIR …`), so that a merge missing another shard can print the
    /// command that reruns it ([`super::merge::rerun`]); empty in records
    /// written before it was kept.
    pub command: Vec<String>,
}

/// `path` relative to `dir` when it lies inside it, else as given.
pub fn relative_to(path: &Path, dir: &Path) -> String {
    let abs = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
    let (p, d) = (abs(path), abs(dir));
    p.strip_prefix(&d).map(Path::to_path_buf).unwrap_or(p).to_string_lossy().replace('\\', "/")
}

// The file's shape. Fields are declared in the order of their names, which
// is the order they are written in (as the record was before it had types).

/// `shard.json`.
#[derive(Serialize, Deserialize)]
struct RecordFile {
    /// Absent in records written before `command` was: no command to show.
    #[serde(default)]
    command: Vec<String>,
    csv: Option<String>,
    failures: Vec<FailureFile>,
    graph: String,
    json: Option<String>,
    range: [usize; 2],
    runs: Vec<RunFile>,
    /// Absent in records written before `sets` was: no --set to read.
    #[serde(default)]
    sets: Vec<(String, String)>,
    shard: String,
    sweep: bool,
    times: bool,
    total: usize,
}

/// A run that failed.
#[derive(Serialize, Deserialize)]
struct FailureFile {
    reason: String,
    run: String,
}

/// A run that succeeded: its sweep index, report and variables
/// (`[name, exact text]`).
#[derive(Serialize, Deserialize)]
struct RunFile {
    index: usize,
    report: ReportFile,
    vars: Vec<(String, String)>,
}

/// A float as Rust's shortest exact text: it reads back bit for bit.
#[derive(Serialize, Deserialize)]
struct Exact(#[serde(with = "evflow_study::exact")] f64);

/// A run's report; times in nanoseconds.
#[derive(Serialize, Deserialize)]
struct ReportFile {
    base_rate: Exact,
    elapsed_ns: u64,
    summaries: Vec<SummaryFile>,
    ticks: u64,
    times: Vec<TimeFile>,
}

/// A node's summary: its values as `[name, exact text, unit]` and its lines.
#[derive(Serialize, Deserialize)]
struct SummaryFile {
    lines: Vec<String>,
    node: String,
    values: Vec<(String, Exact, String)>,
}

/// A node's times.
#[derive(Serialize, Deserialize)]
struct TimeFile {
    elapsed_ns: u64,
    finish_ns: u64,
    node: String,
    process_ns: u64,
    setup_ns: u64,
    #[serde(rename = "type")]
    kind: String,
}

fn nanos(d: Duration) -> u64 {
    d.as_nanos().min(u64::MAX as u128) as u64
}

impl ReportFile {
    fn of(r: &RunReport) -> Self {
        ReportFile {
            base_rate: Exact(r.base_rate),
            elapsed_ns: nanos(r.elapsed),
            summaries: r
                .summaries
                .iter()
                .map(|(node, s)| SummaryFile {
                    lines: s.lines.clone(),
                    node: node.clone(),
                    values: s.values.iter().map(|(k, v, u)| (k.clone(), Exact(*v), u.clone())).collect(),
                })
                .collect(),
            ticks: r.ticks,
            times: r
                .times
                .iter()
                .map(|t| TimeFile {
                    elapsed_ns: nanos(t.elapsed),
                    finish_ns: nanos(t.finish),
                    node: t.node.clone(),
                    process_ns: nanos(t.process),
                    setup_ns: nanos(t.setup),
                    kind: t.kind.to_string(),
                })
                .collect(),
        }
    }

    fn report(self) -> RunReport {
        let registry = evflow_nodes::registry();
        let times = self
            .times
            .into_iter()
            .map(|t| {
                // Node types are the registry's static names; one this build
                // does not know keeps its name for the life of the program.
                let kind: &'static str =
                    registry.get(&t.kind).map(|s| s.name).unwrap_or_else(|| Box::leak(t.kind.into_boxed_str()));
                NodeTime {
                    node: t.node,
                    kind,
                    setup: Duration::from_nanos(t.setup_ns),
                    process: Duration::from_nanos(t.process_ns),
                    finish: Duration::from_nanos(t.finish_ns),
                    elapsed: Duration::from_nanos(t.elapsed_ns),
                }
            })
            .collect();
        let summaries = self
            .summaries
            .into_iter()
            .map(|s| {
                (
                    s.node,
                    Summary { values: s.values.into_iter().map(|(k, v, u)| (k, v.0, u)).collect(), lines: s.lines },
                )
            })
            .collect();
        RunReport {
            ticks: self.ticks,
            base_rate: self.base_rate.0,
            elapsed: Duration::from_nanos(self.elapsed_ns),
            times,
            summaries,
            left_out: Vec::new(),
        }
    }
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
        let file = RecordFile {
            command: self.command.clone(),
            csv: self.csv.clone(),
            failures: self.failures.iter().map(|(l, r)| FailureFile { reason: r.clone(), run: l.clone() }).collect(),
            graph: self.graph.clone(),
            json: self.json.clone(),
            range: [self.range.start, self.range.end],
            runs: self
                .runs
                .iter()
                .zip(&self.indices)
                .map(|((p, r), i)| RunFile {
                    index: *i,
                    report: ReportFile::of(r),
                    vars: p.values.iter().map(|(k, v)| (k.clone(), exact_text(v))).collect(),
                })
                .collect(),
            sets: self.sets.iter().map(|o| (o.key.clone(), exact_text(&o.value))).collect(),
            shard: self.shard.to_string(),
            sweep: self.sweep,
            times: self.timings == Timings::Show,
            total: self.total,
        };
        write_doc(dir, RECORD, &file)
    }

    /// Reads the record in `dir`; errors name the file and what is wrong.
    pub fn read(dir: &Path) -> Result<ShardRecord, RecordError> {
        read_doc(dir, RECORD, |f: RecordFile| f.record())
    }
}

impl RecordFile {
    /// The record it holds, its shard and range checked.
    fn record(self) -> Result<ShardRecord, String> {
        let shard = Shard::parse(&self.shard).map_err(|e| e.to_string())?;
        let [start, end] = self.range;
        if start > end {
            return Err(format!("`range` [{start}, {end}] is not [first, end]"));
        }
        let (indices, runs) = self
            .runs
            .into_iter()
            .map(|r| {
                let values = r.vars.iter().map(|(k, t)| (k.clone(), parse_cli_value(t))).collect();
                (r.index, (Point { values }, r.report.report()))
            })
            .unzip();
        Ok(ShardRecord {
            graph: self.graph,
            shard,
            total: self.total,
            range: start..end,
            indices,
            runs,
            failures: self.failures.into_iter().map(|f| (f.run, f.reason)).collect(),
            sweep: self.sweep,
            timings: if self.times { Timings::Show } else { Timings::Leave },
            csv: self.csv,
            json: self.json,
            sets: self.sets.into_iter().map(|(k, t)| Override { key: k, value: parse_cli_value(&t) }).collect(),
            command: self.command,
        })
    }
}

/// Records for tests here and in the merge's.
#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use evflow_engine::graph::parse_cli_value;
    use serde_json::{json, Value as Json};

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
            command: ["run", "graphs/g.toml", "--shard", &shard.to_string(), "--out", "parts/a b"]
                .map(String::from)
                .to_vec(),
        }
    }

    #[test]
    fn a_record_reads_back_bit_for_bit() {
        let dir = tempfile::tempdir().unwrap();
        let rec = record(Shard { k: 2, n: 3 }, 7, vec![run(1.0 / 7.0, 123_456_789), run(1e300, 0)]);
        rec.write(dir.path()).unwrap();
        assert!(!dir.path().join(format!("{RECORD}.tmp")).exists());
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
        assert_eq!(back.command, rec.command);
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
        let cases: [(Spoil, &str); 7] = [
            (|d| d["shard"] = json!("4/3"), "shard `4/3`: expected K/N with 1 ≤ K ≤ N (e.g. 3/8)"),
            (|d| _ = d.as_object_mut().unwrap().remove("graph"), "missing field `graph`"),
            (|d| d["range"] = json!([0]), "invalid length 1, expected an array of length 2"),
            (|d| d["range"] = json!([3, 1]), "`range` [3, 1] is not [first, end]"),
            (|d| d["runs"][0]["vars"][0] = json!([1, 2]), "invalid type: integer `1`, expected a string"),
            (|d| d["runs"][0]["report"]["summaries"][0]["values"][0][1] = json!("half"), "`half` is not a number"),
            (|d| d["times"] = json!("yes"), "invalid type: string \"yes\", expected a boolean"),
        ];
        for (spoil, what) in cases {
            let mut doc = good.clone();
            spoil(&mut doc);
            std::fs::write(&path, doc.to_string()).unwrap();
            let e = ShardRecord::read(dir.path()).unwrap_err();
            assert!(matches!(e, RecordError::Invalid { .. }), "{e}");
            let prefix = format!("{}: {what}", path.display());
            assert!(e.to_string().starts_with(&prefix), "{e}\nshould start with\n{prefix}");
        }
    }

    #[test]
    fn the_record_is_written_with_its_keys_in_name_order_and_old_records_read() {
        let dir = tempfile::tempdir().unwrap();
        record(Shard { k: 1, n: 1 }, 1, vec![run(2.0, 5)]).write(dir.path()).unwrap();
        let text = std::fs::read_to_string(dir.path().join(RECORD)).unwrap();
        // The layout the hand-built document had: serde_json's map sorts keys.
        let as_map: Json = serde_json::from_str(&text).unwrap();
        assert_eq!(text, serde_json::to_string_pretty(&as_map).unwrap());
        // A record written before `sets` or `command` existed reads, with none.
        let mut old = as_map.clone();
        old.as_object_mut().unwrap().remove("sets");
        old.as_object_mut().unwrap().remove("command");
        std::fs::write(dir.path().join(RECORD), old.to_string()).unwrap();
        let back = ShardRecord::read(dir.path()).unwrap();
        assert!(back.sets.is_empty() && back.command.is_empty());
    }

    #[test]
    fn paths_inside_the_folder_are_relative() {
        assert_eq!(relative_to(Path::new("out/sub/t.csv"), Path::new("out")), "sub/t.csv");
        let outside = relative_to(Path::new("elsewhere/t.csv"), Path::new("out"));
        assert!(outside.ends_with("elsewhere/t.csv") && Path::new(&outside).is_absolute(), "{outside}");
    }
}
