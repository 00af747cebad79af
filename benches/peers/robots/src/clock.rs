//! The thread's CPU clock and the timing statistic both of this crate's
//! programs use: the robots and the contacts are timed in CPU time on both
//! sides (`common.h`'s `peer_cpu_time` in C++), since on a shared machine a
//! pinned loop's wall time also counts the time other processes held its
//! core (observed: the same call 10× slower from one round to the next, and
//! a Panda row 1.7× slower in one benchmark run than alone minutes later).

/// `struct timespec` of Linux's `clock_gettime`.
#[repr(C)]
struct Timespec {
    seconds: i64,
    nanoseconds: i64,
}

extern "C" {
    fn clock_gettime(clock: i32, time: *mut Timespec) -> i32;
}

/// The thread's CPU time in ns (`CLOCK_THREAD_CPUTIME_ID`, Linux).
pub fn cpu_now() -> f64 {
    const CLOCK_THREAD_CPUTIME_ID: i32 = 3;
    let mut t = Timespec {
        seconds: 0,
        nanoseconds: 0,
    };
    // SAFETY: `t` is a valid, writable `struct timespec` for the call.
    let status = unsafe { clock_gettime(CLOCK_THREAD_CPUTIME_ID, &mut t) };
    assert_eq!(status, 0, "the thread's CPU clock is readable");
    t.seconds as f64 * 1e9 + t.nanoseconds as f64
}

/// `common.h`'s `peer_cpu_time`: the median time in
/// ns of `call`, over 31 batches of about 5 ms after doubling the batch up
/// to that length.
pub fn median_ns(mut call: impl FnMut()) -> f64 {
    let iterations = calibrated(&mut call);
    let mut samples: Vec<f64> = (0..31)
        .map(|_| {
            let start = cpu_now();
            for _ in 0..iterations {
                call();
            }
            (cpu_now() - start) / iterations as f64
        })
        .collect();
    samples.sort_by(f64::total_cmp);
    samples[15]
}

/// The median over 31 back-to-back pairs of batches of `b`'s time over
/// `a`'s (each batch as many calls as make `a`'s about 5 ms): a ratio of
/// two calls that a shared machine's slow spells, which last longer than a
/// pair, move together rather than apart. (The contacts' binary's alone.)
#[allow(dead_code)]
pub fn paired_ratio(mut a: impl FnMut(), mut b: impl FnMut()) -> f64 {
    let iterations = calibrated(&mut a);
    let mut ratios: Vec<f64> = (0..31)
        .map(|_| {
            let start = cpu_now();
            for _ in 0..iterations {
                a();
            }
            let middle = cpu_now();
            for _ in 0..iterations {
                b();
            }
            (cpu_now() - middle) / (middle - start)
        })
        .collect();
    ratios.sort_by(f64::total_cmp);
    ratios[15]
}

/// How many calls of `call` make a batch of about 5 ms (doubling from one).
fn calibrated(call: &mut impl FnMut()) -> u64 {
    let mut iterations: u64 = 1;
    loop {
        let start = cpu_now();
        for _ in 0..iterations {
            call();
        }
        if cpu_now() - start > 5e6 || iterations >= 1 << 40 {
            return iterations;
        }
        iterations *= 2;
    }
}
