//! Keeps a thread pool's other workers awake through a batch of steps.
//!
//! A step has several parallel stages with short serial stretches between them. An idle rayon
//! worker looks for work for a few dozen rounds and then sleeps, and the next parallel stage must
//! wake it (a futex and the scheduler: tens of microseconds on a virtual machine, a step of
//! 10,000 spheres on two threads taking about 700). Instead, through a batch, each other worker
//! takes and runs the work the stepping thread offers as soon as it is offered, and looks again
//! at once when there is none, until the batch ends.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

/// Runs `batch` on the current thread of a rayon pool while the pool's other workers look for
/// its parallel work without sleeping; returns what `batch` returns.
pub fn with_workers_awake<R>(batch: impl FnOnce() -> R) -> R {
    with_workers_looking(batch, None)
}

/// [`with_workers_awake`], counting in `rounds` (if any: a test's) the rounds the other workers
/// looked for work. Not counted otherwise: the workers would write, at every round, a line of
/// the stepping thread's stack.
fn with_workers_looking<R>(batch: impl FnOnce() -> R, rounds: Option<&AtomicU64>) -> R {
    let Some(stepping) = rayon::current_thread_index() else {
        return batch();
    };
    if rayon::current_num_threads() < 2 {
        return batch();
    }
    let done = AtomicBool::new(false);
    rayon::in_place_scope(|scope| {
        scope.spawn_broadcast(|_, worker| {
            // The stepping thread runs its own copy too (when it next looks for work): at once.
            if worker.index() != stepping {
                take_work_until(&done, rounds);
            }
        });
        // Set when the batch ends, even by a panic: the scope waits for the workers' copies.
        let _end = EndOfBatch(&done);
        batch()
    })
}

/// Rounds without work after which an awake worker gives its core to any other thread that
/// wants it at each round: more threads than cores (tests run side by side, other programs) must
/// not wait on a worker that only looks for work. A round looks at the other threads' queues (tens
/// of nanoseconds), so this is some tens of microseconds, the length of a step's longer serial
/// stretches; 256 rounds measured the same within the machine's drift.
const ROUNDS_BEFORE_YIELDING: u32 = 2048;

/// Takes and runs the pool's work until `done`, counting the rounds in `rounds` (if any).
fn take_work_until(done: &AtomicBool, rounds: Option<&AtomicU64>) {
    let mut idle = 0;
    while !done.load(Ordering::Acquire) {
        if let Some(rounds) = rounds {
            rounds.fetch_add(1, Ordering::Relaxed);
        }
        if rayon::yield_now() == Some(rayon::Yield::Executed) {
            idle = 0;
        } else if idle < ROUNDS_BEFORE_YIELDING {
            idle += 1;
            std::hint::spin_loop();
        } else {
            std::thread::yield_now();
        }
    }
}

/// Ends the batch when dropped.
struct EndOfBatch<'a>(&'a AtomicBool);

impl Drop for EndOfBatch<'_> {
    fn drop(&mut self) {
        self.0.store(true, Ordering::Release);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pool(threads: usize) -> rayon::ThreadPool {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
    }

    /// Through a batch on two threads, the other worker keeps looking for work in a serial
    /// stretch far longer than a rayon worker looks before it sleeps (a few dozen rounds), runs
    /// the batch's parallel work, and is let go at the batch's end: the call returns.
    ///
    /// The stretch is waited out until the worker has looked `LOOKS` more times, for five
    /// seconds at most, rather than for a fixed time: on a loaded machine (tests and builds side
    /// by side on two cores) a worker that yields its core at each round may look only a few
    /// dozen times in 30 ms (21 once, in CI), where a sleeping one never looks again.
    #[test]
    fn the_other_worker_keeps_looking_through_the_batch_and_is_let_go_at_its_end() {
        const LOOKS: u64 = 200;
        let rounds = AtomicU64::new(0);
        let (during, sum, ran) = pool(2).install(|| {
            let stepping = rayon::current_thread_index();
            with_workers_looking(
                || {
                    std::thread::sleep(std::time::Duration::from_millis(5));
                    let before = rounds.load(Ordering::Relaxed);
                    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(5);
                    while rounds.load(Ordering::Relaxed) - before < LOOKS
                        && std::time::Instant::now() < deadline
                    {
                        std::thread::sleep(std::time::Duration::from_millis(1));
                    }
                    let during = rounds.load(Ordering::Relaxed) - before;
                    // Work that only the other worker takes.
                    let ran = rayon::broadcast(|worker| Some(worker.index()) != stepping);
                    let sum: u64 = rayon::join(|| (0..1000u64).sum::<u64>(), || 7).0;
                    (during, sum, ran.iter().filter(|&&other| other).count())
                },
                Some(&rounds),
            )
        });
        assert!(during >= LOOKS, "{during} rounds in five seconds");
        assert_eq!((sum, ran), (499_500, 1));
    }

    /// A batch that panics ends, and the panic reaches the caller (the other worker is let go:
    /// the scope waits for it).
    #[test]
    fn a_panicking_batch_lets_the_workers_go() {
        let caught = std::panic::catch_unwind(|| {
            pool(2).install(|| with_workers_awake(|| panic!("the batch fails")))
        });
        assert!(caught.is_err());
    }

    /// On one thread, and outside any pool, the batch simply runs.
    #[test]
    fn one_thread_or_none_runs_the_batch_alone() {
        assert_eq!(pool(1).install(|| with_workers_awake(|| 3)), 3);
        assert_eq!(with_workers_awake(|| 4), 4);
    }
}
