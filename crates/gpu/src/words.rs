//! How integers travel in the kernel's buffers, which are all arrays of f32 words.

/// "No such index": no texture, no material override, no record.
pub const NONE: u32 = u32::MAX;

/// An integer carried in an f32 slot (its bits, not its value).
#[inline]
pub fn bits(value: u32) -> f32 {
    f32::from_bits(value)
}
