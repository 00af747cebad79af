//! Which instruction-set extensions the CPU running the program has, for
//! the copies of generated methods that `dispatch: [..]` asks for: read
//! once, then a relaxed atomic load per call. x86-64 only (`lib.rs`).

use core::sync::atomic::{AtomicU8, Ordering};

/// Not yet read.
const UNKNOWN: u8 = 0;
/// Read: the CPU and the operating system support AVX.
const YES: u8 = 1;
/// Read: one of them does not.
const NO: u8 = 2;

/// Whether the CPU runs AVX instructions and the operating system saves
/// their registers: the condition under which a method compiled with
/// `#[target_feature(enable = "avx")]` may be called. Two threads that
/// read it first both detect it; they store the same answer.
#[inline]
pub fn has_avx() -> bool {
    static STATE: AtomicU8 = AtomicU8::new(UNKNOWN);
    match STATE.load(Ordering::Relaxed) {
        YES => true,
        NO => false,
        _ => {
            let avx = detect_avx();
            STATE.store(if avx { YES } else { NO }, Ordering::Relaxed);
            avx
        }
    }
}

/// CPUID leaf 1 says the CPU has AVX (ECX bit 28) and that the operating
/// system has enabled `XGETBV` (OSXSAVE, ECX bit 27); `XCR0` then says
/// whether the system saves the SSE (bit 1) and AVX (bit 2) registers on
/// a context switch. All three are needed (Intel SDM, vol. 1, 14.3).
#[cold]
fn detect_avx() -> bool {
    const OSXSAVE: u32 = 1 << 27;
    const AVX: u32 = 1 << 28;
    const SSE_AND_AVX_STATE: u64 = 0b110;
    let leaf = core::arch::x86_64::__cpuid(1);
    if leaf.ecx & (OSXSAVE | AVX) != OSXSAVE | AVX {
        return false;
    }
    // SAFETY: OSXSAVE is set, so the OS has enabled XGETBV, the
    // instruction `xcr0` runs (and the `xsave` feature it is compiled
    // with is present).
    let xcr0 = unsafe { xcr0() };
    xcr0 & SSE_AND_AVX_STATE == SSE_AND_AVX_STATE
}

/// `XCR0`, the register of the state components the OS saves.
///
/// # Safety
/// The caller has read OSXSAVE in CPUID leaf 1: without it `XGETBV` is
/// an invalid instruction.
#[target_feature(enable = "xsave")]
unsafe fn xcr0() -> u64 {
    // SAFETY: as the function's contract says.
    unsafe { core::arch::x86_64::_xgetbv(0) }
}

#[cfg(test)]
mod tests {
    #[test]
    fn avx_is_what_the_standard_library_detects() {
        // The standard library reads the same bits its own way; both
        // answers, and the cached second read, must agree.
        let expected = std::arch::is_x86_feature_detected!("avx");
        assert_eq!(super::has_avx(), expected);
        assert_eq!(super::has_avx(), expected);
    }
}
