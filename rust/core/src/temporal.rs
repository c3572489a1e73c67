//! A still rig's frames averaged over time: the per-pixel passes of
//! `stereovision.temporal.TemporalFilter` (the motion test between them stays in Python, on
//! OpenCV's blur).
//!
//! Frames are `u8`, row-major `(H, W, C)` with `C` 1 (grey), 3 (BGR) or 4 (BGRA); the running
//! mean is `f32` of the same shape and the per-pixel frame count `u8` of shape `(H, W)`.
//! NumPy reference: `tests/reference/temporal_ref.py` (the same `f32` operations in the same
//! order, so the two agree bit for bit).
//!
//! One thread: the stream runs the filter in its grab thread while the matcher keeps both
//! cores' rayon workers busy, where parallel blocks would wait behind the matcher's (measured
//! in the stream at 640x480: 32 ms a pair on the shared pool against 9.6 ms alone).

use crate::alloc::try_zeroed;
use crate::error::{CoreError, Result};

/// Grey weights of the channels (B, G, R; BT.601, as OpenCV's `BGR2GRAY`); alpha counts 0.
const GREY_BGR: [f32; 3] = [0.114, 0.587, 0.299];

fn weights(channels: usize) -> Result<[f32; 4]> {
    match channels {
        1 => Ok([1.0, 0.0, 0.0, 0.0]),
        3 | 4 => Ok([GREY_BGR[0], GREY_BGR[1], GREY_BGR[2], 0.0]),
        _ => Err(CoreError::param(
            "channels",
            format!("expected 1, 3 or 4 channels, got {channels}"),
        )),
    }
}

fn check(frame: &[u8], mean: &[f32], pixels: usize, channels: usize) -> Result<()> {
    if pixels == 0 {
        return Err(CoreError::EmptyImage {
            width: 0,
            height: 0,
        });
    }
    for (name, len) in [("frame", frame.len()), ("mean", mean.len())] {
        if len != pixels * channels {
            return Err(CoreError::param(
                name,
                format!(
                    "expected {} values ({pixels} pixels x {channels} channels), got {len}",
                    pixels * channels
                ),
            ));
        }
    }
    Ok(())
}

/// Grey value of `frame - mean` per pixel: `sum_c w_c (frame_c - mean_c)`, channels in order.
pub fn grey_difference(
    frame: &[u8],
    mean: &[f32],
    pixels: usize,
    channels: usize,
) -> Result<Vec<f32>> {
    let w = weights(channels)?;
    check(frame, mean, pixels, channels)?;
    // Checked: a failed `vec!` aborted the process.
    let mut out = try_zeroed::<f32>(pixels, "the temporal filter's grey difference")?;
    const ROW: usize = 4096;
    out.chunks_mut(ROW).enumerate().for_each(|(block, chunk)| {
        let p0 = block * ROW;
        let len = chunk.len();
        let fr = frame[p0 * channels..(p0 + len) * channels].chunks_exact(channels);
        let me = mean[p0 * channels..(p0 + len) * channels].chunks_exact(channels);
        for ((o, f), m) in chunk.iter_mut().zip(fr).zip(me) {
            let mut acc = 0f32;
            for ((&f, &m), &w) in f.iter().zip(m).zip(&w[..channels.min(3)]) {
                acc += (f32::from(f) - m) * w;
            }
            *o = acc;
        }
    });
    Ok(out)
}

/// One more frame into the running mean, in place: `mean` and `count` are updated, and the
/// mean rounded half up to `u8` (what the matchers get) is returned, `(H, W, C)`.
///
/// A pixel whose grey difference `|diff|` is at most `ks * sqrt(1 + 1/n)` (`n` its count; `ks`
/// is `k` noise sigmas) keeps averaging: `n' = min(n + 1, max_frames)`, `mean' = mean +
/// (frame - mean) / n'`. Any other pixel starts again from the frame (`n' = 1`). In place: the
/// stream calls it on every pair, and fresh arrays cost their page faults each time.
pub fn running_mean(
    frame: &[u8],
    mean: &mut [f32],
    count: &mut [u8],
    diff: &[f32],
    channels: usize,
    ks: f32,
    max_frames: u8,
) -> Result<Vec<u8>> {
    weights(channels)?;
    let pixels = count.len();
    check(frame, mean, pixels, channels)?;
    if diff.len() != pixels {
        return Err(CoreError::param(
            "diff",
            format!("expected {pixels} values, got {}", diff.len()),
        ));
    }
    if !(ks.is_finite() && ks >= 0.0) {
        return Err(CoreError::param(
            "ks",
            format!("expected a finite number >= 0, got {ks}"),
        ));
    }
    if max_frames == 0 {
        return Err(CoreError::param("max_frames", "expected at least 1, got 0"));
    }
    // Tables by count (a count of 0 never occurs in a filter's state; it is read as 1).
    let limit: Vec<f32> = (0..=255u32)
        .map(|n| ks * (1.0 + 1.0 / n.max(1) as f32).sqrt())
        .collect();
    let weight: Vec<f32> = (0..=255u32).map(|n| 1.0 / n.max(1) as f32).collect();
    let mut out = try_zeroed::<u8>(mean.len(), "the temporal filter's mean image")?;
    let ch = channels;
    let pixels = count
        .iter_mut()
        .zip(diff)
        .zip(frame.chunks_exact(ch))
        .zip(mean.chunks_exact_mut(ch).zip(out.chunks_exact_mut(ch)));
    for (((n, &d), f), (m, o)) in pixels {
        let n1 = if d.abs() <= limit[usize::from(*n)] {
            n.saturating_add(1).min(max_frames)
        } else {
            1
        };
        *n = n1;
        let w = weight[usize::from(n1)];
        for ((&f, m), o) in f.iter().zip(m.iter_mut()).zip(o.iter_mut()) {
            let v = *m + (f32::from(f) - *m) * w;
            *m = v;
            // Half up: the mean of u8 values is in [0, 255], so truncation is floor (and `as`
            // saturates), without a libm call per value.
            *o = (v + 0.5) as u8;
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn still_pixels_average_and_changed_ones_restart() {
        // Two BGR pixels: the first within the limit, the second far off.
        let mut mean = vec![100.0, 100.0, 100.0, 10.0, 10.0, 10.0];
        let frame = vec![104u8, 104, 104, 200, 200, 200];
        let mut count = vec![3u8, 3];
        let diff = grey_difference(&frame, &mean, 2, 3).unwrap();
        assert!((diff[0] - 4.0).abs() < 1e-5 && (diff[1] - 190.0).abs() < 1e-3);
        let out = running_mean(&frame, &mut mean, &mut count, &diff, 3, 5.0, 8).unwrap();
        assert_eq!(count, vec![4, 1]);
        assert_eq!(mean, vec![101.0, 101.0, 101.0, 200.0, 200.0, 200.0]);
        assert_eq!(out, vec![101, 101, 101, 200, 200, 200]);
        // At the cap the count stays and the weight is 1 / max_frames.
        let (mut mean, mut count) = (vec![100.0f32; 3], vec![8u8]);
        let out = running_mean(&frame[..3], &mut mean, &mut count, &diff[..1], 3, 5.0, 8).unwrap();
        assert_eq!(count, vec![8]);
        assert_eq!(mean[0], 100.5);
        assert_eq!(out[0], 101); // half up
    }

    #[test]
    fn bad_shapes_and_parameters_are_named() {
        let e = grey_difference(&[0; 4], &[0.0; 4], 2, 2).unwrap_err();
        assert!(e.to_string().contains("1, 3 or 4 channels"));
        let e = grey_difference(&[0; 5], &[0.0; 6], 2, 3).unwrap_err();
        assert!(e.to_string().contains("`frame`"));
        let (mut m, mut n) = ([0.0f32; 2], [1u8, 1]);
        let e = running_mean(&[0; 2], &mut m, &mut n, &[0.0], 1, 1.0, 8).unwrap_err();
        assert!(e.to_string().contains("`diff`"));
        let e = running_mean(&[0; 2], &mut m, &mut n, &[0.0; 2], 1, f32::NAN, 8).unwrap_err();
        assert!(e.to_string().contains("`ks`"));
        let e = running_mean(&[0; 2], &mut m, &mut n, &[0.0; 2], 1, 1.0, 0).unwrap_err();
        assert!(e.to_string().contains("`max_frames`"));
        assert!(grey_difference(&[], &[], 0, 1).is_err());
    }

    #[test]
    fn grey_difference_weights_b_g_r_and_spans_blocks() {
        // BT.601 in B, G, R order (OpenCV's BGR2GRAY); alpha counts 0; grey frames count 1.
        let d = grey_difference(&[100, 0, 0, 0, 100, 0, 0, 0, 100], &[0.0; 9], 3, 3).unwrap();
        for (v, want) in d.iter().zip([11.4, 58.7, 29.9]) {
            assert!((v - want).abs() < 1e-4, "{v} vs {want}");
        }
        let d = grey_difference(&[0, 0, 0, 200], &[0.0, 0.0, 0.0, 0.0], 1, 4).unwrap();
        assert_eq!(d, vec![0.0]);
        assert_eq!(grey_difference(&[7], &[2.5], 1, 1).unwrap(), vec![4.5]);
        // Past the first 4096-pixel block every pixel still reads its own frame and mean.
        let n = 5000;
        let frame: Vec<u8> = (0..n).map(|i| (i % 251) as u8).collect();
        let mean: Vec<f32> = (0..n).map(|i| (i % 7) as f32).collect();
        let d = grey_difference(&frame, &mean, n, 1).unwrap();
        assert!((0..n).all(|i| d[i] == frame[i] as f32 - mean[i]));
        // ... in BGR too (grey pixels: the weights sum to 1).
        let frame3: Vec<u8> = frame.iter().flat_map(|&v| [v; 3]).collect();
        let mean3: Vec<f32> = mean.iter().flat_map(|&v| [v; 3]).collect();
        let d = grey_difference(&frame3, &mean3, n, 3).unwrap();
        assert!((0..n).all(|i| (d[i] - (frame[i] as f32 - mean[i])).abs() < 1e-3));
    }

    #[test]
    fn the_limit_is_the_old_count_s_and_inclusive() {
        // n = 1: limit ks sqrt(2) = 4.24 at ks 3 (n = 2's would be 3.67): a difference of 4
        // keeps averaging.
        let (mut mean, mut count) = (vec![10.0f32], vec![1u8]);
        running_mean(&[14], &mut mean, &mut count, &[4.0], 1, 3.0, 8).unwrap();
        assert_eq!((count[0], mean[0]), (2, 12.0));
        // A difference exactly at the limit keeps averaging too.
        let lim = 2.0f32 * (1.0f32 + 1.0 / 3.0).sqrt();
        let (mut mean, mut count) = (vec![10.0f32], vec![3u8]);
        running_mean(&[14], &mut mean, &mut count, &[lim], 1, 2.0, 8).unwrap();
        assert_eq!((count[0], mean[0]), (4, 11.0));
        // ks 0 is allowed: only an exact match keeps averaging.
        let (mut mean, mut count) = (vec![10.0f32, 10.0], vec![2u8, 2]);
        running_mean(&[10, 11], &mut mean, &mut count, &[0.0, 1.0], 1, 0.0, 8).unwrap();
        assert_eq!(count, vec![3, 1]);
        assert_eq!(mean, vec![10.0, 11.0]);
    }

    #[test]
    fn a_zero_count_averages_with_count_1_s_limit_and_restarts_at_1() {
        // Count 0 (never in a filter's state) reads count 1's limit: a difference at it keeps
        // averaging (n' = 1), a larger one restarts, also at n' = 1.
        let (mut mean, mut count) = (vec![10.0f32, 10.0], vec![0u8, 0]);
        let lim1 = 3.0f32 * 2f32.sqrt();
        running_mean(&[14, 50], &mut mean, &mut count, &[lim1, 40.0], 1, 3.0, 8).unwrap();
        assert_eq!(count, vec![1, 1]);
        assert_eq!(mean, vec![14.0, 50.0]);
    }

    #[test]
    fn a_negative_difference_restarts_and_ks_must_be_finite() {
        // The limit is on |diff|: a frame far below the mean restarts as one far above does.
        let (mut mean, mut count) = (vec![100.0f32, 100.0], vec![2u8, 2]);
        running_mean(&[60, 140], &mut mean, &mut count, &[-40.0, 40.0], 1, 3.0, 8).unwrap();
        assert_eq!((count, mean), (vec![1, 1], vec![60.0, 140.0]));
        let (mut m, mut n) = ([0.0f32; 2], [1u8, 1]);
        for ks in [f32::INFINITY, -1.0] {
            let e = running_mean(&[0; 2], &mut m, &mut n, &[0.0; 2], 1, ks, 8).unwrap_err();
            assert!(e.to_string().contains("`ks`"), "{ks}: {e}");
        }
    }

    #[test]
    fn the_output_is_the_f32_sum_plus_one_half_truncated() {
        // mean 1 - 2**-24 averaged with a 0 (weight 1/2) is 0.5 - 2**-25; adding 0.5 in f32
        // rounds to 1.0, so the output is 1 (as the NumPy reference's floor(mean + 0.5)), not
        // the 0 of rounding the mean itself.
        let m0 = 1.0f32 - f32::EPSILON / 2.0;
        let (mut mean, mut count) = (vec![m0], vec![1u8]);
        let out = running_mean(&[0], &mut mean, &mut count, &[0.0], 1, 3.0, 8).unwrap();
        assert_eq!(mean[0], 0.5 - f32::EPSILON / 4.0);
        assert_eq!((count[0], out[0]), (2, 1));
    }
}
