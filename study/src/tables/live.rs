//! The tables of `evflow report live`: Markdown for people, CSV for
//! everything else, from a live study or from the shards `evflow merge`
//! joins (the same code, so a merge writes what one run writes).

use crate::gains::AtGain;
use crate::live::row::{Chain, LiveRow};
use crate::live::run::LiveStudy;
use crate::live::scope::LiveScope;
use std::fmt::Write as _;

/// The factor of the stroke's floor the best chain is held to (issue 24, point 5).
pub const WITHIN: f64 = 1.3;

fn f3(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.3}")
    } else {
        "–".into()
    }
}

fn mean(v: impl Iterator<Item = f64>) -> f64 {
    let (mut s, mut n) = (0.0, 0);
    for x in v {
        s += x;
        n += 1;
    }
    if n == 0 {
        f64::NAN
    } else {
        s / n as f64
    }
}

/// A chain's Welch E_s at Table 5.1's gain rule and at its best gain.
fn welch(r: &LiveRow, c: Chain) -> (f64, f64) {
    r.chain(c).map_or((f64::NAN, f64::NAN), |x| (x.chosen.table51.welch, x.chosen.best_welch.welch))
}

/// The rows of one profile and sample (every user).
fn rows_of<'a>(study: &'a LiveStudy, profile: &'a str, sample: &'a str) -> impl Iterator<Item = &'a LiveRow> + 'a {
    study.rows.iter().filter(move |r| r.profile == profile && r.sample == sample)
}

/// Per profile and sample, averaged over the users: nothing, each chain
/// (rule, best), the stroke's floor, the display floor.
struct Cell {
    nothing: f64,
    chains: Vec<(f64, f64)>,
    floor: f64,
    /// The floor's actuation with nothing played around the reversals.
    sliding: f64,
    display_floor: f64,
    users: usize,
}

fn cell(study: &LiveStudy, profile: &str, sample: &str) -> Cell {
    let rows: Vec<&LiveRow> = rows_of(study, profile, sample).collect();
    Cell {
        nothing: mean(rows.iter().map(|r| r.nothing.welch)),
        chains: Chain::ALL
            .iter()
            .map(|c| (mean(rows.iter().map(|r| welch(r, *c).0)), mean(rows.iter().map(|r| welch(r, *c).1))))
            .collect(),
        floor: mean(rows.iter().filter_map(|r| r.floor()).map(|f| f.welch)),
        sliding: mean(rows.iter().filter_map(|r| r.achievable.as_ref()).map(|a| a.sliding_only.welch)),
        display_floor: mean(rows.iter().map(|r| r.display_floor.welch)),
        users: rows.len(),
    }
}

impl Cell {
    /// The best chain at its best gain (index into [`Chain::ALL`]) and its E_s.
    fn best(&self) -> Option<(usize, f64)> {
        self.chains
            .iter()
            .enumerate()
            .filter(|(_, c)| c.1.is_finite())
            .map(|(k, c)| (k, c.1))
            .min_by(|a, b| a.1.total_cmp(&b.1))
    }
}

/// The report's Markdown.
pub fn markdown(study: &LiveStudy, scope: &LiveScope) -> String {
    let mut md = String::new();
    let _ = writeln!(md, "# Live texture rendering under virtual users\n");
    let _ = writeln!(
        md,
        "Every live chain of graphs/texture-live-quality.toml plays under each virtual user's strokes \
         ({} s each) on its own virtual display of the profile, its actuation × the overall gain bounded by \
         `limit` to |u| ≤ 1 (100 Vpp) — every chain and the floor alike; the display's force, high-passed at \
         10 Hz, is scored by E_s (2–200 Hz) against the force the same finger meets on the real sample. \
         **Welch reading** (Hann, half-overlapping one-second segments), mean over the users; each chain \
         **at Table 5.1's gain rule / at its best gain** over the sweep {}. Beside them: nothing (the display \
         with no actuation), the display floor (no actuation, the texture's own force added: a perfect \
         rendering on top of the display's friction) and the **stroke's floor** (the actuation over the whole \
         stroke optimized through the display's twin knowing the finger's path, load and the real force, \
         within |u| ≤ 1, played with noise on like every chain; where a chain scores lower, the chain's value), \
         and that floor's actuation with nothing played within 150 ms of a reversal (how much of the floor \
         lies in the sliding alone). Definitions: docs/texture.md §9.\n",
        scope.seconds,
        scope.gains.iter().map(|g| format!("{g}")).collect::<Vec<_>>().join(", "),
    );
    let users = scope.users.iter().map(|u| {
        format!(
            "{} (seed {}, {}–{} cm/s, {}–{} g, {} cm strokes)",
            u.name, u.seed, u.speed[0], u.speed[1], u.mass[0], u.mass[1], u.travel_cm
        )
    });
    let _ = writeln!(md, "Users: {}.\n", users.collect::<Vec<_>>().join("; "));
    let header = |md: &mut String, first: &str| {
        let _ = write!(md, "| {first} | nothing |");
        for c in Chain::ALL {
            let _ = write!(md, " {} |", c.label());
        }
        let _ = writeln!(md, " stroke floor | its sliding only | display floor | best chain / floor |");
        let _ = write!(md, "|---|---:|");
        for _ in Chain::ALL {
            let _ = write!(md, "---|");
        }
        let _ = writeln!(md, "---:|---:|---:|---:|");
    };
    let line = |md: &mut String, first: &str, c: &Cell| {
        let best = c.best();
        let _ = write!(md, "| {first} | {} |", f3(c.nothing));
        for (k, (rule, b)) in c.chains.iter().enumerate() {
            let bold = best.is_some_and(|(i, _)| i == k);
            let (o, e) = if bold { ("**", "**") } else { ("", "") };
            let _ = write!(md, " {} / {o}{}{e} |", f3(*rule), f3(*b));
        }
        let ratio = best.map_or(f64::NAN, |(_, b)| b / c.floor);
        let _ = writeln!(
            md,
            " {} | {} | {} | {} |",
            f3(c.floor),
            f3(c.sliding),
            f3(c.display_floor),
            if ratio.is_finite() { format!("{ratio:.2}×") } else { "–".into() }
        );
    };
    // Summary per profile: means over samples and users.
    let _ = writeln!(md, "## Mean over samples and users\n");
    header(&mut md, "profile");
    let mut per_profile = Vec::new();
    for p in &scope.profiles {
        let cells: Vec<Cell> = scope.samples.iter().map(|s| cell(study, p, s)).filter(|c| c.users > 0).collect();
        if cells.is_empty() {
            continue;
        }
        let m = Cell {
            nothing: mean(cells.iter().map(|c| c.nothing)),
            chains: (0..Chain::ALL.len())
                .map(|k| (mean(cells.iter().map(|c| c.chains[k].0)), mean(cells.iter().map(|c| c.chains[k].1))))
                .collect(),
            floor: mean(cells.iter().map(|c| c.floor)),
            sliding: mean(cells.iter().map(|c| c.sliding)),
            display_floor: mean(cells.iter().map(|c| c.display_floor)),
            users: cells.iter().map(|c| c.users).sum(),
        };
        line(&mut md, p, &m);
        per_profile.push((p.clone(), cells));
    }
    let _ = writeln!(md);
    // Per profile, per sample.
    for (p, _) in &per_profile {
        let _ = writeln!(md, "## {p}\n");
        header(&mut md, "sample");
        for s in &scope.samples {
            let c = cell(study, p, s);
            if c.users > 0 {
                line(&mut md, s, &c);
            }
        }
        let _ = writeln!(md);
    }
    // The targets.
    let _ = writeln!(md, "## Targets (issue 24, point 5)\n");
    for (p, cells) in &per_profile {
        let within = cells.iter().filter(|c| c.best().is_some_and(|(_, b)| b <= WITHIN * c.floor)).count();
        let live_k = Chain::ALL.iter().position(|c| *c == Chain::Live).unwrap_or(0);
        let live_within = cells.iter().filter(|c| c.chains[live_k].1 <= WITHIN * c.floor).count();
        let room: Vec<&Cell> = cells.iter().filter(|c| c.floor <= 0.9 * c.nothing).collect();
        let beats = room.iter().filter(|c| c.best().is_some_and(|(_, b)| b < c.nothing)).count();
        let live_beats = room.iter().filter(|c| c.chains[live_k].1 < c.nothing).count();
        let live_rule_beats = room.iter().filter(|c| c.chains[live_k].0 < c.nothing).count();
        let _ = writeln!(
            md,
            "* {p}: the best chain within {WITHIN}× of the stroke's floor on {within} of {} samples (the live \
             synthesis on {live_within}); where the floor is ≥ 10 % below nothing ({} samples), the best chain \
             beats nothing on {beats}, the live synthesis on {live_beats} at its best gain and {live_rule_beats} \
             at Table 5.1's rule.",
            cells.len(),
            room.len()
        );
    }
    let _ = writeln!(md);
    if !study.failures.is_empty() {
        let _ = writeln!(md, "## Steps that failed\n");
        for (what, why) in &study.failures {
            let _ = writeln!(md, "* {what}: {why}");
        }
        let _ = writeln!(md);
    }
    md
}

/// Every row and chain: profile, sample, user, chain, then Welch and rect
/// E_s and the gain at Table 5.1's rule and at the best gain.
pub fn csv(study: &LiveStudy) -> String {
    let mut out = String::from(
        "profile,sample,user,chain,rule_gain,rule_welch,rule_rect,best_welch_gain,best_welch,best_rect_gain,best_rect\n",
    );
    let at = |a: &AtGain| (a.gain, a.welch, a.rect);
    for r in &study.rows {
        let mut put = |name: &str, rule: (f64, f64, f64), bw: (f64, f64), br: (f64, f64)| {
            let _ = writeln!(
                out,
                "{},{},{},{name},{},{},{},{},{},{},{}",
                r.profile, r.sample, r.user, rule.0, rule.1, rule.2, bw.0, bw.1, br.0, br.1
            );
        };
        put("nothing", (0.0, r.nothing.welch, r.nothing.rect), (0.0, r.nothing.welch), (0.0, r.nothing.rect));
        for c in &r.chains {
            let (g, w, re) = at(&c.chosen.table51);
            put(
                c.chain.prefix(),
                (g, w, re),
                (c.chosen.best_welch.gain, c.chosen.best_welch.welch),
                (c.chosen.best_rect.gain, c.chosen.best_rect.rect),
            );
        }
        if let Some(f) = r.floor() {
            put("stroke_floor", (f64::NAN, f.welch, f.rect), (f64::NAN, f.welch), (f64::NAN, f.rect));
        }
        if let Some(a) = &r.achievable {
            let f = a.sliding_only;
            put("floor_sliding_only", (f64::NAN, f.welch, f.rect), (f64::NAN, f.welch), (f64::NAN, f.rect));
        }
        let d = r.display_floor;
        put("display_floor", (0.0, d.welch, d.rect), (0.0, d.welch), (0.0, d.rect));
    }
    out
}

/// One figure per profile: E_s (Welch, mean over the users) of nothing,
/// every chain at its best gain and the stroke's floor, sample by sample
/// (x = the sample's number in the scope, 1 …).
pub fn figures(study: &LiveStudy, scope: &LiveScope) -> Vec<(String, crate::figure::Plot)> {
    use crate::figure::{Plot, Series};
    let mut out = Vec::new();
    for p in &scope.profiles {
        let cells: Vec<(f64, Cell)> = scope
            .samples
            .iter()
            .enumerate()
            .map(|(k, s)| ((k + 1) as f64, cell(study, p, s)))
            .filter(|(_, c)| c.users > 0)
            .collect();
        if cells.is_empty() {
            continue;
        }
        let pts =
            |f: &dyn Fn(&Cell) -> f64| cells.iter().map(|(x, c)| (*x, f(c))).filter(|p| p.1.is_finite()).collect();
        let mut series = vec![Series::line_points("nothing", pts(&|c| c.nothing))];
        for (k, ch) in Chain::ALL.iter().enumerate() {
            series.push(Series::line_points(format!("{} (best gain)", ch.label()), pts(&|c| c.chains[k].1)));
        }
        series.push(Series::line_points("stroke floor", pts(&|c| c.floor)));
        let names: Vec<String> = scope.samples.iter().enumerate().map(|(k, s)| format!("{} {s}", k + 1)).collect();
        out.push((
            format!("live-{p}.png"),
            Plot {
                title: format!("{p}: E_s under the virtual users (Welch, mean over users)"),
                x_label: format!("sample: {}", names.join(", ")),
                y_label: "E_s".into(),
                log_x: false,
                log_y: false,
                series,
            },
        ));
    }
    out
}
