//! Tests of `super`'s inertias: the body force about the centre of mass
//! and moving an inertia through it, against the spatial forms.

use super::*;
use crate::expr::num::Num;
use crate::expr::Sym;

/// A full inertia off its origin (exact decimals), and symbolic motion
/// vectors: velocities `q̇₀…q̇₅`, accelerations `q̇₆…q̇₁₁`.
fn body(g: &mut Graph) -> (Inertia, Spatial, Spatial) {
    let n = |g: &mut Graph, x: i128| g.num(Num::ratio(x, 1000));
    let mass = n(g, 1234);
    let com = [n(g, 13), n(g, -27), n(g, 41)];
    let about = [[310, 7, -3], [7, 388, 8], [-3, 8, 428]].map(|row| row.map(|x| n(g, x)));
    let inertia = Inertia::from_com(g, mass, com, &about);
    let vector = |g: &mut Graph, k: usize| [0, 1, 2].map(|i| g.sym(Sym::Vel(k + i)));
    let v = Spatial {
        angular: vector(g, 0),
        linear: vector(g, 3),
    };
    let a = Spatial {
        angular: vector(g, 6),
        linear: vector(g, 9),
    };
    (inertia, v, a)
}

fn values(g: &Graph, ids: &[Id]) -> Vec<f64> {
    g.eval(ids, &|s| match s {
        Sym::Vel(k) => 0.3 - 0.17 * k as f64,
        _ => 0.0,
    })
}

fn parts(s: &Spatial) -> Vec<Id> {
    s.angular.iter().chain(&s.linear).copied().collect()
}

/// Newton and Euler about the centre of mass give the spatial
/// products' force, and the centre is the file's own (exactly).
#[test]
fn the_force_about_the_center_is_the_spatial_one() {
    let mut g = Graph::new();
    let (inertia, v, a) = body(&mut g);
    let momentum = inertia.apply(&mut g, v);
    let ia = inertia.apply(&mut g, a);
    let gyroscopic = v.cross_force(&mut g, momentum);
    let spatial = ia.add(&mut g, gyroscopic);
    let (c, about) = inertia.center(&mut g).expect("numbers");
    assert_eq!(g.as_num(c[1]), Some(Num::Rational(-27, 1000)));
    assert_eq!(g.as_num(about[2][2]), Some(Num::Rational(107, 250)));
    let (classic, _) = inertia.about_center(&mut g, (v, a), c, about);
    let (want, got) = (values(&g, &parts(&spatial)), values(&g, &parts(&classic)));
    for (w, x) in want.iter().zip(&got) {
        assert!(
            (w - x).abs() <= 1e-14 * w.abs().max(1.0),
            "{want:?} {got:?}"
        );
    }
    let (chosen, _) = inertia.force(&mut g, v, a);
    assert_eq!(
        values(&g, &parts(&chosen)),
        got,
        "dense v and a: the centre's form"
    );
}

/// Moving an inertia through its centre of mass is `to_parent`.
#[test]
fn moving_through_the_center_is_to_parent() {
    let mut g = Graph::new();
    let (inertia, v, _) = body(&mut g);
    let angles = [v.angular[0], v.angular[1], v.linear[2]];
    let r = rpy(&mut g, angles);
    let p = v.linear;
    let (a, b) = (
        inertia.to_parent(&mut g, &r, p),
        inertia.moved(&mut g, &r, p),
    );
    let all = |i: &Inertia| {
        let mut out = vec![i.mass];
        out.extend(i.first_moment);
        out.extend(i.rotational.iter().flatten());
        out
    };
    let (want, got) = (values(&g, &all(&a)), values(&g, &all(&b)));
    for (w, x) in want.iter().zip(&got) {
        assert!(
            (w - x).abs() <= 1e-14 * w.abs().max(1.0),
            "{want:?} {got:?}"
        );
    }
}
