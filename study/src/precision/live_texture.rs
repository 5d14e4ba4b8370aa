//! The live texture chain end to end: graphs/texture-live-quality.toml as
//! the live study runs it ([`crate::live`]: the nominal lab, the first
//! default user, the shipped model library graphs/data for the plastic
//! sheet), over `synth.live`'s look-ahead and iterations per tick. The
//! error is the live chain's E_s (Welch) against the force the finger
//! meets on the real sample; the cost is the live chain's CPU per tick —
//! `interp`, `playback`, `synth.live`, gain and limit, the display and
//! the scoring left out.
//!
//! The reference (the real sample's force under the user's true stroke) is
//! exact, but E_s cannot reach 0: the display's noise and what the forward
//! models miss keep it up. The curve's baseline is the same display with no
//! actuation. The graph's recording of every chain's actuation is left
//! out, so the runs write nothing.

use super::curve::{Curve, WorkPoint};
use super::{PrecisionError, Size};
use crate::graphs::{self, seconds_per_tick, value, Sets};
use crate::live::chains::GRAPH;
use crate::live::scope::{LiveSettings, User};
use crate::setup::Profile;
use std::path::Path;

/// The live chain's nodes (its CPU per tick).
pub const CHAIN: [&str; 5] = ["live_interp", "live_play", "live_synth", "live_gain", "live_limit"];
/// The texture (the shipped library's).
pub const SAMPLE: &str = "plastic-sheet";

fn setting(lookahead: usize, iterations: usize) -> String {
    format!("look-ahead {lookahead}, {iterations} iterations")
}

/// The curve.
pub fn curve(graphs: &Path, size: Size) -> Result<Curve, PrecisionError> {
    let file = graphs.join(GRAPH);
    let graph = graphs::without(graphs::read(&file)?, "record");
    let d = LiveSettings::default();
    let (seconds, lookaheads, iterations): (f64, &[usize], &[usize]) = match size {
        Size::Ci => (3.0, &[7, d.lookahead], &[1, d.iterations, 16]),
        Size::Full => (8.0, &[7, d.lookahead, 31], &[1, 2, d.iterations, 8, 16, 32]),
    };
    let user = &User::defaults()[0];
    let base =
        Sets::new().text("sample", SAMPLE).and(Profile::nominal().sets()).num("offset", d.offset).and(user.sets());
    let mut points = Vec::new();
    let mut nothing = f64::NAN;
    for &l in lookaheads {
        for &k in iterations {
            let sets = base.clone().int("lookahead", l as i64).int("iterations", k as i64);
            let r = graphs::run(&graph, &sets, None, Some(seconds))?;
            nothing = value(&r, &file, "nothing_welch", "E_s")?;
            points.push(WorkPoint {
                setting: setting(l, k),
                series: format!("look-ahead {l}"),
                error: value(&r, &file, "live_welch", "E_s")?,
                cost: seconds_per_tick(&r, &file, &CHAIN)?,
                // Per tick: iterations over a horizon of look-ahead + 1 samples.
                work: (k * (l + 1)) as f64,
            });
        }
    }
    Ok(Curve {
        name: "live-texture".into(),
        computation: format!("live texture chain (synth.live, {SAMPLE}, user {}, {seconds} s)", user.name),
        knob: "look-ahead × iterations per tick".into(),
        error_unit: "E_s (Welch)".into(),
        cost_unit: "tick (1 kHz)".into(),
        reference: format!("the real sample's force under the true stroke (exact; no actuation: E_s = {nothing:.3})"),
        reference_error: 0.0,
        baseline: Some(nothing),
        default: setting(d.lookahead, d.iterations),
        points,
    })
}
