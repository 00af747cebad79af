//! The joint model: every kind of joint, declared once.
//!
//! A joint places its child's frame in the joint frame by a rotation `R_J`
//! (about its axis, or a quaternion's) and an offset `p_J` (along its
//! axis), both functions of its coordinates, and moves it along its motion
//! subspace `S`: the child's velocity relative to the parent is `S q̇`, in
//! the child's frame (Featherstone, *Rigid Body Dynamics Algorithms*,
//! §4.4, table 4.1; Pinocchio's `JointModelRevoluteUnaligned`,
//! `JointModelPrismaticUnaligned`, `JointModelHelicalUnaligned`,
//! `JointModelSpherical`). The recursions ([`super::recursion`]), the world
//! frames of points ([`super`]) and the derivation read a joint through
//! [`JointState`] only, so a new kind is one variant of [`JointKind`] and
//! one arm in each of [`JointState`]'s few matches, all in this file.
//!
//! | kind | coordinates | `R_J` | `p_J` | `S` (`[ω; v]`) |
//! |---|---|---|---|---|
//! | revolute | `θ` | about `a` by `θ` | 0 | `[a; 0]` |
//! | prismatic | `d` | `I` | `d a` | `[0; a]` |
//! | helical, pitch `h` | `θ` | about `a` by `θ` | `h θ a` | `[a; h a]` |
//! | spherical | `(w, x, y, z)` | `R(q/\|q\|)` | 0 | `[k G(q); 0]` ([`super::free`]) |
//!
//! Joints of more than one kind are chains of these through massless
//! bodies, whose zero inertias fold away: a free joint is three prismatic
//! joints and a spherical one ([`super::free`]), a planar joint two
//! prismatic joints and a revolute one ([`planar`]).
//!
//! A joint may *mimic* another's coordinate (URDF's `<mimic>`): its value
//! is `m q + o` for the coordinate `q` it follows, so its velocity is
//! `m q̇` and its columns of `S` are scaled by `m` and land on that
//! coordinate. The recursions then sum what several joints contribute to
//! one coordinate: `M` becomes `Gᵀ M G` and `τ` becomes `Gᵀ τ` for the
//! map `G` from the coordinates to the joints' values, as in Pinocchio's
//! `JointModelMimic`.

use super::spatial::{self, Inertia, Spatial, M3, V3};
use super::{Described, Placement};
use crate::expr::{Graph, Id, Sym};

/// How a body moves relative to its parent: one row of the module's table.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JointKind {
    /// Rotation by the coordinate about the axis.
    Revolute,
    /// Translation by the coordinate along the axis.
    Prismatic,
    /// Rotation by the coordinate about the axis and translation by
    /// `pitch` times it along the axis (a screw).
    Helical {
        /// The translation per radian.
        pitch: Id,
    },
    /// Rotation by the unit quaternion of four coordinates from
    /// `coordinate` on, `(w, x, y, z)` (the spherical part of a free
    /// joint, [`super::free`]); the axis is unused.
    Quaternion,
}

impl JointKind {
    /// How many coordinates a joint of this kind has.
    pub fn coordinate_count(self) -> usize {
        match self {
            JointKind::Quaternion => 4,
            JointKind::Revolute | JointKind::Prismatic | JointKind::Helical { .. } => 1,
        }
    }

    /// Whether the joint's motion commutes with a translation along its
    /// axis (a turn about it, a slide or a screw along it), so that its
    /// child's frame may move along the axis without changing the dynamics
    /// ([`super::slide`]).
    pub fn commutes_along_axis(self) -> bool {
        match self {
            JointKind::Revolute | JointKind::Prismatic | JointKind::Helical { .. } => true,
            JointKind::Quaternion => false,
        }
    }

    /// Whether the joint turns its child about its axis.
    pub(super) fn turns_about_axis(self) -> bool {
        matches!(self, JointKind::Revolute | JointKind::Helical { .. })
    }
}

/// A joint's value following another joint's coordinate: `multiplier ·
/// q + offset` (URDF's `<mimic>`).
#[derive(Clone, Copy, Debug)]
pub struct Mimic {
    /// `m`.
    pub multiplier: Id,
    /// `o`.
    pub offset: Id,
}

/// A joint: its kind, where its coordinates are, and its axis.
#[derive(Clone, Copy, Debug)]
pub struct Joint {
    /// Which row of the table.
    pub kind: JointKind,
    /// Index of its (first) coordinate in `q`; with `mimic`, the
    /// coordinate it follows.
    pub coordinate: usize,
    /// The unit axis, in the joint's (and the child's) frame.
    pub axis: V3,
    /// `Some`: the joint has no coordinate of its own.
    pub mimic: Option<Mimic>,
    /// `Some(θ₀)`: a constant turn about the axis added to the joint's
    /// angle, `R_J = R(θ₀ + qᵢ)`: its joint frame's turn about the same
    /// axis folded in ([`super::turn`]). `None` for a joint as described.
    pub turn: Option<Id>,
}

impl Joint {
    /// A joint moved by its own coordinates from `coordinate` on.
    pub fn new(kind: JointKind, coordinate: usize, axis: V3) -> Joint {
        Joint {
            kind,
            coordinate,
            axis,
            mimic: None,
            turn: None,
        }
    }

    /// The coordinates the joint moves: one, or a quaternion's four.
    pub fn coordinates(&self) -> std::ops::Range<usize> {
        self.coordinate..self.coordinate + self.kind.coordinate_count()
    }

    /// How the derivation names the joint, given how to print a number
    /// and a vector, and the names of its coordinates (a mimic's value is
    /// `m q + o` of the coordinate it follows).
    pub fn describe(
        &self,
        number: &dyn Fn(Id) -> String,
        vector: &dyn Fn(V3) -> String,
        names: &[&str],
    ) -> String {
        let q = match self.mimic {
            Some(m) => mimic_value(&number(m.multiplier), &names.join(""), &number(m.offset)),
            None => names.join(""),
        };
        let q = match self.turn {
            Some(t) => format!(
                "{q}, turning its child by {} (constant turns about the axis folded in)",
                mimic_value("1", &q, &number(t))
            ),
            None => q,
        };
        let axis = vector(self.axis);
        match self.kind {
            JointKind::Revolute => format!("revolute about {axis}, {q}"),
            JointKind::Prismatic => format!("prismatic along {axis}, {q}"),
            JointKind::Helical { pitch } => {
                format!("helical about {axis}, pitch {}, {q}", number(pitch))
            }
            JointKind::Quaternion => format!(
                "spherical, quaternion ({}) turned by R(q/|q|), ω = k G(q) q̇ (S = [kG; 0], k = 2/|q|²)",
                names.join(", ")
            ),
        }
    }
}

/// `m·q + o` as a person writes it: no `1·`, `−q` for `m = −1`, no `+ 0`,
/// `− x` for a negative offset.
fn mimic_value(m: &str, q: &str, o: &str) -> String {
    let scaled = match m {
        "1" => q.to_string(),
        "-1" | "−1" => format!("−{q}"),
        _ => format!("{m}·{q}"),
    };
    match o {
        "0" => scaled,
        _ => match o.strip_prefix('-').or_else(|| o.strip_prefix('−')) {
            Some(magnitude) => format!("{scaled} − {magnitude}"),
            None => format!("{scaled} + {o}"),
        },
    }
}

/// A joint's motion at the state, as expressions: what the recursions need.
#[derive(Clone, Copy, Debug)]
pub struct JointState {
    joint: Joint,
    /// The joint's value `qᵢ` (`m q + o` for a mimic).
    pub value: Id,
    /// `sin qᵢ`, `cos qᵢ` for a joint that turns about its axis.
    sin_cos: (Id, Id),
    /// A quaternion joint's coordinates and `R(q)`.
    pub quaternion: Option<([Id; 4], M3)>,
}

impl JointState {
    /// The joint's value, sine and cosine, or quaternion and rotation.
    pub fn new(g: &mut Graph, joint: Joint) -> JointState {
        let q = g.sym(Sym::Coord(joint.coordinate));
        let value = match joint.mimic {
            Some(m) => {
                let scaled = g.mul2(m.multiplier, q);
                g.add2(scaled, m.offset)
            }
            None => q,
        };
        Self::at(g, joint, value)
    }

    /// The joint held at the value `value`: a mimic of a locked joint.
    pub fn at(g: &mut Graph, joint: Joint, value: Id) -> JointState {
        let sin_cos = if joint.kind.turns_about_axis() {
            turned_sin_cos(g, value, joint.turn)
        } else {
            (g.int(0), g.int(1))
        };
        let quaternion = (joint.kind == JointKind::Quaternion).then(|| {
            let q = super::free::coordinates(g, joint.coordinate);
            (q, super::free::rotation(g, q))
        });
        JointState {
            joint,
            value,
            sin_cos,
            quaternion,
        }
    }

    /// `p_J`: the child's origin in the joint frame, `None` where it is
    /// the joint frame's.
    pub fn slide(&self, g: &mut Graph) -> Option<V3> {
        match self.joint.kind {
            JointKind::Prismatic => Some(spatial::scale(g, self.value, self.joint.axis)),
            JointKind::Helical { pitch } => {
                let d = g.mul2(pitch, self.value);
                Some(spatial::scale(g, d, self.joint.axis))
            }
            JointKind::Revolute | JointKind::Quaternion => None,
        }
    }

    /// `R_Jᵀ ω`, `R_Jᵀ v`: the two parts of a motion vector of the joint
    /// frame in the child's axes.
    pub fn to_child(self, g: &mut Graph, w: V3, v: V3) -> Spatial {
        if let Some((_, r)) = self.quaternion {
            return Spatial {
                angular: spatial::mat_t_vec(g, &r, w),
                linear: spatial::mat_t_vec(g, &r, v),
            };
        }
        if !self.joint.kind.turns_about_axis() {
            return Spatial {
                angular: w,
                linear: v,
            };
        }
        // The child's axes are the joint's turned by qᵢ: coordinates by
        // −qᵢ. The velocity held: turned, its sums' contents would
        // multiply every product of the sine and cosine.
        let v = spatial::hold3(g, v);
        let (s, c) = self.sin_cos;
        let back = (g.neg(s), c);
        let a = self.joint.axis;
        Spatial {
            angular: spatial::rotate(g, a, back, w),
            linear: spatial::rotate(g, a, back, v),
        }
    }

    /// `R_J n`, `R_J f`: the two parts of a force vector of the child's
    /// axes in the joint frame's.
    pub fn to_parent(self, g: &mut Graph, n: V3, f: V3) -> (V3, V3) {
        if let Some((_, r)) = self.quaternion {
            return (spatial::mat_vec(g, &r, n), spatial::mat_vec(g, &r, f));
        }
        if !self.joint.kind.turns_about_axis() {
            return (n, f);
        }
        let a = self.joint.axis;
        (
            spatial::rotate(g, a, self.sin_cos, n),
            spatial::rotate(g, a, self.sin_cos, f),
        )
    }

    /// An inertia in the child's axes turned into the joint frame's
    /// (about the same point).
    pub fn turn_inertia(&self, g: &mut Graph, inertia: &Inertia) -> Inertia {
        if let Some((_, r)) = self.quaternion {
            let zero = spatial::zero(g);
            return inertia.to_parent(g, &r, zero);
        }
        if !self.joint.kind.turns_about_axis() {
            return *inertia;
        }
        let (a, sin_cos) = (self.joint.axis, self.sin_cos);
        let turn = |g: &mut Graph, v: V3| spatial::rotate(g, a, sin_cos, v);
        let h = turn(g, inertia.first_moment);
        // R Ī Rᵀ: each column turned, then each row; symmetric.
        let cols = spatial::transpose(&inertia.rotational).map(|col| turn(g, col));
        let half = spatial::transpose(&cols);
        let full = half.map(|row| turn(g, row));
        let rotational = [0, 1, 2].map(|r| [0, 1, 2].map(|c| full[r.min(c)][r.max(c)]));
        Inertia {
            mass: inertia.mass,
            first_moment: h,
            rotational,
        }
    }

    /// `Sᵢ`: the joint's motion subspace, one motion vector (in the
    /// child's frame) per coordinate it moves, scaled by a mimic's
    /// multiplier.
    pub fn columns(&self, g: &mut Graph) -> Vec<(usize, Spatial)> {
        let z = spatial::zero(g);
        let (c, a) = (self.joint.coordinate, self.joint.axis);
        let own = match (self.joint.kind, self.quaternion) {
            (JointKind::Revolute, _) => vec![Spatial {
                angular: a,
                linear: z,
            }],
            (JointKind::Prismatic, _) => vec![Spatial {
                angular: z,
                linear: a,
            }],
            (JointKind::Helical { pitch }, _) => vec![Spatial {
                angular: a,
                linear: spatial::scale(g, pitch, a),
            }],
            (JointKind::Quaternion, Some((q, _))) => super::free::subspace(g, q).to_vec(),
            (JointKind::Quaternion, None) => Vec::new(),
        };
        own.into_iter()
            .enumerate()
            .map(|(k, s)| match self.joint.mimic {
                Some(m) => (c + k, s.scale(g, m.multiplier)),
                None => (c + k, s),
            })
            .collect()
    }

    /// `Σ Ṡₖ q̇ₖ`'s angular part where `S` varies with `q` (a quaternion's,
    /// [`super::free::subspace_rate`]), given `ω = S q̇`; `None` where `S` is
    /// constant in the child's frame.
    pub fn column_rate(&self, g: &mut Graph, omega: V3) -> Option<V3> {
        let (q, _) = self.quaternion?;
        let c = self.joint.coordinate;
        let rates = [0, 1, 2, 3].map(|k| g.sym(Sym::Vel(c + k)));
        Some(super::free::subspace_rate(g, q, rates, omega))
    }

    /// `(R_J, p_J)` as a placement.
    pub fn placement(&self, g: &mut Graph) -> Placement {
        let rotation = match self.quaternion {
            Some((_, r)) => r,
            None if self.joint.kind.turns_about_axis() => {
                spatial::axis_rotation(g, self.joint.axis, self.sin_cos)
            }
            None => spatial::identity(g),
        };
        let translation = self.slide(g).unwrap_or_else(|| spatial::zero(g));
        Placement {
            rotation,
            translation,
        }
    }
}

/// `(sin, cos)` of `value + turn`. A constant turn `θ₀ = k π/2 + δ` (`k`
/// the nearest whole number of quarter turns) is applied as `δ` inside
/// the sine and cosine and `k` quarter turns outside, which only swap
/// and negate them: a turn near a right angle (a URDF's `1.5708`, kept
/// exact) then leaves the argument where the joint's own values are,
/// inside the sine's cheapest range for small angles, where `value + θ₀`
/// would put every state into its range reduction. `δ + k·fl(π/2)` is
/// `θ₀` exactly (Sterbenz), so the angle differs from `value + θ₀` by
/// `k` times the rounding of `π/2`, 6·10⁻¹⁷ each.
fn turned_sin_cos(g: &mut Graph, value: Id, turn: Option<Id>) -> (Id, Id) {
    let Some(theta) = turn
        .and_then(|t| g.as_num(t))
        .map(crate::expr::num::Num::to_f64)
    else {
        let angle = match turn {
            Some(t) => g.add2(value, t),
            None => value,
        };
        return spatial::sin_cos(g, angle);
    };
    let quarter = std::f64::consts::FRAC_PI_2;
    let k = (theta / quarter).round();
    let delta = theta - k * quarter;
    let inside = if delta == 0.0 {
        value
    } else {
        let d = g.num(crate::expr::num::Num::Float(delta));
        g.add2(value, d)
    };
    let (s, c) = spatial::sin_cos(g, inside);
    // `k` is within ±4 of a turn of at most a few radians.
    match (k as i64).rem_euclid(4) {
        0 => (s, c),
        1 => (c, g.neg(s)),
        2 => (g.neg(s), g.neg(c)),
        _ => (g.neg(c), s),
    }
}

/// A planar joint as three described bodies: two massless slides along the
/// `x` and `y` axes of the frame `placement` puts in `parent`, then the
/// body itself turning about that frame's `z` (Pinocchio's
/// `JointModelPlanar`, whose placement is `(R_z(θ), (x, y, 0))`).
/// `first` is the index the first slide will have among the described
/// bodies, `coordinate` that of `x` in `q` (then `y`, then `θ`).
pub fn planar(
    g: &mut Graph,
    name: &str,
    (parent, placement, first): (Option<usize>, Placement, usize),
    coordinate: usize,
    inertia: Inertia,
) -> Vec<Described> {
    let zero = g.int(0);
    let one = g.int(1);
    let unit = |k: usize| {
        let mut u = [zero; 3];
        u[k] = one;
        u
    };
    let parts = [
        ("x", JointKind::Prismatic, unit(0)),
        ("y", JointKind::Prismatic, unit(1)),
        ("", JointKind::Revolute, unit(2)),
    ];
    let mut out = Vec::with_capacity(3);
    for (k, (suffix, kind, axis)) in parts.into_iter().enumerate() {
        let last = k == 2;
        out.push(Described {
            name: if last {
                name.to_string()
            } else {
                format!("{name}/{suffix}")
            },
            parent: if k == 0 { parent } else { Some(first + k - 1) },
            placement: if k == 0 {
                placement
            } else {
                Placement::identity(g)
            },
            joint: Some(Joint::new(kind, coordinate + k, axis)),
            inertia: if last { inertia } else { Inertia::zero(g) },
        });
    }
    out
}
