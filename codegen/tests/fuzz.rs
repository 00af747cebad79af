//! The macro's fuzz harness (issue 13): generated and mutated DSL inputs
//! through `expand`, from a fixed seed. Every input must give tokens or a
//! spanned error: no panic, no hang (a watchdog per input), no error
//! without a location. A sample of the accepted inputs is then compiled for
//! real, with the facade crate, and run: what the macro accepts compiles.
//!
//! `FUZZ_SEED` and `FUZZ_CASES` override the seed (20261122) and the number
//! of inputs that reach the macro (10,000); `scripts/explore.sh` runs it
//! with fresh seeds.

use constrained_codegen::numeric::rng::SplitMix64;
use constrained_codegen::{analyse, expand};
use proc_macro2::TokenStream;
use std::fmt::Write as _;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::mpsc;
use std::time::Duration;

mod common;

/// Per input: far above the slowest expansion seen (~0.1 s).
const WATCHDOG: Duration = Duration::from_secs(20);

struct Gen {
    rng: SplitMix64,
}

impl Gen {
    fn below(&mut self, n: usize) -> usize {
        (self.rng.next_u64() % n as u64) as usize
    }
    fn chance(&mut self, p: f64) -> bool {
        self.rng.next_f64() < p
    }
    fn pick<'a>(&mut self, items: &[&'a str]) -> &'a str {
        items[self.below(items.len())]
    }

    /// A random expression over `names` (coordinates first), `depth` deep.
    fn expr(&mut self, coords: &[String], others: &[String], depth: usize) -> String {
        if depth == 0 || self.chance(0.3) {
            return match self.below(6) {
                0 | 1 => coords[self.below(coords.len())].clone(),
                2 if !others.is_empty() => others[self.below(others.len())].clone(),
                3 => format!("dot({})", coords[self.below(coords.len())]),
                4 => "t".to_string(),
                _ => self
                    .pick(&[
                        "0.0", "1.0", "2.5", "0.5", "3.0", "1e-9", "1e9", "1e150", "7.0",
                    ])
                    .to_string(),
            };
        }
        let sub = |g: &mut Gen| g.expr(coords, others, depth - 1);
        match self.below(14) {
            0 => format!("({} + {})", sub(self), sub(self)),
            1 => format!("({} - {})", sub(self), sub(self)),
            2 => format!("({} * {})", sub(self), sub(self)),
            3 => format!("({} / {})", sub(self), sub(self)),
            4 => format!("(-{})", sub(self)),
            5 => {
                let f = self.pick(&[
                    "sin", "cos", "tan", "sqrt", "exp", "ln", "tanh", "atan", "abs", "signum",
                    "sinh", "cosh", "asin", "acos",
                ]);
                format!("({}).{f}()", sub(self))
            }
            6 => {
                let k = self.pick(&["0", "1", "2", "3", "-1", "-2", "5"]);
                format!("({}).powi({k})", sub(self))
            }
            7 => format!("({}).powf({})", sub(self), sub(self)),
            8 => format!("({}).atan2({})", sub(self), sub(self)),
            9 => {
                let f = self.pick(&["min", "max", "hypot"]);
                format!("{f}({}, {})", sub(self), sub(self))
            }
            10 => format!("clamp({}, {}, {})", sub(self), sub(self), sub(self)),
            11 => format!("dt({})", sub(self)),
            _ => format!("({} * {} + {})", sub(self), sub(self), sub(self)),
        }
    }

    /// A random system: coordinates, parameters, definitions, masses or a
    /// kinetic energy, forces, constraints, sometimes `eliminate`.
    fn system(&mut self) -> String {
        let n = 1 + self.below(4);
        let coords: Vec<String> = (0..n).map(|i| format!("q{i}")).collect();
        let params: Vec<String> = (0..self.below(4)).map(|i| format!("p{i}")).collect();
        let mut others = params.clone();
        let mut defs = Vec::new();
        for i in 0..self.below(3) {
            let e = self.expr(&coords, &others, 2);
            defs.push(format!("d{i} = {e}"));
            others.push(format!("d{i}"));
        }
        let mut text = format!("pub struct Fuzzed {{ coordinates: [{}],", coords.join(", "));
        if !params.is_empty() {
            let _ = write!(text, " parameters: [{}],", params.join(", "));
        }
        if !defs.is_empty() {
            let _ = write!(text, " definitions: [{}],", defs.join(", "));
        }
        if self.chance(0.25) {
            let terms: Vec<String> = coords
                .iter()
                .map(|c| {
                    let m = if params.is_empty() || self.chance(0.5) {
                        self.pick(&["1.0", "2.0", "0.5"]).to_string()
                    } else {
                        params[self.below(params.len())].clone()
                    };
                    format!("{m} * dot({c}).powi(2) / 2.0")
                })
                .collect();
            let _ = write!(text, " kinetic_energy: {},", terms.join(" + "));
            if self.chance(0.5) {
                let v = self.expr(&coords, &params, 2).replace("dot(", "(");
                let _ = write!(text, " potential_energy: {v},");
            }
        } else if self.chance(0.85) {
            let masses: Vec<String> = coords
                .iter()
                .map(|_| {
                    if params.is_empty() || self.chance(0.6) {
                        self.pick(&["1.0", "2.0", "0.5", "3.0", "-1.0", "0.0"])
                            .to_string()
                    } else {
                        params[self.below(params.len())].clone()
                    }
                })
                .collect();
            let _ = write!(text, " mass: diag[{}],", masses.join(", "));
        } else {
            let rows: Vec<String> = (0..n)
                .map(|i| {
                    let row: Vec<String> = (0..n)
                        .map(|j| {
                            if i == j {
                                "2.0".into()
                            } else {
                                self.expr(&coords, &params, 1).replace("dot(", "(")
                            }
                        })
                        .collect();
                    format!("[{}]", row.join(", "))
                })
                .collect();
            let _ = write!(text, " mass: [{}],", rows.join(", "));
        }
        if self.chance(0.8) {
            let forces: Vec<String> = (0..n).map(|_| self.expr(&coords, &others, 3)).collect();
            let _ = write!(text, " forces: [{}],", forces.join(", "));
        }
        let k = self.below(n + 1);
        if k > 0 {
            let constraints: Vec<String> = (0..k)
                .map(|_| {
                    let lhs = self.expr(&coords, &others, 3);
                    if self.chance(0.7) {
                        format!("{lhs} == {}", self.expr(&coords, &others, 1))
                    } else {
                        lhs
                    }
                })
                .collect();
            let _ = write!(text, " constraints: [{}],", constraints.join(", "));
            if self.chance(0.15) {
                let _ = write!(text, " eliminate: [{}],", coords[self.below(n)]);
            }
        }
        text.push_str(" }");
        text
    }

    /// `text` with one to three token-level mutations.
    fn mutate(&mut self, text: &str) -> String {
        let pool = [
            "struct",
            "r#type",
            "1e999",
            "-",
            "==",
            "dot",
            "(",
            ")",
            "[",
            "]",
            "{",
            "}",
            ",",
            ";",
            "::",
            "self",
            "T",
            "Some",
            "t",
            ".powi(4294967298)",
            "0.0",
            "x",
            "mass",
            "forces",
            "constraints",
            "coordinates",
            "parameters",
            "#[derive(Debug)]",
            "1e308",
            "* 1e308",
            ".sin()",
            "dt",
            "=",
            "'a",
            "\"text\"",
            "r#t",
            "correction",
            "eliminate",
            "diag",
        ];
        let mut tokens: Vec<String> = tokenize(text);
        for _ in 0..1 + self.below(3) {
            if tokens.is_empty() {
                break;
            }
            let i = self.below(tokens.len());
            match self.below(4) {
                0 => {
                    tokens.remove(i);
                }
                1 => {
                    let t = tokens[i].clone();
                    tokens.insert(i, t);
                }
                2 => tokens[i] = self.pick(&pool).to_string(),
                _ => tokens.insert(i, self.pick(&pool).to_string()),
            }
        }
        tokens.join(" ")
    }
}

/// The text split into proc-macro tokens (groups flattened to their
/// delimiters), so that mutations act on tokens, not characters.
fn tokenize(text: &str) -> Vec<String> {
    fn walk(stream: TokenStream, out: &mut Vec<String>) {
        for tree in stream {
            match tree {
                proc_macro2::TokenTree::Group(g) => {
                    let (open, close) = match g.delimiter() {
                        proc_macro2::Delimiter::Parenthesis => ("(", ")"),
                        proc_macro2::Delimiter::Bracket => ("[", "]"),
                        proc_macro2::Delimiter::Brace => ("{", "}"),
                        proc_macro2::Delimiter::None => ("", ""),
                    };
                    out.push(open.to_string());
                    walk(g.stream(), out);
                    out.push(close.to_string());
                }
                other => out.push(other.to_string()),
            }
        }
    }
    let mut out = Vec::new();
    if let Ok(stream) = text.parse::<TokenStream>() {
        walk(stream, &mut out);
    }
    out
}

/// What happened to one input.
enum Outcome {
    Accepted,
    Rejected { unspanned: Vec<String> },
    Panicked,
}

/// Expands every input on one worker thread (rustc's 8 MiB stack), with a
/// watchdog per input.
fn expand_all(inputs: Vec<String>) -> Vec<(String, Outcome)> {
    let (send_input, receive_input) = mpsc::channel::<String>();
    let (send_outcome, receive_outcome) = mpsc::channel::<Outcome>();
    std::thread::Builder::new()
        .stack_size(8 << 20)
        .spawn(move || {
            for text in receive_input {
                let outcome = match text.parse::<TokenStream>() {
                    Err(_) => continue, // not tokens: rustc's lexer rejects it first
                    Ok(tokens) => match catch_unwind(AssertUnwindSafe(|| expand(tokens))) {
                        Err(_) => Outcome::Panicked,
                        Ok(Ok(_)) => Outcome::Accepted,
                        Ok(Err(errors)) => Outcome::Rejected {
                            unspanned: errors
                                .into_iter()
                                .filter(|e| e.span().byte_range().is_empty())
                                .map(|e| e.to_string())
                                .collect(),
                        },
                    },
                };
                if send_outcome.send(outcome).is_err() {
                    return;
                }
            }
        })
        .expect("worker");
    let mut results = Vec::new();
    for text in inputs {
        if text.parse::<TokenStream>().is_err() {
            continue;
        }
        send_input.send(text.clone()).expect("worker alive");
        match receive_outcome.recv_timeout(WATCHDOG) {
            Ok(outcome) => results.push((text, outcome)),
            Err(_) => panic!("HANG: no answer in {WATCHDOG:?} for\n{text}"),
        }
    }
    results
}

fn env_or(name: &str, default: u64) -> u64 {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

#[test]
fn generated_and_mutated_inputs_expand_or_fail_with_a_spanned_error() {
    std::panic::set_hook(Box::new(|_| {})); // panics are counted, not printed
    let seed = env_or("FUZZ_SEED", 20261122);
    let cases = env_or("FUZZ_CASES", 10_000) as usize;
    let mut gen = Gen {
        rng: SplitMix64::new(seed),
    };
    let models: Vec<String> = common::model_invocations()
        .into_iter()
        .map(|m| m.tokens.to_string())
        .collect();
    let mut inputs = Vec::with_capacity(cases);
    while inputs.len() < cases {
        let text = match gen.below(3) {
            0 => gen.system(),
            1 => {
                let base = gen.system();
                gen.mutate(&base)
            }
            _ => {
                let i = gen.below(models.len());
                gen.mutate(&models[i])
            }
        };
        // Counted only when they are tokens: what rustc's lexer rejects
        // never reaches the macro.
        if text.parse::<TokenStream>().is_ok() {
            inputs.push(text);
        }
    }
    let results = expand_all(inputs);
    let _ = std::panic::take_hook();
    let (mut accepted, mut rejected, mut panics, mut unspanned) =
        (Vec::new(), 0, Vec::new(), Vec::new());
    for (text, outcome) in &results {
        match outcome {
            Outcome::Accepted => accepted.push(text.clone()),
            Outcome::Rejected { unspanned: u } => {
                rejected += 1;
                if !u.is_empty() {
                    unspanned.push(format!("{u:?} for\n{text}"));
                }
            }
            Outcome::Panicked => panics.push(text.clone()),
        }
    }
    println!(
        "fuzz (seed {seed}): {} inputs tokenized, {} accepted, {rejected} rejected, {} panics, {} unspanned errors",
        results.len(),
        accepted.len(),
        panics.len(),
        unspanned.len()
    );
    assert!(
        panics.is_empty(),
        "{} panics, first:\n{}",
        panics.len(),
        panics[0]
    );
    assert!(
        unspanned.is_empty(),
        "{} unspanned errors, first: {}",
        unspanned.len(),
        unspanned[0]
    );
    assert!(
        accepted.len() >= results.len() / 20,
        "too few accepted to judge the generator"
    );
    compile_a_sample(&accepted, seed);
}

/// Compiles and runs up to 48 accepted inputs as a user's crate would: each
/// one a module with the macro call, instantiated in f64 and f32 and
/// evaluated at a state. The crate is built in the workspace's target
/// directory with the test profile's settings (no second copy of the
/// dependencies on disk). It does not reuse the workspace's facade and
/// macro: its features differ (syn's on the host side, nalgebra's), so
/// those are built again, as they were in a target directory of its own.
fn compile_a_sample(accepted: &[String], seed: u64) {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let tmp = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"));
    let dir = tmp.join("fuzz-compile");
    let target_dir = tmp.parent().unwrap_or(tmp);
    std::fs::create_dir_all(dir.join("src")).expect("temp crate");
    let step = (accepted.len() / 48).max(1);
    let mut main = String::from("#![allow(warnings)]\nuse constrained::nalgebra::SVector;\nuse constrained::{ConstrainedSystem, State};\n");
    let mut calls = String::new();
    let mut count = 0;
    for (i, text) in accepted.iter().step_by(step).take(48).enumerate() {
        let Ok(eq) = analyse(text.parse().expect("tokens")) else {
            continue;
        };
        let (n, p) = (eq.system.dof(), eq.system.parameters.len());
        let name = eq.system.name.to_string();
        let args = |ty: &str| {
            (0..p)
                .map(|j| format!("{}{ty}", 0.6 + 0.1 * j as f64))
                .collect::<Vec<_>>()
                .join(", ")
        };
        let _ = writeln!(
            main,
            "mod case{i} {{\n    use super::*;\n    constrained::constrained_system! {{ {text} }}\n    pub fn run() {{\n        \
             let s = {name}::<f64>::new({});\n        let st = State::new(0.3, SVector::<f64, {n}>::from_element(0.4), SVector::from_element(-0.2));\n        \
             let _ = ConstrainedSystem::acceleration(&s, &st);\n        let _ = ConstrainedSystem::acceleration_gibbs_appell(&s, &st);\n        \
             let s = {name}::<f32>::new({});\n        let st = State::new(0.3f32, SVector::<f32, {n}>::from_element(0.4), SVector::from_element(-0.2));\n        \
             let _ = ConstrainedSystem::acceleration(&s, &st);\n        let _ = {name}::<f64>::DERIVATION.len();\n    }}\n}}",
            args("f64"),
            args("f32"),
        );
        let _ = writeln!(calls, "    case{i}::run();");
        count += 1;
    }
    let _ = write!(
        main,
        "fn main() {{\n{calls}    println!(\"ran {count}\");\n}}\n"
    );
    std::fs::write(dir.join("src/main.rs"), main).expect("write main.rs");
    std::fs::write(
        dir.join("Cargo.toml"),
        format!(
            "[package]\nname = \"fuzz-compile\"\nversion = \"0.0.0\"\nedition = \"2021\"\npublish = false\n\n[dependencies]\nconstrained = {{ path = {:?}, features = [\"std\"] }}\n\n[workspace]\n\n[profile.dev]\nopt-level = 1\ndebug = \"line-tables-only\"\n",
            root.canonicalize().expect("workspace root")
        ),
    )
    .expect("write Cargo.toml");
    let _ = std::fs::copy(root.join("Cargo.lock"), dir.join("Cargo.lock"));
    let output = std::process::Command::new(env!("CARGO"))
        .args(["run", "--quiet", "--offline"])
        .current_dir(&dir)
        .env("CARGO_TARGET_DIR", target_dir)
        .output()
        .expect("cargo runs");
    assert!(
        output.status.success(),
        "seed {seed}: accepted inputs that do not compile or run:\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let ran = String::from_utf8_lossy(&output.stdout);
    println!("compiled and ran {count} accepted inputs ({})", ran.trim());
}
