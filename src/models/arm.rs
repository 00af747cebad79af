use crate::constrained_system;

constrained_system! {
    /// A planar two-link arm in joint angles: `th1` of the first link from the
    /// horizontal, `th2` of the second relative to the first; point masses
    /// `m1`, `m2` at the ends of links `l1`, `l2`; gravity along −y. The mass
    /// matrix depends on `th2` and is not diagonal, and the impressed forces
    /// carry the Coriolis and centrifugal terms of Lagrange's equations. The
    /// tip is held on the horizontal line `y = height`.
    pub struct TwoLinkArmOnLine {
        coordinates: [th1, th2],
        parameters: [m1, m2, l1, l2, g, height],
        definitions: [
            coupling = m2 * l1 * l2 * th2.cos(),
            centrifugal = m2 * l1 * l2 * th2.sin(),
            gravity2 = m2 * g * l2 * (th1 + th2).cos(),
        ],
        mass: [
            [(m1 + m2) * l1.powi(2) + m2 * l2.powi(2) + 2.0 * coupling, m2 * l2.powi(2) + coupling],
            [m2 * l2.powi(2) + coupling, m2 * l2.powi(2)],
        ],
        forces: [
            centrifugal * (2.0 * dot(th1) * dot(th2) + dot(th2).powi(2))
                - (m1 + m2) * g * l1 * th1.cos() - gravity2,
            -centrifugal * dot(th1).powi(2) - gravity2,
        ],
        constraints: [l1 * th1.sin() + l2 * (th1 + th2).sin() == height],
    }
}
