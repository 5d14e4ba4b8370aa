//! `evflow bench mesh`: the cost of the mesh-gradient chain (dissertation
//! chapter 4) against mesh size — BVH build time, one vertical ray cast
//! through the BVH beside a brute-force loop over every triangle (the
//! baseline, as a ratio, with a check that both find the same hit), and the
//! per-tick compute time of the whole live chain (`graphs/mesh-live.toml`)
//! with p50, p99 and max.

use super::stats::percentile;
use crate::cli::graph_args::load_with;
use anyhow::{anyhow, Result};
use evflow_nodes::mesh::raycast::RayCaster;
use evflow_nodes::mesh::scenes::{scene, Shape};
use evflow_nodes::mesh::trimesh::Mesh;
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `evflow bench mesh`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Approximate triangle counts of the Gaussian scenes to measure.
    #[arg(long, value_delimiter = ',', default_value = "1000,100000,1000000")]
    sizes: Vec<usize>,
    /// Ticks of the live chain timed per size (after 1000 warm-up ticks).
    #[arg(long, default_value_t = 20_000, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1..))]
    ticks: usize,
    /// Ray casts timed per size (the brute-force loop gets fewer on big meshes).
    #[arg(long, default_value_t = 20_000, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1..))]
    queries: usize,
    /// The live chain to time; its `surface` and `edges` nodes get the scene.
    #[arg(long, default_value = "graphs/mesh-live.toml")]
    graph: PathBuf,
    /// Gaussian scene configuration (0B4H … 4B0H).
    #[arg(long, default_value = "2B2H")]
    config: String,
    /// Instead: time the live chain (`--graph`, as shipped) per tick with
    /// and without the planner's constants (`docs/pruning.md`), in
    /// alternating rounds of `--ticks` / 10.
    #[arg(long)]
    pruning: bool,
}

/// One row of the result table.
struct Row {
    resolution: usize,
    triangles: usize,
    build_ms: f64,
    cast_ns: f64,
    brute_ns: f64,
    mismatches: usize,
    tick_us: [f64; 3],
    on_mesh: f64,
}

/// Runs the benchmark and prints a Markdown table.
pub fn main(a: Args) -> Result<()> {
    if a.pruning {
        return super::mesh_prune::compare(&a.graph, &[], a.ticks, 10);
    }
    if a.sizes.is_empty() {
        return Err(anyhow!("--sizes needs at least one triangle count"));
    }
    let probe = scene(Shape::Gaussian, &a.config, 8).map_err(|e| anyhow!("{e}"))?;
    let per_res2 = probe.triangles.len() as f64 / 64.0;
    let mut rows = Vec::new();
    for &size in &a.sizes {
        let resolution = ((size as f64 / per_res2).sqrt().round() as usize).clamp(2, 4096);
        eprintln!("mesh of ~{size} triangles (resolution {resolution}) …");
        rows.push(measure(&a, resolution)?);
    }
    println!("| triangles | resolution | BVH build | ray cast (BVH) | ray cast (brute force) | brute / BVH | hit mismatches | tick p50 | tick p99 | tick max | ticks on the mesh |");
    println!("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for r in &rows {
        println!(
            "| {} | {} | {:.1} ms | {:.0} ns | {:.0} ns | {:.0}× | {} | {:.2} µs | {:.2} µs | {:.1} µs | {:.0} % |",
            r.triangles,
            r.resolution,
            r.build_ms,
            r.cast_ns,
            r.brute_ns,
            r.brute_ns / r.cast_ns,
            r.mismatches,
            r.tick_us[0],
            r.tick_us[1],
            r.tick_us[2],
            r.on_mesh * 100.0
        );
    }
    Ok(())
}

/// Measures one scene resolution.
fn measure(a: &Args, resolution: usize) -> Result<Row> {
    let mesh = scene(Shape::Gaussian, &a.config, resolution).map_err(|e| anyhow!("{e}"))?;
    let triangles = mesh.triangles.len();

    // BVH build: the best of three (the first pays for page faults).
    let mut build_ms = f64::INFINITY;
    let mut rc = None;
    for _ in 0..3 {
        let t = Instant::now();
        let built = RayCaster::new(&mesh);
        build_ms = build_ms.min(t.elapsed().as_secs_f64() * 1e3);
        rc = Some(built);
    }
    let rc = rc.expect("three builds ran");

    let points = touch_points(&mesh, a.queries);
    let cast_ns = time_casts(&points, |x, y| rc.cast(x, y).map(|h| h.tri));
    // Brute force visits every triangle: keep its total near a second.
    let n_brute = (2_000_000_000 / triangles.max(1)).max(20).min(points.len());
    let brute_ns = time_casts(&points[..n_brute], |x, y| rc.cast_brute(x, y).map(|h| h.tri));
    let mismatches = points[..n_brute]
        .iter()
        .filter(|&&(x, y)| rc.cast(x, y).map(|h| h.tri) != rc.cast_brute(x, y).map(|h| h.tri))
        .count();

    let (tick_us, on_mesh) = time_chain(a, resolution)?;
    Ok(Row { resolution, triangles, build_ms, cast_ns, brute_ns, mismatches, tick_us, on_mesh })
}

/// Seeded touch points spread over the mesh's footprint.
fn touch_points(mesh: &Mesh, n: usize) -> Vec<(f64, f64)> {
    let b = mesh.bounds();
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..n.max(1))
        .map(|_| (b.min[0] + next() * (b.max[0] - b.min[0]), b.min[1] + next() * (b.max[1] - b.min[1])))
        .collect()
}

/// Mean nanoseconds per cast over the points (the result is kept alive).
fn time_casts(points: &[(f64, f64)], cast: impl Fn(f64, f64) -> Option<u32>) -> f64 {
    let mut sink = 0u64;
    let t = Instant::now();
    for &(x, y) in points {
        sink = sink.wrapping_add(cast(x, y).map_or(0, u64::from));
    }
    let ns = t.elapsed().as_secs_f64() * 1e9 / points.len() as f64;
    std::hint::black_box(sink);
    ns
}

/// p50, p99 and max per-tick compute time of the live chain, µs, and the
/// fraction of ticks whose touch point was on the mesh (`surface.tri` ≥ 0).
fn time_chain(a: &Args, resolution: usize) -> Result<([f64; 3], f64)> {
    let sets = [format!("surface.resolution={resolution}"), format!("edges.resolution={resolution}")];
    let checked = load_with(&a.graph, &sets)?;
    let mut plan = super::tick_plan(&checked)?;
    for _ in 0..1000 {
        plan.tick().map_err(|e| anyhow!("{e}"))?;
    }
    let surface = plan.index("surface").ok_or_else(|| anyhow!("{}: no node `surface`", a.graph.display()))?;
    let tri = plan
        .output_names(surface)
        .iter()
        .position(|n| n == "tri")
        .ok_or_else(|| anyhow!("{}: node `surface` has no output `tri`", a.graph.display()))?;
    let mut us = Vec::with_capacity(a.ticks);
    let mut hits = 0usize;
    for _ in 0..a.ticks.max(1) {
        let t = Instant::now();
        plan.tick().map_err(|e| anyhow!("{e}"))?;
        us.push(t.elapsed().as_secs_f64() * 1e6);
        hits += usize::from(plan.output_at(surface, tri).first().is_some_and(|&t| t >= 0.0));
    }
    let on_mesh = hits as f64 / us.len() as f64;
    Ok(([percentile(&mut us, 0.5), percentile(&mut us, 0.99), percentile(&mut us, 1.0)], on_mesh))
}
