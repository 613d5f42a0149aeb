//! CPU time of the calling thread, the cost measure that other processes on the machine do not
//! inflate (wall time does, on a shared machine).

/// Clock ticks per second of `/proc` times (USER_HZ, 100 on Linux's every architecture).
const TICKS_PER_S: f64 = 100.0;

/// User + system CPU time of the calling thread \[s\] (10 ms resolution), from
/// `/proc/thread-self/stat`; None where that file does not exist.
pub fn thread_cpu_s() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/thread-self/stat").ok()?;
    // Fields after the parenthesised command name, from field 3 (state) on; utime and stime are
    // fields 14 and 15.
    let rest = &stat[stat.rfind(')')? + 1..];
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |k: usize| fields.get(k - 3)?.parse::<f64>().ok();
    Some((ticks(14)? + ticks(15)?) / TICKS_PER_S)
}
