//! Helpers of the crate's unit tests.

/// A xorshift64 generator of test inputs: the same sequence from the same (non-zero) seed.
pub(crate) fn xorshift(seed: u64) -> impl FnMut() -> u64 {
    let mut state = seed;
    move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    }
}
