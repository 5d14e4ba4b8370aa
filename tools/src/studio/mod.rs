//! The studio: a local web page that shows a live session while it runs
//! — traces of the tapped streams, the limiter's state, the timing of the
//! real-time thread, the graph — and steers its live parameters through
//! the session's own command queue (docs/studio.md).
//!
//! Nothing here runs on the real-time thread. The recorder hands every
//! tap sample and event it drains to an [`Ingest`] (the recorder's thread
//! decimates them into a feed), the metrics thread hands it the tick
//! timings; a feeder thread turns what accumulated into one JSON frame
//! every 50 ms and offers it to each browser's bounded queue, where a
//! slow or vanished browser loses frames (counted and shown), never the
//! session a tick.

mod assets;
mod connection;
mod describe;
mod feed;
mod hub;
mod limiter;
mod recorded;
mod scene;
mod server;
mod steer;
mod token;

pub use describe::{default_taps, Description};
pub use feed::Ingest;
pub use recorded::{publish_replay, serve_recorded, RecordedSession, RecordedTap};
pub use scene::scene_json;
pub use server::{Bound, Studio, StudioConfig, StudioError};
