//! What the CPU-specific sweeps (`kernels::avx512`, `kernels::avx2`)
//! share with the portable sweep that calls them ([`crate::kernels::sweep`]): the
//! signature of their loop, the touching flags as bits, and the pairs they leave out as
//! lane masks. Uses the boundary and the grain's vector type only.

use crate::physics::boundary::Boundary;
use crate::physics::dim::Vec2;

/// The loop of a CPU-specific sweep of [`crate::kernels::sweep::sort_pairs`] over `range`
/// (a multiple of its width), as the sweep describes it, on raw pointers: the list, the grains' (x, y)
/// values, the boundary, `reach`, the touching flags, the pairs to skip (ascending, within
/// the range), the three outputs and their counts. The caller makes sure that the
/// pointers are good for the pairs of the range and their grains, and that every write
/// (at most a width of entries from a count, which is at most the index of the first
/// pair of the width) falls within the range.
pub(crate) type WideLoop = unsafe fn(*const [u32; 2], *const f64, &Boundary, *const f64, *const bool, &[u32], std::ops::Range<usize>, *mut u32, *mut Vec2, *mut u32, &mut usize, &mut usize);

/// Four touching flags (bytes 0 or 1) as the low four bits (bit l: flag l): one load and
/// one multiply, the shifted copies of the bytes landing on bits 24..27 without carries.
#[inline(always)]
pub(crate) fn four_flags(flags: [u8; 4]) -> u32 {
    u32::from_le_bytes(flags).wrapping_mul(0x0102_0408) >> 24 & 0xf
}

/// The pairs a CPU-specific sweep leaves out (the `skip` of
/// [`crate::kernels::sweep::sort_pairs`], ascending), as lane masks of its blocks of
/// pairs, block after block. (Builds without one do not
/// use it.)
#[allow(dead_code)]
pub(crate) struct LeftOut<'a> {
    rest: std::slice::Iter<'a, u32>,
    /// The next pair to leave out (`usize::MAX` when none is left).
    next: usize,
}

#[allow(dead_code)]
impl<'a> LeftOut<'a> {
    pub(crate) fn new(skip: &'a [u32]) -> Self {
        let mut rest = skip.iter();
        let next = rest.next().map_or(usize::MAX, |&k| k as usize);
        LeftOut { rest, next }
    }
    /// The lanes of the block of `width` pairs from `k` to leave out (bit l: pair k + l):
    /// usually none, at the cost of one compare. Blocks are asked for in ascending order.
    #[inline(always)]
    pub(crate) fn lanes(&mut self, k: usize, width: usize) -> u32 {
        let mut left_out = 0;
        while self.next < k + width {
            left_out |= 1 << (self.next - k);
            self.next = self.rest.next().map_or(usize::MAX, |&k| k as usize);
        }
        left_out
    }
}
