//! The folders of the runtime and of the attribute's crate are layers: a file may name
//! (`crate::…` or `super::…`, outside comments) its own folder and the folders of lower layers,
//! never a folder of its own layer or above it, and every Rust file of `src/` but `lib.rs`
//! belongs to a folder of the table. Doc links may point anywhere. The public paths of before
//! the folders still resolve.

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

/// What the code (not the comments) of `source` names after `prefix` (`crate::` or `super::`),
/// with its line.
fn named(source: &str, prefix: &str) -> Vec<(usize, String)> {
    let mut found = Vec::new();
    for (i, line) in source.lines().enumerate() {
        let code = line.split("//").next().unwrap_or("");
        for (at, _) in code.match_indices(prefix) {
            let name: String = code[at + prefix.len()..]
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            found.push((i + 1, name));
        }
    }
    found
}

/// Checks every `.rs` file at or under `path` (in `folder`) against the table. `top` is whether
/// `path` is the folder's `mod.rs` or a module file beside `lib.rs`, where `super::` is the
/// crate's root.
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
    let source = fs::read_to_string(path).unwrap();
    let top = path.file_name().is_some_and(|n| n == "mod.rs")
        || path.parent().and_then(|p| p.file_name()) == Some("src".as_ref());
    let mut names = named(&source, "crate::");
    if top {
        // `super::NAME` leaves the folder for the crate's root (`super::*` in a nested test
        // module stays in the file).
        names.extend(
            named(&source, "super::")
                .into_iter()
                .filter(|(_, n)| !n.is_empty()),
        );
    }
    for (line, name) in names {
        let breach = match layer(layers, &name) {
            None => format!("`crate::{name}` is not a folder: name the folder"),
            Some(other) if name != folder && other >= own => {
                format!("`{folder}` (layer {own}) uses `{name}` (layer {other})")
            }
            Some(_) => continue,
        };
        breaches.push(format!("{}:{line}: {breach}", path.display()));
    }
    for (line, _) in named(&source, "super::super::") {
        breaches.push(format!(
            "{}:{line}: `super::super::` may leave the folder: name it from `crate::`",
            path.display()
        ));
    }
}

/// The breaches of `layers` in the crate whose sources are in `src`.
fn breaches(src: &Path, layers: &[(&str, u8)]) -> Vec<String> {
    let mut breaches = Vec::new();
    for entry in fs::read_dir(src).unwrap() {
        let path = entry.unwrap().path();
        let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("");
        // `lib.rs`, and documents (the attribute's reference is a markdown file) are no module.
        let module = path.is_dir() || path.extension().is_some_and(|e| e == "rs");
        if stem == "lib" || !module {
            continue;
        }
        if layer(layers, stem).is_some() {
            check(&path, layers, stem, &mut breaches);
        } else {
            breaches.push(format!("{}: in no layer of the table", path.display()));
        }
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
fn breaches_are_seen() {
    // A crate with a folder using one above it, a top-level module reaching a folder of its own
    // layer through `super::`, a file in no layer, and a folder using one below it (allowed).
    let src = Path::new(env!("CARGO_TARGET_TMPDIR")).join("layers/src");
    let _ = fs::remove_dir_all(&src);
    fs::create_dir_all(src.join("base")).unwrap();
    fs::create_dir_all(src.join("step")).unwrap();
    let files = [
        ("lib.rs", "mod base;\nmod step;\n"),
        (
            "base/mod.rs",
            "// crate::step in a comment\nuse crate::step::State;\n",
        ),
        ("step/mod.rs", "use crate::base::Error;\n"),
        ("quadrature.rs", "use super::space::Manifold;\n"),
        ("helpers.rs", "\n"),
    ];
    for (file, text) in files {
        fs::write(src.join(file), text).unwrap();
    }
    let mut found = breaches(&src, RUNTIME);
    found.sort();
    assert_eq!(found.len(), 3, "{found:#?}");
    assert!(found[0].ends_with("base/mod.rs:2: `base` (layer 0) uses `step` (layer 4)"));
    assert!(found[1].ends_with("helpers.rs: in no layer of the table"));
    assert!(found[2].ends_with("quadrature.rs:1: `quadrature` (layer 1) uses `space` (layer 1)"));
}

/// Every module path of the runtime from before the folders, still public where it was.
#[test]
fn the_public_paths_of_before_resolve() {
    #[allow(unused_imports)]
    use dirac::{
        closed_form, configuration_space, constraint, dense_output, discrete_lagrangian, error,
        euler_lagrange, event, group_euler_lagrange, hamilton, hamiltonian_system, interconnection,
        jacobian, legendre, manifold, modular, newton, plot, product, quadrature, repeated,
        rotation, run, scalar, slot, sphere, step_derivatives, step_equations, stepper, system,
        trajectory, work_precision,
    };
    // And items named through them.
    let point: dirac::constraint::ConstraintPoint = dirac::ConstraintPoint::Midpoint;
    assert_eq!(point, dirac::ConstraintPoint::Midpoint);
    let _: Option<dirac::step_equations::State<1>> = None;
}
