//! Stage 3: [`System`] → [`Equations`]: the constraints differentiated into
//! `A q̈ = b` by the total-derivative rule; then Gauss's principle
//! ([`mass_inverse`]) and the tangent pieces (`tangent`).

mod auxiliary;
mod conditioned;
pub mod gibbs_appell;
pub mod held;
pub mod in_base;
pub mod legs;
pub mod mass_inverse;
pub mod partition;
mod point_tangent;
pub mod saddle_point;
pub mod strategy;
mod surface;
pub(crate) mod tangent;
pub mod velocity;

use crate::expr::common_factors::Factorer;
use crate::expr::diff::{AtRest, Differentiator};
use crate::expr::Id;
use crate::expr::Sym;
use crate::model::{BodyTerms, Constraint, Level, System};
use mass_inverse::MassInverse;
use partition::Partition;
use tangent::{Pieces, Tangent};

/// A system together with its derived constraint equations: everything
/// stage 3 builds is a field of its own, so that stage 2's [`System`] holds
/// only what the input says.
pub struct Equations {
    /// The checked input (its `M` and `F` with their common factors pulled
    /// out, as everything built from them carries them).
    pub system: System,
    /// `A`, k × n: `Aᵢⱼ = ∂ψᵢ/∂q̈ⱼ`.
    pub a: Vec<Vec<Id>>,
    /// `b`, k: `bᵢ = −ψᵢ|_{q̈=0}`.
    pub b: Vec<Id>,
    /// The constraints at velocity level: `φ̇` for position-level `φ`, `φ`
    /// itself otherwise. Zero on consistent states; its Jacobian in `q̇` is `A`.
    pub velocity_constraints: Vec<Id>,
    /// With quaternion joints, `gauss`'s terms in their velocity
    /// coordinates ([`velocity`]).
    pub velocity: Option<VelocityTerms>,
    /// How Gauss's principle is solved (see [`mass_inverse`]).
    pub mass_inverse: MassInverse,
    /// The derivatives of `F`, `M`, `A`, `b` behind `acceleration_jacobian`
    /// (see `equations::tangent`); none when not `jacobians`.
    pub tangent: Tangent,
    /// Whether the Jacobian and linearization are generated
    /// ([`crate::Options`]).
    pub jacobians: bool,
    /// The generalized momentum `p = M(q, t) q̇`, n entries.
    pub momentum: Vec<Id>,
    /// `∂τ/∂q` and `∂τ/∂q̇` of the bodies' inverse dynamics, n × n each
    /// (`inverse_dynamics_jacobian`); where `derivatives:
    /// [inverse_dynamics]` asks for them only.
    pub inverse_jacobian: Option<[Vec<Vec<Id>>; 2]>,
    /// The Gibbs–Appell partition ([`partition`]), measured at consistent
    /// states of the equations above, so found last.
    pub partition: Partition,
}

/// `M` and `F` of a tree with quaternion joints in the quaternions'
/// velocity coordinates, with their common factors pulled out as `M` and
/// `F` are: what [`velocity::form`] is built from.
#[derive(Clone, Debug)]
pub struct VelocityTerms {
    /// `TᵀMT` (the recursions' `velocity_mass`).
    pub mass: Vec<Vec<Id>>,
    /// `TᵀF`, from `F` and the recursions' `velocity_bias`
    /// ([`velocity::forces`]).
    pub forces: Vec<Id>,
}

/// Stage 3: the constraint equations (`constraint_equations`), then the
/// Gibbs–Appell partition measured on them; `Err` where `eliminate` or `M`
/// cannot serve (spanned on it).
pub fn derive(system: System, jacobians: bool) -> syn::Result<Equations> {
    let mut equations = constraint_equations(system, jacobians);
    equations.partition = partition::partition(&equations)?;
    conditioned::reorder(&mut equations);
    Ok(equations)
}

/// Differentiates every constraint: velocity-level φ once, position-level φ
/// twice (`ψ = D φ` or `ψ = D(D φ)`), and splits `ψ` into `A q̈ − b`; then
/// decides how `M⁻¹` is applied and builds the tangent pieces and the
/// momentum. The partition is left empty: [`derive()`] measures it.
///
/// Rows are not normalised: `A` and `b` are the derivatives of φ exactly as
/// written, so that a user's scaling of φ shows up unchanged.
/// `M`, `F`, `A` and `b` have their common factors pulled out
/// ([`crate::expr::common_factors`]) before anything is built from them, so that the
/// derivation and the code both carry the factored forms.
fn constraint_equations(mut system: System, jacobians: bool) -> Equations {
    let n = system.dof();
    let mut factorer = Factorer::keeping(system.named.iter().map(|(_, id)| *id));
    let velocity = factored_dynamics(&mut system, &mut factorer);
    let g = &mut system.graph;
    let in_base = in_base::rows(g, &system.constraints, n);
    let dynamics = (&system.mass[..], &system.forces[..]);
    let rows = constraint_rows(g, &mut factorer, dynamics, &system.constraints, &in_base);
    let tree = system.bodies.as_ref().zip(velocity.as_ref());
    let tree = tree.map(|(t, v)| velocity::Bodies {
        mass: &v.mass,
        forces: &v.forces,
        bodies: &t.tree[..],
        in_base: &in_base[..],
        held: &system.held[..],
    });
    let mass_inverse = mass_inverse::build(
        g,
        &mut factorer,
        (&system.mass, tree),
        &system.forces,
        &rows.a,
        &rows.b,
    );
    let (tangent, inverse_jacobian) =
        derivatives(&mut system, &mass_inverse, (&rows, &in_base), jacobians);
    let momentum = momentum(&mut system.graph, &system.mass, system.bodies.as_ref());
    Equations {
        momentum,
        inverse_jacobian,
        jacobians,
        system,
        a: rows.a,
        b: rows.b,
        velocity_constraints: rows.velocity_constraints,
        velocity,
        mass_inverse,
        tangent,
        partition: Partition::default(),
    }
}

/// The tangent pieces of `acceleration_jacobian` (none without
/// `jacobians`) and the bodies' `inverse_dynamics_jacobian` where
/// `derivatives: [inverse_dynamics]` asks for it.
fn derivatives(
    system: &mut System,
    mass_inverse: &MassInverse,
    (rows, in_base): (&Rows, &[in_base::InBaseRows]),
    jacobians: bool,
) -> (Tangent, Option<[Vec<Vec<Id>>; 2]>) {
    let n = system.dof();
    let inputs: Vec<Sym> = (0..system.inputs).map(|j| system.input(j)).collect();
    // `∂τ/∂q`, `∂τ/∂q̇`, for `inverse_dynamics_jacobian` and for the
    // tangents of a tree whose `M` is factored, on an auxiliary mass
    // (quaternion joints) too: every `M` but a symbolic inverse's.
    let factored = !matches!(mass_inverse, MassInverse::Symbolic(_));
    let inverse_dynamics = system
        .bodies
        .as_ref()
        .filter(|b| (jacobians && factored) || b.inverse_derivatives)
        .map(|b| inverse_dynamics_jacobian(&mut system.graph, b));
    let through_inverse = match (&system.bodies, &inverse_dynamics) {
        (Some(b), Some(jacobian)) if jacobians && factored => Some(tangent::ThroughInverse {
            applied: &b.applied,
            jacobian,
        }),
        _ => None,
    };
    // Long trees on an auxiliary mass (quaternion joints) differentiate
    // `M q̈` (O(n) from the recursions) rather than `M`'s n² entries (see
    // `PRODUCTS_FROM`).
    let mass_times = match (&system.bodies, &mass_inverse) {
        (Some(b), MassInverse::Auxiliary(_)) if jacobians && n >= tangent::PRODUCTS_FROM => Some(
            crate::bodies::recursion::mass_times(&mut system.graph, &b.tree, n),
        ),
        _ => None,
    };
    let pieces = Pieces {
        mass: &system.mass,
        mass_times: mass_times.as_deref(),
        through_inverse,
        forces: &system.forces,
        a: &rows.a,
        b: &rows.b,
        velocity_constraints: &rows.velocity_constraints,
        in_base,
    };
    let tangent = if jacobians {
        tangent::tangent(&mut system.graph, &pieces, &inputs)
    } else {
        Tangent::none()
    };
    let inverse_jacobian = match (&system.bodies, inverse_dynamics) {
        (Some(b), Some(jacobian)) if b.inverse_derivatives => Some(jacobian),
        _ => None,
    };
    (tangent, inverse_jacobian)
}

/// `M` and `F` with their common factors pulled out, and for quaternion
/// joints the same two in their velocity coordinates. `TᵀF` is formed
/// from `F` before it is factored, and each is factored in this order, so
/// that the factors shared between them are named once.
fn factored_dynamics(system: &mut System, factorer: &mut Factorer) -> Option<VelocityTerms> {
    let g = &mut system.graph;
    let bodies = system.bodies.as_ref();
    let velocity_forces = bodies.and_then(|b| velocity::forces(g, b, &system.forces));
    system.mass = factorer.factor_rows(g, &system.mass);
    system.forces = factorer.factor_all(g, &system.forces);
    let velocity_mass = bodies.and_then(|b| b.velocity_mass.as_ref());
    let mass = velocity_mass.map(|m| factorer.factor_rows(g, m));
    let forces = velocity_forces.map(|f| factorer.factor_all(g, &f));
    Some(VelocityTerms {
        mass: mass?,
        forces: forces?,
    })
}

/// The rows of `A q̈ = b` and the velocity-level constraints.
struct Rows {
    a: Vec<Vec<Id>>,
    b: Vec<Id>,
    velocity_constraints: Vec<Id>,
}

/// Every constraint's row of `A` and `b`: each `b` the cheaper of its two
/// derivations ([`cheaper_bias`]), then completed into squares where that
/// pays; the rows of points under a free base in their closed form
/// (`in_base`): the same values, without the quotient rule of `R̂`.
fn constraint_rows(
    g: &mut crate::expr::Graph,
    factorer: &mut Factorer,
    (mass, forces): (&[Vec<Id>], &[Id]),
    constraints: &[Constraint],
    in_base: &[in_base::InBaseRows],
) -> Rows {
    let n = forces.len();
    let mut d = Differentiator::new();
    let mut at_rest = AtRest::default();
    let (mut a, mut b, mut velocity_constraints) = (Vec::new(), Vec::new(), Vec::new());
    let mut structured = Vec::new();
    for c in constraints {
        if let Some(rates) = &c.rates {
            // An orientation lock's row: its derivatives in closed form.
            a.push(factorer.factor_all(g, &rates.row));
            let rhs = g.neg(rates.bias);
            b.push(rhs);
            structured.push(rhs);
            velocity_constraints.push(rates.velocity);
            continue;
        }
        let velocity_level = match c.level {
            Level::Velocity => c.phi,
            // φ has no q̇, so D φ = Σ ∂φ/∂qⱼ q̇ⱼ + ∂φ/∂t has no q̈ term.
            Level::Position => d.time_derivative(g, c.phi, n).1,
        };
        let (row, rest) = d.time_derivative(g, velocity_level, n);
        a.push(factorer.factor_all(g, &row));
        let rhs = g.neg(rest);
        b.push(rhs);
        velocity_constraints.push(velocity_level);
        // The same `b` by forward mode over φ's own structure.
        let velocity = match c.level {
            Level::Velocity => c.phi,
            Level::Position => at_rest.derivative(g, c.phi),
        };
        let rest = at_rest.derivative(g, velocity);
        structured.push(g.neg(rest));
    }
    let b = cheaper_bias(g, factorer, (mass, forces, &a), &b, &structured);
    // b = −(d/dt A)·q̇ is a quadratic form in q̇: written as a sum of
    // squares where that shortens the code, counted with everything else
    // that is computed beside it (crate::expr::squares).
    let mut b = complete_squares(g, factorer, mass, forces, &a, &b);
    for rows in in_base {
        for (i, &r) in rows.rows.iter().enumerate() {
            a[r] = factorer.factor_all(g, &rows.model_a[i]);
            b[r] = factorer.factor(g, rows.model_b[i]);
        }
    }
    Rows {
        a,
        b,
        velocity_constraints,
    }
}

/// `M q̇`: row by row from `M`'s entries (structural zeros vanish), or for
/// a tree of bodies by recursive Newton–Euler without velocities or
/// gravity with `q̇` in `q̈`'s place (`crate::bodies::recursion::mass_times`:
/// O(n) where `M` has n² entries), whichever takes fewer operations. The
/// same function either way.
fn momentum(g: &mut crate::expr::Graph, mass: &[Vec<Id>], bodies: Option<&BodyTerms>) -> Vec<Id> {
    let by_entries = momentum_by_entries(g, mass);
    let Some(bodies) = bodies else {
        return by_entries;
    };
    let products = crate::bodies::recursion::mass_times(g, &bodies.tree, mass.len());
    let rates: Vec<Id> = (0..mass.len()).map(|i| g.sym(Sym::Vel(i))).collect();
    let by_recursion = g.substitute_all(&products, &|s| match s {
        Sym::Accel(i) => rates.get(i).copied(),
        _ => None,
    });
    let cost = |g: &crate::expr::Graph, roots: &[Id]| crate::expr::squares::operations(g, roots);
    if cost(g, &by_recursion) < cost(g, &by_entries) {
        by_recursion
    } else {
        by_entries
    }
}

/// `M q̇` from `M`'s entries, row by row; structural zeros vanish.
fn momentum_by_entries(g: &mut crate::expr::Graph, mass: &[Vec<Id>]) -> Vec<Id> {
    mass.iter()
        .map(|row| {
            let terms: Vec<Id> = (row.iter().enumerate())
                .map(|(j, &m)| {
                    let v = g.sym(Sym::Vel(j));
                    g.mul2(m, v)
                })
                .collect();
            g.add(&terms)
        })
        .collect()
}

/// `∂τ/∂q` and `∂τ/∂q̇` of the bodies' inverse dynamics: by the recursions
/// of `crate::bodies::derivatives`, each subtree on the world in the
/// cheapest of its candidate frames ([`chains`], [`worth_trying`]). The
/// partials of `τ`'s own expressions, exact too, cost more on every tree
/// tried (a short leg's touch three bodies each, which the recursions
/// match once the leg is in its own hip's axes), so they are not built.
fn inverse_dynamics_jacobian(g: &mut crate::expr::Graph, bodies: &BodyTerms) -> [Vec<Vec<Id>>; 2] {
    let tree = crate::bodies::Tree {
        bodies: bodies.tree.clone(),
        gravity: bodies.gravity_vector,
    };
    let n = bodies.inverse.len();
    let chains = chains(&tree);
    // Each subtree on the world takes the cheapest of its candidate
    // frames; the subtrees' entries are apart, so each is costed on its
    // own rows.
    let depth = chains.iter().map(Vec::len).max().unwrap_or(0);
    let mut best: Vec<(usize, Option<usize>)> = vec![(usize::MAX, None); chains.len()];
    let mut built = Vec::with_capacity(depth + 1);
    for d in 0..=depth {
        if !chains.iter().any(|c| worth_trying(g, &tree, c, d)) {
            continue;
        }
        let references: Vec<usize> = chains
            .iter()
            .filter_map(|c| c.get(d.checked_sub(1)?).copied())
            .collect();
        let m = crate::bodies::derivatives::inverse_dynamics_jacobian(g, &tree, n, &references);
        for (k, chain) in chains.iter().enumerate() {
            if !worth_trying(g, &tree, chain, d) {
                continue;
            }
            let rows = subtree_rows(&tree, chain[0], n);
            let roots: Vec<Id> = m
                .iter()
                .flat_map(|by| rows.iter().flat_map(move |&r| by[r].iter().copied()))
                .collect();
            let ops = crate::expr::squares::operations(g, &roots);
            let reference = d.checked_sub(1).and_then(|i| chain.get(i).copied());
            if ops < best[k].0 {
                best[k] = (ops, reference);
            }
        }
        built.push((references, m));
    }
    let references: Vec<usize> = best.iter().filter_map(|&(_, r)| r).collect();
    // Built already where every subtree chose the same depth.
    match built.into_iter().find(|(r, _)| *r == references) {
        Some((_, m)) => m,
        None => crate::bodies::derivatives::inverse_dynamics_jacobian(g, &tree, n, &references),
    }
}

/// Whether `chain`'s subtree is costed in the frame at depth `d` (0: the
/// world's, else `chain[d - 1]`'s): not where the chain's next body slides
/// straight ([`slides_straight`]) from it. That body's frame is this one
/// moved along the slide, so every position below reads the slide's
/// coordinate in this frame and none does in that one: a free base's
/// world frame and its first two slides' each cost more than its last
/// slide's on every tree tried.
fn worth_trying(
    g: &crate::expr::Graph,
    tree: &crate::bodies::Tree,
    chain: &[usize],
    d: usize,
) -> bool {
    d <= chain.len()
        && chain
            .get(d)
            .is_none_or(|&next| !slides_straight(g, &tree.bodies[next]))
}

/// Whether `body` moves on a prismatic joint of its own placed without a
/// turn: its frame is its parent's translated.
fn slides_straight(g: &crate::expr::Graph, body: &crate::bodies::Body) -> bool {
    let unturned = body.placement.rotation.iter().enumerate().all(|(i, row)| {
        row.iter().enumerate().all(|(j, &e)| {
            g.as_num(e)
                .is_some_and(|v| if i == j { v.is_one() } else { v.is_zero() })
        })
    });
    matches!(body.joint.kind, crate::bodies::JointKind::Prismatic)
        && body.joint.mimic.is_none()
        && unturned
}

/// For each body on the world, the bodies down the single chain from it,
/// itself first, at most four: the frames its subtree's recursions are
/// tried in besides the world's. The first links of an arm and a free
/// base after its three slides (the Panda's `∂τ` in 4,344 operations where
/// the world's axes took 5,411, the floating Go1's in 14,718 where they
/// took 18,185); once a subtree branches, no one body's frame spares the
/// others' coordinates.
fn chains(tree: &crate::bodies::Tree) -> Vec<Vec<usize>> {
    let children =
        |at: usize| (0..tree.bodies.len()).filter(move |&i| tree.bodies[i].parent == Some(at));
    (0..tree.bodies.len())
        .filter(|&i| tree.bodies[i].parent.is_none())
        .map(|root| {
            let mut chain = vec![root];
            while chain.len() < 4 {
                let last = chain[chain.len() - 1];
                let mut next = children(last);
                match (next.next(), next.next()) {
                    (Some(only), None) => chain.push(only),
                    _ => break,
                }
            }
            chain
        })
        .collect()
}

/// The coordinates the joints of body `root`'s subtree move.
fn subtree_rows(tree: &crate::bodies::Tree, root: usize, n: usize) -> Vec<usize> {
    let mut rows: Vec<usize> = (0..tree.bodies.len())
        .filter(|&i| crate::bodies::reference::root_of(&tree.bodies, i) == root)
        .flat_map(|i| {
            let j = tree.bodies[i].joint;
            j.coordinate..j.coordinate + j.kind.coordinate_count()
        })
        .filter(|&r| r < n)
        .collect();
    rows.sort_unstable();
    rows.dedup();
    rows
}

/// The entries of `M`, `A` and `F`: what the code computes beside `b`.
fn pieces(mass: &[Vec<Id>], forces: &[Id], a: &[Vec<Id>]) -> Vec<Id> {
    mass.iter()
        .chain(a)
        .flatten()
        .chain(forces)
        .copied()
        .collect()
}

/// Per row, `b` from the partials (`Σᵢⱼ ∂²φ/∂qᵢ∂qⱼ·q̇ᵢq̇ⱼ`) or from
/// forward mode (`D₀ D₀ φ`, [`AtRest`]), whichever costs fewer operations
/// once factored, counted with `M`, `F`, `A` and the rows before (whose
/// subexpressions it may share): equal values, so the choice is one of
/// speed. Forward mode wins for points of bodies, where the partials
/// multiply out every rotation of the chain; the partials win for short
/// polynomial constraints, which they leave as the textbook writes them.
fn cheaper_bias(
    g: &mut crate::expr::Graph,
    factorer: &mut Factorer,
    (mass, forces, a): (&[Vec<Id>], &[Id], &[Vec<Id>]),
    partials: &[Id],
    structured: &[Id],
) -> Vec<Id> {
    // What each candidate adds to the context is what it costs beyond it.
    let mut counted = crate::expr::squares::Counted::new(g, &pieces(mass, forces, a));
    let mut chosen = Vec::with_capacity(partials.len());
    for (&old, &new) in partials.iter().zip(structured) {
        let f_old = factorer.factor(g, old);
        let (pick, factored) = if old == new {
            (old, f_old)
        } else {
            let f_new = factorer.factor(g, new);
            if counted.extra(g, f_new) < counted.extra(g, f_old) {
                (new, f_new)
            } else {
                (old, f_old)
            }
        };
        counted.add(g, factored);
        chosen.push(pick);
    }
    chosen
}

/// Every row of `b` factored, as a sum of squares where that costs at least
/// three operations fewer, counted with `M`, `F`, `A` and the other rows.
fn complete_squares(
    g: &mut crate::expr::Graph,
    factorer: &mut Factorer,
    mass: &[Vec<Id>],
    forces: &[Id],
    a: &[Vec<Id>],
    b: &[Id],
) -> Vec<Id> {
    let mut rows = factorer.factor_all(g, b);
    let shared = pieces(mass, forces, a);
    for i in 0..b.len() {
        let context: Vec<Id> = shared
            .iter()
            .chain(rows.iter().take(i))
            .chain(rows.iter().skip(i + 1))
            .copied()
            .collect();
        rows[i] = crate::expr::squares::complete(g, factorer, b[i], &context);
    }
    rows
}

#[cfg(test)]
mod momentum_tests {
    use crate::expr::Id;

    /// The Panda's `M q̇` by the recursions is `M`'s rows times `q̇` at
    /// random states, and takes fewer operations than those products.
    #[test]
    fn a_trees_momentum_is_its_mass_times_the_rates() {
        let source = crate::tools::fixtures::panda("Panda", 7);
        let eq = crate::analyse(source.parse().expect("tokens")).expect("expands");
        let mut g = eq.system.graph.clone();
        let by_entries = super::momentum_by_entries(&mut g, &eq.system.mass);
        let operations = |roots: &[Id]| crate::expr::squares::operations(&g, roots);
        let (chosen, entries) = (operations(&eq.momentum), operations(&by_entries));
        assert!(chosen < entries, "{chosen} operations against {entries}");
        for point in crate::numeric::rng::sample_points(11) {
            let a = g.eval(&eq.momentum, &point);
            let b = g.eval(&by_entries, &point);
            for (x, y) in a.iter().zip(&b) {
                assert!((x - y).abs() <= 1e-12 * (1.0 + y.abs()), "{x} against {y}");
            }
        }
    }
}
