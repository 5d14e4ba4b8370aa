//! contrib/slurm's array scripts, run by bash as Slurm would run one task
//! (its environment set by hand): rerunning one task of an array alone
//! (`sbatch --array=6`, so Slurm counts one task) works when the array's
//! size is given, and says how when it is not (issue 37, point 16). The
//! shipped slurm.conf keeps a record of ended jobs without a database, in
//! a folder the set-up creates for slurmctld (issue 37, point 17).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("workspace root").to_path_buf()
}

/// model-grid.sbatch as array task `task` of a rerun that Slurm sees as
/// `count` tasks, in `dir` (graphs linked there), cut short by `--set`s.
fn task(dir: &Path, task: &str, count: &str, shards: Option<&str>) -> Output {
    let mut c = Command::new("bash");
    c.arg(root().join("contrib/slurm/model-grid.sbatch"))
        .args(["--set", "epochs=1", "--set", "samples=600", "--set", "passes=2"])
        .current_dir(dir)
        .env("EVFLOW_BIN", env!("CARGO_BIN_EXE_evflow"))
        .env("SLURM_ARRAY_TASK_ID", task)
        .env("SLURM_ARRAY_TASK_COUNT", count)
        .env_remove("EVFLOW_SHARDS");
    if let Some(n) = shards {
        c.env("EVFLOW_SHARDS", n);
    }
    c.output().expect("bash runs")
}

#[test]
fn one_task_of_an_array_reruns_alone_given_the_arrays_size() {
    let dir = tempfile::tempdir().unwrap();
    std::os::unix::fs::symlink(root().join("graphs"), dir.path().join("graphs")).unwrap();
    // Slurm counts one task in `sbatch --array=6`: without the array's
    // size the task stops and says how to give it.
    let o = task(dir.path(), "6", "1", None);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("EVFLOW_SHARDS=9 sbatch --array=6 contrib/slurm/model-grid.sbatch"), "{err}");
    assert!(!dir.path().join("parts/grid/6").exists());
    // With it, task 6 runs the sixth of the nine runs and writes its record.
    let o = task(dir.path(), "6", "1", Some("9"));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let record = std::fs::read_to_string(dir.path().join("parts/grid/6/shard.json")).unwrap();
    let record: serde_json::Value = serde_json::from_str(&record).unwrap();
    assert_eq!(record["range"], serde_json::json!([5, 6]), "{record}");
    assert!(dir.path().join("parts/grid/6/narx-85g-5cms.json").exists(), "the sixth run is mass=85 speed=5");
    // Merged alone, the other eight are named with the commands that rerun
    // them: the Slurm one, and task 6's own command moved to shard 1.
    let o = Command::new(env!("CARGO_BIN_EXE_evflow"))
        .args(["merge", "models", "parts/grid/6"])
        .current_dir(dir.path())
        .output()
        .expect("evflow runs");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.starts_with("shards missing: 1/9, 2/9, 3/9, 4/9, 5/9, 7/9, 8/9, 9/9 (given 1 of 9)"), "{err}");
    assert!(err.contains("EVFLOW_SHARDS=9 sbatch --array=1-5,7-9 <the array's script"), "{err}");
    let by_hand = "evflow run graphs/model-build.toml --sweep mass=60,85,110 --sweep speed=3,4,5 --shard 1/9 \
                   --jobs 1 --no-times -q --out parts/grid/1 --csv parts/grid/1/models.csv --json \
                   parts/grid/1/models.json --set epochs=1 --set samples=600 --set passes=2";
    assert!(err.lines().any(|l| l.trim() == by_hand), "no line `{by_hand}` in\n{err}");
    assert!(!dir.path().join("models").exists());
}

/// The settings of contrib/slurm/slurm.conf, `Key=value` lines without comments.
fn slurm_conf() -> Vec<(String, String)> {
    let text = std::fs::read_to_string(root().join("contrib/slurm/slurm.conf")).unwrap();
    text.lines()
        .map(str::trim)
        .filter(|l| !l.starts_with('#'))
        .filter_map(|l| l.split_once('='))
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect()
}

#[test]
fn slurm_conf_keeps_a_job_record_in_a_folder_the_setup_creates() {
    let conf = slurm_conf();
    let get =
        |key: &str| conf.iter().find(|(k, _)| k == key).map(|(_, v)| v.as_str()).unwrap_or_else(|| panic!("no {key}="));
    // sacct needs slurmdbd, which one node does without: ended jobs go to a
    // text file, and slurmctld keeps them an hour for `scontrol show job`.
    assert_eq!(get("JobCompType"), "jobcomp/filetxt");
    let log = Path::new(get("JobCompLoc"));
    assert!(log.is_absolute(), "{}", log.display());
    let age: u64 = get("MinJobAge").parse().expect("MinJobAge is a number of seconds");
    assert!(age >= 3600, "MinJobAge={age}: ended jobs vanish from scontrol within the hour");
    // slurmctld writes it as SlurmUser: its folder is created owned by that user.
    let user = get("SlurmUser");
    let folder = log.parent().unwrap().to_str().unwrap();
    let setup = std::fs::read_to_string(root().join("contrib/slurm/setup-single-node.sh")).unwrap();
    let owned = format!("install -d -o {user} -g {user} ");
    assert!(
        setup.lines().any(|l| l.trim_start().starts_with(&owned) && l.split_whitespace().any(|w| w == folder)),
        "setup-single-node.sh creates no {folder} owned by {user}"
    );
}
