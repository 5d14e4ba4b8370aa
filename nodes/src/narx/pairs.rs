//! Force and actuation buffered where every gate is open: what the offline
//! sinks that fit a model (`narx.train`) or score one (`narx.score`) read
//! when the stream ends.

use crate::filters::segment::Gates;
use evflow_engine::Io;

/// The buffered pairs (inputs 0 and 1 of the node: force `x`, actuation
/// `y`), the node's gates after them.
pub struct GatedPairs {
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
    /// Nothing buffered yet.
    pub fn new(gates: Gates) -> Self {
        Self { gates, x: Vec::new(), y: Vec::new(), seen: 0 }
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
        let (x, y) = (io.input(0), io.input(1));
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
