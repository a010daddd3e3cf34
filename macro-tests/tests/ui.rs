//! Compile-time errors of `#[dirac_system]`: every malformed input is a compile error pointing
//! at the user's tokens. Each case in `tests/ui/fail` is checked by rustc (`--emit=metadata`:
//! no code generated) against the `dirac` library this test was built with, and its diagnostics
//! must equal the `.stderr` file beside it, paths outside the case normalised (see
//! [`normalise`]). Nothing is built again: the cases need only the workspace's own artifacts in
//! this test's target directory. `DIRAC_BLESS=1 cargo test -p dirac-macro-tests --test ui`
//! writes the `.stderr` files anew from rustc's output (read the diff before committing it).
//! The valid inputs are `tests/expansions/main.rs`.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

/// The folder of the compile-fail cases, relative to this package.
const CASES: &str = "tests/ui/fail";

/// The rustc flags of every case besides its inputs: the snapshots were written with this width.
const FLAGS: &[&str] = &[
    "--edition=2024",
    "--crate-type=bin",
    "--emit=metadata",
    "--color=never",
    "--diagnostic-width=140",
    "-A",
    "dead_code",
];

#[test]
fn ui() {
    let package = Path::new(env!("CARGO_MANIFEST_DIR"));
    // rustc runs in the workspace's root: the runtime's sources are recorded relative to it, and
    // rustc shows the lines of a dependency's source only where it finds the file.
    let workspace = package.parent().expect("the package lies in the workspace");
    let relative = package
        .strip_prefix(workspace)
        .expect("the package lies in the workspace");
    let deps = std::env::current_exe()
        .expect("the test knows its own path")
        .parent()
        .expect("a test binary lies in a folder")
        .to_path_buf();
    let dirac = linked_library(&deps, "dirac");
    let mut cases: Vec<PathBuf> = std::fs::read_dir(package.join(CASES))
        .expect("tests/ui/fail is readable")
        .map(|entry| entry.expect("a readable entry").path())
        .filter(|path| path.extension().is_some_and(|e| e == "rs"))
        .collect();
    cases.sort();
    assert!(!cases.is_empty(), "no cases in {CASES}");
    let checker = Checker {
        workspace,
        package: relative,
        deps: &deps,
        dirac: &dirac,
        out: tempdir(),
        bless: std::env::var_os("DIRAC_BLESS").is_some_and(|v| v == "1"),
    };
    let next = AtomicUsize::new(0);
    let failures = Mutex::new(Vec::new());
    let threads = std::thread::available_parallelism().map_or(2, |n| n.get());
    std::thread::scope(|scope| {
        for _ in 0..threads {
            scope.spawn(|| {
                while let Some(case) = cases.get(next.fetch_add(1, Ordering::Relaxed)) {
                    if let Some(failure) = checker.check(case) {
                        failures.lock().unwrap().push(failure);
                    }
                }
            });
        }
    });
    let _ = std::fs::remove_dir_all(&checker.out);
    let failures = failures.into_inner().unwrap();
    assert!(
        failures.is_empty(),
        "{} of {} cases failed (checked against {}):\n\n{}",
        failures.len(),
        cases.len(),
        dirac.display(),
        failures.join("\n\n")
    );
}

/// What checking a case needs: where rustc runs and what it reads, where it writes.
struct Checker<'a> {
    workspace: &'a Path,
    /// This package's path relative to the workspace.
    package: &'a Path,
    deps: &'a Path,
    dirac: &'a Path,
    out: PathBuf,
    /// Whether to write the snapshots anew rather than compare with them.
    bless: bool,
}

impl Checker<'_> {
    /// Checks one case: `None` where its diagnostics are its snapshot's (or, blessing, were
    /// written into it), else what failed.
    fn check(&self, case: &Path) -> Option<String> {
        let file = case.file_name().expect("a case is a file");
        let name = case
            .file_stem()
            .expect("a case is a file")
            .to_string_lossy()
            .into_owned();
        let source = self.package.join(CASES).join(file);
        let output = Command::new(rustc())
            .current_dir(self.workspace)
            .args(FLAGS)
            .arg("--crate-name")
            .arg(&name)
            .arg("-o")
            .arg(self.out.join(format!("lib{name}.rmeta")))
            .arg("-L")
            .arg(format!("dependency={}", self.deps.display()))
            .arg("--extern")
            .arg(format!("dirac={}", self.dirac.display()))
            .arg(&source)
            .output()
            .expect("rustc runs");
        let stderr = String::from_utf8_lossy(&output.stderr);
        if output.status.success() {
            return Some(format!("{name}: compiled without an error\n{stderr}"));
        }
        if let Some(code) = SETUP_ERRORS.iter().find(|code| stderr.contains(*code)) {
            return Some(format!(
                "{name}: rustc could not load the workspace's crates ({code}): a stale or foreign \
                 build in {}? `cargo clean -p dirac` rebuilds it\n{stderr}",
                self.deps.display()
            ));
        }
        let actual = normalise(&stderr, self.package);
        let snapshot = case.with_extension("stderr");
        if self.bless {
            std::fs::write(&snapshot, &actual).expect("the snapshot is writable");
            return None;
        }
        let expected = std::fs::read_to_string(&snapshot).unwrap_or_default();
        (expected.trim_end() != actual.trim_end()).then(|| {
            format!(
                "{name}: the diagnostics differ from {}\n--- expected\n{}\n--- actual\n{}",
                snapshot.display(),
                expected.trim_end(),
                actual.trim_end()
            )
        })
    }
}

/// The rustc of the toolchain that built this test (rustup's proxy picks the same one).
fn rustc() -> std::ffi::OsString {
    std::env::var_os("RUSTC").unwrap_or_else(|| "rustc".into())
}

/// Errors that say rustc could not load the workspace's crates (not found, several candidates,
/// built by another rustc or against other dependencies), not a diagnostic of the case.
const SETUP_ERRORS: &[&str] = &[
    "E0460", "E0461", "E0462", "E0463", "E0464", "E0514", "E0519",
];

/// The `lib{name}-*.rlib` in `deps` that this test was linked with: the newest one built no later
/// than the test binary (cargo builds a dependency before the test it links, and several builds
/// of one crate, with other features, may share the folder).
fn linked_library(deps: &Path, name: &str) -> PathBuf {
    let prefix = format!("lib{name}-");
    let built = |path: &Path| std::fs::metadata(path).and_then(|m| m.modified()).ok();
    let test = std::env::current_exe().ok().and_then(|exe| built(&exe));
    let candidates: Vec<(PathBuf, Option<std::time::SystemTime>)> = std::fs::read_dir(deps)
        .expect("the test's folder is readable")
        .filter_map(|entry| entry.ok())
        .map(|entry| entry.path())
        .filter(|path| {
            let file = path.file_name().unwrap_or_default().to_string_lossy();
            file.starts_with(&prefix) && file.ends_with(".rlib")
        })
        .map(|path| {
            let time = built(&path);
            (path, time)
        })
        .collect();
    let newest = |before: Option<std::time::SystemTime>| {
        candidates
            .iter()
            .filter(|(_, time)| before.is_none() || *time <= before)
            .max_by_key(|(_, time)| *time)
            .map(|(path, _)| path.clone())
    };
    newest(test)
        .or_else(|| newest(None))
        .unwrap_or_else(|| panic!("no {prefix}*.rlib in {}", deps.display()))
}

/// A fresh folder for the cases' metadata (one per process), removed at the end.
fn tempdir() -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("ui-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("the target's temporary folder is writable");
    dir
}

/// rustc's diagnostics as the snapshots hold them: without the closing summary (`aborting due
/// to …`, `For more information …`); the case's own path relative to this package; a path into
/// the workspace written `$WORKSPACE/…` and one into cargo's registry `$CARGO/crate-$VERSION/…`,
/// both without their line and column, and the line numbers of their quoted lines blanked, so
/// that editing the runtime or updating a dependency does not change the snapshots.
fn normalise(stderr: &str, package: &Path) -> String {
    let package = format!("{}/", package.display());
    let mut lines = Vec::new();
    // Whether the lines quoted now are from a file outside the case.
    let mut outside = false;
    for line in stderr.lines() {
        if line.starts_with("error: aborting due to")
            || line.starts_with("For more information about this error")
            || line.starts_with("For more information about an error")
            || line.starts_with("Some errors have detailed explanations")
        {
            continue;
        }
        if line.starts_with("error") || line.starts_with("warning") {
            outside = false;
        }
        let trimmed = line.trim_start();
        let indent = &line[..line.len() - trimmed.len()];
        let arrow = ["--> ", "::: "]
            .into_iter()
            .find(|arrow| trimmed.starts_with(arrow));
        if let Some(arrow) = arrow {
            let location = &trimmed[arrow.len()..];
            if let Some(own) = location.strip_prefix(&package) {
                outside = false;
                lines.push(format!("{indent}{arrow}{own}"));
            } else {
                outside = true;
                let path = without_line_and_column(location);
                lines.push(format!("{indent}{arrow}{}", outside_path(path)));
            }
            continue;
        }
        if outside {
            // `123 | code`: the number blanked, the width kept.
            let digits = trimmed.len()
                - trimmed
                    .trim_start_matches(|c: char| c.is_ascii_digit())
                    .len();
            if digits > 0 && trimmed[digits..].starts_with(" |") {
                lines.push(format!(
                    "{indent}{}{}",
                    " ".repeat(digits),
                    &trimmed[digits..]
                ));
                continue;
            }
        }
        lines.push(line.to_owned());
    }
    while lines.last().is_some_and(|line| line.trim().is_empty()) {
        lines.pop();
    }
    // Each diagnostic's gutter as wide as the case's own line numbers in it.
    let mut start = 0;
    while start < lines.len() {
        let end = (start + 1..lines.len())
            .find(|&i| lines[i].starts_with("error") || lines[i].starts_with("warning"))
            .unwrap_or(lines.len());
        regutter(&mut lines[start..end]);
        start = end;
    }
    let mut text = lines.join("\n");
    text.push('\n');
    text
}

/// One diagnostic's gutter made as wide as its widest line number left: rustc sized it for the
/// numbers that were blanked too. With gutter width `w`, rustc writes `w` spaces before `--> `
/// and `::: `, `w + 1` before `|` and `=`, and a line's number right-aligned in `w` before ` |`.
fn regutter(lines: &mut [String]) {
    let Some(old) = lines
        .iter()
        .map(|line| (line.len() - line.trim_start().len(), line.trim_start()))
        .find(|(_, text)| text.starts_with("--> ") || text.starts_with("::: "))
        .map(|(spaces, _)| spaces)
    else {
        return;
    };
    // The digits of a numbered line (`  12 | code`), for a gutter of width `old`.
    let numbered = |line: &str| -> Option<usize> {
        let head = line.get(..old)?;
        let digits = head.len() - head.trim_end_matches(|c: char| c.is_ascii_digit()).len();
        (digits > 0 && head[..old - digits].trim().is_empty() && line[old..].starts_with(" |"))
            .then_some(digits)
    };
    let new = lines
        .iter()
        .filter_map(|line| numbered(line))
        .max()
        .unwrap_or(1);
    if new >= old {
        return;
    }
    for line in lines.iter_mut() {
        let spaces = line.len() - line.trim_start().len();
        let text = line.trim_start();
        if let Some(digits) = numbered(line) {
            *line = format!("{:>new$}{}", &line[old - digits..old], &line[old..]);
        } else if spaces == old && (text.starts_with("--> ") || text.starts_with("::: ")) {
            *line = format!("{}{text}", " ".repeat(new));
        } else if spaces == old + 1 && (text.starts_with('|') || text.starts_with('=')) {
            *line = format!("{}{text}", " ".repeat(new + 1));
        }
    }
}

/// `path:line:column` without `:line:column`.
fn without_line_and_column(location: &str) -> &str {
    let mut path = location;
    for _ in 0..2 {
        if let Some((head, tail)) = path.rsplit_once(':')
            && !tail.is_empty()
            && tail.chars().all(|c| c.is_ascii_digit())
        {
            path = head;
        }
    }
    path
}

/// A path outside the case: `$CARGO/crate-$VERSION/…` for a registry's source, `$RUST/…` for
/// the standard library's, else `$WORKSPACE/…` (rustc names the workspace's files relative to
/// its root).
fn outside_path(path: &str) -> String {
    if let Some((_, after)) = path.split_once("/registry/src/")
        && let Some((_, in_index)) = after.split_once('/')
    {
        let (krate, rest) = in_index.split_once('/').unwrap_or((in_index, ""));
        // The version begins at the first `-` before a digit (`num-dual-0.15.1`, `x-1.0.0-rc.1`).
        let dash = krate
            .char_indices()
            .find(|&(i, c)| c == '-' && krate[i + 1..].starts_with(|d: char| d.is_ascii_digit()));
        let name = dash.map_or(krate, |(i, _)| &krate[..i]);
        return format!("$CARGO/{name}-$VERSION/{rest}");
    }
    if (path.starts_with("/rustc/") || path.contains("/lib/rustlib/src/rust/"))
        && let Some((_, library)) = path.split_once("/library/")
    {
        return format!("$RUST/{library}");
    }
    format!("$WORKSPACE/{path}")
}

/// For `scripts/compile_times.sh`: copies the build script's programs of 100, 1 000 and 10 000
/// terms into `$DIRAC_PROGRAMS`.
#[test]
#[ignore = "run by scripts/compile_times.sh"]
fn write_programs() {
    let directory = std::env::var("DIRAC_PROGRAMS").expect("DIRAC_PROGRAMS names a directory");
    std::fs::create_dir_all(&directory).unwrap();
    for terms in [100, 1_000, 10_000] {
        let name = format!("terms_{terms}.rs");
        let from = std::path::Path::new(env!("OUT_DIR")).join(&name);
        std::fs::copy(from, std::path::Path::new(&directory).join(name)).unwrap();
    }
}
