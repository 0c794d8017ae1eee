//! Hands independent jobs of very different lengths to a fixed number of workers, one job at a
//! time, in a chosen order.
//!
//! Splitting a list between workers up front (as a parallel iterator does) leaves a core idle
//! whenever one half holds the long jobs: a 20-minute Warehouse Dec-HDDRQN run beside a finished
//! 3-minute Cen-DDRQN half. Here each worker takes the next job the moment it is free, so at most
//! the last job of a batch runs alone, and jobs start in the order given (the campaign wants seed
//! order, so an interrupted batch leaves every curve with about the same seeds finished).

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// Run `job(i)` for every index in `order`, starting them in that order on `workers` threads
/// (at least one, at most one per job). Returns each job's result at its index in `order`.
/// A job that panics propagates the panic once every worker has stopped; callers that must
/// survive one catch it inside `job`.
pub fn run_in_order<T, F>(order: &[usize], workers: usize, job: F) -> Vec<T>
where
    T: Send,
    F: Fn(usize) -> T + Sync,
{
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<Option<T>>> = Mutex::new(order.iter().map(|_| None).collect());
    let workers = workers.clamp(1, order.len().max(1));
    std::thread::scope(|scope| {
        for _ in 0..workers {
            scope.spawn(|| loop {
                let slot = next.fetch_add(1, Ordering::Relaxed);
                let Some(&index) = order.get(slot) else { break };
                let result = job(index);
                results.lock().unwrap_or_else(|p| p.into_inner())[slot] = Some(result);
            });
        }
    });
    results
        .into_inner()
        .unwrap_or_else(|p| p.into_inner())
        .into_iter()
        .map(|r| r.expect("every slot of the queue ran"))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    #[test]
    fn results_come_back_in_queue_order_whatever_the_worker_count() {
        let order = [4, 0, 3, 1, 2];
        for workers in [0, 1, 2, 7] {
            assert_eq!(
                run_in_order(&order, workers, |i| i * 10),
                vec![40, 0, 30, 10, 20]
            );
        }
        assert!(run_in_order(&[], 2, |i| i).is_empty());
    }

    #[test]
    fn a_free_worker_takes_the_next_job_instead_of_waiting_for_its_half() {
        // One long job first, then short ones: with two workers the second runs every short job
        // while the first is still busy. Split in halves, the long job's half would also hold two
        // of the short ones, which would then start only after it ended.
        let started_during_long = AtomicUsize::new(0);
        let long_done = std::sync::atomic::AtomicBool::new(false);
        run_in_order(&[0, 1, 2, 3], 2, |i| {
            if i == 0 {
                std::thread::sleep(Duration::from_millis(400));
                long_done.store(true, Ordering::SeqCst);
            } else if !long_done.load(Ordering::SeqCst) {
                started_during_long.fetch_add(1, Ordering::SeqCst);
            }
        });
        assert_eq!(started_during_long.load(Ordering::SeqCst), 3);
    }

    #[test]
    fn jobs_start_in_the_order_given() {
        let log = Mutex::new(Vec::new());
        run_in_order(&[2, 0, 1], 1, |i| log.lock().unwrap().push(i));
        assert_eq!(*log.lock().unwrap(), vec![2, 0, 1]);
    }
}
