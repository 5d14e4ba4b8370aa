//! A session from start to end: the set-up, the real-time thread and the
//! ordinary threads around it, the studio when asked for, and the wait
//! for the end.

use super::config::SessionConfig;
use super::ending::{Ended, Ran};
use super::error::SessionError;
use super::recorder::Recorder;
use super::{disk, session, setup, threads};
use evflow_engine::live;
use evflow_engine::Checked;
#[cfg(feature = "studio")]
use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
#[cfg(feature = "studio")]
use std::time::Duration;

/// Runs the graph `checked` (loaded from `c.graph_file` with
/// `c.overrides`) live as `c` says, recording it to its session folder,
/// until its duration, a stop typed on the console or sent by the studio,
/// Ctrl-C, a node's failure or a fault. While it runs it prints what runs
/// and where it records, then (unless quiet) a line of metrics each second
/// and each change as it lands, on stderr. Returns the ended session, its
/// end recorded in the folder; a failure to set it up or to record its end
/// is an error.
pub fn run(c: &SessionConfig, checked: &Checked) -> Result<Ended, SessionError> {
    // Bound before the session (and its folder) starts: a taken port stops
    // nothing that runs.
    #[cfg(feature = "studio")]
    let bound = bind_studio(c)?;
    let graph_text =
        std::fs::read_to_string(&c.graph_file).map_err(SessionError::file(&c.graph_file, "cannot read"))?;
    std::fs::create_dir_all(&c.out).map_err(SessionError::file(&c.out, "cannot create output folder"))?;
    let seed = c.seed.unwrap_or(checked.graph.seed);
    let (lp, n_inputs) = setup::live_plan(c, checked, seed)?;
    let (inputs, outputs) = session::files(lp.taps(), n_inputs)?;
    let folder = setup::Folder { graph_text: &graph_text, seed, inputs: &inputs, outputs: &outputs };
    let (dir, manifest) = folder.open(c, checked, &lp)?;
    let pacing = setup::Pacing::of(c, checked);
    let vars = live::live_vars(checked);
    #[cfg(feature = "studio")]
    let description = c.studio.is_some().then(|| {
        let graph_dir = c.graph_file.parent().unwrap_or(Path::new("."));
        crate::studio::Description::live(checked, &lp, &vars).with_scene(crate::studio::scene_json(checked, graph_dir))
    });
    // The files first: creating them syncs each to disk, which must not
    // happen while the real-time thread fills its rings.
    let files = disk::Files::create(&dir, &[inputs, outputs].concat(), "evflow live")?;
    let mut session = live::start(lp, &pacing.config).map_err(|e| SessionError::Setup(e.to_string()))?;
    let vars_line = setup::vars_line(&vars);
    session.control.bind_vars(vars);
    setup::schedule_changes(&mut session.control, &c.changes)?;
    let base_rate = session.base_rate;
    let names = session.node_names.clone();
    let parts = session.into_parts();
    let shared = parts.shared.clone();
    // The console and the studio queue changes through the same control.
    let control = Arc::new(std::sync::Mutex::new(parts.control));
    #[cfg(feature = "studio")]
    let studio = start_studio(bound, description, &control, &shared)?;
    threads::on_ctrl_c(&shared);

    // Recorder, metrics display and console: ordinary threads.
    let done = Arc::new(AtomicBool::new(false));
    let recorder = Recorder::create(files, parts.taps, parts.events, names, threads::FLUSH_EVERY)?;
    let recorder = if c.quiet { recorder } else { recorder.echo(base_rate) };
    #[cfg(feature = "studio")]
    let recorder = match &studio {
        Some((_, ingest)) => recorder.tee(Box::new(ingest.clone())),
        None => recorder,
    };
    let rec_thread = threads::spawn_recorder(recorder, &done)?;
    let show = !c.quiet;
    #[cfg(feature = "studio")]
    let ingest = studio.as_ref().map(|(_, i)| i.clone());
    #[cfg(not(feature = "studio"))]
    let ingest: Option<()> = None;
    let display = threads::Display { done: done.clone(), shared: shared.clone(), base_rate, show };
    let metrics_thread = display.spawn(parts.stats, ingest)?;
    if show {
        pacing.print_intro(&checked.graph.name, base_rate, &dir, &vars_line);
    }
    threads::spawn_console(control)?;

    let ran = Ran::wait(parts.thread, &done, rec_thread, metrics_thread)?;
    #[cfg(feature = "studio")]
    if let Some((studio, _)) = studio {
        close_studio(studio);
    }
    ran.finish(c, &dir, &manifest, &shared, base_rate)
}

/// Binds the studio's address when the session is to serve it.
#[cfg(feature = "studio")]
fn bind_studio(c: &SessionConfig) -> Result<Option<crate::studio::Bound>, SessionError> {
    Ok(match &c.studio {
        Some(cfg) => Some(crate::studio::Bound::bind(cfg)?),
        None => None,
    })
}

/// Starts serving the studio on the bound address, sharing the session's
/// control; prints its address.
#[cfg(feature = "studio")]
fn start_studio(
    bound: Option<crate::studio::Bound>,
    description: Option<crate::studio::Description>,
    control: &Arc<std::sync::Mutex<live::Control>>,
    shared: &Arc<live::Shared>,
) -> Result<Option<(crate::studio::Studio, crate::studio::Ingest)>, SessionError> {
    Ok(match (bound, description) {
        (Some(bound), Some(d)) => {
            let (studio, ingest) = bound.start_live(&d, control.clone(), shared.clone())?;
            eprintln!("studio: {}", studio.url());
            if studio.token().is_some() {
                eprintln!("studio: serving beyond this machine; the address above holds its one-time token");
            }
            Some((studio, ingest))
        }
        _ => None,
    })
}

/// Lets the last frames reach the page, reports frames browsers lost, and
/// closes the studio.
#[cfg(feature = "studio")]
fn close_studio(studio: crate::studio::Studio) {
    // The last frames reach the page before it is told the session ended.
    std::thread::sleep(Duration::from_millis(150));
    if studio.frames_dropped() > 0 {
        eprintln!(
            "studio: browsers lost {} frames (slow to read; the session was not delayed)",
            studio.frames_dropped()
        );
    }
    studio.close();
}
