//! Writes the programs of a model with a long Lagrangian and a force one-form of as many terms
//! (100, 1 000 and 10 000) into `OUT_DIR`. Each program's `main` checks its model: it compiles
//! (the macro and rustc see no recursion as deep as the sum is long) and evaluates to the value
//! computed term by term in plain Rust, and its momentum ∂L/∂v (through the stepper's dual
//! numbers) to the closed form. `tests/expansions/main.rs` compiles and runs the 10 000-term one;
//! `scripts/compile_times.sh` times the builds of all three (copied out by the ignored test
//! `write_programs` of `tests/ui.rs`).

use std::fmt::Write;
use std::path::Path;

/// The coefficient of term `i`: exact in binary, so sums in any order agree closely.
fn coefficient(i: usize) -> f64 {
    1.0 + (i % 7) as f64 * 0.125
}

/// Term `i` of the Lagrangian, with its sign, on a line of its own (as generated models are
/// written), in the coordinates `q[4]` and the parameter `m`.
fn lagrangian_term(i: usize) -> String {
    let (k, c) = (i % 4, coefficient(i));
    match i % 5 {
        0 => format!("\n        + {c:?} * dot(q[{k}]).powi(2)"),
        1 => format!("\n        - {c:?} * q[{k}]"),
        2 => format!("\n        + {c:?} / (1.0 + q[{k}] * q[{k}])"),
        3 => format!("\n        - m * {c:?} * cos(q[{k}])"),
        _ => format!("\n        + {c:?}"),
    }
}

/// A program defining the model with `terms` terms and checking its Lagrangian and force at a
/// point against the same sums evaluated in a loop.
fn program(terms: usize) -> String {
    // A constant prefix before the first state-dependent term: the rewriter must reorder it.
    let mut lagrangian = String::from("0.5 - 0.25");
    let mut force = String::new();
    for i in 0..terms {
        lagrangian.push_str(&lagrangian_term(i));
        let (k, c) = (i % 4, coefficient(i));
        let sign = match i {
            0 => "",
            _ if i % 2 == 0 => "\n        +",
            _ => "\n        -",
        };
        write!(force, "{sign} {c:?} * dot(q[{k}]) * dq[{k}]").unwrap();
    }
    format!(
        r#"use dirac::prelude::*;

#[dirac_system(
    coordinates(q[4]),
    lagrangian = {lagrangian},
    forces({force}),
)]
struct Long {{
    m: f64,
}}

fn main() {{
    let system = Long {{ m: 1.5 }};
    let q = vector![0.1, -0.2, 0.3, 0.4];
    let v = vector![0.5, 0.6, -0.7, 0.8];
    let (mut expected, mut scale) = (0.25_f64, 0.25_f64);
    let mut force = [0.0_f64; 4];
    let mut momentum = [0.0_f64; 4];
    for i in 0..{terms}_usize {{
        let (k, c) = (i % 4, 1.0 + (i % 7) as f64 * 0.125);
        if i % 5 == 0 {{
            momentum[k] += 2.0 * c * v[k];
        }}
        let term = match i % 5 {{
            0 => c * v[k] * v[k],
            1 => -c * q[k],
            2 => c / (1.0 + q[k] * q[k]),
            3 => -system.m * c * q[k].cos(),
            _ => c,
        }};
        expected += term;
        scale += term.abs();
        force[k] += if i % 2 == 0 {{ c * v[k] }} else {{ -c * v[k] }};
    }}
    let l: f64 = system.lagrangian(&q, &v);
    assert!((l - expected).abs() <= 1e-12 * scale, "L = {{l}}, expected {{expected}}");
    let f: SVector<f64, 4> = system.force(&q, &v, 0.0, &[]);
    // ∂L/∂v through the dual numbers the stepper uses.
    let p = dirac::legendre::momentum(&system, &q, &v);
    for k in 0..4 {{
        assert!((f[k] - force[k]).abs() <= 1e-12 * scale, "f[{{k}}] = {{}}, expected {{}}", f[k], force[k]);
        assert!((p[k] - momentum[k]).abs() <= 1e-12 * scale, "p[{{k}}] = {{}}, expected {{}}", p[k], momentum[k]);
    }}
}}
"#
    )
}

/// Writes the program with `terms` terms into `directory`, as `terms_{terms}.rs`.
fn write_program(directory: &Path, terms: usize) -> std::io::Result<()> {
    std::fs::write(directory.join(format!("terms_{terms}.rs")), program(terms))
}

fn main() -> std::io::Result<()> {
    println!("cargo::rerun-if-changed=build.rs");
    let directory = std::env::var_os("OUT_DIR").expect("cargo sets OUT_DIR for build scripts");
    for terms in [100, 1_000, 10_000] {
        write_program(Path::new(&directory), terms)?;
    }
    Ok(())
}
