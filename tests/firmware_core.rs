//! The reference firmware's portable core (`firmware/core`, C11) built with
//! the host's C compiler and run through its unit tests
//! (`firmware/test/test_core.c`): every frame type, the CRC check value,
//! the worked examples of docs/serial-protocol.md byte for byte, resync
//! after garbage and a damaged length byte, wrapping sequence numbers, the
//! FIFO, the streaming cadence and the watchdog's ramp. The same as
//! `make -C firmware host-test`, without needing `make`; with the address
//! and undefined-behaviour sanitizers where the compiler has them.

use std::path::Path;
use std::process::Command;

/// The C compiler: `$CC`, else `cc` (a Rust toolchain links with it).
fn cc() -> String {
    std::env::var("CC").unwrap_or_else(|_| "cc".into())
}

/// Compiles the core and its tests into `exe`; `extra` flags appended.
fn build(root: &Path, exe: &Path, extra: &[&str]) -> std::process::Output {
    let fw = root.join("firmware");
    let mut cmd = Command::new(cc());
    cmd.args(["-std=c11", "-Wall", "-Wextra", "-Wpedantic", "-Werror", "-O1", "-g"])
        .args(extra)
        .arg(fw.join("core/frame.c"))
        .arg(fw.join("core/device.c"))
        .arg(fw.join("test/test_core.c"))
        .arg("-o")
        .arg(exe);
    cmd.output().unwrap_or_else(|e| panic!("cannot run the C compiler `{}`: {e}", cc()))
}

#[test]
fn the_firmware_core_passes_its_unit_tests_on_the_host() {
    let root = evflow_tests::root();
    let dir = tempfile::tempdir().unwrap();
    let exe = dir.path().join("test_core");
    // Sanitizers when this compiler has them (their runtime is a separate package on some systems).
    let sanitized = build(&root, &exe, &["-fsanitize=address,undefined", "-fno-sanitize-recover=all"]);
    let built = if sanitized.status.success() { sanitized } else { build(&root, &exe, &[]) };
    assert!(built.status.success(), "the core does not compile:\n{}", String::from_utf8_lossy(&built.stderr));
    // The core alone with -Wconversion: every narrowing written out.
    for file in ["core/frame.c", "core/device.c"] {
        let o = Command::new(cc())
            .args(["-std=c11", "-Wall", "-Wextra", "-Wpedantic", "-Wconversion", "-Werror", "-c", "-o"])
            .arg(dir.path().join("x.o"))
            .arg(root.join("firmware").join(file))
            .output()
            .unwrap();
        assert!(o.status.success(), "{file}:\n{}", String::from_utf8_lossy(&o.stderr));
    }
    let run = Command::new(&exe).arg(root.join("docs/serial-protocol.md")).output().unwrap();
    let out = String::from_utf8_lossy(&run.stdout);
    assert!(run.status.success(), "{out}\n{}", String::from_utf8_lossy(&run.stderr));
    let checks: u64 = out
        .split_whitespace()
        .nth(2)
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no count of checks: {out}"));
    assert!(checks > 1000 && out.contains(", 0 failed"), "{out}");
}
