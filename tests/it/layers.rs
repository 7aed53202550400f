//! The module graph of `src/` has no cycle: every `crate::` path outside
//! test code points from a top-level module to another, names the crate root
//! re-exports (`crate::Mesh`) count for the module that defines them, and
//! following those edges never leads back. ARCHITECTURE.md draws this graph.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

type Graph = BTreeMap<String, BTreeMap<String, String>>;

/// The code of `text` with comments, string and char literals blanked out
/// (lines kept), so braces and paths are only those of the code.
fn code_only(text: &str) -> String {
    let b = text.as_bytes();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    let blank = |out: &mut String, s: &[u8]| out.extend(s.iter().map(|&c| if c == b'\n' { '\n' } else { ' ' }));
    while i < b.len() {
        let rest = &b[i..];
        let end = if rest.starts_with(b"//") {
            rest.iter().position(|&c| c == b'\n').unwrap_or(rest.len())
        } else if rest.starts_with(b"/*") {
            rest.windows(2).skip(2).position(|w| w == b"*/").map_or(rest.len(), |p| p + 4)
        } else if rest.starts_with(b"r#\"") || rest.starts_with(b"r\"") {
            let hashes = rest[1..].iter().take_while(|&&c| c == b'#').count();
            let close: Vec<u8> = std::iter::once(b'"').chain(std::iter::repeat_n(b'#', hashes)).collect();
            let open = 2 + hashes;
            rest[open..]
                .windows(close.len())
                .position(|w| w == close.as_slice())
                .map_or(rest.len(), |p| open + p + close.len())
        } else if rest[0] == b'"' {
            let mut j = 1;
            while j < rest.len() && rest[j] != b'"' {
                j += if rest[j] == b'\\' { 2 } else { 1 };
            }
            (j + 1).min(rest.len())
        } else if rest[0] == b'\'' {
            // A char literal ('x', '\n', '\u{..}'), not a lifetime.
            let lit = rest.iter().skip(1).take(12).position(|&c| c == b'\'').map(|p| p + 2);
            match lit {
                Some(n) if rest[1] == b'\\' || n == 3 => n,
                _ => 0,
            }
        } else {
            0
        };
        if end > 0 {
            blank(&mut out, &rest[..end]);
            i += end;
        } else {
            let c = text[i..].chars().next().unwrap_or(' ');
            out.push(c);
            i += c.len_utf8();
        }
    }
    out
}

/// `code` without the bodies of `#[cfg(test)]` modules.
fn without_tests(code: &str) -> String {
    let mut out = String::new();
    let mut rest = code;
    while let Some(at) = rest.find("#[cfg(test)]") {
        out.push_str(&rest[..at]);
        let after = &rest[at + "#[cfg(test)]".len()..];
        let trimmed = after.trim_start();
        if let Some(m) = trimmed.strip_prefix("mod ") {
            let brace = m.find(['{', ';']).unwrap_or(m.len());
            if m[brace..].starts_with('{') {
                let body = &m[brace..];
                let mut depth = 0usize;
                let mut end = body.len();
                for (k, c) in body.char_indices() {
                    match c {
                        '{' => depth += 1,
                        '}' => {
                            depth -= 1;
                            if depth == 0 {
                                end = k + 1;
                                break;
                            }
                        }
                        _ => {}
                    }
                }
                rest = &body[end..];
                continue;
            }
        }
        rest = after;
    }
    out.push_str(rest);
    out
}

/// Identifier at the start of `s`.
fn ident(s: &str) -> &str {
    let n = s.find(|c: char| !(c.is_ascii_alphanumeric() || c == '_')).unwrap_or(s.len());
    &s[..n]
}

/// The first segments of every path a `crate::` in `code` names (`crate::{a::x, b}` gives a, b).
fn crate_paths(code: &str) -> Vec<String> {
    fn group(s: &str, out: &mut Vec<String>) -> usize {
        // `s` starts just after `{`; returns the length consumed up to the matching `}`.
        let mut i = 0;
        let mut first = true;
        let b = s.as_bytes();
        while i < b.len() {
            match b[i] {
                b'}' => return i + 1,
                b',' => {
                    first = true;
                    i += 1;
                }
                b'{' => i += 1 + group(&s[i + 1..], &mut Vec::new()),
                c if first && (c.is_ascii_alphabetic() || c == b'_') => {
                    let id = ident(&s[i..]);
                    out.push(id.to_string());
                    first = false;
                    i += id.len();
                }
                _ => i += 1,
            }
        }
        i
    }
    let mut out = Vec::new();
    for (at, _) in code.match_indices("crate::") {
        if at > 0 && (code.as_bytes()[at - 1].is_ascii_alphanumeric() || code.as_bytes()[at - 1] == b'_') {
            continue; // `$crate::` or a longer name
        }
        let rest = code[at + "crate::".len()..].trim_start();
        if let Some(g) = rest.strip_prefix('{') {
            group(g, &mut out);
        } else {
            out.push(ident(rest).to_string());
        }
    }
    out
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).expect("src/ is readable").flatten() {
        let p = e.path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// Top-level modules (test-only ones left out), and which module each
/// name the crate root re-exports comes from.
fn root(src: &Path) -> (BTreeSet<String>, BTreeMap<String, String>) {
    let lib = code_only(&std::fs::read_to_string(src.join("lib.rs")).expect("lib.rs"));
    let mut mods = BTreeSet::new();
    let mut test_mods = BTreeSet::new();
    let mut test_next = false;
    for line in lib.lines().map(str::trim) {
        if line.starts_with("#[cfg(test)]") {
            test_next = true;
            continue;
        }
        let decl = line.strip_prefix("pub ").unwrap_or(line);
        if let Some(m) = decl.strip_prefix("mod ") {
            let name = ident(m).to_string();
            if test_next {
                test_mods.insert(name.clone());
            }
            mods.insert(name);
        }
        if !line.starts_with("#[") {
            test_next = false;
        }
    }
    let mut names = BTreeMap::new();
    for stmt in lib.split(';') {
        let Some(at) = stmt.find("pub use ") else { continue };
        let path = stmt[at + "pub use ".len()..].trim();
        let module = ident(path).to_string();
        let tail = &path[module.len()..];
        let mut items = BTreeSet::new();
        if let Some(open) = tail.find('{') {
            for item in tail[open + 1..].trim_end_matches('}').split(',') {
                let last = item.rsplit("::").next().unwrap_or("").trim();
                let name = last.rsplit(" as ").next().unwrap_or(last).trim();
                items.insert(ident(name).to_string());
            }
        } else {
            let last = tail.rsplit("::").next().unwrap_or("").trim();
            items.insert(ident(last.rsplit(" as ").next().unwrap_or(last).trim()).to_string());
        }
        for name in items.into_iter().filter(|n| !n.is_empty()) {
            names.insert(name, module.clone());
        }
    }
    (mods.difference(&test_mods).cloned().collect(), names)
}

/// Every edge between two top-level modules, with one place that makes it.
fn graph(src: &Path) -> Graph {
    let (mods, names) = root(src);
    let mut files = Vec::new();
    rust_files(src, &mut files);
    let mut edges = Graph::new();
    for file in files {
        let rel = file.strip_prefix(src).expect("under src/");
        let first = rel.components().next().and_then(|c| c.as_os_str().to_str()).unwrap_or("");
        let top = first.strip_suffix(".rs").unwrap_or(first);
        if !mods.contains(top) || rel.file_name().is_some_and(|f| f == "tests.rs") {
            continue;
        }
        let code = without_tests(&code_only(&std::fs::read_to_string(&file).expect("readable source")));
        for seg in crate_paths(&code) {
            let to = if mods.contains(&seg) { Some(&seg) } else { names.get(&seg) };
            if let Some(to) = to.filter(|t| *t != top && mods.contains(*t)) {
                edges
                    .entry(top.to_string())
                    .or_default()
                    .entry(to.clone())
                    .or_insert_with(|| format!("{} ({seg})", rel.display()));
            }
        }
    }
    edges
}

/// The edges that lie on a cycle: `a -> b` where `a` is reachable from `b`.
fn cycle_edges(edges: &Graph) -> Vec<String> {
    let reach = |from: &str| {
        let mut seen = BTreeSet::new();
        let mut stack = vec![from.to_string()];
        while let Some(m) = stack.pop() {
            for n in edges.get(&m).into_iter().flat_map(|e| e.keys()) {
                if seen.insert(n.clone()) {
                    stack.push(n.clone());
                }
            }
        }
        seen
    };
    let mut out = Vec::new();
    for (a, to) in edges {
        for (b, place) in to {
            if reach(b).contains(a) {
                out.push(format!("{a} -> {b} (in {place})"));
            }
        }
    }
    out
}

#[test]
fn top_level_modules_form_no_cycle() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let edges = graph(&src);
    // The reader must see the edges it is meant to see, or it proves nothing.
    let has = |a: &str, b: &str| edges.get(a).is_some_and(|e| e.contains_key(b));
    assert!(has("tessellate", "nurbs"), "no edge tessellate -> nurbs found: the reader misses paths");
    assert!(has("io", "model"), "no edge io -> model found: the reader misses paths");
    let cycles = cycle_edges(&edges);
    assert!(cycles.is_empty(), "edges that close a cycle between top-level modules:\n{}", cycles.join("\n"));
}

#[test]
fn the_reader_sees_grouped_and_reexported_paths() {
    let code = code_only(
        "use crate::{a::X, b::{c, d}, Mesh};\n// crate::commented\nlet s = \"crate::quoted\";\nf(crate::e::g);\n",
    );
    assert_eq!(crate_paths(&code), ["a", "b", "Mesh", "e"]);
    let t = without_tests("x(crate::a);\n#[cfg(test)]\nmod tests { use crate::b; { } }\ny(crate::c);");
    assert_eq!(crate_paths(&t), ["a", "c"]);
    let mut g = Graph::new();
    g.entry("a".into()).or_default().insert("b".into(), String::new());
    g.entry("b".into()).or_default().insert("c".into(), String::new());
    assert!(cycle_edges(&g).is_empty());
    g.entry("c".into()).or_default().insert("a".into(), String::new());
    assert_eq!(cycle_edges(&g).len(), 3);
}
