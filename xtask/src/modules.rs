//! The module graph of one crate, read from its source files: which file imports which, and the
//! loops among them.
//!
//! A crate's modules are its files under `src/` (`lib.rs` or `main.rs` the root, `a/mod.rs` or
//! `a.rs` the module `a`). A file imports another when a path in its code (`use` trees and paths
//! written inline, outside comments and outside `#[cfg(test)]` modules) starts at `crate::`,
//! `super::` or `self::` and names that module, or an item in it. A *face* (a file that only
//! declares modules and hands names on with `pub use`, as a `mod.rs` or `lib.rs` may) is no
//! room of its own: a path through it is followed to the module its `pub use` names, so
//! `crate::physics::Physics` imports `physics/engine.rs` when `physics/mod.rs` says
//! `pub use engine::Physics`, and a child using its parent's re-export of the child's own item
//! ties nothing. A name a face does not re-export by name (a glob, another crate's item) ties
//! nothing.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// A module: its path from the crate root (`["physics", "scene"]`) and its file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Module {
    /// Path segments below the crate root (empty: the root).
    pub path: Vec<String>,
    /// The source file, relative to the crate directory.
    pub file: PathBuf,
    /// Whether the file only declares modules and re-exports (see the module docs).
    pub face: bool,
}

/// One import between two modules, with the names used.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
pub struct Edge {
    /// Importing file.
    pub from: PathBuf,
    /// Imported file.
    pub to: PathBuf,
    /// The paths as written, after the module (`Phase`, `task::Phase`), sorted.
    pub names: BTreeSet<String>,
}

/// A crate's modules and the imports between them.
#[derive(Debug, Default)]
pub struct Graph {
    /// Every module.
    pub modules: Vec<Module>,
    /// Imports between different modules, neither of them a face.
    pub edges: Vec<Edge>,
}

/// Reads the modules of the crate whose `src` folder is `src` (files given as (path below
/// `src`, text), so tests can give trees that are not on disk).
pub fn graph(files: &[(PathBuf, String)]) -> Graph {
    let modules: Vec<Module> = files
        .iter()
        .filter_map(|(file, text)| {
            module_path(file).map(|path| Module { path, file: file.clone(), face: is_face(text) })
        })
        .collect();
    let by_path: BTreeMap<&[String], &Module> = modules.iter().map(|m| (m.path.as_slice(), m)).collect();
    let faces: BTreeMap<&[String], Vec<(String, String)>> = modules
        .iter()
        .filter(|m| m.face)
        .filter_map(|m| files.iter().find(|(f, _)| f == &m.file).map(|(_, text)| (m.path.as_slice(), re_exports(text))))
        .collect();
    let mut edges: BTreeMap<(PathBuf, PathBuf), BTreeSet<String>> = BTreeMap::new();
    for (file, text) in files {
        let Some(me) = modules.iter().find(|m| &m.file == file) else { continue };
        if me.face {
            continue;
        }
        for written in paths(&strip(text)) {
            let Some((target, rest)) = resolve_through_faces(&written, &me.path, &by_path, &faces) else { continue };
            if target.file == me.file || target.face {
                continue;
            }
            edges.entry((me.file.clone(), target.file.clone())).or_default().insert(rest);
        }
    }
    let edges = edges.into_iter().map(|((from, to), names)| Edge { from, to, names }).collect();
    Graph { modules, edges }
}

/// Reads every `.rs` file under `src` (a crate's source folder).
pub fn read_tree(src: &Path) -> std::io::Result<Vec<(PathBuf, String)>> {
    let mut out = Vec::new();
    let mut stack = vec![src.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir)? {
            let path = entry?.path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                let rel = path.strip_prefix(src).expect("below src").to_path_buf();
                out.push((rel, std::fs::read_to_string(&path)?));
            }
        }
    }
    out.sort();
    Ok(out)
}

/// The loops of the graph: each strongly connected set of two or more files, with its edges.
pub fn loops(g: &Graph) -> Vec<Vec<&Edge>> {
    let files: Vec<&PathBuf> = g.modules.iter().map(|m| &m.file).collect();
    let index = |f: &PathBuf| files.iter().position(|x| *x == f).expect("an edge joins known files");
    let mut next: Vec<Vec<usize>> = vec![Vec::new(); files.len()];
    for e in &g.edges {
        next[index(&e.from)].push(index(&e.to));
    }
    tarjan(&next)
        .into_iter()
        .filter(|scc| scc.len() > 1)
        .map(|scc| {
            let set: BTreeSet<usize> = scc.into_iter().collect();
            g.edges.iter().filter(|e| set.contains(&index(&e.from)) && set.contains(&index(&e.to))).collect()
        })
        .collect()
}

/// Strongly connected components (Tarjan), as node indices.
fn tarjan(next: &[Vec<usize>]) -> Vec<Vec<usize>> {
    struct State<'a> {
        next: &'a [Vec<usize>],
        index: Vec<Option<usize>>,
        low: Vec<usize>,
        on_stack: Vec<bool>,
        stack: Vec<usize>,
        counter: usize,
        out: Vec<Vec<usize>>,
    }
    fn visit(s: &mut State, v: usize) {
        s.index[v] = Some(s.counter);
        s.low[v] = s.counter;
        s.counter += 1;
        s.stack.push(v);
        s.on_stack[v] = true;
        for i in 0..s.next[v].len() {
            let w = s.next[v][i];
            match s.index[w] {
                None => {
                    visit(s, w);
                    s.low[v] = s.low[v].min(s.low[w]);
                }
                Some(iw) if s.on_stack[w] => s.low[v] = s.low[v].min(iw),
                Some(_) => {}
            }
        }
        if Some(s.low[v]) == s.index[v] {
            let mut scc = Vec::new();
            while let Some(w) = s.stack.pop() {
                s.on_stack[w] = false;
                scc.push(w);
                if w == v {
                    break;
                }
            }
            s.out.push(scc);
        }
    }
    let n = next.len();
    let mut s = State {
        next,
        index: vec![None; n],
        low: vec![0; n],
        on_stack: vec![false; n],
        stack: Vec::new(),
        counter: 0,
        out: Vec::new(),
    };
    for v in 0..n {
        if s.index[v].is_none() {
            visit(&mut s, v);
        }
    }
    s.out
}

/// The module path of a file below `src` (`lib.rs`/`main.rs`: the root; `a/mod.rs`, `a.rs`: `a`).
/// Files of a binary's own (`src/bin/`) are not modules of the library.
fn module_path(file: &Path) -> Option<Vec<String>> {
    let mut parts: Vec<String> = file.iter().map(|p| p.to_string_lossy().into_owned()).collect();
    if parts.first().is_some_and(|p| p == "bin") {
        return None;
    }
    let last = parts.pop()?;
    match last.as_str() {
        "lib.rs" | "main.rs" if parts.is_empty() => {}
        "mod.rs" => {}
        name => parts.push(name.strip_suffix(".rs")?.to_string()),
    }
    Some(parts)
}

/// Whether a file only declares modules and re-exports (and holds docs and attributes).
fn is_face(text: &str) -> bool {
    // Inside a `pub use a::{...};` that spans lines, until its `;`.
    let mut in_use = false;
    strip(text).lines().map(str::trim).filter(|l| !l.is_empty()).all(|l| {
        if in_use {
            in_use = !l.ends_with(';');
            return l.chars().all(|c| c.is_alphanumeric() || "_:{}, ;*".contains(c));
        }
        let re_export = l.starts_with("pub use ") || l.starts_with("pub(crate) use ");
        if re_export {
            in_use = !l.ends_with(';');
        }
        re_export
            || l.starts_with("#!")
            || l.starts_with("#[")
            || l.starts_with("pub mod ")
            || l.starts_with("mod ")
            || l.starts_with("pub(crate) mod ")
    })
}

/// The text without comments, string literals and `#[cfg(test)]` modules.
pub fn strip(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let b = text.as_bytes();
    let mut i = 0;
    while i < b.len() {
        if b[i..].starts_with(b"//") {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
        } else if b[i..].starts_with(b"/*") {
            i += 2;
            while i < b.len() && !b[i..].starts_with(b"*/") {
                i += 1;
            }
            i += 2;
        } else if b[i] == b'"' {
            i += 1;
            while i < b.len() && b[i] != b'"' {
                i += if b[i] == b'\\' { 2 } else { 1 };
            }
            i += 1;
            out.push_str("\"\"");
        } else if b[i..].starts_with(b"#[cfg(test)]") {
            // Skip the item that follows: up to its matching closing brace (or semicolon).
            i += "#[cfg(test)]".len();
            let mut depth = 0usize;
            while i < b.len() {
                match b[i] {
                    b'{' => depth += 1,
                    b'}' => {
                        depth = depth.saturating_sub(1);
                        if depth == 0 {
                            i += 1;
                            break;
                        }
                    }
                    b';' if depth == 0 => {
                        i += 1;
                        break;
                    }
                    _ => {}
                }
                i += 1;
            }
        } else {
            out.push(b[i] as char);
            i += 1;
        }
    }
    out
}

/// Every path written in `code` that starts at `crate`, `super` or `self`, with `use` trees
/// expanded (`use super::{a::B, c}` gives `super::a::B` and `super::c`).
fn paths(code: &str) -> Vec<String> {
    let mut out = Vec::new();
    // `use` trees first, then inline paths outside them.
    let mut rest = String::new();
    let mut i = 0;
    while let Some(at) = code[i..].find("use ") {
        let start = i + at;
        let boundary =
            start == 0 || !code.as_bytes()[start - 1].is_ascii_alphanumeric() && code.as_bytes()[start - 1] != b'_';
        rest.push_str(&code[i..start]);
        if !boundary {
            rest.push_str("use ");
            i = start + 4;
            continue;
        }
        let end = code[start..].find(';').map_or(code.len(), |e| start + e);
        let mut named = Vec::new();
        expand(code[start + 4..end].trim(), "", &mut named);
        out.extend(named.into_iter().map(|(_, path)| path));
        i = end;
    }
    rest.push_str(&code[i..]);
    for root in ["crate::", "super::", "self::"] {
        let mut from = 0;
        while let Some(at) = rest[from..].find(root) {
            let start = from + at;
            let before = rest[..start].chars().last();
            from = start + root.len();
            if before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':') {
                continue;
            }
            let len = rest[start..]
                .find(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
                .unwrap_or(rest.len() - start);
            out.push(rest[start..start + len].trim_end_matches(':').to_string());
        }
    }
    out.retain(|p| p.starts_with("crate::") || p.starts_with("super::") || p.starts_with("self::") || p == "crate");
    out
}

/// The names a file hands on with `pub use` (or `pub(crate) use`), each with the path it names
/// as written (`pub use engine::Physics as Engine;` gives (`Engine`, `engine::Physics`)).
fn re_exports(text: &str) -> Vec<(String, String)> {
    let code = strip(text);
    let mut out = Vec::new();
    for opener in ["pub use ", "pub(crate) use "] {
        let mut from = 0;
        while let Some(at) = code[from..].find(opener) {
            let start = from + at + opener.len();
            let end = code[start..].find(';').map_or(code.len(), |e| start + e);
            expand(code[start..end].trim(), "", &mut out);
            from = end;
        }
    }
    out
}

/// Expands one `use` tree below `prefix` into (the name it brings in, the path it names).
fn expand(tree: &str, prefix: &str, out: &mut Vec<(String, String)>) {
    let tree = tree.trim();
    if let Some(open) = tree.find('{') {
        let head = tree[..open].trim().trim_end_matches("::");
        let inner = &tree[open + 1..tree.rfind('}').unwrap_or(tree.len())];
        let prefix = join(prefix, head);
        let mut depth = 0;
        let mut part = String::new();
        for c in inner.chars() {
            match c {
                '{' => depth += 1,
                '}' => depth -= 1,
                ',' if depth == 0 => {
                    expand(&part, &prefix, out);
                    part.clear();
                    continue;
                }
                _ => {}
            }
            part.push(c);
        }
        expand(&part, &prefix, out);
    } else if !tree.is_empty() {
        let mut parts = tree.split(" as ");
        let tree = parts.next().unwrap_or(tree).trim();
        let path = if tree != "self" { join(prefix, tree) } else { prefix.to_string() };
        let name = parts.next().map(str::trim).unwrap_or_else(|| path.rsplit("::").next().unwrap_or(&path));
        out.push((name.to_string(), path));
    }
}

fn join(prefix: &str, tail: &str) -> String {
    match (prefix.is_empty(), tail.is_empty()) {
        (true, _) => tail.to_string(),
        (_, true) => prefix.to_string(),
        _ => format!("{prefix}::{tail}"),
    }
}

/// [`resolve`], then through each face the path lands on to the module the face's `pub use`
/// names; `None` when the path ends at a face (the module itself, or a name it does not
/// re-export by name).
fn resolve_through_faces<'a>(
    written: &str,
    me: &[String],
    by_path: &BTreeMap<&[String], &'a Module>,
    faces: &BTreeMap<&[String], Vec<(String, String)>>,
) -> Option<(&'a Module, String)> {
    let mut written = written.to_string();
    let mut from = me.to_vec();
    // Faces re-exporting each other in a ring would never end: a crate is never this deep.
    for _ in 0..16 {
        let (target, rest) = resolve(&written, &from, by_path)?;
        if !target.face {
            return Some((target, rest));
        }
        let (first, tail) = rest.split_once("::").unwrap_or((rest.as_str(), ""));
        let (_, path) = faces.get(target.path.as_slice())?.iter().find(|(name, _)| name == first)?;
        let rooted = ["crate", "self", "super"].iter().any(|r| path == r || path.starts_with(&format!("{r}::")));
        written = match (rooted, tail.is_empty()) {
            (true, true) => path.clone(),
            (true, false) => format!("{path}::{tail}"),
            (false, true) => format!("self::{path}"),
            (false, false) => format!("self::{path}::{tail}"),
        };
        from = target.path.clone();
    }
    None
}

/// The module a path written in module `me` names (the longest module prefix), and the rest of
/// the path after it.
fn resolve<'a>(
    written: &str,
    me: &[String],
    by_path: &BTreeMap<&[String], &'a Module>,
) -> Option<(&'a Module, String)> {
    let mut segs: Vec<&str> = written.split("::").filter(|s| !s.is_empty()).collect();
    let mut base: Vec<String> = match *segs.first()? {
        "crate" => {
            segs.remove(0);
            Vec::new()
        }
        "self" => {
            segs.remove(0);
            me.to_vec()
        }
        "super" => {
            let mut b = me.to_vec();
            while segs.first() == Some(&"super") {
                segs.remove(0);
                b.pop()?;
            }
            b
        }
        _ => return None,
    };
    let mut found = by_path.get(base.as_slice()).copied().map(|m| (m, 0));
    for (i, s) in segs.iter().enumerate() {
        base.push((*s).to_string());
        match by_path.get(base.as_slice()) {
            Some(m) => found = Some((m, i + 1)),
            None => break,
        }
    }
    let (module, used) = found?;
    Some((module, segs[used..].join("::")))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tree(files: &[(&str, &str)]) -> Vec<(PathBuf, String)> {
        files.iter().map(|(p, t)| (PathBuf::from(p), t.to_string())).collect()
    }

    #[test]
    fn a_loop_is_found_with_the_names_that_tie_it() {
        let g = graph(&tree(&[
            ("lib.rs", "pub mod a;\npub mod b;\n"),
            ("a.rs", "use crate::b::Beta;\npub struct Alpha;\n"),
            ("b.rs", "use super::a::{Alpha, self};\npub struct Beta;\n// use crate::c::Gamma;\n"),
        ]));
        let loops = loops(&g);
        assert_eq!(loops.len(), 1);
        let text: Vec<String> =
            loops[0].iter().map(|e| format!("{} -> {}: {:?}", e.from.display(), e.to.display(), e.names)).collect();
        assert_eq!(text, ["a.rs -> b.rs: {\"Beta\"}", "b.rs -> a.rs: {\"\", \"Alpha\"}"]);
    }

    #[test]
    fn faces_tests_comments_and_strings_tie_nothing() {
        let g = graph(&tree(&[
            ("lib.rs", "//! Docs.\npub mod physics;\npub use physics::Scene;\n"),
            ("physics/mod.rs", "mod scene;\npub use scene::{\n    Scene,\n};\n"),
            // A child using its parent's re-export: the parent is a face.
            ("physics/scene.rs", "use super::Scene as S;\npub struct Scene;\nconst T: &str = \"crate::x\";\n"),
            ("x.rs", "pub fn f() { crate::physics::scene::Scene; }\n#[cfg(test)]\nmod tests { use crate::y::Y; }\n"),
            ("y.rs", "/* crate::x::f */ pub struct Y; fn g() { crate::x::f() }\n"),
        ]));
        assert!(loops(&g).is_empty(), "{:?}", g.edges);
        assert_eq!(g.edges.len(), 2, "x -> scene and y -> x: {:?}", g.edges);
    }

    #[test]
    fn an_inline_path_loop_through_a_face_is_found() {
        // The shape of a loop once left in tendril-twin: `frames` names the trait through the
        // `physics` face, `physics/engine.rs` names the snapshot in `frames`, both inline.
        let g = graph(&tree(&[
            ("lib.rs", "pub mod frames;\npub mod physics;\n"),
            ("physics/mod.rs", "mod engine;\npub use engine::Physics as Engine;\npub use engine::{Other};\n"),
            ("physics/engine.rs", "pub trait Physics { fn s(&self) -> Option<crate::frames::Snapshot>; }\n"),
            ("frames.rs", "pub struct Snapshot;\npub fn offer(p: &dyn crate::physics::Engine) {}\n"),
        ]));
        let loops = loops(&g);
        assert_eq!(loops.len(), 1, "{:?}", g.edges);
        let text: Vec<String> =
            loops[0].iter().map(|e| format!("{} -> {}: {:?}", e.from.display(), e.to.display(), e.names)).collect();
        assert_eq!(
            text,
            ["frames.rs -> physics/engine.rs: {\"Physics\"}", "physics/engine.rs -> frames.rs: {\"Snapshot\"}"]
        );
    }

    #[test]
    fn module_paths_follow_the_file_layout() {
        assert_eq!(module_path(Path::new("lib.rs")), Some(vec![]));
        assert_eq!(module_path(Path::new("a/mod.rs")), Some(vec!["a".to_string()]));
        assert_eq!(module_path(Path::new("a/b.rs")), Some(vec!["a".to_string(), "b".to_string()]));
        assert_eq!(module_path(Path::new("bin/tool.rs")), None);
    }
}
