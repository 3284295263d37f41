//! A request to stop a long computation (Ctrl-C): the binding layer raises it
//! when Python has a pending signal, and every long loop of the core checks it
//! between pieces of work of at most a few milliseconds. A kernel that sees it
//! raised returns at once with a meaningless value; the orchestration that
//! called it turns the raised flag into [`CoreError::Interrupted`], so such
//! values never reach a result.

use std::sync::atomic::{AtomicBool, Ordering};

use crate::error::{CoreError, CoreResult};

#[derive(Debug, Default)]
pub struct Interrupt(AtomicBool);

impl Interrupt {
    /// Not raised.
    pub const fn new() -> Self {
        Interrupt(AtomicBool::new(false))
    }

    /// Asks every loop that checks this flag to stop.
    pub fn raise(&self) {
        self.0.store(true, Ordering::Relaxed);
    }

    pub fn raised(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }

    /// `Err(Interrupted)` once raised.
    pub fn check(&self) -> CoreResult<()> {
        if self.raised() {
            Err(CoreError::Interrupted)
        } else {
            Ok(())
        }
    }
}

/// A flag nobody raises, for callers that cannot be interrupted.
pub static NEVER: Interrupt = Interrupt::new();
