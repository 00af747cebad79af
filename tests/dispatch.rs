//! `dispatch: [avx]`: a system's large methods also compiled for AVX and
//! chosen at run time. The Panda of `tests/frames.rs` (`PandaTool`:
//! published parameters, a tool frame, ∂τ) written again asking for the
//! copies: the expansion has them for the methods large enough, and on a
//! CPU with AVX (where the copies run) every answer is `PandaTool`'s bit
//! for bit, since AVX changes the instructions' encodings and widths, not
//! their roundings; and a system with nothing large expands as it does
//! without the section.

use crate::frames::{numbers, PandaTool};
use nalgebra::{SMatrix, SVector};

/// `PandaTool`'s sections (`tests/frames.rs`), handed to `$then!` after
/// `$head`: one text for the system and for its expansion here. A change
/// to either Panda alone fails the comparison below.
macro_rules! panda_sections {
    ($then:ident!($($head:tt)*)) => {
        $then! { $($head)*
            urdf: "data/panda_published.urdf",
            locked: [finger_joint1, finger_joint2],
            frames: [tool { body: hand, xyz: [0.0, 0.0, 0.1034] }],
            derivatives: [inverse_dynamics],
        }
    };
}

macro_rules! system {
    ($name:ident $($sections:tt)*) => {
        constrained::constrained_system! {
            /// `PandaTool` with `dispatch: [avx]`.
            pub struct $name { $($sections)* }
        }
    };
}

macro_rules! text {
    ($($sections:tt)*) => {
        stringify!($($sections)*)
    };
}

panda_sections!(system!(Dispatched dispatch: [avx],));

/// The expansion with `dispatch: [avx]`: the methods it copies, by name.
fn copied() -> Vec<String> {
    let sections = panda_sections!(text!());
    let source = format!("struct P {{ dispatch: [avx], {sections} }}");
    let expanded = constrained_codegen::expand(source.parse().expect("tokens"))
        .expect("the Panda expands")
        .to_string();
    let mut names: Vec<String> = expanded
        .split("fn __avx_")
        .skip(1)
        .filter_map(|rest| rest.split_whitespace().next().map(str::to_string))
        .collect();
    names.sort();
    names.dedup();
    names
}

#[test]
fn the_large_methods_are_copied_and_the_small_ones_are_not() {
    let names = copied();
    // ∂τ (returned, and stored into `out` by `_to`) and the
    // linearization's right-hand sides are the Panda's bodies above the
    // threshold (about 1,300 operations); `M`, τ, the solve and the rest
    // of `acceleration_jacobian` are below it.
    assert_eq!(
        names,
        [
            "inverse_dynamics_jacobian",
            "inverse_dynamics_jacobian_to",
            "tangent_rhs"
        ]
    );
    let plain = panda_sections!(text!());
    let source = format!("struct P {{ {plain} }}");
    let expanded = constrained_codegen::expand(source.parse().expect("tokens"))
        .expect("the Panda expands")
        .to_string();
    assert!(
        !expanded.contains("has_avx"),
        "no check without the section"
    );
}

/// Equal bit for bit, entry by entry.
fn same_bits<const R: usize, const C: usize>(a: &SMatrix<f64, R, C>, b: &SMatrix<f64, R, C>) {
    for (x, y) in a.iter().zip(b.iter()) {
        assert_eq!(x.to_bits(), y.to_bits(), "{x} against {y}");
    }
}

#[test]
fn on_a_cpu_with_avx_every_answer_is_the_plain_systems_bit_for_bit() {
    if !std::arch::is_x86_feature_detected!("avx") {
        eprintln!("this CPU has no AVX: the copies never run, nothing to compare");
        return;
    }
    let (plain, dispatched) = (PandaTool::<f64>::new(), Dispatched::<f64>::new());
    let mut next = numbers(77);
    for _ in 0..20 {
        let [q, v, a] = [(); 3].map(|()| SVector::<f64, 7>::from_fn(|_, _| next()));
        let (p, d) = (
            plain
                .inverse_dynamics_jacobian(&q, &v, &a, 0.0)
                .expect("finite"),
            dispatched
                .inverse_dynamics_jacobian(&q, &v, &a, 0.0)
                .expect("finite"),
        );
        same_bits(&p.0, &d.0);
        same_bits(&p.1, &d.1);
        let mut kept = (SMatrix::<f64, 7, 7>::zeros(), SMatrix::<f64, 7, 7>::zeros());
        dispatched
            .inverse_dynamics_jacobian_to(&q, &v, &a, 0.0, &mut kept)
            .expect("finite");
        same_bits(&p.0, &kept.0);
        same_bits(&p.1, &kept.1);
        let (p, d) = (
            plain.acceleration_jacobian(&q, &v, 0.0).expect("finite"),
            dispatched
                .acceleration_jacobian(&q, &v, 0.0)
                .expect("finite"),
        );
        same_bits(&p.dq, &d.dq);
        same_bits(&p.dqd, &d.dqd);
        same_bits(
            &plain.mass_matrix(&q, 0.0),
            &dispatched.mass_matrix(&q, 0.0),
        );
        let (p, d) = (
            plain.inverse_dynamics(&q, &v, &a, 0.0).expect("finite"),
            dispatched
                .inverse_dynamics(&q, &v, &a, 0.0)
                .expect("finite"),
        );
        same_bits(&p, &d);
        let (p, d) = (
            plain.acceleration(&q, &v, 0.0).expect("finite"),
            dispatched.acceleration(&q, &v, 0.0).expect("finite"),
        );
        same_bits(&p, &d);
    }
}

/// A system without a large function expands as it does without the
/// section: no copy, no check.
#[test]
fn a_small_system_is_unchanged_by_the_section() {
    let arm = "bodies: [a { joint: revolute(q1, [0.0, 0.0, 1.0]), mass: 1.0, com: [0.3, 0.0, 0.0] }], derivatives: [inverse_dynamics]";
    let expanded = |extra: &str| {
        let source = format!("struct R {{ {arm}{extra} }}");
        constrained_codegen::expand(source.parse().expect("tokens"))
            .expect("expands")
            .to_string()
    };
    assert_eq!(expanded(", dispatch: [avx]"), expanded(""));
}
