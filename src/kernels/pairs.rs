//! The Verlet list: the pairs a neighbour search listed, sorted, with what each pair's
//! kernel needs (constants, reach) and its contact history, which survives every rebuild
//! (the old list's histories are carried over to the new one with one merge); and the
//! checked views the sweeps read grain values through. Uses physics.

use crate::kernels::threads::Threads;
use crate::physics::contact::EnergyMemory;
use crate::physics::contact::rolling::RollingEnergy;
use crate::physics::dim::{Dim, Plane};
use crate::physics::energy::EnergySums;

/// The Verlet list and the history of each listed pair.
#[derive(Clone, Debug, Default)]
pub struct PairList<H, X = (), D: Dim = Plane> {
    /// Listed pairs, i < j, sorted (set by [`PairList::replace`] only).
    pub pairs: Pairs,
    /// What each pair's kernel would otherwise divide out at every step, parallel to `pairs`.
    pub consts: Vec<PairConst>,
    /// `(r_i + r_j)^2` of each pair, m^2, parallel to `pairs`: the pair touches when its
    /// distance squared is below (the contact sweep reads only this, the positions and
    /// `active`).
    pub reach: Vec<f64>,
    /// Tangential state of each pair, parallel to `pairs`.
    pub hist: Vec<H>,
    /// Energy memory of each pair, parallel to `pairs` when `keep_energy`, else empty
    /// (`X`: its rolling torque's part, `()` without rolling resistance).
    pub energy: Vec<EnergyMemory<f64, X, D>>,
    /// True while the pair is (or was at the previous step) touching, parallel to `pairs`.
    pub active: Vec<bool>,
    /// Keep the energy memory (the run has the energy ledger on).
    pub keep_energy: bool,
    /// The arrays of the list before the last rebuild, kept for the next one to fill:
    /// new arrays at every rebuild cost their page faults again (a quarter of the
    /// rebuild's time at 20 000 grains).
    pub(crate) spare: Spare<H, X, D>,
}

/// Spare per-pair arrays ([`PairList::replace`] swaps them with the list's).
#[derive(Clone, Debug, Default)]
pub(crate) struct Spare<H, X = (), D: Dim = Plane> {
    hist: Vec<H>,
    active: Vec<bool>,
    energy: Vec<EnergyMemory<f64, X, D>>,
}

/// The constants of a listed pair, computed once per neighbour-list build.
#[derive(Clone, Copy, Debug, Default)]
pub struct PairConst {
    /// Reduced radius R* = r_i r_j / (r_i + r_j), m.
    pub r_star: f64,
    /// Square root of the reduced mass m* = m_i m_j / (m_i + m_j), kg^1/2.
    pub sqrt_m_star: f64,
    /// 1 / min(r_i, r_j), 1/m (overlap ratio for the watchdog).
    pub inv_r_min: f64,
}

impl<H: Copy + Default + Send + Sync, X: RollingEnergy<f64, D::Spin<f64>>, D: Dim> PairList<H, X, D> {
    /// Replace the pairs, keeping the history of every pair that stays listed, and
    /// compute their constants from the radii `r` and masses `m`; on `threads`, each
    /// taking a stretch of the new list (the old list is sorted too, so a stretch finds
    /// where its histories start by bisection and merges from there).
    pub fn replace(&mut self, new_pairs: Vec<[u32; 2]>, r: &[f64], m: &[f64], threads: &Threads) {
        let np = new_pairs.len();
        self.consts.resize(np, PairConst::default());
        self.reach.resize(np, 0.0);
        // Every entry is written below (kept or not).
        let Spare { mut hist, mut active, mut energy } = std::mem::take(&mut self.spare);
        hist.resize(np, H::default());
        active.resize(np, false);
        energy.resize(if self.keep_energy { np } else { 0 }, EnergyMemory::default());
        let old = Carried { pairs: &self.pairs.list, hist: &self.hist, active: &self.active, energy: &self.energy };
        let new_part = (&new_pairs[..], &mut self.consts[..], &mut self.reach[..]);
        if self.keep_energy {
            threads.split(np, (new_part, (&mut hist[..], &mut active[..], &mut energy[..])), |((new, consts, reach), (hist, active, energy))| {
                constants(new, consts, reach, r, m);
                old.carry(new, hist, active, Some(energy));
            });
        } else {
            threads.split(np, (new_part, (&mut hist[..], &mut active[..])), |((new, consts, reach), (hist, active))| {
                constants(new, consts, reach, r, m);
                old.carry(new, hist, active, None);
            });
        }
        self.pairs = Pairs { top: new_pairs.iter().fold(0, |t, p| t.max(p[0].max(p[1]) as usize + 1)), list: new_pairs };
        self.spare = Spare { hist: std::mem::replace(&mut self.hist, hist), active: std::mem::replace(&mut self.active, active), energy: std::mem::replace(&mut self.energy, energy) };
    }
    /// Take a list a checkpoint saved: sorted pairs (i < j, each grain index below `r`'s
    /// length, checked) and their states, parallel to them; the constants are computed
    /// again from the radii `r` and masses `m`, as the build computed them. An error
    /// says what does not fit.
    pub fn restore(&mut self, pairs: Vec<[u32; 2]>, hist: Vec<H>, active: Vec<bool>, energy: Vec<EnergyMemory<f64, X, D>>, r: &[f64], m: &[f64]) -> Result<(), String> {
        let np = pairs.len();
        if hist.len() != np || active.len() != np || energy.len() != if self.keep_energy { np } else { 0 } {
            return Err(format!("its pair list has {np} pairs but {} histories, {} flags and {} energy memories", hist.len(), active.len(), energy.len()));
        }
        let n = r.len().min(m.len());
        if let Some(p) = pairs.iter().find(|p| p[0] >= p[1] || p[1] as usize >= n) {
            return Err(format!("its pair list holds the pair {p:?}, not of two of its {n} grains in order"));
        }
        if pairs.windows(2).any(|w| w[0] >= w[1]) {
            return Err("its pair list is not sorted".into());
        }
        self.consts = vec![PairConst::default(); np];
        self.reach = vec![0.0; np];
        constants(&pairs, &mut self.consts, &mut self.reach, r, m);
        self.pairs = Pairs { top: pairs.iter().fold(0, |t, p| t.max(p[1] as usize + 1)), list: pairs };
        self.hist = hist;
        self.active = active;
        self.energy = energy;
        Ok(())
    }
    /// The energy sums of every listed pair, added in list order
    /// ([`EnergySums::total`]); zero without the energy ledger.
    pub fn energy_sums(&self) -> EnergySums {
        EnergySums::total(self.energy.iter().map(|e| &e.sums))
    }
    /// The work the rolling torques of every listed pair took since last taken, added in
    /// list order, J; zero without the energy ledger or rolling resistance.
    pub fn rolling_taken(&self) -> f64 {
        self.energy.iter().map(|e| e.rolling.taken()).sum()
    }
    /// Number of pairs currently touching (active history).
    pub fn touching(&self) -> usize {
        self.active.iter().filter(|&&a| a).count()
    }
}

/// The constants and reach of pairs `new` (radii `r`, masses `m`).
fn constants(new: &[[u32; 2]], consts: &mut [PairConst], reach: &mut [f64], r: &[f64], m: &[f64]) {
    for ((&[i, j], c), re) in new.iter().zip(consts).zip(reach) {
        let (i, j) = (i as usize, j as usize);
        *c = PairConst { r_star: crate::physics::material::reduced(r[i], r[j]), sqrt_m_star: crate::physics::material::reduced(m[i], m[j]).sqrt(), inv_r_min: 1.0 / r[i].min(r[j]) };
        let radsum = r[i] + r[j];
        *re = radsum * radsum;
    }
}

/// What the old list carries over to the new one: its pairs (sorted) and their states.
struct Carried<'a, H, X, D: Dim> {
    pairs: &'a [[u32; 2]],
    hist: &'a [H],
    active: &'a [bool],
    /// Empty without the energy ledger.
    energy: &'a [EnergyMemory<f64, X, D>],
}

impl<H: Copy + Default, X: RollingEnergy<f64, D::Spin<f64>>, D: Dim> Carried<'_, H, X, D> {
    /// The states of the pairs of the sorted stretch `new`: those listed before keep
    /// theirs, the others start afresh (every entry is written). The energy sums start
    /// at 0 in the new list: the ledger has taken the old list's.
    fn carry(&self, new: &[[u32; 2]], hist: &mut [H], active: &mut [bool], mut energy: Option<&mut [EnergyMemory<f64, X, D>]>) {
        let old = self.pairs;
        let mut k = new.first().map_or(0, |first| old.partition_point(|p| p < first));
        for (m, p) in new.iter().enumerate() {
            while k < old.len() && old[k] < *p {
                k += 1;
            }
            let kept = k < old.len() && old[k] == *p;
            hist[m] = if kept { self.hist[k] } else { H::default() };
            active[m] = kept && self.active[k];
            if let Some(e) = energy.as_deref_mut() {
                e[m] = if kept { self.energy[k].restarted() } else { EnergyMemory::default() };
            }
        }
    }
}

/// The pairs of a [`PairList`] (read as a slice) and their largest grain index.
#[derive(Clone, Debug, Default)]
pub struct Pairs {
    list: Vec<[u32; 2]>,
    /// One more than the largest grain index in `list` (0 if none).
    top: usize,
}

impl std::ops::Deref for Pairs {
    type Target = [[u32; 2]];
    fn deref(&self) -> &[[u32; 2]] {
        &self.list
    }
}

impl Pairs {
    /// The pairs with what the list knows of them: every grain index is below `top`.
    pub fn checked(&self) -> CheckedPairs<'_> {
        CheckedPairs { pairs: &self.list, top: self.top }
    }
}

/// A pair list (or a part of one) whose largest grain index is known, so that
/// per-grain arrays can be read at its pairs' grains without a bounds check per read:
/// the contact sweep and kernel read up to eight grain values per pair, and a check
/// costs a compare and a branch each (about 7% of the sweep's instructions).
#[derive(Clone, Copy, Debug)]
pub struct CheckedPairs<'a> {
    pairs: &'a [[u32; 2]],
    top: usize,
}

impl<'a> CheckedPairs<'a> {
    /// The pairs.
    #[inline(always)]
    pub fn pairs(self) -> &'a [[u32; 2]] {
        self.pairs
    }
    #[inline(always)]
    pub fn len(self) -> usize {
        self.pairs.len()
    }
    #[inline(always)]
    pub fn is_empty(self) -> bool {
        self.pairs.is_empty()
    }
    /// A part of the list.
    #[inline(always)]
    pub fn part(self, range: std::ops::Range<usize>) -> Self {
        CheckedPairs { pairs: &self.pairs[range], top: self.top }
    }
    /// A per-grain array, to read at the pairs' grains; it must cover every grain of the
    /// list (panics otherwise).
    #[inline(always)]
    pub fn of<T: Copy>(self, a: &'a [T]) -> GrainValues<'a, T> {
        assert!(a.len() >= self.top, "per-grain array of {} for grain indices up to {}", a.len(), self.top);
        GrainValues { pairs: self.pairs, a }
    }
}

/// A per-grain array read at the grains of a [`CheckedPairs`] list.
#[derive(Clone, Copy, Debug)]
pub struct GrainValues<'a, T> {
    pairs: &'a [[u32; 2]],
    a: &'a [T],
}

impl<T: Copy> GrainValues<'_, T> {
    /// The values of the two grains of pair `k`.
    #[inline(always)]
    pub fn at(self, k: usize) -> (T, T) {
        self.of_pair(self.pairs[k])
    }
    /// The values of the two grains of each of the four pairs from `k` on (one bounds
    /// check for the four).
    #[inline(always)]
    pub fn four(self, k: usize) -> [(T, T); 4] {
        let q: &[[u32; 2]; 4] = self.pairs[k..k + 4].try_into().expect("four pairs");
        std::array::from_fn(|l| self.of_pair(q[l]))
    }
    /// The start of the per-grain array: every grain index of the list's pairs is an
    /// offset within it (for code that reads several grains with one instruction).
    #[inline(always)]
    pub fn as_ptr(self) -> *const T {
        self.a.as_ptr()
    }
    #[inline(always)]
    fn of_pair(self, [i, j]: [u32; 2]) -> (T, T) {
        // SAFETY: the pair is one of the list's, whose grain indices are all below `top`
        // (PairList::replace), and `a` is at least `top` long (CheckedPairs::of).
        unsafe { (*self.a.get_unchecked(i as usize), *self.a.get_unchecked(j as usize)) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn history_survives_a_rebuild_and_leaves_with_its_pair() {
        let mut list: PairList<f64> = PairList { keep_energy: true, ..Default::default() };
        let (r, m) = (vec![1.0; 5], vec![1.0; 5]);
        list.replace(vec![[0, 1], [0, 2], [3, 4]], &r, &m, &Threads::serial());
        for (k, h) in list.hist.iter_mut().enumerate() {
            *h = k as f64 + 1.0;
            list.energy[k].fd_prev = 10.0 * (k as f64 + 1.0);
            list.energy[k].sums.friction = 1.0;
            list.active[k] = true;
        }
        // [0, 2] leaves, [1, 2] and [2, 3] arrive, the others stay.
        list.replace(vec![[0, 1], [1, 2], [2, 3], [3, 4]], &r, &m, &Threads::serial());
        assert_eq!(list.consts.len(), 4);
        assert_eq!(list.consts[1].r_star, 0.5);
        let kept: Vec<f64> = list.hist.clone();
        assert_eq!(kept, vec![1.0, 0.0, 0.0, 3.0]);
        let kept: Vec<f64> = list.energy.iter().map(|e| e.fd_prev).collect();
        assert_eq!(kept, vec![10.0, 0.0, 0.0, 30.0]);
        // The sums were the ledger's to take before the rebuild: all start at 0.
        assert!(list.energy.iter().all(|e| e.sums == EnergySums::default()));
        assert_eq!(list.touching(), 2);
    }

    #[test]
    fn checked_pairs_read_grain_values_and_refuse_short_arrays() {
        let mut list: PairList<f64> = PairList::default();
        let (r, m) = (vec![1.0; 6], vec![1.0; 6]);
        list.replace(vec![[0, 4], [1, 2], [2, 3]], &r, &m, &Threads::serial());
        let values = [10.0, 11.0, 12.0, 13.0, 14.0, 15.0];
        let checked = list.pairs.checked();
        assert_eq!(checked.of(&values).at(0), (10.0, 14.0));
        assert_eq!(checked.part(1..3).of(&values).at(1), (12.0, 13.0));
        // Grain 4 is listed: an array of four grains must be refused, not read past.
        let short = std::panic::catch_unwind(|| checked.of(&values[..4]).at(0));
        assert!(short.is_err());
    }
}
