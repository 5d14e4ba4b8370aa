//! Writing a whole text file so that a reader never sees half of it, with
//! its folder: through `PATH.tmp`, synced, then renamed over `PATH`, the
//! temporary a new file and never a link planted at its name
//! ([`evflow_engine::atomic_file`]). Model files (`narx.train`,
//! `forward.train`) are written this way.

use std::path::Path;

/// Writes `text` and a final newline to `path`, creating its folder.
pub fn write_atomically(path: &Path, text: &str) -> std::io::Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)?;
    }
    evflow_engine::atomic_file::write_atomically(path, format!("{text}\n"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_file_appears_whole_and_no_temporary_is_left() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("sub").join("m.json");
        write_atomically(&path, "{}").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "{}\n");
        assert!(!dir.path().join("sub").join("m.json.tmp").exists());
        // A folder where the file should go: the write fails and leaves no temporary.
        let blocked = dir.path().join("blocked");
        std::fs::create_dir_all(blocked.join("x")).unwrap();
        assert!(write_atomically(&blocked.join("x"), "{}").is_err());
        assert!(!blocked.join("x.tmp").exists());
    }
}
