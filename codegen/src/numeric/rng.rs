//! Deterministic pseudo-random numbers for compile-time numeric checks.
//!
//! The macro must expand identically on every machine and every run (stable
//! snapshots, reproducible builds), so it never uses an OS seed.

use crate::expr::Sym;

/// How many points a compile-time check samples a property at.
pub const SAMPLE_POINTS: usize = 4;

/// The [`SAMPLE_POINTS`] deterministic points at which a compile-time
/// check samples a property (two expressions agree, `M` is singular), each
/// a value for every symbol ([`SplitMix64::value_for`]). `stream` makes
/// each check's points its own, so that one check's decisions do not move
/// when another's points change.
pub fn sample_points(stream: u64) -> impl Iterator<Item = impl Fn(Sym) -> f64> {
    let mut rng = SplitMix64::new(stream);
    (0..SAMPLE_POINTS).map(move |_| {
        let seed = rng.next_u64();
        move |s| SplitMix64::value_for(seed, s)
    })
}

/// SplitMix64 (Steele, Lea & Flood 2014): tiny, fast, good enough for choosing
/// test points.
#[derive(Clone, Debug)]
pub struct SplitMix64(u64);

impl SplitMix64 {
    /// A generator with a fixed seed.
    pub fn new(seed: u64) -> Self {
        SplitMix64(seed)
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// A uniform number in `[0, 1)`.
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A value for variable `s` at the point numbered `seed`: uniform in
    /// `[0.2, 0.9)`, inside the domain of every DSL function (`ln`, `sqrt`,
    /// `asin`, `acos`), and different for every variable.
    pub fn value_for(seed: u64, s: Sym) -> f64 {
        let tag = match s {
            Sym::Coord(i) => 4 * i as u64,
            Sym::Vel(i) => 4 * i as u64 + 1,
            Sym::Param(i) => 4 * i as u64 + 2,
            Sym::Time => 3,
            Sym::Multiplier(i) => 4 * i as u64 + 7,
            Sym::Seed(i) => 4 * i as u64 + 9,
            Sym::Accel(i) => 4 * i as u64 + 11,
        };
        let mut r = SplitMix64::new(seed ^ tag.wrapping_mul(0x2545_f491_4f6c_dd1d));
        0.2 + 0.7 * r.next_f64()
    }
}
