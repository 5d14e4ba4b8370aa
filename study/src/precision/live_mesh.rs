//! The live mesh chain end to end: graphs/mesh-live.toml (the virtual user
//! stroking the Gaussian scene 2B2H: touch point → `mesh.gradient` →
//! `mesh.edges` → grain → gain → limit → display) over the mesh resolution.
//! A probe is added to the shipped graph: the same `mesh.gradient` on a
//! much finer mesh of the same scene, fed the same touch points, and an
//! `error` sink comparing the two F^sq streams tick by tick. The error is
//! that relative RMS; the cost is the chain's CPU per tick (gradient,
//! edges, grain, gain, limit; the user, the display and the probe left
//! out).
//!
//! The reference's own error is measured the same way: the reference mesh
//! against one twice as fine. The reference shares the chain's slope
//! estimate (the secant over the finger's last step), so the error is the
//! mesh's alone; the secant's own error against the smooth surface is in
//! the `mesh-gradient` curve.

use super::curve::{Curve, WorkPoint};
use super::{PrecisionError, Size};
use crate::graphs::{self, seconds_per_tick, value, Sets};
use evflow_engine::{Graph, Role, Value};
use std::path::Path;

/// The graph, relative to the graphs folder.
pub const GRAPH: &str = "mesh-live.toml";
/// The generated scene's default `resolution` (cells per 6 cm object side).
pub const DEFAULT_RESOLUTION: usize = 48;
/// The scene stroked (the graph's default `scene`).
pub const SCENE: &str = "2B2H";

/// The shipped graph with the probe: `reference` (a finer mesh) and `err`.
fn probed(file: &Path) -> Result<Graph, PrecisionError> {
    let mut g = graphs::read(file)?;
    let text = |s: &str| Value::Text(s.into());
    g.add_node(
        "reference",
        "mesh.gradient",
        &[
            ("shape", text("$shape")),
            ("scenes", text("$scenes")),
            ("scene", text("$scene")),
            ("range", text("fixed")),
            ("cache", text("none")),
        ],
    );
    g.add_node("err", "error", &[]);
    for c in [
        "finger.x -> reference.x",
        "finger.y -> reference.y",
        "surface.fsq -> err.test",
        "reference.fsq -> err.reference",
    ] {
        g.connect(c).map_err(|e| PrecisionError::Method(format!("{GRAPH} probe: {e}")))?;
    }
    Ok(g)
}

/// The chain whose CPU per tick is the cost: the safety limiter and every
/// node that feeds it, but the touch source (in mesh-live.toml: `surface`,
/// `edges`, `grain`, `gain`, `limit`; the user, the display, the graph's
/// statistics and the probe are not upstream of the limiter), in the
/// graph's order.
pub fn chain(file: &Path, graph: &Graph) -> Result<Vec<String>, PrecisionError> {
    let checked = evflow_engine::check(graph, &evflow_nodes::registry(), &[])
        .map_err(|e| graphs::GraphError { file: file.to_path_buf(), message: e.to_string() })?;
    let mut feeds: Vec<bool> = checked.nodes.iter().map(|n| n.spec.is_guard()).collect();
    let mut grew = true;
    while grew {
        grew = false;
        for e in &checked.edges {
            if feeds[e.to.0] && !feeds[e.from.0] {
                feeds[e.from.0] = true;
                grew = true;
            }
        }
    }
    let kept = checked.nodes.iter().zip(feeds).filter(|(n, f)| *f && n.spec.role != Role::Source);
    Ok(kept.map(|(n, _)| n.name.clone()).collect())
}

/// The values of one run: the chain at `cells`, the reference at `reference` cells.
fn sets(cells: usize, reference: usize) -> Sets {
    Sets::new()
        .words("scenes", &[SCENE])
        .int("scene", 0)
        .int("surface.resolution", cells as i64)
        .int("edges.resolution", cells as i64)
        .text("surface.cache", "none")
        .int("reference.resolution", reference as i64)
}

/// The curve.
pub fn curve(graphs: &Path, size: Size) -> Result<Curve, PrecisionError> {
    let file = graphs.join(GRAPH);
    let graph = probed(&file)?;
    let chain = chain(&file, &graph)?;
    let chain: Vec<&str> = chain.iter().map(String::as_str).collect();
    // The full size stops at 96 cells: measured, 128 cells is 1.7e-3 off the 512-cell reference,
    // whose own error (3.0e-4 against 1024 cells) is not 10× smaller.
    let (seconds, cells, reference): (f64, &[usize], usize) = match size {
        Size::Ci => (2.0, &[8, 16, DEFAULT_RESOLUTION], 192),
        Size::Full => (10.0, &[4, 8, 16, 32, DEFAULT_RESOLUTION, 64, 96], 512),
    };
    // The reference mesh (and its BVH) is the same in every run and in the check: built once, kept
    // until the curve is done.
    let _keep = evflow_nodes::mesh::shared::Keep::new();
    let mut points = Vec::new();
    for &c in cells {
        let r = graphs::run(&graph, &sets(c, reference), None, Some(seconds))?;
        points.push(WorkPoint {
            setting: format!("{c} cells"),
            series: "secant slope".into(),
            error: value(&r, &file, "err", "rel_rms")?,
            cost: seconds_per_tick(&r, &file, &chain)?,
            // A BVH ray cast visits about log₂(triangles) nodes; the scene has 4 objects of 2·c² triangles.
            work: ((8 * c * c) as f64).log2(),
        });
    }
    // The check needs only the two F^sq streams: without the graph's own sinks, the rest of the chain
    // is not built, and the chain's mesh (now the reference's) skips its calibration scan, which
    // F^sq does not depend on.
    let check_graph = graphs::without(graphs::without(graph, "force_stats"), "intensity_stats");
    let check_sets = sets(reference, 2 * reference).text("surface.range", "fixed");
    let check = graphs::run(&check_graph, &check_sets, None, Some(seconds))?;
    Ok(Curve {
        name: "live-mesh".into(),
        computation: format!("live mesh chain (mesh-live.toml, {SCENE}, virtual user, {seconds} s)"),
        knob: "cells per 6 cm object side".into(),
        error_unit: "relative RMS of F^sq".into(),
        cost_unit: "tick (1 kHz)".into(),
        reference: format!(
            "mesh.gradient on {reference} cells, same touch points (its error against {})",
            2 * reference
        ),
        reference_error: value(&check, &file, "err", "rel_rms")?,
        baseline: None,
        default: format!("{DEFAULT_RESOLUTION} cells"),
        points,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[cfg(feature = "lab")]
    #[test]
    fn the_chain_is_what_feeds_the_limiter_but_the_touch_source() {
        let file = Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap().join("graphs").join(GRAPH);
        let chain = chain(&file, &probed(&file).unwrap()).unwrap();
        // The list this study measured before it was derived (issue 35).
        assert_eq!(chain, ["surface", "edges", "grain", "gain", "limit"]);
    }
}
