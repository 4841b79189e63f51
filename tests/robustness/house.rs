//! The house rule as a test (ARCHITECTURE.md, STYLE §22): reads the crate's
//! source and fails when a room (a top-level module of `src/`) refers to a
//! room above it in the pipeline's order, when two children of one room
//! refer to each other through a cycle, when a library file passes 1 000
//! lines of code, or when a file outside the vendor folders, the vendor
//! registry and the robot presets names a vendor. Test modules, comments and
//! string literals are left out; a plain `pub use child::Item` re-export is
//! not a dependency of the parent (it names the child, the child does not
//! use the parent).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The rooms from the bottom of the pipeline (leaves) to the front door: a
/// room may refer only to rooms before it. Kept in step with ARCHITECTURE.md
/// and the crate doc's table.
const ROOMS: &[&str] = &[
    "math", "util", "geometry", "path", "toolaxis", "process", "robot", "optimise", "program",
    "place", "io", "fit", "report", "error", "pipeline", "replan", "python",
];

/// Largest library file, in lines of code (test modules, comments, blanks
/// left out).
const MAX_CODE_LINES: usize = 1000;

/// One source file: its module path below `crate` and its code with test
/// modules, comments and string contents blanked.
struct Source {
    file: PathBuf,
    module: Vec<String>,
    code: String,
}

fn src_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.expect("directory entry").path())
        .collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

/// Blanks comments and the contents of string and char literals, keeping
/// every newline so that line counts stay.
fn strip(text: &str) -> String {
    let b: Vec<char> = text.chars().collect();
    let mut out = String::with_capacity(text.len());
    let blank = |out: &mut String, s: &[char]| {
        for &c in s {
            out.push(if c == '\n' { '\n' } else { ' ' });
        }
    };
    let mut i = 0;
    while i < b.len() {
        let rest = &b[i..];
        let word_before = i > 0 && (b[i - 1].is_alphanumeric() || b[i - 1] == '_');
        if rest.starts_with(&['/', '/']) {
            let end = rest.iter().position(|&c| c == '\n').unwrap_or(rest.len());
            blank(&mut out, &rest[..end]);
            i += end;
        } else if rest.starts_with(&['/', '*']) {
            let (mut depth, mut j) = (1, 2);
            while j < rest.len() && depth > 0 {
                if rest[j..].starts_with(&['/', '*']) {
                    depth += 1;
                    j += 2;
                } else if rest[j..].starts_with(&['*', '/']) {
                    depth -= 1;
                    j += 2;
                } else {
                    j += 1;
                }
            }
            blank(&mut out, &rest[..j]);
            i += j;
        } else if rest[0] == 'r'
            && !word_before
            && rest.len() > 1
            && (rest[1] == '"' || rest[1] == '#')
        {
            let hashes = rest[1..].iter().take_while(|&&c| c == '#').count();
            if rest.get(1 + hashes) != Some(&'"') {
                out.push('r');
                i += 1;
                continue;
            }
            let open = 2 + hashes;
            let mut j = open;
            while j < rest.len() {
                if rest[j] == '"'
                    && rest[j + 1..]
                        .iter()
                        .take(hashes)
                        .filter(|&&c| c == '#')
                        .count()
                        == hashes
                {
                    break;
                }
                j += 1;
            }
            let end = (j + 1 + hashes).min(rest.len());
            out.push_str("\"\"");
            blank(&mut out, &rest[2..end]);
            i += end;
        } else if rest[0] == '"' {
            let mut j = 1;
            while j < rest.len() && rest[j] != '"' {
                j += if rest[j] == '\\' { 2 } else { 1 };
            }
            let end = (j + 1).min(rest.len());
            out.push_str("\"\"");
            blank(&mut out, &rest[2.min(end)..end]);
            i += end;
        } else if rest[0] == '\'' && !word_before {
            // A char literal ('x', '\n', '\u{..}') or a lifetime ('a).
            let len = if rest.get(1) == Some(&'\\') {
                rest[2..].iter().position(|&c| c == '\'').map(|p| p + 3)
            } else if rest.get(2) == Some(&'\'') {
                Some(3)
            } else {
                None
            };
            match len {
                Some(n) => {
                    out.push_str("' '");
                    blank(&mut out, &rest[3..n]);
                    i += n;
                }
                None => {
                    out.push('\'');
                    i += 1;
                }
            }
        } else {
            out.push(rest[0]);
            i += 1;
        }
    }
    out
}

/// The line after the brace block opened at or after line `start` closes
/// (or after the first `;` if none opens: `mod tests;`).
fn block_end(lines: &[&str], start: usize) -> usize {
    let (mut depth, mut opened) = (0i64, false);
    for (k, line) in lines.iter().enumerate().skip(start) {
        for c in line.chars() {
            match c {
                '{' => {
                    depth += 1;
                    opened = true;
                }
                '}' => {
                    depth -= 1;
                    if opened && depth == 0 {
                        return k + 1;
                    }
                }
                _ => {}
            }
        }
        if !opened && line.trim_end().ends_with(';') {
            return k + 1;
        }
    }
    lines.len()
}

/// The library's sources, test modules (`#[cfg(test)]` items and `tests.rs`
/// files) left out.
fn sources() -> Vec<Source> {
    let root = src_dir();
    let mut files = Vec::new();
    rust_files(&root, &mut files);
    let mut out = Vec::new();
    for file in files {
        let rel = file.strip_prefix(&root).expect("below src");
        let mut module: Vec<String> = rel
            .with_extension("")
            .components()
            .map(|c| c.as_os_str().to_string_lossy().into_owned())
            .collect();
        if matches!(module.last().map(String::as_str), Some("mod" | "lib")) {
            module.pop();
        }
        if module.last().is_some_and(|m| m == "tests") {
            continue;
        }
        let text =
            std::fs::read_to_string(&file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        let stripped = strip(&text);
        let lines: Vec<&str> = stripped.lines().collect();
        let mut keep = vec![true; lines.len()];
        let mut k = 0;
        while k < lines.len() {
            if lines[k].trim_start().starts_with("#[cfg(test)]") {
                let end = block_end(&lines, k + 1);
                keep[k..end].iter_mut().for_each(|x| *x = false);
                k = end;
            } else {
                k += 1;
            }
        }
        let code = lines
            .iter()
            .zip(&keep)
            .map(|(l, &kept)| if kept { *l } else { "" })
            .collect::<Vec<_>>()
            .join("\n");
        out.push(Source { file, module, code });
    }
    out
}

/// Every module path another module refers to: `crate::a::b`, `super::a`,
/// `self::a::b`, resolved to absolute paths below `crate` (not yet cut to
/// a module).
fn references(src: &Source) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    let code = &src.code;
    let is_word = |c: char| c.is_alphanumeric() || c == '_';
    let idents = |s: &str| -> Vec<String> {
        let mut v = Vec::new();
        let mut rest = s;
        loop {
            let n = rest.find(|c: char| !is_word(c)).unwrap_or(rest.len());
            if n == 0 {
                break;
            }
            v.push(rest[..n].to_string());
            rest = &rest[n..];
            match rest.strip_prefix("::") {
                Some(r) if r.starts_with(is_word) => rest = r,
                _ => break,
            }
        }
        v
    };
    let mut at = 0;
    while let Some(p) = code[at..].find(['c', 's']) {
        let i = at + p;
        at = i + 1;
        if i > 0 && code[..i].ends_with(is_word) {
            continue;
        }
        let rest = &code[i..];
        if let Some(r) = rest.strip_prefix("crate::") {
            out.push(idents(r));
        } else if rest.starts_with("super::") {
            let mut r = rest;
            let mut up = 0;
            while let Some(x) = r.strip_prefix("super::") {
                r = x;
                up += 1;
            }
            let base = src.module.len().saturating_sub(up);
            let mut path = src.module[..base].to_vec();
            path.extend(idents(r));
            out.push(path);
        } else if let Some(r) = rest.strip_prefix("self::") {
            let mut path = src.module.clone();
            path.extend(idents(r));
            out.push(path);
        }
    }
    out
}

/// The longest prefix of `path` that is a module of the crate.
fn module_of(path: &[String], modules: &BTreeSet<Vec<String>>) -> Vec<String> {
    let mut p = path.to_vec();
    while !p.is_empty() && !modules.contains(&p) {
        p.pop();
    }
    p
}

/// Strongly connected components of more than one node (Tarjan).
fn cycles(edges: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
    struct T<'a> {
        edges: &'a BTreeMap<String, BTreeSet<String>>,
        index: BTreeMap<String, usize>,
        low: BTreeMap<String, usize>,
        stack: Vec<String>,
        on: BTreeSet<String>,
        out: Vec<Vec<String>>,
    }
    fn visit(t: &mut T, v: &str) {
        let n = t.index.len();
        t.index.insert(v.into(), n);
        t.low.insert(v.into(), n);
        t.stack.push(v.into());
        t.on.insert(v.into());
        let next: Vec<String> = t
            .edges
            .get(v)
            .map(|s| s.iter().cloned().collect())
            .unwrap_or_default();
        for w in next {
            if !t.index.contains_key(&w) {
                visit(t, &w);
                let lw = t.low[&w];
                let lv = t.low.get_mut(v).expect("visited");
                *lv = (*lv).min(lw);
            } else if t.on.contains(&w) {
                let iw = t.index[&w];
                let lv = t.low.get_mut(v).expect("visited");
                *lv = (*lv).min(iw);
            }
        }
        if t.low[v] == t.index[v] {
            let mut comp = Vec::new();
            loop {
                let w = t.stack.pop().expect("on the stack");
                t.on.remove(&w);
                let done = w == v;
                comp.push(w);
                if done {
                    break;
                }
            }
            if comp.len() > 1 {
                comp.sort();
                t.out.push(comp);
            }
        }
    }
    let mut t = T {
        edges,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on: BTreeSet::new(),
        out: Vec::new(),
    };
    let nodes: BTreeSet<String> = edges
        .iter()
        .flat_map(|(a, bs)| std::iter::once(a.clone()).chain(bs.iter().cloned()))
        .collect();
    for v in nodes {
        if !t.index.contains_key(&v) {
            visit(&mut t, &v);
        }
    }
    t.out
}

fn room_rank(room: &str) -> Option<usize> {
    ROOMS.iter().position(|r| *r == room)
}

#[test]
fn each_room_refers_only_to_rooms_below_it() {
    let sources = sources();
    let modules: BTreeSet<Vec<String>> = sources.iter().map(|s| s.module.clone()).collect();
    let mut upward = BTreeSet::new();
    let mut unknown = BTreeSet::new();
    for s in &sources {
        let Some(room) = s.module.first() else {
            continue;
        };
        let Some(rank) = room_rank(room) else {
            unknown.insert(room.clone());
            continue;
        };
        for r in references(s) {
            let target = module_of(&r, &modules);
            let Some(to) = target.first() else { continue };
            match room_rank(to) {
                Some(to_rank) if to_rank > rank => {
                    upward.insert(format!(
                        "{} ({}) -> crate::{}",
                        room,
                        s.file.display(),
                        r.join("::")
                    ));
                }
                Some(_) => {}
                None => {
                    unknown.insert(to.clone());
                }
            }
        }
    }
    assert!(
        unknown.is_empty(),
        "rooms missing from ROOMS (and ARCHITECTURE.md): {unknown:?}"
    );
    assert!(
        upward.is_empty(),
        "a room refers to a room above it:\n{}",
        upward.into_iter().collect::<Vec<_>>().join("\n")
    );
}

#[test]
fn no_room_has_an_import_cycle_among_its_children() {
    let sources = sources();
    let modules: BTreeSet<Vec<String>> = sources.iter().map(|s| s.module.clone()).collect();
    let rooms: BTreeSet<Vec<String>> = modules
        .iter()
        .filter(|m| !m.is_empty())
        .map(|m| m[..m.len() - 1].to_vec())
        .collect();
    let mut found = Vec::new();
    for room in &rooms {
        let child = |m: &[String]| -> Option<String> {
            if !m.starts_with(room) {
                return None;
            }
            Some(
                m.get(room.len())
                    .cloned()
                    .unwrap_or_else(|| "(mod.rs)".into()),
            )
        };
        let mut edges: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
        for s in &sources {
            let Some(a) = child(&s.module) else { continue };
            for r in references(s) {
                let target = module_of(&r, &modules);
                if let Some(b) = child(&target) {
                    if a != b {
                        edges.entry(a.clone()).or_default().insert(b);
                    }
                }
            }
        }
        for c in cycles(&edges) {
            found.push(format!("crate::{}: {}", room.join("::"), c.join(" <-> ")));
        }
    }
    assert!(
        found.is_empty(),
        "import cycles inside rooms:\n{}",
        found.join("\n")
    );
}

#[test]
fn no_library_file_passes_a_thousand_lines_of_code() {
    let big: Vec<String> = sources()
        .iter()
        .map(|s| {
            (
                s.code.lines().filter(|l| !l.trim().is_empty()).count(),
                &s.file,
            )
        })
        .filter(|(n, _)| *n > MAX_CODE_LINES)
        .map(|(n, f)| format!("{}: {n} lines of code", f.display()))
        .collect();
    assert!(
        big.is_empty(),
        "files over {MAX_CODE_LINES} lines of code:\n{}",
        big.join("\n")
    );
}

/// The closed set of vendors lives in one registry (STYLE §20): their folders
/// under `program/`, the contract and its registry, and the robot presets and
/// facts (`robot::model`, `robot::controller`).
#[test]
fn only_the_vendor_registry_names_a_vendor() {
    const VENDORS: &[&str] = &["Fanuc", "Kuka", "Abb", "FANUC", "KUKA", "ABB"];
    let allowed = |m: &[String]| -> bool {
        let m: Vec<&str> = m.iter().map(String::as_str).collect();
        matches!(
            m.as_slice(),
            ["program", "fanuc" | "kuka" | "abb", ..]
                | ["program", "contract" | "registry", ..]
                | ["robot", "controller" | "model", ..]
        )
    };
    let mut found = BTreeSet::new();
    for s in sources().iter().filter(|s| !allowed(&s.module)) {
        for (n, line) in s.code.lines().enumerate() {
            let words = line.split(|c: char| !(c.is_alphanumeric() || c == '_'));
            if let Some(w) = words.into_iter().find(|w| VENDORS.contains(w)) {
                found.insert(format!("{}:{}: {w}", s.file.display(), n + 1));
            }
        }
    }
    assert!(
        found.is_empty(),
        "vendors named outside their registry:\n{}",
        found.into_iter().collect::<Vec<_>>().join("\n")
    );
}
