//! `evflow merge` of shards that are not all there (issue 37, point 16): a
//! task killed mid-run leaves a folder without its record, a task that
//! never ran no folder. The merge refuses, naming each missing shard and
//! printing the commands that rerun it (the by-hand one works as printed);
//! `--partial` merges the shards there are, never the killed task's files,
//! marks the output partial and exits 3; once the shards are rerun the
//! merge is one run's, byte for byte, and the mark is gone. A shard rerun
//! drops its old record first.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use crate::files;
use files::tree;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("workspace root").to_path_buf()
}

fn evflow(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_evflow")).args(args).current_dir(root()).output().expect("evflow runs")
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// The 3×3 grid of graphs/excitation.toml into `dir`, its table inside.
fn grid(dir: &Path, extra: &[&str]) -> Output {
    let d = dir.to_str().unwrap();
    let csv = format!("{d}/grid.csv");
    let mut args = vec![
        "run",
        "graphs/excitation.toml",
        "--sweep",
        "mass=60,85,110",
        "--sweep",
        "speed=3,4,5",
        "--no-times",
        "-q",
        "--out",
        d,
        "--csv",
        &csv,
    ];
    args.extend_from_slice(extra);
    evflow(&args)
}

/// The line of `text` that holds `what`, trimmed.
fn line_with<'a>(text: &'a str, what: &str) -> &'a str {
    text.lines().find(|l| l.contains(what)).unwrap_or_else(|| panic!("no line with `{what}` in\n{text}")).trim()
}

/// Runs a printed `evflow …` command line with this build's evflow, in the
/// workspace root, through sh (as a person would paste it).
fn paste(line: &str) -> Output {
    let command = line.strip_prefix("evflow ").unwrap_or_else(|| panic!("not an evflow command: {line}"));
    Command::new("sh")
        .arg("-c")
        .arg(format!("\"$EVFLOW\" {command}"))
        .env("EVFLOW", env!("CARGO_BIN_EXE_evflow"))
        .current_dir(root())
        .output()
        .expect("sh runs")
}

#[test]
fn missing_shards_are_named_with_their_reruns_and_partial_merges_are_marked() {
    let base = tempfile::tempdir().unwrap();
    let one = base.path().join("one");
    assert!(grid(&one, &[]).status.success());
    let part = |k: usize| base.path().join(format!("parts/{k}"));
    for k in 1..=4 {
        let o = grid(&part(k), &["--shard", &format!("{k}/4")]);
        assert!(o.status.success(), "shard {k}: {}", text(&o.stderr));
    }
    // Shard 2 (runs 4 and 5 of 9) killed after writing its files: no
    // record. Shard 4 never ran: no folder.
    std::fs::remove_file(part(2).join("shard.json")).unwrap();
    std::fs::remove_dir_all(part(4)).unwrap();
    let given: Vec<String> = (1..=3).map(|k| part(k).display().to_string()).collect();
    let merged = base.path().join("merged");
    let m = merged.to_str().unwrap();
    let with = |flags: &[&str]| {
        let mut args = vec!["merge"];
        args.extend_from_slice(flags);
        args.push(m);
        args.extend(given.iter().map(String::as_str));
        evflow(&args)
    };

    let o = with(&[]);
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.starts_with("shards missing: 2/4, 4/4 (given 2 of 4); nothing was merged"), "{err}");
    let record2 = part(2).join("shard.json");
    assert!(err.contains(&format!("2/4: {} does not exist", record2.display())), "{err}");
    assert!(err.contains("4/4: no folder given holds it"), "{err}");
    assert!(err.contains("EVFLOW_SHARDS=4 sbatch --array=2,4 <the array's script"), "{err}");
    assert!(err.contains("evflow merge --partial"), "{err}");
    assert!(!merged.exists(), "a refused merge wrote {m}");
    // The by-hand commands are the shards' own, moved to K and its folder.
    let (p2, p4) = (part(2).display().to_string(), part(4).display().to_string());
    let rerun2 = line_with(&err, "--shard 2/4").to_string();
    let rerun4 = line_with(&err, "--shard 4/4").to_string();
    assert_eq!(
        rerun2,
        format!(
            "evflow run graphs/excitation.toml --sweep mass=60,85,110 --sweep speed=3,4,5 --no-times -q --out {p2} \
             --csv {p2}/grid.csv --shard 2/4"
        )
    );
    assert!(rerun4.contains(&format!("--out {p4} --csv {p4}/grid.csv")), "{rerun4}");

    // --partial: shards 1 and 3 merge, shard 2's files stay out, the output says so.
    let o = with(&["--partial"]);
    let (out, err) = (text(&o.stdout), text(&o.stderr));
    assert_eq!(o.status.code(), Some(3), "{out}{err}");
    assert!(out.contains("partial: shards 2, 4 of 4 missing"), "{out}");
    assert!(out.contains("merged 2 shards of graphs/excitation.toml: 5 of 9 runs"), "{out}");
    assert!(err.contains("partial merge into") && err.contains("--shard 2/4"), "{err}");
    let note = std::fs::read_to_string(merged.join("PARTIAL.txt")).unwrap();
    assert!(note.starts_with("partial merge: shards 2, 4 of 4 missing\n"), "{note}");
    assert!(note.contains(&rerun2) && note.contains("EVFLOW_SHARDS=4 sbatch --array=2,4"), "{note}");
    let rows = std::fs::read_to_string(merged.join("grid.csv")).unwrap();
    assert_eq!(rows.lines().count(), 1 + 5, "{rows}");
    assert!(!rows.lines().any(|l| l.starts_with("85,3,") || l.starts_with("85,4,")), "{rows}");
    let half: Vec<PathBuf> =
        tree(&part(2)).into_iter().map(|(p, _)| p).filter(|p| p != Path::new("grid.csv")).collect();
    assert!(!half.is_empty());
    for p in &half {
        assert!(!merged.join(p).exists(), "the killed shard's {} was merged", p.display());
    }

    // The printed commands rerun them; then the merge is one run's, unmarked.
    for line in [&rerun2, &rerun4] {
        let o = paste(line);
        assert!(o.status.success(), "{line}: {}", text(&o.stderr));
    }
    let all: Vec<String> = (1..=4).map(|k| part(k).display().to_string()).collect();
    let mut args = vec!["merge", m];
    args.extend(all.iter().map(String::as_str));
    let o = evflow(&args);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(!merged.join("PARTIAL.txt").exists(), "a complete merge left the partial mark");
    assert!(tree(&one) == tree(&merged), "the merge after the reruns differs from one run");
}

#[test]
fn folders_without_any_record_are_named_and_a_rerun_drops_its_old_record() {
    let base = tempfile::tempdir().unwrap();
    let (a, b) = (base.path().join("a"), base.path().join("b"));
    std::fs::create_dir_all(&a).unwrap();
    let o = evflow(&["merge", base.path().join("m").to_str().unwrap(), a.to_str().unwrap(), b.to_str().unwrap()]);
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains(&format!("none of {}, {} holds a shard's record", a.display(), b.display()))
            && err.contains("EVFLOW_SHARDS=N sbatch --array="),
        "{err}"
    );
    // A shard run again into its folder drops the record of its first run
    // before it starts: ended early (here its table cannot be written), it
    // leaves none, and its half-new files are not taken as done.
    let s = base.path().join("s");
    assert!(grid(&s, &["--shard", "1/3"]).status.success());
    assert!(s.join("shard.json").exists());
    std::fs::write(s.join("blocker"), "a file, not a folder").unwrap();
    let csv = s.join("blocker/grid.csv");
    let (s_, csv) = (s.to_str().unwrap(), csv.to_str().unwrap());
    let o = evflow(&[
        "run",
        "graphs/excitation.toml",
        "--sweep",
        "mass=60,85",
        "-q",
        "--shard",
        "1/3",
        "--out",
        s_,
        "--csv",
        csv,
    ]);
    assert!(!o.status.success() && text(&o.stderr).contains("cannot write table"), "{}", text(&o.stderr));
    assert!(!s.join("shard.json").exists(), "a rerun that did not end left the first run's record");
}
