//! Velocity Verlet for translation and rotation (LIGGGHTS `fix nve/sphere`).
//!
//! One step: `v += dt/2 F/m`, `x += dt v`, `w += dt/2 M/I` (initial half), then the
//! forces at the new positions, then `v += dt/2 F/m`, `w += dt/2 M/I` (final half).
//! The forces are therefore evaluated with the half-step velocities v(n+1/2), as in
//! LIGGGHTS and YADE: that is the velocity the damping and the tangential increment see.

use crate::contact::ContactLaw;
use crate::error::Error;
use crate::pipeline::Stage;
use crate::sim::World;

/// First half kick and drift of the free grains; `ROT` adds the spin half kick.
pub struct InitialIntegrate<const ROT: bool>;

impl<L: ContactLaw, const ROT: bool> Stage<L> for InitialIntegrate<ROT> {
    fn name(&self) -> String {
        if ROT { "VelocityVerlet(x, v, w)".into() } else { "VelocityVerlet(x, v)".into() }
    }
    fn run(&mut self, w: &mut World<L>) -> Result<(), Error> {
        let dt = w.dt;
        let dtf = 0.5 * dt;
        let p = &mut w.p;
        let n = p.n_free;
        for i in 0..n {
            let dtfm = dtf / p.m[i];
            p.v[i] += dtfm * p.f[i];
            p.x[i] += dt * p.v[i];
        }
        if ROT {
            for i in 0..n {
                p.omega[i] += dtf / p.inertia[i] * p.torque[i];
                p.theta[i] += dt * p.omega[i];
            }
        }
        Ok(())
    }
}

/// Second half kick of the free grains.
pub struct FinalIntegrate<const ROT: bool>;

impl<L: ContactLaw, const ROT: bool> Stage<L> for FinalIntegrate<ROT> {
    fn name(&self) -> String {
        "FinalKick".into()
    }
    fn run(&mut self, w: &mut World<L>) -> Result<(), Error> {
        let dtf = 0.5 * w.dt;
        let p = &mut w.p;
        for i in 0..p.n_free {
            let dtfm = dtf / p.m[i];
            p.v[i] += dtfm * p.f[i];
        }
        if ROT {
            for i in 0..p.n_free {
                p.omega[i] += dtf / p.inertia[i] * p.torque[i];
            }
        }
        Ok(())
    }
}
