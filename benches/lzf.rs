//! Criterion bench of the LZF decoder (`stereovision_core::lzf`) on the `binary_compressed`
//! data of a 640x480 organised cloud as PCL writes it: the x, y, z and packed rgb values field
//! by field, a sloped surface of float32 points with 40 % holes (NaN) in blobs and a textured
//! colour, compressed here as liblzf's `lzf_compress` does (greedy, last position of each 3
//! bytes). Throughput is decompressed bytes per second.
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use stereovision_core::lzf::lzf_decompress;

const W: usize = 640;
const H: usize = 480;

/// The cloud's fields one after the other (x, y, z as f32, then rgb as u32), little-endian.
fn cloud_planes() -> Vec<u8> {
    let n = W * H;
    let (mut x, mut y, mut z, mut rgb) =
        (vec![0f32; n], vec![0f32; n], vec![0f32; n], vec![0u32; n]);
    let f = 640.0f32;
    for r in 0..H {
        for c in 0..W {
            let i = r * W + c;
            // holes in blobs of ~40 % of the pixels (textureless and occluded areas)
            let hole = ((c / 23) * 7 + (r / 17) * 3) % 5 < 2;
            let depth = 2.0 + 0.004 * r as f32 + 0.3 * ((c as f32) * 0.02).sin();
            // the disparity a matcher finds is quantised to 1/16 pixel
            let d = (f * 0.06 / depth * 16.0).round() / 16.0;
            let zz = if hole { f32::NAN } else { f * 0.06 / d };
            z[i] = zz;
            x[i] = (c as f32 - 320.0) * zz / f;
            y[i] = (r as f32 - 240.0) * zz / f;
            let t = ((c * 31 + r * 17) % 64) as u32;
            rgb[i] = 0xff00_0000 | (90 + t) << 16 | (120 + t / 2) << 8 | (60 + (r % 8) as u32);
        }
    }
    let mut out = Vec::with_capacity(n * 16);
    for plane in [&x, &y, &z] {
        plane.iter().for_each(|v| out.extend(v.to_le_bytes()));
    }
    rgb.iter().for_each(|v| out.extend(v.to_le_bytes()));
    out
}

/// LZF of `data` as liblzf's `lzf_compress` writes it (see the module docs).
fn lzf_compress(data: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    let mut last = vec![usize::MAX; 1 << 16];
    let (mut i, mut lit, n) = (0usize, 0usize, data.len());
    let literals = |out: &mut Vec<u8>, from: usize, to: usize| {
        for run in data[from..to].chunks(32) {
            out.push(run.len() as u8 - 1);
            out.extend_from_slice(run);
        }
    };
    while i + 2 < n {
        let key = u32::from_le_bytes([data[i], data[i + 1], data[i + 2], 0]);
        let slot = (key.wrapping_mul(2_654_435_761) >> 16) as usize;
        let r = last[slot];
        last[slot] = i;
        if r == usize::MAX || i - r > 8192 || data[r..r + 3] != data[i..i + 3] {
            i += 1;
            continue;
        }
        let mut k = 3;
        while i + k < n && k < 264 && data[r + k] == data[i + k] {
            k += 1;
        }
        literals(&mut out, lit, i);
        let (back, m) = (i - r - 1, k - 2);
        if m >= 7 {
            out.extend([(7 << 5 | back >> 8) as u8, (m - 7) as u8]);
        } else {
            out.push((m << 5 | back >> 8) as u8);
        }
        out.push(back as u8);
        i += k;
        lit = i;
    }
    literals(&mut out, lit, n);
    out
}

fn bench_lzf(c: &mut Criterion) {
    let plain = cloud_planes();
    let packed = lzf_compress(&plain);
    assert_eq!(lzf_decompress(&packed, plain.len()).unwrap(), plain);
    eprintln!(
        "lzf: {W}x{H} cloud, {} bytes -> {} compressed ({:.2}x)",
        plain.len(),
        packed.len(),
        plain.len() as f64 / packed.len() as f64
    );
    let mut g = c.benchmark_group("lzf");
    g.sample_size(20).measurement_time(Duration::from_secs(3));
    g.throughput(Throughput::Bytes(plain.len() as u64));
    g.bench_function(format!("decompress_{W}x{H}_cloud"), |b| {
        b.iter(|| lzf_decompress(&packed, plain.len()).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench_lzf);
criterion_main!(benches);
