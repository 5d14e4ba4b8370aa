//! Reading and validating a graph file in one call.

use crate::check::{check, Checked, Override};
use crate::diag::{Diagnostic, Diagnostics};
use crate::graph::{parse_graph, Graph};
use crate::registry::Registry;
use std::path::Path;

/// Why a graph file could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    /// The file could not be read.
    #[error("{path}: {source}")]
    Read {
        /// The file.
        path: String,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The file was read but is not a valid graph.
    #[error("{0}")]
    Invalid(#[from] Diagnostics),
}

/// Reads, parses and validates a graph file.
pub fn load_file(path: &Path, registry: &Registry, overrides: &[Override]) -> Result<Checked, LoadError> {
    let graph = read_graph(path)?;
    Ok(check(&graph, registry, overrides)?)
}

/// Reads and parses a graph file (syntax only; [`check`] validates it).
pub fn read_graph(path: &Path) -> Result<Graph, LoadError> {
    let bytes = crate::files::read_regular(path)
        .map_err(|source| LoadError::Read { path: path.display().to_string(), source })?;
    let text = match String::from_utf8(bytes) {
        Ok(t) => t,
        Err(e) => {
            let at = e.utf8_error().valid_up_to();
            let text = String::from_utf8_lossy(e.as_bytes()).into_owned();
            let loc = crate::diag::LineIndex::new(&text).loc(&text, at);
            return Err(Diagnostics(vec![Diagnostic {
                file: path.to_path_buf(),
                loc,
                node: None,
                message: "the file is not UTF-8 text".into(),
                help: None,
            }])
            .into());
        }
    };
    Ok(parse_graph(path, &text)?)
}
