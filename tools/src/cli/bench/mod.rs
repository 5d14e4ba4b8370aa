//! `evflow bench`: benchmarks that report distributions (per-tick p50, p99,
//! max) and ratios against a baseline measured in the same run — the
//! figures of `docs/benchmarks.md`. Throughput of whole graphs is
//! `evflow run`'s timing; micro-benchmarks are criterion benches.

pub mod mesh;
pub mod narx;
pub mod narx_export;
pub mod stats;
pub mod texture;

/// Arguments of `evflow bench`.
#[derive(clap::Args, Debug)]
pub struct BenchArgs {
    #[command(subcommand)]
    which: Which,
}

#[derive(clap::Subcommand, Debug)]
enum Which {
    /// The mesh-gradient chain (chapter 4): BVH build time, ray casts
    /// through the BVH against a brute-force loop over all triangles, and
    /// the live chain's per-tick compute time, for meshes of 1 k, 100 k and
    /// 1 M triangles. Build with --release.
    ///
    /// Example: cargo run --release -p evflow -- bench mesh
    Mesh(mesh::Args),
    /// The inverse NARX model (chapter 5): training time of the default
    /// network (15-10-5, LM) on 3066 lab samples, its closed-loop error on a
    /// held-out recording, and closed-loop inference throughput;
    /// `--export DIR` writes the data for bench/narx_peer.py. Build with
    /// --release.
    ///
    /// Example: cargo run --release -p evflow -- bench narx --curve
    Narx(narx::Args),
    /// The texture chain (chapter 6): per-tick compute time of
    /// graphs/texture-live.toml, the ticks that start a 10 Hz table update
    /// apart from the others. Build with --release.
    ///
    /// Example: cargo run --release -p evflow -- bench texture
    Texture(texture::Args),
}

/// A plan built tick by tick, as the live runner steps it, but offline (a
/// bench never opens a device), without per-node timing.
pub(crate) fn tick_plan(checked: &evflow_engine::Checked) -> anyhow::Result<evflow_engine::Plan> {
    let opts = evflow_engine::PlanOptions { max_block: 1, timing: false, ..Default::default() };
    evflow_engine::Plan::build(checked, &opts).map_err(|e| anyhow::anyhow!("{e}"))
}

/// Runs the chosen benchmark.
pub fn main(a: BenchArgs) -> anyhow::Result<()> {
    match a.which {
        Which::Mesh(m) => mesh::main(m),
        Which::Narx(n) => narx::main(n),
        Which::Texture(t) => texture::main(t),
    }
}
