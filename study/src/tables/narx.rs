//! The Markdown table of the NARX settings study
//! ([`crate::narx`]):
//! written by `evflow report narx` and, from the shards' items, by `evflow
//! merge`, so both write the same bytes; and the report's figure
//! ([`figure`]).

use crate::figure::{Plot, Series};
use crate::narx::run::{pareto, Scored};
use crate::setup::Cond;
use std::fmt::Write as _;

/// What the table shows.
#[derive(Debug, Clone)]
pub struct Table<'a> {
    /// The condition.
    pub condition: Cond,
    /// The textures scored.
    pub textures: &'a [String],
    /// The textures left out (their recording or optimized synthesis failed).
    pub left_out: &'a [String],
    /// The gain sweep.
    pub gains: &'a [f64],
    /// Seeds tried per setting.
    pub seeds: u32,
    /// Whether training times are shown (and with them the Pareto front);
    /// without them the table is the same on every run.
    pub times: bool,
    /// The settings' rows.
    pub scored: &'a [Scored],
}

/// The table, with its caption, in Markdown.
pub fn markdown(t: &Table<'_>) -> String {
    let mut md = String::new();
    let left_out = if t.left_out.is_empty() {
        String::new()
    } else {
        format!("; left out, their recording or optimized synthesis failed: {}", t.left_out.join(", "))
    };
    let _ = writeln!(
        md,
        "Error against run time of the inverse NARX model at {} ({} textures{left_out}; gain sweep {:?}): mean E_s (Eq. 5.2, 2–200 Hz, rectangular segments as the `metric` node takes it) of the virtual against the real force at the gain Table 5.1's rule chooses, and at the best gain of the sweep, as `report textures` scores every method; training time of graphs/model-build.toml (3066 samples); each the mean over the models trained from seeds 1–{} that were scored (column seeds; a setting none of whose models was scored shows –).",
        t.condition.label(),
        t.textures.len(),
        t.gains,
        t.seeds,
    );
    if !t.times {
        let _ = writeln!(md, "Training times are left out (--no-times), and with them the Pareto front.");
    }
    let _ = writeln!(md);
    let front = pareto(&t.scored.iter().map(|s| (s.seconds, s.es)).collect::<Vec<_>>());
    let (pareto_head, pareto_rule) = if t.times { (" Pareto front |", "---|") } else { ("", "") };
    let _ = writeln!(md, "| setting | network, taps, trainer | seeds | weights | epochs | training time (s) | closed-loop transition agreement | mean E_s | E_s range over seeds | mean E_s, best gain |{pareto_head}");
    let _ = writeln!(md, "|---|---|---:|---:|---:|---:|---:|---:|---|---:|{pareto_rule}");
    for (s, on) in t.scored.iter().zip(&front) {
        let seeds = format!("{} of {}", s.seeds, s.of);
        let (name, describe) = (&s.setting.name, s.setting.describe());
        if s.seeds == 0 {
            let pareto = if t.times { " – |" } else { "" };
            let _ = writeln!(md, "| {name} | {describe} | {seeds} | – | – | – | – | – | – | – |{pareto}");
            continue;
        }
        let time = if t.times { format!("{:.2}", s.seconds) } else { "–".into() };
        let pareto = if t.times { format!(" {} |", if *on { "yes" } else { "" }) } else { String::new() };
        let _ = writeln!(
            md,
            "| {name} | {describe} | {seeds} | {} | {:.0} | {time} | {:.3} | {:.3} | {:.2}–{:.2} | {:.3} |{pareto}",
            s.weights, s.epochs, s.transitions, s.es, s.spread.0, s.spread.1, s.best,
        );
    }
    if t.times {
        if let Some(i) = t.scored.iter().position(|s| s.setting.name == "default" && s.seeds > 0) {
            let _ =
                writeln!(md, "\nThe default network is {}on the Pareto front.", if front[i] { "" } else { "**not** " });
        }
    }
    md
}

/// The report's figure: mean E_s against training time, one point per
/// setting that was scored.
pub fn figure(condition: &Cond, scored: &[Scored]) -> Plot {
    Plot {
        title: format!("Inverse NARX: E_s against training time at {}", condition.label()),
        x_label: "training time (s)".into(),
        y_label: "mean E_s".into(),
        log_x: true,
        log_y: false,
        series: scored
            .iter()
            .filter(|s| s.seeds > 0)
            .map(|s| Series::points(format!("{} ({})", s.setting.name, s.setting.describe()), vec![(s.seconds, s.es)]))
            .collect(),
        ..Default::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::narx::run::{aggregate, Item, SeedScore};
    use crate::narx::setting::Setting;

    fn table(times: bool) -> String {
        let settings: Vec<Setting> = ["default=5/1/10/lm", "slow=3/1/5/adam", "broken=5/1/1000/lm"]
            .iter()
            .map(|s| Setting::parse(s).unwrap())
            .collect();
        let ok = |index, setting, seed, es, seconds| Item {
            index,
            setting,
            seed,
            score: Ok(SeedScore { es, best: es / 2.0, seconds, epochs: 3, transitions: 0.5, weights: 86 }),
        };
        let failed = |index, setting, seed| Item { index, setting, seed, score: Err("no".into()) };
        let items = vec![
            ok(0, 0, 1, 0.5, 1.0),
            failed(1, 0, 2),
            ok(2, 1, 1, 0.75, 3.0),
            ok(3, 1, 2, 0.75, 3.0),
            failed(4, 2, 1),
            failed(5, 2, 2),
        ];
        let scored = aggregate(&settings, 2, &items);
        markdown(&Table {
            condition: Cond { mass: 60.0, speed: 5.0 },
            textures: &["plastic-sheet".into()],
            left_out: &["felt-fabric".into()],
            gains: &[1.0],
            seeds: 2,
            times,
            scored: &scored,
        })
    }

    #[test]
    fn rows_say_over_how_many_seeds_and_failed_settings_show_dashes() {
        let md = table(true);
        assert!(
            md.contains("(1 textures; left out, their recording or optimized synthesis failed: felt-fabric;"),
            "{md}"
        );
        let rows: Vec<&str> = md.lines().filter(|l| l.starts_with("| ") && !l.starts_with("| setting")).collect();
        assert_eq!(
            rows,
            [
                "| default | 5, k_y 1, k_x 10, LM | 1 of 2 | 86 | 3 | 1.00 | 0.500 | 0.500 | 0.50–0.50 | 0.250 | yes |",
                "| slow | 3, k_y 1, k_x 5, ADAM | 2 of 2 | 86 | 3 | 3.00 | 0.500 | 0.750 | 0.75–0.75 | 0.375 |  |",
                "| broken | 5, k_y 1, k_x 1000, LM | 0 of 2 | – | – | – | – | – | – | – | – |",
            ]
        );
        assert!(md.ends_with("The default network is on the Pareto front.\n"), "{md}");
    }

    #[test]
    fn without_times_the_time_is_a_dash_and_the_front_is_left_out() {
        let md = table(false);
        let rows: Vec<&str> = md.lines().filter(|l| l.starts_with("| ")).collect();
        assert!(!rows[0].contains("Pareto") && md.contains("left out (--no-times)"), "{md}");
        assert_eq!(
            rows[1],
            "| default | 5, k_y 1, k_x 10, LM | 1 of 2 | 86 | 3 | – | 0.500 | 0.500 | 0.50–0.50 | 0.250 |"
        );
        assert_eq!(rows[3], "| broken | 5, k_y 1, k_x 1000, LM | 0 of 2 | – | – | – | – | – | – | – |");
        assert!(!md.contains("on the Pareto front"), "{md}");
        // Every row has as many cells as the header.
        let cells = |l: &str| l.matches('|').count();
        assert!(rows.iter().all(|r| cells(r) == cells(rows[0])), "{md}");
    }
}
