//! The page's files, built into the binary (no CDN, nothing fetched at
//! run time).

/// `(path, content type, body)` of every file served.
pub(crate) const FILES: &[(&str, &str, &str)] = &[
    ("/", "text/html; charset=utf-8", include_str!("assets/index.html")),
    ("/studio.css", "text/css; charset=utf-8", include_str!("assets/studio.css")),
    ("/studio.js", "text/javascript; charset=utf-8", include_str!("assets/studio.js")),
    ("/plot.js", "text/javascript; charset=utf-8", include_str!("assets/plot.js")),
];

/// The file at `path` (query stripped).
pub(crate) fn get(path: &str) -> Option<(&'static str, &'static str)> {
    let path = path.split('?').next().unwrap_or(path);
    let path = if path == "/index.html" { "/" } else { path };
    FILES.iter().find(|f| f.0 == path).map(|f| (f.1, f.2))
}
