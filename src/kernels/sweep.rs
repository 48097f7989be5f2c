//! The contact sweep: one branch-free pass over the Verlet list that sorts out the pairs
//! touching now (with their separations) and those just released, so that the kernel
//! runs on those only; on AVX-512 and AVX2 CPUs the wide sweeps of
//! `kernels::avx512` and `kernels::avx2` (one of them in a build, by its target CPU; with
//! what they share, [`crate::kernels::wide`]) give the portable sweep's bits. Uses physics and the pair list.

use simba::simd::{SimdBool, SimdPartialOrd};
use crate::kernels::pairs::CheckedPairs;
use crate::kernels::wide::{WideLoop, four_flags};
use crate::physics::boundary::Boundary;
use crate::physics::dim::{Dim, Vec2};
use crate::physics::lanes::{LANES, Lanes, gather};

/// The pairs of a list part that are touching, and those that were at the previous step
/// and are not any more, as indices into the part, in list order: the first `nt` of
/// `touching` and the first `nr` of `released`, `(nt, nr)` returned; `sep[m]` is the
/// separation (minimum image, i minus j) of pair `touching[m]`. `reach` holds each
/// pair's `(r_i + r_j)^2` ([`crate::kernels::pairs::PairList::reach`]). `skip` (indices into
/// the part, ascending) leaves out pairs computed elsewhere: the portable sweep sweeps
/// the stretches between them one after the other, so that no pair pays for a test; the
/// CPU-specific sweeps (AVX-512, AVX2) mask their lanes. No branch per pair, and the
/// lists keep their length from step to step (no clearing).
/// In the plane the CPU-specific sweep (where the build has one) runs in front of the
/// portable one; in space the portable sweep runs alone ([`sort_pairs_portable`]).
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn sort_pairs<D: Dim>(x: &[D::Vector<f64>], boundary: &Boundary<D>, pairs: CheckedPairs<'_>, reach: &[f64], active: &[bool], skip: &[u32], touching: &mut Vec<u32>, sep: &mut Vec<D::Vector<f64>>, released: &mut Vec<u32>) -> (usize, usize) {
    if let (Some(x), Some(b), Some(sep)) = (D::plane_vectors(x), boundary.plane(), D::plane_vec_mut(sep)) {
        return sort_pairs_with(true, x, &b, pairs, reach, active, skip, touching, sep, released);
    }
    sort_pairs_portable(x, boundary, pairs, reach, active, skip, touching, sep, released)
}

/// The CPU-specific sweep the build has, as its width (pairs per step) and loop: eight
/// pairs a step with AVX-512 ([`crate::kernels::avx512`]), four with AVX2 alone
/// ([`crate::kernels::avx2`]), none otherwise.
#[cfg(all(target_arch = "x86_64", target_feature = "avx512f", target_feature = "avx512vl", target_feature = "avx512bw"))]
const WIDE_SWEEP: Option<(usize, WideLoop)> = Some((crate::kernels::avx512::WIDTH, crate::kernels::avx512::eights));
#[cfg(all(target_arch = "x86_64", target_feature = "avx2", not(all(target_feature = "avx512f", target_feature = "avx512vl", target_feature = "avx512bw"))))]
const WIDE_SWEEP: Option<(usize, WideLoop)> = Some((crate::kernels::avx2::WIDTH, crate::kernels::avx2::fours));
#[cfg(not(any(all(target_arch = "x86_64", target_feature = "avx512f", target_feature = "avx512vl", target_feature = "avx512bw"), all(target_arch = "x86_64", target_feature = "avx2", not(all(target_feature = "avx512f", target_feature = "avx512vl", target_feature = "avx512bw"))))))]
const WIDE_SWEEP: Option<(usize, WideLoop)> = None;

/// Sort out the pairs `range.start..range.start + width m` (the largest multiple of
/// `width` that fits in `range`) with a CPU-specific loop `body`, as the portable sweep
/// does, leaving out those in `skip` (ascending, within the range): touching pairs
/// appended to `touching` (with their separations to `sep`) from `nt` on, released ones to
/// `released` from `nr` on; `nt` and `nr` move on. Every pair before the range is sorted
/// out or skipped already, so `nt` and `nr` are at most `range.start`. Returns the end of
/// what it swept, for the portable sweep to take the rest. Skipped pairs (the parallel
/// stage's cross pairs) are masked lanes, not breaks in the sweep.
#[allow(clippy::too_many_arguments, dead_code)]
fn sweep_wide(
    (width, body): (usize, WideLoop),
    x: &[Vec2],
    boundary: &Boundary,
    pairs: CheckedPairs<'_>,
    reach: &[f64],
    active: &[bool],
    skip: &[u32],
    range: std::ops::Range<usize>,
    touching: &mut [u32],
    sep: &mut [Vec2],
    released: &mut [u32],
    nt: &mut usize,
    nr: &mut usize,
) -> usize {
    let end = range.start + range.len() / width * width;
    // Every read of the loop is of pairs before `end`, and of the grains of those pairs
    // (`CheckedPairs::of` checks that `x` covers them). Every write is of at most `width`
    // entries from `nt` or `nr`, which are at most the index of the first pair of the
    // width: so within `end`.
    let xs = pairs.of(x);
    assert!(end <= pairs.len() && end <= reach.len() && end <= active.len());
    // The AVX-512 loop's gathers take a grain index doubled as an i32 offset.
    assert!(x.len() <= 1 << 30, "{} grains: the CPU-specific sweeps take at most 2^30", x.len());
    assert!(*nt <= range.start && *nr <= range.start && end <= touching.len().min(sep.len()).min(released.len()));
    assert!(skip.first().is_none_or(|&k| k as usize >= range.start) && skip.is_sorted());
    // SAFETY: the build targets the loop's CPU features (it is compiled only then), and
    // the pointers are good for the pairs before `end`, their grains and the writes
    // (asserted above).
    unsafe { body(pairs.pairs().as_ptr(), xs.as_ptr() as *const f64, boundary, reach.as_ptr(), active.as_ptr(), skip, range.start..end, touching.as_mut_ptr(), sep.as_mut_ptr(), released.as_mut_ptr(), nt, nr) };
    end
}

/// [`sort_pairs`], with the CPU-specific sweep (`wide`, where the build has one:
/// [`WIDE_SWEEP`]) or the portable one alone (for the tests that compare them).
#[allow(clippy::too_many_arguments)]
fn sort_pairs_with(wide: bool, x: &[Vec2], boundary: &Boundary, pairs: CheckedPairs<'_>, reach: &[f64], active: &[bool], skip: &[u32], touching: &mut Vec<u32>, sep: &mut Vec<Vec2>, released: &mut Vec<u32>) -> (usize, usize) {
    let np = pairs.len();
    let (reach, active, touching, sep, released) = lists(np, reach, active, touching, sep, released);
    let (mut nt, mut nr, mut from) = (0, 0, 0);
    // Where the build has a CPU-specific sweep, it takes all but a short tail.
    let skip = match WIDE_SWEEP {
        Some(w) if wide => {
            from = sweep_wide(w, x, boundary, pairs, reach, active, skip, 0..np, touching, sep, released, &mut nt, &mut nr);
            &skip[skip.partition_point(|&k| (k as usize) < from)..]
        }
        _ => skip,
    };
    sweep_stretches(x, boundary, pairs, (reach, active), skip, from, (touching, sep, released), (&mut nt, &mut nr));
    (nt, nr)
}

/// [`sort_pairs`] in the plane or in space, with the portable sweep alone (the
/// CPU-specific sweeps are the plane's).
#[allow(clippy::too_many_arguments)]
pub fn sort_pairs_portable<D: Dim>(x: &[D::Vector<f64>], boundary: &Boundary<D>, pairs: CheckedPairs<'_>, reach: &[f64], active: &[bool], skip: &[u32], touching: &mut Vec<u32>, sep: &mut Vec<D::Vector<f64>>, released: &mut Vec<u32>) -> (usize, usize) {
    let (reach, active, touching, sep, released) = lists(pairs.len(), reach, active, touching, sep, released);
    let (mut nt, mut nr) = (0, 0);
    sweep_stretches(x, boundary, pairs, (reach, active), skip, 0, (touching, sep, released), (&mut nt, &mut nr));
    (nt, nr)
}

/// The per-pair slices of a sort cut to the `np` pairs, the output lists grown to them
/// first (they keep their length from step to step).
#[allow(clippy::type_complexity)]
fn lists<'a, V: Copy + Default>(np: usize, reach: &'a [f64], active: &'a [bool], touching: &'a mut Vec<u32>, sep: &'a mut Vec<V>, released: &'a mut Vec<u32>) -> (&'a [f64], &'a [bool], &'a mut [u32], &'a mut [V], &'a mut [u32]) {
    if touching.len() < np {
        touching.resize(np, 0);
        sep.resize(np, V::default());
        released.resize(np, 0);
    }
    (&reach[..np], &active[..np], &mut touching[..np], &mut sep[..np], &mut released[..np])
}

/// The portable sweep from pair `from` on, over the stretches between the pairs of
/// `skip` (ascending, all at or after `from`).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn sweep_stretches<D: Dim>(x: &[D::Vector<f64>], boundary: &Boundary<D>, pairs: CheckedPairs<'_>, (reach, active): (&[f64], &[bool]), skip: &[u32], mut from: usize, (touching, sep, released): (&mut [u32], &mut [D::Vector<f64>], &mut [u32]), (nt, nr): (&mut usize, &mut usize)) {
    for to in skip.iter().map(|&k| k as usize).chain(std::iter::once(pairs.len())) {
        if to > from {
            sweep(x, boundary, pairs, reach, active, from..to, touching, sep, released, nt, nr);
        }
        from = to + 1;
    }
}

/// The sweep of [`sort_pairs`] over the pairs `range` of the part: four pairs'
/// distances at a time in lanes, then their indices appended where they belong (from
/// `nt` and `nr` on, which it moves on). Every pair before the range is already sorted
/// out or skipped, so `nt` and `nr` are at most its first index and every write is in
/// bounds. Written once for the plane and space.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn sweep<D: Dim>(x: &[D::Vector<f64>], boundary: &Boundary<D>, pairs: CheckedPairs<'_>, reach: &[f64], active: &[bool], range: std::ops::Range<usize>, touching: &mut [u32], sep: &mut [D::Vector<f64>], released: &mut [u32], nt: &mut usize, nr: &mut usize) {
    let xs = pairs.of(x);
    let (mut t, mut r) = (*nt, *nr);
    // Every index written below is at most the index of the pair being sorted out
    // (`t` and `r` count a part of the pairs before it), so these checks cover them all.
    assert!(t <= range.start && r <= range.start && range.end <= touching.len().min(sep.len()).min(released.len()));
    let quads = range.len() / LANES * LANES;
    let k0 = range.start;
    let (reach, active) = (&reach[range.clone()], &active[range.clone()]);
    for (q, (rq, aq)) in reach[..quads].chunks_exact(LANES).zip(active[..quads].chunks_exact(LANES)).enumerate() {
        let k = k0 + q * LANES;
        let g = xs.four(k);
        let d: D::Vector<Lanes> = boundary.image(D::gather(|l| g[l].0 - g[l].1));
        let touch = D::norm_squared(d).simd_lt(gather(|l| rq[l])).bitmask();
        let was = four_flags([aq[0] as u8, aq[1] as u8, aq[2] as u8, aq[3] as u8]) as u64;
        // Touching: every index written, the count moved on where it touches.
        for l in 0..LANES {
            debug_assert!(t <= k + l);
            // SAFETY: t <= k + l < range.end <= touching.len(), sep.len() (asserted above).
            unsafe {
                *touching.get_unchecked_mut(t) = (k + l) as u32;
                *sep.get_unchecked_mut(t) = D::lane(&d, l);
            }
            t += touch as usize >> l & 1;
        }
        // Released: a few per step, so a branch that is almost never taken.
        let gone = !touch & was;
        if gone != 0 {
            for l in 0..LANES {
                released[r] = (k + l) as u32;
                r += gone as usize >> l & 1;
            }
        }
    }
    for m in quads..range.len() {
        let k = k0 + m;
        let (xi, xj) = xs.at(k);
        let d = boundary.image(xi - xj);
        let touch = D::norm_squared(d) < reach[m];
        touching[t] = k as u32;
        sep[t] = d;
        released[r] = k as u32;
        t += touch as usize;
        r += (!touch & active[m]) as usize;
    }
    (*nt, *nr) = (t, r);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernels::cells::brute_force_pairs;
    use crate::kernels::pairs::PairList;
    use rand::{Rng, SeedableRng};

    /// The CPU-specific sweep (AVX-512 or AVX2) gives the portable sweep's lists and
    /// separations, bit for bit: across the periodic seam and without periodicity, with
    /// pairs released, and with skipped pairs at every lane position (masked in the wide
    /// blocks, between stretches in the portable sweep that takes the tail).
    #[cfg(any(all(target_arch = "x86_64", target_feature = "avx512f", target_feature = "avx512vl", target_feature = "avx512bw"), all(target_arch = "x86_64", target_feature = "avx2", not(all(target_feature = "avx512f", target_feature = "avx512vl", target_feature = "avx512bw")))))]
    #[test]
    fn wide_sweep_gives_the_portable_bits() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let n = 400;
        for boundary in [Boundary::periodic_x(-0.5, 1.0), Boundary::open()] {
            let x: Vec<Vec2> = (0..n).map(|_| Vec2::new(rng.random::<f64>() - 0.5, 0.3 * rng.random::<f64>())).collect();
            let r: Vec<f64> = (0..n).map(|_| 0.01 + 0.01 * rng.random::<f64>()).collect();
            let mut list: PairList<f64> = PairList::default();
            list.replace(brute_force_pairs(&x, &r, n, &boundary, 0.01), &r, &vec![1.0; n], &crate::kernels::threads::Threads::serial());
            let np = list.pairs.len();
            let seam = list.pairs.iter().filter(|p| (x[p[0] as usize].x - x[p[1] as usize].x).abs() > 0.5).count();
            assert!(np > 200 && (seam > 5) == boundary.is_periodic(), "{np} pairs, {seam} across the seam");
            let active: Vec<bool> = (0..np).map(|_| rng.random::<bool>()).collect();
            for skip_rate in [0.0, 0.05, 0.3] {
                let skip: Vec<u32> = (0..np as u32).filter(|_| rng.random::<f64>() < skip_rate).collect();
                let sweep = |wide: bool| {
                    let (mut t, mut s, mut rel) = (Vec::new(), Vec::new(), Vec::new());
                    let (nt, nr) = sort_pairs_with(wide, &x, &boundary, list.pairs.checked(), &list.reach, &active, &skip, &mut t, &mut s, &mut rel);
                    (t[..nt].to_vec(), s[..nt].iter().map(|d| [d.x.to_bits(), d.y.to_bits()]).collect::<Vec<_>>(), rel[..nr].to_vec())
                };
                let (wide, portable) = (sweep(true), sweep(false));
                assert!(portable.0.len() > 20 && portable.2.len() > 20, "{} touching, {} released", portable.0.len(), portable.2.len());
                assert_eq!(wide, portable, "skip rate {skip_rate}, periodic {}", boundary.is_periodic());
            }
        }
    }

    /// The sweep with pairs to skip gives what it gives without, less those pairs: the
    /// stretches between skipped pairs (any length, so with and without a scalar tail)
    /// are swept as the whole list is.
    #[test]
    fn skipped_pairs_leave_the_rest_of_the_sweep_unchanged() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let n = 300;
        let boundary = Boundary::<crate::physics::dim::Plane>::periodic_x(0.0, 1.0);
        let x: Vec<Vec2> = (0..n).map(|_| Vec2::new(rng.random::<f64>(), 0.3 * rng.random::<f64>())).collect();
        let r: Vec<f64> = (0..n).map(|_| 0.01 + 0.01 * rng.random::<f64>()).collect();
        let mut list: PairList<f64> = PairList::default();
        list.replace(brute_force_pairs(&x, &r, n, &boundary, 0.01), &r, &vec![1.0; n], &crate::kernels::threads::Threads::serial());
        let np = list.pairs.len();
        assert!(np > 100, "{np} pairs");
        let active: Vec<bool> = (0..np).map(|_| rng.random::<bool>()).collect();
        let skip: Vec<u32> = (0..np as u32).filter(|_| rng.random::<f64>() < 0.1).chain([0, np as u32 - 1]).collect::<std::collections::BTreeSet<_>>().into_iter().collect();
        let sweep = |skip: &[u32]| {
            let (mut t, mut s, mut rel) = (Vec::new(), Vec::new(), Vec::new());
            let (nt, nr) = sort_pairs(&x, &boundary, list.pairs.checked(), &list.reach, &active, skip, &mut t, &mut s, &mut rel);
            (t[..nt].to_vec(), s[..nt].to_vec(), rel[..nr].to_vec())
        };
        let (all_t, all_s, all_r) = sweep(&[]);
        let (t, s, rel) = sweep(&skip);
        assert!(!all_t.is_empty() && !all_r.is_empty());
        let kept = |k: &u32| skip.binary_search(k).is_err();
        let want: Vec<(u32, Vec2)> = all_t.iter().zip(&all_s).filter(|(k, _)| kept(k)).map(|(&k, &d)| (k, d)).collect();
        assert_eq!(t.iter().copied().zip(s).collect::<Vec<_>>(), want);
        assert_eq!(rel, all_r.iter().copied().filter(|k| kept(k)).collect::<Vec<_>>());
        // Against the definition: touching when closer than r_i + r_j, released when
        // not touching but active.
        for (k, (p, &was)) in list.pairs.iter().zip(&active).enumerate() {
            let [i, j] = p.map(|g| g as usize);
            let touch = boundary.image(x[i] - x[j]).norm() < r[i] + r[j];
            assert_eq!(all_t.contains(&(k as u32)), touch, "pair {k}");
            assert_eq!(all_r.contains(&(k as u32)), !touch && was, "pair {k}");
        }
    }
}
