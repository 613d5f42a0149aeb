//! A clean stop on SIGINT and SIGTERM (or a request from within): the handler only raises a flag that the spin loop polls,
//! so the node is dropped normally (its DDS entities removed, final messages sent).
use std::sync::atomic::{AtomicBool, Ordering};

static REQUESTED: AtomicBool = AtomicBool::new(false);

extern "C" fn on_signal(_: libc::c_int) {
    // Only an atomic store: async-signal-safe.
    REQUESTED.store(true, Ordering::SeqCst);
}

/// Installs the handler for SIGINT and SIGTERM.
pub fn install() -> std::io::Result<()> {
    for sig in [libc::SIGINT, libc::SIGTERM] {
        // SAFETY: `on_signal` is async-signal-safe (one atomic store) and lives for the program.
        let previous = unsafe { libc::signal(sig, on_signal as extern "C" fn(libc::c_int) as libc::sighandler_t) };
        if previous == libc::SIG_ERR {
            return Err(std::io::Error::last_os_error());
        }
    }
    Ok(())
}

/// Asks for the same clean stop from within (a managed node's `shutdown` transition).
pub fn request() {
    REQUESTED.store(true, Ordering::SeqCst);
}

/// Whether SIGINT or SIGTERM has arrived since [`install`], or [`request`] was called.
pub fn requested() -> bool {
    REQUESTED.load(Ordering::SeqCst)
}
