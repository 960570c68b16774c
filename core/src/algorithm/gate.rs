//! A gate that lets at most a fixed number of tile workers in at once; the
//! rest sleep on a condition variable (not spinning) until one leaves.
//!
//! A pool of more threads than the machine has cores would otherwise
//! time-slice its tile workers, each with its own sample buffers (a 256²
//! frustum's are over a megabyte), which then evict each other from the
//! caches at every switch: `--threads 8` on two cores measured up to 1.16×
//! the time of `--threads 2`. A worker holds its place until no tile is
//! left, so the workers let in are the only ones that render.
//!
//! A worker waits here only before it renders anything, and tile rendering
//! starts no parallel work of its own, so no worker inside ever waits on
//! one outside.

use std::sync::{Condvar, Mutex, OnceLock};

/// At most `places` holders of a [`Place`] at once.
pub(super) struct Gate {
    free: Mutex<usize>,
    left: Condvar,
}

/// A place inside a [`Gate`], given back when dropped.
pub(super) struct Place<'g>(&'g Gate);

impl Gate {
    /// A gate with `places` places (at least one).
    pub(super) fn new(places: usize) -> Gate {
        Gate {
            free: Mutex::new(places.max(1)),
            left: Condvar::new(),
        }
    }

    /// A place, once one is free.
    pub(super) fn enter(&self) -> Place<'_> {
        let mut free = self.free.lock().unwrap_or_else(|e| e.into_inner());
        while *free == 0 {
            free = self.left.wait(free).unwrap_or_else(|e| e.into_inner());
        }
        *free -= 1;
        Place(self)
    }
}

impl Drop for Place<'_> {
    fn drop(&mut self) {
        *self.0.free.lock().unwrap_or_else(|e| e.into_inner()) += 1;
        self.0.left.notify_one();
    }
}

/// The cores this process may run on (its CPU quota where one is set).
pub(super) fn cores() -> usize {
    static CORES: OnceLock<usize> = OnceLock::new();
    *CORES.get_or_init(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicUsize, Ordering};

    /// Of 8 threads entering a gate of 2 places, never more than 2 are in,
    /// and every one gets in.
    #[test]
    fn a_gate_lets_in_at_most_its_places() {
        let gate = Gate::new(2);
        let (inside, most, entered) = (
            AtomicUsize::new(0),
            AtomicUsize::new(0),
            AtomicUsize::new(0),
        );
        std::thread::scope(|s| {
            for _ in 0..8 {
                s.spawn(|| {
                    for _ in 0..50 {
                        let _place = gate.enter();
                        let now = inside.fetch_add(1, Ordering::SeqCst) + 1;
                        most.fetch_max(now, Ordering::SeqCst);
                        std::thread::yield_now();
                        inside.fetch_sub(1, Ordering::SeqCst);
                        entered.fetch_add(1, Ordering::SeqCst);
                    }
                });
            }
        });
        assert_eq!(entered.load(Ordering::SeqCst), 400);
        assert_eq!(most.load(Ordering::SeqCst), 2);
    }
}
