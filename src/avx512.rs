//! The contact sweep on CPUs with AVX-512: eight listed pairs per instruction.
//!
//! The sweep ([`crate::pipeline::sort_pairs`]) reads every pair of the Verlet list at
//! every step to find the few that touch; at 5000 grains it was about 40% of the contact
//! stage. The portable code reads the two grains of each of four pairs one by one and
//! appends the touching ones lane by lane. Two AVX-512 instructions do what no portable
//! code (and no compiler, from it) does here:
//! - gathers: the positions of eight grains with one instruction;
//! - compress: the touching pairs of eight, and their separations, packed to the front
//!   of a register and stored with one write, however many touch.
//!
//! The arithmetic is the portable sweep's, operation for operation (the minimum image
//! with [`crate::boundary::nearest_integer`]'s two additions, `dx dx + dy dy`, no fused
//! multiply-add), so the lists and separations are the same bits; the unit test below
//! checks it against the portable sweep. Compiled only when the build targets AVX-512
//! (the default `-C target-cpu=native` on a machine that has it, `.cargo/config.toml`);
//! otherwise the portable sweep does all of it.

use std::arch::x86_64::*;
use std::ops::Range;

use crate::boundary::{Boundary, ROUND_EXACT_FROM, ROUND_SHIFT};
use crate::dim::Vec2;
use crate::neighbor::CheckedPairs;

/// Pairs per step of [`sweep_eights`].
pub const WIDTH: usize = 8;

/// Sort out the pairs `range.start..range.start + 8 m` (the largest multiple of eight
/// that fits in `range`) as the portable sweep does, leaving out those in `skip`
/// (ascending, within the range): touching pairs appended to `touching` (with their
/// separations to `sep`) from `nt` on, released ones to `released` from `nr` on; `nt`
/// and `nr` move on. Every pair before the range is sorted out or skipped already, so
/// `nt` and `nr` are at most `range.start`. Returns the end of what it swept, for the
/// portable sweep to take the rest. Skipped pairs (the parallel stage's cross pairs) are
/// masked lanes, not breaks in the sweep: the eight-wide blocks go on undisturbed.
#[allow(clippy::too_many_arguments)]
pub fn sweep_eights(
    x: &[Vec2],
    boundary: &Boundary,
    pairs: CheckedPairs<'_>,
    reach: &[f64],
    active: &[bool],
    skip: &[u32],
    range: Range<usize>,
    touching: &mut [u32],
    sep: &mut [Vec2],
    released: &mut [u32],
    nt: &mut usize,
    nr: &mut usize,
) -> usize {
    let end = range.start + range.len() / WIDTH * WIDTH;
    let (mut t, mut r) = (*nt, *nr);
    // Every read below is of pairs before `end`, and of the grains of those pairs
    // (`CheckedPairs::of` checks that `x` covers them). Every write is of at most eight
    // entries from `t` or `r`, which are at most the index of the first pair of the
    // eight: so within `end`.
    let xs = pairs.of(x);
    assert!(end <= pairs.len() && end <= reach.len() && end <= active.len());
    // The gathers take a grain index doubled as an i32 offset.
    assert!(x.len() <= 1 << 30, "{} grains: the AVX-512 sweep takes at most 2^30", x.len());
    assert!(t <= range.start && r <= range.start && end <= touching.len().min(sep.len()).min(released.len()));
    assert!(skip.first().is_none_or(|&k| k as usize >= range.start) && skip.is_sorted());
    let list = pairs.pairs().as_ptr();
    // SAFETY: the build targets these features (the module is compiled only then), and
    // the pointers are good for the pairs before `end` (asserted above).
    unsafe { eights(list, xs.as_ptr() as *const f64, boundary, reach.as_ptr(), active.as_ptr(), skip, range.start..end, touching.as_mut_ptr(), sep.as_mut_ptr(), released.as_mut_ptr(), &mut t, &mut r) };
    (*nt, *nr) = (t, r);
    end
}

/// The loop of [`sweep_eights`] over `range` (a multiple of eight pairs), on raw
/// pointers that are good for it.
#[target_feature(enable = "avx512f,avx512vl,avx512bw")]
#[allow(clippy::too_many_arguments)]
unsafe fn eights(list: *const [u32; 2], xp: *const f64, boundary: &Boundary, reach: *const f64, active: *const bool, skip: &[u32], range: Range<usize>, touching: *mut u32, sep: *mut Vec2, released: *mut u32, t: &mut usize, r: &mut usize) {
    let period = _mm512_set1_pd(boundary.period);
    let inv_period = _mm512_set1_pd(boundary.inv_period());
    let (shift, exact) = (_mm512_set1_pd(ROUND_SHIFT), _mm512_set1_pd(ROUND_EXACT_FROM));
    let lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    // Separations from eight x and eight y values back to eight (x, y) pairs.
    let (first, second) = (_mm512_setr_epi64(0, 8, 1, 9, 2, 10, 3, 11), _mm512_setr_epi64(4, 12, 5, 13, 6, 14, 7, 15));
    let mut k = range.start;
    let mut skip = skip.iter().map(|&k| k as usize).peekable();
    while k < range.end {
        // The lanes to leave out: usually none (one compare).
        let mut left_out = 0u8;
        while let Some(m) = skip.next_if(|&m| m < k + WIDTH) {
            left_out |= 1 << (m - k);
        }
        // SAFETY: see the caller; a grain index doubled is a positive i32 offset
        // (asserted there: fewer than 2^30 grains).
        unsafe {
            // Eight pairs as eight u64 (j << 32 | i): i and j as eight u32 each.
            let p = _mm512_loadu_si512(list.add(k) as *const __m512i);
            let i = _mm256_slli_epi32::<1>(_mm512_cvtepi64_epi32(p));
            let j = _mm256_slli_epi32::<1>(_mm512_cvtepi64_epi32(_mm512_srli_epi64::<32>(p)));
            let dx = _mm512_sub_pd(_mm512_i32gather_pd::<8>(i, xp), _mm512_i32gather_pd::<8>(j, xp));
            let dy = _mm512_sub_pd(_mm512_i32gather_pd::<8>(i, xp.add(1)), _mm512_i32gather_pd::<8>(j, xp.add(1)));
            // The minimum image, as Boundary::image.
            let v = _mm512_mul_pd(dx, inv_period);
            let small = _mm512_cmp_pd_mask::<_CMP_LT_OQ>(_mm512_abs_pd(v), exact);
            let s = _mm512_mask_blend_pd(small, v, _mm512_sub_pd(_mm512_add_pd(v, shift), shift));
            let dx = _mm512_sub_pd(dx, _mm512_mul_pd(period, s));
            let d2 = _mm512_add_pd(_mm512_mul_pd(dx, dx), _mm512_mul_pd(dy, dy));
            let touch = _mm512_cmp_pd_mask::<_CMP_LT_OQ>(d2, _mm512_loadu_pd(reach.add(k))) & !left_out;
            let index = _mm256_add_epi32(_mm256_set1_epi32(k as i32), lane);
            _mm256_storeu_si256(touching.add(*t) as *mut __m256i, _mm256_maskz_compress_epi32(touch, index));
            let (cx, cy) = (_mm512_maskz_compress_pd(touch, dx), _mm512_maskz_compress_pd(touch, dy));
            let out = sep.add(*t) as *mut f64;
            _mm512_storeu_pd(out, _mm512_permutex2var_pd(cx, first, cy));
            _mm512_storeu_pd(out.add(WIDTH), _mm512_permutex2var_pd(cx, second, cy));
            *t += touch.count_ones() as usize;
            // Released: touching before (flag bytes 0 or 1), not now. A few per step.
            let flags = _mm_loadl_epi64(active.add(k) as *const __m128i);
            let gone = !(touch | left_out) & _mm_test_epi8_mask(flags, flags) as u8;
            if gone != 0 {
                _mm256_storeu_si256(released.add(*r) as *mut __m256i, _mm256_maskz_compress_epi32(gone, index));
                *r += gone.count_ones() as usize;
            }
        }
        k += WIDTH;
    }
}
