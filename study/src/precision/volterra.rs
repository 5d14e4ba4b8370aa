//! The forward Volterra model's memory (`synth.train`'s `memory`): models
//! identified ([`evflow_nodes::synth::volterra_fit::fit`], as the node
//! fits) on a random binary actuation driven through the noiseless
//! simulated lab (display, force sensor, 10 Hz high-pass: the system the
//! model stands for, [`evflow_nodes::narx::labdata::Lab`]), scored on the
//! held-out last 15 % against that lab's force; the cost is the model's
//! evaluation per sample (`Volterra::eval`, what the optimized synthesis
//! runs many times per iteration).
//!
//! This is a model-structure error, not a discretization: it falls with the
//! memory until the second-order structure, not the memory, limits it.

use super::curve::{Curve, WorkPoint};
use super::{time_best, PrecisionError, Size};
use evflow_nodes::narx::labdata::{rbs, Lab};
use evflow_nodes::synth::volterra_fit::{fit, FitConfig};

/// `synth.train`'s default memory, samples.
pub const DEFAULT_MEMORY: usize = 20;

/// The curve.
pub fn curve(size: Size) -> Result<Curve, PrecisionError> {
    let (n, memories): (usize, &[usize]) = match size {
        Size::Ci => (5000, &[1, 4, 10, 20]),
        Size::Full => (20_000, &[1, 2, 4, 8, 12, 16, 20, 28, 40]),
    };
    let u = rbs(n, 5);
    let y = Lab { noise: 0.0, ..Lab::default() }.force(&u);
    let keep = vec![true; n];
    let mut points = Vec::new();
    for &m in memories {
        let f = fit(&u, &y, &keep, &FitConfig { memory: m, ..FitConfig::default() })
            .map_err(|e| PrecisionError::Method(format!("volterra fit, memory {m}: {e}")))?;
        let mut out = vec![0.0; n];
        let seconds = time_best(size.repeats(), || f.model.eval(&u, &mut out));
        points.push(WorkPoint {
            setting: format!("memory {m}"),
            series: "second-order Volterra".into(),
            error: f
                .scores
                .validation_rel_rms
                .ok_or_else(|| PrecisionError::Method(format!("volterra fit, memory {m}: no held-out rows")))?,
            cost: seconds / n as f64,
            work: f.model.n_params() as f64,
        });
    }
    Ok(Curve {
        name: "volterra-memory".into(),
        computation: "forward Volterra model (synth.train)".into(),
        knob: "memory (samples at 1 kHz)".into(),
        error_unit: "relative RMS, held-out 15 %".into(),
        cost_unit: "sample evaluated".into(),
        reference: "the noiseless simulated lab it models".into(),
        reference_error: 0.0,
        baseline: None,
        default: format!("memory {DEFAULT_MEMORY}"),
        points,
    })
}
