//! LZF decompression (liblzf's `lzf_decompress`): PCL's `binary_compressed` PCD data.
//!
//! The stream is a sequence of chunks, each led by a control byte `ctrl`:
//! * `ctrl < 32`: a literal run, the next `ctrl + 1` bytes copied as they are;
//! * else a back reference: `len = ctrl >> 5` (7 means: plus the next byte), then the offset's
//!   low byte; `len + 2` bytes are copied from `((ctrl & 31) << 8) + low + 1` bytes back in the
//!   output. A reference may overlap its own output (offset < length): the bytes are copied one
//!   by one, so they repeat, as liblzf does.
//!
//! The input is untrusted (a file): every damaged or cut stream is a [`CoreError::CorruptData`],
//! never a panic, and nothing is allocated beyond the `out_len` bytes the caller expects (and
//! not even those when the input is too short to decompress to them).

use crate::alloc::try_reserve_len;
use crate::error::{CoreError, Result};

/// The most output one byte of LZF input can give: a back reference of 3 bytes (control,
/// length, offset) copies at most `7 + 255 + 2 = 264` bytes.
pub const MAX_EXPANSION: usize = 264 / 3;

fn corrupt(reason: String) -> CoreError {
    CoreError::CorruptData {
        format: "LZF",
        reason,
    }
}

/// The `out_len` bytes `input` decompresses to, or [`CoreError::CorruptData`] when it does not
/// decompress to exactly that many (a reference before the start, output past `out_len`, the
/// input cut inside a chunk, or less output than `out_len`).
///
/// An `out_len` more than [`MAX_EXPANSION`] times the input's length is refused before any
/// allocation (a header's size is untrusted); one that cannot be allocated is
/// [`CoreError::OutOfMemory`].
pub fn lzf_decompress(input: &[u8], out_len: usize) -> Result<Vec<u8>> {
    check_expansion(input.len(), out_len)?;
    let mut out = Vec::new();
    try_reserve_len(&mut out, out_len, "the decompressed LZF data")?;
    out.resize(out_len, 0);
    lzf_decompress_into(input, &mut out)?;
    Ok(out)
}

/// Refuses an `out_len` that `n` input bytes cannot decompress to (see [`MAX_EXPANSION`]).
pub fn check_expansion(n: usize, out_len: usize) -> Result<()> {
    if out_len > n.saturating_mul(MAX_EXPANSION) {
        return Err(corrupt(format!(
            "{n} bytes cannot decompress to {out_len} bytes (at most {MAX_EXPANSION} times \
             their size)"
        )));
    }
    Ok(())
}

/// [`lzf_decompress`] into `out`, which the stream must fill exactly.
pub fn lzf_decompress_into(input: &[u8], out: &mut [u8]) -> Result<()> {
    let (n, out_len) = (input.len(), out.len());
    let (mut ip, mut op) = (0usize, 0usize);
    while ip < n {
        let at = ip; // the chunk's control byte, for the messages
        let ctrl = usize::from(input[ip]);
        ip += 1;
        if ctrl < 32 {
            let run = ctrl + 1;
            if run > n - ip {
                return Err(corrupt(format!(
                    "the data end inside a literal run of {run} bytes (control byte at {at})"
                )));
            }
            if run > out_len - op {
                return Err(past_end(out_len, at));
            }
            out[op..op + run].copy_from_slice(&input[ip..ip + run]);
            ip += run;
            op += run;
            continue;
        }
        let mut len = ctrl >> 5;
        if len == 7 {
            let Some(&more) = input.get(ip) else {
                return Err(cut_reference(at));
            };
            len += usize::from(more);
            ip += 1;
        }
        len += 2;
        let Some(&low) = input.get(ip) else {
            return Err(cut_reference(at));
        };
        ip += 1;
        let back = ((ctrl & 31) << 8) + usize::from(low) + 1;
        if back > op {
            return Err(corrupt(format!(
                "a back reference (control byte at {at}) reaches {back} bytes back, {op} bytes \
                 after the start"
            )));
        }
        if len > out_len - op {
            return Err(past_end(out_len, at));
        }
        let from = op - back;
        if back >= len {
            out.copy_within(from..from + len, op);
        } else {
            // Overlapping its own output: byte by byte, so that the last `back` bytes repeat.
            for k in 0..len {
                out[op + k] = out[from + k];
            }
        }
        op += len;
    }
    if op != out_len {
        return Err(corrupt(format!(
            "the data decompress to {op} bytes, expected {out_len}"
        )));
    }
    Ok(())
}

fn past_end(out_len: usize, at: usize) -> CoreError {
    corrupt(format!(
        "the data decompress to more than {out_len} bytes (control byte at {at})"
    ))
}

fn cut_reference(at: usize) -> CoreError {
    corrupt(format!(
        "the data end inside a back reference (control byte at {at})"
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reason(r: Result<Vec<u8>>) -> String {
        match r {
            Err(CoreError::CorruptData { format, reason }) => {
                assert_eq!(format, "LZF");
                reason
            }
            other => panic!("expected CorruptData, got {other:?}"),
        }
    }

    #[test]
    fn lzf_literal_runs() {
        assert_eq!(lzf_decompress(b"\x02abc", 3).unwrap(), b"abc");
        // the longest run: control 31, 32 bytes; then another run
        let mut s = vec![31u8];
        s.extend(0..32u8);
        s.extend([0u8, 99]);
        let want: Vec<u8> = (0..32u8).chain([99]).collect();
        assert_eq!(lzf_decompress(&s, 33).unwrap(), want);
        assert_eq!(lzf_decompress(b"", 0).unwrap(), b"");
    }

    #[test]
    fn lzf_back_references() {
        // "abcd", then 3 bytes from 4 back (len 1 + 2), then 4 bytes from 2 back (overlapping)
        let s = b"\x03abcd\x20\x03\x40\x01";
        assert_eq!(lzf_decompress(s, 11).unwrap(), b"abcdabcbcbc");
        // a literal 'A' and 12 more from one byte back (liblzf's overlapping copy)
        assert_eq!(
            lzf_decompress(b"\x00A\xe0\x03\x00", 13).unwrap(),
            [b'A'; 13]
        );
        // the longest reference: 7 + 255 + 2 = 264 bytes; offset's high bits from the control
        let mut s = vec![31u8];
        s.extend(0..32u8);
        let mut s2 = s.clone();
        s2.extend([0xe0, 255, 31]); // 264 bytes from 32 back: the run repeats
        let out = lzf_decompress(&s2, 32 + 264).unwrap();
        assert!(out.iter().enumerate().all(|(i, &b)| b as usize == i % 32));
        // offset with high bits: 256 + 0 + 1 = 257 back
        let mut long = Vec::new();
        for i in 0..9u8 {
            long.push(31);
            long.extend((0..32u8).map(|k| k.wrapping_mul(7).wrapping_add(i)));
        }
        let plain = lzf_decompress(&long, 288).unwrap();
        long.extend([0x21, 0x00]); // 3 bytes from 257 back
        let out = lzf_decompress(&long, 291).unwrap();
        assert_eq!(out[288..], plain[31..34]);
    }

    #[test]
    fn lzf_reference_before_the_start() {
        let r = reason(lzf_decompress(b"\x20\x05", 3));
        assert_eq!(
            r,
            "a back reference (control byte at 0) reaches 6 bytes back, 0 bytes after the start"
        );
        let r = reason(lzf_decompress(b"\x01ab\x21\x00", 5));
        assert!(r.contains("reaches 257 bytes back, 2 bytes after"), "{r}");
    }

    #[test]
    fn lzf_output_past_out_len() {
        let r = reason(lzf_decompress(b"\x02abc", 2));
        assert_eq!(
            r,
            "the data decompress to more than 2 bytes (control byte at 0)"
        );
        let r = reason(lzf_decompress(b"\x00A\xe0\x03\x00", 12));
        assert_eq!(
            r,
            "the data decompress to more than 12 bytes (control byte at 2)"
        );
    }

    #[test]
    fn lzf_input_cut() {
        let r = reason(lzf_decompress(b"\x05abc", 6));
        assert_eq!(
            r,
            "the data end inside a literal run of 6 bytes (control byte at 0)"
        );
        for cut in [&b"\x00A\xe0"[..], b"\x00A\xe0\x03", b"\x00A\x20"] {
            let r = reason(lzf_decompress(cut, 13));
            assert_eq!(
                r,
                "the data end inside a back reference (control byte at 2)"
            );
        }
    }

    #[test]
    fn lzf_output_short() {
        let r = reason(lzf_decompress(b"\x00A", 3));
        assert_eq!(r, "the data decompress to 1 bytes, expected 3");
        let r = reason(lzf_decompress(b"", 1));
        assert!(r.starts_with("0 bytes cannot decompress to 1 bytes"), "{r}");
    }

    #[test]
    fn lzf_untrusted_out_len_allocates_nothing() {
        // 2 bytes of input claiming 4 GiB of output: refused before any allocation
        let r = reason(lzf_decompress(b"\x00A", u32::MAX as usize));
        assert_eq!(
            r,
            "2 bytes cannot decompress to 4294967295 bytes (at most 88 times their size)"
        );
        assert!(lzf_decompress(b"\x00A", usize::MAX).is_err());
        // the bound is reachable: 3 bytes of reference give 264 bytes
        let mut s = vec![0u8, 7, 0xe0, 255, 0];
        assert_eq!(lzf_decompress(&s, 265).unwrap(), [7u8; 265]);
        s.extend([0xe0, 255, 0]);
        assert_eq!(lzf_decompress(&s, 529).unwrap().len(), 529);
    }

    #[test]
    fn lzf_random_streams_never_panic() {
        // every byte string is either decoded or refused, in time bounded by its length
        let mut next = crate::testing::xorshift(0x1f2e_3d4c);
        for _ in 0..2000 {
            let n = (next() % 40) as usize;
            let s: Vec<u8> = (0..n).map(|_| next() as u8).collect();
            for out_len in [0, 1, 7, 64, 500] {
                let _ = lzf_decompress(&s, out_len);
            }
        }
    }
}
