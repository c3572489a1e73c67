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

#[cfg(test)]
mod tests {
    #[test]
    fn visits_every_row_once() {
        let w = 3;
        let mut buf = vec![0usize; w * 37];
        super::for_each_row(&mut buf, w, |y, row| row.iter_mut().for_each(|v| *v += y + 1));
        for (y, row) in buf.chunks(w).enumerate() {
            assert!(row.iter().all(|&v| v == y + 1));
        }
    }
}
