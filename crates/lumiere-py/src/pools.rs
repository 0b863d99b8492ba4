//! The rayon pools all of the module's library work runs in: renders in a pool of the thread count
//! asked for, everything else (loads, BVH builds, films, image files) in one of the default count.
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
pub fn for_render(threads: usize) -> PyResult<Arc<ThreadPool>> {
    if threads > MAX_THREADS {
        return Err(invalid(format!("threads must be at most {MAX_THREADS}, got {threads}")));
    }
    static RENDER: Mutex<Option<Kept>> = Mutex::new(None);
    kept(&RENDER, threads)
}

/// Runs `work` in the pool of the default thread count kept for the module's other work.
pub fn install<T: Send>(work: impl FnOnce() -> T + Send) -> PyResult<T> {
    Ok(for_work()?.install(work))
}

/// The pool of the default thread count kept for the module's other work (see [`install`]).
pub fn for_work() -> PyResult<Arc<ThreadPool>> {
    static WORK: Mutex<Option<Kept>> = Mutex::new(None);
    kept(&WORK, 0)
}

/// `cache`'s pool if it has `threads` workers and was started by this process, else a new one,
/// kept in its place. A pool inherited from the parent of a fork is forgotten, never dropped:
/// dropping it would wake threads that do not exist here.
fn kept(cache: &Mutex<Option<Kept>>, threads: usize) -> PyResult<Arc<ThreadPool>> {
    let process = std::process::id();
    let mut cache = cache.lock().unwrap_or_else(|e| e.into_inner());
    match cache.take() {
        Some(kept) if kept.process == process && kept.threads == threads => {
            let pool = kept.pool.clone();
            *cache = Some(kept);
            return Ok(pool);
        }
        Some(kept) if kept.process != process => std::mem::forget(kept),
        _ => {}
    }
    let pool = Arc::new(lumiere::util::threads::pool(threads).or_py()?);
    *cache = Some(Kept { process, threads, pool: pool.clone() });
    Ok(pool)
}
