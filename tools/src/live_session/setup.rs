//! The session's set-up before the real-time thread starts: the live plan
//! and its taps, the session folder with its manifest, the pacing and the
//! scripted changes.

use super::config::{SessionConfig, DEFAULT_MISS_STREAK};
use super::error::SessionError;
use super::integrity;
use super::session::{FileSpec, Manifest};

type Result<T> = std::result::Result<T, SessionError>;
use evflow_engine::live::{Control, LiveConfig, LivePlan, LiveVar, RealtimeRequest, Tap};
use evflow_engine::{Checked, Plan, PlanOptions};
use std::path::{Path, PathBuf};
use std::time::Duration;

/// Builds the graph's plan for one-sample ticks and the live plan that
/// records its sources, guards, `--tap`s (and, with the studio, what its
/// page shows by default); also returns how many of the taps are inputs.
pub(super) fn live_plan(c: &SessionConfig, checked: &Checked, seed: u64) -> Result<(LivePlan, usize)> {
    let opts = PlanOptions {
        max_block: 1,
        seed: Some(seed),
        base_dir: None,
        out_dir: Some(c.out.clone()),
        timing: false,
        mode: evflow_engine::RunMode::Live,
        check_only: false,
    };
    let plan = Plan::build(checked, &opts).map_err(|e| SessionError::Setup(format!("{e}")))?;
    #[allow(unused_mut)]
    let mut extra = c.taps.clone();
    #[cfg(feature = "studio")]
    if c.studio.is_some() {
        // What the page shows by default is recorded too.
        extra.extend(crate::studio::default_taps(checked, &plan).into_iter().map(|t| format!("{}.{}", t.node, t.port)));
    }
    let (taps, n_inputs) = taps_of(&plan, &extra)?;
    let lp = LivePlan::new(plan, &taps).map_err(|e| SessionError::Setup(format!("{}: {e}", c.graph_file.display())))?;
    Ok((lp, n_inputs))
}

/// What the session folder is opened with.
pub(super) struct Folder<'a> {
    /// The graph file's text, copied into the folder.
    pub graph_text: &'a str,
    /// The seed of every random stream.
    pub seed: u64,
    /// The recorded inputs.
    pub inputs: &'a [FileSpec],
    /// The recorded outputs.
    pub outputs: &'a [FileSpec],
}

impl Folder<'_> {
    /// Creates the session folder (refusing one that holds a session), copies
    /// the graph into it and writes the manifest as `running`, before
    /// anything runs. Returns the folder and its manifest.
    pub(super) fn open(&self, c: &SessionConfig, checked: &Checked, lp: &LivePlan) -> Result<(PathBuf, Manifest)> {
        let dir = c.session.clone().unwrap_or_else(|| c.out.join("sessions").join(session_name(&checked.graph.name)));
        if dir.join("session.json").exists() {
            return Err(SessionError::Setup(format!(
                "{}: a session is already recorded there; choose another --session",
                dir.display()
            )));
        }
        std::fs::create_dir_all(&dir).map_err(SessionError::file(&dir, "cannot create the session folder"))?;
        std::fs::write(dir.join("graph.toml"), self.graph_text)
            .map_err(SessionError::file(dir.join("graph.toml"), "cannot write"))?;
        let graph_hash = integrity::file_hash(&dir.join("graph.toml"))
            .map_err(SessionError::file(dir.join("graph.toml"), "cannot read back"))?;
        let graph_path = std::fs::canonicalize(&c.graph_file).unwrap_or_else(|_| c.graph_file.clone());
        let base_rate = lp.plan().base_rate();
        let manifest = Manifest {
            identity: Some(integrity::identity(
                &graph_hash,
                self.seed,
                &c.overrides,
                base_rate,
                self.inputs,
                self.outputs,
            )),
            graph_hash: Some(graph_hash),
            name: checked.graph.name.clone(),
            base_dir: graph_path.parent().map(Path::to_path_buf).unwrap_or_default(),
            graph_source: graph_path,
            overrides: c.overrides.clone(),
            seed: self.seed,
            base_rate,
            inputs: self.inputs.to_vec(),
            outputs: self.outputs.to_vec(),
            started: std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map(|d| d.as_secs())
                .unwrap_or(0),
        };
        manifest.write(&dir, "running", None)?;
        Ok((dir, manifest))
    }
}

/// How the real-time thread is paced and when it stops.
pub(super) struct Pacing {
    /// The session length (`None`: until stopped).
    pub duration: Option<f64>,
    /// Deadline misses in a row that stop the session (0: never).
    pub miss_streak: u64,
    /// Whether the graph drives hardware.
    pub hardware: bool,
    /// The configuration the session starts with.
    pub config: LiveConfig,
}

impl Pacing {
    /// The session length, real-time request and miss streak from the
    /// arguments and the graph.
    pub(super) fn of(c: &SessionConfig, checked: &Checked) -> Self {
        let duration = if c.endless { None } else { c.duration.or(checked.graph.duration) };
        let last_cpu = std::thread::available_parallelism().map(|n| n.get() - 1).unwrap_or(0);
        let realtime = if !c.realtime {
            RealtimeRequest::default()
        } else {
            RealtimeRequest { priority: Some(c.priority), lock_memory: true, cpu: Some(c.cpu.unwrap_or(last_cpu)) }
        };
        let hardware = checked.nodes.iter().any(|n| n.spec.hardware);
        let miss_streak = c.miss_streak.unwrap_or(if hardware { DEFAULT_MISS_STREAK } else { 0 });
        let config = LiveConfig {
            duration,
            realtime,
            spin: Duration::from_micros(c.spin_us),
            miss_streak,
            ..LiveConfig::default()
        };
        Pacing { duration, miss_streak, hardware, config }
    }

    /// Prints what runs, where it records, what stops it and how to steer it.
    pub(super) fn print_intro(&self, name: &str, base_rate: f64, dir: &Path, vars_line: &str) {
        eprintln!(
            "live: `{}` at {base_rate} Hz{}; recording to {}",
            name,
            self.duration.map(|d| format!(" for {d} s")).unwrap_or_default(),
            dir.display()
        );
        eprintln!(
            "{}",
            match (self.miss_streak, self.hardware) {
                (0, false) => "deadline misses are counted; without hardware they never stop the session \
                               (--miss-streak N stops it after N in a row)"
                    .to_string(),
                (0, true) => "deadline misses are counted and never stop the session (--miss-streak 0)".to_string(),
                (n, _) => format!("{n} deadline misses in a row stop the session (--miss-streak)"),
            }
        );
        eprintln!("type node.param=value and Enter to change a live parameter, `stop` or Ctrl-C to stop");
        if !vars_line.is_empty() {
            eprintln!("or variable=value for a graph variable, which changes its parameters at one tick: {vars_line}");
        }
    }
}

/// The graph variables and the parameters each sets, for the console's
/// help: `name (node.param, …); …`.
pub(super) fn vars_line(vars: &[LiveVar]) -> String {
    vars.iter()
        .map(|v| {
            let uses: Vec<String> = v.uses.iter().map(|(n, p)| format!("{n}.{p}")).collect();
            format!("{} ({})", v.name, uses.join(", "))
        })
        .collect::<Vec<_>>()
        .join("; ")
}

/// Queues the `--change SECONDS:…` changes at their ticks.
pub(super) fn schedule_changes(control: &mut Control, changes: &[String]) -> Result<()> {
    for c in changes {
        let (t, change) = c.split_once(':').ok_or_else(|| {
            SessionError::Setup(format!("--change {c}: expected SECONDS:node.param=value or SECONDS:variable=value"))
        })?;
        let t: f64 = t
            .trim()
            .parse()
            .map_err(|_| SessionError::Setup(format!("--change {c}: `{t}` is not a number of seconds")))?;
        let at = control.tick_at(t);
        control.set_text(change, Some(at)).map_err(|e| SessionError::Setup(format!("--change {c}: {e}")))?;
    }
    Ok(())
}

/// Sources first (the session's inputs), then guards and `--tap`s.
fn taps_of(plan: &Plan, extra: &[String]) -> Result<(Vec<Tap>, usize)> {
    let mut taps = LivePlan::source_taps(plan);
    let n_inputs = taps.len();
    for t in LivePlan::guard_taps(plan) {
        if !taps.contains(&t) {
            taps.push(t);
        }
    }
    for e in extra {
        let (node, port) =
            e.split_once('.').ok_or_else(|| SessionError::Setup(format!("--tap {e}: expected node.port")))?;
        let t = Tap::new(node, port);
        if !taps[n_inputs..].contains(&t) {
            taps.push(t);
        }
    }
    Ok((taps, n_inputs))
}

/// `NAME-YYYYMMDD-HHMMSS` in UTC.
fn session_name(graph: &str) -> String {
    let secs = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map(|d| d.as_secs()).unwrap_or(0);
    let days = (secs / 86_400) as i64;
    let rem = secs % 86_400;
    // Civil date from days since 1970-01-01 (H. Hinnant's algorithm).
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!("{graph}-{y:04}{m:02}{d:02}-{:02}{:02}{:02}", rem / 3600, rem % 3600 / 60, rem % 60)
}

#[cfg(test)]
mod tests {
    #[test]
    fn session_names_sort_by_time() {
        let n = super::session_name("g");
        assert!(n.starts_with("g-20"), "{n}");
        assert_eq!(n.len(), "g-20250101-120000".len());
    }
}
