//! The modules of `squeal-core` are laid out along the data path: no module uses one that
//! uses it back, directly or through others. Read from the sources: every `crate::` path
//! outside comments and test code, root re-exports resolved to the module they come from.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

/// The top-level modules (`lib.rs`'s `pub mod` lines).
fn modules(lib: &str) -> Vec<String> {
    lib.lines()
        .filter_map(|l| l.trim().strip_prefix("pub mod "))
        .map(|m| m.trim_end_matches(';').to_string())
        .collect()
}

/// Names the crate root re-exports, with the module each comes from (`pub use m::{..}`).
fn root_names(lib: &str, mods: &[String]) -> BTreeMap<String, String> {
    let mut out = BTreeMap::new();
    let code = strip(lib);
    for stmt in code.split(';') {
        let Some(rest) = stmt.trim().strip_prefix("pub use ") else {
            continue;
        };
        let Some((module, items)) = rest.split_once("::") else {
            continue;
        };
        if !mods.iter().any(|m| m == module) {
            continue;
        }
        for item in items.trim_matches(|c| c == '{' || c == '}').split(',') {
            let name = item.trim();
            if !name.is_empty() {
                out.insert(name.to_string(), module.to_string());
            }
        }
    }
    out
}

/// The source without comments and without `#[cfg(test)]` items.
fn strip(text: &str) -> String {
    let mut out = String::new();
    let mut lines = text.lines().peekable();
    while let Some(line) = lines.next() {
        let t = line.trim_start();
        if t.starts_with("#[cfg(test)]") {
            // skip the item that follows: one line, or a braced block
            let mut depth = 0i32;
            let mut opened = false;
            for l in lines.by_ref() {
                depth += l.matches('{').count() as i32 - l.matches('}').count() as i32;
                opened |= l.contains('{');
                if (opened && depth <= 0) || (!opened && l.trim_end().ends_with(';')) {
                    break;
                }
            }
            continue;
        }
        if t.starts_with("//") {
            continue;
        }
        let code = match line.find("//") {
            Some(i) if !line[..i].contains('"') => &line[..i],
            _ => line,
        };
        out.push_str(code);
        out.push('\n');
    }
    out
}

/// Source files of module `m` (its file or its directory), test files excluded.
fn files_of(m: &str) -> Vec<PathBuf> {
    let file = src().join(format!("{m}.rs"));
    if file.exists() {
        return vec![file];
    }
    let mut out = Vec::new();
    let mut stack = vec![src().join(m)];
    while let Some(dir) = stack.pop() {
        for e in fs::read_dir(&dir).expect("module directory").flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "rs")
                && p.file_name().is_some_and(|n| n != "tests.rs")
            {
                out.push(p);
            }
        }
    }
    out
}

/// The modules `code` refers to through `crate::` paths.
fn uses(code: &str, mods: &[String], roots: &BTreeMap<String, String>) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    let resolve = |name: &str, out: &mut BTreeSet<String>| {
        let head = name.split("::").next().unwrap_or("").trim();
        if mods.iter().any(|m| m == head) {
            out.insert(head.to_string());
        } else if let Some(m) = roots.get(head) {
            out.insert(m.clone());
        }
    };
    for (i, _) in code.match_indices("crate::") {
        let rest = &code[i + "crate::".len()..];
        if let Some(list) = rest.strip_prefix('{') {
            // top-level items of the braced list
            let mut depth = 0;
            let mut item = String::new();
            for c in list.chars() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => break,
                    '}' => depth -= 1,
                    ',' if depth == 0 => {
                        resolve(&item, &mut out);
                        item.clear();
                        continue;
                    }
                    _ => {}
                }
                item.push(c);
            }
            resolve(&item, &mut out);
        } else {
            let name: String = rest
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            resolve(&name, &mut out);
        }
    }
    out
}

/// A cycle of `graph` if it has one.
fn cycle(graph: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        n: &str,
        graph: &BTreeMap<String, BTreeSet<String>>,
        state: &mut BTreeMap<String, u8>,
        path: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        state.insert(n.to_string(), 1);
        path.push(n.to_string());
        for next in graph.get(n).into_iter().flatten() {
            match state.get(next.as_str()).copied().unwrap_or(0) {
                1 => {
                    let start = path.iter().position(|p| p == next).expect("on the path");
                    let mut c = path[start..].to_vec();
                    c.push(next.clone());
                    return Some(c);
                }
                0 => {
                    if let Some(c) = visit(next, graph, state, path) {
                        return Some(c);
                    }
                }
                _ => {}
            }
        }
        path.pop();
        state.insert(n.to_string(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for n in graph.keys() {
        if state.get(n.as_str()).copied().unwrap_or(0) == 0 {
            if let Some(c) = visit(n, graph, &mut state, &mut Vec::new()) {
                return Some(c);
            }
        }
    }
    None
}

fn module_graph() -> BTreeMap<String, BTreeSet<String>> {
    let lib = fs::read_to_string(src().join("lib.rs")).expect("lib.rs");
    let mods = modules(&lib);
    let roots = root_names(&lib, &mods);
    let mut graph = BTreeMap::new();
    for m in &mods {
        let mut deps = BTreeSet::new();
        for f in files_of(m) {
            let text = fs::read_to_string(&f).expect("source file");
            deps.extend(uses(&strip(&text), &mods, &roots));
        }
        deps.remove(m);
        graph.insert(m.clone(), deps);
    }
    graph
}

#[test]
fn core_modules_use_each_other_without_a_cycle() {
    let graph = module_graph();
    assert!(graph.len() >= 10, "modules found: {:?}", graph.keys());
    // the data path: the operator and its modes at the bottom, reduction at the top
    assert!(graph["operator"]
        .iter()
        .all(|d| d == "linalg" || d == "error"));
    assert!(graph["reduction"].contains("contact"));
    if let Some(c) = cycle(&graph) {
        panic!("import cycle in squeal-core: {}", c.join(" -> "));
    }
}

#[test]
fn the_cycle_finder_finds_a_cycle_and_the_reader_sees_root_names() {
    let mut g = BTreeMap::new();
    g.insert("a".to_string(), BTreeSet::from(["b".to_string()]));
    g.insert("b".to_string(), BTreeSet::from(["c".to_string()]));
    g.insert("c".to_string(), BTreeSet::from(["a".to_string()]));
    assert_eq!(cycle(&g).map(|c| c.len()), Some(4));
    g.get_mut("c").unwrap().clear();
    assert_eq!(cycle(&g), None);

    let mods = vec!["qep".to_string(), "eigen".to_string()];
    let roots = BTreeMap::from([("ComplexModes".to_string(), "operator".to_string())]);
    let code = strip(
        "use crate::{c64, ComplexModes, qep::{a, b}};\n// crate::eigen in a comment\n\
         #[cfg(test)]\nmod tests {\n    use crate::eigen::X;\n}\n",
    );
    let found = uses(&code, &mods, &roots);
    assert_eq!(
        found,
        BTreeSet::from(["operator".to_string(), "qep".to_string()])
    );
}
