//! The README and the docs stand on their own: every relative link points
//! at a file of the repository, nothing points outside it (the design notes
//! the project was started from are not part of a clone), and the crate
//! docs do not defer to the README.

use std::path::{Component, Path, PathBuf};

/// The repository (this package is its `tests/` folder).
const ROOT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/..");

/// README.md, docs/*.md, and the Rust sources whose comments become docs.
fn documents() -> Vec<PathBuf> {
    let root = Path::new(ROOT);
    let mut files = vec![root.join("README.md")];
    let mut stack = vec![
        root.join("docs"),
        root.join("src"),
        root.join("runtime/src"),
        root.join("codegen/src"),
        root.join("macros/src"),
    ];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).expect("a source folder") {
            let path = entry.expect("an entry").path();
            if path.is_dir() {
                stack.push(path);
            } else if matches!(path.extension().and_then(|e| e.to_str()), Some("md" | "rs")) {
                files.push(path);
            }
        }
    }
    files
}

/// The targets of Markdown links `[text](target)` and `src="target"`.
fn link_targets(text: &str) -> Vec<String> {
    let mut targets = Vec::new();
    for (open, close) in [("](", ')'), ("src=\"", '"')] {
        let mut rest = text;
        while let Some(i) = rest.find(open) {
            rest = &rest[i + open.len()..];
            if let Some(end) = rest.find(close) {
                targets.push(rest[..end].to_string());
            }
        }
    }
    targets
}

/// `path` with `.` and `..` resolved lexically, or `None` if it climbs
/// above the start.
fn normalise(path: &Path) -> Option<PathBuf> {
    let mut out = PathBuf::new();
    for c in path.components() {
        match c {
            Component::ParentDir => {
                if !out.pop() {
                    return None;
                }
            }
            Component::CurDir => {}
            other => out.push(other),
        }
    }
    Some(out)
}

#[test]
fn links_stay_inside_the_repository() {
    let root = Path::new(ROOT);
    let mut broken = Vec::new();
    for file in documents() {
        let text = std::fs::read_to_string(&file).expect("readable");
        let name = file
            .strip_prefix(root)
            .unwrap_or(&file)
            .display()
            .to_string();
        if text.contains("../shared") {
            broken.push(format!(
                "{name}: mentions ../shared, which is not in the repository"
            ));
        }
        if file.extension().is_some_and(|e| e == "rs") {
            continue; // Rust sources: only the mention above (their links are intra-doc)
        }
        for target in link_targets(&text) {
            let target = target.split('#').next().unwrap_or("").trim().to_string();
            if target.is_empty() || target.contains("://") || target.starts_with("mailto:") {
                continue;
            }
            let relative = file
                .parent()
                .expect("in a folder")
                .strip_prefix(root)
                .expect("inside");
            match normalise(&relative.join(&target)) {
                Some(resolved) if root.join(&resolved).exists() => {}
                Some(resolved) => broken.push(format!(
                    "{name}: {target} → {} does not exist",
                    resolved.display()
                )),
                None => broken.push(format!("{name}: {target} leaves the repository")),
            }
        }
    }
    assert!(broken.is_empty(), "{}", broken.join("\n"));
}

/// The guides link to each other by name, not by path: the same file is a
/// rustdoc module, where a relative `.md` link would break.
#[test]
fn guides_have_no_relative_links() {
    for file in std::fs::read_dir(Path::new(ROOT).join("docs")).expect("docs/") {
        let path = file.expect("an entry").path();
        if path.extension().is_some_and(|e| e == "md") {
            let text = std::fs::read_to_string(&path).expect("readable");
            let relative: Vec<String> = link_targets(&text)
                .into_iter()
                .filter(|t| !t.contains("://"))
                .collect();
            assert!(relative.is_empty(), "{}: {relative:?}", path.display());
        }
    }
}

#[test]
fn crate_docs_do_not_defer_to_the_readme() {
    let lib = std::fs::read_to_string(Path::new(ROOT).join("src/lib.rs")).expect("src/lib.rs");
    let docs: String = lib
        .lines()
        .filter(|l| l.trim_start().starts_with("//!") || l.trim_start().starts_with("///"))
        .collect();
    assert!(
        !docs.contains("README"),
        "the crate docs refer to the README"
    );
}
