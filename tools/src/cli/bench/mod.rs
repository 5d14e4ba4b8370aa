//! `evflow bench`: benchmarks that report distributions (per-tick p50, p99,
//! max) and ratios against a baseline measured in the same run — the
//! figures of `docs/benchmarks.md`. Throughput of whole graphs is
//! `evflow run`'s timing; micro-benchmarks are criterion benches.

#[cfg(feature = "mesh")]
pub mod mesh;
#[cfg(feature = "mesh")]
pub mod mesh_prune;
#[cfg(feature = "narx")]
pub mod narx;
#[cfg(any(feature = "mesh", feature = "texture"))]
pub mod stats;
#[cfg(feature = "texture")]
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
    /// With --pruning: the per-tick time of the live chain with and without
    /// the planner's constants (mesh.edges held on the Gaussian scenes).
    ///
    /// Example: cargo run --release -p evflow -- bench mesh
    #[cfg(feature = "mesh")]
    Mesh(mesh::Args),
    /// The inverse NARX model (chapter 5): training time of the default
    /// network (15-10-5, LM) on 3066 lab samples, its closed-loop error on a
    /// held-out recording, and closed-loop inference throughput;
    /// `--export DIR` writes the data for bench/narx_peer.py. Build with
    /// --release.
    ///
    /// Example: cargo run --release -p evflow -- bench narx --curve
    #[cfg(feature = "narx")]
    Narx(narx::Args),
    /// The texture chain (chapter 6): per-tick compute time of
    /// graphs/texture-live.toml, the ticks that start a 10 Hz table update
    /// apart from the others. Build with --release.
    ///
    /// Example: cargo run --release -p evflow -- bench texture
    #[cfg(feature = "texture")]
    Texture(texture::Args),
}

#[cfg(any(feature = "mesh", feature = "texture"))]
/// A plan built tick by tick, as the live runner steps it, but offline (a
/// bench never opens a device), without per-node timing.
pub(crate) fn tick_plan(checked: &evflow_engine::Checked) -> anyhow::Result<evflow_engine::Plan> {
    let opts = evflow_engine::PlanOptions { max_block: 1, timing: false, ..Default::default() };
    evflow_engine::Plan::build(checked, &opts).map_err(|e| anyhow::anyhow!("{e}"))
}

/// Runs the chosen benchmark.
pub fn main(a: BenchArgs) -> anyhow::Result<()> {
    match a.which {
        #[cfg(feature = "mesh")]
        Which::Mesh(m) => mesh::main(m),
        #[cfg(feature = "narx")]
        Which::Narx(n) => narx::main(n),
        #[cfg(feature = "texture")]
        Which::Texture(t) => texture::main(t),
    }
}
