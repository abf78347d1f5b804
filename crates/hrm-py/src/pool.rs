//! The package's own rayon thread pool, and long work run off the calling thread so that Ctrl-C
//! is honoured while it runs.
//!
//! The pool is the package's, not rayon's global one, for three reasons:
//! - a process forked by `multiprocessing` (Linux's default start method) copies the pool's
//!   handle but none of its threads, so a parallel call in the child would wait forever for
//!   workers that do not exist; the pool remembers the process it was built in, and a child
//!   builds a fresh one (the parent's is leaked, not dropped: its threads are not there to
//!   join);
//! - `RAYON_NUM_THREADS` is read here and checked ([`MAX_THREADS`]): a value that is not a
//!   number of threads is an [`InvalidInput`](crate::errors::InvalidInput) naming the variable,
//!   not a panic that leaves rayon's global pool unusable for the rest of the process; nothing
//!   is kept from a failed attempt, so setting the variable right makes the next call work;
//! - [`run`] executes work on another thread while the calling thread, with the GIL released,
//!   checks for signals every [`SIGNAL_POLL`]: a `KeyboardInterrupt` is raised within that
//!   time, and the work is told to stop ([`Cancel`]) and stops at its next chunk.

use crate::errors::{Error, Result};
use pyo3::prelude::*;
use rayon::{ThreadPool, ThreadPoolBuilder};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// The most threads `RAYON_NUM_THREADS` may ask for.
pub(crate) const MAX_THREADS: usize = 1024;

/// How often a thread waiting for long work checks for signals (Ctrl-C).
const SIGNAL_POLL: Duration = Duration::from_millis(50);

/// The pool and the process (id) that built it.
static POOL: Mutex<Option<(u32, Arc<ThreadPool>)>> = Mutex::new(None);

/// The number of threads `RAYON_NUM_THREADS` asks for: unset, empty or 0 is one per core.
fn threads() -> Result<usize> {
    let cores = || std::thread::available_parallelism().map_or(1, std::num::NonZero::get);
    let Some(value) = std::env::var_os("RAYON_NUM_THREADS") else {
        return Ok(cores());
    };
    let text = value.to_string_lossy();
    match text.trim().parse::<usize>() {
        _ if text.trim().is_empty() => Ok(cores()),
        Ok(0) => Ok(cores()),
        Ok(n) if n <= MAX_THREADS => Ok(n),
        _ => Err(Error::input(format!(
            "RAYON_NUM_THREADS must be a number of threads from 0 (one per core) to \
             {MAX_THREADS}, got {:?}",
            text.chars().take(40).collect::<String>()
        ))),
    }
}

/// The package's thread pool, built on first use in this process (again in a forked child).
pub(crate) fn pool() -> Result<Arc<ThreadPool>> {
    let mut slot = POOL.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    let pid = std::process::id();
    if let Some((owner, pool)) = slot.as_ref()
        && *owner == pid
    {
        return Ok(Arc::clone(pool));
    }
    // A pool from the parent of a fork has no threads here: leak it rather than drop it.
    if let Some(inherited) = slot.take() {
        std::mem::forget(inherited);
    }
    let threads = threads()?;
    let pool = ThreadPoolBuilder::new()
        .num_threads(threads)
        .thread_name(|i| format!("hrm-{i}"))
        .build()
        .map_err(|e| {
            Error::input(format!(
                "cannot start {threads} threads (RAYON_NUM_THREADS): {e}"
            ))
        })?;
    let pool = Arc::new(pool);
    *slot = Some((pid, Arc::clone(&pool)));
    Ok(pool)
}

/// A flag the thread waiting for long work sets when the user interrupted it: the work checks
/// it between chunks and stops. Clones share the flag.
#[derive(Clone)]
pub(crate) struct Cancel(Arc<AtomicBool>);

impl Cancel {
    /// Whether the work should stop.
    pub(crate) fn is_set(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }

    /// A flag that is not set (for work that runs without a waiting thread, it stays so).
    pub(crate) fn new() -> Self {
        Self(Arc::new(AtomicBool::new(false)))
    }
}

/// Runs `work` inside the package's pool on a thread of its own, the GIL released; the calling
/// thread checks for signals every [`SIGNAL_POLL`]. On a worker of the pool already, `work`
/// runs on it. A signal whose handler raises (Ctrl-C's
/// `KeyboardInterrupt`) sets `cancel`, waits for `work` to return (it checks `cancel` between
/// chunks) and is raised in place of the result.
pub(crate) fn run<T: Send>(
    py: Python<'_>,
    cancel: &Cancel,
    work: impl FnOnce() -> T + Send,
) -> PyResult<T> {
    // Called on one of the pool's workers (a run started from a Python callback of a run):
    // waiting there for another worker can take the pool's last thread and wait forever, so the
    // work runs here, the GIL released; the outer call's thread watches for signals.
    if rayon::current_thread_index().is_some() {
        return Ok(py.detach(work));
    }
    let pool = pool()?;
    let (value, interrupt) = py.detach(|| {
        std::thread::scope(|scope| {
            let (done, finished) = std::sync::mpsc::channel::<()>();
            let worker = scope.spawn(move || {
                let value = pool.install(work);
                // The receiver lives until the worker is joined.
                let _ = done.send(());
                value
            });
            let mut interrupt = None;
            while finished.recv_timeout(SIGNAL_POLL).is_err() && !worker.is_finished() {
                if interrupt.is_none()
                    && let Err(error) = Python::attach(|py| py.check_signals())
                {
                    cancel.0.store(true, Ordering::Relaxed);
                    interrupt = Some(error);
                }
            }
            match worker.join() {
                Ok(value) => (value, interrupt),
                Err(panic) => std::panic::resume_unwind(panic),
            }
        })
    });
    match interrupt {
        Some(error) => Err(error),
        None => Ok(value),
    }
}
