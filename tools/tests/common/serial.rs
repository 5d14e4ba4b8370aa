//! What the serial end-to-end tests share (`serial_e2e.rs`,
//! `firmware_qemu.rs`): a recording's channel, a value from a summary, and
//! how two sample sequences differ.

use evflow_nodes::recording::format::Recording;
use std::path::Path;

/// Channel `ch` of the recording `name` in `dir`.
pub fn channel(dir: &Path, name: &str, ch: &str) -> Vec<f64> {
    let r = Recording::open(&dir.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
    r.channel(ch).unwrap_or_else(|| panic!("{name} has no channel {ch}")).to_vec()
}

/// The number after `key` (and `=`) on the line of `text` that starts with it.
pub fn value(text: &str, key: &str) -> f64 {
    let l = text.lines().find(|l| l.starts_with(key)).unwrap_or_else(|| panic!("no `{key}` in\n{text}"));
    l[key.len()..].trim().trim_start_matches('=').split_whitespace().next().unwrap().parse().unwrap()
}

/// How `have` differs from `want` as sequences: (values of `want` missing
/// from `have`, values of `have` not in `want`), by the longest common
/// subsequence.
pub fn in_order(want: &[i16], have: &[i16]) -> (usize, usize) {
    let mut prev = vec![0u32; have.len() + 1];
    let mut row = vec![0u32; have.len() + 1];
    for w in want {
        for (j, h) in have.iter().enumerate() {
            row[j + 1] = if w == h { prev[j] + 1 } else { prev[j + 1].max(row[j]) };
        }
        std::mem::swap(&mut prev, &mut row);
    }
    let common = prev[have.len()] as usize;
    (want.len() - common, have.len() - common)
}
