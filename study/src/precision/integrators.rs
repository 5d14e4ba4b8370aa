//! The simulated lab's integrators (issue 3, point 6): the shipped graph
//! `graphs/lab-work-precision.toml` run at every integrator and sub-step
//! count; each of its three lab nodes (display, force sensor, tribometer)
//! is one curve, its error the graph's `error` sink against the same node
//! integrated exactly with many sub-steps, its cost the node's processing
//! time per sample. The reference's own error is measured by running the
//! exact integrator at the reference's sub-steps against a reference 2.4×
//! finer (10 000 sub-steps, the parameter's limit).

use super::curve::{Curve, WorkPoint};
use super::{PrecisionError, Size};
use crate::graphs::{self, seconds_per_tick, value, Sets};
use std::path::Path;

/// The graph, relative to the graphs folder.
pub const GRAPH: &str = "lab-work-precision.toml";

/// The lab nodes the graph compares: (node, its error sink, curve name, computation).
const NODES: [(&str, &str, &str, &str); 3] = [
    ("display", "err_display", "lab-display", "sim.display (force on the finger)"),
    ("sensor", "err_sensor", "lab-forcesensor", "sim.forcesensor"),
    ("tribometer", "err_trib", "lab-tribometer", "sim.tribometer (load)"),
];

/// The shipped default of every lab node (`integrator`, `substeps`).
pub const DEFAULT: (&str, usize) = ("exact", 4);

fn setting(integrator: &str, substeps: usize) -> String {
    format!("{integrator} × {substeps}")
}

fn ref_sets(substeps: usize) -> Sets {
    ["display_ref", "trib_ref", "sensor_ref"]
        .iter()
        .fold(Sets::new(), |s, n| s.int(&format!("{n}.substeps"), substeps as i64))
}

/// The three curves, one per lab node; `graphs` is the shipped graphs' folder.
pub fn curves(graphs: &Path, size: Size) -> Result<Vec<Curve>, PrecisionError> {
    let file = graphs.join(GRAPH);
    let graph = graphs::read(&file)?;
    // CI: 0.6 s of signal (the force sensor sees no force before 0.3 s) against 1024 sub-steps; full: the
    // graph's own length and reference (its 1024 sub-steps left out: the reference, measured 1.3e-4 off
    // on the display, is not 10× better than them).
    let (duration, substeps, reference): (Option<f64>, &[usize], usize) = match size {
        Size::Ci => (Some(0.6), &[1, 4, 16, 64], 1024),
        Size::Full => (None, &[1, 4, 16, 64, 256], 4096),
    };
    // One shared sweep over every setting: the sources and the three references (the same at every
    // setting) run once for all of them, each setting's lab nodes and error sinks once per setting.
    let settings: Vec<(&str, usize)> =
        ["exact", "rk4", "euler"].into_iter().flat_map(|i| substeps.iter().map(move |&s| (i, s))).collect();
    let sweep: Vec<Sets> = settings
        .iter()
        .map(|&(integrator, s)| {
            Sets::new().text("integrator", integrator).int("substeps", s as i64).and(ref_sets(reference))
        })
        .collect();
    let reports = graphs::run_sweep(&graph, &sweep, None, duration)?;
    let mut points: Vec<Vec<WorkPoint>> = vec![Vec::new(); NODES.len()];
    for (&(integrator, s), r) in settings.iter().zip(&reports) {
        for (k, &(node, sink, _, _)) in NODES.iter().enumerate() {
            points[k].push(WorkPoint {
                setting: setting(integrator, s),
                series: integrator.into(),
                error: value(r, &file, sink, "rel_rms")?,
                cost: seconds_per_tick(r, &file, &[node])?,
                // RK4 evaluates four stages per sub-step.
                work: (s * if integrator == "rk4" { 4 } else { 1 }) as f64,
            });
        }
    }
    let sets = Sets::new().text("integrator", "exact").int("substeps", reference as i64).and(ref_sets(10_000));
    let check = graphs::run(&graph, &sets, None, duration)?;
    NODES
        .iter()
        .zip(points)
        .map(|(&(_, sink, name, computation), points)| {
            Ok(Curve {
                name: name.into(),
                computation: computation.into(),
                knob: "integrator × substeps".into(),
                error_unit: "relative RMS".into(),
                cost_unit: "sample (1 kHz)".into(),
                reference: format!("exact × {reference} sub-steps"),
                reference_error: value(&check, &file, sink, "rel_rms")?,
                baseline: None,
                default: setting(DEFAULT.0, DEFAULT.1),
                points,
            })
        })
        .collect()
}
