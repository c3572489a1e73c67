"""Plain Python reference of the LZF decoder (``rust/core/src/lzf.rs``, liblzf's
``lzf_decompress``: PCL's ``binary_compressed`` PCD data), and an LZF compressor for the tests.

``lzf_decompress`` was ``read_pcd``'s own decoder before the Rust one: the same bytes out, and a
``ValueError`` for every stream the Rust decoder refuses.
"""

from __future__ import annotations


def lzf_decompress(data: bytes, size: int) -> bytes:
    """``data`` decompressed into ``size`` bytes; a damaged stream is a ValueError."""
    out = bytearray()
    i, n = 0, len(data)
    damaged = "corrupt LZF data"
    try:
        while i < n:
            ctrl = data[i]
            i += 1
            if ctrl < 32:  # a literal run of ctrl + 1 bytes
                run = data[i : i + ctrl + 1]
                if len(run) != ctrl + 1:
                    raise ValueError(damaged)
                out += run
                i += ctrl + 1
                continue
            length = ctrl >> 5  # a back reference: length + 2 bytes from back there
            if length == 7:
                length += data[i]
                i += 1
            start = len(out) - ((ctrl & 0x1F) << 8) - data[i] - 1
            i += 1
            length += 2
            if start < 0:
                raise ValueError(damaged)
            chunk = out[start : start + length]
            if len(chunk) < length:  # overlapping its own output: the bytes repeat
                chunk = (chunk * (length // len(chunk) + 1))[:length]
            out += chunk
            if len(out) > size:
                raise ValueError(damaged)
    except IndexError:  # a back reference cut short
        raise ValueError(damaged) from None
    if len(out) != size:
        raise ValueError(damaged)
    return bytes(out)


def lzf_compress(data: bytes) -> bytes:
    """LZF of ``data`` as liblzf's ``lzf_compress`` writes it (greedy, the last position of each
    3 bytes remembered): literal runs of 1-32 bytes (control 0-31), back references of 3-264
    bytes up to 8192 back, overlapping ones included."""
    out, last = bytearray(), {}
    i, lit, n = 0, 0, len(data)

    def literals(end: int) -> None:
        for s in range(lit, end, 32):
            run = data[s : min(s + 32, end)]
            out.append(len(run) - 1)
            out.extend(run)

    while i + 2 < n:
        key = data[i : i + 3]
        ref = last.get(key)
        last[key] = i
        if ref is None or i - ref > 8192:
            i += 1
            continue
        k = 3
        while i + k < n and k < 264 and data[ref + k] == data[i + k]:
            k += 1
        literals(i)
        back, m = i - ref - 1, k - 2
        out += bytes([7 << 5 | back >> 8, m - 7]) if m >= 7 else bytes([m << 5 | back >> 8])
        out.append(back & 0xFF)
        i += k
        lit = i
    literals(n)
    return bytes(out)
