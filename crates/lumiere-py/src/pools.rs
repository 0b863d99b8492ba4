//! The rayon pools all of the module's library work runs in: renders in a pool of the thread count
//! asked for; work that a Ctrl-C may leave running in the background (loads, BVH builds, image
//! encodings) in one of the default count; short calls on films in another, so that they never
//! queue behind an abandoned load while holding the GIL.
//! Never rayon's global pool, which a forked process could not replace: a process forked from one
//! that had started pools (multiprocessing's `fork`, the default start method on Linux before
//! Python 3.14) inherits them without their threads, and work handed to them waited forever. Each
//! pool is kept for the next call of its kind, and made anew in a forked child.

use std::sync::{Arc, Mutex};

use lumiere::util::threads::MAX_THREADS;
use pyo3::prelude::*;
use rayon::ThreadPool;

use crate::errors::{OrPyErr, invalid};

/// A pool kept for reuse: starting threads for every call would cost milliseconds each.
struct Kept {
    /// The process that started the pool's threads.
    process: u32,
    threads: usize,
    pool: Arc<ThreadPool>,
}

/// A rayon pool of `threads` workers (0: `RAYON_NUM_THREADS` or one per core) for a render, as the
/// CLI builds it. Only the last one is kept, so a notebook that tries one thread count after
/// another does not pile up threads; a render still running on a replaced pool keeps it until it
/// ends.
pub fn for_render(py: Python<'_>, threads: usize) -> PyResult<Arc<ThreadPool>> {
    if threads > MAX_THREADS {
        return Err(invalid(format!("threads must be at most {MAX_THREADS}, got {threads}")));
    }
    static RENDER: Mutex<Option<Kept>> = Mutex::new(None);
    kept(py, &RENDER, threads)
}

/// Runs `work` in the pool of the default thread count kept for short calls on films, with the
/// GIL held, as a method borrowing its object needs (another thread's call then waits for it,
/// where without the GIL it would find the object borrowed). Nothing long runs in that pool, so
/// the GIL is not held for long: loads and encodings that a Ctrl-C leaves running use
/// [`for_background`].
pub fn install<T: Send>(py: Python<'_>, work: impl FnOnce() -> T + Send) -> PyResult<T> {
    static SHORT: Mutex<Option<Kept>> = Mutex::new(None);
    Ok(kept(py, &SHORT, 0)?.install(work))
}

/// The pool of the default thread count kept for work that may go on in the background after a
/// Ctrl-C (loads, builds, image encodings: see [`crate::watch::abandonable`]) or that runs
/// without the GIL (saving a checkpoint).
pub fn for_background(py: Python<'_>) -> PyResult<Arc<ThreadPool>> {
    static BACKGROUND: Mutex<Option<Kept>> = Mutex::new(None);
    kept(py, &BACKGROUND, 0)
}

/// `cache`'s pool if it has `threads` workers (0: as many as `RAYON_NUM_THREADS` asks for now, or
/// one per core) and was started by this process (see [`reused`]), else a new one, kept in its
/// place.
///
/// Starting a thousand threads takes about half a second: it happens without the GIL, so that
/// other Python threads run meanwhile, and without the cache's lock, which a thread holding the
/// GIL may be waiting for; so does dropping the pool replaced. Another call may start its own pool
/// meanwhile; the last one made is kept.
fn kept(py: Python<'_>, cache: &Mutex<Option<Kept>>, threads: usize) -> PyResult<Arc<ThreadPool>> {
    // By the count it stands for, so that 0 follows `RAYON_NUM_THREADS` as a new pool would.
    let threads = lumiere::util::threads::resolved(threads);
    if let Some(pool) = reused(cache, threads) {
        return Ok(pool);
    }
    let pool = Arc::new(py.detach(|| lumiere::util::threads::pool(threads)).or_py()?);
    let kept = Kept { process: std::process::id(), threads, pool: pool.clone() };
    let replaced = cache.lock().unwrap_or_else(|e| e.into_inner()).replace(kept);
    py.detach(move || drop(replaced));
    Ok(pool)
}

/// `cache`'s pool if it has `threads` workers and was started by this process. A pool inherited
/// from the parent of a fork is taken out and forgotten, never dropped: dropping it would wake
/// threads that do not exist here.
fn reused(cache: &Mutex<Option<Kept>>, threads: usize) -> Option<Arc<ThreadPool>> {
    let process = std::process::id();
    let mut cache = cache.lock().unwrap_or_else(|e| e.into_inner());
    match cache.take() {
        Some(kept) if kept.process == process && kept.threads == threads => {
            let pool = kept.pool.clone();
            *cache = Some(kept);
            Some(pool)
        }
        Some(kept) if kept.process != process => {
            std::mem::forget(kept);
            None
        }
        // Another count's pool: kept until its replacement is made (a render may still use it).
        other => {
            *cache = other;
            None
        }
    }
}
