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
    let mut out = vec![0f32; pixels];
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

/// What [`running_mean`] returns.
#[derive(Debug, Clone, PartialEq)]
pub struct Averaged {
    /// New running mean, `(H, W, C)`.
    pub mean: Vec<f32>,
    /// New frame counts, `(H, W)`.
    pub count: Vec<u8>,
    /// The mean rounded half up, `(H, W, C)`.
    pub out: Vec<u8>,
}

/// The running mean after one more frame, with the new per-pixel counts and the mean rounded to
/// `u8` (what the matchers get).
///
/// A pixel whose grey difference `|diff|` is at most `ks * sqrt(1 + 1/n)` (`n` its count; `ks`
/// is `k` noise sigmas) keeps averaging: `n' = min(n + 1, max_frames)`, `mean' = mean +
/// (frame - mean) / n'`. Any other pixel starts again from the frame (`n' = 1`).
#[allow(clippy::too_many_arguments)]
pub fn running_mean(
    frame: &[u8],
    mean: &[f32],
    count: &[u8],
    diff: &[f32],
    channels: usize,
    ks: f32,
    max_frames: u8,
) -> Result<Averaged> {
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
    let mut new_mean = vec![0f32; mean.len()];
    let mut new_count = vec![0u8; pixels];
    let mut out = vec![0u8; mean.len()];
    const ROW: usize = 2048;
    let ch = channels;
    new_count
        .chunks_mut(ROW)
        .zip(new_mean.chunks_mut(ROW * ch))
        .zip(out.chunks_mut(ROW * ch))
        .enumerate()
        .for_each(|(block, ((cnt, mn), o))| {
            let p0 = block * ROW;
            let len = cnt.len();
            let fr = &frame[p0 * ch..(p0 + len) * ch];
            let me = &mean[p0 * ch..(p0 + len) * ch];
            let (co, di) = (&count[p0..p0 + len], &diff[p0..p0 + len]);
            let pixels = cnt
                .iter_mut()
                .zip(co.iter().zip(di))
                .zip(fr.chunks_exact(ch).zip(me.chunks_exact(ch)))
                .zip(mn.chunks_exact_mut(ch).zip(o.chunks_exact_mut(ch)));
            for (((n_out, (&n, &d)), (f, m)), (mn, o)) in pixels {
                let n1 = if d.abs() <= limit[usize::from(n)] {
                    n.saturating_add(1).min(max_frames)
                } else {
                    1
                };
                *n_out = n1;
                let w = weight[usize::from(n1)];
                for (((&f, &m), mn), o) in f.iter().zip(m).zip(mn.iter_mut()).zip(o.iter_mut()) {
                    let v = m + (f32::from(f) - m) * w;
                    *mn = v;
                    // Half up: the mean of u8 values is in [0, 255], so truncation is floor
                    // (and `as` saturates), without a libm call per value.
                    *o = (v + 0.5) as u8;
                }
            }
        });
    Ok(Averaged {
        mean: new_mean,
        count: new_count,
        out,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn still_pixels_average_and_changed_ones_restart() {
        // Two BGR pixels: the first within the limit, the second far off.
        let mean = vec![100.0, 100.0, 100.0, 10.0, 10.0, 10.0];
        let frame = vec![104u8, 104, 104, 200, 200, 200];
        let count = vec![3u8, 3];
        let diff = grey_difference(&frame, &mean, 2, 3).unwrap();
        assert!((diff[0] - 4.0).abs() < 1e-5 && (diff[1] - 190.0).abs() < 1e-3);
        let a = running_mean(&frame, &mean, &count, &diff, 3, 5.0, 8).unwrap();
        assert_eq!(a.count, vec![4, 1]);
        assert_eq!(&a.mean[..3], &[101.0, 101.0, 101.0]);
        assert_eq!(&a.mean[3..], &[200.0, 200.0, 200.0]);
        assert_eq!(a.out, vec![101, 101, 101, 200, 200, 200]);
        // At the cap the count stays and the weight is 1 / max_frames.
        let a = running_mean(&frame[..3], &mean[..3], &[8], &diff[..1], 3, 5.0, 8).unwrap();
        assert_eq!(a.count, vec![8]);
        assert_eq!(a.mean[0], 100.5);
        assert_eq!(a.out[0], 101); // half up
    }

    #[test]
    fn bad_shapes_and_parameters_are_named() {
        let e = grey_difference(&[0; 4], &[0.0; 4], 2, 2).unwrap_err();
        assert!(e.to_string().contains("1, 3 or 4 channels"));
        let e = grey_difference(&[0; 5], &[0.0; 6], 2, 3).unwrap_err();
        assert!(e.to_string().contains("`frame`"));
        let e = running_mean(&[0; 2], &[0.0; 2], &[1, 1], &[0.0], 1, 1.0, 8).unwrap_err();
        assert!(e.to_string().contains("`diff`"));
        let e = running_mean(&[0; 2], &[0.0; 2], &[1, 1], &[0.0; 2], 1, f32::NAN, 8).unwrap_err();
        assert!(e.to_string().contains("`ks`"));
        let e = running_mean(&[0; 2], &[0.0; 2], &[1, 1], &[0.0; 2], 1, 1.0, 0).unwrap_err();
        assert!(e.to_string().contains("`max_frames`"));
        assert!(grey_difference(&[], &[], 0, 1).is_err());
    }
}
