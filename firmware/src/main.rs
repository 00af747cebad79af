//! Runs the shared simulation and prints its report: on a Cortex-M4 through
//! semihosting (then exits QEMU with the result as status), on the host to
//! standard output, for comparison.

#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod bare_metal {
    use constrained_firmware::{simulate, write_report};
    use cortex_m_rt::entry;
    use cortex_m_semihosting::{debug, hio};

    #[entry]
    fn main() -> ! {
        let status = match (simulate(), hio::hstdout()) {
            (Ok(report), Ok(mut out)) => {
                let mut writer = Writer(&mut out);
                match write_report(&mut writer, &report) {
                    Ok(()) => debug::EXIT_SUCCESS,
                    Err(_) => debug::EXIT_FAILURE,
                }
            }
            _ => debug::EXIT_FAILURE,
        };
        debug::exit(status);
        #[allow(clippy::empty_loop)]
        loop {}
    }

    /// `core::fmt::Write` over the semihosting stdout.
    struct Writer<'a>(&'a mut hio::HostStream);

    impl core::fmt::Write for Writer<'_> {
        fn write_str(&mut self, s: &str) -> core::fmt::Result {
            self.0.write_all(s.as_bytes()).map_err(|_| core::fmt::Error)
        }
    }

    #[panic_handler]
    fn panic(_: &core::panic::PanicInfo) -> ! {
        debug::exit(debug::EXIT_FAILURE);
        #[allow(clippy::empty_loop)]
        loop {}
    }
}

#[cfg(not(target_os = "none"))]
fn main() {
    let report = constrained_firmware::simulate().expect("the simulation runs");
    let mut out = String::new();
    constrained_firmware::write_report(&mut out, &report).expect("formatting into a String");
    print!("{out}");
    // The host alone: the same loop in f64, the reference for the f32 gain
    // and trajectory (on standard error, so that the reports compare).
    let reference = constrained_firmware::balance::<f64>().expect("the f64 loop runs");
    let gain = report.gain.map(f64::from) - reference.gain;
    let gain = gain.amax() / reference.gain.amax();
    let state = (report.cart_pole.q.map(f64::from) - reference.state.q).amax();
    eprintln!(
        "cart-pole f32 vs f64: gain {gain:.2e} (relative), final q {state:.2e}; \
         late |θ − π| f32 {:.2e}, f64 {:.2e}",
        report.cart_pole_late_offset, reference.late_offset
    );
    let balanced = report.cart_pole_late_offset < 1e-2 && reference.late_offset < 1e-2;
    if gain > 1e-3 || state > 1e-3 || !balanced {
        eprintln!("error: the f32 loop does not match the f64 one, or does not balance");
        std::process::exit(1);
    }
}
