//! The URDF robot's links lowered into described bodies: each joint's
//! kind, a chain for floating and planar joints, and mimics resolved to
//! the coordinates they follow.

use super::*;

impl Robot {
    /// The links as bodies, numbers lowered into `g`; a floating joint's
    /// child as the four bodies of a free joint.
    pub fn described(&self, g: &mut Graph) -> Vec<Described> {
        let first = self.first_coordinates();
        let mut out: Vec<Described> = Vec::with_capacity(self.links.len());
        // Each link's index in `out` (its own body, after a chain's slides).
        let mut index: Vec<usize> = Vec::with_capacity(self.links.len());
        for (link, &coordinate) in self.links.iter().zip(&first) {
            let parent = link.parent.and_then(|p| index.get(p).copied());
            let inertia = inertia(g, link.inertial.as_ref(), self.snap);
            let Some(j) = &link.joint else {
                let placement = Placement::identity(g);
                out.push(described(link, parent, placement, None, inertia));
                index.push(out.len() - 1);
                continue;
            };
            let a = angles(g, &j.rpy, self.snap);
            let translation = numbers(g, &j.xyz);
            let placement = Placement {
                rotation: spatial::rpy(g, a),
                translation,
            };
            let at = (parent, placement, out.len());
            match (j.kind, coordinate) {
                (Some(Moves::Floating), Some(c)) => {
                    out.extend(crate::bodies::free::described(
                        g, &link.name, at, c, inertia,
                    ));
                }
                (Some(Moves::Planar), Some(c)) => {
                    out.extend(crate::bodies::joint::planar(g, &link.name, at, c, inertia));
                }
                (Some(Moves::One(kind)), _) => {
                    let (placement, joint) = self.one(g, j, kind, coordinate, &first, placement);
                    out.push(described(link, parent, placement, joint, inertia));
                }
                _ => out.push(described(link, parent, placement, None, inertia)),
            }
            index.push(out.len() - 1);
        }
        out
    }

    /// A one-coordinate joint: its own coordinate, or the one it mimics
    /// (`first` holds each link's). A mimic of a joint that does not move
    /// (fixed or locked) is held where it follows it, at its offset: its
    /// placement takes that motion, and it has no joint.
    fn one(
        &self,
        g: &mut Graph,
        j: &JointSpec,
        kind: JointKind,
        coordinate: Option<usize>,
        first: &[Option<usize>],
        placement: Placement,
    ) -> (Placement, Option<Joint>) {
        let axis = numbers(g, &j.axis);
        let norm2 = spatial::dot(g, axis, axis);
        let norm = g.sqrt(norm2);
        let axis = axis.map(|c| g.div(c, norm));
        let Some(m) = &j.mimic else {
            return (placement, coordinate.map(|c| Joint::new(kind, c, axis)));
        };
        let followed = self
            .links
            .iter()
            .position(|l| l.joint.as_ref().is_some_and(|p| p.name == m.joint))
            .and_then(|i| first[i]);
        let multiplier = number(g, &m.multiplier);
        let offset = number(g, &m.offset);
        match followed {
            Some(c) => {
                let mut joint = Joint::new(kind, c, axis);
                joint.mimic = Some(Mimic { multiplier, offset });
                (placement, Some(joint))
            }
            None => {
                let held =
                    crate::bodies::joint::JointState::at(g, Joint::new(kind, 0, axis), offset);
                let motion = held.placement(g);
                (placement.then(g, &motion), None)
            }
        }
    }

    /// Every `<mimic>` follows a joint of the file with one coordinate or
    /// none, and not another mimic.
    pub(super) fn check_mimics(&self, file: &str) -> syn::Result<()> {
        let joints: Vec<&JointSpec> = self.links.iter().filter_map(|l| l.joint.as_ref()).collect();
        for j in &joints {
            let Some(m) = &j.mimic else { continue };
            let at = |why: String| {
                syn::Error::new(
                    self.span,
                    format!("{file}:{}: joint `{}`: {why}", m.line, j.name),
                )
            };
            let Some(followed) = joints.iter().find(|p| p.name == m.joint) else {
                return Err(at(format!(
                    "<mimic> names `{}`, which is not a joint of the file",
                    m.joint
                )));
            };
            if followed.mimic.is_some() {
                return Err(at(format!(
                    "<mimic> names `{}`, itself a mimic: name the joint it follows",
                    m.joint
                )));
            }
            if matches!(followed.own(), Some(Moves::Floating | Moves::Planar)) {
                return Err(at(format!(
                    "<mimic> names `{}`, which has more than one coordinate",
                    m.joint
                )));
            }
        }
        Ok(())
    }

    /// A joint with coordinates of its own must carry inertia: if every
    /// link it moves (its child and all below) is massless, exactly (no
    /// `<inertial>`, or a mass and an inertia of zero as written), its
    /// column of `M` is zero and no acceleration of it is determined.
    /// Refused here, at the joint, rather than later as a rank deficiency
    /// of `M` with no element named. Pinocchio loads such a file and its
    /// `crba` gives the same zero column.
    pub(super) fn check_inertia(&self, file: &str) -> syn::Result<()> {
        let mut massive: Vec<bool> = self
            .links
            .iter()
            .map(|l| l.inertial.as_ref().is_some_and(Inertial::is_nonzero))
            .collect();
        for i in (0..self.links.len()).rev() {
            if let Some(p) = self.links[i].parent.filter(|_| massive[i]) {
                massive[p] = true;
            }
        }
        // A mimic joint's links move with the joint it follows.
        let followed_by_mass = |name: &str| {
            self.links.iter().zip(&massive).any(|(l, &m)| {
                m && l
                    .joint
                    .as_ref()
                    .and_then(|j| j.mimic.as_ref())
                    .is_some_and(|mimic| mimic.joint == name)
            })
        };
        let empty = self.links.iter().zip(&massive).find(|(l, &m)| {
            !m && l
                .joint
                .as_ref()
                .is_some_and(|j| j.own().is_some() && !followed_by_mass(&j.name))
        });
        let Some((link, _)) = empty else {
            return Ok(());
        };
        let Some(joint) = link.joint.as_ref() else {
            return Ok(());
        };
        Err(syn::Error::new(
            self.span,
            format!(
                "{file}:{}: joint `{}` moves only massless links (from `{}` down: no \
                 <inertial>, or mass and inertia zero), so its column of the mass matrix \
                 is zero and its acceleration is not determined; give a link it moves an \
                 <inertial>, or hold the joint with `locked: [{}]`",
                joint.line,
                joint.name,
                link.name,
                identifier(&joint.name),
            ),
        ))
    }
}

impl Inertial {
    /// Whether the mass or any entry of the inertia is written as a
    /// nonzero number (each was checked to be a finite decimal on reading).
    fn is_nonzero(&self) -> bool {
        std::iter::once(&self.mass)
            .chain(&self.inertia)
            .any(|v| Num::parse_decimal(v).is_some_and(|n| !n.is_zero()))
    }
}
