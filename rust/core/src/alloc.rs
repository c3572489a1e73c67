//! A global allocator that keeps recently freed large blocks for reuse.
//!
//! Every kernel allocates image-sized buffers (grey images, maps, per-band statistics) and frees
//! them at the end of the call. glibc serves such blocks from `mmap` or trims them off the heap
//! when they are freed, so the next call on the next frame faults the same pages in again: on
//! cloth3 that was 14-22 % of the default `depth_map` and 7-16 % of the Hopfield channel (measured
//! by raising glibc's mmap and trim thresholds for the whole process, which we do not want to
//! impose on the host program). [`BlockCache`] keeps up to [`SLOTS`] freed blocks of at least
//! [`MIN_CACHED`] bytes, [`MAX_CACHED_BYTES`] in all, and hands one back for a request of exactly
//! its size and alignment (a frame of the same size asks for the same sizes); the oldest is
//! released when the cache is full. Everything else goes straight to the system allocator. Only
//! the extension's own (Rust) allocations use it: `rust/py` installs it as `#[global_allocator]`.
//! The Gabor channel keeps its planes in its own pool (`matching::gabor::pool`: best-fit reuse
//! without a zero fill, also under `cargo bench`); `stereovision.release_memory()` empties both.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::Mutex;

use crate::error::{CoreError, Result};

/// Smallest block kept (bytes): below glibc's default mmap threshold blocks are cheap to get.
pub const MIN_CACHED: usize = 128 * 1024;
/// Most bytes kept in all.
pub const MAX_CACHED_BYTES: usize = 128 << 20;
/// Most blocks kept.
pub const SLOTS: usize = 128;

/// A kept block: address, size and alignment of the layout it was allocated with.
#[derive(Clone, Copy)]
struct Block {
    ptr: usize,
    size: usize,
    align: usize,
}

/// An unused slot.
const EMPTY: Block = Block {
    ptr: 0,
    size: 0,
    align: 0,
};

/// The kept blocks, oldest first.
struct Kept {
    blocks: [Block; SLOTS],
    len: usize,
    bytes: usize,
}

/// The allocator (see the module docs). `const`-constructible, for a `static`.
pub struct BlockCache {
    kept: Mutex<Kept>,
}

impl BlockCache {
    /// An empty cache.
    pub const fn new() -> Self {
        BlockCache {
            kept: Mutex::new(Kept {
                blocks: [EMPTY; SLOTS],
                len: 0,
                bytes: 0,
            }),
        }
    }

    /// The cache, unless another thread holds it: then the caller goes to the system allocator
    /// instead of waiting. So a process forked while a thread held the lock (the child inherits
    /// it locked) bypasses the cache instead of deadlocking. Nothing inside the lock can panic;
    /// a poisoned lock would still hold consistent data.
    fn lock(&self) -> Option<std::sync::MutexGuard<'_, Kept>> {
        match self.kept.try_lock() {
            Ok(g) => Some(g),
            Err(std::sync::TryLockError::Poisoned(e)) => Some(e.into_inner()),
            Err(std::sync::TryLockError::WouldBlock) => None,
        }
    }

    /// The newest kept block of exactly this layout, removed from the cache.
    fn take(&self, l: Layout) -> Option<*mut u8> {
        let mut k = self.lock()?;
        let len = k.len;
        let i = (0..len)
            .rev()
            .find(|&i| k.blocks[i].size == l.size() && k.blocks[i].align == l.align())?;
        let b = k.blocks[i];
        k.blocks.copy_within(i + 1..len, i);
        k.len -= 1;
        k.bytes -= b.size;
        Some(b.ptr as *mut u8)
    }

    /// Keeps the block, releasing the oldest ones to make room; false if it does not fit at all.
    ///
    /// # Safety
    /// `ptr` must have been allocated by `System` with layout `l` and not be used afterwards.
    unsafe fn put(&self, ptr: *mut u8, l: Layout) -> bool {
        if l.size() > MAX_CACHED_BYTES {
            return false;
        }
        let mut release = [EMPTY; SLOTS];
        let mut n_release = 0;
        {
            let Some(mut k) = self.lock() else {
                return false;
            };
            while k.len == SLOTS || k.bytes + l.size() > MAX_CACHED_BYTES {
                let old = k.blocks[0];
                let len = k.len;
                k.blocks.copy_within(1..len, 0);
                k.len -= 1;
                k.bytes -= old.size;
                release[n_release] = old;
                n_release += 1;
            }
            let len = k.len;
            k.blocks[len] = Block {
                ptr: ptr as usize,
                size: l.size(),
                align: l.align(),
            };
            k.len += 1;
            k.bytes += l.size();
        }
        // Outside the lock: the system allocator may take its own.
        // SAFETY: kept blocks come from `System` with exactly their recorded layout.
        unsafe { release_all(&release[..n_release]) };
        true
    }

    /// Returns every kept block to the system (e.g. before a long idle period); returns the
    /// bytes released (0 if another thread held the cache).
    pub fn clear(&self) -> usize {
        let mut all = [EMPTY; SLOTS];
        let (n, bytes) = {
            let Some(mut k) = self.lock() else {
                return 0;
            };
            let n = k.len;
            all[..n].copy_from_slice(&k.blocks[..n]);
            let bytes = k.bytes;
            k.len = 0;
            k.bytes = 0;
            (n, bytes)
        };
        // SAFETY: as in `put`.
        unsafe { release_all(&all[..n]) };
        bytes
    }

    /// Number of blocks and bytes kept (for tests and diagnostics; (0, 0) if another thread
    /// held the cache).
    pub fn kept(&self) -> (usize, usize) {
        self.lock().map_or((0, 0), |k| (k.len, k.bytes))
    }
}

/// Frees blocks to the system allocator.
///
/// # Safety
/// Each block must come from `System` with exactly its recorded layout and be owned by nobody.
unsafe fn release_all(blocks: &[Block]) {
    for b in blocks {
        // SAFETY: by the caller's contract.
        unsafe {
            System.dealloc(
                b.ptr as *mut u8,
                Layout::from_size_align_unchecked(b.size, b.align),
            )
        };
    }
}

impl Default for BlockCache {
    fn default() -> Self {
        Self::new()
    }
}

// SAFETY: every block handed out is either fresh from `System` or a kept one that was allocated
// by `System` with exactly the requested size and alignment and freed by its previous owner;
// a block is in the cache or handed out, never both (the lock serialises take and put).
unsafe impl GlobalAlloc for BlockCache {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        if l.size() >= MIN_CACHED {
            if let Some(p) = self.take(l) {
                return p;
            }
        }
        // SAFETY: forwarded with the caller's (valid, non-zero-size) layout.
        unsafe { System.alloc(l) }
    }

    unsafe fn alloc_zeroed(&self, l: Layout) -> *mut u8 {
        if l.size() >= MIN_CACHED {
            if let Some(p) = self.take(l) {
                // SAFETY: the block holds l.size() writable bytes.
                unsafe { p.write_bytes(0, l.size()) };
                return p;
            }
        }
        // SAFETY: as in `alloc`.
        unsafe { System.alloc_zeroed(l) }
    }

    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        // SAFETY: `p` came from this allocator with layout `l`, hence from `System` with `l`.
        if l.size() >= MIN_CACHED && unsafe { self.put(p, l) } {
            return;
        }
        // SAFETY: as above.
        unsafe { System.dealloc(p, l) }
    }
}

/// The process that first locked a process-wide cache ([`cache_lock`]).
static CACHE_HOME: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);

/// The lock of a process-wide cache of buffers (the Gabor planes' pool, the census matcher's
/// kept volume and rows), or None in a forked process when it is held: the caller then works
/// without the cache (fresh buffers, the same results).
///
/// Why: `fork()` copies a lock held by another thread of the parent (a kernel running in a
/// Python thread while another forks: multiprocessing's "fork" start method) as held, and no
/// thread of the child ever releases it: a blocking `lock` waited forever on the child's first
/// kernel (seen on about 1 fork in 200 while the parent ran Gabor in a thread). The process
/// that first took such a lock keeps waiting for it as before; any other process (a forked
/// one) only tries it.
pub(crate) fn cache_lock<T>(m: &Mutex<T>) -> Option<std::sync::MutexGuard<'_, T>> {
    use std::sync::atomic::Ordering;
    let pid = std::process::id();
    let home = match CACHE_HOME.compare_exchange(0, pid, Ordering::AcqRel, Ordering::Acquire) {
        Ok(_) => pid,
        Err(p) => p,
    };
    // A poisoned lock still holds consistent data: the caches only move whole vectors.
    if home == pid {
        return Some(m.lock().unwrap_or_else(std::sync::PoisonError::into_inner));
    }
    match m.try_lock() {
        Ok(g) => Some(g),
        Err(std::sync::TryLockError::Poisoned(e)) => Some(e.into_inner()),
        Err(std::sync::TryLockError::WouldBlock) => None,
    }
}

/// `bytes` for a message: "6.00 GiB (6442450944 bytes)".
pub fn human_bytes(bytes: usize) -> String {
    let (v, unit) = if bytes >= 1 << 30 {
        (bytes as f64 / (1u64 << 30) as f64, "GiB")
    } else if bytes >= 1 << 20 {
        (bytes as f64 / (1u64 << 20) as f64, "MiB")
    } else {
        return format!("{bytes} bytes");
    };
    format!("{v:.2} {unit} ({bytes} bytes)")
}

/// Types whose all-zero bit pattern is the value zero (so a zeroed allocation holds zeros).
///
/// # Safety
/// Every bit pattern of zeros must be a valid value of the type.
pub unsafe trait ZeroBits: Copy {}
// SAFETY: plain integers and IEEE floats: all-zero bits are 0 / +0.0.
unsafe impl ZeroBits for u8 {}
// SAFETY: as above.
unsafe impl ZeroBits for u16 {}
// SAFETY: as above.
unsafe impl ZeroBits for u32 {}
// SAFETY: as above.
unsafe impl ZeroBits for u64 {}
// SAFETY: as above.
unsafe impl ZeroBits for i16 {}
// SAFETY: as above.
unsafe impl ZeroBits for i32 {}
// SAFETY: as above.
unsafe impl ZeroBits for f32 {}
// SAFETY: as above.
unsafe impl ZeroBits for f64 {}
// SAFETY: as above.
unsafe impl ZeroBits for usize {}
// SAFETY: a zero byte is `false`.
unsafe impl ZeroBits for bool {}

/// `vec![T::zero; n]` that returns [`CoreError::OutOfMemory`] instead of aborting the process
/// when the allocation fails. The same zeroed allocation as `vec!` (pages the system hands out
/// zeroed are not written).
pub fn try_zeroed<T: ZeroBits>(n: usize, what: &'static str) -> Result<Vec<T>> {
    let size = std::mem::size_of::<T>();
    if n == 0 || size == 0 {
        return Ok(Vec::new());
    }
    let layout = Layout::array::<T>(n).map_err(|_| CoreError::oom(n.saturating_mul(size), what))?;
    // SAFETY: `layout` has a non-zero size.
    let p = unsafe { std::alloc::alloc_zeroed(layout) }.cast::<T>();
    if p.is_null() {
        return Err(CoreError::oom(layout.size(), what));
    }
    // SAFETY: `p` comes from the global allocator with `Layout::array::<T>(n)`, the layout a
    // `Vec<T>` of capacity `n` has, and holds `n` zeroed (valid, by `ZeroBits`) values.
    Ok(unsafe { Vec::from_raw_parts(p, n, n) })
}

/// `vec![value; n]` that returns [`CoreError::OutOfMemory`] instead of aborting the process.
pub fn try_filled<T: Clone>(n: usize, value: T, what: &'static str) -> Result<Vec<T>> {
    let mut v = Vec::new();
    try_reserve_len(&mut v, n, what)?;
    v.resize(n, value);
    Ok(v)
}

/// Makes room in `v` for `n` values in all (not `n` more), or returns
/// [`CoreError::OutOfMemory`]; the values are not changed.
pub fn try_reserve_len<T>(v: &mut Vec<T>, n: usize, what: &'static str) -> Result<()> {
    let more = n.saturating_sub(v.len());
    v.try_reserve_exact(more)
        .map_err(|_| CoreError::oom(n.saturating_mul(std::mem::size_of::<T>()), what))
}

/// Room for `more` values after those in `v`, grown as `push` or `extend` would (amortised:
/// for a vector whose final length is not known in advance), or [`CoreError::OutOfMemory`]
/// (the smallest size that would hold them); the values are not changed.
pub fn try_grow<T>(v: &mut Vec<T>, more: usize, what: &'static str) -> Result<()> {
    v.try_reserve(more).map_err(|_| {
        let n = v.len().saturating_add(more);
        CoreError::oom(n.saturating_mul(std::mem::size_of::<T>()), what)
    })
}

/// `it.collect()` of an iterator of exactly `n` values into a vector allocated at once, or
/// [`CoreError::OutOfMemory`] (a `collect` aborts the process when it cannot allocate).
pub fn try_collect<T>(n: usize, it: impl Iterator<Item = T>, what: &'static str) -> Result<Vec<T>> {
    let mut v = Vec::new();
    try_reserve_len(&mut v, n, what)?;
    v.extend(it);
    debug_assert_eq!(v.len(), n, "try_collect: the iterator must yield n values");
    Ok(v)
}

/// `parts.concat()` (or a flattening `collect`) into a vector allocated at once, or
/// [`CoreError::OutOfMemory`] (those abort the process when they cannot allocate). The parts
/// are moved, not cloned.
pub fn try_concat<T>(parts: Vec<Vec<T>>, what: &'static str) -> Result<Vec<T>> {
    let n = parts.iter().map(Vec::len).fold(0, usize::saturating_add);
    let mut v = Vec::new();
    try_reserve_len(&mut v, n, what)?;
    for p in parts {
        v.extend(p);
    }
    Ok(v)
}

/// `it.collect::<Result<Vec<T>>>()` of a parallel iterator of known length into a vector
/// allocated at once, checked: [`CoreError::OutOfMemory`] (a `collect` aborts the process when
/// it cannot allocate). An item's error is returned instead of the vector (one of them, as
/// `collect` returns one); the other items are still computed.
pub fn try_par_collect<T, I>(it: I, what: &'static str) -> Result<Vec<T>>
where
    T: Send + Default,
    I: rayon::iter::IndexedParallelIterator<Item = Result<T>>,
{
    use rayon::iter::IndexedParallelIterator;
    let mut v = Vec::new();
    try_reserve_len(&mut v, it.len(), what)?;
    let failed = Mutex::new(None);
    it.map(|r| {
        r.unwrap_or_else(|e| {
            let mut f = failed.lock().unwrap_or_else(|p| p.into_inner());
            f.get_or_insert(e);
            T::default()
        })
    })
    .collect_into_vec(&mut v); // into the reserved room: no reallocation
    match failed.into_inner().unwrap_or_else(|p| p.into_inner()) {
        Some(e) => Err(e),
        None => Ok(v),
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    #[test]
    fn fallible_allocations_fail_with_the_size() {
        // Far more than any address space holds: an error naming the size, not an abort.
        let n = usize::MAX / 4;
        let e = try_zeroed::<u16>(n, "the test buffer").unwrap_err();
        assert_eq!(e, CoreError::oom(n * 2, "the test buffer"));
        assert!(e
            .to_string()
            .starts_with("out of memory: the test buffer needs "));
        let e = try_zeroed::<u64>(n, "x").unwrap_err();
        assert_eq!(e, CoreError::oom(usize::MAX, "x"));
        assert!(matches!(
            try_filled(1usize << 60, 1.0f32, "y"),
            Err(CoreError::OutOfMemory { what: "y", .. })
        ));
        let mut v = vec![1u8; 3];
        assert!(try_reserve_len(&mut v, usize::MAX, "z").is_err());
        assert_eq!(v, [1, 1, 1]);
        assert_eq!(
            try_grow(&mut v, usize::MAX / 2, "g"),
            Err(CoreError::oom(usize::MAX / 2 + 3, "g"))
        );
        try_grow(&mut v, 5, "g").unwrap();
        assert!(v.capacity() >= 8 && v == [1, 1, 1]);
        // Success: the same values as `vec!`.
        assert_eq!(try_zeroed::<f32>(5, "a").unwrap(), vec![0.0f32; 5]);
        assert_eq!(try_zeroed::<u8>(0, "a").unwrap(), Vec::<u8>::new());
        assert_eq!(try_filled(4, f32::NAN, "b").unwrap().len(), 4);
        assert_eq!(human_bytes(3 << 30), "3.00 GiB (3221225472 bytes)");
        assert_eq!(human_bytes(512), "512 bytes");
        assert!(matches!(
            try_collect(1usize << 61, std::iter::repeat(0u32), "c"),
            Err(CoreError::OutOfMemory { what: "c", .. })
        ));
        assert_eq!(try_collect(3, 1..4u8, "c").unwrap(), vec![1, 2, 3]);
        let parts = vec![vec![1u16, 2], Vec::new(), vec![3]];
        assert_eq!(try_concat(parts.clone(), "d").unwrap(), parts.concat());
        assert_eq!(
            try_concat(Vec::<Vec<u8>>::new(), "d").unwrap(),
            Vec::<u8>::new()
        );
        use rayon::prelude::*;
        let items = |n: usize| (0..n).into_par_iter().map(|i| Ok(vec![i; i % 3]));
        assert!(matches!(
            try_par_collect(items(1 << 60), "p"),
            Err(CoreError::OutOfMemory { what: "p", .. })
        ));
        let want: Vec<Vec<usize>> = (0..1000).map(|i| vec![i; i % 3]).collect();
        assert_eq!(try_par_collect(items(1000), "p").unwrap(), want);
        let failing = (0..1000usize).into_par_iter().map(|i| match i {
            700 => Err(CoreError::oom(7, "an item")),
            _ => Ok(vec![i]),
        });
        assert_eq!(
            try_par_collect(failing, "p"),
            Err(CoreError::oom(7, "an item"))
        );
    }

    /// Run by [`a_concat_too_large_to_allocate_is_an_error`] in a child process: four 8 MiB
    /// parts under an address-space limit of 16 MiB more than is mapped.
    #[cfg(target_os = "linux")]
    #[test]
    #[ignore = "a child of a_concat_too_large_to_allocate_is_an_error"]
    fn concat_under_a_memory_limit() {
        if std::env::var_os("SV_OOM_CHILD").is_none() {
            return;
        }
        let parts: Vec<Vec<u8>> = (0..4u8).map(|i| vec![i + 1; 8 << 20]).collect();
        crate::segment::tests::limit_address_space(crate::segment::tests::vm_size() + (16 << 20));
        match try_concat(parts, "the parts") {
            Ok(v) => println!("child: concatenated {}", v.len()),
            Err(e) => println!("child: error: {e}"),
        }
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn a_concat_too_large_to_allocate_is_an_error() {
        let stdout =
            crate::segment::tests::run_oom_child("alloc::tests::concat_under_a_memory_limit");
        let want = "child: error: out of memory: the parts needs 32.00 MiB (33554432 bytes)";
        assert!(stdout.contains(want), "{want} not in {stdout}");
    }

    #[test]
    fn reuses_exact_layouts_and_keeps_the_bounds() {
        let cache = BlockCache::new();
        let big = Layout::from_size_align(MIN_CACHED, 64).unwrap();
        let small = Layout::from_size_align(MIN_CACHED - 1, 64).unwrap();
        unsafe {
            let a = cache.alloc(big);
            assert!(!a.is_null() && (a as usize).is_multiple_of(64));
            a.write_bytes(7, big.size());
            cache.dealloc(a, big);
            assert_eq!(cache.kept(), (1, MIN_CACHED));
            // Same layout: the same block, zeroed on request.
            let b = cache.alloc_zeroed(big);
            assert_eq!(b, a);
            assert!(std::slice::from_raw_parts(b, big.size())
                .iter()
                .all(|&v| v == 0));
            assert_eq!(cache.kept(), (0, 0));
            // Another size or alignment: not this block.
            cache.dealloc(b, big);
            let other = Layout::from_size_align(MIN_CACHED + 8, 64).unwrap();
            let c = cache.alloc(other);
            assert_ne!(c, b);
            let d = cache.alloc(Layout::from_size_align(MIN_CACHED, 128).unwrap());
            assert_ne!(d, b);
            cache.dealloc(d, Layout::from_size_align(MIN_CACHED, 128).unwrap());
            cache.dealloc(c, other);
            assert_eq!(cache.kept().0, 3);
            // Small blocks are never kept.
            let s = cache.alloc(small);
            cache.dealloc(s, small);
            assert_eq!(cache.kept().0, 3);
            // The slot bound: the oldest go first; the byte bound likewise.
            let mut held = Vec::new();
            for _ in 0..SLOTS + 5 {
                held.push(System.alloc(big));
            }
            for p in held {
                cache.dealloc(p, big);
            }
            assert_eq!(cache.kept(), (SLOTS, SLOTS * MIN_CACHED));
            let huge = Layout::from_size_align(MAX_CACHED_BYTES / 2 + 1, 8).unwrap();
            let h = cache.alloc(huge);
            cache.dealloc(h, huge);
            let (n, bytes) = cache.kept();
            assert_eq!((n, bytes), (SLOTS, (SLOTS - 1) * MIN_CACHED + huge.size()));
            let h2 = cache.alloc(huge);
            let h3 = cache.alloc(huge);
            cache.dealloc(h2, huge);
            // Two of them do not fit in the byte bound: the older one and the blocks before it go.
            cache.dealloc(h3, huge);
            let (n, bytes) = cache.kept();
            assert!(bytes <= MAX_CACHED_BYTES && n <= SLOTS);
            assert_eq!(bytes, huge.size() + (n - 1) * MIN_CACHED);
            // Too large to keep at all.
            let over = Layout::from_size_align(MAX_CACHED_BYTES + 1, 8).unwrap();
            let o = cache.alloc(over);
            cache.dealloc(o, over);
            assert_eq!(cache.kept(), (n, bytes));
            // Everything back to the system.
            assert_eq!(cache.clear(), bytes);
            assert_eq!(cache.kept(), (0, 0));
        }
    }

    #[test]
    fn a_held_lock_bypasses_the_cache() {
        let cache = BlockCache::new();
        let l = Layout::from_size_align(MIN_CACHED, 8).unwrap();
        unsafe {
            let p = cache.alloc(l);
            let _held = cache.kept.lock().unwrap();
            // As in a child forked while another thread held the lock: no wait, no caching.
            assert!(!cache.put(p, l));
            assert!(cache.take(l).is_none());
            System.dealloc(p, l);
        }
    }

    #[test]
    fn works_as_a_shared_allocator_across_threads() {
        static CACHE: BlockCache = BlockCache::new();
        let l = Layout::from_size_align(MIN_CACHED * 2, 16).unwrap();
        std::thread::scope(|s| {
            for t in 0..4u8 {
                s.spawn(move || unsafe {
                    for i in 0..200u32 {
                        let p = CACHE.alloc(l);
                        p.write_bytes(t, l.size());
                        assert!(std::slice::from_raw_parts(p, l.size())
                            .iter()
                            .all(|&v| v == t));
                        if i % 3 == 0 {
                            let z = CACHE.alloc_zeroed(l);
                            assert!(std::slice::from_raw_parts(z, l.size())
                                .iter()
                                .all(|&v| v == 0));
                            CACHE.dealloc(z, l);
                        }
                        CACHE.dealloc(p, l);
                    }
                });
            }
        });
        let (n, bytes) = CACHE.kept();
        assert!(n <= SLOTS && bytes == n * l.size());
    }

    #[test]
    fn takes_the_newest_of_a_layout_and_keeps_the_rest() {
        let cache = BlockCache::new();
        let l1 = Layout::from_size_align(MIN_CACHED, 64).unwrap();
        let l2 = Layout::from_size_align(MIN_CACHED + 64, 64).unwrap();
        unsafe {
            let (a1, b, a2) = (System.alloc(l1), System.alloc(l2), System.alloc(l1));
            cache.dealloc(a1, l1);
            cache.dealloc(b, l2);
            cache.dealloc(a2, l1);
            assert_eq!(cache.kept(), (3, 3 * MIN_CACHED + 64));
            // Out of the middle: the blocks either side stay, each once.
            assert_eq!(cache.alloc(l2), b);
            assert_eq!(cache.kept(), (2, 2 * MIN_CACHED));
            // Newest first, by plain `alloc` too (a request of exactly MIN_CACHED is served).
            assert_eq!(cache.alloc(l1), a2);
            assert_eq!(cache.alloc(l1), a1);
            assert_eq!(cache.kept(), (0, 0));
            // A larger kept block does not serve a smaller request (it would be freed with the
            // smaller layout).
            cache.dealloc(b, l2);
            let c = cache.alloc(l1);
            assert_ne!(c, b);
            assert_eq!(cache.kept(), (1, MIN_CACHED + 64));
            cache.clear();
            for (p, l) in [(a1, l1), (c, l1), (a2, l1)] {
                System.dealloc(p, l);
            }
        }
    }

    #[test]
    fn releases_the_oldest_and_fills_the_bounds_exactly() {
        let cache = BlockCache::new();
        let l = Layout::from_size_align(MIN_CACHED, 8).unwrap();
        unsafe {
            let held: Vec<_> = (0..SLOTS + 1).map(|_| System.alloc(l)).collect();
            for &p in &held {
                cache.dealloc(p, l);
            }
            // The first one went back to the system; the others come out newest first.
            assert_eq!(cache.kept(), (SLOTS, SLOTS * MIN_CACHED));
            let back: Vec<_> = (0..SLOTS).map(|_| cache.alloc(l)).collect();
            let want: Vec<_> = held[1..].iter().rev().copied().collect();
            assert_eq!(back, want);
            for p in back {
                System.dealloc(p, l);
            }
            // Blocks that add up to exactly MAX_CACHED_BYTES are all kept, as is one block of
            // exactly that size (pages of a fresh block are not touched: cheap to allocate).
            let rest = Layout::from_size_align(MAX_CACHED_BYTES - MIN_CACHED, 8).unwrap();
            let (p, q) = (System.alloc(rest), System.alloc(l));
            cache.dealloc(p, rest);
            cache.dealloc(q, l);
            assert_eq!(cache.kept(), (2, MAX_CACHED_BYTES));
            let all = Layout::from_size_align(MAX_CACHED_BYTES, 8).unwrap();
            cache.dealloc(System.alloc(all), all);
            assert_eq!(cache.kept(), (1, MAX_CACHED_BYTES));
            assert_eq!(cache.clear(), MAX_CACHED_BYTES);
        }
    }

    #[test]
    fn human_bytes_units_and_reserve_to_a_total() {
        assert_eq!(human_bytes(1 << 30), "1.00 GiB (1073741824 bytes)");
        assert_eq!(human_bytes((1 << 30) - 1), "1024.00 MiB (1073741823 bytes)");
        assert_eq!(human_bytes(1 << 20), "1.00 MiB (1048576 bytes)");
        assert_eq!(human_bytes(3 << 19), "1.50 MiB (1572864 bytes)");
        assert_eq!(human_bytes((1 << 20) - 1), "1048575 bytes");
        // Room for 10 in all, not 10 more.
        let mut v = vec![1u8; 3];
        try_reserve_len(&mut v, 10, "v").unwrap();
        assert!(v.capacity() >= 10 && v.capacity() < 13, "{}", v.capacity());
        assert_eq!(v, [1, 1, 1]);
    }

    /// Runs `f` in a child forked while another thread of this process holds `m` (as a kernel
    /// running in another thread holds a cache's lock); true when the child ends normally
    /// within 20 s (an `alarm` kills a child that waits for the lock). `f` must start no
    /// thread and use no rayon pool: the child has only the forking thread.
    #[cfg(target_os = "linux")]
    pub(crate) fn ends_in_a_child_forked_while_held<T: Send>(
        m: &'static Mutex<T>,
        f: fn(),
    ) -> bool {
        extern "C" {
            fn fork() -> i32;
            fn waitpid(pid: i32, status: *mut i32, options: i32) -> i32;
            fn alarm(seconds: u32) -> u32;
            fn _exit(status: i32) -> !;
        }
        let (held_tx, held_rx) = std::sync::mpsc::channel();
        let (done_tx, done_rx) = std::sync::mpsc::channel::<()>();
        let holder = std::thread::spawn(move || {
            // Through cache_lock: this process is the cache's first, which waits for it.
            let guard = cache_lock(m);
            held_tx.send(guard.is_some()).unwrap();
            done_rx.recv().unwrap();
        });
        assert!(
            held_rx.recv().unwrap(),
            "the parent could not take the lock"
        );
        // SAFETY: the child calls only `alarm`, `f` (allocations: glibc's malloc is fork-safe)
        // and `_exit`.
        let pid = unsafe { fork() };
        assert!(pid >= 0, "fork failed");
        if pid == 0 {
            // SAFETY: plain libc calls in the child.
            unsafe { alarm(20) };
            let ok = std::panic::catch_unwind(f).is_ok();
            // SAFETY: ends the child without running the parent's exit handlers.
            unsafe { _exit(if ok { 0 } else { 1 }) };
        }
        let mut status = 0;
        // SAFETY: waits for our own child; `status` is a valid pointer.
        let waited = unsafe { waitpid(pid, &mut status, 0) };
        done_tx.send(()).unwrap();
        holder.join().unwrap();
        waited == pid && status == 0
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn a_cache_held_in_the_parent_at_fork_is_skipped_in_the_child() {
        // The first process takes the lock as a blocking `lock` does (a second thread waits
        // for it); a forked one whose copy is held goes without it instead of waiting forever.
        static M: Mutex<Vec<u8>> = Mutex::new(Vec::new());
        cache_lock(&M).unwrap().push(1);
        assert_eq!(*cache_lock(&M).unwrap(), [1]);
        assert!(ends_in_a_child_forked_while_held(&M, || {
            assert!(cache_lock(&M).is_none());
        }));
        // Once released, the parent has it again.
        assert_eq!(*cache_lock(&M).unwrap(), [1]);
    }
}
