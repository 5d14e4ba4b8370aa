//! Ports: their declaration ([`PortSpec`], part of a node's
//! [`crate::spec::NodeSpec`]) and named port constants. A node names its ports once, in its `PORTS` list,
//! and reads them through constants found in that list by name **at compile
//! time** — a misspelt name, or an input asked for as an output, does not
//! compile. [`crate::Io`] takes these constants instead of bare indices.
//!
//! ```
//! use evflow_engine::ports::{InPort, OutPort};
//! use evflow_engine::PortSpec;
//!
//! const PORTS: &[PortSpec] = &[
//!     PortSpec::input("x", "1", "signal"),
//!     PortSpec::output("y", "1", "result"),
//!     PortSpec::input("gain", "1", "multiplier"),
//! ];
//! const X: InPort = InPort::named(PORTS, "x");
//! const GAIN: InPort = InPort::named(PORTS, "gain");
//! const Y: OutPort = OutPort::named(PORTS, "y");
//! assert_eq!((X.index(), GAIN.index(), Y.index()), (0, 1, 0));
//! ```
//!
//! A name that is not an input of the list is a compile error:
//!
//! ```compile_fail
//! use evflow_engine::ports::InPort;
//! use evflow_engine::PortSpec;
//! const PORTS: &[PortSpec] = &[PortSpec::input("x", "1", "signal"), PortSpec::output("y", "1", "result")];
//! const Y: InPort = InPort::named(PORTS, "y");
//! let _ = Y.index();
//! ```
//!
//! A port repeated per entry of a list parameter ([`PortSpec::per`]) is
//! found by its declared name and gives the first of its ports; the k-th is
//! [`InPort::nth`]. Such a port must be the last of its direction, which
//! `named` checks.

/// Which way samples flow through a port.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// The node reads samples from this port.
    In,
    /// The node writes samples to this port.
    Out,
}

/// The sample rate a port runs at.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RateSpec {
    /// The node's own rate: the rate of its `Node` inputs, or for a node
    /// without such inputs the value of its rate parameter
    /// ([`crate::spec::NodeSpec::rate_param`]), or else the graph's base rate.
    Node,
    /// An input that accepts any rate (used by rate-changing nodes).
    Any,
    /// The rate in Hz given by the named parameter (e.g. a resampler's output).
    Param(&'static str),
}

/// The unit of an output that carries its input's unit (a filter, a rate
/// change, a gain): `check` shows the unit of what feeds the node's first
/// input in its place — or the node's text parameter [`UNIT_PARAM`], when
/// it has one and it is set (a gain that converts, N → g).
pub const SAME_AS_INPUT: &str = "as its input";

/// The text parameter that names the unit of a [`SAME_AS_INPUT`] output
/// where the node changes it.
pub const UNIT_PARAM: &str = "unit";

/// One port of a node type.
#[derive(Debug, Clone, Copy)]
pub struct PortSpec {
    /// Port name, as written in connections (`node.port`).
    pub name: &'static str,
    /// Input or output.
    pub dir: Direction,
    /// The port's rate.
    pub rate: RateSpec,
    /// Unit of the samples (e.g. `N`, `1` for normalized, `m/s`).
    pub unit: &'static str,
    /// One-line description.
    pub doc: &'static str,
    /// When set, this declaration stands for several ports whose names are
    /// the entries of the named text-list parameter (e.g. one port per
    /// channel of a recording).
    pub multi: Option<&'static str>,
    /// True when the studio shows it by default (see [`PortSpec::view`]).
    pub view: bool,
}

impl PortSpec {
    /// An input port at the node's rate.
    pub const fn input(name: &'static str, unit: &'static str, doc: &'static str) -> Self {
        Self { name, dir: Direction::In, rate: RateSpec::Node, unit, doc, multi: None, view: false }
    }
    /// An output port at the node's rate.
    pub const fn output(name: &'static str, unit: &'static str, doc: &'static str) -> Self {
        Self { name, dir: Direction::Out, rate: RateSpec::Node, unit, doc, multi: None, view: false }
    }
    /// The same port with another rate.
    pub const fn at(mut self, rate: RateSpec) -> Self {
        self.rate = rate;
        self
    }
    /// The same port repeated once per entry of a text-list parameter.
    pub const fn per(mut self, list_param: &'static str) -> Self {
        self.multi = Some(list_param);
        self
    }
    /// The same port, shown by default in the studio (`evflow live
    /// --studio`, `evflow studio`): an output's samples, or for an input,
    /// the stream that feeds it (e.g. what reaches the safety limiter).
    /// A repeated port ([`PortSpec::per`]) is never shown by default.
    pub const fn view(mut self) -> Self {
        self.view = true;
        self
    }
}

/// An input port of a node: its index among the node's inputs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct InPort(usize);

/// An output port of a node: its index among the node's outputs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OutPort(usize);

/// The two port constants differ only in the direction they look up.
macro_rules! port_constant {
    ($($port:ident: $dir:ident, $what:literal;)*) => {$(
        impl $port {
            #[doc = concat!("The ", $what, " called `name` in `ports` (the node's declaration). Fails to")]
            /// compile (in a `const`) when `ports` has no such port of that
            /// direction, or when a repeated port of that direction comes before it.
            pub const fn named(ports: &[PortSpec], name: &str) -> Self {
                Self(find(ports, name, Direction::$dir))
            }

            #[doc = concat!("The `k`-th ", $what, " counted from 0, for a node whose ", $what, "s are")]
            /// a list (e.g. `add`'s operands) or the ports after the first of
            /// a repeated port.
            pub const fn at(k: usize) -> Self {
                Self(k)
            }

            /// The `k`-th of a repeated port that starts here.
            pub const fn nth(self, k: usize) -> Self {
                Self(self.0 + k)
            }

            #[doc = concat!("Its index among the node's ", $what, "s.")]
            pub const fn index(self) -> usize {
                self.0
            }
        }
    )*};
}

port_constant! {
    InPort: In, "input";
    OutPort: Out, "output";
}

/// Index of the port `name` among the ports of direction `dir`.
const fn find(ports: &[PortSpec], name: &str, dir: Direction) -> usize {
    let mut i = 0;
    let mut index = 0;
    let mut after_repeated = false;
    while i < ports.len() {
        let p = &ports[i];
        let same_dir = matches!((p.dir, dir), (Direction::In, Direction::In) | (Direction::Out, Direction::Out));
        if same_dir {
            if after_repeated {
                panic!("a port repeated per list entry must be the last of its direction");
            }
            if same(p.name, name) {
                return index;
            }
            after_repeated = p.multi.is_some();
            index += 1;
        }
        i += 1;
    }
    panic!("no port of this name and direction in the node's declaration")
}

/// Byte equality of two names, usable in `const`.
const fn same(a: &str, b: &str) -> bool {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    if a.len() != b.len() {
        return false;
    }
    let mut i = 0;
    while i < a.len() {
        if a[i] != b[i] {
            return false;
        }
        i += 1;
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    const PORTS: &[PortSpec] = &[
        PortSpec::input("a", "1", ""),
        PortSpec::output("y", "1", ""),
        PortSpec::input("b", "1", ""),
        PortSpec::output("z", "1", ""),
        PortSpec::input("gate", "1", "").per("gates"),
    ];

    #[test]
    fn ports_are_counted_within_their_direction() {
        assert_eq!(InPort::named(PORTS, "a").index(), 0);
        assert_eq!(InPort::named(PORTS, "b").index(), 1);
        assert_eq!(InPort::named(PORTS, "gate").nth(2).index(), 4);
        assert_eq!(OutPort::named(PORTS, "y").index(), 0);
        assert_eq!(OutPort::named(PORTS, "z").index(), 1);
    }

    #[test]
    #[should_panic(expected = "no port of this name")]
    fn an_output_is_not_an_input() {
        InPort::named(PORTS, "y");
    }

    #[test]
    #[should_panic(expected = "no port of this name")]
    fn a_misspelt_name_is_refused() {
        OutPort::named(PORTS, "Y");
    }

    #[test]
    #[should_panic(expected = "must be the last")]
    fn nothing_follows_a_repeated_port() {
        const BAD: &[PortSpec] = &[PortSpec::input("gate", "1", "").per("gates"), PortSpec::input("x", "1", "")];
        InPort::named(BAD, "x");
    }
}
