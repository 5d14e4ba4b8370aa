//! A stroke's score for people: a Markdown table of E_s (Welch headline,
//! rect beside it, the gain each was reached at) and the figure of the
//! amplitude spectra.

use super::Score;
use crate::figure::{Plot, Series};
use crate::gains::AtGain;
use std::fmt::Write as _;

fn f3(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.3}")
    } else {
        "–".into()
    }
}

fn ratio(a: f64, b: f64) -> String {
    if a.is_finite() && b.is_finite() && b > 0.0 {
        format!("{:.2}×", a / b)
    } else {
        "–".into()
    }
}

/// The best Welch reading of a sweep and its gain.
fn best(sweep: &[AtGain]) -> Option<AtGain> {
    sweep.iter().copied().min_by(|a, b| a.welch.total_cmp(&b.welch))
}

/// The score as Markdown.
pub fn markdown(s: &Score) -> String {
    let mut md = String::new();
    let r = &s.row;
    let c = s.chain();
    let material = if s.material.is_empty() { "(not recorded)" } else { s.material.as_str() };
    let _ = writeln!(md, "# Score of {} on {}\n", r.user, s.display);
    let _ = writeln!(
        md,
        "- stroke: `{}`\n- actuation: `{}`\n- real force: `{}` (material {material}; the display floor takes off {})\n- {:.3} s \
         scored; E_s of the display's force against the real force, both high-passed at 10 Hz, 2–200 Hz; Welch \
         (Hann, half-overlapping one-second segments) and rect (the dissertation's); every actuation × gain, then \
         |u| ≤ 1\n",
        s.files[0].display(),
        s.files[1].display(),
        s.files[2].display(),
        s.base.describe(),
        s.seconds
    );
    let _ = writeln!(md, "| | E_s Welch | E_s rect | gain |\n|---|---|---|---|");
    let mut line = |what: &str, welch: f64, rect: f64, gain: &str| {
        let _ = writeln!(md, "| {what} | {} | {} | {gain} |", f3(welch), f3(rect));
    };
    line("nothing (no actuation)", r.nothing.welch, r.nothing.rect, "–");
    line(
        "display floor (no actuation + the texture's own force modulation)",
        r.display_floor.welch,
        r.display_floor.rect,
        "–",
    );
    if let Some(g1) = s.at_gain_1() {
        line("**the chain's actuation, as recorded**", g1.welch, g1.rect, "1");
    }
    let t = c.chosen.table51;
    line("the chain's actuation at Table 5.1's gain", t.welch, t.rect, &format!("{}", t.gain));
    let b = c.chosen.best_welch;
    line("the chain's actuation at its best gain", b.welch, c.chosen.best_rect.rect, &format!("{}", b.gain));
    if let (Some(tf), Some(f)) = (&r.target_floor, r.target_floor()) {
        let g = best(&tf.sweep).map_or("–".into(), |a| format!("{}", a.gain));
        line("target's floor (optimized towards the chain's own target)", f.welch, f.rect, &g);
    }
    if let (Some(a), Some(f)) = (&r.achievable, r.floor()) {
        let g = best(&a.sweep).map_or("–".into(), |x| format!("{}", x.gain));
        line("stroke's floor (optimized towards the real force)", f.welch, f.rect, &g);
        line(
            "stroke's floor, nothing played within 150 ms of a reversal",
            a.sliding_only.welch,
            a.sliding_only.rect,
            "best",
        );
    }
    let _ = writeln!(md);
    let g1 = s.at_gain_1().map_or(f64::NAN, |a| a.welch);
    let _ = writeln!(md, "- the chain (gain 1) / nothing: {}", ratio(g1, r.nothing.welch));
    if let Some(f) = r.floor() {
        let _ = writeln!(
            md,
            "- the chain / the stroke's floor: {} at gain 1, {} at its best gain",
            ratio(g1, f.welch),
            ratio(b.welch, f.welch)
        );
    }
    if let (Some(tf), Some(f)) = (r.target_floor(), r.floor()) {
        let _ = writeln!(
            md,
            "- what the target lacks (target's floor / stroke's floor): {}; what the synthesis loses (the chain at \
             its best gain / target's floor): {}",
            ratio(tf.welch, f.welch),
            ratio(b.welch, tf.welch)
        );
    }
    if let (Some(a), Some(tf)) = (&r.achievable, &r.target_floor) {
        let _ = writeln!(
            md,
            "- floors: the best of the carrier starts and the chain's own actuation, each optimized {} \
             (stroke's floor from `{}`, {:.1} s; target's floor from `{}`, {:.1} s), played over the gains {}; where \
             the chain does better, its value",
            if s.display.starts_with("forward models") {
                "through the forward models (the display itself)"
            } else {
                "through the display's twin (noise off), then played with noise"
            },
            a.start,
            a.seconds,
            tf.start,
            tf.seconds,
            c.sweep.iter().map(|x| format!("{}", x.gain)).collect::<Vec<_>>().join(", ")
        );
    }
    md
}

/// The figure: the real force's amplitude spectrum beside the rendered
/// one (the chain's actuation as recorded), nothing's and the stroke's
/// floor's (Welch, 2–200 Hz, log amplitude).
pub fn figure(s: &Score) -> Plot {
    let mut series = vec![
        Series::line("real force", s.spectra.real.clone()),
        Series::line("the chain's actuation (gain 1)", s.spectra.rendered.clone()),
        Series::line("nothing", s.spectra.nothing.clone()),
    ];
    if let Some(f) = &s.spectra.floor {
        series.push(Series::line("stroke's floor", f.clone()));
    }
    let g1 = s.at_gain_1().map_or(f64::NAN, |a| a.welch);
    Plot {
        title: format!(
            "{} on {}: E_s {} (nothing {}{})",
            s.row.user,
            s.display,
            f3(g1),
            f3(s.row.nothing.welch),
            s.row.floor().map_or(String::new(), |f| format!(", stroke's floor {}", f3(f.welch)))
        ),
        x_label: "frequency, Hz".into(),
        y_label: "amplitude (Welch, high-passed at 10 Hz), N".into(),
        log_x: false,
        log_y: true,
        series,
        ..Default::default()
    }
}
