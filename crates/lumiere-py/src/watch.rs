//! Long work with the GIL released, still answering Python: the work runs on a thread of its own
//! while the calling thread sleeps without the GIL, waking every few milliseconds to check for
//! signals (Ctrl-C raises `KeyboardInterrupt`, as Python code would), to call the progress
//! callback and to issue the warnings the work left (`RuntimeWarning`). A signal or an exception
//! from the callback or a warning (under a filter that makes it one) sets the cancel flag, which
//! the library polls inside passes, and is raised once the work has stopped ([`run`]). Work the
//! library cannot stop (a load, a BVH build) is left to finish in the background ([`abandonable`]).

use std::ffi::CString;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError};
use std::sync::{Arc, Mutex};
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

impl Watch {
    /// Counts `samples` more pixel samples done, for the progress callback: a render's progress
    /// hook.
    pub fn count(&self, samples: u64) {
        self.done.fetch_add(samples, Ordering::Relaxed);
    }
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
    let mut worker = Worker::spawn("a render", {
        let watch = watch.clone();
        move || work(&watch)
    })?;
    let mut failure: Option<PyErr> = None;
    let mut reported = None;
    let result = loop {
        let result = worker.wait(py)?;
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
        if let Some(result) = result {
            break result;
        }
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

/// Runs `work` (`what`, for messages), which the library cannot stop part-way (loading a scene,
/// building its BVH, encoding an image), on a
/// thread of its own while the calling thread sleeps without the GIL, waking every few
/// milliseconds to check for signals: Ctrl-C raises `KeyboardInterrupt` at once, as it would in
/// Python code, and the work runs to its end in the background, where its result is dropped.
/// Work left running so is waited for (still answering Ctrl-C) before the next starts, so that
/// interrupting a load again and again never piles up scenes in memory.
pub fn abandonable<T: Send + 'static>(
    py: Python<'_>,
    what: &'static str,
    work: impl FnOnce() -> T + Send + 'static,
) -> PyResult<T> {
    wait_for_work_left_running(py)?;
    let mut worker = Worker::spawn(what, work)?;
    loop {
        if let Some(value) = worker.wait(py)? {
            return Ok(value);
        }
        if let Err(interrupt) = py.check_signals() {
            let mut left = LEFT_RUNNING.lock().unwrap_or_else(|e| e.into_inner());
            left.0 = worker.process;
            left.1.extend(worker.thread.take());
            return Err(interrupt);
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

/// Work on a thread of its own, whose result comes back through a channel: the waiting thread
/// wakes as soon as it is sent, or as soon as the work panics and the sender is dropped.
struct Worker<T> {
    /// `None` once the thread was joined or handed over.
    thread: Option<JoinHandle<()>>,
    /// `None` only while a wait holds it: a receiver cannot be shared with the GIL-free wait.
    receive: Option<Receiver<T>>,
    /// The process that started the thread: a child forked meanwhile has no such thread.
    process: u32,
    /// What the work is, for the forked child's message ("a render").
    what: &'static str,
}

impl<T: Send + 'static> Worker<T> {
    fn spawn(what: &'static str, work: impl FnOnce() -> T + Send + 'static) -> PyResult<Self> {
        let (send, receive) = mpsc::sync_channel(1);
        let thread = std::thread::Builder::new()
            .name("lumiere-work".into())
            .spawn(move || {
                // Refused once the caller left the work running: the result is dropped here.
                let _ = send.send(work());
            })
            .map_err(|e| PyOSError::new_err(format!("cannot start a thread for {what}: {e}")))?;
        Ok(Worker { thread: Some(thread), receive: Some(receive), process: std::process::id(), what })
    }

    /// Waits up to [`POLL`] without the GIL: the result, if the work is over; its panic goes on
    /// here. In a process forked since the work started, an error: its thread stayed in the parent.
    fn wait(&mut self, py: Python<'_>) -> PyResult<Option<T>> {
        let receive = self.receive.take().expect("a wait at a time");
        let (receive, received) = py.detach(move || {
            let received = receive.recv_timeout(POLL);
            (receive, received)
        });
        self.receive = Some(receive);
        if std::process::id() != self.process {
            // The handle is the parent's thread's: forgotten, never joined or detached here.
            std::mem::forget(self.thread.take());
            return Err(invalid(format!(
                "this process was forked during {}, which it cannot go on with: its thread stayed in the parent",
                self.what
            )));
        }
        match received {
            Ok(value) => Ok(Some(value)),
            Err(RecvTimeoutError::Timeout) => Ok(None),
            Err(RecvTimeoutError::Disconnected) => match self.thread.take().map(JoinHandle::join) {
                Some(Err(panic)) => std::panic::resume_unwind(panic),
                _ => unreachable!("the work sends its result before it ends"),
            },
        }
    }
}
