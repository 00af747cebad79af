//! The rank-one Gibbs–Appell rows written in `DERIVATION` are the rows the
//! generated code computes: for every reference model of rank 1, the
//! symbolic entries, evaluated at consistent states, equal the runtime's
//! `gibbs_appell::system` fed with the same A, b, M, F, wherever the runtime
//! keeps the compile-time partition.

use constrained_codegen::equations::gibbs_appell::rank_one;
use constrained_codegen::equations::partition::{consistent_states, StateValues};
use constrained_codegen::expr::{Id, Sym};
use constrained_runtime::gibbs_appell::WELL_CONDITIONED;
use nalgebra::{SMatrix, SVector};

mod common;

fn env(s: &StateValues) -> impl Fn(Sym) -> f64 + '_ {
    move |v| match v {
        Sym::Coord(i) => s.q[i],
        Sym::Vel(i) => s.qd[i],
        Sym::Time => s.t,
        Sym::Param(i) => s.params[i],
        Sym::Multiplier(_) | Sym::Seed(_) | Sym::Accel(_) => f64::NAN,
    }
}

fn runtime_rows<const N: usize, const I: usize>(
    a: &[f64],
    b: f64,
    m: &[f64],
    f: &[f64],
    e: usize,
    coupled: bool,
) -> (SMatrix<f64, N, N>, SVector<f64, N>) {
    constrained_runtime::gibbs_appell::system::<f64, N, 1, 1, I>(
        &SMatrix::<f64, 1, N>::from_row_slice(a),
        &SVector::<f64, 1>::new(b),
        &SMatrix::<f64, N, N>::from_row_slice(m),
        &SVector::<f64, N>::from_column_slice(f),
        &[e],
        coupled,
    )
    .expect("generic consistent state")
}

#[test]
fn symbolic_rows_equal_the_runtime() {
    let (mut checked, mut re_pivoted) = (0, 0);
    for model in common::model_invocations() {
        let eq = constrained_codegen::analyse(model.tokens).unwrap();
        let Some(rank_one) = rank_one(&eq, &eq.partition) else {
            continue;
        };
        if eq.a.len() != 1 {
            continue;
        }
        let n = eq.system.dof();
        let coupled = !eq.mass_inverse.is_diagonal();
        for state in consistent_states(&eq) {
            let g = &eq.system.graph;
            let a = g.eval(&eq.a[0], &env(&state));
            let b = g.eval(&eq.b, &env(&state))[0];
            let mass: Vec<Id> = eq.system.mass.iter().flatten().copied().collect();
            let m = g.eval(&mass, &env(&state));
            let f = g.eval(&eq.system.forces, &env(&state));
            let e = eq.partition.eliminated[0];
            // The runtime keeps the compile-time column only while it is well
            // conditioned (rank 1: a_e² against the largest a_j²), and the
            // written rows are those of that column.
            let largest = a.iter().fold(0.0f64, |m, x| m.max(x * x));
            if a[e] * a[e] < WELL_CONDITIONED * largest {
                re_pivoted += 1;
                continue;
            }
            let (s, rhs): (Vec<f64>, Vec<f64>) = match n {
                2 => {
                    let (s, r) = runtime_rows::<2, 1>(&a, b, &m, &f, e, coupled);
                    (s.transpose().as_slice().to_vec(), r.as_slice().to_vec())
                }
                3 => {
                    let (s, r) = runtime_rows::<3, 2>(&a, b, &m, &f, e, coupled);
                    (s.transpose().as_slice().to_vec(), r.as_slice().to_vec())
                }
                4 => {
                    let (s, r) = runtime_rows::<4, 3>(&a, b, &m, &f, e, coupled);
                    (s.transpose().as_slice().to_vec(), r.as_slice().to_vec())
                }
                _ => panic!("{}: add a size here", model.name),
            };
            for (i, (row, rhs_i)) in rank_one.rows.iter().enumerate() {
                let symbolic = rank_one.graph.eval(row, &env(&state));
                let symbolic_rhs = rank_one.graph.eval(&[*rhs_i], &env(&state))[0];
                for j in 0..n {
                    let runtime = s[(i + 1) * n + j];
                    assert!(
                        (symbolic[j] - runtime).abs() <= 1e-10 * runtime.abs().max(1.0),
                        "{} row {} col {j}: symbolic {} vs runtime {runtime}",
                        model.name,
                        i + 2,
                        symbolic[j]
                    );
                }
                let runtime = rhs[i + 1];
                assert!(
                    (symbolic_rhs - runtime).abs() <= 1e-10 * runtime.abs().max(1.0),
                    "{} rhs {}: symbolic {symbolic_rhs} vs runtime {runtime}",
                    model.name,
                    i + 2
                );
            }
            checked += 1;
        }
    }
    assert!(
        checked >= 30 && re_pivoted < checked,
        "checked {checked} states, {re_pivoted} re-pivoted"
    );
}
