//! Writes the 10 000-term model that `tests/expansions/main.rs` compiles and runs.

#[path = "src/long_lagrangian.rs"]
mod long_lagrangian;

fn main() -> std::io::Result<()> {
    println!("cargo::rerun-if-changed=src/long_lagrangian.rs");
    let directory = std::env::var_os("OUT_DIR").expect("cargo sets OUT_DIR for build scripts");
    long_lagrangian::write_program(std::path::Path::new(&directory), 10_000)?;
    Ok(())
}
