//! The reference hole fill of evaluation.md, used by the evaluation and by the fused dense map
//! (NumPy reference: `tests/reference/row_fill_ref.py`, bit-identical), and the colour side rule
//! the dense map runs before it ([`side_fill`]).
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

/// The colour side rule, run before [`row_fill`] (NumPy reference:
/// `tests/reference/row_fill_ref.py`, bit-identical): a hole run between a nearer valid value on
/// its left and a farther one on its right takes, pixel by pixel, the left value where the
/// pixel's colour is closer to the left neighbour's than to the right neighbour's by more than
/// `tau`, and the right value otherwise. The row rule's background preference is right for the
/// runs an occlusion leaves (in the left view the occluded strip lies left of the nearer
/// surface, so its left neighbour is the farther one), and those runs are left to it, as are
/// the runs that touch the row's ends. A run with a nearer left side is no occlusion: what is
/// missing there (a patch no matcher was sure of, a foreground edge the dense map dropped) is
/// as likely to belong to either side, and the colour tells which.
///
/// `lab` is row-major `(H, W, 3)` colour (the caller's: CIE Lab of the blurred left image); the
/// distance is Euclidean. Rows run in parallel and independently, so the result does not depend
/// on the thread count.
///
/// # Panics
/// If `lab.len() != 3 * disp.len()`.
pub fn side_fill(disp: &mut [f32], lab: &[f32], w: usize, tau: f32) {
    assert_eq!(
        lab.len(),
        3 * disp.len(),
        "lab must hold 3 values per pixel"
    );
    if w == 0 {
        return;
    }
    disp.par_chunks_mut(w)
        .zip(lab.par_chunks(3 * w))
        .for_each(|(row, lab)| side_row(row, lab, tau));
}

/// Euclidean distance of two colours (the reference sums the squares in the same order).
#[inline]
fn colour_distance(a: &[f32], b: &[f32]) -> f32 {
    let (x, y, z) = (a[0] - b[0], a[1] - b[1], a[2] - b[2]);
    (x * x + y * y + z * z).sqrt()
}

/// One row of [`side_fill`].
fn side_row(row: &mut [f32], lab: &[f32], tau: f32) {
    let w = row.len();
    let mut x = 0;
    while x < w {
        if row[x].is_finite() {
            x += 1;
            continue;
        }
        let a = x;
        while x < w && !row[x].is_finite() {
            x += 1;
        }
        if a == 0 || x == w {
            continue; // a run at an end of the row: the row rule's
        }
        let (vl, vr) = (row[a - 1], row[x]);
        if vl <= vr {
            continue; // the occlusion pattern (or equal sides): the row rule's
        }
        let (cl, cr) = (&lab[3 * (a - 1)..3 * a], &lab[3 * x..3 * x + 3]);
        for (p, v) in row[a..x].iter_mut().enumerate() {
            let c = &lab[3 * (a + p)..3 * (a + p) + 3];
            *v = if colour_distance(c, cl) + tau < colour_distance(c, cr) {
                vl
            } else {
                vr
            };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_side_rule_follows_the_colour_where_the_left_is_nearer() {
        let nan = f32::NAN;
        // Row 0: nearer left (5) than right (2); pixels 2-3 have the left colour, 4 the right's.
        // Row 1: farther left (1) than right (4): the occlusion pattern, left to the row rule.
        // Row 2: a run at the row's start: left to the row rule.
        let mut d = vec![
            5.0, 5.0, nan, nan, nan, 2.0, //
            1.0, nan, nan, nan, nan, 4.0, //
            nan, nan, 3.0, nan, nan, 1.0,
        ];
        let colours: [f32; 18] = [
            10.0, 10.0, 10.0, 11.0, 50.0, 50.0, //
            0.0, 0.0, 0.0, 0.0, 0.0, 0.0, //
            0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
        ];
        let lab: Vec<f32> = colours.iter().flat_map(|&c| [c, 0.0, 0.0]).collect();
        side_fill(&mut d, &lab, 6, 5.0);
        assert_eq!(&d[..6], &[5.0, 5.0, 5.0, 5.0, 2.0, 2.0]);
        assert!(d[7..11].iter().all(|v| v.is_nan()));
        assert!(d[12].is_nan() && d[13].is_nan());
        // Pixels 15-16 (between 3 and 1, all colours equal): not closer to the left by tau.
        assert_eq!(&d[15..17], &[1.0, 1.0]);
    }

    #[test]
    fn maps_of_width_zero_are_left_alone() {
        // An empty map of width 0 (no chunking by 0, which would panic).
        let mut d: Vec<f32> = Vec::new();
        row_fill(&mut d, 0);
        side_fill(&mut d, &[], 0, 1.0);
        assert!(d.is_empty());
    }

    #[test]
    #[should_panic(expected = "lab must hold 3 values per pixel")]
    fn the_side_rule_refuses_colours_of_another_length() {
        // One colour short: a silent zip would leave the last pixel's run unfilled.
        let mut d = vec![5.0, f32::NAN, 2.0];
        side_fill(&mut d, &[0.0; 6], 3, 1.0);
    }

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

    /// Hand-computed rows (tau 2, colours along the first channel unless noted): the left and
    /// right neighbours' own colours are the references (not the run's end pixels), a tie
    /// `d_l + tau == d_r` goes right, the distance is Euclidean over all three channels,
    /// equal sides and a run reaching the row's end are left alone, an infinite value is a hole.
    #[test]
    fn the_side_rule_on_hand_computed_rows() {
        let (n, inf) = (f32::NAN, f32::INFINITY);
        // (disparities, Lab colours, expected) per row.
        type Row = ([f32; 5], [[f32; 3]; 5], [f32; 5]);
        let rows: [Row; 7] = [
            // d to 0 / 20: 4/16 left; 10/10 and 16/4 right (a reference at pixel 1: 10 left).
            (
                [6.0, n, n, n, 1.0],
                [
                    [0.0; 3],
                    [4.0, 0.0, 0.0],
                    [10.0, 0.0, 0.0],
                    [16.0, 0.0, 0.0],
                    [20.0, 0.0, 0.0],
                ],
                [6.0, 6.0, 1.0, 1.0, 1.0],
            ),
            // 8/12 left (a reference at pixel 3: 8/8, right).
            (
                [6.0, n, n, n, 1.0],
                [
                    [0.0; 3],
                    [4.0, 0.0, 0.0],
                    [8.0, 0.0, 0.0],
                    [16.0, 0.0, 0.0],
                    [20.0, 0.0, 0.0],
                ],
                [6.0, 6.0, 6.0, 1.0, 1.0],
            ),
            // 9 + 2 == 11: a tie goes right.
            (
                [6.0, n, 1.0, 1.0, 1.0],
                [
                    [0.0; 3],
                    [9.0, 0.0, 0.0],
                    [20.0, 0.0, 0.0],
                    [0.0; 3],
                    [0.0; 3],
                ],
                [6.0, 1.0, 1.0, 1.0, 1.0],
            ),
            // Three channels: 3 + 2 == |(0, -4, 3)| = 5, a tie again.
            (
                [6.0, n, 1.0, 1.0, 1.0],
                [
                    [0.0; 3],
                    [0.0, 0.0, 3.0],
                    [0.0, 4.0, 0.0],
                    [0.0; 3],
                    [0.0; 3],
                ],
                [6.0, 1.0, 1.0, 1.0, 1.0],
            ),
            (
                [3.0, n, 3.0, 1.0, 1.0],
                [[0.0; 3]; 5],
                [3.0, n, 3.0, 1.0, 1.0],
            ),
            ([1.0, 1.0, 5.0, n, n], [[0.0; 3]; 5], [1.0, 1.0, 5.0, n, n]),
            (
                [5.0, inf, 2.0, 2.0, 2.0],
                [
                    [0.0; 3],
                    [0.0; 3],
                    [20.0, 0.0, 0.0],
                    [20.0, 0.0, 0.0],
                    [20.0, 0.0, 0.0],
                ],
                [5.0, 5.0, 2.0, 2.0, 2.0],
            ),
        ];
        for (i, (d, lab, want)) in rows.iter().enumerate() {
            let mut got = d.to_vec();
            let lab: Vec<f32> = lab.iter().flatten().copied().collect();
            side_fill(&mut got, &lab, 5, 2.0);
            let same = got
                .iter()
                .zip(want)
                .all(|(g, w)| g == w || (g.is_nan() && w.is_nan()));
            assert!(same, "row {i}: {got:?}, want {want:?}");
        }
    }
}
