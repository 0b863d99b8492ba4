//! Long work with the GIL released, still answering Python: the work runs on a thread of its own
//! while the calling thread sleeps without the GIL, waking every few milliseconds to check for
//! signals (Ctrl-C raises `KeyboardInterrupt`, as Python code would), to call the progress
//! callback and to issue the warnings the work left (`RuntimeWarning`). A signal or an exception
//! from the callback or a warning (under a filter that makes it one) sets the cancel flag, which
//! the library polls inside passes, and is raised once the work has stopped ([`run`]). Work the
//! library cannot stop (a load, a BVH build) is left to finish in the background ([`abandonable`]).

use std::ffi::CString;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::{self, RecvTimeoutError};
use std::sync::{Arc, Condvar, Mutex};
use std::thread::JoinHandle;
use std::time::Duration;

use pyo3::exceptions::{PyOSError, PyRuntimeWarning};
use pyo3::prelude::*;

use crate::errors::{invalid, to_py};

/// How often the waiting thread checks signals and reports progress.
const POLL: Duration = Duration::from_millis(25);

/// What the work sees: the cancel flag to pass to the library, a counter of samples done, and
/// the warnings to issue in Python.
pub struct Watch {
    pub cancel: AtomicBool,
    pub done: AtomicU64,
    pub warnings: Mutex<Vec<String>>,
}

/// Runs `work` on a new thread; calls `progress(done, total)` as `watch.done` moves (and once at
/// the end), and issues the warnings it leaves `stacklevel` frames up from the caller (1: the
/// caller's line). The result of `work`, or the first signal or callback exception. The thread
/// owns what it works on, so that a process forked meanwhile (from a `progress` callback), which
/// has no such thread, can give up on it instead of waiting forever.
pub fn run<T: Send + 'static>(
    py: Python<'_>,
    total: Option<u64>,
    progress: Option<&Bound<'_, PyAny>>,
    stacklevel: i32,
    work: impl FnOnce(&Watch) -> lumiere::Result<T> + Send + 'static,
) -> PyResult<T> {
    let watch =
        Arc::new(Watch { cancel: AtomicBool::new(false), done: AtomicU64::new(0), warnings: Mutex::new(Vec::new()) });
    let finished = Arc::new(Finished::default());
    let worker = {
        let (watch, finished) = (watch.clone(), finished.clone());
        std::thread::Builder::new()
            .name("lumiere-render".into())
            .spawn(move || {
                // Dropped when the work returns or panics: either way the waiting thread wakes.
                let _signal = SignalOnDrop(&finished);
                work(&watch)
            })
            .map_err(|e| PyOSError::new_err(format!("cannot start a thread for the render: {e}")))?
    };
    let process = std::process::id();
    let mut failure: Option<PyErr> = None;
    let mut reported = None;
    loop {
        let over = py.detach(|| finished.wait(POLL));
        if std::process::id() != process {
            // The handle is the parent's thread's: forgotten, never joined or detached here.
            std::mem::forget(worker);
            return Err(invalid(
                "this process was forked during a render, which it cannot go on with: the render's thread stayed in the parent",
            ));
        }
        if failure.is_none() {
            let step = py
                .check_signals()
                .and_then(|()| warn(py, &watch.warnings, stacklevel))
                .and_then(|()| report(progress, &watch.done, total, &mut reported));
            if let Err(e) = step {
                watch.cancel.store(true, Ordering::SeqCst);
                failure = Some(e);
            }
        }
        if over {
            break;
        }
    }
    let result = match py.detach(move || worker.join()) {
        Ok(result) => result,
        Err(panic) => std::panic::resume_unwind(panic),
    };
    if let Some(e) = failure {
        return Err(e);
    }
    let value = result.map_err(to_py)?;
    warn(py, &watch.warnings, stacklevel)?;
    report(progress, &watch.done, total, &mut reported)?;
    Ok(value)
}

/// Work that a Ctrl-C left running in the background (see [`abandonable`]), with the process
/// that started it: a child forked meanwhile inherits the handles, not the threads.
static LEFT_RUNNING: Mutex<(u32, Vec<JoinHandle<()>>)> = Mutex::new((0, Vec::new()));

/// Runs `work`, which the library cannot stop part-way (loading a scene, building its BVH), on a
/// thread of its own while the calling thread sleeps without the GIL, waking every few
/// milliseconds to check for signals: Ctrl-C raises `KeyboardInterrupt` at once, as it would in
/// Python code, and the work runs to its end in the background, where its result is dropped.
/// Work left running so is waited for (still answering Ctrl-C) before the next starts, so that
/// interrupting a load again and again never piles up scenes in memory.
pub fn abandonable<T: Send + 'static>(py: Python<'_>, work: impl FnOnce() -> T + Send + 'static) -> PyResult<T> {
    wait_for_work_left_running(py)?;
    let (send, mut receive) = mpsc::sync_channel(1);
    let worker = std::thread::Builder::new()
        .name("lumiere-work".into())
        .spawn(move || {
            // The receiver is gone once the caller was interrupted: the result is dropped here.
            let _ = send.send(work());
        })
        .map_err(|e| PyOSError::new_err(format!("cannot start a thread for the work: {e}")))?;
    loop {
        // The receiver goes into the GIL-free wait and comes back out: it cannot be shared.
        let (back, received) = py.detach(move || {
            let received = receive.recv_timeout(POLL);
            (receive, received)
        });
        receive = back;
        match received {
            Ok(value) => return Ok(value),
            Err(RecvTimeoutError::Timeout) => {
                if let Err(interrupt) = py.check_signals() {
                    let mut left = LEFT_RUNNING.lock().unwrap_or_else(|e| e.into_inner());
                    left.0 = std::process::id();
                    left.1.push(worker);
                    return Err(interrupt);
                }
            }
            // The work panicked before sending anything: the panic goes on here.
            Err(RecvTimeoutError::Disconnected) => match worker.join() {
                Err(panic) => std::panic::resume_unwind(panic),
                Ok(()) => unreachable!("the worker sends its result before it ends"),
            },
        }
    }
}

/// Returns once no work a Ctrl-C left running is still running, or with the next signal.
fn wait_for_work_left_running(py: Python<'_>) -> PyResult<()> {
    loop {
        let mut left = LEFT_RUNNING.lock().unwrap_or_else(|e| e.into_inner());
        if left.0 != std::process::id() {
            // Forked: the threads are the parent's. Their handles are forgotten, never dropped
            // (which would detach threads that do not exist here).
            std::mem::forget(std::mem::take(&mut left.1));
        }
        left.1.retain(|worker| !worker.is_finished());
        if left.1.is_empty() {
            return Ok(());
        }
        drop(left);
        py.detach(|| std::thread::sleep(POLL));
        py.check_signals()?;
    }
}

/// Issues the warnings the work left, as `RuntimeWarning`s `stacklevel` frames up; an error where
/// a filter makes them errors.
fn warn(py: Python<'_>, warnings: &Mutex<Vec<String>>, stacklevel: i32) -> PyResult<()> {
    let pending = std::mem::take(&mut *warnings.lock().unwrap_or_else(|e| e.into_inner()));
    for message in pending {
        // A message holds no NUL: the library writes numbers and words.
        let message = CString::new(message.replace('\0', " ")).unwrap_or_default();
        PyErr::warn(py, &py.get_type::<PyRuntimeWarning>(), &message, stacklevel)?;
    }
    Ok(())
}

/// Calls the callback if the count moved since the last call.
fn report(
    progress: Option<&Bound<'_, PyAny>>,
    done: &AtomicU64,
    total: Option<u64>,
    reported: &mut Option<u64>,
) -> PyResult<()> {
    let Some(callback) = progress else { return Ok(()) };
    let now = done.load(Ordering::Relaxed);
    if *reported != Some(now) {
        *reported = Some(now);
        callback.call1((now, total))?;
    }
    Ok(())
}

/// Set once the work is over, waking the waiting thread at once rather than at its next poll.
#[derive(Default)]
struct Finished {
    over: Mutex<bool>,
    wake: Condvar,
}

impl Finished {
    /// Waits up to `timeout`; whether the work is over.
    fn wait(&self, timeout: Duration) -> bool {
        let over = self.over.lock().unwrap_or_else(|e| e.into_inner());
        let (over, _) = self.wake.wait_timeout_while(over, timeout, |over| !*over).unwrap_or_else(|e| e.into_inner());
        *over
    }
}

struct SignalOnDrop<'a>(&'a Finished);

impl Drop for SignalOnDrop<'_> {
    fn drop(&mut self) {
        *self.0.over.lock().unwrap_or_else(|e| e.into_inner()) = true;
        self.0.wake.notify_all();
    }
}
