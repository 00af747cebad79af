//! Expands each URDF file named on the command line as
//! `constrained_system! { struct Robot { urdf: "<file>" } }` and prints one
//! JSON object per line: the file, whether it expanded, the expansion's
//! wall time, the coordinates' count, the operations of `q̈` (generated
//! `acceleration`), the number of sines and cosines of constants left in
//! the generated code (none are expected), or the error's message, which
//! names the file and line of the element refused. With
//! `RIGHT_ANGLES_WITHIN=<radians>` set, each file is expanded with
//! `right_angles_within: <radians>` (what snapping near-right angles saves).
//! With `LOCKED=<joint>,<joint>,..` set, each file is expanded with those
//! joints `locked:` (the truncations `benches/growth.py` counts), and the
//! line also gives the operations of `mass_matrix` and `inverse_dynamics`.

use std::time::Instant;

fn main() {
    for path in std::env::args().skip(1) {
        println!("{}", expand(&path));
    }
}

/// One file's JSON line.
fn expand(path: &str) -> String {
    let snap = std::env::var("RIGHT_ANGLES_WITHIN")
        .map(|t| format!("right_angles_within: {t},"))
        .unwrap_or_default();
    let locked = std::env::var("LOCKED")
        .ok()
        .filter(|names| !names.is_empty())
        .map(|names| format!("locked: [{names}],"))
        .unwrap_or_default();
    let source = format!("struct Robot {{ urdf: {path:?}, {snap} {locked} }}");
    let tokens: proc_macro2::TokenStream = match source.parse() {
        Ok(tokens) => tokens,
        Err(e) => return line(path, &format!("\"error\": {:?}", e.to_string())),
    };
    let start = Instant::now();
    let expanded =
        constrained_codegen::expand_with(tokens, constrained_codegen::Options { jacobians: false });
    let seconds = start.elapsed().as_secs_f64();
    match expanded {
        Err(e) => line(path, &format!("\"error\": {:?}", e.to_string())),
        Ok(tokens) => {
            let text = tokens.to_string();
            let file: syn::File = match syn::parse2(tokens) {
                Ok(file) => file,
                Err(e) => return line(path, &format!("\"error\": {:?}", e.to_string())),
            };
            let ops = constrained_codegen::tools::op_count::acceleration(&file)
                .map_or(0, |ops| ops.total());
            let n = count_coordinates(&text);
            let method = |name| {
                constrained_codegen::tools::op_count::method(&file, name)
                    .map_or(0, |ops| ops.total())
            };
            format!(
                "{{\"file\": {path:?}, \"ok\": true, \"seconds\": {seconds:.3}, \"n\": {n}, \
                 \"ops\": {ops}, \"mass_matrix_ops\": {}, \"inverse_dynamics_ops\": {}, \
                 \"constant_trig\": {}}}",
                method("mass_matrix"),
                method("inverse_dynamics"),
                constant_trig(&text)
            )
        }
    }
}

fn line(path: &str, rest: &str) -> String {
    format!("{{\"file\": {path:?}, \"ok\": false, {rest}}}")
}

/// `COORDINATES`' length, from its type `[&'static str; n]`.
fn count_coordinates(text: &str) -> usize {
    let Some(at) = text.find("COORDINATES") else {
        return 0;
    };
    let rest = &text[at..];
    let Some(semicolon) = rest.find(';') else {
        return 0;
    };
    rest[semicolon + 1..]
        .split(']')
        .next()
        .and_then(|n| n.trim().parse().ok())
        .unwrap_or(0)
}

/// Calls of `sin_cos`, `.sin()` or `.cos()` whose argument is a literal,
/// written in place or bound at the method's top (`__lit{k}`, a constant
/// the method reads more than once).
fn constant_trig(text: &str) -> usize {
    let literal_call = text
        .matches("sin_cos (:: constrained :: __private :: lit")
        .count()
        + text.matches("sin_cos (__lit").count();
    let bound = text
        .match_indices("__lit")
        .filter(|(at, _)| {
            let after = text[at + "__lit".len()..].trim_start_matches(|c: char| c.is_ascii_digit());
            let tail = after.trim_start();
            tail.starts_with(". sin ()") || tail.starts_with(". cos ()")
        })
        .count();
    let method = ["lit :: < T > (", "lit::<T>("]
        .iter()
        .map(|lit| {
            text.match_indices(lit)
                .filter(|(at, _)| {
                    let after = &text[*at..];
                    let close = after.find(')').unwrap_or(0);
                    let tail = after[close + 1..].trim_start();
                    tail.starts_with(". sin ()") || tail.starts_with(". cos ()")
                })
                .count()
        })
        .sum::<usize>();
    literal_call + method + bound
}
