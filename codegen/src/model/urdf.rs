//! The `urdf` section: a URDF file read at compile time into the
//! [`Described`] bodies of `crate::bodies`.
//!
//! Read: `<link>` (its `<inertial>`: `<origin xyz rpy>`, `<mass value>`,
//! `<inertia ixx ixy ixz iyy iyz izz>`, about the inertial frame's origin,
//! which is the centre of mass), `<joint>` of type `revolute`,
//! `continuous`, `prismatic`, `planar`, `fixed` or `floating` (`<origin
//! xyz rpy>`, `<parent link>`, `<child link>`, `<axis xyz>`, default
//! `1 0 0`), and `<mimic joint multiplier offset>` on a one-coordinate
//! joint: it follows the joint it names, `m q + o`, with no coordinate of
//! its own (`crate::bodies::joint`), as Pinocchio's `buildModel(..,
//! mimic=True)` reads it; a mimic of a joint that does not move is held at
//! its offset. Ignored, as by the rigid-body algorithms of Pinocchio:
//! visual and collision geometry, `<limit>`, `<dynamics>`,
//! `<safety_controller>`, `<calibration>`, `<transmission>`, `<gazebo>`,
//! `<material>`, `<mimic>` on a fixed or locked joint, and a planar
//! joint's `<axis>` (its plane is the joint frame's `x`–`y`, as in
//! Pinocchio). Refused with the file and line: other joint types, a mimic
//! of a mimic or of a joint with several coordinates, a tree with no
//! single root, a link that is two joints' child, a missing or unreadable
//! number.
//!
//! The joints become the coordinates, named after the joints (characters
//! other than letters, digits and `_` replaced by `_`), in Pinocchio's
//! order (`model.names[1:]` of `pinocchio::urdf::buildModel`): depth-first
//! from the root, the child joints of each link in the order of their
//! names compared byte by byte (urdfdom keeps the joints in a map keyed by
//! name), whatever their order in the file. Fixed joints take no
//! coordinate but are walked through in the same order. The generated
//! `COORDINATES` lists the joints' names as written in the file. Joints
//! named in `locked: [..]` are held at zero (fixed).
//!
//! A `floating` joint is the `bodies` section's free joint
//! (`crate::bodies::free`): seven coordinates, named after the joint with
//! `_x`, `_y`, `_z` (the child's origin in the joint frame) and `_qw`,
//! `_qx`, `_qy`, `_qz` (its attitude, a unit quaternion whose norm is a
//! constraint), in that order — `w` first, unlike Pinocchio's `q`. A
//! `planar` joint has three, `_x`, `_y`, `_theta`
//! (`crate::bodies::joint::planar`).
//!
//! Numbers are read as written, exactly (decimals are rationals until the
//! generated code rounds them once). One exception keeps exact zeros: an
//! angle of `rpy` that is a nonzero multiple of π/2 to double precision
//! (`1.5707963267948966`, `-3.141592653589793`: within 4 ulps) is that
//! multiple exactly, which moves no answer by more than rounding. Anything
//! farther (`1.5708`, `1.57079632679`) is the angle written, as Pinocchio,
//! MuJoCo and Drake read it.

use crate::bodies::spatial::{self, Inertia};
use crate::bodies::{Described, Joint, JointKind, Mimic, Placement};
use crate::expr::num::Num;
use crate::expr::Graph;
use crate::parse::List;
use proc_macro2::Span;
use syn::{Ident, LitFloat, LitStr};

/// A URDF tree, its numbers as written.
pub struct Robot {
    /// The file as the build reads it, for `include_bytes!`.
    pub path: String,
    links: Vec<Link>,
    span: Span,
    /// `right_angles_within`: the tolerance, in radians, within which an
    /// angle is read as the multiple of π/2 it is near (`None`: only a
    /// decimal that is that multiple to double precision).
    snap: Option<f64>,
}

/// One link in depth-first order; the joint that carries it, if any.
struct Link {
    name: String,
    parent: Option<usize>,
    joint: Option<JointSpec>,
    inertial: Option<Inertial>,
}

/// A link's `<inertial>` as written: origin `xyz`, `rpy`, mass, and
/// `ixx ixy ixz iyy iyz izz`.
struct Inertial {
    xyz: [String; 3],
    rpy: [String; 3],
    mass: String,
    inertia: [String; 6],
}

/// How a URDF joint moves: a row of the joint model
/// (`crate::bodies::joint`), or one of the chains of rows.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Moves {
    /// `revolute`, `continuous` or `prismatic`: one coordinate.
    One(JointKind),
    /// `floating`: a free joint, seven coordinates.
    Floating,
    /// `planar`: three coordinates.
    Planar,
}

impl Moves {
    /// The coordinates' suffixes after the joint's name (none: the name).
    fn suffixes(self) -> &'static [&'static str] {
        match self {
            Moves::One(_) => &[""],
            Moves::Floating => &FLOATING,
            Moves::Planar => &PLANAR,
        }
    }
}

/// A `<mimic>` on a joint that moves, as written, with its line.
struct MimicSpec {
    joint: String,
    multiplier: String,
    offset: String,
    line: u32,
}

struct JointSpec {
    name: String,
    /// `None`: fixed (or locked).
    kind: Option<Moves>,
    xyz: [String; 3],
    rpy: [String; 3],
    axis: [String; 3],
    /// `Some`: the joint follows another's coordinate and has none itself.
    mimic: Option<MimicSpec>,
    /// Where the file writes it, for messages.
    line: u32,
}

impl JointSpec {
    /// The coordinates the joint has: none for a fixed, locked or mimic joint.
    fn own(&self) -> Option<Moves> {
        self.kind.filter(|_| self.mimic.is_none())
    }
}

type Node<'a, 'i> = roxmltree::Node<'a, 'i>;

struct Reader<'a> {
    doc: &'a roxmltree::Document<'a>,
    file: &'a str,
    span: Span,
}

impl Reader<'_> {
    fn error(&self, node: Node, message: impl std::fmt::Display) -> syn::Error {
        let pos = self.doc.text_pos_at(node.range().start);
        syn::Error::new(self.span, format!("{}:{}: {message}", self.file, pos.row))
    }

    fn attribute(&self, node: Node, name: &str) -> syn::Result<String> {
        node.attribute(name).map(str::to_string).ok_or_else(|| {
            self.error(
                node,
                format!("<{}> needs the attribute `{name}`", node.tag_name().name()),
            )
        })
    }

    fn numbers<const N: usize>(
        &self,
        node: Node,
        name: &str,
        default: &str,
    ) -> syn::Result<[String; N]> {
        let text = node.attribute(name).unwrap_or(default);
        let parts: Vec<&str> = text.split_whitespace().collect();
        if parts.len() != N
            || parts
                .iter()
                .any(|p| Num::parse_decimal(p).is_none_or(|n| !n.to_f64().is_finite()))
        {
            return Err(self.error(
                node,
                format!("`{name}` must be {N} finite numbers, not \"{text}\""),
            ));
        }
        Ok(std::array::from_fn(|i| parts[i].to_string()))
    }

    fn child<'a, 'i>(node: Node<'a, 'i>, name: &str) -> Option<Node<'a, 'i>> {
        node.children().find(|c| c.has_tag_name(name))
    }

    fn origin(&self, node: Node) -> syn::Result<([String; 3], [String; 3])> {
        match Self::child(node, "origin") {
            Some(o) => Ok((
                self.numbers(o, "xyz", "0 0 0")?,
                self.numbers(o, "rpy", "0 0 0")?,
            )),
            None => Ok((zeros(), zeros())),
        }
    }

    fn inertial(&self, link: Node) -> syn::Result<Option<Inertial>> {
        let Some(inertial) = Self::child(link, "inertial") else {
            return Ok(None);
        };
        let (xyz, rpy) = self.origin(inertial)?;
        let mass = Self::child(inertial, "mass")
            .ok_or_else(|| self.error(inertial, "<inertial> needs <mass>"))?;
        let [mass] = self.numbers::<1>(mass, "value", "")?;
        let inertia = Self::child(inertial, "inertia")
            .ok_or_else(|| self.error(inertial, "<inertial> needs <inertia>"))?;
        let names = ["ixx", "ixy", "ixz", "iyy", "iyz", "izz"];
        let mut values: [String; 6] = Default::default();
        for (value, name) in values.iter_mut().zip(names) {
            [*value] = self.numbers::<1>(inertia, name, "")?;
        }
        Ok(Some(Inertial {
            xyz,
            rpy,
            mass,
            inertia: values,
        }))
    }

    fn joint(&self, joint: Node, locked: &[String]) -> syn::Result<JointSpec> {
        let name = self.attribute(joint, "name")?;
        let is_locked = locked.contains(&identifier(&name));
        let kind = match self.attribute(joint, "type")?.as_str() {
            _ if is_locked => None,
            "revolute" | "continuous" => Some(Moves::One(JointKind::Revolute)),
            "prismatic" => Some(Moves::One(JointKind::Prismatic)),
            "floating" => Some(Moves::Floating),
            "planar" => Some(Moves::Planar),
            "fixed" => None,
            other => {
                return Err(self.error(joint, format!(
                    "joint `{name}` of type `{other}` is not supported (revolute, continuous, prismatic, planar, floating, fixed)"
                )))
            }
        };
        // A fixed or locked joint does not move, so whom it would mimic is
        // moot (TALOS's grippers write <mimic> on fixed joints).
        let mimic = match Self::child(joint, "mimic").filter(|_| kind.is_some()) {
            Some(m) => Some(self.mimic(m, &name, kind)?),
            None => None,
        };
        let (xyz, rpy) = self.origin(joint)?;
        let axis = match Self::child(joint, "axis") {
            Some(a) => self.numbers(a, "xyz", "1 0 0")?,
            None => ["1".into(), "0".into(), "0".into()],
        };
        Ok(JointSpec {
            name,
            kind,
            xyz,
            rpy,
            axis,
            mimic,
            line: self.doc.text_pos_at(joint.range().start).row,
        })
    }

    /// `<mimic joint multiplier offset>` on the joint `name`, which moves
    /// as `kind`: only a one-coordinate joint can follow one coordinate.
    fn mimic(&self, m: Node, name: &str, kind: Option<Moves>) -> syn::Result<MimicSpec> {
        if !matches!(kind, Some(Moves::One(_))) {
            return Err(self.error(
                m,
                format!(
                    "joint `{name}`: only a revolute, continuous or prismatic joint can <mimic>"
                ),
            ));
        }
        let [multiplier] = self.numbers::<1>(m, "multiplier", "1")?;
        let [offset] = self.numbers::<1>(m, "offset", "0")?;
        Ok(MimicSpec {
            joint: self.attribute(m, "joint")?,
            multiplier,
            offset,
            line: self.doc.text_pos_at(m.range().start).row,
        })
    }
}

/// The suffixes of a floating joint's coordinates.
const FLOATING: [&str; 7] = ["_x", "_y", "_z", "_qw", "_qx", "_qy", "_qz"];

/// The suffixes of a planar joint's coordinates.
const PLANAR: [&str; 3] = ["_x", "_y", "_theta"];

fn zeros() -> [String; 3] {
    ["0".into(), "0".into(), "0".into()]
}

/// A joint's name as a Rust identifier.
fn identifier(name: &str) -> String {
    let mut s: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if s.is_empty() || s.starts_with(|c: char| c.is_ascii_digit()) {
        s.insert(0, 'j');
    }
    s
}

impl Robot {
    /// Reads the file named by `path`, relative to the directory of the
    /// crate being compiled (`CARGO_MANIFEST_DIR`).
    pub fn read(
        path: &LitStr,
        locked: Option<&List<Ident>>,
        snap: Option<&LitFloat>,
    ) -> syn::Result<Robot> {
        let snap = snap.map(tolerance).transpose()?;
        let base = std::env::var("CARGO_MANIFEST_DIR").unwrap_or_else(|_| ".".into());
        let full = std::path::Path::new(&base).join(path.value());
        // Messages name the file as written (relative to the manifest).
        let file = path.value();
        let text = std::fs::read_to_string(&full)
            .map_err(|e| syn::Error::new(path.span(), format!("cannot read `{file}`: {e}")))?;
        let doc = roxmltree::Document::parse(&text).map_err(|e| {
            syn::Error::new(
                path.span(),
                format!("{file}: not a well-formed XML file: {e}"),
            )
        })?;
        let reader = Reader {
            doc: &doc,
            file: &file,
            span: path.span(),
        };
        let locked: Vec<String> = locked.map_or_else(Vec::new, |l| {
            l.items.iter().map(ToString::to_string).collect()
        });
        let links = reader.tree(&locked)?;
        if links
            .iter()
            .all(|l| l.joint.as_ref().is_none_or(|j| j.own().is_none()))
        {
            return Err(reader.error(
                doc.root_element(),
                "no joint of the robot moves (every one is fixed or locked): \
                 a system needs at least one coordinate",
            ));
        }
        let known: Vec<String> = links
            .iter()
            .filter_map(|l| l.joint.as_ref())
            .map(|j| identifier(&j.name))
            .collect();
        if let Some(unknown) = locked.iter().find(|name| !known.contains(name)) {
            let at = path.span();
            return Err(syn::Error::new(
                at,
                format!("`{unknown}` is not a joint of `{file}`"),
            ));
        }
        let robot = Robot {
            path: full.display().to_string(),
            links,
            span: path.span(),
            snap,
        };
        robot.check_mimics(&file)?;
        robot.check_inertia(&file)?;
        Ok(robot)
    }

    /// The coordinates: the movable joints' names, in the tree's order (a
    /// floating or planar joint's suffixed, see the module docs; a mimic
    /// joint has none).
    pub fn coordinates(&self) -> Vec<Ident> {
        self.coordinate_names()
            .iter()
            .map(|name| Ident::new(&identifier(name), self.span))
            .collect()
    }

    /// The coordinates' names as the file writes the joints' (a floating
    /// or planar joint's suffixed), in the order of
    /// [`coordinates`](Self::coordinates).
    pub fn coordinate_names(&self) -> Vec<String> {
        let mut out = Vec::new();
        for j in self.links.iter().filter_map(|l| l.joint.as_ref()) {
            if let Some(moves) = j.own() {
                out.extend(moves.suffixes().iter().map(|s| format!("{}{s}", j.name)));
            }
        }
        out
    }

    /// The index in `q` of each floating joint's `qw`.
    pub fn quaternions(&self) -> Vec<usize> {
        let mut coordinate = 0;
        let mut out = Vec::new();
        for moves in self.links.iter().filter_map(|l| l.joint.as_ref()?.own()) {
            if moves == Moves::Floating {
                out.push(coordinate + 3);
            }
            coordinate += moves.suffixes().len();
        }
        out
    }

    /// The first coordinate of each link's joint (`None`: it has none).
    fn first_coordinates(&self) -> Vec<Option<usize>> {
        let mut coordinate = 0;
        self.links
            .iter()
            .map(|l| {
                let moves = l.joint.as_ref()?.own()?;
                coordinate += moves.suffixes().len();
                Some(coordinate - moves.suffixes().len())
            })
            .collect()
    }
}

fn described(
    link: &Link,
    parent: Option<usize>,
    placement: Placement,
    joint: Option<Joint>,
    inertia: Inertia,
) -> Described {
    Described {
        name: link.name.clone(),
        parent,
        placement,
        joint,
        inertia,
    }
}

/// A link's inertia about its frame's origin, from its `<inertial>`.
fn inertia(g: &mut Graph, inertial: Option<&Inertial>, snap: Option<f64>) -> Inertia {
    let Some(Inertial {
        xyz,
        rpy,
        mass,
        inertia: i,
    }) = inertial
    else {
        return Inertia::zero(g);
    };
    let a = angles(g, rpy, snap);
    let r = spatial::rpy(g, a);
    let [xx, xy, xz, yy, yz, zz] = i.clone().map(|v| number(g, &v));
    let local = [[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]];
    let rl = spatial::mat_mul(g, &r, &local);
    let about_com = spatial::mat_mul(g, &rl, &spatial::transpose(&r));
    let mass = number(g, mass);
    let com = numbers(g, xyz);
    Inertia::from_com(g, mass, com, &about_com)
}

impl Reader<'_> {
    /// Each link's parent link and the joint between them, as written.
    fn parents<'n>(
        &self,
        names: &[String],
        joint_nodes: &[Node<'n, 'n>],
    ) -> syn::Result<Vec<Option<(usize, Node<'n, 'n>)>>> {
        let mut parent_of: Vec<Option<(usize, Node)>> = vec![None; names.len()];
        for &j in joint_nodes {
            let link_of = |tag: &str| -> syn::Result<usize> {
                let node = Self::child(j, tag)
                    .ok_or_else(|| self.error(j, format!("<joint> needs <{tag} link=..>")))?;
                let name = self.attribute(node, "link")?;
                names
                    .iter()
                    .position(|n| *n == name)
                    .ok_or_else(|| self.error(node, format!("unknown link `{name}`")))
            };
            let (parent, child) = (link_of("parent")?, link_of("child")?);
            if parent_of[child].is_some() {
                return Err(self.error(
                    j,
                    format!("link `{}` is the child of two joints", names[child]),
                ));
            }
            parent_of[child] = Some((parent, j));
        }
        Ok(parent_of)
    }

    /// The links in depth-first order from the single root.
    fn tree(&self, locked: &[String]) -> syn::Result<Vec<Link>> {
        let robot = self.doc.root_element();
        if !robot.has_tag_name("robot") {
            return Err(self.error(robot, "the root element must be <robot>"));
        }
        let link_nodes: Vec<Node> = robot
            .children()
            .filter(|c| c.has_tag_name("link"))
            .collect();
        let joint_nodes: Vec<Node> = robot
            .children()
            .filter(|c| c.has_tag_name("joint"))
            .collect();
        let names: Vec<String> = link_nodes
            .iter()
            .map(|l| self.attribute(*l, "name"))
            .collect::<syn::Result<_>>()?;
        let parent_of = self.parents(&names, &joint_nodes)?;
        let roots: Vec<usize> = (0..names.len())
            .filter(|&i| parent_of[i].is_none())
            .collect();
        let [root] = roots[..] else {
            return Err(self.error(
                robot,
                format!(
                    "the links must form one tree; roots: {:?}",
                    roots.iter().map(|&r| &names[r]).collect::<Vec<_>>()
                ),
            ));
        };
        let mut links = Vec::with_capacity(names.len());
        let mut stack = vec![(root, None)];
        let mut visited = 0;
        while let Some((i, parent)) = stack.pop() {
            visited += 1;
            if visited > names.len() {
                break;
            }
            let joint = match parent_of[i] {
                Some((_, j)) => Some(self.joint(j, locked)?),
                None => None,
            };
            links.push(Link {
                name: names[i].clone(),
                parent,
                joint,
                inertial: self.inertial(link_nodes[i])?,
            });
            let me = links.len() - 1;
            // Children by their joints' names, byte by byte: urdfdom keeps
            // the joints in a map keyed by name and hands each link its
            // child joints in that order, which is the order Pinocchio's
            // `buildModel` numbers them in. Pushed in reverse onto the stack.
            let mut children: Vec<(&str, usize)> = (0..names.len())
                .filter_map(|c| {
                    let (p, joint) = parent_of[c]?;
                    (p == i).then(|| (joint.attribute("name").unwrap_or_default(), c))
                })
                .collect();
            children.sort_unstable();
            stack.extend(children.into_iter().rev().map(|(_, c)| (c, Some(me))));
        }
        if links.len() != names.len() {
            return Err(self.error(robot, "the joints form a loop: a URDF is a tree"));
        }
        Ok(links)
    }
}

#[path = "urdf_bodies.rs"]
mod bodies_of;

#[path = "urdf_numbers.rs"]
mod numbers;
use numbers::{angles, number, numbers, tolerance};

#[cfg(test)]
#[path = "urdf_tests.rs"]
mod tests;
