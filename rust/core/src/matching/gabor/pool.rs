//! A small process-wide pool of `f32` buffers, so that repeated calls (video frames) and the
//! many same-sized planes inside one call reuse memory instead of mapping fresh pages.
//!
//! Measured on cloth3 (626x555, 2 cores): fresh multi-megabyte `Vec`s are `mmap`ed and
//! unmapped by glibc on every use; the page faults cost ~20 % of the CPU time and serialise
//! the two threads on the kernel's memory-map lock (-36 % wall time when memory is retained).
//! Buffers come back zero-filled, so results are identical with or without the pool.

use std::ops::{Deref, DerefMut};
use std::sync::Mutex;

use crate::alloc::try_zeroed;
use crate::error::Result;

/// Names a plane in an out-of-memory error.
pub const WHAT: &str = "a plane of the Gabor matcher";

/// Buffers smaller than this (in f32) are not worth pooling (malloc serves them from its heap).
const MIN_POOLED: usize = 16 * 1024;
/// Upper bound of the memory the pool keeps between uses (bytes): enough for the working set of
/// a 0.4 Mpx pair, bounded so an idle process does not hold more than this.
pub const POOL_MAX_BYTES: usize = 256 << 20;

static POOL: Mutex<Vec<Vec<f32>>> = Mutex::new(Vec::new());

/// The pool, or None in a forked process whose copy of it is held by a thread it does not have
/// ([`crate::alloc::cache_lock`]): the planes are then allocated and freed without it.
fn lock() -> Option<std::sync::MutexGuard<'static, Vec<Vec<f32>>>> {
    crate::alloc::cache_lock(&POOL)
}

/// A zero-initialised `f32` buffer that returns its memory to the pool when dropped.
///
/// The vector keeps its full (initialised) length while pooled; `n` is the logical length. So a
/// reused buffer needs no fill for [`Buf::scratch`] (refilling the tail of a shorter vector was
/// a visible share of the run time).
#[derive(Debug, Default)]
pub struct Buf {
    v: Vec<f32>,
    n: usize,
}

impl Buf {
    /// `n` zeros, reusing the smallest pooled buffer that is large enough.
    /// A failed allocation is [`crate::CoreError::OutOfMemory`], not an abort.
    pub fn zeroed(n: usize) -> Result<Buf> {
        let mut b = Buf::scratch(n)?;
        b.iter_mut().for_each(|v| *v = 0.0);
        Ok(b)
    }

    /// `n` values with unspecified (but initialised) contents, for outputs the caller overwrites
    /// entirely: skips the zero fill of a reused buffer.
    pub fn scratch(n: usize) -> Result<Buf> {
        if n >= MIN_POOLED {
            let taken = lock().and_then(|mut p| {
                let best = p
                    .iter()
                    .enumerate()
                    .filter(|(_, b)| b.len() >= n)
                    .min_by_key(|(_, b)| b.len())
                    .map(|(i, _)| i);
                best.map(|i| p.swap_remove(i))
            });
            if let Some(v) = taken {
                return Ok(Buf { v, n });
            }
        }
        Ok(Buf {
            v: try_zeroed(n, WHAT)?,
            n,
        })
    }

    /// A pooled copy of `src`.
    pub fn from_slice(src: &[f32]) -> Result<Buf> {
        let mut b = Buf::scratch(src.len())?;
        b.copy_from_slice(src);
        Ok(b)
    }

    /// Takes the buffer out of the pool's custody (it will be freed normally).
    pub fn into_vec(mut self) -> Vec<f32> {
        let mut v = std::mem::take(&mut self.v);
        v.truncate(self.n);
        v
    }
}

impl Deref for Buf {
    type Target = [f32];
    fn deref(&self) -> &[f32] {
        &self.v[..self.n]
    }
}

impl DerefMut for Buf {
    fn deref_mut(&mut self) -> &mut [f32] {
        &mut self.v[..self.n]
    }
}

impl Drop for Buf {
    fn drop(&mut self) {
        let v = std::mem::take(&mut self.v);
        if v.len() < MIN_POOLED {
            return;
        }
        let Some(mut p) = lock() else {
            return; // freed without the pool
        };
        p.push(v);
        // Keep the total under the cap, dropping the oldest buffers first.
        let mut total: usize = p.iter().map(|b| b.capacity() * 4).sum();
        while total > POOL_MAX_BYTES && !p.is_empty() {
            let old = p.remove(0);
            total -= old.capacity() * 4;
        }
    }
}

/// Bytes the pool holds between uses.
pub fn held_bytes() -> usize {
    lock().map_or(0, |p| p.iter().map(|b| b.capacity() * 4).sum())
}

/// Frees every pooled buffer; returns the bytes they held.
pub fn release() -> usize {
    let all = lock()
        .map(|mut p| std::mem::take(&mut *p))
        .unwrap_or_default();
    all.iter().map(|b| b.capacity() * 4).sum()
}

#[cfg(test)]
mod tests {
    use super::Buf;

    #[cfg(target_os = "linux")]
    #[test]
    fn a_child_forked_while_the_pool_is_held_gets_its_planes() {
        // The pool's lock, held by a thread of the parent at fork (a Gabor kernel running in
        // another Python thread), stayed held in the child: its first plane waited forever.
        assert!(crate::alloc::tests::ends_in_a_child_forked_while_held(
            &super::POOL,
            || {
                let mut b = Buf::zeroed(super::MIN_POOLED + 3).unwrap();
                assert!(b.iter().all(|&v| v == 0.0));
                b[0] = 1.0;
                drop(b); // freed without the pool
                assert_eq!(super::held_bytes(), 0);
                assert_eq!(super::release(), 0);
            }
        ));
    }

    #[test]
    fn reused_buffers_are_zeroed() {
        let n = 100_000;
        {
            let mut a = Buf::zeroed(n).unwrap();
            a.iter_mut().for_each(|v| *v = 3.0);
        }
        let b = Buf::zeroed(n - 10).unwrap();
        assert_eq!(b.len(), n - 10);
        assert!(b.iter().all(|&v| v == 0.0));
        drop(b);
        assert_eq!(Buf::scratch(n + 5).unwrap().len(), n + 5);
        assert_eq!(
            Buf::from_slice(&[1.0, 2.0]).unwrap().into_vec(),
            vec![1.0, 2.0]
        );
    }

    /// A fresh (not pooled) buffer of exactly `n` values.
    fn fresh(n: usize) -> Buf {
        Buf {
            v: crate::alloc::try_zeroed(n, "test").unwrap(),
            n,
        }
    }

    /// The pool is shared with every test of the binary (the Gabor ones take and return planes
    /// concurrently), so a check of what it hands back is retried: another caller may take the
    /// buffer in between. A wrong pool fails every try.
    fn eventually(mut check: impl FnMut() -> bool) -> bool {
        (0..10).any(|_| check())
    }

    #[test]
    fn best_fit_reuse_from_min_pooled_up_and_the_byte_cap() {
        use super::{held_bytes, release, MIN_POOLED, POOL_MAX_BYTES};
        // A returned buffer of exactly the size, from MIN_POOLED up, comes back unfilled.
        for n in [MIN_POOLED, 3_000_000] {
            let reused = eventually(|| {
                let mut a = fresh(n);
                a[0] = 7.0;
                let p = a.as_ptr();
                drop(a);
                let b = Buf::scratch(n).unwrap();
                b.as_ptr() == p && b[0] == 7.0
            });
            assert!(reused, "{n}");
        }
        // The smallest that fits (not a larger one, nor the exact ones just returned), cut to
        // the asked length.
        let n = 4_000_000;
        let best = eventually(|| {
            let (mut a, mut b) = (fresh(n + 1000), fresh(n + 10));
            (a[0], b[0]) = (1.0, 2.0);
            drop(a);
            drop(b);
            Buf::scratch(n).unwrap()[0] == 2.0
        });
        assert!(best);
        drop(fresh(n + 10));
        assert_eq!(Buf::scratch(n).unwrap().into_vec().len(), n);
        // Over the cap the oldest goes, and only as many as needed; sizes are in bytes.
        let big = POOL_MAX_BYTES / 4 * 3 / 4;
        let capped = eventually(|| {
            release();
            let (mut a, mut b) = (fresh(big), fresh(big));
            // Marked: a freed block can come back from the system at the same address.
            (a[0], b[0]) = (1.0, 2.0);
            drop(a);
            drop(b);
            assert!(held_bytes() <= POOL_MAX_BYTES);
            let kept = held_bytes() >= 4 * big;
            let c = Buf::scratch(big).unwrap();
            let newest = c[0] == 2.0;
            drop(c);
            kept && newest && release() >= 4 * big
        });
        assert!(capped);
    }
}
