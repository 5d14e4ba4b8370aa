//! The commands that rerun shards: with Slurm, the array's script as an
//! array of those tasks given the whole array's size (`EVFLOW_SHARDS`,
//! contrib/slurm/README.md "Rerunning one task"); by hand, another shard's
//! own command line with its K and its folder changed.

use std::path::Path;

/// `ks` (in order) as Slurm's `--array` takes them: `6,8`, three or more
/// in a row as a range (`1-5,7,8`).
pub fn array(ks: &[usize]) -> String {
    let mut parts: Vec<String> = Vec::new();
    let mut i = 0;
    while i < ks.len() {
        let mut j = i;
        while j + 1 < ks.len() && ks[j + 1] == ks[j] + 1 {
            j += 1;
        }
        if j - i >= 2 {
            parts.push(format!("{}-{}", ks[i], ks[j]));
        } else {
            parts.extend(ks[i..=j].iter().map(usize::to_string));
        }
        i = j + 1;
    }
    parts.join(",")
}

/// The Slurm command that reruns tasks `ks` of an array of `n`, run with
/// the array's `script`.
pub fn slurm(ks: &[usize], n: usize, script: &str) -> String {
    format!("EVFLOW_SHARDS={n} sbatch --array={} {script}", array(ks))
}

/// `arg` as a shell reads it back: as it is when it holds only characters
/// that need no quoting, else in single quotes.
pub fn quote(arg: &str) -> String {
    let plain = |c: char| c.is_ascii_alphanumeric() || "_-./:=,+@%".contains(c);
    if !arg.is_empty() && arg.chars().all(plain) {
        arg.to_string()
    } else {
        format!("'{}'", arg.replace('\'', r"'\''"))
    }
}

/// The value of option `name` (`--name V` or `--name=V`) in `args`, if given.
fn value_of<'a>(args: &'a [String], name: &str) -> Option<&'a str> {
    let eq = format!("{name}=");
    let mut it = args.iter();
    while let Some(a) = it.next() {
        if a == name {
            return it.next().map(String::as_str);
        }
        if let Some(v) = a.strip_prefix(&eq) {
            return Some(v);
        }
    }
    None
}

/// The `--out` folder of a shard's command line, if it gives one.
pub fn out_of(command: &[String]) -> Option<&str> {
    value_of(command, "--out")
}

/// `path` with a leading `from` (the whole of it, or up to a `/`) put as `to`.
fn moved(path: &str, from: &str, to: &str) -> Option<String> {
    let rest = path.strip_prefix(from)?;
    (rest.is_empty() || rest.starts_with('/')).then(|| format!("{to}{rest}"))
}

/// A shard's command line (`run GRAPH … --shard J/N --out DIR …`, as the
/// record keeps it) turned into the command that runs shard `k` of `n`
/// into `to`: `--shard` becomes `k/n`, and `--out`, and every argument
/// that is a path inside it (`--csv DIR/t.csv`, `--json=DIR/r.json`),
/// move into `to`. `None` without `--shard` or `--out`.
pub fn by_hand(command: &[String], k: usize, n: usize, to: &str) -> Option<String> {
    let out = out_of(command)?.to_string();
    value_of(command, "--shard")?;
    let shard = format!("{k}/{n}");
    let mut args = Vec::with_capacity(command.len() + 1);
    let mut after_shard = false;
    for a in command {
        let arg = if after_shard {
            shard.clone()
        } else if a.starts_with("--shard=") {
            format!("--shard={shard}")
        } else if let Some(p) = moved(a, &out, to) {
            p
        } else if let Some((opt, p)) = a.split_once('=').filter(|(o, _)| o.starts_with("--")) {
            moved(p, &out, to).map(|p| format!("{opt}={p}")).unwrap_or_else(|| a.clone())
        } else {
            a.clone()
        };
        after_shard = a == "--shard";
        args.push(quote(&arg));
    }
    Some(format!("evflow {}", args.join(" ")))
}

/// The folder shard `k` goes into when the shards' folders are named by
/// their K (`parts/grid/6`, as the Slurm scripts name them): the sibling of
/// shard `j`'s folder `dir`; `None` when `dir` is not named `j`.
pub fn sibling(dir: &str, j: usize, k: usize) -> Option<String> {
    let p = Path::new(dir);
    if p.file_name()?.to_str()? != j.to_string() {
        return None;
    }
    let parent = p.parent().map(|q| q.to_string_lossy().into_owned()).unwrap_or_default();
    Some(if parent.is_empty() { k.to_string() } else { format!("{parent}/{k}") })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args(s: &str) -> Vec<String> {
        s.split(' ').map(String::from).collect()
    }

    #[test]
    fn a_shards_command_is_moved_to_another_k_and_folder() {
        let grid = args(
            "run graphs/model-build.toml --sweep mass=60,85,110 --shard 3/9 --jobs 1 --no-times -q \
             --out parts/grid/3 --csv parts/grid/3/models.csv --json=parts/grid/3/models.json",
        );
        assert_eq!(
            by_hand(&grid, 6, 9, "parts/grid/6").unwrap(),
            "evflow run graphs/model-build.toml --sweep mass=60,85,110 --shard 6/9 --jobs 1 --no-times -q \
             --out parts/grid/6 --csv parts/grid/6/models.csv --json=parts/grid/6/models.json"
        );
        // `--shard=`, `--out=`, a path that only starts like the folder, and quoting.
        let odd = args("run g.toml --shard=1/2 --out=p/1 --csv p/10/t.csv --set name=a'b");
        assert_eq!(
            by_hand(&odd, 2, 2, "p/2 x").unwrap(),
            r"evflow run g.toml --shard=2/2 '--out=p/2 x' --csv p/10/t.csv --set 'name=a'\''b'"
        );
        assert_eq!(by_hand(&args("run g.toml --out p"), 1, 2, "q"), None);
        assert_eq!(by_hand(&args("run g.toml --shard 1/2"), 1, 2, "q"), None);
        assert_eq!(by_hand(&[], 1, 2, "q"), None);
    }

    #[test]
    fn folders_named_by_their_k_have_siblings_and_slurm_reruns_a_list() {
        assert_eq!(sibling("parts/grid/3", 3, 6).as_deref(), Some("parts/grid/6"));
        assert_eq!(sibling("3", 3, 6).as_deref(), Some("6"));
        assert_eq!(sibling("/abs/3", 3, 6).as_deref(), Some("/abs/6"));
        assert_eq!(sibling("parts/part3", 3, 6), None);
        assert_eq!(
            slurm(&[6, 8], 9, "contrib/slurm/model-grid.sbatch"),
            "EVFLOW_SHARDS=9 sbatch --array=6,8 contrib/slurm/model-grid.sbatch"
        );
        assert_eq!(array(&[1, 2, 3, 4, 5, 7, 8, 10, 11, 12]), "1-5,7,8,10-12");
        assert_eq!(array(&[3]), "3");
        assert_eq!(quote(""), "''");
    }
}
