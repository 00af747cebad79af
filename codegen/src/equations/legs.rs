//! Stage 3's decision that a floating base stands on legs: every joint
//! but the base's belongs to one three-joint leg, eliminated through its
//! own foot's three rows (`emit`'s `legs.rs` writes the closed-form
//! elimination; its module docs give the algebra). Decided here, on the
//! velocity form's saddle-point structure, so that the strategy
//! (`super::strategy`) is one value that emission and the derivation read.

use super::velocity::Velocity;

/// The legs of a floating base, by position in the velocity form's
/// coordinates (`Velocity::coordinates`) and rows (`Velocity::rows`).
pub struct Legs {
    /// The base's six unknowns `z`, `β`.
    pub base: [usize; 6],
    /// Each leg's three joints and its foot's three rows.
    pub legs: Vec<([usize; 3], [usize; 3])>,
}

/// The legs of `v`, where every coordinate but a free base's belongs to one
/// and every row to one foot; `None` otherwise (the saddle-point solve
/// answers).
pub(super) fn find(v: &Velocity) -> Option<Legs> {
    let &[(x, _)] = v.system.free.as_slice() else {
        return None;
    };
    // The base's quaternion follows its position: `(x, y, z, w, …)`.
    let w = x + 3;
    if v.system.quaternions.iter().map(|&(c, _)| c).ne([w])
        || v.system.in_base.iter().any(|rows| rows.base != x)
    {
        return None;
    }
    let position = |i: usize| v.coordinates.iter().position(|&c| c == i);
    let base = [x, x + 1, x + 2, w + 1, w + 2, w + 3].map(position);
    let base = base.map(|p| p.unwrap_or(usize::MAX));
    if base.contains(&usize::MAX) {
        return None;
    }
    let (nr, s) = (v.coordinates.len(), &v.structure.nonzero);
    let mut owner: Vec<Option<usize>> = vec![None; nr];
    let mut legs = Vec::new();
    let mut rows_seen = vec![false; v.rows.len()];
    for (t, triple) in v.system.in_base.iter().enumerate() {
        let rows = triple
            .rows
            .map(|r| v.rows.iter().position(|&x| x == r).unwrap_or(usize::MAX));
        if rows.contains(&usize::MAX) {
            return None;
        }
        let joints: Vec<usize> = (0..nr)
            .filter(|p| !base.contains(p))
            .filter(|&p| rows.iter().any(|&rr| s[nr + rr][p]))
            .collect();
        let joints: [usize; 3] = joints.try_into().ok()?;
        for p in joints {
            if owner[p].replace(t).is_some() {
                return None;
            }
        }
        for rr in rows {
            rows_seen[rr] = true;
        }
        legs.push((joints, rows));
    }
    // Every joint in a leg, every row a foot's, and no inertia between legs.
    let covered = (0..nr).all(|p| base.contains(&p) || owner[p].is_some());
    let coupled = (0..nr).any(|i| {
        (0..nr).any(|j| matches!((owner[i], owner[j]), (Some(a), Some(b)) if a != b && s[i][j]))
    });
    (!legs.is_empty() && covered && !coupled && rows_seen.iter().all(|&r| r))
        .then_some(Legs { base, legs })
}
