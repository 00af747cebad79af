//! The README and the docs stand on their own: every relative link points
//! at a file of the repository, nothing points outside it (the design notes
//! the project was started from are not part of a clone), and the crate
//! docs do not defer to the README; and the README and the code's comments
//! carry no history (dates, commit hashes, superseded timings).

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
        let name = repository_path(&file);
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

/// The README is an introduction, not a diary.
const README_MAX_LINES: usize = 250;

/// Where comments must say why, not when or how fast it once was.
const COMMENTED_SOURCES: [&str; 4] = ["src", "runtime/src", "codegen/src", "macros/src"];

/// Every `.rs` file under `dir`.
fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).expect("a source folder") {
            let path = entry.expect("an entry").path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                files.push(path);
            }
        }
    }
    files
}

/// A date written `YYYY-MM-DD` (years 1900–2099, a real month and day).
fn date_in(line: &str) -> Option<&str> {
    let b = line.as_bytes();
    let digits = |r: std::ops::Range<usize>| b[r].iter().all(u8::is_ascii_digit);
    let number = |r: std::ops::Range<usize>| line[r].parse::<u32>().unwrap_or(0);
    (0..b.len().saturating_sub(9)).find_map(|i| {
        let fits = digits(i..i + 4)
            && b[i + 4] == b'-'
            && digits(i + 5..i + 7)
            && b[i + 7] == b'-'
            && digits(i + 8..i + 10)
            && (i == 0 || !b[i - 1].is_ascii_digit())
            && b.get(i + 10).is_none_or(|c| !c.is_ascii_digit());
        (fits
            && (1900..2100).contains(&number(i..i + 4))
            && (1..=12).contains(&number(i + 5..i + 7))
            && (1..=31).contains(&number(i + 8..i + 10)))
        .then(|| &line[i..i + 10])
    })
}

/// A word that looks like a commit hash: 7 to 40 lowercase hex digits with
/// at least one digit and one letter, standing alone (not part of an
/// identifier, not a `0x` literal).
fn hash_in(line: &str) -> Option<&str> {
    let is_word = |c: char| c.is_alphanumeric() || c == '_';
    let mut start = None;
    for (i, c) in line.char_indices().chain([(line.len(), ' ')]) {
        match (start, is_word(c)) {
            (None, true) => start = Some(i),
            (Some(s), false) => {
                let word = &line[s..i];
                let hex = word.bytes().all(|c| matches!(c, b'0'..=b'9' | b'a'..=b'f'));
                let mixed = word.bytes().any(|c| c.is_ascii_digit())
                    && word.bytes().any(|c| c.is_ascii_lowercase());
                let literal = line[..s].ends_with("0x") || line[..s].ends_with("0X");
                if hex && mixed && (7..=40).contains(&word.len()) && !literal {
                    return Some(word);
                }
                start = None;
            }
            _ => {}
        }
    }
    None
}

/// A time figure (`2.5 µs`, `45 s`, `8 min`) in a sentence that says it
/// changed: a superseded timing.
fn timing_history_in(line: &str) -> Option<&'static str> {
    const UNITS: [&str; 9] = [
        "ns", "µs", "us", "ms", "s", "min", "minutes", "seconds", "h",
    ];
    const MARKERS: [&str; 12] = [
        " was ",
        " were ",
        "used to",
        "previously",
        "earlier",
        "→",
        "went from",
        "became",
        "before",
        "instead of",
        "down from",
        "up from",
    ];
    let words: Vec<&str> = line
        .split(|c: char| c.is_whitespace() || matches!(c, ',' | ';' | '(' | ')' | '`'))
        .filter(|w| !w.is_empty())
        .collect();
    let figure = words.windows(2).any(|w| {
        let number = w[0].trim_start_matches(['~', '≈']).replace(['.', ','], "");
        let unit = w[1].trim_end_matches(['.', ':']);
        !number.is_empty() && number.bytes().all(|c| c.is_ascii_digit()) && UNITS.contains(&unit)
    }) || words.iter().any(|w| {
        let w = w.trim_end_matches(['.', ':']);
        UNITS.iter().any(|u| {
            w.strip_suffix(u).is_some_and(|n| {
                let n = n.replace(['.', ','], "");
                !n.is_empty() && n.bytes().all(|c| c.is_ascii_digit())
            })
        })
    });
    let lower = line.to_lowercase();
    figure
        .then(|| MARKERS.into_iter().find(|m| lower.contains(m)))
        .flatten()
}

/// The sentences of the comments of a Rust source (`//`, `//!`, `///` lines,
/// consecutive ones joined, so that a sentence broken across lines is read
/// whole), each with the number of the line it starts on.
fn comments(text: &str) -> Vec<(usize, String)> {
    let mut sentences = Vec::new();
    let mut current: Option<(usize, String)> = None;
    for (n, line) in text.lines().enumerate() {
        let trimmed = line.trim_start();
        let Some(body) = trimmed.strip_prefix("//") else {
            sentences.extend(current.take());
            continue;
        };
        let body = body.trim_start_matches(['/', '!']).trim();
        let (start, mut sentence) = current.take().unwrap_or((n + 1, String::new()));
        let mut start = start;
        for (i, part) in body.split_inclusive(". ").enumerate() {
            if i > 0 {
                sentences.push((start, std::mem::take(&mut sentence)));
                start = n + 1;
            }
            if !sentence.is_empty() {
                sentence.push(' ');
            }
            sentence.push_str(part.trim());
        }
        if body.is_empty() || body.ends_with('.') {
            sentences.push((start, sentence));
        } else {
            current = Some((start, sentence));
        }
    }
    sentences.extend(current);
    sentences
}

/// What in `line` is history, if anything.
fn history_in(line: &str) -> Option<String> {
    if let Some(date) = date_in(line) {
        return Some(format!("a date, {date}"));
    }
    if let Some(hash) = hash_in(line) {
        return Some(format!("a commit hash, {hash}"));
    }
    timing_history_in(line).map(|m| format!("a superseded timing (`{}`)", m.trim()))
}

#[test]
fn history_detector_is_precise() {
    for (line, caught) in [
        ("/// Measured again at 16f6982 with every magnitude", true),
        ("// a51e6cc", true),
        ("//! Measured and not kept (2026-12-03): the same", true),
        ("/// operations and 2.54 → 2.43 µs, but the chain", true),
        ("// the quadruped's q̈ took 934 µs before, 82 µs after", true),
        ("// the 32-link chain ran 369 ns where it was 327 ns", true),
        ("let seed = 0x6a1b_b5e1_9c3e_f00d; // 0xdeadbeef12", false),
        ("/// `0x6a1b5e1f` seeds the generator", false),
        (
            "/// one division per divisor: LLVM keeps each x / d a division",
            false,
        ),
        ("/// ~90 ns each, four evaluations of q̈ per step", false),
        ("/// before any step, `InvalidParameter`", false),
        (
            "/// a deadbeef coffee; 1234567 states; 1e-16 and 2.5e-11",
            false,
        ),
        ("/// `__t3a5b6c7` and face_1234567", false),
        ("/// ISO 8601 is YYYY-MM-DD; 10-12-2026 is not", false),
    ] {
        assert_eq!(
            history_in(line).is_some(),
            caught,
            "{line}: {:?}",
            history_in(line)
        );
    }
}

/// The README and the code's comments say what is and why; the history of
/// measurements, dates and commits lives in git (and BENCHMARKS.md shows
/// the latest run).
#[test]
fn readme_and_comments_carry_no_history() {
    let root = Path::new(ROOT);
    let mut found = Vec::new();
    let readme = std::fs::read_to_string(root.join("README.md")).expect("README.md");
    let lines = readme.lines().count();
    if lines > README_MAX_LINES {
        found.push(format!(
            "README.md: {lines} lines, more than {README_MAX_LINES}: move the detail into docs/"
        ));
    }
    for (n, line) in readme.lines().enumerate() {
        if let Some(what) = history_in(line) {
            found.push(format!("README.md:{}: {what}: {line}", n + 1));
        }
    }
    for dir in COMMENTED_SOURCES {
        for file in rust_files(&root.join(dir)) {
            let text = std::fs::read_to_string(&file).expect("readable");
            let name = repository_path(&file);
            for (n, comment) in comments(&text) {
                if let Some(what) = history_in(&comment) {
                    found.push(format!("{name}:{n}: {what}: {comment}"));
                }
            }
        }
    }
    assert!(
        found.is_empty(),
        "history belongs in git:\n{}",
        found.join("\n")
    );
}

/// A file's path relative to the repository, for messages.
fn repository_path(file: &Path) -> String {
    let root = Path::new(ROOT);
    file.strip_prefix(root)
        .unwrap_or(file)
        .display()
        .to_string()
}
