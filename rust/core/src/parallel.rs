//! Row-band parallelism helpers (rayon).
//!
//! Kernels split an image into bands of rows; each band is processed independently so results are
//! bit-identical whatever the thread count (no reductions across bands in floating point).

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

#[cfg(test)]
mod tests {
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
}
