//! The tables of `evflow report textures`: Markdown for people, CSV for
//! everything else. `evflow report textures` writes them from its study,
//! `evflow merge` from the study its shards saved; with
//! [`Timings::Leave`] (`--no-times`) no time is written, so that both are
//! byte for byte the same.

use crate::row::{Method, Row};
use crate::run::{Study, StudyConfig};
use crate::summary::{es, standing, Basis};
use evflow_nodes::lab::texture::samples::NAMES;
use evflow_nodes::narx::model::Model;
use evflow_nodes::synth::model_file::ForwardModel;

pub use super::Timings;
use std::fmt::Write as _;

/// The basis of the headline figures.
pub const HEADLINE: Basis = Basis::Table51Welch;

/// The method the targets are held to.
pub const BEST: Method = Method::Optimized;

/// Dissertation Table 5.1: gains per (condition, TS1–TS6).
const TABLE_51: [(&str, [f64; 6]); 4] = [
    ("60 g, 3 cm/s", [1.4, 1.0, 0.6, 0.6, 1.4, 1.2]),
    ("60 g, 5 cm/s", [1.0, 1.4, 1.0, 0.6, 1.0, 1.0]),
    ("110 g, 3 cm/s", [1.0, 1.0, 0.6, 0.6, 0.6, 0.6]),
    ("110 g, 5 cm/s", [1.0, 1.4, 1.0, 0.8, 0.6, 1.0]),
];

fn f3(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.3}")
    } else {
        "–".into()
    }
}

fn ratio(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.2}×")
    } else {
        "–".into()
    }
}

/// The report's Markdown.
pub fn markdown(study: &Study, cfg: &StudyConfig, timings: Timings) -> String {
    let mut md = String::new();
    let _ = writeln!(md, "# Texture rendering: every method on every lab profile\n");
    let _ = writeln!(
        md,
        "Every method's actuation is played on the virtual display of the profile (the tribometer repeats \
         the recording's pass) and its force scored by E_s (Eq. 5.2, 2–200 Hz, constant-speed stretch) against \
         repetition 2 of the real recording; every method gets the same gain sweep ({}) and the same rules. \
         **Headline: {}** — Table 5.1's rule is the dissertation's; the Welch reading (Hann window, half-overlapping \
         one-second segments) is used for the headline because with one or two rectangular segments per pass \
         E_s swings with the noise of a single spectrum (and leaks); the rect reading and the best-gain rule are \
         tabulated below. Definitions: docs/synthesis.md.\n",
        cfg.scope.gains.iter().map(|g| g.to_string()).collect::<Vec<_>>().join(", "),
        HEADLINE.label()
    );
    let _ = writeln!(
        md,
        "* **repeat baseline**: repetition 1 against repetition 2 (§5.3.1).\n\
         * **display floor**: repetition 1 plus the display's own force with no actuation — electrovibration \
         only adds friction.\n\
         * **achievable floor**: the best E_s reached by optimizing the actuation through the lab's own simulated \
         display (noise off, u in [−1, 1], several starts, gain sweep), or a method's where one did better.\n"
    );
    models_table(&mut md, study, timings);
    for profile in &cfg.profiles {
        let rows: Vec<&Row> = study.rows.iter().filter(|r| r.profile == profile.name).collect();
        rows_table(&mut md, &profile.name, &rows, timings);
    }
    standing_tables(&mut md, study, cfg);
    table_51(&mut md, study, cfg);
    targets(&mut md, study, cfg);
    if timings == Timings::Show {
        let _ = writeln!(md, "\nWhole report: {:.0} s.", study.seconds);
    }
    md
}

fn models_table(md: &mut String, study: &Study, timings: Timings) {
    let secs = |s: f64| if timings == Timings::Show { format!("{s:.2}") } else { "–".into() };
    let _ = writeln!(md, "## Models\n");
    let _ = writeln!(
        md,
        "| profile | condition | NARX binary: closed-loop transitions / noise as force / s | NARX multilevel: level agreement / s | forward: validation error / carrier gain (N) / s |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|");
    for (profile, c, m) in &study.models {
        let narx = Model::load(&m.narx).map_or("–".to_string(), |m| {
            let t = &m.training;
            format!(
                "{} / {} / {}",
                f3(t.closed_loop.map_or(f64::NAN, |c| c.transition_agreement)),
                f3(t.closed_loop_noise_force.map_or(f64::NAN, |c| c.transition_agreement)),
                secs(t.seconds)
            )
        });
        let ml = m.narx_multilevel.as_ref().and_then(|p| Model::load(p).ok()).map_or("–".to_string(), |m| {
            let t = &m.training;
            format!("{} / {}", f3(t.closed_loop.map_or(f64::NAN, |c| c.sign_agreement)), secs(t.seconds))
        });
        let fwd = ForwardModel::load(&m.forward).map_or("–".to_string(), |f| {
            format!(
                "{} / {:.4} / {}",
                f3(f.training.scores.validation_rel_rms.unwrap_or(f64::NAN)),
                f.carrier_gain_n,
                secs(f.training.seconds)
            )
        });
        let _ = writeln!(md, "| {profile} | {} | {narx} | {ml} | {fwd} |", c.label());
    }
    let _ = writeln!(md);
}

fn rows_table(md: &mut String, profile: &str, rows: &[&Row], timings: Timings) {
    let methods: Vec<Method> =
        Method::ALL.into_iter().filter(|m| rows.iter().any(|r| r.method(*m).is_some())).collect();
    let _ = writeln!(md, "## {profile}\n\n{} per row; time: synthesis of the optimized actuation.\n", HEADLINE.label());
    let mut head = "| texture | condition | repeat | display floor | achievable floor |".to_string();
    for m in &methods {
        let _ = write!(head, " {} |", m.label());
    }
    head += " best / achievable | best / display floor | best / repeat | beats playback | time (s) |";
    let _ = writeln!(md, "{head}");
    let _ = writeln!(md, "|---|---|{}", "---:|".repeat(3 + methods.len() + 5));
    for r in rows {
        let floor = r.floor().map_or(f64::NAN, |f| HEADLINE.of(f));
        let mut line = format!(
            "| {} | {} | {} | {} | {} |",
            r.sample,
            r.cond.label(),
            f3(HEADLINE.of(r.repeat)),
            f3(HEADLINE.of(r.display_floor)),
            f3(floor)
        );
        for m in &methods {
            let _ = write!(line, " {} |", es(r, *m, HEADLINE).map_or("–".into(), f3));
        }
        let best = es(r, BEST, HEADLINE).unwrap_or(f64::NAN);
        let play = es(r, Method::Playback, HEADLINE).unwrap_or(f64::NAN);
        let _ = write!(
            line,
            " {} | {} | {} | {} | {} |",
            ratio(best / floor),
            ratio(best / HEADLINE.of(r.display_floor)),
            ratio(best / HEADLINE.of(r.repeat)),
            if best < play { "yes" } else { "**no**" },
            match timings {
                Timings::Show => format!("{:.2}", r.method(BEST).map_or(f64::NAN, |m| m.seconds)),
                Timings::Leave => "–".into(),
            }
        );
        let _ = writeln!(md, "{line}");
    }
    let _ = writeln!(md);
}

fn standing_tables(md: &mut String, study: &Study, cfg: &StudyConfig) {
    for basis in Basis::ALL {
        let _ = writeln!(md, "## Standing — {}\n", basis.label());
        let _ = writeln!(
            md,
            "| profile | method | rows | mean E_s | mean / achievable floor | worst / achievable floor | within 1.3× | within 2× | mean / display floor | mean / repeat | below fair playback |"
        );
        let _ = writeln!(md, "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
        for p in &cfg.profiles {
            let rows: Vec<&Row> = study.rows.iter().filter(|r| r.profile == p.name).collect();
            for m in Method::ALL {
                let s = standing(&rows, m, basis);
                if s.rows == 0 {
                    continue;
                }
                let _ = writeln!(
                    md,
                    "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
                    p.name,
                    m.label(),
                    s.rows,
                    f3(s.mean),
                    ratio(s.mean_over_floor),
                    ratio(s.worst_over_floor),
                    s.within_1_3,
                    s.within_2,
                    ratio(s.mean_over_display_floor),
                    ratio(s.mean_over_repeat),
                    if m == Method::Playback { "–".into() } else { s.beats_playback.to_string() }
                );
            }
        }
        let _ = writeln!(md);
    }
}

fn table_51(md: &mut String, study: &Study, cfg: &StudyConfig) {
    let _ = writeln!(
        md,
        "## Table 5.1: the gains chosen (nominal lab)\n\nEach cell: the dissertation's gain | inverse NARX (binary) | optimized synthesis | fair playback, chosen by Table 5.1's rule.\n"
    );
    let samples = &cfg.scope.samples;
    let _ = writeln!(md, "| condition | {} |", samples.join(" | "));
    let _ = writeln!(md, "|---|{}", "---|".repeat(samples.len()));
    for c in &cfg.scope.conds {
        let mut line = format!("| {} |", c.label());
        for s in samples {
            let diss = TABLE_51
                .iter()
                .find(|(l, _)| *l == c.label())
                .and_then(|(_, g)| NAMES.iter().position(|n| n == s).and_then(|i| g.get(i)));
            let r = study.rows.iter().find(|r| r.profile == "nominal" && &r.sample == s && r.cond == *c);
            let g = |m: Method| r.and_then(|r| r.method(m)).map_or("–".into(), |m| m.chosen.table51.gain.to_string());
            let _ = write!(
                line,
                " {} \\| {} \\| {} \\| {} |",
                diss.map_or("–".into(), |d| d.to_string()),
                g(Method::NarxBinary),
                g(Method::Optimized),
                g(Method::Playback)
            );
        }
        let _ = writeln!(md, "{line}");
    }
    let _ = writeln!(md);
}

fn targets(md: &mut String, study: &Study, cfg: &StudyConfig) {
    let _ = writeln!(md, "## Targets (issue 13, point 6), {}\n", HEADLINE.label());
    for p in &cfg.profiles {
        let rows: Vec<&Row> = study.rows.iter().filter(|r| r.profile == p.name).collect();
        let s = standing(&rows, BEST, HEADLINE);
        let _ = writeln!(
            md,
            "* {}: {} within 1.3× of the achievable floor on {} of {} rows, within 2× on {}, below fair playback on {}.",
            p.name,
            BEST.label(),
            s.within_1_3,
            s.rows,
            s.within_2,
            s.beats_playback
        );
    }
}

/// Every row, every method, every reading, as CSV (`seconds` empty
/// without times).
pub fn csv(study: &Study, timings: Timings) -> String {
    let mut out = String::from(
        "profile,sample,mass_g,speed_cm_s,repeat_rect,repeat_welch,display_floor_rect,display_floor_welch,achievable_rect,achievable_welch,method,gain_t51,rect_t51,welch_t51,peak_ratio_t51,gain_best_rect,rect_best,gain_best_welch,welch_best,seconds\n",
    );
    for r in &study.rows {
        let f = r.floor();
        for m in &r.methods {
            let c = &m.chosen;
            let _ = writeln!(
                out,
                "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
                r.profile,
                r.sample,
                r.cond.mass,
                r.cond.speed,
                r.repeat.rect,
                r.repeat.welch,
                r.display_floor.rect,
                r.display_floor.welch,
                f.map_or(f64::NAN, |f| f.rect),
                f.map_or(f64::NAN, |f| f.welch),
                m.method.chain(),
                c.table51.gain,
                c.table51.rect,
                c.table51.welch,
                c.table51.peak_ratio,
                c.best_rect.gain,
                c.best_rect.rect,
                c.best_welch.gain,
                c.best_welch.welch,
                if timings == Timings::Show { m.seconds.to_string() } else { String::new() }
            );
        }
    }
    out
}
