//! What `evflow run` prints: sink summaries and run times (the tables are
//! library code, `evflow_tools::batch::tables`).

use evflow_engine::RunReport;
use evflow_tools::batch::tables::{number, unit_suffix, Timings};

/// Prints what the sinks report and, unless `quiet`, the run's times.
pub fn print_report(r: &RunReport, quiet: bool, timings: Timings) {
    let base_rate = r.base_rate;
    if !quiet {
        for l in &r.left_out {
            eprintln!("{l}");
        }
    }
    for (node, s) in &r.summaries {
        for l in &s.lines {
            println!("{node}: {l}");
        }
        for (k, v, unit) in &s.values {
            println!("{node}: {k} = {}{}", number(*v), unit_suffix(unit));
        }
    }
    if quiet || timings == Timings::Leave {
        return;
    }
    let secs = r.elapsed.as_secs_f64();
    let simulated = r.ticks as f64 / base_rate;
    let total: f64 = r.times.iter().map(|t| t.elapsed.as_secs_f64()).sum::<f64>();
    let set_up_and_finish: f64 = r.times.iter().map(|t| (t.setup + t.finish).as_secs_f64()).sum();
    println!(
        "\nran {} ticks ({simulated:.3} s of signal) in {:.3} s: {:.0} ticks/s, {:.0}× real time \
         (the nodes' set-up and finish, writing files included, took {:.3} s more)",
        r.ticks,
        secs,
        r.ticks_per_second(),
        simulated / secs.max(1e-12),
        set_up_and_finish
    );
    println!("{:<16} {:<16} {:>10} {:>10} {:>10} {:>6}", "node", "type", "set-up", "run", "finish", "share");
    for t in &r.times {
        let ms = |d: std::time::Duration| format!("{:.3}ms", d.as_secs_f64() * 1e3);
        println!(
            "{:<16} {:<16} {:>10} {:>10} {:>10} {:>5.1}%",
            t.node,
            t.kind,
            ms(t.setup),
            ms(t.process),
            ms(t.finish),
            100.0 * t.elapsed.as_secs_f64() / total.max(1e-12)
        );
    }
}
