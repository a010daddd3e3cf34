//! Compile-time errors of `#[dirac_system]`: every malformed input is a compile error pointing
//! at the user's tokens (tests/ui/fail, one diagnostic per file). With compile-fail cases only,
//! trybuild checks them (`cargo check`) rather than builds them: the valid inputs are
//! `tests/expansions/main.rs`.

#[test]
fn ui() {
    // trybuild passes its flags as `build.rustflags`, adding `--diagnostic-width=140` for the
    // check of the cases and not for the check of their dependencies before it, so the
    // dependencies were checked twice. The environment's flags win over the configuration's:
    // one set for both.
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
    trybuild::TestCases::new().compile_fail("tests/ui/fail/*.rs");
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
