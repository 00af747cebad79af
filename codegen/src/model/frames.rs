//! The `frames` section: frames fixed in bodies, named for the generated
//! kinematics (`crate::bodies::kinematics`), each written as a body is,
//!
//! ```text
//! frames: [tool { body: panda_link8, xyz: [0.0, 0.0, 0.1034], rpy: [0.0, 0.0, -0.785] }]
//! ```
//!
//! `body` naming any body of the `bodies` section or link of the URDF
//! file (one on a fixed joint too), `xyz` and `rpy` (optional) placing the
//! frame in that body's frame as they place a joint frame in its parent's.

use super::lower::Lowerer;
use crate::bodies::kinematics::{self, Kinematics};
use crate::bodies::Described;
use crate::parse::{BodyInput, List};
use syn::ext::IdentExt;
use syn::{Expr, Ident};

/// The fields of a frame, for messages.
const FIELDS: &str = "`body`, `xyz`, `rpy`";

/// Frame names whose methods (`{name}_jacobian`, ..) another generated
/// method already has: `center_of_mass_jacobian`, `acceleration_jacobian`,
/// `try_acceleration_jacobian`, `gap_jacobian`,
/// `center_of_mass_and_jacobian`.
const RESERVED: &[&str] = &[
    "center_of_mass",
    "center_of_mass_and",
    "acceleration",
    "try_acceleration",
    "gap",
];

impl Lowerer<'_> {
    /// The frames of `list` and the centre of mass of `described`, whose
    /// world frames [`Lowerer::described`] recorded; errors recorded for
    /// every frame that cannot be placed. Without bodies there is nothing
    /// to place (`super::source` says the section needs them).
    pub(super) fn frames_section(
        &mut self,
        list: &List<BodyInput>,
        described: &[Described],
    ) -> Kinematics {
        if described.is_empty() {
            return Kinematics {
                frames: Vec::new(),
                center_of_mass: None,
            };
        }
        let mut frames = Vec::with_capacity(list.items.len());
        let mut seen: Vec<String> = Vec::new();
        for input in &list.items {
            let name = input.name.unraw().to_string();
            if seen.contains(&name) {
                self.errors
                    .spanned(&input.name, format!("duplicate frame `{name}`"));
            } else if RESERVED.contains(&name.as_str()) {
                self.errors.spanned(
                    &input.name,
                    format!("`{name}` is the name of a generated method: name the frame otherwise"),
                );
            }
            seen.push(name.clone());
            if let Some(frame) = self.frame(input, name, described) {
                frames.push(frame);
            }
        }
        let world: Vec<crate::bodies::Placement> = self.frames.iter().map(|(_, p)| *p).collect();
        let center_of_mass = kinematics::center_of_mass(self.graph, described, &world, self.n);
        Kinematics {
            frames,
            center_of_mass,
        }
    }

    /// One frame, or `None` with its errors recorded.
    fn frame(
        &mut self,
        input: &BodyInput,
        name: String,
        described: &[Described],
    ) -> Option<kinematics::Frame> {
        let before = self.errors.count();
        check_fields(self, input);
        let body = match input.fields.iter().find(|(k, _)| k == "body") {
            Some((_, e)) => self.frame_body(e),
            None => {
                self.errors.at(
                    input.span,
                    format!("frame `{name}` needs `body: <a body or link>`"),
                );
                None
            }
        };
        let offset = self.placement(input);
        let body = body.filter(|&b| b < self.frames.len())?;
        let world: Vec<crate::bodies::Placement> = self.frames.iter().map(|(_, p)| *p).collect();
        (self.errors.count() == before).then(|| {
            let bodies = (described, &world[..]);
            kinematics::frame(self.graph, name, bodies, body, &offset, self.n)
        })
    }

    /// The index among the described bodies of the body `e` names.
    fn frame_body(&mut self, e: &Expr) -> Option<usize> {
        let name = match e {
            Expr::Path(p) => p.path.get_ident(),
            _ => None,
        };
        let Some(name) = name else {
            self.errors
                .spanned(e, "expected the name of a body (or URDF link)");
            return None;
        };
        let text = name.unraw().to_string();
        let found = self.frames.iter().position(|(n, _)| *n == text);
        if found.is_none() {
            let known: Vec<String> = self.frames.iter().map(|(n, _)| format!("`{n}`")).collect();
            self.errors.spanned(
                name,
                format!(
                    "unknown body `{text}`: expected one of {}",
                    known.join(", ")
                ),
            );
        }
        found
    }
}

/// Known fields once each; a frame has no inertia.
fn check_fields(lower: &mut Lowerer, input: &BodyInput) {
    if let Some((key, _)) = &input.inertia {
        lower
            .errors
            .spanned(key, "a frame has no inertia: give it to a body");
    }
    let mut seen: Vec<&Ident> = Vec::new();
    for (key, _) in &input.fields {
        if !["body", "xyz", "rpy"].iter().any(|k| key == k) {
            lower.errors.spanned(
                key,
                format!("unknown field `{key}` of a frame: expected one of {FIELDS}"),
            );
        } else if seen.contains(&key) {
            lower
                .errors
                .spanned(key, format!("duplicate field `{key}`"));
        }
        seen.push(key);
    }
}
