//! The thread count a front end asks for, and its pools: 0 means `RAYON_NUM_THREADS` where that
//! holds a positive count (as rayon reads it) and one per core otherwise, and no count exceeds
//! [`MAX_THREADS`], whether it came from a flag, an argument or the environment.

use crate::error::{Error, Result};

/// More threads than this would only cost memory and start-up time (100,000 took minutes to
/// start), and can exhaust the system's limit on processes.
pub const MAX_THREADS: usize = 1024;

/// The threads a count of `threads` starts (see the module note).
pub fn resolved(threads: usize) -> usize {
    if threads != 0 {
        return threads.min(MAX_THREADS);
    }
    let from_environment = std::env::var("RAYON_NUM_THREADS").ok().and_then(|v| v.trim().parse().ok());
    let count = from_environment.filter(|&n: &usize| n > 0);
    count.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get())).min(MAX_THREADS)
}

/// A rayon pool of [`resolved`]`(threads)` workers; an error naming the count when the system
/// will not start them (a limit on processes, as containers set).
pub fn pool(threads: usize) -> Result<rayon::ThreadPool> {
    let threads = resolved(threads);
    rayon::ThreadPoolBuilder::new().num_threads(threads).build().map_err(|e| cannot_start(threads, &e))
}

/// Starts rayon's global pool, which work outside any front end's pool uses (scene loading, the
/// benchmarks' set-up), with [`resolved`]`(0)` workers, once per process (later calls return the
/// first one's outcome): left to start on first use, a pool that cannot start panics there instead
/// of failing with a message.
pub fn start_global_pool() -> Result<()> {
    static STARTED: std::sync::OnceLock<std::result::Result<(), String>> = std::sync::OnceLock::new();
    let started = STARTED.get_or_init(|| {
        let threads = resolved(0);
        let built = rayon::ThreadPoolBuilder::new().num_threads(threads).build_global();
        built.map_err(|e| cannot_start(threads, &e).to_string())
    });
    started.clone().map_err(Error::invalid)
}

fn cannot_start(threads: usize, error: &rayon::ThreadPoolBuildError) -> Error {
    let what = if threads == 1 { "a thread".to_string() } else { format!("{threads} threads") };
    Error::invalid(format!("cannot start {what}: {error}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_are_capped_and_zero_is_at_least_one() {
        assert_eq!(resolved(3), 3);
        assert_eq!(resolved(100_000), MAX_THREADS);
        assert!((1..=MAX_THREADS).contains(&resolved(0)));
    }
}
