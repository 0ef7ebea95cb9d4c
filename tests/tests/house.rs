//! The house keeps its shape: every crate's module table names every `pub mod`, no two modules
//! of a crate import each other (directly or round a cycle), and no hand-written module grows
//! past 600 lines before its tests. Read from the sources, so the check costs nothing to run.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The crates whose `src/lib.rs` carries a module table.
const CRATES: [&str; 6] = ["drivers", "perception", "models", "firmware", "sim", "lab"];
/// Lines a module may have before its `#[cfg(test)]` part.
const MAX_LINES: usize = 600;
/// Imports known to close a cycle, left for a later change (crate, from, to, why). Each is
/// taken out of the graph before the search, so any other cycle still fails the test.
const KNOWN_CYCLE_EDGES: [(&str, &str, &str, &str); 5] = [
    (
        "drivers",
        "lidar",
        "ldrobot",
        "AnyLidar and the detector dispatch to every model from lidar/, which also holds the common Revolution",
    ),
    ("drivers", "lidar", "lds01", "as above"),
    ("drivers", "lidar", "rplidar", "as above"),
    (
        "models",
        "forest",
        "forest_tables",
        "forest() hands out the generated tables, which are built of forest's types",
    ),
    (
        "sim",
        "lds01",
        "scenario",
        "the LDS-01 byte source runs a scenario whose sensor model lives in lds01",
    ),
];
/// Generated files, exempt from the size rule.
const GENERATED: [&str; 1] = ["models/src/forest_tables.rs"];

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// `pub mod NAME;` lines of a file (with or without a `#[cfg]` above).
fn pub_mods(text: &str) -> Vec<String> {
    text.lines()
        .filter_map(|l| l.trim().strip_prefix("pub mod "))
        .filter_map(|r| r.strip_suffix(';'))
        .map(str::to_owned)
        .collect()
}

#[test]
fn every_pub_mod_is_in_its_crates_module_table() {
    let mut missing = Vec::new();
    for c in CRATES {
        let lib = root().join(c).join("src/lib.rs");
        let text = read(&lib);
        let table: String = text
            .lines()
            .filter(|l| l.starts_with("//! |"))
            .collect::<Vec<_>>()
            .join("\n");
        assert!(!table.is_empty(), "{c}/src/lib.rs has no module table");
        for m in pub_mods(&text) {
            if !table.contains(&format!("`{m}`")) && !table.contains(&format!("[`{m}`]")) {
                missing.push(format!("{c}: {m}"));
            }
        }
    }
    assert!(
        missing.is_empty(),
        "modules missing from their crate's `//!` table: {missing:?}"
    );
}

/// The crate's top-level modules: `src/NAME.rs` or `src/NAME/` (all files inside).
fn modules(src: &Path) -> BTreeMap<String, Vec<PathBuf>> {
    let mut out: BTreeMap<String, Vec<PathBuf>> = BTreeMap::new();
    for e in std::fs::read_dir(src).unwrap().flatten() {
        let p = e.path();
        let name = p.file_stem().unwrap().to_string_lossy().into_owned();
        if p.is_dir() {
            if name == "bin" {
                continue;
            }
            let files = walk(&p);
            out.entry(name).or_default().extend(files);
        } else if p.extension().is_some_and(|x| x == "rs") && name != "lib" && name != "main" {
            out.entry(name).or_default().push(p);
        }
    }
    out
}

fn walk(dir: &Path) -> Vec<PathBuf> {
    let mut v = Vec::new();
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let p = e.path();
        if p.is_dir() {
            v.extend(walk(&p));
        } else if p.extension().is_some_and(|x| x == "rs") {
            v.push(p);
        }
    }
    v
}

/// The text before the file's test module.
fn before_tests(text: &str) -> &str {
    match text.find("#[cfg(test)]") {
        Some(i) => &text[..i],
        None => text,
    }
}

/// A cycle in `graph`, if there is one (depth-first search).
fn cycle(graph: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        n: &str,
        g: &BTreeMap<String, BTreeSet<String>>,
        state: &mut BTreeMap<String, u8>,
        path: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        match state.get(n) {
            Some(2) => return None,
            Some(1) => {
                let i = path.iter().position(|p| p == n).unwrap();
                let mut c = path[i..].to_vec();
                c.push(n.to_owned());
                return Some(c);
            }
            _ => {}
        }
        state.insert(n.to_owned(), 1);
        path.push(n.to_owned());
        for m in g.get(n).into_iter().flatten() {
            if let Some(c) = visit(m, g, state, path) {
                return Some(c);
            }
        }
        path.pop();
        state.insert(n.to_owned(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for n in graph.keys() {
        if let Some(c) = visit(n, graph, &mut state, &mut Vec::new()) {
            return Some(c);
        }
    }
    None
}

#[test]
fn no_module_imports_a_module_that_imports_it() {
    let mut found = Vec::new();
    for c in CRATES {
        let mods = modules(&root().join(c).join("src"));
        let names: BTreeSet<&String> = mods.keys().collect();
        let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
        for (m, files) in &mods {
            let deps = graph.entry(m.clone()).or_default();
            for f in files {
                let text = read(f);
                // Code outside the tests and comments: `crate::NAME` in use lines and paths.
                let code: String = before_tests(&text)
                    .lines()
                    .filter(|l| !l.trim_start().starts_with("//"))
                    .collect::<Vec<_>>()
                    .join("\n");
                for (i, _) in code.match_indices("crate::") {
                    let rest = &code[i + "crate::".len()..];
                    let name: String = rest
                        .chars()
                        .take_while(|ch| ch.is_alphanumeric() || *ch == '_')
                        .collect();
                    let known = KNOWN_CYCLE_EDGES
                        .iter()
                        .any(|(k, from, to, _)| *k == c && from == m && *to == name);
                    if name != *m && names.contains(&name) && !known {
                        deps.insert(name);
                    }
                }
            }
        }
        if let Some(cyc) = cycle(&graph) {
            found.push(format!("{c}: {}", cyc.join(" → ")));
        }
    }
    assert!(found.is_empty(), "modules import each other: {found:?}");
}

#[test]
fn no_hand_written_module_is_over_600_lines_before_its_tests() {
    let mut big = Vec::new();
    for c in CRATES {
        for f in walk(&root().join(c).join("src")) {
            let rel = f
                .strip_prefix(root())
                .unwrap()
                .to_string_lossy()
                .into_owned();
            if GENERATED.contains(&rel.as_str()) {
                continue;
            }
            let n = before_tests(&read(&f)).lines().count();
            if n > MAX_LINES {
                big.push(format!("{rel}: {n}"));
            }
        }
    }
    assert!(big.is_empty(), "modules over {MAX_LINES} lines: {big:?}");
}
