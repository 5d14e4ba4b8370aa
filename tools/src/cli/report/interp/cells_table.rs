//! The Markdown report of `evflow report interp --cells narx|optimized|playback`
//! ([`super::cells`]): the trained cells with their control, then
//! the cross-validation in both orders.

use super::Args;
use evflow_nodes::texture::kernel::INTERP_CUTOFF;
use evflow_study::crossval::{Cell, Run, SchemeRun};
use evflow_study::row::Method;
use evflow_study::xval::GRAPH;
use std::fmt::Write as _;

fn num(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.3}")
    } else {
        "—".into()
    }
}

/// The Markdown report.
pub(super) fn table(
    a: &Args,
    method: Method,
    periods: &[(String, f64)],
    cells: &[Cell],
    rows: &[(bool, Run)],
    seconds: f64,
) -> String {
    let ff_how = match method {
        Method::Optimized => "the optimized synthesis through the nearest trained condition's forward model, offline",
        Method::Playback => "none: the playback cells are the forces",
        _ => "the nearest trained condition's inverse NARX model",
    };
    let mut md = String::new();
    periods_line(&mut md, a, method, periods);
    trained_cells(&mut md, a, ff_how, cells);
    cross_validation(&mut md, a, rows);
    means(&mut md, ff_how, rows, seconds);
    md
}

/// The cells' method, lab profile and loop periods.
fn periods_line(md: &mut String, a: &Args, method: Method, periods: &[(String, f64)]) {
    let _ = write!(
        md,
        "Cells: {}, lab profile {}. Loops of whole main periods (`interp`'s `period`, measured on the trained recordings):",
        method.label(),
        a.profile
    );
    for (k, (s, p)) in periods.iter().enumerate() {
        let _ = write!(md, "{} {s} {:.4} mm", if k == 0 { "" } else { "," }, p * 10.0);
    }
    let _ = writeln!(md, ".\n");
}

/// The trained cells against their control; `ff_how`: how the forces
/// first scheme makes its actuation.
fn trained_cells(md: &mut String, a: &Args, ff_how: &str, cells: &[Cell]) {
    let (lo, hi) = (a.band[0], a.band[1]);
    let _ = writeln!(
        md,
        "## Trained cells U_ij and the control\n\nE_s (Eq. 5.2, {lo}–{hi} Hz, constant-speed stretch) against \
         repetition 2 at the trained condition itself. `synthesize`: the cell as graphs/synthesize.toml scored it \
         (gain chosen over {:?} by Table 5.1's rule, as `report textures` does). `through interp`: the grid \
         interpolated at the cell's own condition by graphs/{GRAPH} — no interpolation is needed there, so both \
         schemes should give the cell back. `above cutoff`: the share of the cell's power above {:.0} % of the \
         Nyquist frequency, which `interp`'s re-sampling kernel removes. Forces first: {ff_how}.\n",
        a.gains,
        INTERP_CUTOFF * 100.0
    );
    let _ = writeln!(
        md,
        "| sample | condition | repeat baseline | cells E_s, synthesize | gain | through interp: basic | improved | above cutoff | record-and-playback E_s | its gain | forces first: basic | improved |"
    );
    let _ = writeln!(md, "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for c in cells {
        let [b, i] = &c.run.schemes;
        let _ = writeln!(
            md,
            "| {} | {} | {:.3} | {:.3} | {} | {:.3} | {:.3} | {:.0} % | {:.3} | {} | {} | {} |",
            c.run.sample,
            c.run.cond.label(),
            c.repeat,
            c.cell.rect,
            c.cell.gain,
            b.scores.cells,
            i.scores.cells,
            c.above_cutoff * 100.0,
            c.playback.rect,
            c.playback.gain,
            num(b.ff_es()),
            num(i.ff_es())
        );
    }
}

/// The grid interpolated to each untrained condition and played there.
fn cross_validation(md: &mut String, a: &Args, rows: &[(bool, Run)]) {
    let (lo, hi) = (a.band[0], a.band[1]);
    let _ = writeln!(
        md,
        "\n## Cross-validation on the display (Fig. 5.6, 5.9, 6.8)\n\nThe grid interpolated to each untrained \
         condition and played on the virtual display there (graphs/{GRAPH}); E_s ({lo}–{hi} Hz) against \
         repetition 2 of the real recording at that condition; the main peak of each force.\n"
    );
    let _ = writeln!(
        md,
        "| sample | load (g) | speed (cm/s) | repeat baseline | cells basic (§5.3.3) | cells improved (Eq. 6.4) | improved better | main peak, Hz: real / basic / improved | record-and-playback basic | record-and-playback improved | forces first: model | basic | improved | improved better | main peak, Hz: basic / improved |"
    );
    let _ = writeln!(md, "|---|---:|---:|---:|---:|---:|---|---|---:|---:|---|---:|---:|---|---|");
    let peak = |s: &SchemeRun| s.ff.as_ref().map_or("—".to_string(), |f| f.1.to_string());
    for (velocity, r) in rows {
        let [b, i] = &r.schemes;
        let verdict = |better: bool| match (velocity, better) {
            (false, _) => "— (no velocity step)",
            (true, true) => "yes",
            (true, false) => "**no**",
        };
        let _ = writeln!(
            md,
            "| {} | {} | {} | {:.3} | {:.3} | {:.3} | {} | {} / {} / {} | {:.3} | {:.3} | {} | {} | {} | {} | {} / {} |",
            r.sample,
            r.cond.mass,
            r.cond.speed,
            i.scores.repeat,
            b.scores.cells,
            i.scores.cells,
            verdict(i.scores.cells < b.scores.cells),
            i.scores.real_peak_hz,
            b.scores.cells_peak_hz,
            i.scores.cells_peak_hz,
            b.scores.playback,
            i.scores.playback,
            r.near.label(),
            num(b.ff_es()),
            num(i.ff_es()),
            verdict(i.ff_es() < b.ff_es()),
            peak(b),
            peak(i)
        );
    }
}

/// The means over the conditions, and how often the improved scheme wins.
fn means(md: &mut String, ff_how: &str, rows: &[(bool, Run)], seconds: f64) {
    let mean = |f: &dyn Fn(&Run) -> f64| rows.iter().map(|(_, r)| f(r)).sum::<f64>() / rows.len().max(1) as f64;
    let velocity: Vec<&Run> = rows.iter().filter(|(v, _)| *v).map(|(_, r)| r).collect();
    let wins = velocity.iter().filter(|r| r.schemes[1].scores.cells < r.schemes[0].scores.cells).count();
    let ff_wins = velocity.iter().filter(|r| r.schemes[1].ff_es() < r.schemes[0].ff_es()).count();
    let _ = writeln!(
        md,
        "\nMean E_s: repeat {:.3}; cells basic {:.3}, improved {:.3}; record-and-playback basic {:.3}, improved {:.3}. \
         The improved scheme is better on {wins} of {} velocity-interpolated conditions.\n\n\
         Forces first (the recorded forces interpolated, then {ff_how}): \
         mean E_s basic {}, improved {}; the improved scheme is better on {ff_wins} of {} velocity-interpolated \
         conditions. Whole report: {seconds:.0} s.",
        mean(&|r| r.schemes[1].scores.repeat),
        mean(&|r| r.schemes[0].scores.cells),
        mean(&|r| r.schemes[1].scores.cells),
        mean(&|r| r.schemes[0].scores.playback),
        mean(&|r| r.schemes[1].scores.playback),
        velocity.len(),
        num(mean(&|r| r.schemes[0].ff_es())),
        num(mean(&|r| r.schemes[1].ff_es())),
        velocity.len()
    );
}
