//! A live session (`evflow live`): the graph run in real time while its
//! sources, safety guards and taps are recorded to a session folder that
//! `evflow replay` and `evflow studio` read back.
//!
//! [`run()`] runs one as a [`SessionConfig`] says and returns it [`Ended`];
//! [`session`] and [`integrity`] read and check what it recorded; every
//! failure is a [`SessionError`]. Inside:
//! `setup` (the live plan, the folder and its manifest, the pacing),
//! `threads` (Ctrl-C, the console, the metrics display, the recorder's
//! thread), `recorder` (drains the real-time thread's rings), `disk`
//! (writes and flushes the files), `steal` (time the hypervisor took) and
//! `ending` (the record of the end and the report).
//!
//! It is a module of the tools library, not a crate of its own, because
//! only tools' commands use it (`live`, `replay`, `studio`) and it needs
//! tools' studio (served while a session runs) and report tables.

mod config;
mod disk;
mod ending;
pub mod error;
pub mod integrity;
mod recorder;
mod run;
pub mod session;
mod setup;
mod steal;
mod threads;

pub use config::{SessionConfig, DEFAULT_MISS_STREAK};
pub use ending::Ended;
pub use error::SessionError;
pub use run::run;
