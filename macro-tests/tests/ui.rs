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
