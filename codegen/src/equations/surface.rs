//! Consistent states for the partition's rank decision
//! ([`partition`](super::partition) says why they must be consistent and
//! generic): deterministic pseudo-random states, positions brought onto
//! the orientation locks' branches by damped least squares, then projected
//! onto `φ = 0` by Newton's method with minimum-norm steps (positions onto
//! the position-level rows, velocities onto every row at velocity level),
//! with the parameters the position rows read where `q` alone reaches no
//! state ([`Surface::consistent_states_from`]).

use crate::equations::Equations;
use crate::expr::tape::Tape;
use crate::expr::{Id, Sym};
use crate::model::Level;
use crate::numeric::linalg::{damped_least_squares, minimum_norm_solve};
use crate::numeric::rng::SplitMix64;

/// How many consistent states to look for, and how many seeds to try.
pub(super) const STATES: usize = 8;
const SEEDS: u64 = 64;

/// The seeds of the generators the rank is measured with.
#[derive(Clone, Copy, Debug)]
pub struct Seeds {
    /// The first batch of consistent states.
    pub states: u64,
    /// The batch that checks the decision.
    pub check: u64,
    /// The random states used where no consistent state is found.
    pub random: u64,
}

impl Default for Seeds {
    fn default() -> Self {
        Seeds {
            states: 0x000c_0515_7e47,
            check: 0x0c4e_c4ed_0a11,
            random: 0x6a1b_b5e1,
        }
    }
}

/// A state of the system: values of every variable.
#[derive(Clone, Debug)]
pub struct StateValues {
    /// `q`.
    pub q: Vec<f64>,
    /// `q̇`.
    pub qd: Vec<f64>,
    /// `t`.
    pub t: f64,
    /// Parameters.
    pub params: Vec<f64>,
}

impl StateValues {
    pub(super) fn env(&self) -> impl Fn(Sym) -> f64 + '_ {
        move |s| match s {
            Sym::Coord(i) => self.q[i],
            Sym::Vel(i) => self.qd[i],
            Sym::Time => self.t,
            Sym::Param(i) => self.params[i],
            Sym::Multiplier(_) | Sym::Seed(_) | Sym::Accel(_) => f64::NAN,
        }
    }
}

/// `STATES` random states (off the constraints), from the generator
/// seeded with `stream`: where rank is measured when no consistent state
/// is found.
pub(super) fn random_states(eq: &Equations, stream: u64) -> Vec<StateValues> {
    let mut rng = SplitMix64::new(stream);
    (0..STATES).map(|_| random_state(eq, &mut rng)).collect()
}

fn random_state(eq: &Equations, rng: &mut SplitMix64) -> StateValues {
    let n = eq.system.dof();
    let mut uniform = |lo: f64, hi: f64| lo + (hi - lo) * rng.next_f64();
    StateValues {
        q: (0..n).map(|_| uniform(-1.0, 1.0)).collect(),
        qd: (0..n).map(|_| uniform(-1.0, 1.0)).collect(),
        t: uniform(0.0, 1.0),
        params: (0..eq.system.parameters.len())
            .map(|_| uniform(0.5, 1.5))
            .collect(),
    }
}

/// `A` at `s`, row by row (once: for many states, [`Surface::a`]).
pub(super) fn eval_a(eq: &Equations, s: &StateValues) -> Vec<Vec<f64>> {
    rows_of(eq, &a_tape(eq).eval(&s.env()))
}

/// Every entry of `A`, row after row, in one tape: the rows share their
/// kinematics (the quadruped's feet share the base's).
fn a_tape(eq: &Equations) -> Tape {
    let entries: Vec<Id> = eq.a.iter().flatten().copied().collect();
    eq.system.graph.tape(&entries)
}

/// `A`'s rows from its entries' values, row after row.
fn rows_of(eq: &Equations, values: &[f64]) -> Vec<Vec<f64>> {
    match eq.a.first().map_or(0, Vec::len) {
        0 => vec![Vec::new(); eq.a.len()],
        n => values.chunks(n).map(<[f64]>::to_vec).collect(),
    }
}

/// Up to `STATES` consistent states, from deterministic seeds.
pub fn consistent_states(eq: &Equations) -> Vec<StateValues> {
    consistent_states_from(eq, Seeds::default().states)
}

/// Up to `STATES` consistent states, from the generator seeded with `seed`.
pub fn consistent_states_from(eq: &Equations, seed: u64) -> Vec<StateValues> {
    Surface::new(eq).consistent_states_from(seed)
}

/// The position-level rows: their indices and their `φ`.
pub(super) fn position_rows(eq: &Equations) -> (Vec<usize>, Vec<Id>) {
    let rows: Vec<usize> = (0..eq.a.len())
        .filter(|&i| eq.system.constraints[i].level == Level::Position)
        .collect();
    let phi = rows.iter().map(|&i| eq.system.constraints[i].phi).collect();
    (rows, phi)
}

/// The orientation locks' branch residuals (`model::Constraint::branch`).
pub(super) fn branches(eq: &Equations) -> Vec<Id> {
    eq.system
        .constraints
        .iter()
        .filter_map(|c| c.branch)
        .collect()
}

/// What the search for consistent states evaluates at every step, compiled
/// once (`expr::tape`): the rows of `A` ([`a_tape`]), the position-level
/// rows' `φ`, the locks' branch residuals and the rows at velocity level.
pub(super) struct Surface<'a> {
    eq: &'a Equations,
    a: Tape,
    positions: Vec<usize>,
    phi: Tape,
    branches: usize,
    branch: Tape,
    velocity: Tape,
    /// The parameters the position rows' `φ` read.
    parameters: Vec<usize>,
    /// Whether those parameters are moved onto the surface too
    /// ([`Surface::consistent_states_from`]).
    with_parameters: std::cell::Cell<bool>,
}

impl<'a> Surface<'a> {
    /// The tapes of `eq`'s rows.
    pub(super) fn new(eq: &'a Equations) -> Surface<'a> {
        let g = &eq.system.graph;
        let (positions, phi) = position_rows(eq);
        let branch = branches(eq);
        Surface {
            eq,
            a: a_tape(eq),
            positions,
            phi: g.tape(&phi),
            branches: branch.len(),
            branch: g.tape(&branch),
            velocity: g.tape(&eq.velocity_constraints),
            parameters: read_parameters(g, &phi),
            with_parameters: std::cell::Cell::new(false),
        }
    }

    /// `A` at `s`, row by row.
    pub(super) fn a(&self, s: &StateValues) -> Vec<Vec<f64>> {
        rows_of(self.eq, &self.a.eval(&s.env()))
    }

    /// Up to `STATES` consistent states, from the generator seeded with
    /// `seed`. Where the first `STATES` seeds all fail to reach `φ = 0` by
    /// moving `q` alone and the position rows read parameters, the seeds
    /// are projected with those parameters free as well: points held at
    /// parameters (`position(foot, r) == [x, y, z]`) are consistent only
    /// for some of their values (three points of one rigid foot must keep
    /// the foot's distances), which random parameters miss, and the rank
    /// is to be measured where the model is used. The choice holds for the
    /// surface's later batches.
    pub(super) fn consistent_states_from(&self, seed: u64) -> Vec<StateValues> {
        if !self.with_parameters.get() {
            let found = self.states_from(seed, false);
            if !found.is_empty() || self.parameters.is_empty() {
                return found;
            }
            self.with_parameters.set(true);
        }
        self.states_from(seed, true)
    }

    /// Up to `STATES` consistent states from `seed`. Moving `q` alone
    /// where the rows read parameters, none unless one of the first
    /// `STATES` seeds succeeds: the parameters are then freed.
    fn states_from(&self, seed: u64, parameters: bool) -> Vec<StateValues> {
        let mut rng = SplitMix64::new(seed);
        let mut found = Vec::new();
        for tried in 0..SEEDS {
            if found.len() == STATES
                || (!parameters
                    && !self.parameters.is_empty()
                    && found.is_empty()
                    && tried == STATES as u64)
            {
                break;
            }
            let mut s = random_state(self.eq, &mut rng);
            if self.project(&mut s, parameters) {
                found.push(s);
            }
        }
        found
    }

    /// Newton with minimum-norm steps, from the locks' branches; `true` when
    /// φ and φ̇ vanish to 1e-13 and the state is still on every branch.
    /// With `parameters`, the position step moves the parameters the rows
    /// read as well as `q`.
    fn project(&self, s: &mut StateValues, parameters: bool) -> bool {
        if !self.onto_branches(s) {
            return false;
        }
        let free: &[usize] = if parameters { &self.parameters } else { &[] };
        self.converge(s, Level::Position, free)
            && self
                .branch
                .eval(&s.env())
                .iter()
                .all(|x| x.abs() < BRANCH_TOLERANCE)
            && self.converge(s, Level::Velocity, &[])
    }

    /// Newton on the position rows' `φ` (in `q`, and the `free`
    /// parameters) or on every row at velocity level (in `q̇`). It gives up
    /// after `STALL` steps without a new smallest residual: on an
    /// inconsistent system the minimum-norm steps wander, and a
    /// convergent run improves at nearly every step.
    fn converge(&self, s: &mut StateValues, level: Level, free: &[usize]) -> bool {
        let every: Vec<usize>;
        let (residual, rows): (&Tape, &[usize]) = match level {
            Level::Position => (&self.phi, &self.positions),
            _ => {
                every = (0..self.eq.a.len()).collect();
                (&self.velocity, &every)
            }
        };
        let mut best = f64::INFINITY;
        let mut since = 0;
        for _ in 0..60 {
            let r = residual.eval(&s.env());
            let size = r.iter().fold(0.0, |m: f64, x| m.max(x.abs()));
            if size < 1e-13 {
                return true;
            }
            if !size.is_finite() {
                return false;
            }
            if size < best {
                (best, since) = (size, 0);
            } else {
                since += 1;
                if since == STALL {
                    return false;
                }
            }
            let a = self.a(s);
            let mut j: Vec<Vec<f64>> = rows.iter().map(|&i| a[i].clone()).collect();
            let by_parameter = self.parameter_columns(s, free);
            for (row, extra) in j.iter_mut().zip(&by_parameter) {
                row.extend(extra);
            }
            let step = minimum_norm_solve(&j, &r);
            let (own, rest) = step.split_at(step.len() - free.len());
            let target = if level == Level::Position {
                &mut s.q
            } else {
                &mut s.qd
            };
            target.iter_mut().zip(own).for_each(|(x, d)| *x -= d);
            free.iter().zip(rest).for_each(|(&p, d)| s.params[p] -= d);
        }
        false
    }

    /// `∂φ/∂p` of the position rows for each of the `free` parameters, row
    /// by row, by central differences: `φ` is most often linear in them
    /// (a point's target), and the state need only reach `φ = 0`, which
    /// Newton on the exact `∂φ/∂q` then finishes.
    fn parameter_columns(&self, s: &StateValues, free: &[usize]) -> Vec<Vec<f64>> {
        if free.is_empty() {
            return Vec::new();
        }
        let mut columns = vec![vec![0.0; free.len()]; self.positions.len()];
        for (k, &p) in free.iter().enumerate() {
            let h = 1e-6 * s.params[p].abs().max(1.0);
            let mut shifted = s.clone();
            shifted.params[p] = s.params[p] + h;
            let plus = self.phi.eval(&shifted.env());
            shifted.params[p] = s.params[p] - h;
            let minus = self.phi.eval(&shifted.env());
            for (row, (a, b)) in columns.iter_mut().zip(plus.iter().zip(&minus)) {
                row[k] = (a - b) / (2.0 * h);
            }
        }
        columns
    }

    /// The position rows' and the branch residuals' values at `s`.
    fn residual(&self, s: &StateValues) -> Vec<f64> {
        let mut r = self.phi.eval(&s.env());
        r.extend(self.branch.eval(&s.env()));
        r
    }

    /// Positions brought onto the locks' branches (module docs): damped
    /// least-squares steps on the position rows and the branch residuals
    /// together, each step halved until it reduces the residual. The branch
    /// residuals' gradients come from central differences (their values
    /// need only reach `BRANCH_TOLERANCE`; Newton on the exact rows
    /// follows). `true` at once without locks.
    fn onto_branches(&self, s: &mut StateValues) -> bool {
        if self.branches == 0 {
            return true;
        }
        let size = |r: &[f64]| r.iter().map(|x| x * x).sum::<f64>();
        for _ in 0..100 {
            let r = self.residual(s);
            if r.iter().any(|x| !x.is_finite()) {
                return false;
            }
            if r.iter().all(|x| x.abs() < BRANCH_TOLERANCE) {
                return true;
            }
            let a = self.a(s);
            let mut j: Vec<Vec<f64>> = self.positions.iter().map(|&i| a[i].clone()).collect();
            j.extend(self.branch_gradients(s));
            let step = damped_least_squares(&j, &r, 1e-12);
            let mut scale = 1.0;
            let accepted = (0..30).any(|_| {
                let mut trial = s.clone();
                trial
                    .q
                    .iter_mut()
                    .zip(&step)
                    .for_each(|(x, d)| *x -= scale * d);
                let better = size(&self.residual(&trial)) < size(&r);
                if better {
                    *s = trial;
                }
                scale /= 2.0;
                better
            });
            if !accepted {
                return false;
            }
        }
        false
    }

    /// `∂(Eᵢᵢ − 1)/∂q` of every branch residual, by central differences.
    fn branch_gradients(&self, s: &StateValues) -> Vec<Vec<f64>> {
        let h = 1e-6;
        let mut rows = vec![vec![0.0; s.q.len()]; self.branches];
        for j in 0..s.q.len() {
            let mut shifted = s.clone();
            shifted.q[j] = s.q[j] + h;
            let plus = self.branch.eval(&shifted.env());
            shifted.q[j] = s.q[j] - h;
            let minus = self.branch.eval(&shifted.env());
            for (i, row) in rows.iter_mut().enumerate() {
                row[j] = (plus[i] - minus[i]) / (2.0 * h);
            }
        }
        rows
    }
}

/// The parameters that `roots` read, in order.
fn read_parameters(g: &crate::expr::Graph, roots: &[Id]) -> Vec<usize> {
    let mut read: Vec<usize> = g
        .reachable(roots)
        .into_iter()
        .filter_map(|id| match g.node(id) {
            crate::expr::Node::Sym(Sym::Param(p)) => Some(*p),
            _ => None,
        })
        .collect();
    read.sort_unstable();
    read.dedup();
    read
}

/// How near its branch a lock is brought before Newton takes over (and
/// must stay): Newton then moves `q` by about as much, and the half turns
/// are `Eᵢᵢ − 1 ~ −2` away.
const BRANCH_TOLERANCE: f64 = 1e-8;

/// Newton steps without a new smallest residual before a projection is
/// abandoned.
const STALL: usize = 8;
