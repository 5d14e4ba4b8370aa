//! The port parameters `serial.in` and `serial.out` share, and what a node
//! does with them when its plan is prepared: open the link in a live run,
//! stay off the device otherwise.

use evflow_engine::typed_params::{Float, Int, Text};
use evflow_engine::{NodeError, ParamSpec, Params};
use std::time::Duration;

use super::link::LinkConfig;

/// `port`: the serial device, empty for none.
const PORT: Text = Text::new(
    "port",
    "",
    "serial device (e.g. /dev/ttyACM0, the pty `evflow devsim` prints, COM3); empty = no device: the node runs \
     unconnected",
);
/// `baud`: the baud rate.
const BAUD: Int = Int::new("baud", 50, 12_000_000, 921_600, "Bd", "baud rate (ignored by USB CDC devices and ptys)");
/// `wait`: how long a live start waits for the device's HELLO.
const WAIT: Float = Float::new(
    "wait",
    0.0,
    600.0,
    2.0,
    "s",
    "how long starting a live run waits for the device's HELLO before it fails (0: start unconnected)",
);
/// `timeout`: silence after which the link is down.
const TIMEOUT: Float = Float::new("timeout", 0.01, 60.0, 0.25, "s", "no valid frame for this long: the link is down");
/// `retry`: how often a lost port is reopened.
const RETRY: Float = Float::new("retry", 0.01, 600.0, 0.5, "s", "after a disconnect, reopen the port this often");

/// The shared parameters.
pub const PORT_PARAMS: [ParamSpec; 5] = [PORT.spec(), BAUD.spec(), WAIT.spec(), TIMEOUT.spec(), RETRY.spec()];

/// Why a node with a port does not use it in an offline run or a replay.
pub const OFFLINE: &str = "offline run: the port was not opened; serial nodes talk to the device only in live \
     runs (`evflow live`), never in `evflow run`, a sweep, a report or `evflow replay`, whatever the block size";

/// The text of a node without a port.
pub const NO_PORT: &str = "no port given (port = \"\"): ran without a device";

/// The port settings of a node, `None` when `port` is empty.
pub fn link_config(p: &Params) -> Option<LinkConfig> {
    let port = PORT.get(p).trim();
    (!port.is_empty()).then(|| LinkConfig {
        port: port.to_string(),
        baud: BAUD.get(p).clamp(1, u32::MAX as i64) as u32,
        wait: Duration::from_secs_f64(WAIT.get(p)),
        timeout: Duration::from_secs_f64(TIMEOUT.get(p)),
        retry: Duration::from_secs_f64(RETRY.get(p)),
    })
}

/// A node rate as the u16 of a HELLO.
pub fn rate_hz(node: &str, rate: f64) -> Result<u16, NodeError> {
    if !(1.0..=65535.0).contains(&rate.round()) {
        return Err(NodeError::Other(format!("`{node}`: rate {rate} Hz does not fit the protocol's u16 field")));
    }
    Ok(rate.round() as u16)
}
