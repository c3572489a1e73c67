//! Kernels in a process forked after they ran get a thread pool of their own.
//!
//! rayon's global pool lives in threads that `fork()` does not copy: a child forked after a
//! kernel ran (Python's `multiprocessing` with the "fork" start method, a preforking server)
//! waited forever on its first kernel. The first process to run a kernel keeps using the global
//! pool as before (no hand-over to a pool thread per call: on this VM waking one costs about
//! 0.35 ms); a process forked after that runs its kernels in a pool it makes on first use (sized
//! as rayon's default: `RAYON_NUM_THREADS`, else the logical CPUs), and so does a child of that
//! child. A pool is never freed: in a child its parent's pool has no threads to wait for.

use std::ptr::null_mut;
use std::sync::atomic::{AtomicPtr, AtomicU32, Ordering};

use pyo3::Python;

/// The process that first ran a kernel: rayon's global pool belongs to it.
static FIRST: AtomicU32 = AtomicU32::new(0);

/// A pool and the (forked) process that made it.
struct Owned {
    pid: u32,
    pool: rayon::ThreadPool,
}

static FORKED: AtomicPtr<Owned> = AtomicPtr::new(null_mut());

/// The pool of this forked process, or None if its threads cannot be started.
fn forked_pool(pid: u32) -> Option<&'static rayon::ThreadPool> {
    loop {
        let cur = FORKED.load(Ordering::Acquire);
        // SAFETY: a published pool is never freed (see the module docs).
        if let Some(owned) = unsafe { cur.as_ref() } {
            if owned.pid == pid {
                return Some(&owned.pool);
            }
        }
        let pool = rayon::ThreadPoolBuilder::new()
            .thread_name(|i| format!("stereovision-{i}"))
            .build()
            .ok()?;
        let fresh = Box::into_raw(Box::new(Owned { pid, pool }));
        match FORKED.compare_exchange(cur, fresh, Ordering::AcqRel, Ordering::Acquire) {
            // SAFETY: `fresh` is ours and now published; it is never freed.
            Ok(_) => return Some(&unsafe { &*fresh }.pool),
            // Another thread published one first: ours was never used, drop it and take that.
            // SAFETY: `fresh` came from `Box::into_raw` above and was never published.
            Err(_) => drop(unsafe { Box::from_raw(fresh) }),
        }
    }
}

/// Runs `f` with the GIL released: in rayon's global pool in the process that first ran a
/// kernel, in a pool of its own in a process forked after that.
pub fn detach<T: Send>(py: Python<'_>, f: impl FnOnce() -> T + Send) -> T {
    py.detach(|| {
        let pid = std::process::id();
        let first = match FIRST.compare_exchange(0, pid, Ordering::AcqRel, Ordering::Acquire) {
            Ok(_) => pid,
            Err(p) => p,
        };
        if first == pid {
            return f();
        }
        match forked_pool(pid) {
            Some(pool) => pool.install(f),
            None => f(), // no thread could be started: the kernel may wait, as before
        }
    })
}
