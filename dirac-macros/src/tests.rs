//! The macro as a library function: random token streams and random expression trees (256 of
//! each, from fixed seeds) never make it panic, and well-formed expressions expand to Rust that
//! parses.

use proc_macro2::TokenStream;

use crate::expand::dirac_system;
use crate::lower::expression::{BINARY, UNARY};

const ITEM: &str = "struct S { m: f64, k: [f64; 2] }";

/// Expands `#[dirac_system(args)] ITEM`; `None` if `args` does not tokenise.
fn expand(args: &str, item: &str) -> Option<TokenStream> {
    let args: TokenStream = args.parse().ok()?;
    let item: TokenStream = item.parse().ok()?;
    Some(dirac_system(args, item))
}

fn is_error(output: &TokenStream) -> bool {
    output.to_string().contains("compile_error")
}

fn parses(output: &TokenStream) -> bool {
    syn::parse2::<syn::File>(output.clone()).is_ok()
}

/// Random cases from a fixed seed (xorshift64*): reproducible, and a failing case is printed
/// whole by the assertion that catches it.
struct Random(u64);

impl Random {
    fn new(seed: u64) -> Self {
        Random(seed.max(1))
    }

    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }

    /// Uniform in `0..n`.
    fn below(&mut self, n: usize) -> usize {
        // The high bits: xorshift64*'s low bits are its weakest.
        ((self.next() >> 32) % n as u64) as usize
    }

    fn pick<'a>(&mut self, from: &[&'a str]) -> &'a str {
        from[self.below(from.len())]
    }

    fn coin(&mut self) -> bool {
        self.next() >> 63 == 1
    }

    /// One of `first` and `then` taken together, uniformly.
    fn pick_of_two<'a>(&mut self, first: &[&'a str], then: &[&'a str]) -> &'a str {
        let i = self.below(first.len() + then.len());
        first
            .get(i)
            .copied()
            .unwrap_or_else(|| then[i - first.len()])
    }

    /// Whether a tree of at most `top` levels stops here, `depth` levels above its bottom: never
    /// at its root, always at the bottom, a third of the time in between.
    fn at_leaf(&mut self, depth: usize, top: usize) -> bool {
        depth == 0 || (depth < top && self.below(3) == 0)
    }
}

/// `a op b` for an arithmetic operator, its operands from `inner`.
fn arithmetic(random: &mut Random, inner: impl Fn(&mut Random) -> String) -> String {
    let a = inner(random);
    let op = random.pick(&["+", "-", "*", "/"]);
    format!("{a} {op} {}", inner(random))
}

/// How many random cases each property takes.
const CASES: u64 = 256;

/// Runs `property` on `CASES` random cases from `seed`, offset by `DIRAC_PROPERTY_SEED` where
/// that is set (to explore other cases); a failure names the offset that reproduces it.
fn for_random_cases(seed: u64, mut property: impl FnMut(&mut Random)) {
    let offset: u64 = std::env::var("DIRAC_PROPERTY_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0);
    /// Says how to run the failing case again when the property panics.
    struct Reproduce(u64);
    impl Drop for Reproduce {
        fn drop(&mut self) {
            if std::thread::panicking() {
                eprintln!("these cases run again with DIRAC_PROPERTY_SEED={}", self.0);
            }
        }
    }
    let _reproduce = Reproduce(offset);
    let mut random = Random::new(seed.wrapping_add(offset));
    for _ in 0..CASES {
        property(&mut random);
    }
}

/// The depths of the random trees.
const EXPRESSION_DEPTH: usize = 6;
const GROUP_DEPTH: usize = 5;
const TOKEN_DEPTH: usize = 5;

/// An expression built from every supported form, with odd literals and paths, nested at most
/// `depth` deep.
fn expression(random: &mut Random, one_form: bool, depth: usize) -> String {
    const LEAVES: [&str; 15] = [
        "x",
        "y",
        "theta[0]",
        "theta[1]",
        "m",
        "k[1]",
        "C",
        "std::f64::consts::PI",
        "0.5",
        "2",
        "0",
        "1e300",
        "5e-324",
        "18446744073709551616",
        "0x10",
    ];
    let differentials = match one_form {
        true => ["dx", "dtheta[1]"],
        false => ["dot(x)", "dot(theta[1])"],
    };
    if random.at_leaf(depth, EXPRESSION_DEPTH) {
        return random.pick_of_two(&LEAVES, &differentials).into();
    }
    let inner = |random: &mut Random| expression(random, one_form, depth - 1);
    match random.below(7) {
        0 => arithmetic(random, inner),
        1 => format!("-{}", inner(random)),
        2 => format!("({})", inner(random)),
        3 => {
            let f = random.pick(UNARY);
            let a = inner(random);
            match random.coin() {
                true => format!("({a}).{f}()"),
                false => format!("{f}({a})"),
            }
        }
        4 => {
            let binary: Vec<&str> = BINARY
                .iter()
                .map(|b| b.0)
                .filter(|f| *f != "powi")
                .collect();
            let f = random.pick(&binary);
            let (a, b) = (inner(random), inner(random));
            match random.coin() {
                true => format!("({a}).{f}({b})"),
                false => format!("{f}({a}, {b})"),
            }
        }
        5 => format!("powi({}, {})", inner(random), random.below(7) as i32 - 3),
        _ => format!("user({})", inner(random)),
    }
}

/// An expression of numbers, vectors and matrices on a model with a rotation `R`, a unit vector
/// `n` and a real `x`, well and badly shaped alike, nested at most `depth` deep.
fn group_expression(random: &mut Random, one_form: bool, depth: usize) -> String {
    const LEAVES: [&str; 19] = [
        "x",
        "R",
        "n",
        "rho",
        "j",
        "m",
        "[1.0, x, 2.0]",
        "0.5",
        "R[1][2]",
        "n[0]",
        "rho[2]",
        "j[0][1]",
        "bodies[1]",
        "bodies[2]",
        "R[3]",
        // Names that start with `d` but are no differentials: a parameter, `d` alone, `d2`.
        "dm",
        "d",
        "d2",
        "d[1]",
    ];
    let differentials = match one_form {
        true => ["dR", "dn", "dx", "dbodies[0]"],
        false => ["omega(R)", "dot(n)", "dot(R)", "omega(n)"],
    };
    if random.at_leaf(depth, GROUP_DEPTH) {
        return random.pick_of_two(&LEAVES, &differentials).into();
    }
    let inner = |random: &mut Random| group_expression(random, one_form, depth - 1);
    match random.below(4) {
        0 => arithmetic(random, inner),
        1 => format!("-({})", inner(random)),
        2 => {
            let f = random.pick(&["dot", "cross", "transpose", "trace", "norm", "sin", "omega"]);
            let (a, b) = (inner(random), inner(random));
            match random.below(3) {
                0 => format!("{f}({a})"),
                1 => format!("{f}({a}, {b})"),
                _ => format!("({a}).{f}({b})"),
            }
        }
        _ => format!("({})[{}]", inner(random), random.below(4)),
    }
}

/// Balanced token soup: names, keywords, operators and literals, grouped at random, nested at
/// most `depth` deep.
fn tokens(random: &mut Random, depth: usize) -> String {
    const VOCABULARY: [&str; 49] = [
        "x",
        "theta",
        "dx",
        "dot",
        "sin",
        "powi",
        "powf",
        "m",
        "t",
        "__q",
        "self",
        "fn",
        "struct",
        "coordinates",
        "lagrangian",
        "constraints",
        "holonomic",
        "forces",
        "inputs",
        "quadrature",
        "galerkin",
        "constraint_at",
        "+",
        "-",
        "*",
        "/",
        "^",
        "%",
        "=",
        ",",
        ".",
        ";",
        "!",
        "::",
        "&",
        "|",
        "<",
        ">",
        "..",
        "'a",
        "1",
        "0",
        "2.5",
        "1e400",
        "99999999999999999999999",
        "1u8",
        "2f32",
        "\"s\"",
        "true",
    ];
    if random.at_leaf(depth, TOKEN_DEPTH) {
        return random.pick(&VOCABULARY).into();
    }
    let parts: Vec<String> = (0..random.below(6))
        .map(|_| tokens(random, depth - 1))
        .collect();
    let (open, close) = [("(", ")"), ("[", "]"), ("{", "}"), ("", "")][random.below(4)];
    format!("{open}{}{close}", parts.join(" "))
}

#[test]
fn random_lagrangians_expand_to_rust() {
    for_random_cases(1, |random| {
        let expr = expression(random, false, EXPRESSION_DEPTH);
        let output = expand(
            &format!("coordinates(x, y, theta[2]), lagrangian = {expr}"),
            ITEM,
        )
        .expect("tokenises");
        assert!(!is_error(&output), "{expr}\n{output}");
        assert!(parses(&output), "{expr}\n{output}");
    });
}

#[test]
fn random_one_forms_and_holonomic_constraints_never_panic() {
    for_random_cases(2, |random| {
        let (form, g) = (
            expression(random, true, EXPRESSION_DEPTH),
            expression(random, false, EXPRESSION_DEPTH),
        );
        let args = format!(
            "coordinates(x, y, theta[2]), lagrangian = dot(x) * dot(x), constraints({form}), \
             holonomic({g}), forces({form})"
        );
        let output = expand(&args, ITEM).expect("tokenises");
        assert!(parses(&output), "{args}\n{output}");
    });
}

#[test]
fn random_vector_expressions_never_panic() {
    for_random_cases(3, |random| {
        let (expr, form) = (
            group_expression(random, false, GROUP_DEPTH),
            group_expression(random, true, GROUP_DEPTH),
        );
        let item = "struct S { m: f64, rho: [f64; 3], j: [[f64; 3]; 3], dm: f64, d: [f64; 3] }";
        for args in [
            format!("coordinates(x, R: SO3, n: S2, bodies[2]: SO3), lagrangian = {expr}"),
            format!(
                "coordinates(x, R: SO3, n: S2, bodies[2]: SO3), lagrangian = dot(x) * dot(x), \
                 constraints({form}), forces({form})"
            ),
        ] {
            let output = expand(&args, item).expect("tokenises");
            assert!(parses(&output), "{args}\n{output}");
        }
    });
}

#[test]
fn random_tokens_never_panic() {
    for_random_cases(4, |random| {
        let soup = tokens(random, TOKEN_DEPTH);
        for args in [
            soup.clone(),
            format!("coordinates(x, theta[2]), lagrangian = {soup}"),
            format!("coordinates(x, theta[2]), lagrangian = dot(x) * dot(x), constraints({soup})"),
            format!("coordinates({soup}), lagrangian = x"),
            format!("coordinates(x), lagrangian = x, quadrature = {soup}"),
        ] {
            if let Some(output) = expand(&args, ITEM) {
                assert!(parses(&output), "{args}\n{output}");
            }
        }
        let _ = expand(
            "coordinates(x), lagrangian = x",
            &format!("struct S {{ {soup} }}"),
        );
        let _ = expand("coordinates(x), lagrangian = x", &soup);
    });
}

/// A 10 000-term sum, as syn parses it a 10 000-deep left spine, expands without deep recursion.
#[test]
fn ten_thousand_terms_expand() {
    let sum: Vec<String> = (0..10_000)
        .map(|i| {
            format!(
                "{}.5 * dot(theta[{}]) * theta[{}]",
                i % 7,
                i % 2,
                (i + 1) % 2
            )
        })
        .collect();
    let force: Vec<String> = (0..10_000)
        .map(|i| format!("{}.5 * dot(theta[1]) * dtheta[{}]", i % 7, i % 2))
        .collect();
    let args = format!(
        "coordinates(x, theta[2]), lagrangian = 1.0 - {}, forces({})",
        sum.join(" + "),
        force.join(" - "),
    );
    let output = expand(&args, ITEM).expect("tokenises");
    assert!(!is_error(&output));
    assert!(parses(&output));
}

/// A long sum of vector expressions on a rotation is lowered along its spine, without deep
/// recursion.
#[test]
fn long_vector_sums_expand() {
    let sum: Vec<String> = (0..5_000)
        .map(|i| format!("{}.5 * dot(omega(R), R * rho)", i % 7))
        .collect();
    let args = format!(
        "coordinates(R: SO3), lagrangian = 1.0 - {}",
        sum.join(" + ")
    );
    let output = expand(&args, "struct S { rho: [f64; 3] }").expect("tokenises");
    assert!(!is_error(&output));
    assert!(parses(&output));
}

/// Nesting beyond the limit is one error, not a crash.
#[test]
fn deep_nesting_is_one_error() {
    // Just past the expression's limit: its own check reports it; far past (deeper than the
    // parser could recurse on a small stack): the bracket check before parsing reports it.
    for (depth, says) in [
        (70, "nests more than"),
        (300, "brackets nested"),
        (100_000, "brackets nested"),
    ] {
        let nested = format!("{}x{}", "(".repeat(depth), ")".repeat(depth));
        let output = expand(&format!("coordinates(x), lagrangian = {nested}"), ITEM).unwrap();
        let text = output.to_string();
        assert_eq!(text.matches("compile_error").count(), 1, "{depth}");
        assert!(text.contains(says), "{depth}: {text:.300}");
    }
}

/// Inputs that once reached arithmetic in the macro: an index into a zero-length array, array
/// lengths summing past `usize::MAX`. Each is a compile error.
#[test]
fn edge_lengths_are_errors() {
    for args in [
        "coordinates(theta[0]), lagrangian = theta[0] * dot(theta[0])",
        "coordinates(a[18446744073709551615], b[2]), lagrangian = a[0] * dot(b[1])",
    ] {
        let output = expand(args, ITEM).unwrap();
        assert!(parses(&output), "{args}");
    }
    // Arrays of rotations and unit vectors are written out element by element: a huge one is
    // one error on its length, not a crash or a hang.
    for args in [
        "coordinates(links[18446744073709551615]: SO3), lagrangian = dot(omega(links[0]), omega(links[0]))",
        "coordinates(x, links[100000000000]: SO3, n[18446744073709551615]: S2), \
         lagrangian = dot(omega(links[3]), omega(links[0])) + n[5][2], forces(dlinks[2][0])",
        "coordinates(links[1001]: SO3), lagrangian = dot(omega(links[1000]), omega(links[0]))",
        "coordinates(a[18446744073709551615]: SO3, b[2]: SO3, c: S2), \
         lagrangian = dot(omega(b[1]), omega(a[7])) + c[0], constraints(dc[0] + db[1][2])",
    ] {
        let output = expand(args, ITEM).unwrap();
        assert!(is_error(&output) && parses(&output), "{args}");
        assert!(output.to_string().contains("at most 1000"), "{args}");
    }
}

/// Names that are no one's differential stay what they are; a parameter or input that reads as
/// a coordinate's differential where differentials are read is one error naming both.
#[test]
fn names_like_differentials() {
    let item = "struct S { d: [f64; 3], d2: f64, dx: f64, damp: f64 }";
    // No differentials read: `dx` is the parameter.
    let output = expand("coordinates(x), lagrangian = dx * dot(x) * dot(x)", item).unwrap();
    assert!(!is_error(&output), "{output}");
    // `d` and `d2` are nobody's differential, beside rotations too.
    let output = expand(
        "coordinates(R: SO3, x), lagrangian = d2 * dot(d, omega(R)) + dot(x), forces(d2 * dx)",
        "struct S { d: [f64; 3], d2: f64 }",
    )
    .unwrap();
    assert!(!is_error(&output), "{output}");
    for (args, name) in [
        (
            "coordinates(x), lagrangian = dot(x) * dot(x), forces(-dx * dot(x) * dx)",
            "`dx`",
        ),
        (
            "coordinates(amp), lagrangian = dot(amp) * dot(amp), constraints(damp * damp)",
            "`damp`",
        ),
        (
            "coordinates(x), lagrangian = dot(x) * dot(x), forces(u * dx), inputs(dx)",
            "`dx`",
        ),
    ] {
        let output = expand(args, item).unwrap().to_string();
        assert!(
            output.contains("compile_error") && output.contains(name),
            "{args}: {output}"
        );
        assert!(output.contains("reads as the differential"), "{args}");
    }
    // Beside a rotation `x`, a parameter `dx` is refused even without one-forms.
    let output = expand(
        "coordinates(x: SO3), lagrangian = dx * dot(omega(x), omega(x))",
        item,
    )
    .unwrap()
    .to_string();
    assert!(
        output.contains("reads as the differential of coordinate `x`"),
        "{output}"
    );
}

/// `crate = path` binds the runtime for every generated path; without it, `::dirac` does.
#[test]
fn the_runtime_is_reached_by_the_given_path() {
    let lagrangian = "coordinates(x), lagrangian = 0.5 * dot(x).powi(2) - m * x";
    let item = "struct S { m: f64 }";
    let custom = expand(&format!("crate = dirac_runtime, {lagrangian}"), item).unwrap();
    let default = expand(lagrangian, item).unwrap();
    for (output, path) in [
        (&custom, "use dirac_runtime as __dirac"),
        (&default, "use :: dirac as __dirac"),
    ] {
        let text = output.to_string();
        assert!(!is_error(output) && parses(output), "{text}");
        assert_eq!(text.matches(path).count(), 1, "{text}");
        // Every other mention of the runtime goes through the alias.
        assert_eq!(
            text.matches("dirac ::").count(),
            text.matches("__dirac ::").count(),
            "{text}"
        );
    }
    let refused = expand(&format!("crate = 1 + 2, {lagrangian}"), item).unwrap();
    assert!(
        refused
            .to_string()
            .contains("takes the path of the runtime crate")
    );
}

/// A Lagrangian is declared finite at every finite state only when it is built of operations
/// defined on every real; a root, a logarithm or a division by the state keeps the check of `L`
/// at each step's end.
#[test]
fn only_lagrangians_without_a_domain_are_declared_entire() {
    let item = "struct S { m: f64, k: [f64; 2] }";
    let declared = |lagrangian: &str| {
        let output = expand(
            &format!("coordinates(x, y), lagrangian = {lagrangian}"),
            item,
        )
        .unwrap();
        assert!(!is_error(&output) && parses(&output), "{output}");
        output
            .to_string()
            .contains("const LAGRANGIAN_ENTIRE : bool = true")
    };
    for entire in [
        "0.5 * m * dot(x).powi(2) + cos(x - y) * dot(y) - k[0] * x.powi(4)",
        "dot(x) * dot(y) / m - exp(x) + atan(y) + x.abs()",
        "0.5 * dot(x).powi(2) - sqrt(m) * x",
    ] {
        assert!(declared(entire), "{entire}");
    }
    for restricted in [
        "0.5 * dot(x).powi(2) - sqrt(x)",
        "0.5 * dot(x).powi(2) - ln(y)",
        "0.5 * dot(x).powi(2) - m / x",
        "0.5 * dot(x).powi(2) - x.powi(-2)",
        "0.5 * dot(x).powi(2) - tan(x)",
        "0.5 * dot(x).powi(2) - acos(y)",
        "0.5 * dot(x).powi(2) - x.powf(m)",
    ] {
        assert!(!declared(restricted), "{restricted}");
    }
}
