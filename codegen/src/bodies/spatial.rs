//! 3-vectors and 3×3 matrices of expressions, and the spatial (6-D)
//! quantities of rigid-body dynamics built from them (Featherstone, *Rigid
//! Body Dynamics Algorithms*, ch. 2): motion vectors `[ω; v]`, force
//! vectors `[n; f]`, rigid-body inertias by their ten parameters. Every
//! operation goes through the graph's constructors, so the zeros and ones
//! of axis-aligned frames fold away exactly and nothing is built for them.

use crate::expr::num::Num;
use crate::expr::{Func, Graph, Id};

/// A 3-vector of expressions.
pub type V3 = [Id; 3];
/// A 3×3 matrix of expressions, row by row.
pub type M3 = [[Id; 3]; 3];

/// `x` as one operand ([`Func::Hold`]) where it is a sum of two or more
/// parts, so that scaling it by a constant (a rotation by a right angle, a
/// mass) does not copy its terms: what keeps the recursions' expressions
/// O(n) rather than growing with every body they pass through.
pub fn hold(g: &mut Graph, x: Id) -> Id {
    g.hold(x)
}

/// [`hold`] on each component.
pub fn hold3(g: &mut Graph, v: V3) -> V3 {
    v.map(|x| hold(g, x))
}

/// The zero vector.
pub fn zero(g: &mut Graph) -> V3 {
    let z = g.int(0);
    [z; 3]
}

/// The identity matrix.
pub fn identity(g: &mut Graph) -> M3 {
    let (z, o) = (g.int(0), g.int(1));
    [[o, z, z], [z, o, z], [z, z, o]]
}

/// `a + b`.
pub fn add(g: &mut Graph, a: V3, b: V3) -> V3 {
    [0, 1, 2].map(|i| g.add2(a[i], b[i]))
}

/// The sum of 3-vectors, as one sum per component.
pub fn sum(g: &mut Graph, parts: &[V3]) -> V3 {
    [0, 1, 2].map(|k| {
        let terms: Vec<Id> = parts.iter().map(|p| p[k]).collect();
        g.add(&terms)
    })
}

/// `a − b`.
pub fn sub(g: &mut Graph, a: V3, b: V3) -> V3 {
    [0, 1, 2].map(|i| g.sub(a[i], b[i]))
}

/// `s·a` for an expression `s`.
pub fn scale(g: &mut Graph, s: Id, a: V3) -> V3 {
    a.map(|x| g.mul2(s, x))
}

/// `−a`.
pub fn neg(g: &mut Graph, a: V3) -> V3 {
    a.map(|x| g.neg(x))
}

/// `a · b`.
pub fn dot(g: &mut Graph, a: V3, b: V3) -> Id {
    let terms = [0, 1, 2].map(|i| g.mul2(a[i], b[i]));
    g.add(&terms)
}

/// `a × b`.
pub fn cross(g: &mut Graph, a: V3, b: V3) -> V3 {
    let mut c = |i: usize, j: usize| {
        let (p, q) = (g.mul2(a[i], b[j]), g.mul2(a[j], b[i]));
        g.sub(p, q)
    };
    [c(1, 2), c(2, 0), c(0, 1)]
}

/// `m v`.
pub fn mat_vec(g: &mut Graph, m: &M3, v: V3) -> V3 {
    [0, 1, 2].map(|i| dot(g, m[i], v))
}

/// The coordinate axis `v` points along and its sign, where `v` is `±eₖ`
/// exactly.
pub fn unit(g: &Graph, v: V3) -> Option<(usize, Id)> {
    let mut found = None;
    for (k, &x) in v.iter().enumerate() {
        let value = g.as_num(x)?;
        if value.is_zero() {
            continue;
        }
        if found.is_some() || !(value.is_one() || (-value).is_one()) {
            return None;
        }
        found = Some((k, x));
    }
    found
}

/// Whether `m` mixes components: some entry is not the constant 0, 1 or
/// −1 (a symbolic entry counts), so that each component of `m v` is a sum
/// of products. Its input is then worth
/// holding ([`hold3`]): a sum fed through such a matrix is otherwise
/// distributed into every component, and again into whatever reads them.
pub fn mixes(g: &Graph, m: &M3) -> bool {
    m.iter().flatten().any(|&e| {
        !g.as_num(e)
            .is_some_and(|n| n.is_zero() || n.is_one() || (-n).is_one())
    })
}

/// `mᵀ v`.
pub fn mat_t_vec(g: &mut Graph, m: &M3, v: V3) -> V3 {
    mat_vec(g, &transpose(m), v)
}

/// `mᵀ`.
pub fn transpose(m: &M3) -> M3 {
    [0, 1, 2].map(|i| [0, 1, 2].map(|j| m[j][i]))
}

/// `a b`.
pub fn mat_mul(g: &mut Graph, a: &M3, b: &M3) -> M3 {
    let bt = transpose(b);
    [0, 1, 2].map(|i| [0, 1, 2].map(|j| dot(g, a[i], bt[j])))
}

/// `a + b`.
pub fn mat_add(g: &mut Graph, a: &M3, b: &M3) -> M3 {
    [0, 1, 2].map(|i| add(g, a[i], b[i]))
}

/// The cross-product matrix `ã` (`ã v = a × v`).
pub fn skew(g: &mut Graph, a: V3) -> M3 {
    let z = g.int(0);
    let n = a.map(|x| g.neg(x));
    [[z, n[2], a[1]], [a[2], z, n[0]], [n[1], a[0], z]]
}

/// `sin x` and `cos x`, exact where `x` is a constant multiple of π/2 (to
/// within a few units in the last place, as `PI / 2.0` evaluates): a frame
/// turned by a right angle has exact zeros and ones, which then fold; the
/// nearest doubles for any other constant (`crate::expr::rounded`).
pub fn sin_cos(g: &mut Graph, x: Id) -> (Id, Id) {
    if let Some(value) = g.as_num(x).map(Num::to_f64) {
        let quarter = value / std::f64::consts::FRAC_PI_2;
        let k = quarter.round();
        if (quarter - k).abs() <= 4.0 * f64::EPSILON * k.abs().max(1.0) {
            let (s, c) = match (k as i64).rem_euclid(4) {
                0 => (0, 1),
                1 => (1, 0),
                2 => (0, -1),
                _ => (-1, 0),
            };
            return (g.int(s), g.int(c));
        }
    }
    // Any other constant angle: evaluated here, each rounded once, so the
    // generated code has no sine of a constant and whatever it multiplies
    // (a locked subtree's inertia) folds into constants.
    if let Some((s, c)) = g.as_num(x).and_then(crate::expr::rounded::sin_cos) {
        return (g.num(Num::Float(s)), g.num(Num::Float(c)));
    }
    (g.func(Func::Sin, x), g.func(Func::Cos, x))
}

/// The rotation matrix `R = Rz(yaw) Ry(pitch) Rx(roll)` (URDF's `rpy`): its
/// columns are the rotated frame's axes in the fixed frame.
pub fn rpy(g: &mut Graph, angles: V3) -> M3 {
    let [(sr, cr), (sp, cp), (sy, cy)] = angles.map(|a| sin_cos(g, a));
    let z = g.int(0);
    let o = g.int(1);
    let rx = [[o, z, z], [z, cr, g.neg(sr)], [z, sr, cr]];
    let ry = [[cp, z, sp], [z, o, z], [g.neg(sp), z, cp]];
    let rz = [[cy, g.neg(sy), z], [sy, cy, z], [z, z, o]];
    let yx = mat_mul(g, &ry, &rx);
    mat_mul(g, &rz, &yx)
}

/// The rotation about the unit `axis` by the angle of sine `s` and cosine
/// `c` (Rodrigues), as a matrix.
pub fn axis_rotation(g: &mut Graph, axis: V3, (s, c): (Id, Id)) -> M3 {
    let one = g.int(1);
    let v = g.sub(one, c);
    let k = skew(g, axis);
    [0, 1, 2].map(|i| {
        [0, 1, 2].map(|j| {
            let aa = g.mul(&[v, axis[i], axis[j]]);
            let sk = g.mul2(s, k[i][j]);
            let diag = if i == j { c } else { g.int(0) };
            g.add(&[aa, sk, diag])
        })
    })
}

/// `R(θ) v` for the rotation by `θ` (given by its sine and cosine) about
/// the unit `axis`: `a(a·v) + cos θ (v − a(a·v)) + sin θ (a × v)`, written
/// so that the components along an axis-aligned `a` cancel exactly.
pub fn rotate(g: &mut Graph, axis: V3, (s, c): (Id, Id), v: V3) -> V3 {
    let along = dot(g, axis, v);
    let parallel = scale(g, along, axis);
    let normal = sub(g, v, parallel);
    let turned = cross(g, axis, v);
    let normal = scale(g, c, normal);
    let turned = scale(g, s, turned);
    let sum = add(g, parallel, normal);
    add(g, sum, turned)
}

/// `x ← x + y`, where `x` starts at 0: a coordinate that several joints
/// move (a mimic's) sums their parts.
pub fn accumulate(g: &mut Graph, x: &mut Id, y: Id) {
    *x = if g.is_zero(*x) { y } else { g.add2(*x, y) };
}

/// A motion vector `[ω; v]` (angular velocity, velocity of the frame's
/// origin) or a force vector `[n; f]` (moment about the origin, force).
#[derive(Clone, Copy, Debug)]
pub struct Spatial {
    /// `ω` or `n`.
    pub angular: V3,
    /// `v` or `f`.
    pub linear: V3,
}

impl Spatial {
    /// The zero vector.
    pub fn zero(g: &mut Graph) -> Spatial {
        let z = zero(g);
        Spatial {
            angular: z,
            linear: z,
        }
    }

    /// Each component [`hold`]: a body's velocity, acceleration or force.
    pub fn held(self, g: &mut Graph) -> Spatial {
        Spatial {
            angular: hold3(g, self.angular),
            linear: hold3(g, self.linear),
        }
    }

    /// `self + other`.
    pub fn add(self, g: &mut Graph, other: Spatial) -> Spatial {
        Spatial {
            angular: add(g, self.angular, other.angular),
            linear: add(g, self.linear, other.linear),
        }
    }

    /// `s · self`.
    pub fn scale(self, g: &mut Graph, s: Id) -> Spatial {
        Spatial {
            angular: scale(g, s, self.angular),
            linear: scale(g, s, self.linear),
        }
    }

    /// The motion cross product `self × m` (`crm`).
    pub fn cross_motion(self, g: &mut Graph, m: Spatial) -> Spatial {
        let angular = cross(g, self.angular, m.angular);
        let a = cross(g, self.angular, m.linear);
        let b = cross(g, self.linear, m.angular);
        Spatial {
            angular,
            linear: add(g, a, b),
        }
    }

    /// The force cross product `self ×* f` (`crf`).
    pub fn cross_force(self, g: &mut Graph, f: Spatial) -> Spatial {
        let a = cross(g, self.angular, f.angular);
        let b = cross(g, self.linear, f.linear);
        Spatial {
            angular: add(g, a, b),
            linear: cross(g, self.angular, f.linear),
        }
    }

    /// `selfᵀ other` (a force applied to a motion: power).
    pub fn dot(self, g: &mut Graph, other: Spatial) -> Id {
        let a = dot(g, self.angular, other.angular);
        let b = dot(g, self.linear, other.linear);
        g.add2(a, b)
    }
}

/// A rigid-body inertia about a frame's origin, in that frame's axes, by
/// its ten parameters: mass `m`, first moment `h = m c`, and the rotational
/// inertia about the origin `Ī_O = Ī_C + m c̃ c̃ᵀ`.
#[derive(Clone, Copy, Debug)]
pub struct Inertia {
    /// `m`.
    pub mass: Id,
    /// `h = m c`.
    pub first_moment: V3,
    /// `Ī_O`, symmetric.
    pub rotational: M3,
}

/// A body's motion at its centre of mass, where recursive Newton–Euler
/// takes its force there ([`Inertia::force`]), in the body's axes.
#[derive(Clone, Copy, Debug)]
pub struct Center {
    /// `c`, the centre of mass.
    pub com: V3,
    /// `Ī_C`, the rotational inertia about it.
    pub about_com: M3,
    /// `ċ = v_O + ω × c`, the velocity of the centre of mass.
    pub velocity: V3,
    /// `c̈ = a_O + ω̇ × c + ω × ċ`, its classical acceleration.
    pub acceleration: V3,
    /// `L = Ī_C ω`, the angular momentum about it.
    pub spin: V3,
}

impl Inertia {
    /// Whether every entry is the constant zero (a massless body).
    pub fn is_zero(&self, g: &Graph) -> bool {
        g.is_zero(self.mass)
            && self.first_moment.iter().all(|&e| g.is_zero(e))
            && self.rotational.iter().flatten().all(|&e| g.is_zero(e))
    }

    /// No mass.
    pub fn zero(g: &mut Graph) -> Inertia {
        let z = g.int(0);
        Inertia {
            mass: z,
            first_moment: [z; 3],
            rotational: [[z; 3]; 3],
        }
    }

    /// From mass, centre of mass and inertia about the centre of mass
    /// (Featherstone eq. 2.63: `Ī_O = Ī_C + m c̃ c̃ᵀ`).
    pub fn from_com(g: &mut Graph, mass: Id, com: V3, about_com: &M3) -> Inertia {
        let h = scale(g, mass, com);
        let c = skew(g, com);
        let hc = skew(g, h);
        // m c̃ c̃ᵀ = −h̃ c̃.
        let shift = mat_mul(g, &hc, &c);
        let rotational = [0, 1, 2].map(|i| [0, 1, 2].map(|j| g.sub(about_com[i][j], shift[i][j])));
        Inertia {
            mass,
            first_moment: h,
            rotational,
        }
    }

    /// `I m` for a motion vector `m = [ω; v]`: the momentum
    /// `[Ī_O ω + h × v; m v − h × ω]`.
    pub fn apply(&self, g: &mut Graph, m: Spatial) -> Spatial {
        let iw = mat_vec(g, &self.rotational, m.angular);
        let hv = cross(g, self.first_moment, m.linear);
        let mv = scale(g, self.mass, m.linear);
        let hw = cross(g, self.first_moment, m.angular);
        Spatial {
            angular: add(g, iw, hv),
            linear: sub(g, mv, hw),
        }
    }

    /// `I a + v ×* (I v)`: the force recursive Newton–Euler asks of a body
    /// moving with velocity `v = [ω; v_O]` and acceleration `a = [ω̇; a_O]`,
    /// and, where it is taken about the centre of mass, the terms of that.
    /// Where the inertia is numbers, the mass is not zero and it costs
    /// fewer operations (for the body's own `v` and `a`), by Newton and
    /// Euler about the centre of mass `c` moved to the origin: with
    /// `ċ = v_O + ω × c` and `c̈ = a_O + ω̇ × c + ω × ċ` (the classical
    /// acceleration of `c`) and `L = Ī_C ω`, `f = m c̈` and
    /// `n = Ī_C ω̇ + ω × L + c × f`: for a full inertia 102 operations where
    /// the two spatial products and the cross product of them take 126.
    pub fn force(&self, g: &mut Graph, v: Spatial, a: Spatial) -> (Spatial, Option<Center>) {
        let momentum = self.apply(g, v).held(g);
        let ia = self.apply(g, a);
        let gyroscopic = v.cross_force(g, momentum);
        let spatial = ia.add(g, gyroscopic);
        let Some((c, about_center)) = self.center(g) else {
            return (spatial, None);
        };
        let (force, center) = self.about_center(g, (v, a), c, about_center);
        // Near the root, where v and a have few entries, the spatial
        // products of the inertia's constants can be the cheaper: the
        // single body on a vertical axis is `I_zz q̈` one way and twelve
        // operations the other. Both read the same v and a.
        let cost = |g: &Graph, f: &Spatial| {
            let roots: Vec<Id> = f.angular.iter().chain(&f.linear).copied().collect();
            crate::expr::squares::operations(g, &roots)
        };
        if cost(g, &spatial) <= cost(g, &force) {
            (spatial, None)
        } else {
            (force, Some(center))
        }
    }

    /// [`Inertia::force`] about the centre of mass `c` (inertia `Ī_C` there).
    fn about_center(
        &self,
        g: &mut Graph,
        (v, a): (Spatial, Spatial),
        c: V3,
        about_center: M3,
    ) -> (Spatial, Center) {
        let (w, dw) = (v.angular, a.angular);
        // Each vector held, as the recursions hold theirs: a product of
        // two sums stays one product.
        let wc = cross(g, w, c);
        let velocity = add(g, v.linear, wc);
        let velocity = hold3(g, velocity);
        let turning = cross(g, w, velocity);
        let spun = cross(g, dw, c);
        let sum = add(g, a.linear, spun);
        let sum = add(g, sum, turning);
        let acceleration = hold3(g, sum);
        // A multiple of the held `c̈`: nothing more to hold.
        let f = scale(g, self.mass, acceleration);
        let euler = mat_vec(g, &about_center, dw);
        let spin = mat_vec(g, &about_center, w);
        let spin = hold3(g, spin);
        let gyroscopic = cross(g, w, spin);
        let moment = cross(g, c, f);
        let n = add(g, euler, gyroscopic);
        let force = Spatial {
            angular: add(g, n, moment),
            linear: f,
        };
        let center = Center {
            com: c,
            about_com: about_center,
            velocity,
            acceleration,
            spin,
        };
        (force, center)
    }

    /// The same inertia in a frame where this one has rotation `r` and
    /// origin `p`, as [`Inertia::to_parent`], but through the centre of mass
    /// where the inertia is numbers ([`Inertia::force`]'s `c` and `Ī_C`):
    /// `c' = R c + p`, `h' = m c'` and `Ī' = R Ī_C Rᵀ + m (|c'|² 1 − c' c'ᵀ)`,
    /// whose shift needs no `R h` of its own (113 operations against 135
    /// for a dense `R`).
    pub fn moved(self, g: &mut Graph, r: &M3, p: V3) -> Inertia {
        let Some((c, about_center)) = self.center(g) else {
            return self.to_parent(g, r, p);
        };
        let rc = mat_vec(g, r, c);
        let center = add(g, rc, p);
        let h = scale(g, self.mass, center);
        let turned = mat_mul(g, r, &about_center);
        let products: [[Id; 3]; 3] = [0, 1, 2].map(|i| [0, 1, 2].map(|j| g.mul2(h[i], center[j])));
        let diagonal = [0, 1, 2].map(|i| products[i][i]);
        let squared = g.add(&diagonal);
        let mut rotational = [[g.int(0); 3]; 3];
        for row in 0..3 {
            for col in row..3 {
                let rir = dot(g, turned[row], r[col]);
                let mut e = g.sub(rir, products[row][col]);
                if row == col {
                    e = g.add2(e, squared);
                }
                rotational[row][col] = e;
                rotational[col][row] = e;
            }
        }
        Inertia {
            mass: self.mass,
            first_moment: h,
            rotational,
        }
    }

    /// The centre of mass `c = h / m` and the inertia about it `Ī_C = Ī_O +
    /// h̃ c̃` ([`Inertia::from_com`] undone), where every parameter is a
    /// number and the mass is not zero: folded at compile time, exactly for
    /// the decimals of a model (rationals).
    fn center(&self, g: &mut Graph) -> Option<(V3, M3)> {
        let numbers = std::iter::once(&self.mass)
            .chain(&self.first_moment)
            .chain(self.rotational.iter().flatten());
        let constant = numbers.into_iter().all(|&x| g.as_num(x).is_some());
        if !constant || g.is_zero(self.mass) {
            return None;
        }
        let one = g.int(1);
        let inverse = g.div(one, self.mass);
        let c = scale(g, inverse, self.first_moment);
        let (hc, cc) = (skew(g, self.first_moment), skew(g, c));
        let shift = mat_mul(g, &hc, &cc);
        let about_center = mat_add(g, &self.rotational, &shift);
        Some((c, about_center))
    }

    /// Each parameter [`hold`]: a composite inertia.
    pub fn held(&self, g: &mut Graph) -> Inertia {
        Inertia {
            mass: hold(g, self.mass),
            first_moment: hold3(g, self.first_moment),
            rotational: self.rotational.map(|row| hold3(g, row)),
        }
    }

    /// `self + other` (both about the same origin, in the same axes).
    pub fn add(&self, g: &mut Graph, other: &Inertia) -> Inertia {
        Inertia {
            mass: g.add2(self.mass, other.mass),
            first_moment: add(g, self.first_moment, other.first_moment),
            rotational: mat_add(g, &self.rotational, &other.rotational),
        }
    }

    /// The same inertia about the origin of a frame in which this frame has
    /// rotation `r` (columns: this frame's axes) and origin `p`:
    /// `h' = R h + m p` and, with `s = R h + (m/2) p`,
    /// `Ī' = R Ī Rᵀ − (p sᵀ + s pᵀ) + 2 (p·s) 1`: the shift
    /// `−(h̃ p̃ + p̃ h̃) − m p̃ p̃` (`h = R h`) written by
    /// `ã b̃ = b aᵀ − (a·b) 1`, each symmetric entry built once.
    pub fn to_parent(self, g: &mut Graph, r: &M3, p: V3) -> Inertia {
        let m = self.mass;
        let rh = mat_vec(g, r, self.first_moment);
        let half = g.num(crate::expr::num::Num::Rational(1, 2));
        let half_m = g.mul2(half, m);
        let s = scale(g, half_m, p);
        let s = add(g, rh, s);
        // Held: each component is read by three entries and by `p·s`,
        // which would otherwise each multiply its terms one by one.
        let s = hold3(g, s);
        let turned = mat_mul(g, r, &self.rotational);
        let ps = dot(g, p, s);
        let two = g.int(2);
        let diagonal = g.mul2(two, ps);
        let mut rotational = [[g.int(0); 3]; 3];
        for row in 0..3 {
            for col in row..3 {
                let rir = dot(g, turned[row], r[col]);
                let a = g.mul2(p[row], s[col]);
                let b = g.mul2(s[row], p[col]);
                let mut e = g.sub(rir, a);
                e = g.sub(e, b);
                if row == col {
                    e = g.add2(e, diagonal);
                }
                rotational[row][col] = e;
                rotational[col][row] = e;
            }
        }
        let mp = scale(g, m, p);
        Inertia {
            mass: m,
            first_moment: add(g, rh, mp),
            rotational,
        }
    }
}

#[cfg(test)]
#[path = "spatial_tests.rs"]
mod tests;
