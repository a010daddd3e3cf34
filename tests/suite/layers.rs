//! The folders of the runtime and of the attribute's crate are layers: a file may name
//! (`crate::…`, outside comments) its own folder and the folders of lower layers, never a folder
//! of its own layer or above it. Doc links may point anywhere.

use std::fs;
use std::path::Path;

/// Each folder (or top-level module) of the runtime with its layer.
const RUNTIME: &[(&str, u8)] = &[
    ("base", 0),
    ("space", 1),
    ("solve", 1),
    ("quadrature", 1),
    ("model", 2),
    ("discrete", 3),
    ("step", 4),
    ("integrate", 5),
    ("study", 6),
];

/// The same for the attribute: syntax and errors, lowering, checking, expansion (the unit tests
/// on top).
const MACROS: &[(&str, u8)] = &[
    ("internals", 0),
    ("lower", 1),
    ("check", 2),
    ("expand", 3),
    ("tests", 4),
];

fn layer(layers: &[(&str, u8)], name: &str) -> Option<u8> {
    layers.iter().find(|(n, _)| *n == name).map(|&(_, l)| l)
}

/// The folders named by `crate::NAME` in the code (not the comments) of `source`.
fn named(source: &str) -> Vec<(usize, String)> {
    let mut found = Vec::new();
    for (i, line) in source.lines().enumerate() {
        let code = line.split("//").next().unwrap_or("");
        for (at, _) in code.match_indices("crate::") {
            let name: String = code[at + 7..]
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            found.push((i + 1, name));
        }
    }
    found
}

/// Checks every `.rs` file at or under `path` (in `folder`) against the table.
fn check(path: &Path, layers: &[(&str, u8)], folder: &str, breaches: &mut Vec<String>) {
    if path.is_dir() {
        for entry in fs::read_dir(path).unwrap() {
            check(&entry.unwrap().path(), layers, folder, breaches);
        }
        return;
    }
    if path.extension().is_none_or(|e| e != "rs") {
        return;
    }
    let own = layer(layers, folder).expect("a folder of the table");
    for (line, name) in named(&fs::read_to_string(path).unwrap()) {
        let breach = match layer(layers, &name) {
            None => format!("`crate::{name}` is not a folder: name the folder"),
            Some(other) if name != folder && other >= own => {
                format!("`{folder}` (layer {own}) uses `{name}` (layer {other})")
            }
            Some(_) => continue,
        };
        breaches.push(format!("{}:{line}: {breach}", path.display()));
    }
}

/// The breaches of `layers` in the crate whose sources are in `src`.
fn breaches(src: &Path, layers: &[(&str, u8)]) -> Vec<String> {
    let mut breaches = Vec::new();
    for (folder, _) in layers {
        let dir = src.join(folder);
        let path = if dir.is_dir() {
            dir
        } else {
            src.join(format!("{folder}.rs"))
        };
        check(&path, layers, folder, &mut breaches);
    }
    breaches
}

#[test]
fn no_folder_uses_its_own_layer_or_above() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for (krate, layers) in [("dirac-runtime", RUNTIME), ("dirac-macros", MACROS)] {
        let found = breaches(&root.join(krate).join("src"), layers);
        assert!(
            found.is_empty(),
            "{krate}'s layering broken:\n{}",
            found.join("\n")
        );
    }
}

#[test]
fn a_breach_is_seen() {
    // A line of code naming a higher layer is found; the same words in a comment are not.
    let found = named("use crate::step::State; // crate::study\n/// [`x`](crate::integrate)");
    assert_eq!(found, vec![(1, "step".to_string())]);
}
