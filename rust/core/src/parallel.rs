//! Row-band parallelism helpers (rayon), and [`run_hot`], which the matchers' and the
//! refinement's entry points wrap their work in.
//!
//! Kernels split an image into bands of rows; each band is processed independently so results are
//! bit-identical whatever the thread count (no reductions across bands in floating point).

use std::cell::Cell;

use rayon::prelude::*;

/// Rows per rayon task: large enough to amortise scheduling, small enough to balance 2-16 cores.
pub const ROWS_PER_TASK: usize = 16;

/// Calls `f(y, row)` for every row of a `width`-wide row-major buffer, in parallel bands.
pub fn for_each_row<T, F>(buf: &mut [T], width: usize, f: F)
where
    T: Send,
    F: Fn(usize, &mut [T]) + Sync,
{
    if width == 0 {
        return;
    }
    buf.par_chunks_mut(width * ROWS_PER_TASK)
        .enumerate()
        .for_each(|(band, chunk)| {
            for (i, row) in chunk.chunks_mut(width).enumerate() {
                f(band * ROWS_PER_TASK + i, row);
            }
        });
}

/// Like [`for_each_row`] for two buffers of the same shape written together (`f(y, row_a, row_b)`).
pub fn for_each_row2<A, B, F>(a: &mut [A], b: &mut [B], width: usize, f: F)
where
    A: Send,
    B: Send,
    F: Fn(usize, &mut [A], &mut [B]) + Sync,
{
    for_each_row_pair(a, width, b, width, f)
}

/// Two buffers with the same number of rows but different row lengths (`wa`, `wb`).
pub fn for_each_row_pair<A, B, F>(a: &mut [A], wa: usize, b: &mut [B], wb: usize, f: F)
where
    A: Send,
    B: Send,
    F: Fn(usize, &mut [A], &mut [B]) + Sync,
{
    if wa == 0 || wb == 0 {
        return;
    }
    a.par_chunks_mut(wa * ROWS_PER_TASK)
        .zip(b.par_chunks_mut(wb * ROWS_PER_TASK))
        .enumerate()
        .for_each(|(band, (ca, cb))| {
            for (i, (ra, rb)) in ca.chunks_mut(wa).zip(cb.chunks_mut(wb)).enumerate() {
                f(band * ROWS_PER_TASK + i, ra, rb);
            }
        });
}

/// Runs `f` on a worker of the current rayon pool while every other worker of the pool stays
/// awake, taking the pool's work as it appears, until `f` returns; returns `f`'s value.
///
/// Why: on a virtual machine a worker that has gone to sleep (its CPU halted) took about 0.35 ms
/// to start on a new parallel region (measured on the 2-core development machine), and a kernel
/// made of many short parallel regions with sequential stretches between them paid that at
/// nearly every region, on both sides (the workers waking, then the caller). The waiting workers
/// poll with [`rayon::yield_now`] (they run any pending job of the pool, this call's or
/// another's) and `sched_yield` in between, so a runnable thread of another program still gets
/// the CPU. The result is whatever `f` computes: bit-identical kernels stay bit-identical.
pub fn run_hot<R: Send>(f: impl FnOnce() -> R + Send) -> R {
    use std::sync::atomic::{AtomicBool, Ordering};
    let others = rayon::current_num_threads().saturating_sub(1);
    if others == 0 || HOT.with(Cell::get) || !spin_wait_enabled() {
        return f(); // one thread, already inside a hot region on this thread, or opted out
    }
    /// Ends the waiting even when `f` panics (the scope then re-raises the panic).
    struct Done<'a>(&'a AtomicBool);
    impl Drop for Done<'_> {
        fn drop(&mut self) {
            self.0.store(true, Ordering::Release);
        }
    }
    let done = AtomicBool::new(false);
    rayon::scope(|s| {
        for _ in 0..others {
            s.spawn(|_| {
                while !done.load(Ordering::Acquire) {
                    if rayon::yield_now() != Some(rayon::Yield::Executed) {
                        std::thread::yield_now();
                    }
                }
            });
        }
        let _done = Done(&done);
        HOT.with(|h| h.set(true));
        let _hot = ResetHot;
        f()
    })
}

/// Environment variable that turns [`run_hot`]'s waiting workers off when set to `0` (for a
/// machine where an idle core is worth more than the latency, e.g. on battery).
pub const SPIN_WAIT_ENV: &str = "STEREOVISION_SPIN_WAIT";

/// Whether [`run_hot`] keeps the workers awake: [`SPIN_WAIT_ENV`] read once per process.
pub fn spin_wait_enabled() -> bool {
    static ON: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *ON.get_or_init(|| std::env::var(SPIN_WAIT_ENV).map_or(true, |v| v.trim() != "0"))
}

thread_local! {
    /// Set while this thread runs the body of a [`run_hot`] call.
    static HOT: Cell<bool> = const { Cell::new(false) };
}

/// Clears [`HOT`] when the body ends (also by a panic).
struct ResetHot;

impl Drop for ResetHot {
    fn drop(&mut self) {
        HOT.with(|h| h.set(false));
    }
}

#[cfg(test)]
mod tests {
    use rayon::prelude::*;

    fn work(n: u64) -> u64 {
        (0..n).into_par_iter().map(|v| v * v % 7).sum()
    }

    #[test]
    fn run_hot_returns_the_body_value_and_nests() {
        let want = work(10_000);
        assert_eq!(super::run_hot(|| work(10_000)), want);
        // A hot region inside another runs in place.
        assert_eq!(
            super::run_hot(|| super::run_hot(|| work(10_000)) + 1),
            want + 1
        );
    }

    #[test]
    fn run_hot_from_many_threads_at_once_completes() {
        // More concurrent callers than workers: a waiting worker runs the other calls' jobs
        // (and bodies); every call must still finish with its own value.
        let want = work(20_000);
        std::thread::scope(|s| {
            let hs: Vec<_> = (0..6)
                .map(|t| {
                    s.spawn(move || {
                        (0..20)
                            .map(|_| super::run_hot(|| work(20_000) + t))
                            .collect::<Vec<_>>()
                    })
                })
                .collect();
            for (t, h) in hs.into_iter().enumerate() {
                assert!(h.join().unwrap().iter().all(|&v| v == want + t as u64));
            }
        });
    }

    #[test]
    fn run_hot_propagates_a_panic_and_stays_usable() {
        let r = std::panic::catch_unwind(|| super::run_hot(|| -> u64 { panic!("boom") }));
        assert!(r.is_err());
        assert_eq!(super::run_hot(|| work(1000)), work(1000));
    }

    #[test]
    fn visits_every_row_once() {
        let w = 3;
        let mut buf = vec![0usize; w * 37];
        super::for_each_row(&mut buf, w, |y, row| {
            row.iter_mut().for_each(|v| *v += y + 1)
        });
        for (y, row) in buf.chunks(w).enumerate() {
            assert!(row.iter().all(|&v| v == y + 1));
        }
        let mut a = vec![0usize; w * 37];
        let mut b = vec![0usize; w * 37];
        super::for_each_row2(&mut a, &mut b, w, |y, ra, rb| {
            ra.iter_mut().for_each(|v| *v = y);
            rb.iter_mut().for_each(|v| *v = 2 * y);
        });
        assert!(a
            .chunks(w)
            .enumerate()
            .all(|(y, r)| r.iter().all(|&v| v == y)));
        assert!(b
            .chunks(w)
            .enumerate()
            .all(|(y, r)| r.iter().all(|&v| v == 2 * y)));
    }

    #[test]
    fn rows_of_different_widths_and_empty_rows() {
        // Two buffers of 37 rows, 2 and 5 wide: row y of each, whatever the band split.
        let (wa, wb, h) = (2, 5, 37);
        let mut a = vec![usize::MAX; wa * h];
        let mut b = vec![usize::MAX; wb * h];
        super::for_each_row_pair(&mut a, wa, &mut b, wb, |y, ra, rb| {
            assert_eq!((ra.len(), rb.len()), (wa, wb));
            ra.iter_mut().for_each(|v| *v = y);
            rb.iter_mut().for_each(|v| *v = 10 * y);
        });
        assert!(a
            .chunks(wa)
            .enumerate()
            .all(|(y, r)| r.iter().all(|&v| v == y)));
        assert!(b
            .chunks(wb)
            .enumerate()
            .all(|(y, r)| r.iter().all(|&v| v == 10 * y)));
        // A zero width on either side is no rows: no call (and no zero-sized chunks).
        let mut none: Vec<usize> = Vec::new();
        super::for_each_row(&mut none, 0, |_, _| panic!("called"));
        super::for_each_row_pair(&mut a, wa, &mut none, 0, |_, _, _| panic!("called"));
        super::for_each_row_pair(&mut none, 0, &mut b, wb, |_, _, _| panic!("called"));
    }

    #[test]
    fn run_hot_marks_its_body_and_clears_the_mark() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        pool.install(|| {
            let hot = || super::HOT.with(std::cell::Cell::get);
            assert!(!hot());
            // Set in the body (so a nested call runs in place), cleared after it, also after a panic.
            // (Unless STEREOVISION_SPIN_WAIT=0 turned the waiting, and so the mark, off.)
            assert_eq!(super::run_hot(hot), super::spin_wait_enabled());
            assert!(!hot());
            let r = std::panic::catch_unwind(|| super::run_hot(|| panic!("boom")));
            assert!(r.is_err());
            assert!(!hot());
        });
    }
}
