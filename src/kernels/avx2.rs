//! The contact sweep on CPUs with AVX2 but without AVX-512: four pairs per step, the
//! touching ones packed with a table instead of lane by lane.
//!
//! The sweep ([`crate::kernels::sweep::sort_pairs`]) reads every pair of the Verlet list at
//! every step to find the few that touch: at 5000 grains about 30% of a step. The
//! portable sweep appends the touching pairs of four lane by lane, every index and
//! separation stored and the count moved on by one touch flag after the other: a chain
//! of dependent stores that the CPU waits on (perf annotate on a Zen 4). AVX2 has no
//! compress instruction (AVX-512 has, [`crate::kernels::avx512`]); here a table does it:
//! - the four pairs' indices: `k` plus the table's row for the touch mask (the touching
//!   lanes first), stored with one write, the count moved on once by the number that
//!   touch;
//! - the separations, kept as (x, y) pairs two to a register as they are stored: each
//!   register's touching pair moved to the front where only its second one touches
//!   (one permute), and the two registers stored one after the other, the second where
//!   the first one's touching pairs end.
//!
//! The grains' positions are read as the (x, y) pairs they are stored as, two pairs to a
//! register, and the minimum image is taken on the x lanes of those registers (the y
//! lanes get 0 periods). The arithmetic is the portable sweep's, operation for operation
//! (`dx - period * nearest_integer(dx / period)` with
//! [`crate::physics::boundary::nearest_integer`]'s two additions, `dx dx + dy dy`, no fused
//! multiply-add), so the lists and separations are the same bits; the unit test
//! `wide_sweep_gives_the_portable_bits` (src/pipeline.rs) checks it.
//!
//! Compiled only when the build targets AVX2 and not AVX-512 (the default
//! `-C target-cpu=native`, `.cargo/config.toml`, on such a machine); otherwise the AVX-512
//! sweep or the portable one does it.

use std::arch::x86_64::*;
use std::ops::Range;

use crate::kernels::wide::{LeftOut, four_flags};
use crate::physics::boundary::{Boundary, ROUND_EXACT_FROM, ROUND_SHIFT};
use crate::physics::dim::Vec2;

/// Pairs per step of [`fours`].
pub const WIDTH: usize = 4;

/// For each mask of four touch flags (bit l: lane l), the touching lanes in order, first
/// (the rest of the row is never read back).
const PACKED: [[i32; 4]; 16] = {
    let mut t = [[0; 4]; 16];
    let mut m = 0;
    while m < 16 {
        let (mut c, mut l) = (0, 0);
        while l < 4 {
            if m >> l & 1 == 1 {
                t[m][c] = l;
                c += 1;
            }
            l += 1;
        }
        m += 1;
    }
    t
};

/// For the two touch flags of a register of two (x, y) pairs: the permutation (of its
/// eight 32-bit words) that brings the touching pair to the front. Only "the second
/// touches, the first does not" moves anything.
const FRONT: [[i32; 8]; 4] = [[0, 1, 2, 3, 4, 5, 6, 7], [0, 1, 2, 3, 4, 5, 6, 7], [4, 5, 6, 7, 0, 1, 2, 3], [0, 1, 2, 3, 4, 5, 6, 7]];

/// The sweep's loop over `range` (a multiple of four pairs): `sweep_wide` in
/// src/pipeline.rs calls it.
///
/// # Safety
/// The pointers must be good for the pairs of `range`, their grains and the writes, as
/// `WideLoop` (src/pipeline.rs) says; `sweep_wide` asserts it.
#[target_feature(enable = "avx2")]
#[allow(clippy::too_many_arguments)]
pub unsafe fn fours(list: *const [u32; 2], xp: *const f64, boundary: &Boundary, reach: *const f64, active: *const bool, skip: &[u32], range: Range<usize>, touching: *mut u32, sep: *mut Vec2, released: *mut u32, t: &mut usize, r: &mut usize) {
    // The x lanes of two (x, y) pairs get the period, the y lanes none.
    let period = _mm256_setr_pd(boundary.period, 0.0, boundary.period, 0.0);
    let inv_period = _mm256_setr_pd(boundary.inv_period(), 0.0, boundary.inv_period(), 0.0);
    let (shift, exact) = (_mm256_set1_pd(ROUND_SHIFT), _mm256_set1_pd(ROUND_EXACT_FROM));
    let abs = _mm256_castsi256_pd(_mm256_set1_epi64x(i64::MAX));
    let mut k = range.start;
    let mut skip = LeftOut::new(skip);
    while k < range.end {
        let left_out = skip.lanes(k, WIDTH);
        // SAFETY: the caller's (`sweep_wide`'s checks).
        unsafe {
            let p = list.add(k);
            let at = |l: usize, g: usize| xp.add(2 * (*p.add(l))[g] as usize);
            // Separations (i minus j) of pairs 0 and 1, and of pairs 2 and 3, as stored.
            let a = _mm256_sub_pd(_mm256_loadu2_m128d(at(1, 0), at(0, 0)), _mm256_loadu2_m128d(at(1, 1), at(0, 1)));
            let b = _mm256_sub_pd(_mm256_loadu2_m128d(at(3, 0), at(2, 0)), _mm256_loadu2_m128d(at(3, 1), at(2, 1)));
            // The minimum image, as Boundary::image (y lanes: 0 periods, unchanged).
            let image = |d: __m256d| {
                let v = _mm256_mul_pd(d, inv_period);
                let small = _mm256_cmp_pd::<_CMP_LT_OQ>(_mm256_and_pd(v, abs), exact);
                let s = _mm256_blendv_pd(v, _mm256_sub_pd(_mm256_add_pd(v, shift), shift), small);
                _mm256_sub_pd(d, _mm256_mul_pd(period, s))
            };
            let (a, b) = (image(a), image(b));
            // dx dx + dy dy of the four pairs, in order: the squares of pairs 0 and 2, and
            // of pairs 1 and 3, side by side, then added pairwise.
            let (a2, b2) = (_mm256_mul_pd(a, a), _mm256_mul_pd(b, b));
            let d2 = _mm256_hadd_pd(_mm256_permute2f128_pd::<0x20>(a2, b2), _mm256_permute2f128_pd::<0x31>(a2, b2));
            let m = _mm256_movemask_pd(_mm256_cmp_pd::<_CMP_LT_OQ>(d2, _mm256_loadu_pd(reach.add(k)))) as u32;
            let touch = m & !left_out;
            let index = _mm_add_epi32(_mm_set1_epi32(k as i32), _mm_loadu_si128(PACKED[touch as usize].as_ptr() as *const __m128i));
            _mm_storeu_si128(touching.add(*t) as *mut __m128i, index);
            let front = |d: __m256d, m: u32| _mm256_castps_pd(_mm256_permutevar8x32_ps(_mm256_castpd_ps(d), _mm256_loadu_si256(FRONT[m as usize].as_ptr() as *const __m256i)));
            let out = sep.add(*t) as *mut f64;
            _mm256_storeu_pd(out, front(a, touch & 3));
            _mm256_storeu_pd(out.add(2 * (touch & 3).count_ones() as usize), front(b, touch >> 2));
            *t += touch.count_ones() as usize;
            // Released: touching before (flag bytes 0 or 1), not now. A few per step.
            let was = four_flags(std::ptr::read_unaligned(active.add(k) as *const [u8; 4]));
            let gone = !(touch | left_out) & was;
            if gone != 0 {
                for l in 0..WIDTH {
                    *released.add(*r) = (k + l) as u32;
                    *r += (gone >> l & 1) as usize;
                }
            }
        }
        k += WIDTH;
    }
}
