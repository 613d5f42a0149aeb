//! A clean stop on SIGINT and SIGTERM (or a request from within): the handler only raises a flag that the spin loop polls,
//! so the node is dropped normally (its DDS entities removed, final messages sent), within a bound
//! ([`bound_teardown`]).
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

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

/// How long a node's teardown (its DDS entities removed, rcl shut down) may take once its work is
/// done: under the 5 s after which `ros2 launch` escalates SIGINT to SIGTERM.
pub const TEARDOWN_LIMIT: Duration = Duration::from_secs(2);

/// Called when a node's work is done (its last messages sent): if the process has not ended
/// [`TEARDOWN_LIMIT`] later, it exits with `code` and a warning on stderr. A teardown that hangs in
/// the middleware (seen once in a launch test: skin_watchdog logged its stop, then never left it)
/// must not keep a stopped node on the graph until the launch system kills it.
pub fn bound_teardown(code: i32) {
    std::thread::spawn(move || {
        std::thread::sleep(TEARDOWN_LIMIT);
        let name = std::env::args().next().unwrap_or_default();
        eprintln!("[WARN] {name}: the middleware's teardown did not end within {TEARDOWN_LIMIT:?}; exiting without it");
        // SAFETY: ends the process; no atexit handlers, which would run the same hung teardown.
        unsafe { libc::_exit(code) };
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Set in the child process of [`a_hung_teardown_ends_the_process`].
    const CHILD: &str = "SKIN_SHUTDOWN_TEST_CHILD";

    #[test]
    fn a_hung_teardown_ends_the_process() {
        if std::env::var_os(CHILD).is_some() {
            bound_teardown(3);
            std::thread::sleep(Duration::from_secs(600)); // a teardown that never returns
            return;
        }
        let start = std::time::Instant::now();
        let out = std::process::Command::new(std::env::current_exe().unwrap())
            .args(["--exact", "shutdown::tests::a_hung_teardown_ends_the_process", "--nocapture"])
            .env(CHILD, "1")
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(3), "the bound's exit code; stderr: {stderr}");
        assert!(stderr.contains("teardown did not end"), "the warning: {stderr}");
        assert!(start.elapsed() < Duration::from_secs(300), "ended by the bound, not the sleep");
    }
}
