//! Where the solvers' parallel passes run.
//!
//! A yarn substep runs four or five parallel passes (rayon). Called from a
//! thread outside any rayon pool (a program's main thread, an FMU master's
//! thread), each pass would hand its work to the global pool and put the
//! caller to sleep until it is done: thread wake-ups at every pass, which
//! on a small virtual machine cost about as much as the passes themselves.
//! [`on_pool`] moves a whole call (one substep, or many) onto a worker of
//! the global pool once; the passes inside it then run as nested work of
//! that pool. The results are the same bits either way (the passes'
//! chunking does not depend on threads).

/// Runs `f` on a rayon worker: here when this thread is one (of any pool),
/// else on the global pool, with this thread waiting for it.
pub fn on_pool<R: Send>(f: impl FnOnce() -> R + Send) -> R {
    if rayon::current_thread_index().is_some() {
        f()
    } else {
        rayon::scope(|_| f())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_on_a_worker_and_returns_the_result() {
        assert_eq!(rayon::current_thread_index(), None);
        let (on_worker, value) = on_pool(|| (rayon::current_thread_index().is_some(), 42));
        assert!(on_worker);
        assert_eq!(value, 42);
        // already on a worker: runs in place, on the same worker
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        pool.install(|| {
            let me = rayon::current_thread_index();
            assert_eq!(on_pool(rayon::current_thread_index), me);
        });
    }
}
