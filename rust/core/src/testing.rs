//! Helpers shared by the unit tests.

/// Xorshift64 (13, 7, 17): a deterministic stream of `u64`s from a non-zero `seed`, for test
/// images and maps that must be the same on every run and platform.
pub(crate) fn xorshift(mut s: u64) -> impl FnMut() -> u64 {
    move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        s
    }
}
