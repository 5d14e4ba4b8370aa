//! The house's rules, held against the code (docs/architecture.md):
//!
//! * **Layers.** dsp, engine < nodes < study < tools: a crate depends only on
//!   crates below it (its `Cargo.toml`), so no arrow runs back up between
//!   the layers.
//! * **No circles.** Inside each crate, no two source files import each
//!   other, directly or round a loop. A file's imports are the module paths
//!   it names outside its tests (`use crate::a::b`, `super::x`, `self::y`,
//!   inline `crate::a::f()` and `child::f()`), each taken to the file that
//!   holds the longest module prefix. A module's own descendants are not
//!   its imports: a folder's `mod.rs` declares its files, hands their names
//!   on and calls into them, and they may use what it holds (the types its
//!   files share) — so a circle is a loop through siblings or across
//!   folders, the kind that makes two files one.
//!
//! The reading is textual, like any reader of imports: it ignores comments
//! and test modules, and it is checked on small made-up trees below so that
//! it can fail.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The layers, bottom first, with the crate folders that form them.
const LAYERS: &[(&str, &str)] = &[
    ("evflow-dsp", "dsp"),
    ("evflow-engine", "engine"),
    ("evflow-nodes", "nodes"),
    ("evflow-study", "study"),
    ("evflow", "tools"),
];

/// One crate root's module tree: module path → file, and the names each
/// module hands on (`pub use path::Name`) with the path they name.
struct Tree {
    files: BTreeMap<Vec<String>, PathBuf>,
    reexports: BTreeMap<(Vec<String>, String), String>,
}

/// Lines of `text` with comments cut and `#[cfg(test)]` items (a module
/// block or a `mod x;` line) left out.
fn code_lines(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut lines = text.lines().peekable();
    let mut in_block_comment = false;
    while let Some(line) = lines.next() {
        let mut l = line.to_string();
        if in_block_comment {
            match l.find("*/") {
                Some(i) => {
                    l = l[i + 2..].to_string();
                    in_block_comment = false;
                }
                None => continue,
            }
        }
        // Whichever comment opens first (`//` makes a later `/*` text).
        let line_comment = l.find("//");
        match l.find("/*") {
            Some(i) if line_comment.is_none_or(|c| i < c) => {
                if !l[i..].contains("*/") {
                    in_block_comment = true;
                }
                l.truncate(i);
            }
            _ => {
                if let Some(c) = line_comment {
                    l.truncate(c);
                }
            }
        }
        if l.trim() == "#[cfg(test)]" {
            // Skip the attributes that follow, then the item: a `mod x;` line
            // or a `mod x { … }` block (to its matching brace).
            let mut depth = 0i32;
            let mut opened = false;
            for next in lines.by_ref() {
                let t = next.trim();
                if t.starts_with("#[") && !opened {
                    continue;
                }
                depth += next.matches('{').count() as i32 - next.matches('}').count() as i32;
                opened |= next.contains('{');
                if (opened && depth <= 0) || (!opened && t.ends_with(';')) {
                    break;
                }
            }
            continue;
        }
        out.push(l);
    }
    out
}

/// The children a file declares (`mod x;`, `pub mod x;`, `pub(crate) mod x;`).
fn children(lines: &[String]) -> Vec<String> {
    lines
        .iter()
        .filter_map(|l| {
            let t = l.trim();
            let t = t.strip_prefix("pub(crate) ").or_else(|| t.strip_prefix("pub ")).unwrap_or(t);
            let name = t.strip_prefix("mod ")?.strip_suffix(';')?;
            name.chars().all(|c| c.is_alphanumeric() || c == '_').then(|| name.to_string())
        })
        .collect()
}

/// The module tree from a crate root file.
fn tree(root: &Path) -> Tree {
    let mut files = BTreeMap::new();
    let mut reexports = BTreeMap::new();
    let mut todo = vec![(Vec::<String>::new(), root.to_path_buf())];
    while let Some((module, file)) = todo.pop() {
        let text = std::fs::read_to_string(&file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        let dir = if module.is_empty() || file.file_name().is_some_and(|n| n == "mod.rs") {
            file.parent().unwrap().to_path_buf()
        } else {
            file.with_extension("")
        };
        let lines = code_lines(&text);
        for (public, stmt) in use_statements(&lines) {
            if public {
                for (path, name) in expand(&stmt).into_iter().filter_map(|p| aliased(&p)) {
                    reexports.insert((module.clone(), name), path);
                }
            }
        }
        for child in children(&lines) {
            let flat = dir.join(format!("{child}.rs"));
            let nested = dir.join(&child).join("mod.rs");
            let at = if flat.is_file() { flat } else { nested };
            assert!(at.is_file(), "{}: `mod {child};` has no file", file.display());
            let mut m = module.clone();
            m.push(child);
            todo.push((m, at));
        }
        files.insert(module, file);
    }
    Tree { files, reexports }
}

/// `a::{b, c::{d, e}}` → `a::b`, `a::c::d`, `a::c::e` (self kept as the prefix).
fn expand(path: &str) -> Vec<String> {
    let Some(open) = path.find('{') else {
        return vec![path.trim().trim_end_matches("::self").to_string()];
    };
    let close = path.rfind('}').unwrap_or(path.len());
    let head = &path[..open];
    let inner = &path[open + 1..close.max(open + 1)];
    let mut parts = Vec::new();
    let (mut depth, mut start) = (0, 0);
    for (i, c) in inner.char_indices() {
        match c {
            '{' => depth += 1,
            '}' => depth -= 1,
            ',' if depth == 0 => {
                parts.push(&inner[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    parts.push(&inner[start..]);
    parts
        .into_iter()
        .map(str::trim)
        .filter(|p| !p.is_empty())
        .flat_map(|p| {
            if p == "self" {
                vec![head.trim_end_matches("::").to_string()]
            } else {
                expand(&format!("{head}{p}"))
            }
        })
        .collect()
}

/// The `use` statements of a file, each whole on one line: (public, path).
fn use_statements(lines: &[String]) -> Vec<(bool, String)> {
    let code = lines.join("\n");
    let mut out = Vec::new();
    let mut rest = code.as_str();
    let mut offset = 0;
    while let Some(i) = rest.find("use ") {
        let at = offset + i;
        let before = code[..at].chars().last();
        rest = &rest[i + 4..];
        offset = at + 4;
        if before.is_some_and(|c| c.is_alphanumeric() || c == '_') {
            continue;
        }
        let Some(end) = rest.find(';') else { break };
        let line_start = code[..at].rfind('\n').map_or(0, |n| n + 1);
        let public = code[line_start..at].trim_start().starts_with("pub");
        out.push((public, rest[..end].split_whitespace().collect::<Vec<_>>().join(" ")));
    }
    out
}

/// `a::b::C as D` → (`a::b::C`, `D`); `a::b::C` → (`a::b::C`, `C`); a glob → None.
fn aliased(path: &str) -> Option<(String, String)> {
    let (p, alias) = match path.split_once(" as ") {
        Some((p, a)) => (p.trim(), a.trim()),
        None => (path.trim(), path.trim().rsplit("::").next().unwrap_or("")),
    };
    (!p.ends_with('*') && !p.is_empty()).then(|| (p.to_string(), alias.to_string()))
}

/// The module paths a file names: `use` statements expanded, and inline
/// `crate::…`, `super::…` and `self::…` paths.
fn named_paths(lines: &[String]) -> Vec<String> {
    let code = lines.join("\n");
    let mut paths = Vec::new();
    for (_, stmt) in use_statements(lines) {
        paths.extend(expand(&stmt).into_iter().filter_map(|p| aliased(&p)).map(|(p, _)| p));
    }
    // Inline paths.
    for key in ["crate::", "super::", "self::"] {
        let mut from = 0;
        while let Some(i) = code[from..].find(key) {
            let at = from + i;
            from = at + key.len();
            if code[..at].chars().last().is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':') {
                continue;
            }
            let p: String = code[at..].chars().take_while(|c| c.is_alphanumeric() || *c == '_' || *c == ':').collect();
            paths.push(p.trim_end_matches(':').to_string());
        }
    }
    paths
}

/// The module a path names, from `module` (the naming file's module), or
/// None for another crate or the standard library.
fn resolve(path: &str, module: &[String], is_dir_module: bool, tree: &Tree) -> Option<Vec<String>> {
    resolve_at(path, module, is_dir_module, tree, 0)
}

/// [`resolve`], `depth` re-exports deep.
fn resolve_at(path: &str, module: &[String], is_dir_module: bool, tree: &Tree, depth: usize) -> Option<Vec<String>> {
    let segs: Vec<&str> = path.split("::").filter(|s| !s.is_empty()).collect();
    let (mut at, rest): (Vec<String>, &[&str]) = match segs.first()? {
        &"crate" => (Vec::new(), &segs[1..]),
        &"self" => (module.to_vec(), &segs[1..]),
        &"super" => {
            let mut m = module.to_vec();
            let mut k = 0;
            while segs.get(k) == Some(&"super") {
                m.pop();
                k += 1;
            }
            (m, &segs[k..])
        }
        first => {
            // A child module of this one, named without `self::`.
            let mut m = module.to_vec();
            m.push(first.to_string());
            if tree.files.contains_key(&m) && is_dir_module {
                (module.to_vec(), &segs[..])
            } else {
                return None;
            }
        }
    };
    for s in rest {
        let mut m = at.clone();
        m.push(s.to_string());
        if !tree.files.contains_key(&m) {
            // A name the module hands on: the module it comes from.
            if let Some(p) = tree.reexports.get(&(at.clone(), s.to_string())) {
                if depth < 8 {
                    let dir = at.is_empty() || tree.files[&at].file_name().is_some_and(|n| n == "mod.rs");
                    return resolve_at(p, &at, dir, tree, depth + 1).or(Some(at));
                }
            }
            break;
        }
        at = m;
    }
    Some(at)
}

/// File → the files it imports, for one crate root.
fn arrows(tree: &Tree) -> BTreeMap<PathBuf, BTreeSet<PathBuf>> {
    let mut out = BTreeMap::new();
    for (module, file) in &tree.files {
        let lines = code_lines(&std::fs::read_to_string(file).unwrap());
        let is_dir_module = module.is_empty() || file.file_name().is_some_and(|n| n == "mod.rs");
        let mut paths = named_paths(&lines);
        if is_dir_module {
            // Inline paths through a child module: `child::f()`.
            let code = lines.join("\n");
            let kids = tree.files.keys().filter(|m| m.len() == module.len() + 1 && m.starts_with(module));
            for kid in kids {
                let key = format!("{}::", kid[module.len()]);
                let mut from = 0;
                while let Some(i) = code[from..].find(&key) {
                    let at = from + i;
                    from = at + key.len();
                    if !code[..at].chars().last().is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':') {
                        paths.push(format!("self::{key}"));
                    }
                }
            }
        }
        let mut to = BTreeSet::new();
        for p in paths {
            if let Some(target) = resolve(&p, module, is_dir_module, tree) {
                if target.len() > module.len() && target.starts_with(module) {
                    continue; // a descendant: this module's own part
                }
                let t = &tree.files[&target];
                if t != file {
                    to.insert(t.clone());
                }
            }
        }
        out.insert(file.clone(), to);
    }
    out
}

/// The circles: groups of two or more files that reach each other (Tarjan).
fn circles(arrows: &BTreeMap<PathBuf, BTreeSet<PathBuf>>) -> Vec<Vec<PathBuf>> {
    struct State<'a> {
        arrows: &'a BTreeMap<PathBuf, BTreeSet<PathBuf>>,
        index: BTreeMap<&'a PathBuf, usize>,
        low: BTreeMap<&'a PathBuf, usize>,
        stack: Vec<&'a PathBuf>,
        on: BTreeSet<&'a PathBuf>,
        out: Vec<Vec<PathBuf>>,
    }
    fn visit<'a>(s: &mut State<'a>, v: &'a PathBuf) {
        let n = s.index.len();
        s.index.insert(v, n);
        s.low.insert(v, n);
        s.stack.push(v);
        s.on.insert(v);
        for w in s.arrows.get(v).into_iter().flatten() {
            if !s.index.contains_key(w) {
                let w = s.arrows.get_key_value(w).map(|(k, _)| k).unwrap_or(w);
                visit(s, w);
                let lw = s.low[w];
                let lv = s.low.get_mut(v).unwrap();
                *lv = (*lv).min(lw);
            } else if s.on.contains(w) {
                let iw = s.index[w];
                let lv = s.low.get_mut(v).unwrap();
                *lv = (*lv).min(iw);
            }
        }
        if s.low[v] == s.index[v] {
            let mut group = Vec::new();
            while let Some(w) = s.stack.pop() {
                s.on.remove(w);
                group.push(w.clone());
                if w == v {
                    break;
                }
            }
            if group.len() > 1 {
                group.sort();
                s.out.push(group);
            }
        }
    }
    let mut s = State {
        arrows,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on: BTreeSet::new(),
        out: Vec::new(),
    };
    for v in arrows.keys() {
        if !s.index.contains_key(v) {
            visit(&mut s, v);
        }
    }
    s.out
}

/// The crate roots of a crate folder: src/lib.rs and src/main.rs.
fn roots(dir: &Path) -> Vec<PathBuf> {
    ["src/lib.rs", "src/main.rs"].iter().map(|r| dir.join(r)).filter(|p| p.is_file()).collect()
}

/// The evflow crates a Cargo.toml depends on, in its `[dependencies]` and
/// its `[dev-dependencies]` (a test that imports a crate above is an arrow
/// up too, and with that crate's own dependency, a circle).
fn evflow_dependencies(manifest: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(manifest).unwrap();
    let mut section = String::new();
    let mut deps = Vec::new();
    for line in text.lines() {
        let t = line.trim();
        if t.starts_with('[') {
            section = t.to_string();
        } else if section == "[dependencies]" || section == "[dev-dependencies]" {
            let name = t.split(['=', ' ', '.']).next().unwrap_or("");
            if name.starts_with("evflow") {
                deps.push(name.to_string());
            }
        }
    }
    deps
}

#[test]
fn each_layer_depends_only_on_the_layers_below() {
    let root = evflow_tests::root();
    for (k, (name, dir)) in LAYERS.iter().enumerate() {
        let below: Vec<&str> = LAYERS[..k].iter().map(|(n, _)| *n).collect();
        for dep in evflow_dependencies(&root.join(dir).join("Cargo.toml")) {
            assert!(below.contains(&dep.as_str()), "{name} ({dir}/Cargo.toml) depends on {dep}, which is not below it");
        }
    }
}

#[test]
fn no_source_files_import_each_other() {
    // EVFLOW_LAYERS_ROOT: another checkout to read (e.g. an older commit).
    let root = std::env::var_os("EVFLOW_LAYERS_ROOT").map_or_else(evflow_tests::root, PathBuf::from);
    let mut found = Vec::new();
    let mut files = 0;
    for (_, dir) in LAYERS {
        for r in roots(&root.join(dir)) {
            let t = tree(&r);
            files += t.files.len();
            let a = arrows(&t);
            let name = |p: &PathBuf| p.strip_prefix(&root).unwrap_or(p).display().to_string();
            for c in circles(&a) {
                // Each arrow of the circle, so that the one to cut can be chosen.
                let within: Vec<String> = c
                    .iter()
                    .flat_map(|f| a[f].iter().filter(|t| c.contains(t)).map(move |t| (f, t)))
                    .map(|(f, t)| format!("  {} → {}", name(f), name(t)))
                    .collect();
                found.push(format!("{} files:\n{}", c.len(), within.join("\n")));
            }
        }
    }
    assert!(files > 250, "only {files} files read: is the tree walk right?");
    assert!(found.is_empty(), "import circles:\n{}", found.join("\n"));
}

/// Writes a made-up crate under `dir`: `files` as (path under src, text).
fn crate_of(dir: &Path, files: &[(&str, &str)]) -> PathBuf {
    for (p, text) in files {
        let at = dir.join("src").join(p);
        std::fs::create_dir_all(at.parent().unwrap()).unwrap();
        std::fs::write(at, text).unwrap();
    }
    dir.join("src/lib.rs")
}

fn circles_of(files: &[(&str, &str)]) -> Vec<Vec<String>> {
    let dir = tempfile::tempdir().unwrap();
    let root = crate_of(dir.path(), files);
    let src = dir.path().join("src");
    circles(&arrows(&tree(&root)))
        .into_iter()
        .map(|c| c.iter().map(|p| p.strip_prefix(&src).unwrap().display().to_string()).collect())
        .collect()
}

#[test]
fn the_reader_sees_circles_through_every_kind_of_path() {
    // Two siblings through `use crate::…` with braces.
    let c = circles_of(&[
        ("lib.rs", "pub mod a;\npub mod b;\n"),
        ("a.rs", "use crate::{b::{self, B}};\npub struct A;\n"),
        ("b.rs", "use crate::a::A;\npub struct B;\n"),
    ]);
    assert_eq!(c, [["a.rs", "b.rs"]]);
    // Two children through their parent: one uses what the parent re-exports
    // of the other (an inline child path), the other uses the first.
    let c = circles_of(&[
        ("lib.rs", "mod m;\nmod n;\n"),
        ("m/mod.rs", "mod k;\npub use k::K;\n"),
        ("m/k.rs", "pub struct K(crate::n::N);\n"),
        ("n.rs", "pub struct N;\nfn f() { let _: Option<crate::m::K> = None; }\n"),
    ]);
    assert_eq!(c, [["m/k.rs", "n.rs"]], "n → m::K, which is m/k's; m/k → n");
    // A loop of three through an inline path.
    let c = circles_of(&[
        ("lib.rs", "mod a;\nmod b;\nmod c;\n"),
        ("a.rs", "fn f() { crate::b::g() }\n"),
        ("b.rs", "pub fn g() { crate::c::h() }\n"),
        ("c.rs", "pub fn h() { let _ = crate::a::X; }\n"),
    ]);
    assert_eq!(c, [["a.rs", "b.rs", "c.rs"]]);
}

#[test]
fn tests_comments_declarations_and_other_crates_are_no_arrows() {
    let c = circles_of(&[
        ("lib.rs", "pub mod a;\npub mod b;\n"),
        ("a.rs", "use crate::b::B;\npub struct A;\n"),
        (
            "b.rs",
            "// use crate::a::A;\n/* crate::a::A */\n/// files/*.toml\npub struct B;\nuse std::fmt;\nuse other::a::A;\n\
             #[cfg(test)]\nmod tests {\n    use crate::a::A;\n    fn f() { let _ = super::super::a::A; }\n}\n",
        ),
    ]);
    assert!(c.is_empty(), "{c:?}");
    // A parent that declares, re-exports and calls its children, which use
    // what it holds: no circle.
    let c = circles_of(&[
        ("lib.rs", "pub mod m;\npub use m::Shared;\n"),
        ("m/mod.rs", "pub mod k;\npub use k::K;\npub struct Shared;\nfn f() { k::g() }\n"),
        ("m/k.rs", "use super::Shared;\nuse crate::Shared as S;\npub struct K;\npub fn g() {}\n"),
    ]);
    assert!(c.is_empty(), "{c:?}");
}

#[test]
fn a_dependency_on_a_higher_layer_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let manifest = dir.path().join("Cargo.toml");
    std::fs::write(
        &manifest,
        "[package]\nname = \"x\"\n\n[dependencies]\nevflow-engine.workspace = true\nevflow-study = { path = \"../study\" }\n\n[dev-dependencies]\nevflow = { path = \"../tools\" }\n",
    )
    .unwrap();
    // A dev-dependency counts: `tools` once dev-depended on `evflow-tests`,
    // which depends on `tools` — a circle through the tests.
    assert_eq!(evflow_dependencies(&manifest), ["evflow-engine", "evflow-study", "evflow"]);
}

/// Every `X.rs` in `dir` (recursively) beside a folder `X/` that holds
/// Rust files: a module with files of its own is written one way only,
/// as `X/mod.rs`.
fn file_and_folder_pairs(dir: &Path) -> Vec<PathBuf> {
    let holds_rust = |folder: &Path| {
        std::fs::read_dir(folder)
            .map(|es| es.flatten().any(|e| e.path().extension().is_some_and(|x| x == "rs")))
            .unwrap_or(false)
    };
    let mut found: Vec<PathBuf> = rust_files(dir).into_iter().filter(|p| holds_rust(&p.with_extension(""))).collect();
    found.sort();
    found
}

#[test]
fn a_module_with_files_is_a_folder_with_mod_rs() {
    let root = evflow_tests::root();
    let pairs: Vec<PathBuf> =
        LAYERS.iter().flat_map(|(_, dir)| file_and_folder_pairs(&root.join(dir).join("src"))).collect();
    assert!(pairs.is_empty(), "write these as FOLDER/mod.rs: {pairs:?}");
    // The reader sees a pair.
    let d = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(d.path().join("a")).unwrap();
    std::fs::write(d.path().join("a.rs"), "mod b;").unwrap();
    std::fs::write(d.path().join("a/b.rs"), "").unwrap();
    assert_eq!(file_and_folder_pairs(d.path()), [d.path().join("a.rs")]);
}

/// Every `.rs` file under `dir`, recursively.
fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let Ok(entries) = std::fs::read_dir(dir) else { return found };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            found.extend(rust_files(&p));
        } else if p.extension().is_some_and(|x| x == "rs") {
            found.push(p);
        }
    }
    found
}

/// Where `text`, its `//` comments cut, names one of rustfft's or rubato's
/// generic constructors: `(line number, line)`.
fn generic_dsp_constructors(text: &str) -> Vec<(usize, String)> {
    const NAMES: [&str; 5] = ["FftPlanner", "Async::<", "Async::new", "Fft::<f64>", "rubato::Fft"];
    text.lines()
        .enumerate()
        .filter(|(_, l)| {
            let code = l.split("//").next().unwrap_or("");
            NAMES.iter().any(|n| code.contains(n))
        })
        .map(|(i, l)| (i + 1, l.trim().to_string()))
        .collect()
}

#[test]
fn rustfft_and_rubato_are_instantiated_only_in_dsp() {
    // dsp/src/lib.rs: named anywhere else, the planner with all its
    // butterflies is compiled again there (and again for its unit tests).
    let root = evflow_tests::root();
    let mut found = Vec::new();
    for (_, dir) in LAYERS.iter().filter(|(_, d)| *d != "dsp").chain([&("evflow-tests", "tests")]) {
        // This file names them to look for them.
        for f in rust_files(&root.join(dir)).into_iter().filter(|f| !f.ends_with("tests/layers.rs")) {
            let text = std::fs::read_to_string(&f).unwrap();
            for (n, l) in generic_dsp_constructors(&text) {
                found.push(format!("{}:{n}: {l}", f.strip_prefix(&root).unwrap_or(&f).display()));
            }
        }
    }
    assert!(found.is_empty(), "use evflow_dsp::fft / evflow_dsp::resamplers instead:\n{}", found.join("\n"));
    // The reader sees a use, not a comment.
    let made_up = "let p = FftPlanner::new();\n// FftPlanner in a comment\nlet r = Async::<f64>::new_poly(1.0);";
    assert_eq!(generic_dsp_constructors(made_up).iter().map(|(n, _)| *n).collect::<Vec<_>>(), [1, 3]);
}
