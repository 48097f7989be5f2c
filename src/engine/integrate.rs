//! Velocity Verlet for translation and rotation (LIGGGHTS `fix nve/sphere`).
//!
//! One step: `v += dt/2 F/m`, `x += dt v`, `w += dt/2 M/I` (initial half), then the
//! forces at the new positions, then `v += dt/2 F/m`, `w += dt/2 M/I` (final half).
//! The forces are therefore evaluated with the half-step velocities v(n+1/2), as in
//! LIGGGHTS and YADE: that is the velocity the damping and the tangential increment see.
//!
//! The final half kick of a step and the first of the next use the same forces, so when
//! nothing looks at the grains in between, the final one is left to the next drift
//! ([`crate::engine::world::KickFactors::defer`]): one pass over the grains' arrays instead of two, and the same
//! two roundings per grain (`v += dt/2 F/m` twice, never `v += dt F/m`), so the same bits.

use std::sync::atomic::{AtomicBool, Ordering};

use crate::engine::world::{PendingKick, Stage, World};
use crate::error::Error;
use crate::physics::contact::ContactLaw;
use crate::physics::dim::{Dim, Plane};
use crate::physics::walls::Glued;

/// Give the final half kick left pending ([`crate::engine::world::KickFactors::pending`]), if any: the
/// velocities and spins are then those of the end of the step.
pub fn settle<L: ContactLaw>(w: &mut World<L>) {
    if let Some(k) = w.kick.pending.take() {
        if k.spin {
            kick_free::<L, true>(w, k.dt);
        } else {
            kick_free::<L, false>(w, k.dt);
        }
    }
}

/// First half kick and drift of the free grains; `ROT` adds the spin half kick. Then
/// back into the periodic cell, and the neighbour list's watch (has a grain moved more
/// than half the skin since the last build?): with AVX-512 in the same pass. The forces
/// (and torques) it has used are set to zero there ([`World::zeroed`]): the step's
/// contact stage adds the new ones, and `ClearForces` need not pass over them again.
///
/// The rough walls' grains follow their walls in the same pass ([`Glued::follow`]; the
/// walls themselves have moved in [`crate::engine::stages::MoveWalls`] just before), on the
/// last thread, whose part of the grains ends with them: no serial stage of their own.
/// (In the contact stage the first thread adds their forces; moving their zeroing to it,
/// in `ClearForces`, timed the same at 100 000 grains.)
#[derive(Default)]
pub struct InitialIntegrate<const ROT: bool, D: Dim = Plane> {
    /// Stands in for the positions at the last build before there is a build.
    origin: Vec<D::Vector<f64>>,
    /// The rough walls' grains and their moves this step.
    glued: Vec<Glued<D>>,
}

impl<L: ContactLaw<D = D>, D: Dim, const ROT: bool> Stage<L> for InitialIntegrate<ROT, D> {
    fn name(&self) -> String {
        if ROT { "VelocityVerlet(x, v, w)".into() } else { "VelocityVerlet(x, v)".into() }
    }
    fn run(&mut self, w: &mut World<L>) -> Result<(), Error> {
        let dt = w.dt;
        // The last step's final half kick, if it was left to this pass (with the factors
        // of this step, which it shares; else it is given on its own first).
        if w.kick.pending.is_some_and(|k| k.dt != dt || k.spin != ROT) {
            settle(w);
        }
        let twice = w.kick.pending.take().is_some();
        let p = &mut w.p;
        let (n, n_free) = (p.len(), p.n_free);
        let k = &mut w.kick;
        k.update(p, dt);
        let (b, limit) = (w.boundary, w.neighbours.limit());
        let listed = w.neighbours.at_build().len() == n;
        if !listed {
            // No list yet: the next stage builds one whatever this pass finds.
            self.origin.resize(n, D::zero());
        }
        let at = if listed { w.neighbours.at_build() } else { &self.origin[..] };
        self.glued.clear();
        self.glued.extend(w.walls.iter().filter_map(|wall| Glued::of(wall, dt)));
        let glued = &self.glued;
        let far = AtomicBool::new(false);
        let translation = (&mut p.v[..], &mut p.x[..], &mut p.f[..], at, (&k.dtfm[..], &k.dtfm2[..]));
        let rotation = (&mut p.torque[..], &mut p.omega[..n_free], &k.dtfi[..]);
        w.threads.split_free(n_free, n, (translation, rotation), |range, ((v, x, f, at, (dtfm, dtfm2)), (torque, omega, dtfi))| {
            // The free grains of this part, then the glued ones.
            let nf = dtfm.len();
            let (v, vg) = v.split_at_mut(nf);
            let (x, xg) = x.split_at_mut(nf);
            let (f, fg) = f.split_at_mut(nf);
            let (torque, tg) = torque.split_at_mut(nf);
            let (at, atg) = at.split_at(nf);
            // Where the build has AVX-512, eight grains at a time first (the same bits),
            // with the pending kick in the same pass: in the plane.
            #[cfg(all(target_arch = "x86_64", target_feature = "avx512f", target_feature = "avx512vl", target_feature = "avx512bw"))]
            let (from, mut far_here, out) = match (D::plane_vectors_mut(v), D::plane_vectors_mut(f), D::plane_spins_mut(omega), D::plane_spins_mut(torque), D::plane_spins(dtfi), D::plane_vectors_mut(x), D::plane_vectors(at), b.plane()) {
                (Some(v), Some(f), Some(omega), Some(torque), Some(dtfi), Some(x), Some(at), Some(b)) => {
                    let g = crate::kernels::avx512::GrainPart { v, f, dtfm, omega, torque, dtfi };
                    if twice {
                        crate::kernels::avx512::drift::<ROT, true>(g, x, at, dt, &b, limit)
                    } else {
                        crate::kernels::avx512::drift::<ROT, false>(g, x, at, dt, &b, limit)
                    }
                }
                _ => (0, false, false),
            };
            #[cfg(not(all(target_arch = "x86_64", target_feature = "avx512f", target_feature = "avx512vl", target_feature = "avx512bw")))]
            let (from, mut far_here, out) = {
                let _ = dtfm;
                (0, false, false)
            };
            let part = (&mut v[from..], &mut x[from..], &mut f[from..], &dtfm2[from..]);
            let spin = (&mut omega[from..], &mut torque[from..], &dtfi[from..]);
            if twice {
                drift_free::<D, ROT, true>(part, spin, dt);
            } else {
                drift_free::<D, ROT, false>(part, spin, dt);
            }
            // Back into the periodic cell: rarely anyone to bring back, so one check of
            // all first (the wrap itself is a chain of roundings per grain).
            let mut watch = from;
            if out || b.any_outside(&x[from..]) {
                x.iter_mut().for_each(|x| b.wrap(x));
                (far_here, watch) = (false, 0);
            }
            far_here = far_here || b.any_moved_beyond(&x[watch..], &at[watch..], limit);
            // The glued grains: their forces are cleared here too.
            let g0 = range.start + nf;
            for g in glued {
                let (lo, hi) = (g.grains.start.max(g0), g.grains.end.min(range.end));
                if lo < hi {
                    let part = lo - g0..hi - g0;
                    far_here |= g.follow(&mut xg[part.clone()], &mut vg[part.clone()], &atg[part], &b, limit);
                }
            }
            fg.fill(D::zero());
            if ROT {
                tg.fill(D::spin_zero());
            }
            if far_here {
                far.store(true, Ordering::Relaxed);
            }
        });
        w.neighbours.moved_far |= far.into_inner();
        w.zeroed = crate::engine::world::Zeroed { forces: n, torques: if ROT { n } else { 0 } };
        Ok(())
    }
}

/// The grains' velocities, positions, forces and the kick factors of their components
/// ([`crate::engine::world::crate::engine::world::KickFactors::dtfm2`]), in the plane or space.
type Translation<'a, D> = (&'a mut [<D as Dim>::Vector<f64>], &'a mut [<D as Dim>::Vector<f64>], &'a mut [<D as Dim>::Vector<f64>], &'a [<D as Dim>::Vector<f64>]);
/// The grains' spins, torques and the kick factors of their components.
type Rotation<'a, D> = (&'a mut [<D as Dim>::Spin<f64>], &'a mut [<D as Dim>::Spin<f64>], &'a [<D as Dim>::Spin<f64>]);

/// The first half kick (after the pending final one of the last step when `TWICE`) and
/// the drift of free grains; their forces (and torques) are then used, and set to zero
/// for the step's contacts to add to. Written once for the plane and space: component
/// by component, so the same loop for both ([`crate::engine::world::KickFactors::dtfm2`]).
#[inline(always)]
pub fn drift_free<D: Dim, const ROT: bool, const TWICE: bool>((v, x, f, dtfm2): Translation<'_, D>, (omega, torque, dtfi): Rotation<'_, D>, dt: f64) {
    let (vc, xc, fc, mc) = (D::flat_mut(v), D::flat_mut(x), D::flat(f), D::flat(dtfm2));
    for (((v, x), f), m) in vc.iter_mut().zip(xc.iter_mut()).zip(fc).zip(mc) {
        if TWICE {
            *v += *m * *f;
        }
        *v += *m * *f;
        *x += dt * *v;
    }
    f.fill(D::zero());
    if ROT {
        for ((w, t), m) in D::spin_flat_mut(omega).iter_mut().zip(D::spin_flat(torque)).zip(D::spin_flat(dtfi)) {
            if TWICE {
                *w += *m * *t;
            }
            *w += *m * *t;
        }
        torque.fill(D::spin_zero());
    }
}

/// A half kick of free grains `v` (and with `ROT` their spins `omega`) from their forces
/// `f` and torques, component by component; written once for the plane and space.
#[inline(always)]
pub fn kick_components<D: Dim, const ROT: bool>(v: &mut [D::Vector<f64>], f: &[D::Vector<f64>], dtfm2: &[D::Vector<f64>], (omega, torque, dtfi): (&mut [D::Spin<f64>], &[D::Spin<f64>], &[D::Spin<f64>])) {
    for ((v, f), m) in D::flat_mut(v).iter_mut().zip(D::flat(f)).zip(D::flat(dtfm2)) {
        *v += *m * *f;
    }
    if ROT {
        for ((w, t), m) in D::spin_flat_mut(omega).iter_mut().zip(D::spin_flat(torque)).zip(D::spin_flat(dtfi)) {
            *w += *m * *t;
        }
    }
}

/// A half kick of free grains `v` (and with `ROT` their spins `omega`) from their forces
/// and torques; in the plane with AVX-512 eight grains at a time first.
fn kick_part<D: Dim, const ROT: bool>(v: &mut [D::Vector<f64>], f: &mut [D::Vector<f64>], (dtfm, dtfm2): (&[f64], &[D::Vector<f64>]), omega: &mut [D::Spin<f64>], torque: &mut [D::Spin<f64>], dtfi: &[D::Spin<f64>]) {
    #[cfg(all(target_arch = "x86_64", target_feature = "avx512f", target_feature = "avx512vl", target_feature = "avx512bw"))]
    let from = match (D::plane_vectors_mut(v), D::plane_vectors_mut(f), D::plane_spins_mut(omega), D::plane_spins_mut(torque), D::plane_spins(dtfi)) {
        (Some(v), Some(f), Some(omega), Some(torque), Some(dtfi)) => crate::kernels::avx512::kick::<ROT>(crate::kernels::avx512::GrainPart { v, f, dtfm, omega, torque, dtfi }),
        _ => 0,
    };
    #[cfg(not(all(target_arch = "x86_64", target_feature = "avx512f", target_feature = "avx512vl", target_feature = "avx512bw")))]
    let from = {
        let _ = dtfm;
        0
    };
    kick_components::<D, ROT>(&mut v[from..], &f[from..], &dtfm2[from..], (&mut omega[from..], &torque[from..], &dtfi[from..]));
}

/// The half kick of all free grains for time step `dt`, on the run's threads.
fn kick_free<L: ContactLaw, const ROT: bool>(w: &mut World<L>, dt: f64) {
    let p = &mut w.p;
    let n = p.n_free;
    let k = &mut w.kick;
    k.update(p, dt);
    let rotation = (&mut p.omega[..n], &mut p.torque[..n], &k.dtfi[..]);
    w.threads.split(n, ((&mut p.v[..n], &mut p.f[..n], (&k.dtfm[..], &k.dtfm2[..])), rotation), |((v, f, dtfm), (omega, torque, dtfi))| kick_part::<L::D, ROT>(v, f, dtfm, omega, torque, dtfi));
}

/// Second half kick of the free grains, or left to the next drift when nothing looks at
/// the grains before it ([`crate::engine::world::KickFactors::defer`]).
#[derive(Default)]
pub struct FinalIntegrate<const ROT: bool>;

impl<L: ContactLaw, const ROT: bool> Stage<L> for FinalIntegrate<ROT> {
    fn name(&self) -> String {
        "FinalKick".into()
    }
    fn run(&mut self, w: &mut World<L>) -> Result<(), Error> {
        if w.kick.defer {
            w.kick.pending = Some(PendingKick { dt: w.dt, spin: ROT });
        } else {
            kick_free::<L, ROT>(w, w.dt);
        }
        Ok(())
    }
}
