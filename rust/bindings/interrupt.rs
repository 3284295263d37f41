//! Long computations that Ctrl-C can stop. The work runs on its own thread
//! with the GIL released; the calling thread waits for it in short slices and,
//! between them, lets Python run its signal handlers. When one raises (SIGINT
//! gives `KeyboardInterrupt`), the core's [`Interrupt`] is raised, the work's
//! loops return within milliseconds, and the handler's exception is returned.

use std::sync::mpsc::{self, RecvTimeoutError};
use std::time::Duration;

use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;

use crate::error::CoreResult;
use crate::interrupt::Interrupt;

/// How long the caller waits for the work between two looks at the signals.
const SIGNAL_POLL: Duration = Duration::from_millis(50);

/// Runs `work` without the GIL; a pending signal whose handler raises stops it
/// and returns that exception.
pub fn run_interruptible<T, F>(py: Python<'_>, work: F) -> PyResult<T>
where
    T: Send,
    F: FnOnce(&Interrupt) -> CoreResult<T> + Send,
{
    let stop = Interrupt::new();
    let stop_ref = &stop;
    std::thread::scope(|scope| {
        let (done, mut result) = mpsc::channel();
        let worker = scope.spawn(move || {
            // The receiver may be gone after an interrupt: nothing to report then.
            let _ = done.send(work(stop_ref));
        });
        loop {
            // The receiver travels into the GIL-free closure and back (it is not Sync).
            let (received, back) = py.detach(move || (result.recv_timeout(SIGNAL_POLL), result));
            result = back;
            match received {
                Ok(outcome) => return outcome.map_err(PyErr::from),
                Err(RecvTimeoutError::Timeout) => {
                    if let Err(err) = py.check_signals() {
                        stop.raise();
                        // The loops check the flag often: this wait is short.
                        py.detach(move || {
                            let _ = result.recv();
                        });
                        return Err(err);
                    }
                }
                Err(RecvTimeoutError::Disconnected) => {
                    let message = match worker.join() {
                        Err(panic) => panic
                            .downcast_ref::<&str>()
                            .map(|s| s.to_string())
                            .or_else(|| panic.downcast_ref::<String>().cloned())
                            .unwrap_or_else(|| "unknown panic".into()),
                        Ok(()) => "the computation ended without a result".into(),
                    };
                    return Err(PyRuntimeError::new_err(format!(
                        "internal error in the Rust core: {message}"
                    )));
                }
            }
        }
    })
}
