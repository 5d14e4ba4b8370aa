//! A live session (`evflow live`): the graph run in real time while its
//! sources, safety guards and taps are recorded to a session folder that
//! `evflow replay` and `evflow studio` read back.
//!
//! * [`session`]: the folder's manifest, event log and recordings;
//! * [`integrity`]: the fingerprints that prove a recorded session whole;
//! * [`recorder`]: the thread that drains the real-time thread's rings;
//! * [`disk`]: the thread that writes and flushes the session's files;
//! * [`steal`]: the time a hypervisor took from this machine.

pub mod disk;
pub mod integrity;
pub mod recorder;
pub mod session;
pub mod steal;
