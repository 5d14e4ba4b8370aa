//! The one-time token a studio served beyond loopback requires: 128 bits
//! from the system's random source, compared without early exit.

use std::io::Read;

/// A new token, 32 hex digits.
pub(crate) fn new_token() -> std::io::Result<String> {
    let mut b = [0u8; 16];
    std::fs::File::open("/dev/urandom")?.read_exact(&mut b)?;
    Ok(b.iter().map(|x| format!("{x:02x}")).collect())
}

/// True when `given` equals `token` (time independent of where they differ).
pub(crate) fn matches(token: &str, given: &str) -> bool {
    token.len() == given.len() && token.bytes().zip(given.bytes()).fold(0u8, |acc, (a, b)| acc | (a ^ b)) == 0
}

/// The value of `key` in a request target's query (`/ws?token=…`).
pub(crate) fn query<'a>(target: &'a str, key: &str) -> Option<&'a str> {
    let q = target.split_once('?')?.1;
    q.split('&').find_map(|kv| kv.split_once('=').filter(|(k, _)| *k == key).map(|(_, v)| v))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tokens_are_random_and_checked_exactly() {
        let (a, b) = (new_token().unwrap(), new_token().unwrap());
        assert_eq!(a.len(), 32);
        assert_ne!(a, b);
        assert!(matches(&a, &a.clone()));
        assert!(!matches(&a, &b));
        assert!(!matches(&a, &a[..31]));
        assert!(!matches(&a, ""));
    }

    #[test]
    fn query_values() {
        assert_eq!(query("/ws?token=abc&x=1", "token"), Some("abc"));
        assert_eq!(query("/?x=1&token=z", "token"), Some("z"));
        assert_eq!(query("/", "token"), None);
        assert_eq!(query("/?tokenx=1", "token"), None);
    }
}
