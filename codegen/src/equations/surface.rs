//! Consistent states for the partition's rank decision
//! ([`partition`](super::partition) says why they must be consistent and
//! generic): deterministic pseudo-random states, positions brought onto
//! the orientation locks' branches by damped least squares, then projected
//! onto `φ = 0` by Newton's method with minimum-norm steps (positions onto
//! the position-level rows, velocities onto every row at velocity level).

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
        }
    }

    /// `A` at `s`, row by row.
    pub(super) fn a(&self, s: &StateValues) -> Vec<Vec<f64>> {
        rows_of(self.eq, &self.a.eval(&s.env()))
    }

    /// Up to `STATES` consistent states, from the generator seeded with
    /// `seed`.
    pub(super) fn consistent_states_from(&self, seed: u64) -> Vec<StateValues> {
        let mut rng = SplitMix64::new(seed);
        let mut found = Vec::new();
        for _ in 0..SEEDS {
            if found.len() == STATES {
                break;
            }
            let mut s = random_state(self.eq, &mut rng);
            if self.project(&mut s) {
                found.push(s);
            }
        }
        found
    }

    /// Newton with minimum-norm steps, from the locks' branches; `true` when
    /// φ and φ̇ vanish to 1e-13 and the state is still on every branch.
    fn project(&self, s: &mut StateValues) -> bool {
        if !self.onto_branches(s) {
            return false;
        }
        let converge = |s: &mut StateValues, residual: &Tape, rows: &[usize], velocity: bool| {
            for _ in 0..60 {
                let r = residual.eval(&s.env());
                if r.iter().all(|x| x.abs() < 1e-13) {
                    return true;
                }
                if r.iter().any(|x| !x.is_finite()) {
                    return false;
                }
                let a = self.a(s);
                let j: Vec<Vec<f64>> = rows.iter().map(|&i| a[i].clone()).collect();
                let step = minimum_norm_solve(&j, &r);
                let target = if velocity { &mut s.qd } else { &mut s.q };
                target.iter_mut().zip(&step).for_each(|(x, d)| *x -= d);
            }
            false
        };
        let all: Vec<usize> = (0..self.eq.a.len()).collect();
        converge(s, &self.phi, &self.positions, false)
            && self
                .branch
                .eval(&s.env())
                .iter()
                .all(|x| x.abs() < BRANCH_TOLERANCE)
            && converge(s, &self.velocity, &all, true)
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

/// How near its branch a lock is brought before Newton takes over (and
/// must stay): Newton then moves `q` by about as much, and the half turns
/// are `Eᵢᵢ − 1 ~ −2` away.
const BRANCH_TOLERANCE: f64 = 1e-8;
