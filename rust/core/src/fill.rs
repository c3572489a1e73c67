//! The reference hole fill of evaluation.md, used by the evaluation and by the fused dense map
//! (NumPy reference: `tests/reference/row_fill_ref.py`, bit-identical).
//!
//! Along each row a hole (any non-finite value) takes the smaller, i.e. the background, of the
//! nearest valid disparity to its left and the nearest valid disparity to its right; with a
//! valid value on one side only it takes that one; a row with none stays NaN.

use rayon::prelude::*;

/// Fills the holes of a row-major `(H, W)` map in place (see the module docs). Rows run in
/// parallel; each is independent, so the result does not depend on the thread count.
pub fn row_fill(disp: &mut [f32], w: usize) {
    if w == 0 {
        return;
    }
    disp.par_chunks_mut(w)
        .for_each_init(|| vec![f32::NAN; w], |left, row| fill_row(row, left));
}

/// One row; `left` is scratch of the row's length.
pub(crate) fn fill_row(row: &mut [f32], left: &mut [f32]) {
    let mut last = f32::NAN;
    for (v, l) in row.iter().zip(left.iter_mut()) {
        if v.is_finite() {
            last = *v;
        }
        *l = last;
    }
    let mut next = f32::NAN;
    for (v, l) in row.iter_mut().zip(left.iter()).rev() {
        if v.is_finite() {
            next = *v;
        } else {
            // f32::min returns the other operand when one is NaN: one side only -> that side.
            *v = l.min(next);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fills_with_the_background_side() {
        let nan = f32::NAN;
        let mut d = vec![
            nan,
            3.0,
            nan,
            nan,
            1.0,
            nan,
            f32::INFINITY,
            2.0,
            nan,
            nan,
            nan,
            nan,
        ];
        row_fill(&mut d, 8);
        assert_eq!(&d[..8], &[3.0, 3.0, 1.0, 1.0, 1.0, 1.0, 1.0, 2.0]);
        assert!(d[8..].iter().all(|v| v.is_nan())); // a row with no valid value stays NaN
    }
}
