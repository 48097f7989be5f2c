//! Velocity Verlet for translation and rotation (LIGGGHTS `fix nve/sphere`).
//!
//! One step: `v += dt/2 F/m`, `x += dt v`, `w += dt/2 M/I` (initial half), then the
//! forces at the new positions, then `v += dt/2 F/m`, `w += dt/2 M/I` (final half).
//! The forces are therefore evaluated with the half-step velocities v(n+1/2), as in
//! LIGGGHTS and YADE: that is the velocity the damping and the tangential increment see.

use std::sync::atomic::{AtomicBool, Ordering};

use crate::contact::ContactLaw;
use crate::dim::Vec2;
use crate::neighbor::Neighbours;
use crate::error::Error;
use crate::particles::Particles;
use crate::pipeline::Stage;
use crate::sim::World;
use crate::walls::Glued;

/// The half-kick factors `dt/2 / m` and `dt/2 / I` of the free grains, divided out once
/// per time step value instead of at every step (the same division, so the same bits as
/// LIGGGHTS' `dtfm = dtf / rmass[i]`). One set per world (`World::kick`), shared by both
/// half kicks.
#[derive(Default)]
pub struct KickFactors {
    dt: f64,
    /// dt/2 / m, s/kg.
    pub dtfm: Vec<f64>,
    /// dt/2 / I, s/(kg m^2).
    pub dtfi: Vec<f64>,
}

impl KickFactors {
    /// Recompute for time step `dt` if it (or the number of free grains) changed.
    pub fn update(&mut self, p: &Particles, dt: f64) {
        let n = p.n_free;
        if self.dt != dt || self.dtfm.len() != n {
            let dtf = 0.5 * dt;
            self.dt = dt;
            self.dtfm = p.m[..n].iter().map(|m| dtf / m).collect();
            self.dtfi = p.inertia[..n].iter().map(|i| dtf / i).collect();
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
/// walls themselves have moved in [`crate::pipeline::MoveWalls`] just before), on the
/// thread that owns them in the contact stage: its cache has them, and a serial stage
/// would have to fetch them from there.
#[derive(Default)]
pub struct InitialIntegrate<const ROT: bool> {
    /// Stands in for the positions at the last build before there is a build.
    origin: Vec<Vec2>,
    /// The rough walls' grains and their moves this step.
    glued: Vec<Glued>,
}

impl<L: ContactLaw, const ROT: bool> Stage<L> for InitialIntegrate<ROT> {
    fn name(&self) -> String {
        if ROT { "VelocityVerlet(x, v, w)".into() } else { "VelocityVerlet(x, v)".into() }
    }
    fn run(&mut self, w: &mut World<L>) -> Result<(), Error> {
        let dt = w.dt;
        let p = &mut w.p;
        let (n, n_free) = (p.len(), p.n_free);
        let k = &mut w.kick;
        k.update(p, dt);
        let (b, limit) = (w.boundary, w.neighbours.limit());
        let listed = w.neighbours.at_build().len() == n;
        if !listed {
            // No list yet: the next stage builds one whatever this pass finds.
            self.origin.resize(n, Vec2::zeros());
        }
        let at = if listed { w.neighbours.at_build() } else { &self.origin[..] };
        self.glued.clear();
        self.glued.extend(w.walls.iter().filter_map(|wall| Glued::of(wall, dt)));
        let glued = &self.glued;
        let far = AtomicBool::new(false);
        let translation = (&mut p.v[..], &mut p.x[..], &mut p.f[..], at, &k.dtfm[..]);
        let rotation = (&mut p.torque[..], &mut p.omega[..n_free], &k.dtfi[..]);
        w.threads.split_free(n_free, n, (translation, rotation), |range, ((v, x, f, at, dtfm), (torque, omega, dtfi))| {
            // The free grains of this part, then the glued ones.
            let nf = dtfm.len();
            let (v, vg) = v.split_at_mut(nf);
            let (x, xg) = x.split_at_mut(nf);
            let (f, fg) = f.split_at_mut(nf);
            let (torque, tg) = torque.split_at_mut(nf);
            let (at, atg) = at.split_at(nf);
            // Where the build has AVX-512, eight grains at a time first (the same bits).
            #[cfg(all(target_arch = "x86_64", target_feature = "avx512f", target_feature = "avx512vl", target_feature = "avx512bw"))]
            let (from, mut far_here, out) = {
                let g = crate::avx512::GrainPart { v: &mut *v, f: &mut *f, dtfm, omega: &mut *omega, torque: &mut *torque, dtfi };
                crate::avx512::drift::<ROT>(g, &mut *x, at, dt, &b, limit)
            };
            #[cfg(not(all(target_arch = "x86_64", target_feature = "avx512f", target_feature = "avx512vl", target_feature = "avx512bw")))]
            let (from, mut far_here, out) = (0, false, false);
            for (((v, x), f), m) in v[from..].iter_mut().zip(x[from..].iter_mut()).zip(&f[from..]).zip(&dtfm[from..]) {
                *v += *m * *f;
                *x += dt * *v;
            }
            // The forces (and torques) are used: zero for the step's contacts to add to.
            f[from..].fill(Vec2::zeros());
            if ROT {
                for ((w, t), m) in omega[from..].iter_mut().zip(&torque[from..]).zip(&dtfi[from..]) {
                    *w += *m * *t;
                }
                torque[from..].fill(0.0);
            }
            // Back into the periodic cell: rarely anyone to bring back, so one check of
            // all first (the wrap itself is a chain of roundings per grain).
            let mut watch = from;
            if out || b.any_outside(&x[from..]) {
                x.iter_mut().for_each(|x| b.wrap(x));
                (far_here, watch) = (false, 0);
            }
            far_here = far_here || Neighbours::moved(&x[watch..], &at[watch..], &b, limit);
            // The glued grains: their forces are cleared here too.
            let g0 = range.start + nf;
            for g in glued {
                let (lo, hi) = (g.grains.start.max(g0), g.grains.end.min(range.end));
                if lo < hi {
                    let part = lo - g0..hi - g0;
                    far_here |= g.follow(&mut xg[part.clone()], &mut vg[part.clone()], &atg[part], &b, limit);
                }
            }
            fg.fill(Vec2::zeros());
            if ROT {
                tg.fill(0.0);
            }
            if far_here {
                far.store(true, Ordering::Relaxed);
            }
        });
        w.neighbours.moved_far |= far.into_inner();
        w.zeroed = crate::sim::Zeroed { forces: n, torques: if ROT { n } else { 0 } };
        Ok(())
    }
}

/// Second half kick of the free grains.
#[derive(Default)]
pub struct FinalIntegrate<const ROT: bool>;

impl<L: ContactLaw, const ROT: bool> Stage<L> for FinalIntegrate<ROT> {
    fn name(&self) -> String {
        "FinalKick".into()
    }
    fn run(&mut self, w: &mut World<L>) -> Result<(), Error> {
        let p = &mut w.p;
        let n = p.n_free;
        let k = &mut w.kick;
        k.update(p, w.dt);
        let rotation = (&mut p.omega[..n], &mut p.torque[..n], &k.dtfi[..]);
        w.threads.split(n, ((&mut p.v[..n], &mut p.f[..n], &k.dtfm[..]), rotation), |((v, f, dtfm), (omega, torque, dtfi))| {
            #[cfg(all(target_arch = "x86_64", target_feature = "avx512f", target_feature = "avx512vl", target_feature = "avx512bw"))]
            let from = crate::avx512::kick::<ROT>(crate::avx512::GrainPart { v: &mut *v, f: &mut *f, dtfm, omega: &mut *omega, torque: &mut *torque, dtfi });
            #[cfg(not(all(target_arch = "x86_64", target_feature = "avx512f", target_feature = "avx512vl", target_feature = "avx512bw")))]
            let from = 0;
            for ((v, f), m) in v[from..].iter_mut().zip(&f[from..]).zip(&dtfm[from..]) {
                *v += *m * *f;
            }
            if ROT {
                for ((w, t), m) in omega[from..].iter_mut().zip(&torque[from..]).zip(&dtfi[from..]) {
                    *w += *m * *t;
                }
            }
        });
        Ok(())
    }
}
