//! The contact sweep and the integrator on CPUs with AVX-512: eight pairs or grains per
//! instruction.
//!
//! The sweep ([`crate::kernels::sweep::sort_pairs`]) reads every pair of the Verlet list at
//! every step to find the few that touch; at 5000 grains it was about 40% of the contact
//! stage. The portable code reads the two grains of each of four pairs one by one and
//! appends the touching ones lane by lane. Two AVX-512 instructions do what no portable
//! code (and no compiler, from it) does here:
//! - gathers: the positions of eight grains with one instruction;
//! - compress: the touching pairs of eight, and their separations, packed to the front
//!   of a register and stored with one write, however many touch.
//!
//! The arithmetic is the portable sweep's, operation for operation (the minimum image
//! with [`crate::physics::boundary::nearest_integer`]'s two additions, `dx dx + dy dy`, no fused
//! multiply-add), so the lists and separations are the same bits; the unit test below
//! checks it against the portable sweep.
//!
//! The drift and the kicks of the integrator ([`drift`], [`kick`]) take eight grains at a
//! time here too, on their (x, y) pairs as they are stored, with the skin watch and the
//! periodic check in the same pass; the same operations as the portable loops, so the
//! same bits (a unit test below).
//!
//! Compiled only when the build targets AVX-512 (the default `-C target-cpu=native` on a
//! machine that has it, `.cargo/config.toml`); otherwise the portable code does all of it.

use std::arch::x86_64::*;
use std::ops::Range;

use crate::kernels::wide::LeftOut;
use crate::physics::boundary::{Boundary, ROUND_EXACT_FROM, ROUND_SHIFT};
use crate::physics::dim::Vec2;

/// Pairs per step of [`eights`].
pub const WIDTH: usize = 8;

/// The sweep's loop over `range` (a multiple of eight pairs): `sweep_wide` in
/// src/pipeline.rs calls it.
///
/// # Safety
/// The pointers must be good for the pairs of `range`, their grains and the writes, as
/// `WideLoop` (src/pipeline.rs) says; `sweep_wide` asserts it.
#[target_feature(enable = "avx512f,avx512vl,avx512bw")]
#[allow(clippy::too_many_arguments)]
pub unsafe fn eights(list: *const [u32; 2], xp: *const f64, boundary: &Boundary, reach: *const f64, active: *const bool, skip: &[u32], range: Range<usize>, touching: *mut u32, sep: *mut Vec2, released: *mut u32, t: &mut usize, r: &mut usize) {
    let period = _mm512_set1_pd(boundary.period);
    let inv_period = _mm512_set1_pd(boundary.inv_period());
    let (shift, exact) = (_mm512_set1_pd(ROUND_SHIFT), _mm512_set1_pd(ROUND_EXACT_FROM));
    let lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    // Separations from eight x and eight y values back to eight (x, y) pairs.
    let (first, second) = (_mm512_setr_epi64(0, 8, 1, 9, 2, 10, 3, 11), _mm512_setr_epi64(4, 12, 5, 13, 6, 14, 7, 15));
    let mut k = range.start;
    let mut skip = LeftOut::new(skip);
    while k < range.end {
        let left_out = skip.lanes(k, WIDTH) as u8;
        // SAFETY: the caller's (`sweep_wide`'s checks); a grain index doubled is a
        // positive i32 offset (asserted there: at most 2^30 grains).
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

/// The arrays of one thread's part of the free grains for [`drift`] and [`kick`]: with
/// `ROT` also the spin, torque and spin kick factor; empty otherwise. (The drift sets the
/// forces and torques to zero once it has used them; the kick leaves them.)
pub struct GrainPart<'a> {
    pub v: &'a mut [Vec2],
    pub f: &'a mut [Vec2],
    /// dt/2 / m, s/kg.
    pub dtfm: &'a [f64],
    pub omega: &'a mut [f64],
    pub torque: &'a mut [f64],
    /// dt/2 / I, s/(kg m^2).
    pub dtfi: &'a [f64],
}

impl GrainPart<'_> {
    /// The grains all arrays cover (the spin arrays only with `ROT`), in whole eights.
    fn eights<const ROT: bool>(&self) -> usize {
        let mut n = self.v.len().min(self.f.len()).min(self.dtfm.len());
        if ROT {
            n = n.min(self.omega.len()).min(self.torque.len()).min(self.dtfi.len());
        }
        n / WIDTH * WIDTH
    }
}

/// The first half kick and the drift of the grains `0..8 m` of a part (the largest
/// multiple of eight it holds), as [`crate::engine::integrate::InitialIntegrate`] does them grain
/// by grain: `v += dtfm f`, `x += dt v` (`ROT`: `w += dtfi M`), with the same operations
/// (a multiply, then an add; none fused), so the same bits; the forces and torques used
/// are set to zero (`World::zeroed`). In the same pass, the watch
/// of the neighbour list (any grain farther than `limit.sqrt()` from `at`, its place at
/// the last build, minimum image in x) and whether any grain left the periodic cell (then
/// the caller wraps them and watches again). Eight grains at a time in two registers
/// per vector array, (x, y) pairs as they are stored: the portable loop splits the pairs
/// into x and y registers and back, and that shuffling, not memory, bounded it. Returns
/// (grains done, far, outside). With `TWICE`, the last step's final half kick first
/// (the same kick, with the same forces, once more before it: the bits of two passes).
pub fn drift<const ROT: bool, const TWICE: bool>(g: GrainPart<'_>, x: &mut [Vec2], at: &[Vec2], dt: f64, boundary: &Boundary, limit: f64) -> (usize, bool, bool) {
    let end = g.eights::<ROT>().min(x.len()).min(at.len());
    // SAFETY: the module is compiled only for AVX-512F; every array is read or written
    // below `end` grains.
    let (far, out) = unsafe { drift_eights::<ROT, TWICE>(end, g, x.as_mut_ptr() as *mut f64, at.as_ptr() as *const f64, dt, boundary, limit) };
    (end, far, out)
}

/// The loop of [`drift`] over `end` grains (a multiple of eight).
#[target_feature(enable = "avx512f")]
unsafe fn drift_eights<const ROT: bool, const TWICE: bool>(end: usize, g: GrainPart<'_>, x: *mut f64, at: *const f64, dt: f64, boundary: &Boundary, limit: f64) -> (bool, bool) {
    let (v, f, m) = (g.v.as_mut_ptr() as *mut f64, g.f.as_mut_ptr() as *mut f64, g.dtfm.as_ptr());
    let (w, t, mi) = (g.omega.as_mut_ptr(), g.torque.as_mut_ptr(), g.dtfi.as_ptr());
    let (lo, hi) = (_mm512_setr_epi64(0, 0, 1, 1, 2, 2, 3, 3), _mm512_setr_epi64(4, 4, 5, 5, 6, 6, 7, 7));
    let dtv = _mm512_set1_pd(dt);
    // The minimum image acts on the x lanes only: y lanes get period and 1/period 0, so
    // that they keep their value (d - 0 * 0).
    let (p, ip) = (boundary.period, boundary.inv_period());
    let period = _mm512_setr_pd(p, 0.0, p, 0.0, p, 0.0, p, 0.0);
    let inv_period = _mm512_setr_pd(ip, 0.0, ip, 0.0, ip, 0.0, ip, 0.0);
    let (shift, exact) = (_mm512_set1_pd(ROUND_SHIFT), _mm512_set1_pd(ROUND_EXACT_FROM));
    let (x_min, full, zero, lim) = (_mm512_set1_pd(boundary.x_min), _mm512_set1_pd(p), _mm512_setzero_pd(), _mm512_set1_pd(limit));
    let periodic = boundary.is_periodic();
    let (mut far, mut out) = (0u8, 0u8);
    let mut k = 0;
    while k < end {
        // SAFETY: grains k..k + 8 < end, covered by every array (the caller).
        unsafe {
            let m8 = _mm512_loadu_pd(m.add(k));
            for (h, idx) in [(0, lo), (1, hi)] {
                let o = 2 * k + 8 * h;
                if TWICE {
                    kick_four(v, f, m8, idx, o);
                }
                let vv = kick_four(v, f, m8, idx, o);
                _mm512_storeu_pd(f.add(o), _mm512_setzero_pd());
                let xx = _mm512_add_pd(_mm512_loadu_pd(x.add(o)), _mm512_mul_pd(dtv, vv));
                _mm512_storeu_pd(x.add(o), xx);
                // The watch: |image(x - at)|^2 > limit, as Boundary::any_moved_beyond.
                let d = _mm512_sub_pd(xx, _mm512_loadu_pd(at.add(o)));
                let s = _mm512_mul_pd(d, inv_period);
                let small = _mm512_cmp_pd_mask::<_CMP_LT_OQ>(_mm512_abs_pd(s), exact);
                let s = _mm512_mask_blend_pd(small, s, _mm512_sub_pd(_mm512_add_pd(s, shift), shift));
                let d = _mm512_sub_pd(d, _mm512_mul_pd(period, s));
                let d2 = _mm512_mul_pd(d, d);
                // x x + y y in the x lanes.
                let r2 = _mm512_add_pd(d2, _mm512_permute_pd::<0b0101_0101>(d2));
                far |= _mm512_cmp_pd_mask::<_CMP_GT_OQ>(r2, lim) & 0x55;
                // Outside the cell: not 0 <= x - x_min < period (x lanes).
                if periodic {
                    let xr = _mm512_sub_pd(xx, x_min);
                    let inside = _mm512_cmp_pd_mask::<_CMP_GE_OQ>(xr, zero) & _mm512_cmp_pd_mask::<_CMP_LT_OQ>(xr, full);
                    out |= !inside & 0x55;
                }
            }
            if ROT {
                if TWICE {
                    kick_spins(w, t, mi, k);
                }
                kick_spins(w, t, mi, k);
                _mm512_storeu_pd(t.add(k), _mm512_setzero_pd());
            }
        }
        k += WIDTH;
    }
    (far != 0, out != 0)
}

/// `v += dtfm f` for the four grains whose (x, y) pairs start at number `o` of `v` and
/// `f` (their factors `dtfm` in the lanes `idx` of `m8`, each twice); the new `v`.
///
/// SAFETY: `v` and `f` hold the numbers `o..o + 8`.
#[inline(always)]
unsafe fn kick_four(v: *mut f64, f: *const f64, m8: __m512d, idx: __m512i, o: usize) -> __m512d {
    // SAFETY: see above.
    unsafe {
        let vv = _mm512_add_pd(_mm512_loadu_pd(v.add(o)), _mm512_mul_pd(_mm512_permutexvar_pd(idx, m8), _mm512_loadu_pd(f.add(o))));
        _mm512_storeu_pd(v.add(o), vv);
        vv
    }
}

/// `w += dtfi M` for the eight grains from `k`.
///
/// SAFETY: `w`, `t` and `mi` hold the grains `k..k + 8`.
#[inline(always)]
unsafe fn kick_spins(w: *mut f64, t: *const f64, mi: *const f64, k: usize) {
    // SAFETY: see above.
    unsafe { _mm512_storeu_pd(w.add(k), _mm512_add_pd(_mm512_loadu_pd(w.add(k)), _mm512_mul_pd(_mm512_loadu_pd(mi.add(k)), _mm512_loadu_pd(t.add(k))))) };
}

/// The second half kick of the grains `0..8 m` of a part, as
/// [`crate::engine::integrate::FinalIntegrate`] does it grain by grain (`v += dtfm f`; `ROT`:
/// `w += dtfi M`), with the same operations, eight grains at a time. Returns the grains done.
pub fn kick<const ROT: bool>(g: GrainPart<'_>) -> usize {
    let end = g.eights::<ROT>();
    // SAFETY: the module is compiled only for AVX-512F; every array is read or written
    // below `end` grains.
    unsafe { kick_eights::<ROT>(end, g) };
    end
}

/// The loop of [`kick`] over `end` grains (a multiple of eight).
#[target_feature(enable = "avx512f")]
unsafe fn kick_eights<const ROT: bool>(end: usize, g: GrainPart<'_>) {
    let (v, f, m) = (g.v.as_mut_ptr() as *mut f64, g.f.as_ptr() as *const f64, g.dtfm.as_ptr());
    let (w, t, mi) = (g.omega.as_mut_ptr(), g.torque.as_ptr(), g.dtfi.as_ptr());
    let (lo, hi) = (_mm512_setr_epi64(0, 0, 1, 1, 2, 2, 3, 3), _mm512_setr_epi64(4, 4, 5, 5, 6, 6, 7, 7));
    let mut k = 0;
    while k < end {
        // SAFETY: grains k..k + 8 < end, covered by every array (the caller).
        unsafe {
            let m8 = _mm512_loadu_pd(m.add(k));
            for (h, idx) in [(0, lo), (1, hi)] {
                kick_four(v, f, m8, idx, 2 * k + 8 * h);
            }
            if ROT {
                kick_spins(w, t, mi, k);
            }
        }
        k += WIDTH;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// Random grains of a part: velocities, forces, factors, spins; positions spread over
    /// a periodic cell [-0.5, 0.5) with some next to either edge, and their places at the
    /// last build (a few far from there).
    #[allow(clippy::type_complexity)]
    fn grains(n: usize, seed: u64) -> (Vec<Vec2>, Vec<Vec2>, Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>, Vec<Vec2>, Vec<Vec2>) {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let mut u = |a: f64, b: f64| a + (b - a) * rng.random::<f64>();
        let v = (0..n).map(|_| Vec2::new(u(-1.0, 1.0), u(-1.0, 1.0))).collect();
        let f = (0..n).map(|_| Vec2::new(u(-1e-2, 1e-2), u(-1e-2, 1e-2))).collect();
        let dtfm = (0..n).map(|_| u(1e-6, 1e-4)).collect();
        let omega = (0..n).map(|_| u(-1e3, 1e3)).collect();
        let torque = (0..n).map(|_| u(-1e-6, 1e-6)).collect();
        let dtfi = (0..n).map(|_| u(1e-1, 1e1)).collect();
        let x: Vec<Vec2> = (0..n).map(|k| Vec2::new(if k % 7 == 0 { 0.5 - 1e-9 } else if k % 11 == 0 { -0.5 } else { u(-0.5, 0.5) }, u(0.0, 0.1))).collect();
        // A few far away in y, beyond half the period: the minimum image is in x only.
        let at = x.iter().enumerate().map(|(k, x)| x + if k % 13 == 0 { Vec2::new(2e-3, 0.0) } else if k % 17 == 0 { Vec2::new(0.0, 0.7) } else { Vec2::new(u(-1e-4, 1e-4), u(-1e-4, 1e-4)) }).collect();
        (v, f, dtfm, omega, torque, dtfi, x, at)
    }

    /// The AVX-512 drift gives the portable loops' bits (velocities, positions, spins)
    /// and the same watch (far) and periodic (outside) findings: with and without
    /// periodicity, lengths that are and are not whole eights, grains that leave the cell
    /// and grains past the limit (in x, or in y by more than half the period), or none.
    /// Fails with a fused multiply-add, or with the minimum image on the y lanes (tried).
    #[test]
    fn drift_and_kick_give_the_portable_bits() {
        let dt = 1e-3;
        for boundary in [Boundary::periodic_x(-0.5, 1.0), Boundary::open()] {
            for (n, seed) in [(64, 1), (61, 2), (7, 3), (200, 4)] {
                for (limit, far_somewhere) in [(1e-6, true), (0.25, true), (1.0, false)] {
                    let (mut v, f, dtfm, mut omega, torque, dtfi, mut x, at) = grains(n, seed);
                    let (mut v0, mut x0, mut omega0) = (v.clone(), x.clone(), omega.clone());
                    // The fused pending kick: two kicks, as two passes give them.
                    let (mut v2, mut x2, mut omega2) = (v.clone(), x.clone(), omega.clone());
                    let mut used = (f.clone(), torque.clone());
                    let (done2, ..) = drift::<true, true>(GrainPart { v: &mut v2, f: &mut used.0, dtfm: &dtfm, omega: &mut omega2, torque: &mut used.1, dtfi: &dtfi }, &mut x2, &at, dt, &boundary, limit);
                    let (mut v2_want, mut x2_want, mut omega2_want) = (v.clone(), x.clone(), omega.clone());
                    for k in 0..done2 {
                        v2_want[k] += dtfm[k] * f[k];
                        v2_want[k] += dtfm[k] * f[k];
                        x2_want[k] += dt * v2_want[k];
                        omega2_want[k] += dtfi[k] * torque[k];
                        omega2_want[k] += dtfi[k] * torque[k];
                    }
                    for k in 0..n {
                        v0[k] += dtfm[k] * f[k];
                        x0[k] += dt * v0[k];
                        omega0[k] += dtfi[k] * torque[k];
                    }
                    let (far0, out0) = (boundary.any_moved_beyond(&x0, &at, limit), boundary.any_outside(&x0));
                    let (mut used_f, mut used_t) = (f.clone(), torque.clone());
                    let (done, far, out) = drift::<true, false>(GrainPart { v: &mut v, f: &mut used_f, dtfm: &dtfm, omega: &mut omega, torque: &mut used_t, dtfi: &dtfi }, &mut x, &at, dt, &boundary, limit);
                    assert_eq!(done, n / WIDTH * WIDTH);
                    // The forces and torques used are zero, the rest untouched.
                    assert!(used_f[..done].iter().all(|f| *f == Vec2::zeros()) && used_t[..done].iter().all(|&t| t == 0.0));
                    assert!(used_f[done..] == f[done..] && used_t[done..] == torque[done..]);
                    let bits = |a: &[Vec2]| a[..done].iter().map(|p| [p.x.to_bits(), p.y.to_bits()]).collect::<Vec<_>>();
                    let spin_bits = |a: &[f64]| a[..done].iter().map(|w| w.to_bits()).collect::<Vec<_>>();
                    assert_eq!(bits(&v), bits(&v0), "v, n = {n}");
                    assert_eq!(bits(&x), bits(&x0), "x, n = {n}");
                    assert_eq!(spin_bits(&omega), spin_bits(&omega0), "spins, n = {n}");
                    assert_eq!(done2, done);
                    assert_eq!((bits(&v2), bits(&x2), spin_bits(&omega2)), (bits(&v2_want), bits(&x2_want), spin_bits(&omega2_want)), "twice, n = {n}");
                    // The eights' findings are those of the same grains' portable watch.
                    assert_eq!(far, boundary.any_moved_beyond(&x0[..done], &at[..done], limit), "far, n = {n}, limit {limit}");
                    assert_eq!(out, boundary.any_outside(&x0[..done]), "outside, n = {n}");
                    if done == n && n > 60 {
                        assert_eq!((far, out), (far0, out0));
                        assert_eq!(far, far_somewhere, "the test has grains past the limit {limit}");
                        assert_eq!(out, boundary.is_periodic(), "the test has grains outside the periodic cell");
                    }
                    let (mut v1, mut omega1) = (v0.clone(), omega0.clone());
                    let done = kick::<true>(GrainPart { v: &mut v0, f: &mut f.clone(), dtfm: &dtfm, omega: &mut omega0, torque: &mut torque.clone(), dtfi: &dtfi });
                    for k in 0..done {
                        v1[k] += dtfm[k] * f[k];
                        omega1[k] += dtfi[k] * torque[k];
                    }
                    assert_eq!(done, n / WIDTH * WIDTH);
                    assert_eq!(bits(&v0), bits(&v1), "kick v, n = {n}");
                    assert_eq!(spin_bits(&omega0), spin_bits(&omega1), "kick spins, n = {n}");
                }
            }
        }
    }
}
