//! Rate nodes — the only nodes whose output runs at another rate than
//! their input: `hold` (zero-order hold to another rate), `decimate`
//! (integer step down with a linear-phase anti-aliasing filter) and
//! `resample` (any ratio, through rubato, with a fixed latency); the exact
//! cross-rate sample ordering they share ([`clock`]), and the numerics
//! behind them ([`kaiser`], [`decimator`], [`resampler`]).

pub mod clock;
pub mod decimate;
pub mod decimator;
pub mod hold;
pub mod kaiser;
pub mod resample;
pub mod resampler;

use evflow_engine::NodeSpec;

/// The node types of this family.
pub static SPECS: &[&NodeSpec] = &[&hold::SPEC, &decimate::SPEC, &resample::SPEC];

/// Test helpers shared by the rate nodes' tests.
#[cfg(test)]
pub(crate) mod testing {
    use evflow_engine::harness::Single;
    use evflow_engine::NodeSpec;

    /// Runs the node `spec` with `params` on `x` at `fs_in` Hz in a graph of
    /// base rate `base`, for `ticks` base ticks in blocks of `block` ticks;
    /// returns its output `out`.
    pub fn run_node(
        spec: &'static NodeSpec,
        params: &str,
        x: &[f64],
        fs_in: f64,
        base: f64,
        ticks: u64,
        block: usize,
    ) -> Result<Vec<f64>, String> {
        Single::new(spec, params)
            .input("in", x.to_vec(), fs_in)
            .output("out")
            .base_rate(base)
            .ticks(ticks)
            .block(block)
            .run()
            .map(|mut o| o.remove(0))
    }

    /// `len` samples uniform in [−0.5, 0.5) from the lab's generator.
    pub fn noise(len: usize, seed: u64) -> Vec<f64> {
        let mut r = crate::rng::Rng::new(seed);
        (0..len).map(|_| r.uniform() - 0.5).collect()
    }
}
