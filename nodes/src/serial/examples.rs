//! The worked examples of `docs/serial-protocol.md`: one frame of each type.
//! A test checks that the bytes printed in the document are what the
//! encoder writes.

use super::message::{caps, faults, Hello, Message, Role, Touch, VERSION};

/// `(name, sequence number, message)` of each worked example, in the
/// document's order.
pub fn examples() -> Vec<(&'static str, u16, Message)> {
    vec![
        (
            "hello-host",
            0,
            Message::Hello(Hello {
                version: VERSION,
                role: Role::Host,
                caps: caps::ACTUATION,
                actuation_hz: 1000,
                touch_hz: 40,
            }),
        ),
        (
            "hello-device",
            0,
            Message::Hello(Hello {
                version: VERSION,
                role: Role::Device,
                caps: caps::TOUCH | caps::FORCE,
                actuation_hz: 1000,
                touch_hz: 40,
            }),
        ),
        ("actuation", 1, Message::Actuation(16384)),
        ("touch", 2, Message::Touch(Touch { x: 0.04, y: 0.03, load: 0.8, flags: 1 })),
        ("force", 3, Message::Force(0.25)),
        ("heartbeat", 4, Message::Heartbeat { faults: 0, uptime_ms: 1500 }),
        ("fault", 5, Message::Fault { faults: faults::OVERCURRENT }),
    ]
}

/// The frame bytes of a message as spaced upper-case hex (`A5 5A 02 …`).
pub fn hex(m: &Message, seq: u16) -> String {
    let (b, n) = m.to_bytes(seq);
    b[..n].iter().map(|x| format!("{x:02X}")).collect::<Vec<_>>().join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The hex lines of the code block after `<!-- frame: NAME -->`.
    fn doc_block(doc: &str, name: &str) -> Option<String> {
        let marker = format!("<!-- frame: {name} -->");
        let rest = &doc[doc.find(&marker)? + marker.len()..];
        let body = &rest[rest.find("```")? + 3..];
        let body = &body[body.find('\n')? + 1..];
        let body = &body[..body.find("```")?];
        Some(body.split_whitespace().collect::<Vec<_>>().join(" "))
    }

    #[test]
    fn the_documents_example_bytes_are_what_the_encoder_writes() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/serial-protocol.md");
        let doc = std::fs::read_to_string(path).expect("docs/serial-protocol.md");
        for (name, seq, m) in examples() {
            let have = doc_block(&doc, name).unwrap_or_else(|| panic!("the document has no example `{name}`"));
            assert_eq!(have, hex(&m, seq), "example `{name}` in docs/serial-protocol.md");
        }
        assert!(doc.contains("0x29B1"), "the document gives the CRC check value");
    }
}
