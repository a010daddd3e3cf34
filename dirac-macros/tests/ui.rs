//! Compile-time behaviour of `#[dirac_system]`: every malformed input is a compile error pointing
//! at the user's tokens (tests/ui/fail, one diagnostic per file), and valid inputs compile and run
//! (tests/ui/pass).

#[test]
fn ui() {
    let cases = trybuild::TestCases::new();
    cases.compile_fail("tests/ui/fail/*.rs");
    cases.pass("tests/ui/pass/*.rs");
}
