//! Live synthesis (`synth.live`): the actuation computed at every tick for
//! the texture force the finger is about to meet, through the display's
//! forward models blended at the finger's condition, on a receding horizon.
//!
//! * [`envelope`] — the forward model seen through a Nyquist-rate carrier,
//!   and the grid of models blended at a (load, speed);
//! * [`horizon`] — one tick's bounded optimization, warm-started;
//! * [`window_min`] — the running minimum that sets the carrier's offset;
//! * [`tracking_highpass`] — the target's high-pass whose cut-off follows
//!   the finger's speed;
//! * [`node`] — the node.

pub mod envelope;
pub mod horizon;
pub mod node;
pub mod tracking_highpass;
pub mod window_min;
