//! The lock that makes one `impulse.World` safe to share between Python threads.
//!
//! Every method of a world takes the lock for its whole call, so calls on one world run one
//! at a time, each whole (a `step(n)` is never interleaved with another call). A thread
//! waiting for the lock does so with the GIL released (`MutexExt::lock_py_attached`), and a
//! step releases the GIL while it runs, so other threads and other worlds run meanwhile.
//!
//! A call cannot wait for a lock its own thread holds (that would wait forever): Python code
//! that runs inside a call on the world — a signal handler run between the chunks of a
//! `step(n)`, a finaliser — and uses the same world gets `RuntimeError` instead.

use std::ops::{Deref, DerefMut};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::sync::MutexExt;

thread_local! {
    /// Its address names the current thread (never 0, unique among live threads).
    static THREAD_MARK: u8 = const { 0 };
}

fn current_thread() -> usize {
    THREAD_MARK.with(|mark| std::ptr::from_ref(mark) as usize)
}

/// An engine world behind a mutex that remembers which thread holds it.
pub(crate) struct WorldLock {
    world: Mutex<impulse::World>,
    /// `current_thread()` of the holder, 0 while free.
    holder: AtomicUsize,
}

/// Exclusive access to the engine world; releases the lock when dropped.
pub(crate) struct WorldGuard<'a> {
    world: std::sync::MutexGuard<'a, impulse::World>,
    holder: &'a AtomicUsize,
}

impl WorldLock {
    pub(crate) fn new(world: impulse::World) -> Self {
        WorldLock {
            world: Mutex::new(world),
            holder: AtomicUsize::new(0),
        }
    }

    /// Waits (without the GIL) until no other call uses the world, then holds it. Raises
    /// `RuntimeError` when the calling thread already holds it (Python code run from inside a
    /// call on this world).
    pub(crate) fn lock(&self, py: Python<'_>) -> PyResult<WorldGuard<'_>> {
        let me = current_thread();
        // Only the holder stores its own mark, so seeing ours means we hold the lock.
        if self.holder.load(Ordering::Acquire) == me {
            return Err(PyRuntimeError::new_err(
                "this world is in use by a call on this same thread (Python code run from \
                 inside that call, such as a signal handler during `step`, cannot use it)",
            ));
        }
        // A poisoned lock only means a panic unwound through a holder; every engine call runs
        // inside `errors::guarded`, which reports that panic, so the world is still readable.
        let world = self
            .world
            .lock_py_attached(py)
            .unwrap_or_else(|poisoned| poisoned.into_inner());
        self.holder.store(me, Ordering::Release);
        Ok(WorldGuard {
            world,
            holder: &self.holder,
        })
    }
}

impl Drop for WorldGuard<'_> {
    fn drop(&mut self) {
        // Cleared before the mutex (a field, dropped after this) is released.
        self.holder.store(0, Ordering::Release);
    }
}

impl Deref for WorldGuard<'_> {
    type Target = impulse::World;

    fn deref(&self) -> &impulse::World {
        &self.world
    }
}

impl DerefMut for WorldGuard<'_> {
    fn deref_mut(&mut self) -> &mut impulse::World {
        &mut self.world
    }
}
