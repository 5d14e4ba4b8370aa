//! Force and actuation buffered where every gate is open: what the offline
//! sinks that fit a model (`narx.train`) or score one (`narx.score`) read
//! when the stream ends.

use crate::filters::segment::Gates;
use evflow_engine::ports::InPort;
use evflow_engine::Io;

/// The buffered pairs (the node's inputs force `x` and actuation `y`),
/// kept where the node's gates are open.
pub struct GatedPairs {
    /// The node's force input.
    pub x_port: InPort,
    /// The node's actuation input.
    pub y_port: InPort,
    /// The gate inputs.
    pub gates: Gates,
    /// Force samples kept.
    pub x: Vec<f64>,
    /// Actuation samples kept, one per force sample.
    pub y: Vec<f64>,
    /// Samples of the stream seen, kept or not.
    pub seen: usize,
}

impl GatedPairs {
    /// Nothing buffered yet, for the force and actuation inputs `x_port`
    /// and `y_port`.
    pub fn new(x_port: InPort, y_port: InPort, gates: Gates) -> Self {
        Self { x_port, y_port, gates, x: Vec::new(), y: Vec::new(), seen: 0 }
    }

    /// Room for a long recording before the run (offline only: the
    /// buffers grow with the recording).
    pub fn reserve(&mut self, max_block: usize) {
        self.x.reserve(max_block.max(1 << 16));
        self.y.reserve(max_block.max(1 << 16));
    }

    /// Keeps the block's samples where every gate is open, from stream
    /// sample `skip` on and up to `take` samples in all.
    pub fn push(&mut self, io: &Io<'_>, skip: usize, take: usize) {
        let (x, y) = (io.input(self.x_port), io.input(self.y_port));
        let start = self.seen;
        let (bx, by) = (&mut self.x, &mut self.y);
        self.gates.open_runs(io, |a, b| {
            for i in a..b {
                if start + i >= skip && bx.len() < take {
                    bx.push(x[i]);
                    by.push(y[i]);
                }
            }
        });
        self.seen += io.len();
    }

    /// Back to nothing buffered.
    pub fn clear(&mut self) {
        self.x.clear();
        self.y.clear();
        self.seen = 0;
    }
}
