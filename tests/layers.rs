//! The "Layers" paragraph of the crate docs (`src/lib.rs`) is true: each
//! top-level module's code uses only the modules the paragraph lists
//! before it.
//!
//! The paragraph is read, not copied here: its backticked module names, in
//! order, are the layers. Each module's files are scanned for `crate::name`
//! paths in code (comments and doc links may point anywhere, and unit-test
//! modules at a file's end may use what they need). Root re-exports
//! (`crate::Glt`) are not allowed in module code, so every dependency is
//! visible as a module path.
//!
//! Inside a module, no two files import each other, directly or round a
//! longer circle (`super::file` paths between sibling files form no cycle).

use std::collections::BTreeMap;
use std::fs;
use std::path::{Path, PathBuf};

fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

/// The backticked names in the "Layers" section of `src/lib.rs`, in order,
/// that name a top-level module.
fn layers() -> Vec<String> {
    let lib = fs::read_to_string(src().join("lib.rs")).unwrap();
    let text: String = lib
        .lines()
        .filter_map(|l| l.strip_prefix("//!"))
        .skip_while(|l| l.trim() != "## Layers")
        .skip(1)
        .take_while(|l| !l.trim_start().starts_with("## "))
        .collect::<Vec<_>>()
        .join(" ");
    let mut names = Vec::new();
    for (i, piece) in text.split('`').enumerate() {
        let is_module = src().join(format!("{piece}.rs")).is_file()
            || src().join(piece).join("mod.rs").is_file();
        if i % 2 == 1 && is_module && !names.iter().any(|n| n == piece) {
            names.push(piece.to_string());
        }
    }
    names
}

/// Every `.rs` file of top-level module `name`.
fn files(name: &str) -> Vec<PathBuf> {
    let single = src().join(format!("{name}.rs"));
    if single.is_file() {
        return vec![single];
    }
    let mut out = Vec::new();
    let mut stack = vec![src().join(name)];
    while let Some(dir) = stack.pop() {
        for entry in fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                out.push(path);
            }
        }
    }
    out.sort();
    out
}

/// The names after `crate::` in the code of `text` (not its comments, not
/// a trailing `#[cfg(test)] mod`), with their line numbers.
fn crate_paths(text: &str) -> Vec<(usize, String)> {
    let lines: Vec<&str> = text.lines().collect();
    let mut out = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        let next = lines.get(i + 1).map_or("", |l| l.trim_start());
        if line.trim() == "#[cfg(test)]" && next.starts_with("mod tests") {
            break;
        }
        let code = line.split("//").next().unwrap();
        let mut rest = code;
        while let Some(at) = rest.find("crate::") {
            rest = &rest[at + "crate::".len()..];
            let name: String = rest
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .collect();
            out.push((i + 1, name));
        }
    }
    out
}

/// For each module, what its code uses that the layers forbid.
fn violations(layers: &[String]) -> BTreeMap<String, Vec<String>> {
    let mut found = BTreeMap::new();
    for (rank, module) in layers.iter().enumerate() {
        for file in files(module) {
            let text = fs::read_to_string(&file).unwrap();
            let shown = file.strip_prefix(src()).unwrap().display().to_string();
            for (line, name) in crate_paths(&text) {
                let bad = if name.starts_with(|c: char| c.is_ascii_uppercase()) {
                    Some("a root re-export; use its module path")
                } else {
                    match layers.iter().position(|m| *m == name) {
                        Some(r) if r > rank => Some("a module listed after it"),
                        Some(_) => None,
                        None => Some("a module the Layers text does not list"),
                    }
                };
                if let Some(why) = bad {
                    found
                        .entry(module.clone())
                        .or_insert_with(Vec::new)
                        .push(format!("src/{shown}:{line}: crate::{name} ({why})"));
                }
            }
        }
    }
    found
}

#[test]
fn every_module_uses_only_the_layers_listed_before_it() {
    let layers = layers();
    // Every module the crate declares is in the paragraph.
    let lib = fs::read_to_string(src().join("lib.rs")).unwrap();
    for line in lib.lines() {
        let decl = line.trim_start_matches("pub ").trim();
        if let Some(name) = decl.strip_prefix("mod ").and_then(|d| d.strip_suffix(';')) {
            assert!(
                layers.iter().any(|l| l == name),
                "module `{name}` is missing from the Layers text ({layers:?})"
            );
        }
    }
    let found = violations(&layers);
    assert!(found.is_empty(), "upward or unlisted uses: {found:#?}");
}

/// Control: the check sees an upward use. With the order reversed every
/// module that uses another is a violation, and `glt` (which uses `cut`)
/// is among them.
#[test]
fn the_check_sees_an_upward_use() {
    let mut reversed = layers();
    reversed.reverse();
    let found = violations(&reversed);
    assert!(found.contains_key("glt"), "{found:#?}");
    assert!(found["glt"].iter().any(|v| v.contains("crate::cut")));
    // And a path in a comment is not a use.
    assert!(crate_paths("// crate::glt::Glt\n/// [`x`](crate::cut)\n").is_empty());
    assert_eq!(
        crate_paths("use crate::math::Aabb; // crate::glt")[0].1,
        "math"
    );
}

/// The sibling files each `.rs` file of `dir` (but `mod.rs`) imports
/// through `super::name`.
fn sibling_uses(dir: &Path) -> BTreeMap<String, Vec<String>> {
    let mut names = Vec::new();
    for entry in fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        let stem = path.file_stem().unwrap().to_string_lossy().to_string();
        if path.extension().is_some_and(|e| e == "rs") && stem != "mod" {
            names.push(stem);
        }
    }
    let mut graph = BTreeMap::new();
    for name in &names {
        let text = fs::read_to_string(dir.join(format!("{name}.rs"))).unwrap();
        let mut uses = Vec::new();
        for line in text.lines() {
            if line.trim() == "#[cfg(test)]" {
                break;
            }
            let mut rest = line.split("//").next().unwrap();
            while let Some(at) = rest.find("super::") {
                rest = &rest[at + "super::".len()..];
                let used: String = rest
                    .chars()
                    .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                    .collect();
                if used != *name && names.contains(&used) && !uses.contains(&used) {
                    uses.push(used);
                }
            }
        }
        graph.insert(name.clone(), uses);
    }
    graph
}

/// A cycle in `graph`, if there is one.
fn cycle(graph: &BTreeMap<String, Vec<String>>) -> Option<Vec<String>> {
    fn visit(
        node: &str,
        graph: &BTreeMap<String, Vec<String>>,
        path: &mut Vec<String>,
        done: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        if let Some(at) = path.iter().position(|p| p == node) {
            let mut found = path[at..].to_vec();
            found.push(node.to_string());
            return Some(found);
        }
        if done.iter().any(|d| d == node) {
            return None;
        }
        path.push(node.to_string());
        for next in graph.get(node).into_iter().flatten() {
            if let Some(c) = visit(next, graph, path, done) {
                return Some(c);
            }
        }
        path.pop();
        done.push(node.to_string());
        None
    }
    let mut done = Vec::new();
    graph
        .keys()
        .find_map(|k| visit(k, graph, &mut Vec::new(), &mut done))
}

#[test]
fn no_two_files_of_a_module_import_each_other() {
    let mut stack = vec![src()];
    let mut dirs = 0;
    while let Some(dir) = stack.pop() {
        for entry in fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            }
        }
        dirs += 1;
        let graph = sibling_uses(&dir);
        assert_eq!(
            cycle(&graph),
            None,
            "files of {} import in a circle",
            dir.display()
        );
    }
    assert!(dirs > 10, "{dirs} directories");
    // Control: the check sees a circle (cut_rules.rs and tables.rs once
    // imported each other) and a longer one, and not a chain.
    let g = |edges: &[(&str, &str)]| {
        let mut m: BTreeMap<String, Vec<String>> = BTreeMap::new();
        for (a, b) in edges {
            m.entry(a.to_string()).or_default().push(b.to_string());
            m.entry(b.to_string()).or_default();
        }
        m
    };
    assert!(cycle(&g(&[("cut_rules", "tables"), ("tables", "cut_rules")])).is_some());
    assert!(cycle(&g(&[("a", "b"), ("b", "c"), ("c", "a")])).is_some());
    assert_eq!(cycle(&g(&[("a", "b"), ("b", "c"), ("a", "c")])), None);
}
