//! Reading the files a user names — graph files, recordings, meshes,
//! models, profiles — only when they are regular files: a name that is a
//! link to `/dev/zero`, a FIFO, a socket or a folder is refused before a
//! byte is read (read whole, `/dev/zero` would grow until the machine
//! stops it; a FIFO would block for ever). A link to a regular file is
//! followed. The file is checked by name and again on the open handle, so
//! a name swapped in between is caught.

use std::fs::File;
use std::io::Read;
use std::path::Path;

/// Why a file was not opened.
#[derive(Debug, thiserror::Error)]
pub enum OpenError {
    /// The operating system refused (no such file, no permission, …).
    #[error("{0}")]
    Io(#[from] std::io::Error),
    /// It exists but is not a regular file.
    #[error("is {what}, not a regular file")]
    NotAFile {
        /// `a folder`, or `a device, FIFO or socket`.
        what: &'static str,
    },
}

impl From<OpenError> for std::io::Error {
    fn from(e: OpenError) -> Self {
        match e {
            OpenError::Io(e) => e,
            e @ OpenError::NotAFile { .. } => std::io::Error::new(std::io::ErrorKind::InvalidInput, e.to_string()),
        }
    }
}

fn kind(m: &std::fs::Metadata) -> Result<(), OpenError> {
    let t = m.file_type();
    if t.is_file() {
        Ok(())
    } else if t.is_dir() {
        Err(OpenError::NotAFile { what: "a folder" })
    } else {
        Err(OpenError::NotAFile { what: "a device, FIFO or socket" })
    }
}

/// Opens `path` for reading if it is a regular file; with its length.
pub fn open_regular(path: &Path) -> Result<(File, u64), OpenError> {
    kind(&std::fs::metadata(path)?)?;
    let file = File::open(path)?;
    let m = file.metadata()?;
    kind(&m)?;
    Ok((file, m.len()))
}

/// The whole of `path`, a regular file ([`open_regular`]); other files
/// give an [`std::io::ErrorKind::InvalidInput`] error saying what it is.
pub fn read_regular(path: &Path) -> std::io::Result<Vec<u8>> {
    let (mut file, len) = open_regular(path)?;
    let mut bytes = Vec::with_capacity(usize::try_from(len).unwrap_or(0));
    file.read_to_end(&mut bytes)?;
    Ok(bytes)
}

/// [`read_regular`] as UTF-8 text.
pub fn read_regular_to_string(path: &Path) -> std::io::Result<String> {
    String::from_utf8(read_regular(path)?).map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidData, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regular_files_and_links_to_them_are_read_the_rest_refused() {
        let dir = tempfile::tempdir().unwrap();
        let f = dir.path().join("a.txt");
        std::fs::write(&f, "text").unwrap();
        assert_eq!(read_regular_to_string(&f).unwrap(), "text");
        let e = read_regular(dir.path()).unwrap_err();
        assert_eq!(e.to_string(), "is a folder, not a regular file");
        #[cfg(unix)]
        {
            let link = dir.path().join("link.txt");
            std::os::unix::fs::symlink(&f, &link).unwrap();
            assert_eq!(read_regular(&link).unwrap(), b"text");
            let zero = dir.path().join("zero.obj");
            std::os::unix::fs::symlink("/dev/zero", &zero).unwrap();
            let e = read_regular(&zero).unwrap_err();
            assert_eq!(e.kind(), std::io::ErrorKind::InvalidInput);
            assert_eq!(e.to_string(), "is a device, FIFO or socket, not a regular file");
        }
        assert!(matches!(open_regular(&dir.path().join("none")), Err(OpenError::Io(_))));
    }
}
