//! The core's module graph has no cycle (issue 14): between its top-level modules (the
//! method's folders and files under `src/`), and between the files of each folder. Edges are
//! read from `crate::` paths and `super::` paths in the code (comments and strings skipped); a
//! folder's `mod.rs` is its interface, so `super::` references to it from its own files and its
//! re-exports of them are not edges between files.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn src() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("src")
}

/// Source text without comments and string literals.
fn code_of(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let b = text.as_bytes();
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'/' && i + 1 < b.len() && b[i + 1] == b'/' {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
        } else if b[i] == b'/' && i + 1 < b.len() && b[i + 1] == b'*' {
            i += 2;
            while i + 1 < b.len() && !(b[i] == b'*' && b[i + 1] == b'/') {
                i += 1;
            }
            i += 2;
        } else if b[i] == b'"' {
            i += 1;
            while i < b.len() && b[i] != b'"' {
                if b[i] == b'\\' {
                    i += 1;
                }
                i += 1;
            }
            i += 1;
            out.push_str("\"\"");
        } else if b[i] == b'\'' && i + 2 < b.len() && (b[i + 2] == b'\'' || (b[i + 1] == b'\\' && i + 3 < b.len() && b[i + 3] == b'\'')) {
            // a char literal such as '"' or '\n' (lifetimes are left alone)
            i += if b[i + 1] == b'\\' { 4 } else { 3 };
        } else {
            out.push(b[i] as char);
            i += 1;
        }
    }
    out
}

/// Identifiers following `prefix` in `code`, including the members of a `prefix{a, b::c}` group.
fn paths_after(code: &str, prefix: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = code;
    while let Some(p) = rest.find(prefix) {
        let before = rest[..p].chars().last();
        rest = &rest[p + prefix.len()..];
        if before.map(|c| c.is_alphanumeric() || c == '_').unwrap_or(false) {
            continue;
        }
        if let Some(group) = rest.strip_prefix('{') {
            let end = group.find('}').unwrap_or(group.len());
            for item in group[..end].split(',') {
                let name: String = item.trim().chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
                if !name.is_empty() {
                    out.push(name);
                }
            }
        } else {
            let name: String = rest.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
            if !name.is_empty() {
                out.push(name);
            }
        }
    }
    out
}

/// Every `.rs` file under `dir`.
fn files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            out.extend(files(&p));
        } else if p.extension().map(|x| x == "rs").unwrap_or(false) {
            out.push(p);
        }
    }
    out.sort();
    out
}

/// A cycle in `graph`, if any (depth-first search).
fn find_cycle(graph: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(n: &str, g: &BTreeMap<String, BTreeSet<String>>, state: &mut BTreeMap<String, u8>, stack: &mut Vec<String>) -> Option<Vec<String>> {
        state.insert(n.to_string(), 1);
        stack.push(n.to_string());
        for m in g.get(n).into_iter().flatten() {
            match state.get(m.as_str()).copied().unwrap_or(0) {
                1 => {
                    let at = stack.iter().position(|x| x == m).unwrap();
                    let mut c = stack[at..].to_vec();
                    c.push(m.clone());
                    return Some(c);
                }
                0 => {
                    if let Some(c) = visit(m, g, state, stack) {
                        return Some(c);
                    }
                }
                _ => {}
            }
        }
        stack.pop();
        state.insert(n.to_string(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for n in graph.keys() {
        if state.get(n.as_str()).copied().unwrap_or(0) == 0 {
            let mut stack = Vec::new();
            if let Some(c) = visit(n, graph, &mut state, &mut stack) {
                return Some(c);
            }
        }
    }
    None
}

/// The top-level module a file belongs to (`hbm` for `src/hbm/solve.rs`, `level` for
/// `src/level.rs`), and its name within its folder (`solve`, or `mod`).
fn place(path: &Path) -> (String, String) {
    let rel = path.strip_prefix(src()).unwrap();
    let parts: Vec<String> = rel.iter().map(|c| c.to_string_lossy().trim_end_matches(".rs").to_string()).collect();
    if parts.len() == 1 {
        (parts[0].clone(), "mod".into())
    } else {
        (parts[0].clone(), parts[1..].join("/"))
    }
}

#[test]
fn core_modules_form_no_cycle() {
    let all = files(&src());
    let tops: BTreeSet<String> = all.iter().map(|f| place(f).0).filter(|t| t != "lib" && t != "main").collect();
    let mut folders: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    let mut siblings: BTreeMap<String, BTreeMap<String, BTreeSet<String>>> = BTreeMap::new();
    for f in &all {
        let (top, name) = place(f);
        if top == "lib" {
            continue;
        }
        let code = code_of(&std::fs::read_to_string(f).unwrap());
        let folder = folders.entry(top.clone()).or_default();
        for target in paths_after(&code, "crate::") {
            if tops.contains(&target) && target != top {
                folder.insert(target);
            }
        }
        // files of the same folder: `super::x` from a file directly in the folder, and
        // `crate::top::x`
        let files_here: BTreeSet<String> = all.iter().filter(|g| place(g).0 == top).map(|g| place(g).1.split('/').next().unwrap().to_string()).collect();
        if name != "mod" && !name.contains('/') {
            let own = siblings.entry(top.clone()).or_default().entry(name.clone()).or_default();
            let mut targets = paths_after(&code, "super::");
            targets.extend(paths_after(&code, &format!("crate::{top}::")));
            for t in targets {
                if files_here.contains(&t) && t != name && t != "mod" {
                    own.insert(t);
                }
            }
        }
    }
    if let Some(c) = find_cycle(&folders) {
        panic!("cycle between top-level modules: {}", c.join(" -> "));
    }
    for (top, g) in &siblings {
        if let Some(c) = find_cycle(g) {
            panic!("cycle between the files of {top}/: {}", c.join(" -> "));
        }
    }
    println!("{} top-level modules, no cycle: {folders:#?}", folders.len());
}

#[test]
fn the_checker_finds_a_cycle() {
    let g: BTreeMap<String, BTreeSet<String>> = [("a", vec!["b"]), ("b", vec!["c"]), ("c", vec!["a"]), ("d", vec![])]
        .into_iter()
        .map(|(k, v)| (k.to_string(), v.into_iter().map(String::from).collect()))
        .collect();
    assert_eq!(find_cycle(&g), Some(vec!["a".into(), "b".into(), "c".into(), "a".into()]));
    assert_eq!(paths_after(&code_of("use crate::{hbm::X, jp}; // crate::rom\n\"crate::io\""), "crate::"), vec!["hbm", "jp"]);
}
