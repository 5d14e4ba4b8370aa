//! The worker pool of a batch: `jobs` scoped threads take items from a
//! shared queue in order; the calling thread receives each result in item
//! order (a result that finishes early waits for the ones before it).
//!
//! Why scoped threads and not rayon: the items are few and coarse (whole
//! graph runs, seconds to minutes each), so work stealing buys nothing; a
//! plain queue gives exactly `jobs` runs in flight, in-order streaming of
//! results to the caller (rayon's `collect` holds every result until the
//! end), a stop flag checked between items, and no new dependency.
//!
//! Memory is bounded: at most `jobs` items run at once, and a worker does
//! not start item `i` until every item before `i - 2·jobs` has been handed
//! to the caller, so at most `2·jobs` finished results wait in the
//! reordering buffer ([`for_each_ordered`]; [`for_each_ordered_ahead`]
//! takes that bound from its caller, for batches of small results).

use std::collections::BTreeMap;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{mpsc, Condvar, Mutex};

/// What became of one item: its result, or the message of a panic inside
/// its work (one item's panic does not take the batch down).
pub type Outcome<R> = Result<R, String>;

/// The default number of jobs: the cores this process may use
/// ([`std::thread::available_parallelism`]), 1 if unknown.
pub fn default_jobs() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// The queue the workers share: the next item to hand out, and how many
/// results the caller has received (which gates how far ahead workers go).
struct Queue<I> {
    items: I,
    next: usize,
    received: usize,
    stopped: bool,
}

/// Runs `work(index, item)` for every item on `jobs` threads (1: in the
/// calling thread, no thread started) and calls `receive(index, outcome)`
/// in the calling thread, in item order. When `stop` becomes true, no
/// further item starts; those running finish and are received. Returns how
/// many items were received (all of them unless stopped). At most `2·jobs`
/// finished results wait for an earlier one ([`for_each_ordered_ahead`]).
pub fn for_each_ordered<T, R, W, C>(items: Vec<T>, jobs: usize, stop: &AtomicBool, work: W, receive: C) -> usize
where
    T: Send,
    R: Send,
    W: Fn(usize, T) -> R + Sync,
    C: FnMut(usize, Outcome<R>),
{
    for_each_ordered_ahead(items, jobs, 2 * jobs.max(1), stop, work, receive)
}

/// [`for_each_ordered`], with a worker starting item `i` only once every
/// item before `i - ahead` has been received: `ahead` bounds how many
/// finished results wait in memory for a slow earlier one. A batch whose
/// results are small and whose items differ widely in length passes the
/// number of items, so that no worker ever waits.
pub fn for_each_ordered_ahead<T, R, W, C>(
    items: Vec<T>,
    jobs: usize,
    ahead: usize,
    stop: &AtomicBool,
    work: W,
    mut receive: C,
) -> usize
where
    T: Send,
    R: Send,
    W: Fn(usize, T) -> R + Sync,
    C: FnMut(usize, Outcome<R>),
{
    let run = |i: usize, t: T| -> Outcome<R> { catch_unwind(AssertUnwindSafe(|| work(i, t))).map_err(panic_text) };
    let jobs = jobs.max(1).min(items.len().max(1));
    if jobs == 1 {
        let mut received = 0;
        for (i, t) in items.into_iter().enumerate() {
            if stop.load(Ordering::Relaxed) {
                break;
            }
            receive(i, run(i, t));
            received += 1;
        }
        return received;
    }
    let window = ahead.max(jobs);
    let queue = Mutex::new(Queue { items: items.into_iter(), next: 0, received: 0, stopped: false });
    let moved = Condvar::new();
    let (tx, rx) = mpsc::channel::<(usize, Outcome<R>)>();
    std::thread::scope(|s| {
        for _ in 0..jobs {
            let tx = tx.clone();
            let (queue, moved, run) = (&queue, &moved, &run);
            s.spawn(move || loop {
                let (i, t) = {
                    let mut q = queue.lock().unwrap_or_else(|p| p.into_inner());
                    while !q.stopped && q.next >= q.received + window && !stop.load(Ordering::Relaxed) {
                        q = moved.wait(q).unwrap_or_else(|p| p.into_inner());
                    }
                    if q.stopped || stop.load(Ordering::Relaxed) {
                        return;
                    }
                    let Some(t) = q.items.next() else { return };
                    q.next += 1;
                    (q.next - 1, t)
                };
                if tx.send((i, run(i, t))).is_err() {
                    return;
                }
            });
        }
        drop(tx);
        let mut waiting: BTreeMap<usize, Outcome<R>> = BTreeMap::new();
        let mut received = 0;
        // The channel closes when every worker has returned.
        for (i, r) in rx.iter() {
            waiting.insert(i, r);
            while let Some(r) = waiting.remove(&received) {
                receive(received, r);
                received += 1;
                let mut q = queue.lock().unwrap_or_else(|p| p.into_inner());
                q.received = received;
                moved.notify_all();
            }
            if stop.load(Ordering::Relaxed) {
                queue.lock().unwrap_or_else(|p| p.into_inner()).stopped = true;
                moved.notify_all();
            }
        }
        received
    })
}

/// The text of a panic's payload.
fn panic_text(p: Box<dyn std::any::Any + Send>) -> String {
    format!("panicked: {}", panic_message(p.as_ref()))
}

/// The message a panic's payload carries (`panic!`'s text), or
/// `(no message)`.
pub fn panic_message(p: &(dyn std::any::Any + Send)) -> String {
    p.downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| p.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "(no message)".into())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::AtomicUsize;
    use std::time::Duration;

    /// Results arrive in item order whatever order the work finishes in.
    #[test]
    fn results_arrive_in_item_order_for_any_number_of_jobs() {
        for jobs in [1, 2, 3, 8, 50] {
            let items: Vec<u64> = (0..23).collect();
            let mut got = Vec::new();
            let n = for_each_ordered(
                items,
                jobs,
                &AtomicBool::new(false),
                |i, x| {
                    // Later items finish sooner.
                    std::thread::sleep(Duration::from_micros(200 * (23 - i as u64)));
                    x * x
                },
                |i, r| got.push((i, r.unwrap())),
            );
            assert_eq!(n, 23);
            assert_eq!(got, (0..23).map(|i| (i as usize, i * i)).collect::<Vec<_>>(), "jobs {jobs}");
        }
    }

    /// No more than `jobs` items run at once, and they do run at once.
    #[test]
    fn at_most_jobs_items_run_at_once() {
        let running = AtomicUsize::new(0);
        let most = AtomicUsize::new(0);
        for_each_ordered(
            vec![(); 12],
            3,
            &AtomicBool::new(false),
            |_, ()| {
                let now = running.fetch_add(1, Ordering::SeqCst) + 1;
                most.fetch_max(now, Ordering::SeqCst);
                std::thread::sleep(Duration::from_millis(5));
                running.fetch_sub(1, Ordering::SeqCst);
            },
            |_, _| {},
        );
        let m = most.load(Ordering::SeqCst);
        assert!((2..=3).contains(&m), "{m} in flight");
    }

    /// A slow first item holds back at most `2·jobs` finished results.
    #[test]
    fn a_slow_item_bounds_how_far_the_others_run_ahead() {
        let started = AtomicUsize::new(0);
        let ahead = AtomicUsize::new(0);
        for_each_ordered(
            (0..40).collect::<Vec<usize>>(),
            2,
            &AtomicBool::new(false),
            |i, _| {
                started.fetch_add(1, Ordering::SeqCst);
                if i == 0 {
                    std::thread::sleep(Duration::from_millis(60));
                    // Everything started while item 0 ran.
                    ahead.store(started.load(Ordering::SeqCst), Ordering::SeqCst);
                }
            },
            |_, _| {},
        );
        let a = ahead.load(Ordering::SeqCst);
        assert!(a <= 4, "{a} items started before the first was received");
    }

    /// With `ahead` the number of items, a slow first item holds no one
    /// back, and the results still arrive in item order.
    #[test]
    fn a_slow_item_holds_no_one_back_when_all_may_run_ahead() {
        let started = AtomicUsize::new(0);
        let ahead = AtomicUsize::new(0);
        let mut got = Vec::new();
        for_each_ordered_ahead(
            (0..40).collect::<Vec<usize>>(),
            2,
            40,
            &AtomicBool::new(false),
            |i, _| {
                started.fetch_add(1, Ordering::SeqCst);
                if i == 0 {
                    // Wait (at most 5 s) until every other item has started.
                    for _ in 0..5000 {
                        if started.load(Ordering::SeqCst) == 40 {
                            break;
                        }
                        std::thread::sleep(Duration::from_millis(1));
                    }
                    ahead.store(started.load(Ordering::SeqCst), Ordering::SeqCst);
                }
                i
            },
            |i, r| got.push((i, r.unwrap())),
        );
        assert_eq!(ahead.load(Ordering::SeqCst), 40, "every item started while the first ran");
        assert_eq!(got, (0..40).map(|i| (i, i)).collect::<Vec<_>>());
    }

    /// A panic is that item's outcome; the other items still run.
    #[test]
    fn a_panicking_item_does_not_lose_the_others() {
        for jobs in [1, 2] {
            let mut got = Vec::new();
            for_each_ordered(
                vec![1, 2, 3, 4],
                jobs,
                &AtomicBool::new(false),
                |_, x| {
                    assert!(x != 3, "item three is bad");
                    x
                },
                |_, r| got.push(r),
            );
            assert_eq!(got.len(), 4);
            assert_eq!(got[3], Ok(4));
            assert!(got[2].as_ref().unwrap_err().contains("item three is bad"), "{got:?}");
        }
    }

    /// Stopping starts nothing new; what was received is a prefix.
    #[test]
    fn a_stop_ends_the_batch_early() {
        for jobs in [1, 2] {
            let stop = AtomicBool::new(false);
            let mut got = Vec::new();
            let n = for_each_ordered(
                (0..100).collect::<Vec<usize>>(),
                jobs,
                &stop,
                |i, _| {
                    if i == 5 {
                        stop.store(true, Ordering::SeqCst);
                    }
                    i
                },
                |i, r| got.push((i, r.unwrap())),
            );
            assert!((6..=10).contains(&n), "jobs {jobs}: {n}");
            assert_eq!(got, (0..n).map(|i| (i, i)).collect::<Vec<_>>());
        }
    }
}
