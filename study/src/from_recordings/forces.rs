//! A texture recording → its `forces-SAMPLE` cell: the force resampled to
//! 1 kHz and high-passed at 10 Hz (graphs/forces-recordings.toml), cut to
//! the recording's longest forward constant-speed stretch.
//!
//! **Stroke directions.** The cell is one stretch of one forward pass
//! (velocity > 0), the first of the longest: one contiguous stretch of
//! texture, as the simulated lab's library holds (`evflow library build`
//! records one forward pass). Backward passes are left out: the forward
//! models are identified on forward passes (graphs/forward-build-recordings.toml),
//! so the forces and the models describe one direction; the sensor's bias
//! and the friction's sign change at every reversal, and a joint between
//! two stretches inside the loop `interp` plays would be a seam. The live
//! chains play the cell in both directions (`playback` reads it backwards
//! when the finger goes back), so nothing is missing at play time.

use super::survey::{forward_gate, longest_run, Texture, CHAIN_RATE};
use crate::cells::write_force_samples;
use crate::graphs::{run_graph, Sets};
use crate::recordings::recording_in;
use crate::StudyError;
use evflow_nodes::texture::grid::{offset_ratio, OFFSET_RATIO_MAX};
use std::path::{Path, PathBuf};

/// Makes `t`'s cell in `grid` (`grid/u-SAMPLE-TAG`), running the graph in
/// `work` (a scratch folder); returns the cell's path and its length in s.
pub fn cell(graphs: &Path, t: &Texture, work: &Path, grid: &Path) -> Result<(PathBuf, f64), StudyError> {
    let sets = Sets::new()
        .path("recording", &t.path)
        .num("rate", t.rate)
        .num("load_g", t.cond.mass)
        .num("velocity_cm_s", t.cond.speed)
        .text("material", &t.material);
    run_graph(&graphs.join("forces-recordings.toml"), &sets, work)?;
    let rec = recording_in(work)?;
    let (force, velocity) = match (rec.channel("force"), rec.channel("velocity")) {
        (Some(f), Some(v)) => (f, v),
        _ => return Err(StudyError::Recording(format!("{}: the graph wrote no force or velocity", work.display()))),
    };
    let run = longest_run(&forward_gate(velocity, t.cond.speed, CHAIN_RATE)).ok_or_else(|| {
        StudyError::Recording(format!(
            "{}: no forward constant-speed stretch left after resampling to 1 kHz",
            t.path.display()
        ))
    })?;
    let kept = &force[run.clone()];
    // The library must pass its own guard (interp `expect = "force"`).
    let ratio = offset_ratio(kept, CHAIN_RATE);
    if ratio > OFFSET_RATIO_MAX {
        return Err(StudyError::Recording(format!(
            "{}: the high-passed force still carries an offset ({ratio:.2} > {OFFSET_RATIO_MAX}): a drift slower than \
             the stretch? Look at the recording's force over its forward pass",
            t.path.display()
        )));
    }
    let name = t.path.file_stem().unwrap_or_default().to_string_lossy();
    let source = format!(
        "evflow library from-recordings: {name}, the force resampled to 1 kHz, high-passed at 10 Hz, over its longest \
         forward constant-speed stretch"
    );
    let path = write_force_samples(kept, CHAIN_RATE, grid, &t.material, &t.cond, source, &t.path)?;
    Ok((path, run.len() as f64 / CHAIN_RATE))
}
