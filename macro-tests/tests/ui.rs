//! Compile-time behaviour of `#[dirac_system]`: every malformed input is a compile error pointing
//! at the user's tokens (tests/ui/fail, one diagnostic per file), valid inputs compile and run
//! (tests/ui/pass), and so does a model with a 10 000-term Lagrangian
//! (tests/long_lagrangian/mod.rs). One set of cases, so that trybuild builds its dependencies
//! once and the cases side by side.

use std::path::Path;

// The generator of the 10 000-term program (a folder's mod.rs: cargo does not take it for a test
// binary of its own).
mod long_lagrangian;

#[test]
fn ui() {
    let directory = Path::new(env!("CARGO_TARGET_TMPDIR")).join("long_lagrangian");
    let long = long_lagrangian::write_program(&directory, 10_000);
    // trybuild passes its flags as `build.rustflags`, adding `--diagnostic-width=140` for the
    // batch build and not for the runs of the pass cases, so each run built its program again
    // (the 10 000-term one takes 14 s). The environment's flags win over the configuration's:
    // one set for all of trybuild's builds.
    // SAFETY: std serialises its own reads and writes of the environment, and nothing in this
    // process reads it through libc.
    unsafe {
        std::env::set_var(
            "CARGO_ENCODED_RUSTFLAGS",
            [
                "--cfg",
                "trybuild",
                "--verbose",
                "-A",
                "dead_code",
                "--diagnostic-width=140",
            ]
            .join("\x1f"),
        )
    };
    let cases = trybuild::TestCases::new();
    cases.compile_fail("tests/ui/fail/*.rs");
    cases.pass("tests/ui/pass/*.rs");
    cases.pass(long);
}

/// For `scripts/compile_times.sh`: writes the programs for 100, 1 000 and 10 000 terms into
/// `$DIRAC_PROGRAMS`.
#[test]
#[ignore = "run by scripts/compile_times.sh"]
fn write_programs() {
    let directory = std::env::var("DIRAC_PROGRAMS").expect("DIRAC_PROGRAMS names a directory");
    for terms in [100, 1_000, 10_000] {
        long_lagrangian::write_program(Path::new(&directory), terms);
    }
}
