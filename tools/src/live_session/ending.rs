//! The session's end: waiting for its threads, the record of how it ended
//! (in the manifest and `--json`) and the report to print.

use super::config::SessionConfig;
use super::error::SessionError;
use super::integrity;
use super::recorder::RecorderReport;
use super::session::Manifest;
use evflow_engine::live::{Metrics, MetricsSummary, Percentiles, RtExit, RtThread, Shared};
use evflow_engine::Summary;
use serde_json::json;
use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// A session that has run: what its threads returned.
pub(super) struct Ran {
    /// The real-time thread's exit.
    exit: RtExit,
    /// Wall-clock time from the wait's start to the real-time thread's end.
    wall: Duration,
    /// Host steal during the session (seconds), where the system tells it.
    stolen: Option<f64>,
    /// What the recorder wrote.
    rec: RecorderReport,
    /// The tick timings of the whole session.
    metrics: Metrics,
}

impl Ran {
    /// Waits for the real-time thread to end, then tells the recorder and
    /// the metrics display (`done`) and waits for them.
    pub(super) fn wait(
        thread: RtThread,
        done: &AtomicBool,
        rec_thread: JoinHandle<RecorderReport>,
        metrics_thread: JoinHandle<Metrics>,
    ) -> Result<Self, SessionError> {
        let started = Instant::now();
        let steal_before = super::steal::steal_seconds();
        let exit = thread.join();
        let wall = started.elapsed();
        let stolen = super::steal::steal_seconds().zip(steal_before).map(|(b, a)| (b - a).max(0.0));
        done.store(true, Ordering::Release);
        let rec = rec_thread.join().map_err(|_| SessionError::Thread("the recorder thread panicked".into()))?;
        let metrics = metrics_thread.join().map_err(|_| SessionError::Thread("the metrics thread panicked".into()))?;
        Ok(Ran { exit, wall, stolen, rec, metrics })
    }

    /// Finishes the plan's nodes and writes how the session ended to the
    /// manifest (and `--json`); the session's report and outcome.
    pub(super) fn finish(
        self,
        c: &SessionConfig,
        dir: &Path,
        manifest: &Manifest,
        shared: &Arc<Shared>,
        base_rate: f64,
    ) -> Result<Ended, SessionError> {
        let summary = self.metrics.summary(shared, base_rate);
        let mut exit = self.exit;
        let sums = exit.plan.plan_mut().finish().map_err(|e| SessionError::Run(e.to_string()))?;

        let reason = match (&exit.failure, exit.reason) {
            (Some(f), _) => format!("node failure: {f}"),
            (None, Some(r)) => r.as_str().to_string(),
            (None, None) => "unknown".into(),
        };
        let (wall, stolen, rec) = (self.wall, self.stolen, self.rec);
        let ended = Ended { dir: dir.to_path_buf(), base_rate, reason, exit, wall, stolen, rec, summary, sums };
        let record = ended.record();
        manifest.write(dir, if ended.exit.failure.is_some() { "failed" } else { "ended" }, Some(record.clone()))?;
        if let Some(path) = &c.json {
            let text =
                serde_json::to_string_pretty(&record).map_err(SessionError::json(path, "cannot write results"))?;
            std::fs::write(path, text).map_err(SessionError::file(path, "cannot write results"))?;
        }
        Ok(ended)
    }
}

/// A session that has ended, its end recorded in its folder: the report
/// to print (its `Display`) and its outcome.
pub struct Ended {
    dir: PathBuf,
    base_rate: f64,
    /// Why it stopped, for people.
    reason: String,
    exit: RtExit,
    /// Wall-clock time of the real-time thread.
    wall: Duration,
    /// Host steal during the session (seconds), where the system tells it.
    stolen: Option<f64>,
    rec: RecorderReport,
    summary: MetricsSummary,
    /// The nodes' summaries.
    sums: Vec<(String, Summary)>,
}

impl Ended {
    /// Fails when a node or a fault stopped the session.
    pub fn outcome(self) -> Result<(), SessionError> {
        match self.exit.failure {
            Some(f) => Err(SessionError::Run(f.to_string())),
            None if self.exit.reason.is_some_and(|r| r.is_fault()) => {
                Err(SessionError::Run(format!("session stopped by a fault: {}", self.reason)))
            }
            None => Ok(()),
        }
    }

    /// The record of the session's end: ticks, times, why it stopped, the
    /// metrics and each recorded file with its fingerprint.
    fn record(&self) -> serde_json::Value {
        let files: Vec<_> = self
            .rec
            .files
            .iter()
            .map(|(f, n, gap, err)| {
                // The fingerprint of the samples as written: `evflow replay --check` holds the file to it.
                let hash = integrity::file_hash(&self.dir.join(format!("{f}.wav"))).ok();
                json!({ "file": f, "frames": n, "gap_frames": gap, "error": err, "hash": hash })
            })
            .collect();
        json!({
            "ticks": self.exit.ticks,
            "seconds": self.exit.ticks as f64 / self.base_rate,
            "wall_seconds": self.wall.as_secs_f64(),
            "stopped": self.reason,
            "realtime": self.exit.realtime.to_string(),
            "metrics": metrics_json(&self.summary),
            "host_steal_seconds": self.stolen,
            "files": files,
            "events": self.rec.events,
        })
    }
}

/// The report: ticks and why it stopped, the real-time grant, host steal,
/// the metrics, the recorded files and the nodes' summaries.
impl fmt::Display for Ended {
    fn fmt(&self, out: &mut fmt::Formatter<'_>) -> fmt::Result {
        let exit = &self.exit;
        writeln!(
            out,
            "session {}: {} ticks ({:.3} s), stopped: {}",
            self.dir.display(),
            exit.ticks,
            exit.ticks as f64 / self.base_rate,
            self.reason
        )?;
        writeln!(out, "real-time thread: {}", exit.realtime)?;
        if let Some(st) = self.stolen.filter(|&st| st > 0.0) {
            writeln!(
                out,
                "host steal: {:.0} ms of CPU time taken from this virtual machine by its host during the session \
                 (stalls no setting inside the machine prevents; see docs/live.md)",
                st * 1e3
            )?;
        }
        writeln!(out, "{}", self.summary)?;
        for (f, n, gap, err) in &self.rec.files {
            let gap = if *gap > 0 {
                format!(", {gap} lost to a full tap ring: the recorder fell behind (zero-filled, see events.jsonl)")
            } else {
                String::new()
            };
            match err {
                None => writeln!(out, "recorded {f} ({n} frames{gap})")?,
                Some(e) => writeln!(out, "recorded {f}: FAILED: {e}")?,
            }
        }
        if let Some(e) = &self.rec.event_error {
            writeln!(out, "event log: FAILED: {e}")?;
        }
        writeln!(out, "{RECORDED}")?;
        for (node, s) in &self.sums {
            for l in &s.lines {
                writeln!(out, "{node}: {l}")?;
            }
            for (k, v, unit) in &s.values {
                writeln!(
                    out,
                    "{node}: {k} = {}{}",
                    crate::batch::tables::number(*v),
                    crate::batch::tables::unit_suffix(unit)
                )?;
            }
        }
        Ok(())
    }
}

/// What a session records, said after the list of its files.
const RECORDED: &str = "(a session records what its replay needs: every source's outputs and every safety \
     guard's; `--tap NODE.PORT` records another output too, to see it in `evflow studio` or read it later — \
     `evflow check FILE` lists the outputs there are)";

/// The session's metrics as JSON (microseconds).
fn metrics_json(s: &MetricsSummary) -> serde_json::Value {
    let p = |p: &Percentiles| json!({ "p50": p.p50, "p99": p.p99, "p99_9": p.p999, "max": p.max, "mean": p.mean });
    json!({
        "jitter_us": p(&s.jitter),
        "compute_us": p(&s.compute),
        "deadline_misses": s.misses,
        "longest_miss_streak": s.longest_streak,
        "tap_overruns": s.tap_overruns,
        "event_overruns": s.event_overruns,
        "stat_overruns": s.stat_overruns,
        "command_overruns": s.command_overruns,
    })
}
