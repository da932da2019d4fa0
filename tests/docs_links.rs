//! The docs' pointers hold: every relative link in the README, the book (`docs/`), the crates'
//! READMEs and `models/README.md` names a file that exists and, with `#anchor`, a heading in it;
//! every `docs/PAGE.md#anchor` cited in the code, tests, scenarios and models does too; and no file
//! cites a path outside the repository (`../shared/...`), which a user of the repository does not
//! have.
//!
//! Anchors follow mdBook's rule (GitHub's agrees for the headings used here): the heading in lower
//! case, letters, digits, `-` and `_` kept, spaces turned to `-`, everything else dropped.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Files under `dir` (recursively) whose name ends with one of `exts`, skipping build output.
fn files(dir: &Path, exts: &[&str], out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for entry in entries.flatten() {
        let path = entry.path();
        let name = entry.file_name().to_string_lossy().into_owned();
        if path.is_dir() {
            if !matches!(name.as_str(), "target" | "vendor" | ".git" | "node_modules") {
                files(&path, exts, out);
            }
        } else if exts.iter().any(|e| name.ends_with(e)) {
            out.push(path);
        }
    }
}

/// mdBook's anchor for a heading's text.
fn anchor(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter_map(|c| match c {
            c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c),
            c if c.is_whitespace() => Some('-'),
            _ => None,
        })
        .collect()
}

/// The text of a markdown file outside its fenced code blocks, with mdBook's
/// `{{#include FILE}}` expanded.
fn prose(file: &Path) -> String {
    let text = std::fs::read_to_string(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    let mut out = String::new();
    let mut fenced = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced {
            continue;
        }
        if let Some(inc) = line.trim().strip_prefix("{{#include ").and_then(|l| l.strip_suffix("}}")) {
            out.push_str(&prose(&file.parent().unwrap().join(inc.trim())));
        } else {
            out.push_str(line);
        }
        out.push('\n');
    }
    out
}

/// The anchors of a markdown file's headings.
fn anchors(file: &Path) -> BTreeSet<String> {
    prose(file)
        .lines()
        .filter(|l| l.starts_with('#'))
        .map(|l| anchor(l.trim_start_matches('#').replace('`', "").as_str()))
        .collect()
}

/// Checks `target` (`path`, `path#anchor` or `#anchor`) relative to `base_dir`, for `from`.
fn check(from: &Path, base_dir: &Path, target: &str, errors: &mut Vec<String>) {
    let (path, fragment) = match target.split_once('#') {
        Some((p, f)) => (p, Some(f)),
        None => (target, None),
    };
    let file = if path.is_empty() { from.to_path_buf() } else { base_dir.join(path) };
    let shown = from.strip_prefix(root()).unwrap_or(from).display().to_string();
    if !file.exists() {
        errors.push(format!("{shown}: `{target}`: no such file"));
        return;
    }
    if let Some(fragment) = fragment
        && file.extension().is_some_and(|e| e == "md")
        && !anchors(&file).contains(fragment)
    {
        errors.push(format!("{shown}: `{target}`: no heading with that anchor"));
    }
}

/// The targets of a markdown text's inline links and images, `[text](target)`.
fn link_targets(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = text;
    while let Some(i) = rest.find("](") {
        rest = &rest[i + 2..];
        let end = rest.find(')').unwrap_or(rest.len());
        let target = rest[..end].split_whitespace().next().unwrap_or("").trim_matches(['<', '>']);
        if !target.is_empty() && !target.contains("://") && !target.starts_with("mailto:") {
            out.push(target.to_string());
        }
    }
    out
}

#[test]
fn every_relative_link_in_the_docs_resolves() {
    let root = root();
    let mut pages = vec![root.join("README.md"), root.join("models/README.md")];
    files(&root.join("docs"), &[".md"], &mut pages);
    files(&root.join("crates"), &["README.md"], &mut pages);
    assert!(pages.len() > 40, "found only {} pages", pages.len());
    let mut errors = Vec::new();
    let mut links = 0;
    for page in &pages {
        for target in link_targets(&prose(page)) {
            links += 1;
            check(page, page.parent().unwrap(), &target, &mut errors);
        }
    }
    assert!(links > 100, "found only {links} links");
    assert!(errors.is_empty(), "broken links:\n{}", errors.join("\n"));
}

#[test]
fn every_book_page_the_code_cites_exists_with_its_anchor() {
    let root = root();
    let mut sources = Vec::new();
    for dir in ["src", "crates", "tests", "benches", "scenarios", "models", "xtask"] {
        files(&root.join(dir), &[".rs", ".toml", ".xml", ".script", ".md"], &mut sources);
    }
    let mut errors = Vec::new();
    let mut citations = 0;
    for source in &sources {
        let shown = source.strip_prefix(&root).unwrap().display().to_string();
        if shown == "tests/docs_links.rs" {
            continue; // it names the patterns it looks for
        }
        let text = std::fs::read_to_string(source).unwrap();
        if text.contains("../shared/") || text.contains("shared/reference") {
            errors.push(format!("{shown}: cites a path outside the repository (../shared/...)"));
        }
        for (i, _) in text.match_indices("docs/") {
            // Only a citation of a page: `docs/` at a word's start, then a path ending in `.md`.
            if i > 0 && text.as_bytes()[i - 1].is_ascii_alphanumeric() {
                continue;
            }
            let cited: String = text[i..].chars().take_while(|c| c.is_alphanumeric() || "/._-#".contains(*c)).collect();
            let cited = cited.trim_end_matches(['.', '#']);
            if cited.split('#').next().is_some_and(|p| p.ends_with(".md")) {
                citations += 1;
                check(source, &root, cited, &mut errors);
            }
        }
    }
    assert!(citations > 30, "found only {citations} citations of book pages");
    assert!(errors.is_empty(), "broken citations:\n{}", errors.join("\n"));
}

#[test]
fn anchors_follow_mdbooks_rule() {
    assert_eq!(
        anchor("Why the shampoo's drop used to move with the step"),
        "why-the-shampoos-drop-used-to-move-with-the-step"
    );
    assert_eq!(anchor("Scenario keys: [hardware]"), "scenario-keys-hardware");
    assert_eq!(anchor("Rapier 0.36"), "rapier-036");
    assert_eq!(link_targets("see [a](docs/x.md#y) and ![b](img/c.png \"t\")"), ["docs/x.md#y", "img/c.png"]);
}
