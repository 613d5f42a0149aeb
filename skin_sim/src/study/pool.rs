//! A worker pool over a list of jobs: `jobs` threads take the next item until none is left; the
//! calling thread collects the results in item order and reports each as it arrives.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc;

/// `f` over every item on `jobs` threads (at least one); `done(item index, result)` is called on
/// the calling thread as each finishes. Results in item order.
pub fn map<T: Sync, R: Send>(
    items: &[T],
    jobs: usize,
    f: impl Fn(usize, &T) -> R + Sync,
    mut done: impl FnMut(usize, &R),
) -> Vec<R> {
    let next = AtomicUsize::new(0);
    let (tx, rx) = mpsc::channel();
    let mut out: Vec<Option<R>> = items.iter().map(|_| None).collect();
    std::thread::scope(|s| {
        for _ in 0..jobs.clamp(1, items.len().max(1)) {
            let tx = tx.clone();
            let (next, f) = (&next, &f);
            s.spawn(move || loop {
                let k = next.fetch_add(1, Ordering::Relaxed);
                let Some(item) = items.get(k) else { break };
                // The receiver lives until every worker is done.
                let _ = tx.send((k, f(k, item)));
            });
        }
        drop(tx);
        for (k, r) in rx {
            done(k, &r);
            out[k] = Some(r);
        }
    });
    out.into_iter().map(|r| r.expect("every item ran")).collect()
}
