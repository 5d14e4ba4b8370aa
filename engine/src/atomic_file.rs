//! Writing a file whole or not at all, and never through a link.
//!
//! Every file evflow writes under its final name in one go — tables,
//! records, indexes, models, reports, plots, an offline recording — is
//! filled under a temporary name beside it, synced and renamed over its
//! name: a reader sees the old file or the new one, never half of one, and
//! a failed write removes its temporary.
//!
//! The temporary is always a new file ([`create_temporary`]), created
//! exclusively (`O_CREAT | O_EXCL`: an existing name, a link included, is
//! refused without being followed) at `PATH.tmp` or, when that name is
//! taken — a temporary left by a crash, another writer's, or a link someone
//! planted there pointing out of the output folder — at `PATH.PID-K.tmp`.
//! Nothing at a taken name is opened, written or removed, so a planted link
//! is neither written through nor renamed into place, and two processes
//! writing one file each write their own temporary. The rename replaces a
//! link at the final name rather than writing where it points.

use std::fs::{File, OpenOptions};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// How many names [`create_temporary`] tries before it gives up.
const ATTEMPTS: u64 = 64;

/// Temporaries this process has named after its id (each gets its own K).
static NAMED: AtomicU64 = AtomicU64::new(0);

/// `PATH.tmp`: the name beside `path` a whole-file write fills before it is
/// renamed to `path`, when that name is free.
pub fn temporary_name(path: &Path) -> PathBuf {
    with_suffix(path, ".tmp")
}

fn with_suffix(path: &Path, suffix: &str) -> PathBuf {
    let mut s = path.as_os_str().to_owned();
    s.push(suffix);
    PathBuf::from(s)
}

/// Creates a new, empty regular file beside `path` to fill before renaming
/// it to `path`, open for reading and writing: [`temporary_name`], or
/// `PATH.PID-K.tmp` when that is taken. Returns the file and its name. Never
/// opens, follows or removes what is already there.
pub fn create_temporary(path: &Path) -> std::io::Result<(File, PathBuf)> {
    let mut name = temporary_name(path);
    for _ in 0..ATTEMPTS {
        match OpenOptions::new().read(true).write(true).create_new(true).open(&name) {
            Ok(file) => return Ok((file, name)),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                let k = NAMED.fetch_add(1, Ordering::Relaxed);
                name = with_suffix(path, &format!(".{}-{k}.tmp", std::process::id()));
            }
            Err(e) => return Err(e),
        }
    }
    Err(std::io::Error::new(
        std::io::ErrorKind::AlreadyExists,
        format!("no free temporary name beside {} ({ATTEMPTS} tried)", path.display()),
    ))
}

/// Writes `path` whole through a temporary ([`create_temporary`]): `fill`
/// writes the contents, then the file is synced and renamed over `path`.
/// On any error the temporary is removed and `path` is as it was. The
/// folder must exist.
pub fn write_with(path: &Path, fill: impl FnOnce(&mut File) -> std::io::Result<()>) -> std::io::Result<()> {
    let (mut file, tmp) = create_temporary(path)?;
    let result = fill(&mut file).and_then(|()| file.sync_all());
    drop(file); // closed before the rename or removal (required on Windows)
    let result = result.and_then(|()| std::fs::rename(&tmp, path));
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// Writes `bytes` to `path` whole ([`write_with`]).
pub fn write_atomically(path: &Path, bytes: impl AsRef<[u8]>) -> std::io::Result<()> {
    write_with(path, |f| f.write_all(bytes.as_ref()))
}

/// Copies the regular file `from` to `to` whole ([`write_with`]); `from`
/// is opened as [`crate::files::open_regular`] opens.
pub fn copy_atomically(from: &Path, to: &Path) -> std::io::Result<()> {
    let (mut source, _) = crate::files::open_regular(from)?;
    write_with(to, |f| std::io::copy(&mut source, f).map(drop))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_appears_whole_and_no_temporary_is_left() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.json");
        write_atomically(&path, "{}").unwrap();
        write_atomically(&path, "{\"b\": 1}").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "{\"b\": 1}");
        assert_eq!(temporary_name(&path), dir.path().join("a.json.tmp"));
        assert!(!temporary_name(&path).exists());
        // A failed fill: the old file stays, the temporary goes.
        let e = write_with(&path, |_| Err(std::io::Error::other("disk full"))).unwrap_err();
        assert_eq!(e.to_string(), "disk full");
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "{\"b\": 1}");
        assert!(!temporary_name(&path).exists());
        // A folder where the file should go: the rename fails, no temporary is left.
        std::fs::create_dir(dir.path().join("x")).unwrap();
        assert!(write_atomically(&dir.path().join("x"), "{}").is_err());
        assert!(!dir.path().join("x.tmp").exists());
        // A folder at the temporary name is left alone.
        std::fs::create_dir(dir.path().join("y.tmp")).unwrap();
        write_atomically(&dir.path().join("y"), "{}").unwrap();
        assert!(dir.path().join("y.tmp").is_dir());
        // A copy is byte for byte.
        copy_atomically(&path, &dir.path().join("c.json")).unwrap();
        assert_eq!(std::fs::read(dir.path().join("c.json")).unwrap(), std::fs::read(&path).unwrap());
        assert!(copy_atomically(dir.path(), &dir.path().join("d")).is_err(), "a folder is not copied");
        assert!(!dir.path().join("d").exists());
        assert_eq!(temporaries(dir.path()), ["y.tmp"]);
    }

    /// The names in `dir` ending in `.tmp`.
    fn temporaries(dir: &Path) -> Vec<String> {
        let names = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned());
        names.filter(|n| n.ends_with(".tmp")).collect()
    }

    #[test]
    fn a_taken_temporary_name_is_left_alone_and_another_used() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.csv");
        std::fs::write(temporary_name(&path), "left by a crash").unwrap();
        write_atomically(&path, "new").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "new");
        assert_eq!(std::fs::read_to_string(temporary_name(&path)).unwrap(), "left by a crash");
        assert_eq!(temporaries(dir.path()), ["t.csv.tmp"]);
        // Two writers at once each fill their own temporary.
        let (mut a, an) = create_temporary(&path).unwrap();
        let (mut b, bn) = create_temporary(&path).unwrap();
        assert_ne!(an, bn);
        assert!(bn.to_string_lossy().ends_with(".tmp"), "{}", bn.display());
        a.write_all(b"a").unwrap();
        b.write_all(b"b").unwrap();
        assert_eq!((std::fs::read(&an).unwrap(), std::fs::read(&bn).unwrap()), (b"a".to_vec(), b"b".to_vec()));
    }

    #[cfg(unix)]
    #[test]
    fn a_link_planted_at_the_temporary_name_is_never_followed() {
        // Issue 37, point 2.
        let dir = tempfile::tempdir().unwrap();
        let elsewhere = dir.path().join("elsewhere");
        let out = dir.path().join("out");
        std::fs::create_dir_all(&elsewhere).unwrap();
        std::fs::create_dir_all(&out).unwrap();
        let target = elsewhere.join("X.wav");
        std::fs::write(&target, "precious").unwrap();
        let path = out.join("r.wav");
        std::os::unix::fs::symlink(&target, temporary_name(&path)).unwrap();
        write_atomically(&path, "output").unwrap();
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "precious", "written through the link");
        let meta = std::fs::symlink_metadata(&path).unwrap();
        assert!(meta.file_type().is_file(), "the link was renamed into place");
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "output");
        // A dangling link: nothing is created where it points.
        let missing = elsewhere.join("new.wav");
        let other = out.join("n.wav");
        std::os::unix::fs::symlink(&missing, temporary_name(&other)).unwrap();
        write_atomically(&other, "output").unwrap();
        assert!(!missing.exists(), "created through the link");
        // A link at the final name is replaced, not written through.
        let final_link = out.join("f.wav");
        std::os::unix::fs::symlink(&target, &final_link).unwrap();
        write_atomically(&final_link, "output").unwrap();
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "precious");
        assert!(std::fs::symlink_metadata(&final_link).unwrap().file_type().is_file());
    }
}
