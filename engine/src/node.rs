//! The node trait and what a node sees while it runs.

use crate::ports::{InPort, OutPort};
use std::path::{Component, Path, PathBuf};

/// An error raised by a node: at construction (bad file, inconsistent
/// parameters), at `prepare`, while processing (I/O) or at `finish`.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum NodeError {
    /// A parameter combination the declaration's limits cannot express.
    #[error("parameter `{param}`: {message}")]
    Param {
        /// The parameter.
        param: String,
        /// What is wrong and what would be right.
        message: String,
    },
    /// A file the node reads or writes.
    #[error("{path}: {message}")]
    File {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// Input data the node cannot use (e.g. a NaN in a recording).
    #[error("{0}")]
    Data(String),
    /// Anything else, explained.
    #[error("{0}")]
    Other(String),
}

impl NodeError {
    /// A parameter error.
    pub fn param(param: &str, message: impl Into<String>) -> Self {
        NodeError::Param { param: param.to_string(), message: message.into() }
    }
    /// A file error.
    pub fn file(path: &Path, message: impl std::fmt::Display) -> Self {
        NodeError::File { path: path.to_path_buf(), message: message.to_string() }
    }
}

/// A live parameter change a node does not take (see [`Node::set`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("this node does not take `{0}` while it runs")]
pub struct Refused(pub &'static str);

/// A live change of one parameter, as [`Node::set`] receives it: the
/// declared name and the value, already checked against the declared limits
/// (flags as 0/1, choices as the index of the word). A node reads it through
/// its parameter handles (`GAIN.changed(&c)` in [`crate::typed_params`]),
/// which give the value typed, so no node matches the name as text.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Change {
    /// The declared name of the parameter.
    pub param: &'static str,
    /// The checked value.
    pub value: f64,
}

impl Change {
    /// The refusal of this change, for a node that does not take it.
    pub fn refused(&self) -> Refused {
        Refused(self.param)
    }
}

/// What a constructor knows besides its parameters.
#[derive(Debug, Clone)]
pub struct BuildContext {
    /// The node's name in the graph.
    pub node: String,
    /// The graph's base rate in Hz.
    pub base_rate: f64,
    /// This node's rate in Hz (see [`crate::spec::RateSpec::Node`]).
    pub rate: f64,
    /// The rate in Hz of each input port, in order (read with [`BuildContext::input_rate`]).
    pub input_rates: Vec<f64>,
    /// The rate in Hz of each output port, in order (read with [`BuildContext::output_rate`]).
    pub output_rates: Vec<f64>,
    /// The folder relative input paths are taken from (the graph file's folder).
    pub base_dir: PathBuf,
    /// The folder relative output paths are written to (the run's output
    /// folder: `--out`, by default the current directory).
    pub out_dir: PathBuf,
    /// The run's seed; nodes that draw random numbers derive their stream from
    /// it and their name, so runs are reproducible.
    pub seed: u64,
    /// The plan is built only to be checked (`evflow check`) and will never
    /// run: a node validates its files as a run would, but need not keep
    /// what only running needs (a recording's samples are checked while
    /// streaming through the file, not loaded).
    pub check_only: bool,
}

impl BuildContext {
    /// The rate in Hz of input `port`.
    pub fn input_rate(&self, port: InPort) -> f64 {
        self.input_rates[port.index()]
    }

    /// The rate in Hz of output `port`.
    pub fn output_rate(&self, port: OutPort) -> f64 {
        self.output_rates[port.index()]
    }

    /// A path parameter resolved against the graph file's folder.
    pub fn path(&self, p: &str) -> PathBuf {
        let p = Path::new(p);
        if p.is_absolute() {
            p.to_path_buf()
        } else {
            self.base_dir.join(p)
        }
    }

    /// A file the run writes, parameter `param` = `p`, resolved inside the
    /// run's output folder — and refused, naming the parameter, when it would
    /// land outside it: an absolute path, a `..` (a sidecar field or a sweep
    /// value spliced into a name can carry one), or a link in the output
    /// folder that points out of it. Choose the folder with `--out`.
    pub fn output_path(&self, param: &str, p: &str) -> Result<PathBuf, NodeError> {
        let shown = crate::diag::cut(p, 120);
        let rel = Path::new(p);
        let escapes = rel.components().any(|c| !matches!(c, Component::Normal(_) | Component::CurDir));
        if p.is_empty() || escapes {
            return Err(NodeError::param(
                param,
                format!(
                    "`{shown}` would be written outside the output folder{}: output paths are relative to it and \
                     hold no `..` (choose the folder with --out)",
                    if self.out_dir.as_os_str().is_empty() {
                        String::new()
                    } else {
                        format!(" {}", self.out_dir.display())
                    }
                ),
            ));
        }
        let full = self.out_dir.join(rel);
        // A link on the way (a folder of the output folder that points out of
        // it): the deepest part of the path that exists must resolve inside.
        if let Ok(root) = std::fs::canonicalize(&self.out_dir) {
            let mut at = full.parent().map(Path::to_path_buf);
            while let Some(a) = at {
                if let Ok(real) = std::fs::canonicalize(&a) {
                    if !real.starts_with(&root) {
                        return Err(NodeError::param(
                            param,
                            format!(
                                "`{shown}` would be written through {}, a link out of the output folder {}",
                                a.display(),
                                root.display()
                            ),
                        ));
                    }
                    break;
                }
                at = a.parent().map(Path::to_path_buf);
            }
            if let Ok(meta) = std::fs::symlink_metadata(&full) {
                if meta.file_type().is_symlink() {
                    return Err(NodeError::param(
                        param,
                        format!("`{shown}` is a link in the output folder; it would be written wherever it points"),
                    ));
                }
            }
        }
        Ok(full)
    }

    /// A path parameter for the node's own working files (e.g. a cache),
    /// resolved against the run's output folder; not checked to stay in it.
    pub fn out_path(&self, p: &str) -> PathBuf {
        let p = Path::new(p);
        if p.is_absolute() {
            p.to_path_buf()
        } else {
            self.out_dir.join(p)
        }
    }

    /// A seed for this node: the run seed mixed with the node's name
    /// (SplitMix64 finalizer over an FNV-1a hash), so two noise sources in
    /// one graph draw different streams.
    pub fn node_seed(&self) -> u64 {
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        for b in self.node.bytes() {
            h ^= b as u64;
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
        let mut z = h ^ self.seed.wrapping_mul(0x9E37_79B9_7F4A_7C15);
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
}

/// How a plan runs. Nodes that drive hardware decide by it, never by the
/// block size, whether to touch their device.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum RunMode {
    /// As fast as the machine allows, over recordings and simulations:
    /// `evflow run`, sweeps, reports, benches and `evflow replay` (at any
    /// block size, one tick included). Hardware nodes never open their
    /// device.
    #[default]
    Offline,
    /// On the live runner's real-time thread, one tick per period (`evflow
    /// live`): hardware nodes open their device.
    Live,
}

/// What `prepare` is told: the largest block the node will be asked for,
/// and whether the plan runs live.
#[derive(Debug, Clone, Copy)]
pub struct PrepareContext {
    /// The largest number of samples per port in one call, at the port's own
    /// rate (index as the node's resolved ports).
    pub max_block: usize,
    /// How the plan runs.
    pub mode: RunMode,
}

/// Results a node reports when the run ends (metrics, files written).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Summary {
    /// Named values with units, e.g. `("E_s", 0.12, "1")`.
    pub values: Vec<(String, f64, String)>,
    /// Free lines for people (e.g. `wrote out.wav (3066 frames)`).
    pub lines: Vec<String>,
}

impl Summary {
    /// Adds a named value.
    pub fn value(mut self, name: &str, v: f64, unit: &str) -> Self {
        self.values.push((name.to_string(), v, unit.to_string()));
        self
    }
    /// A value by name.
    pub fn get(&self, name: &str) -> Option<f64> {
        self.values.iter().find(|(k, _, _)| k == name).map(|(_, v, _)| *v)
    }
    /// Adds a line.
    pub fn line(mut self, l: impl Into<String>) -> Self {
        self.lines.push(l.into());
        self
    }
    /// True when there is nothing to report.
    pub fn is_empty(&self) -> bool {
        self.values.is_empty() && self.lines.is_empty()
    }
}

/// A node's output declared constant for a plan: per output port (in the
/// order of the node's resolved outputs) its value, or `None` for a port
/// that is not constant (a diagnostic output), and why, in words for
/// `evflow check` (see `docs/pruning.md`). The planner replaces the node
/// only when every output some node reads is constant.
#[derive(Debug, Clone, PartialEq)]
pub struct Constant {
    /// The value of each output port at every sample from t = 0 (`None`:
    /// not constant).
    pub outputs: Vec<Option<f64>>,
    /// Why, e.g. `gain = 0`.
    pub reason: String,
}

impl Constant {
    /// Every one of `n` outputs at `value`.
    pub fn all(n: usize, value: f64, reason: impl Into<String>) -> Self {
        Self { outputs: vec![Some(value); n], reason: reason.into() }
    }
    /// The given output values (`None`: that port is not constant).
    pub fn new(outputs: Vec<Option<f64>>, reason: impl Into<String>) -> Self {
        Self { outputs, reason: reason.into() }
    }
}

/// The ports of one node during one call: inputs to read, outputs to fill.
///
/// Each port has its own length for this call (ports at different rates
/// carry different numbers of samples over the same span of base ticks).
pub struct Io<'a> {
    pub(crate) pool: &'a [Vec<f64>],
    pub(crate) in_slots: &'a [usize],
    pub(crate) in_lens: &'a [usize],
    pub(crate) outs: &'a mut [Vec<f64>],
    pub(crate) out_lens: &'a [usize],
    pub(crate) start: u64,
}

impl<'a> Io<'a> {
    /// Builds an `Io` over caller-owned buffers (used by the engine and the
    /// single-node harness). `in_slots[i]` indexes `pool`; `outs[j]` must hold
    /// at least `out_lens[j]` samples.
    pub fn new(
        pool: &'a [Vec<f64>],
        in_slots: &'a [usize],
        in_lens: &'a [usize],
        outs: &'a mut [Vec<f64>],
        out_lens: &'a [usize],
        start: u64,
    ) -> Self {
        Self { pool, in_slots, in_lens, outs, out_lens, start }
    }

    /// Number of input ports.
    pub fn n_inputs(&self) -> usize {
        self.in_slots.len()
    }
    /// Number of output ports.
    pub fn n_outputs(&self) -> usize {
        self.outs.len()
    }
    /// The samples of input `i` for this call.
    #[inline]
    pub fn input(&self, i: InPort) -> &[f64] {
        let i = i.index();
        &self.pool[self.in_slots[i]][..self.in_lens[i]]
    }
    /// The buffer of output `o` for this call, to be filled completely.
    #[inline]
    pub fn output(&mut self, o: OutPort) -> &mut [f64] {
        let o = o.index();
        let n = self.out_lens[o];
        &mut self.outs[o][..n]
    }
    /// Input `i` and output `o` together.
    #[inline]
    pub fn io(&mut self, i: InPort, o: OutPort) -> (&[f64], &mut [f64]) {
        let (i, o) = (i.index(), o.index());
        let n = self.out_lens[o];
        (&self.pool[self.in_slots[i]][..self.in_lens[i]], &mut self.outs[o][..n])
    }
    /// All outputs at once (for nodes writing several ports in one loop).
    #[inline]
    pub fn outputs(&mut self) -> &mut [Vec<f64>] {
        self.outs
    }
    /// Samples in this call at the node's own rate: the length of the first
    /// output, or else of the first input.
    #[inline]
    pub fn len(&self) -> usize {
        self.out_lens.first().or(self.in_lens.first()).copied().unwrap_or(0)
    }
    /// True when this call carries no samples.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// Length of output `o` in this call.
    pub fn output_len(&self, o: OutPort) -> usize {
        self.out_lens[o.index()]
    }
    /// Length of input `i` in this call.
    pub fn input_len(&self, i: InPort) -> usize {
        self.in_lens[i.index()]
    }
    /// Index, at the node's rate, of the first sample of this call since t = 0.
    pub fn start(&self) -> u64 {
        self.start
    }
}

/// A node: a unit of signal processing with a fixed lifecycle.
///
/// * `prepare` may allocate (buffers sized for the largest block).
/// * `process` handles one block; it must not allocate, lock, do blocking I/O
///   (sinks hand I/O to buffered writers sized in `prepare`) or panic. Block
///   processing and one-sample processing (the live tick, a block of one)
///   give identical output — a generic test checks every node type.
/// * `reset` returns the node to t = 0.
pub trait Node: Send {
    /// Sizes internal buffers; may allocate.
    fn prepare(&mut self, _ctx: &PrepareContext) -> Result<(), NodeError> {
        Ok(())
    }

    /// Processes one block (of one sample when live).
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError>;

    /// Returns to the state at t = 0.
    fn reset(&mut self);

    /// For finite sources: samples left at the node's rate. `None` means
    /// endless (the run needs a duration).
    fn remaining(&self) -> Option<u64> {
        None
    }

    /// Called once when a run ends normally: flush, rename, report.
    fn finish(&mut self) -> Result<Summary, NodeError> {
        Ok(Summary::default())
    }

    /// For cycle-breaking nodes inside a feedback cycle: write the outputs of
    /// this block from past inputs only (called early in the step).
    fn emit(&mut self, _io: &mut Io<'_>) -> Result<(), NodeError> {
        Err(NodeError::Other("this node cannot break a feedback cycle".into()))
    }

    /// For cycle-breaking nodes inside a feedback cycle: take this block's
    /// inputs (called at the end of the step).
    fn absorb(&mut self, _io: &mut Io<'_>) -> Result<(), NodeError> {
        Err(NodeError::Other("this node cannot break a feedback cycle".into()))
    }

    /// For cycle-breaking nodes: how many samples of delay they add (the
    /// largest block a cycle through them allows).
    fn cycle_delay(&self) -> usize {
        0
    }

    /// Changes a parameter declared [`crate::spec::ParamSpec::live`] between
    /// two calls of `process` (a live session's parameter queue, or a replay
    /// applying the session's recorded changes at the same tick); see
    /// [`Change`]. Like `process`, it must not allocate, lock or block; the
    /// node moves to the new value without a click (e.g. a ramp). The
    /// default refuses.
    fn set(&mut self, change: Change) -> Result<(), Refused> {
        Err(change.refused())
    }

    /// Asked once, right after the node is built: `Some` when what the node
    /// loaded makes its output a constant whatever its inputs — and whatever
    /// values its live parameters take later (e.g. `mesh.edges` on meshes
    /// without a convex edge sharper than `max_angle`). The planner then
    /// drops the node, holds its outputs at the constant and leaves out
    /// what fed only it (`docs/pruning.md`). Decisions that need only the
    /// parameters and constant inputs belong in the declaration's
    /// [`crate::spec::NodeSpec::fold`], which the planner asks before
    /// anything is built.
    fn constant_output(&self) -> Option<Constant> {
        None
    }

    /// Lines for people about what the node loaded and how it will use it
    /// (e.g. a mesh's bounds, up axis and scale), asked right after the node
    /// is built; `evflow check` prints them (unless `--no-build`).
    fn notes(&self) -> Vec<String> {
        Vec::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ctx(out: &Path) -> BuildContext {
        BuildContext {
            node: "sink".into(),
            base_rate: 1000.0,
            rate: 1000.0,
            input_rates: Vec::new(),
            output_rates: Vec::new(),
            base_dir: out.to_path_buf(),
            out_dir: out.to_path_buf(),
            seed: 1,
            check_only: false,
        }
    }

    #[test]
    fn output_paths_stay_in_the_output_folder_or_are_refused_by_name() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out");
        std::fs::create_dir_all(out.join("cells")).unwrap();
        let c = ctx(&out);
        assert_eq!(c.output_path("path", "cells/u-felt").unwrap(), out.join("cells/u-felt"));
        assert_eq!(c.output_path("path", "./a/b/c").unwrap(), out.join("./a/b/c"), "folders to be made are fine");
        for bad in ["../x", "narx-x/../../../../tmp/ESCAPED/u", "/tmp/abs", "a/../../b", ""] {
            let e = c.output_path("path", bad).unwrap_err().to_string();
            assert!(e.contains("`path`") && e.contains("outside the output folder"), "{bad}: {e}");
        }
        // A link in the output folder that points out of it.
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink(dir.path(), out.join("away")).unwrap();
            let e = c.output_path("path", "away/evil").unwrap_err().to_string();
            assert!(e.contains("a link out of the output folder"), "{e}");
            std::os::unix::fs::symlink(dir.path().join("target"), out.join("file-link")).unwrap();
            let e = c.output_path("path", "file-link").unwrap_err().to_string();
            assert!(e.contains("is a link"), "{e}");
            // A link that stays inside is fine.
            std::os::unix::fs::symlink(out.join("cells"), out.join("inside")).unwrap();
            assert!(c.output_path("path", "inside/u").is_ok());
        }
        // A huge name is cut in the message.
        let long = "x/".repeat(100_000) + "../y";
        let e = c.output_path("path", &long).unwrap_err().to_string();
        assert!(e.len() < 1000, "{} bytes", e.len());
    }
}
