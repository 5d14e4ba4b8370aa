//! `evflow report stability` from the command line: a passing case exits
//! 0 and writes its table, a failing one exits 1 naming it, a filter that
//! matches nothing is an error. (The whole CI-size suite runs in
//! tests/stability.rs, through the library.)

use std::path::PathBuf;
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn evflow(args: &[&str]) -> (Option<i32>, String, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_evflow")).args(args).current_dir(root()).output().expect("evflow runs");
    (o.status.code(), String::from_utf8_lossy(&o.stdout).into_owned(), String::from_utf8_lossy(&o.stderr).into_owned())
}

#[test]
fn a_passing_case_exits_0_and_writes_its_table_and_rows() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let (code, stdout, stderr) =
        evflow(&["report", "stability", "--size", "ci", "--only", "butterworth · order 16", "--out", out]);
    assert_eq!(code, Some(0), "{stdout}\n{stderr}");
    assert!(stdout.contains("| butterworth · order 16 is refused | stiff |"), "{stdout}");
    assert!(stdout.contains("stability: 1 cases (0 generated, 1 stiff, 0 graph families), 1 pass, 0 fail"), "{stdout}");
    let csv = std::fs::read_to_string(dir.path().join("rows.csv")).unwrap();
    assert_eq!(csv.lines().count(), 2, "{csv}");
    assert!(std::fs::read_to_string(dir.path().join("table.md")).unwrap().contains("error naming `order`"));
}

#[test]
fn a_failing_case_exits_1_and_a_filter_matching_nothing_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    // The shipped cases all pass: a graph folder holding a graph that
    // cannot be loaded (an unknown node type) gives a failing case.
    let graphs = dir.path().join("graphs");
    std::fs::create_dir(&graphs).unwrap();
    std::fs::write(
        graphs.join("broken.toml"),
        "[graph]\nformat = 1\nname = \"broken\"\nrate = 1000\nconnections = [\"s.out -> t.in\"]\n\
         [nodes.s]\ntype = \"sine\"\n[nodes.t]\ntype = \"no.such.node\"\n",
    )
    .unwrap();
    let (code, stdout, stderr) = evflow(&[
        "report",
        "stability",
        "--size",
        "ci",
        "--only",
        "graphs · broken",
        "--graphs",
        graphs.to_str().unwrap(),
        "--out",
        out,
    ]);
    assert_eq!(code, Some(1), "{stdout}\n{stderr}");
    assert!(stderr.contains("FAIL graphs · broken") && stderr.contains("1 stability case(s) failed"), "{stderr}");
    let (code, _, stderr) = evflow(&["report", "stability", "--only", "no such case", "--out", out]);
    assert_eq!(code, Some(1));
    assert!(stderr.contains("no case matches `no such case`"), "{stderr}");
}
