//! 10⁵ steps of each integrator (and each stabilization) on the double
//! pendulum allocate nothing: a counting global allocator proves it.
//! Runs without the test harness so that no other thread allocates
//! meanwhile; prints a summary line the test runners understand.

use constrained::models::DoublePendulum;
use constrained::{DormandPrince45, Rk4, SemiImplicitEuler, Stabilization, State};
use std::alloc::{GlobalAlloc, Layout, System};

use std::sync::atomic::{AtomicUsize, Ordering};

struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::SeqCst);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::SeqCst);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn start() -> (DoublePendulum<f64>, State<f64, 4>) {
    let (l1, l2) = (1.2, 0.8);
    let state = constrained::models::double_pendulum_state(l1, l2, 0.0, [2.0, -1.0], [0.5, 1.5]);
    (DoublePendulum::new(1.0, 1.5, l1, l2, 9.81), state)
}

/// Allocations made by `run`, and the number of steps it reports.
fn count(run: impl FnOnce() -> usize) -> (usize, usize) {
    let before = ALLOCATIONS.load(Ordering::SeqCst);
    let steps = run();
    (ALLOCATIONS.load(Ordering::SeqCst) - before, steps)
}

fn main() {
    // The counter itself works: a vector allocates once.
    let (allocs, _) = count(|| std::hint::black_box(vec![1u8; 16]).len());
    assert_eq!(
        allocs, 1,
        "the counting allocator must see a Vec's allocation"
    );
    let (system, initial) = start();
    let stabilizations = [
        ("none", Stabilization::None),
        ("Baumgarte", Stabilization::baumgarte(10.0)),
        ("projection", Stabilization::projection(1e-12)),
    ];
    let mut results: Vec<(String, usize, usize)> = Vec::new();
    for (name, stabilization) in stabilizations {
        let mut s = initial;
        let rk4 = Rk4::new(1e-3).with_stabilization(stabilization);
        let (allocs, steps) = count(|| rk4.advance(&system, &mut s, 100.0).expect("rk4").steps);
        results.push((format!("Rk4, {name}"), allocs, steps));

        let mut s = initial;
        let euler = SemiImplicitEuler::new(1e-3).with_stabilization(stabilization);
        let (allocs, steps) = count(|| euler.advance(&system, &mut s, 100.0).expect("euler").steps);
        results.push((format!("SemiImplicitEuler, {name}"), allocs, steps));

        let mut s = initial;
        // A step bound makes the adaptive method take at least 10⁵ steps
        // too (its first steps are shorter, hence the extra 0.1 s).
        let dopri = DormandPrince45::new(1e-8, 1e-10)
            .with_max_step(1e-3)
            .with_stabilization(stabilization);
        let (allocs, steps) = count(|| dopri.advance(&system, &mut s, 100.1).expect("dopri").steps);
        results.push((format!("DormandPrince45, {name}"), allocs, steps));
    }
    let mut failed = 0;
    for (name, allocs, steps) in &results {
        let ok = *allocs == 0 && *steps >= 100_000;
        println!(
            "{}: {name}: {steps} steps, {allocs} allocations",
            if ok { "ok" } else { "FAILED" }
        );
        failed += usize::from(!ok);
    }
    println!("{} passed, {failed} failed", results.len() - failed);
    if failed > 0 {
        std::process::exit(1);
    }
}
