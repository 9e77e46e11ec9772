//! Long calls that Ctrl-C interrupts: the work runs on a thread of its own while the
//! calling thread, without the GIL, looks for signals every few milliseconds. On one the
//! signal's exception (`KeyboardInterrupt`) is raised at once and the work is told to stop;
//! what it would have returned is dropped. A panic in the work is a `RuntimeError`, never an
//! abort of the interpreter.

use glam::DVec2;
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use rwt_core::density::{Density, LocalModel, Patch};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

/// How often the calling thread looks for signals.
const POLL: Duration = Duration::from_millis(20);

/// Raised when a call is interrupted: work that sees it may stop early.
#[derive(Clone, Debug, Default)]
pub struct Cancel(Arc<AtomicBool>);

impl Cancel {
    /// Whether the call was interrupted.
    pub fn is_set(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }
}

/// Runs `work` so that a signal interrupts the call (see the module docs).
pub fn interruptible<T: Send + 'static>(
    py: Python<'_>,
    work: impl FnOnce(Cancel) -> T + Send + 'static,
) -> PyResult<T> {
    let cancel = Cancel::default();
    let (sender, receiver) = std::sync::mpsc::sync_channel(1);
    // Only this thread receives; the lock makes the receiver shareable with `detach`.
    let receiver = std::sync::Mutex::new(receiver);
    let theirs = cancel.clone();
    std::thread::Builder::new()
        .name("rwt call".into())
        .spawn(move || {
            let done = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| work(theirs)));
            let _ = sender.send(done);
        })
        .map_err(|e| PyRuntimeError::new_err(format!("cannot start the call's thread: {e}")))?;
    loop {
        let next = py.detach(|| {
            let receiver = receiver.lock().unwrap_or_else(|p| p.into_inner());
            receiver.recv_timeout(POLL)
        });
        match next {
            Ok(Ok(value)) => return Ok(value),
            Ok(Err(panic)) => {
                let what = panic
                    .downcast_ref::<String>()
                    .map(String::as_str)
                    .or_else(|| panic.downcast_ref::<&str>().copied())
                    .unwrap_or("a panic");
                return Err(PyRuntimeError::new_err(format!("rwt failed: {what}")));
            }
            Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {
                if let Err(signal) = py.check_signals() {
                    cancel.0.store(true, Ordering::Relaxed);
                    return Err(signal);
                }
            }
            Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => {
                return Err(PyRuntimeError::new_err("rwt's call ended without a result"));
            }
        }
    }
}

/// A density that becomes empty once its call is interrupted, so that a query stops within
/// a few tiles (its result is dropped). Until then it is `inner`, bounds and shortcuts
/// included.
pub struct Cancellable<D: ?Sized> {
    /// Set by the interrupt.
    pub cancel: Cancel,
    /// The density.
    pub inner: Arc<D>,
}

impl<D: Density + ?Sized> Density for Cancellable<D> {
    #[inline]
    fn density(&self, p: DVec2) -> f64 {
        if self.cancel.is_set() {
            0.0
        } else {
            self.inner.density(p)
        }
    }

    fn max_over(&self, min: DVec2, max: DVec2) -> f64 {
        if self.cancel.is_set() {
            0.0
        } else {
            self.inner.max_over(min, max)
        }
    }

    fn min_over(&self, min: DVec2, max: DVec2) -> f64 {
        if self.cancel.is_set() {
            0.0
        } else {
            self.inner.min_over(min, max)
        }
    }

    #[inline]
    fn exceeds(&self, p: DVec2, factor: f64, threshold: f64) -> bool {
        !self.cancel.is_set() && self.inner.exceeds(p, factor, threshold)
    }

    #[inline]
    fn exceeds_near(&self, p: DVec2, factor: f64, threshold: f64) -> bool {
        !self.cancel.is_set() && self.inner.exceeds_near(p, factor, threshold)
    }

    fn local_model(&self, patch: &Patch) -> Option<LocalModel> {
        if self.cancel.is_set() {
            None
        } else {
            self.inner.local_model(patch)
        }
    }
}
