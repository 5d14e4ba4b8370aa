//! The runs a graph file makes with the command line's `--set` and
//! `--sweep`: what `evflow check` and `evflow run` both start from, so that
//! they see the same runs.

use evflow_engine::graph::{Axis, Graph};
use evflow_engine::sweep::{check_axes, count, effective_axes, parse_axis, points, Point};
use evflow_engine::{read_graph, Override};
use std::path::Path;

/// Reads `file`, checks the `--sweep` axes against its variables, expands
/// its files axes, refuses more than [`evflow_engine::sweep::MAX_RUNS`]
/// runs, and returns the graph, the axes swept (the graph's, replaced or
/// joined by `--sweep`, less those `--set` fixes) and the runs in sweep
/// order (one run of no values without a sweep). Errors are ready for a
/// person, naming the file or the flag.
pub fn sweep_runs(
    file: &Path,
    overrides: &[Override],
    sweep: &[String],
) -> Result<(Graph, Vec<Axis>, Vec<Point>), String> {
    let axes =
        sweep.iter().map(|s| parse_axis(s).map_err(|e| format!("--sweep {e}"))).collect::<Result<Vec<_>, _>>()?;
    let graph = read_graph(file).map_err(|e| e.to_string())?;
    check_axes(&graph, &axes)?;
    let at = |e: String| format!("{}: {e}", graph.file.display());
    let expanded =
        evflow_engine::sweep_files::expand(&graph, overrides, &evflow_nodes::recording::sweep_fields::sweep_fields)
            .map_err(|e| at(e.to_string()))?;
    count(&expanded, &axes, overrides).map_err(at)?;
    let all = points(&expanded, &axes, overrides);
    let swept = effective_axes(&expanded, &axes, overrides).into_iter().cloned().collect();
    Ok((graph, swept, all))
}
