//! `evflow report live` end to end on tiny sizes (one profile, one sample,
//! two users, 3 s strokes, two gains, a few floor iterations): the tables
//! hold every chain beside the floors, the stroke's floor is never above a
//! chain's best, and shards merged out of order by `evflow merge` give the
//! tables of one run byte for byte.
#![cfg(feature = "synth")]

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("workspace root").to_path_buf()
}

fn evflow(args: &[&str]) -> (bool, String, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_evflow")).args(args).current_dir(root()).output().expect("evflow runs");
    (
        o.status.success(),
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

fn report(out: &Path, extra: &[&str]) -> (bool, String, String) {
    let mut args = vec![
        "report",
        "live",
        "--out",
        out.to_str().unwrap(),
        "--profiles",
        "nominal",
        "--samples",
        "plastic-sheet",
        "--users",
        "person,short-strokes",
        "--gains",
        "0.6,1.0",
        "--seconds",
        "3",
        "--floor-iterations",
        "4",
        "--epochs",
        "3",
        "--iterations",
        "5",
        "--no-plots",
    ];
    args.extend_from_slice(extra);
    evflow(&args)
}

#[test]
fn the_live_report_holds_every_chain_and_its_shards_merge_into_one_run() {
    let base = tempfile::tempdir().unwrap();
    let one = base.path().join("one");
    let (ok, out, err) = report(&one, &[]);
    assert!(ok, "{out}{err}");
    let md = std::fs::read_to_string(one.join("live.md")).unwrap();
    for chain in [
        "nothing",
        "record-and-playback cells",
        "NARX cells",
        "optimized cells",
        "forces first (NARX)",
        "live synthesis",
        "stroke floor",
        "display floor",
    ] {
        assert!(md.contains(chain), "{chain}: {md}");
    }
    assert!(md.contains("| plastic-sheet |") && md.contains("## Targets"), "{md}");
    // rows.csv: per user, nothing, five chains, the floor, the target's floor, the floor's sliding only, the display floor.
    let csv = std::fs::read_to_string(one.join("rows.csv")).unwrap();
    let lines: Vec<&str> = csv.lines().skip(1).collect();
    assert_eq!(lines.len(), 2 * 10, "{csv}");
    assert!(md.contains("target's floor") && md.contains("against its goals"), "{md}");
    for user in ["person", "short-strokes"] {
        let best = |chain: &str| -> f64 {
            let l =
                lines.iter().find(|l| l.contains(&format!(",{user},{chain},"))).unwrap_or_else(|| panic!("{chain}"));
            l.split(',').nth(8).unwrap().parse().unwrap()
        };
        let floor = best("stroke_floor");
        assert!(floor.is_finite() && floor > 0.0, "{csv}");
        for chain in ["playback", "narx", "optimized", "ff", "live"] {
            assert!(floor <= best(chain), "{user}: the floor {floor} above {chain}'s best {}", best(chain));
        }
        // The target's floor is never above the live synthesis, and never below the stroke's floor by much
        // (both are optimized alike; the stroke's floor knows the real force).
        let target = best("target_floor");
        assert!(target.is_finite() && target <= best("live"), "{user}: {csv}");
    }

    // Shards, merged out of order: the same tables.
    let shards: Vec<PathBuf> = (1..=2).map(|k| base.path().join(format!("s{k}"))).collect();
    for (k, dir) in shards.iter().enumerate() {
        let shard = format!("{}/2", k + 1);
        let (ok, out, err) = report(dir, &["--shard", &shard]);
        assert!(ok, "{out}{err}");
        assert!(dir.join("live-shard.json").is_file() && !dir.join("live.md").exists(), "{out}");
    }
    let merged = base.path().join("merged");
    let m = |dirs: &[&PathBuf]| {
        let mut args = vec!["merge", merged.to_str().unwrap()];
        args.extend(dirs.iter().map(|d| d.to_str().unwrap()));
        evflow(&args)
    };
    let (ok, _, err) = m(&[&shards[1]]);
    assert!(!ok && err.contains("shards missing: 1/2"), "{err}");
    assert!(!merged.exists());
    let (ok, out, err) = m(&[&shards[1], &shards[0]]);
    assert!(ok, "{out}{err}");
    assert!(out.contains("merged 2 shards of a live report: 2 rows of 2 items"), "{out}");
    for f in ["live.md", "rows.csv"] {
        assert_eq!(
            std::fs::read_to_string(merged.join(f)).unwrap(),
            std::fs::read_to_string(one.join(f)).unwrap(),
            "{f}"
        );
    }
}

#[test]
fn two_members_of_the_display_family_play_the_live_synthesis_from_its_own_library() {
    let base = tempfile::tempdir().unwrap();
    let out = base.path().join("family");
    let (ok, stdout, err) = evflow(&[
        "report",
        "live",
        "--out",
        out.to_str().unwrap(),
        "--profiles",
        "family/tuning-04,family/held-out-01",
        "--chains",
        "live",
        "--samples",
        "plastic-sheet",
        "--users",
        "person",
        "--gains",
        "1.0",
        "--seconds",
        "2",
        "--floor-iterations",
        "3",
        "--no-plots",
    ]);
    assert!(ok, "{stdout}{err}");
    let md = std::fs::read_to_string(out.join("live.md")).unwrap();
    assert!(md.contains("| tuning-04 |") && md.contains("| held-out-01 |"), "{md}");
    assert!(!md.contains("NARX cells"), "only the live synthesis plays: {md}");
    assert!(md.contains("against its goals"), "{md}");
    // The live synthesis' own library: forward models and forces, no inverse models or cells.
    let lib = out.join("work/tuning-04/live-library");
    assert!(lib.join("models/forward-60g-3cms.json").is_file() && lib.join("forces-plastic-sheet").is_dir());
    assert!(!lib.join("models/narx-60g-3cms.json").exists() && !lib.join("narx-plastic-sheet").exists());
    let csv = std::fs::read_to_string(out.join("rows.csv")).unwrap();
    for chain in ["nothing", "live", "stroke_floor", "target_floor", "display_floor"] {
        assert_eq!(csv.lines().filter(|l| l.contains(&format!(",{chain},"))).count(), 2, "{chain}: {csv}");
    }
    // A typo in --chains is refused by name.
    let (ok, _, err) = evflow(&["report", "live", "--chains", "liev", "--out", out.to_str().unwrap()]);
    assert!(!ok && err.contains("no chain named `liev`"), "{err}");
}
