//! Where a run's grains must stay, and what a run that goes wrong is told.
//!
//! The build sets the region from the scene's declared domain: between the walls (which
//! may move), in the periodic cell, or, where the scene declares no bound, around the
//! grains' first places by as far as the energy the scene starts with could carry the
//! lightest grain over the run, several times over. At every neighbour-list rebuild
//! (already a pass over all grains) the run checks that every grain is inside and that
//! none moved more than [`crate::engine::consistency::MAX_STEP_MOVE`] of the smallest radius in
//! one step; the watchdog checks overlaps every step and finite numbers every 100. A
//! run that fails a check stops with a diagnosis that names the grain, the step and the
//! likely cause ([`Context::likely_cause`]).

use std::marker::PhantomData;

use crate::physics::boundary::Boundary;
use crate::physics::dim::{Dim, Plane};
use crate::physics::particles::Particles;
use crate::physics::walls::{Control, Wall};

/// The region of a run, in the plane (the default `D`) or space.
#[derive(Clone, Debug, Default)]
pub struct Domain<D: Dim = Plane> {
    /// The x range grains must stay in, m; none when x is periodic.
    pub x: Option<[f64; 2]>,
    /// The y range without walls, m; with walls the grains stay between them.
    pub y: Option<[f64; 2]>,
    /// In space, the z range grains must stay in, m; none when z is periodic (and in
    /// the plane).
    pub z: Option<[f64; 2]>,
    /// How far beyond a wall's contact surface a grain may be, m (four largest radii: a
    /// grain there has passed through the wall).
    pub wall_margin: f64,
    /// The highest the top wall may rise, m (its start plus ten gaps).
    pub top_max: f64,
    /// The most a grain may move in one step, m.
    pub max_step: f64,
    pub dim: PhantomData<D>,
}

/// A check a run failed.
#[derive(Clone, Debug, PartialEq)]
pub enum Fault {
    /// Grain `grain` is outside the domain, at `at` (its coordinates, m).
    Left { grain: usize, at: Vec<f64> },
    /// Grain `grain` moved `moved` m in one step (at least).
    Jumped { grain: usize, moved: f64 },
    /// The top wall's contact surface is at or below the bottom wall's.
    WallsCrossed { gap: f64 },
    /// The top wall rose to `y`.
    WallEscaped { y: f64 },
}

impl<D: Dim> Domain<D> {
    /// The region of a built scene: `margin` is how far, m, a grain may travel from its
    /// first place where no wall or periodic cell bounds it.
    pub fn new(p: &Particles<D>, walls: &[Wall<D>], boundary: &Boundary<D>, margin: f64, max_step: f64) -> Self {
        let r_max = p.r.iter().cloned().fold(0.0, f64::max);
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for x in &p.x {
            for a in 0..D::D {
                lo[a] = lo[a].min(x[a]);
                hi[a] = hi[a].max(x[a]);
            }
        }
        let reach = margin + 4.0 * r_max;
        let x = (!boundary.is_periodic()).then_some([lo[0] - reach, hi[0] + reach]);
        let y = walls.is_empty().then_some([lo[1] - reach, hi[1] + reach]);
        let z = (D::D == 3 && !boundary.is_periodic_z()).then_some([lo[2] - reach, hi[2] + reach]);
        let top_max = match walls {
            [b, t] => t.y + 10.0 * (t.y - b.y).abs() + 10.0 * r_max,
            _ => f64::INFINITY,
        };
        Domain { x, y, z, wall_margin: 4.0 * r_max, top_max, max_step, dim: PhantomData }
    }

    /// Check the grains at a neighbour-list rebuild, against their positions `at_build`
    /// at the last one. The drift asks for a rebuild as soon as a grain has moved half the
    /// skin (`half_skin`), so a grain found further than that plus one step's largest move
    /// moved more than that in its last step.
    pub fn check(&self, p: &Particles<D>, walls: &[Wall<D>], at_build: &[D::Vector<f64>], boundary: &Boundary<D>, half_skin: f64) -> Option<Fault> {
        if let [b, t] = walls {
            let (bottom, top) = (b.contact_surface(), t.contact_surface());
            if !(top > bottom) {
                return Some(Fault::WallsCrossed { gap: top - bottom });
            }
            if !(t.y <= self.top_max) {
                return Some(Fault::WallEscaped { y: t.y });
            }
        }
        let (ylo, yhi) = match (self.y, walls) {
            (Some([a, b]), _) => (a, b),
            (None, [b, t]) => (b.contact_surface() - self.wall_margin, t.contact_surface() + self.wall_margin),
            _ => (f64::NEG_INFINITY, f64::INFINITY),
        };
        let [xlo, xhi] = self.x.unwrap_or([f64::NEG_INFINITY, f64::INFINITY]);
        let [zlo, zhi] = self.z.unwrap_or([f64::NEG_INFINITY, f64::INFINITY]);
        let inside = |x: &D::Vector<f64>| x[0] >= xlo && x[0] <= xhi && x[1] >= ylo && x[1] <= yhi && (D::D == 2 || (x[2] >= zlo && x[2] <= zhi));
        // One pass: a grain outside, or one further from its place at the last build than
        // half the skin and one step's most (squared, no root but for the message).
        let check_moves = at_build.len() == p.len();
        let limit = half_skin + self.max_step;
        let limit2 = limit * limit;
        for i in 0..p.len() {
            if i < p.n_free && !inside(&p.x[i]) {
                return Some(Fault::Left { grain: i, at: D::flat(std::slice::from_ref(&p.x[i])).to_vec() });
            }
            if check_moves {
                let far2 = D::norm_squared(boundary.image(p.x[i] - at_build[i]));
                if !(far2 <= limit2) {
                    return Some(Fault::Jumped { grain: i, moved: far2.sqrt() - half_skin });
                }
            }
        }
        None
    }
}


/// What the build knew that helps tell why a run went wrong.
#[derive(Clone, Debug, Default)]
pub struct Context {
    /// The largest overlap at the start, as a fraction of the smaller radius, between
    /// which grains, and the speed its stored energy would throw them apart at, m/s.
    pub start_overlap: Option<(f64, String, f64)>,
    /// The speed the time step was chosen for, m/s.
    pub characteristic_speed: f64,
    /// Hertz contact time of the reference contact, s.
    pub contact_time: f64,
    /// Stability limit of the time step, s.
    pub stability_limit: f64,
    /// The scene allowed a time step beyond the stability limit.
    pub allow_unstable: bool,
    /// The top wall's pressure, Pa, if it carries one.
    pub pressure: Option<f64>,
    /// The largest speed of a grain or wall at the start, m/s.
    pub start_speed: f64,
}

impl Context {
    /// The likely cause of a failed run, as advice: set-up, load and wall mass, gravity or
    /// the time step, from what the run looks like at `time` (s) and which grain
    /// (`grain`, if one is to blame) went wrong.
    #[allow(clippy::too_many_arguments)]
    pub fn likely_cause<D: Dim>(&self, p: &Particles<D>, walls: &[Wall<D>], gravity: D::Vector<f64>, dt: f64, time: f64, grain: Option<usize>, max_step: f64) -> String {
        // Set-up: grains created overlapping push apart in their first contact times, at
        // speeds far above those the time step was chosen for.
        if let Some((ratio, pair, release)) = &self.start_overlap
            && *release > 10.0 * self.characteristic_speed
            && time < 10.0 * self.contact_time
        {
            return format!(
                "the scene's grains start overlapping ({pair} overlap by {ratio:.2e} of a radius, enough to throw them apart at about {release:.3e} m/s, against the {} m/s the time step was chosen for). Start them apart (a lower grains.pack.packing_fraction, or listed grains further apart)",
                self.characteristic_speed
            );
        }
        // The load: a wall that moves more than a grain may in a step, or whose grain
        // went wrong.
        if let Some(pa) = self.pressure
            && let Some(w) = walls.iter().find(|w| matches!(w.control, Control::Load { .. }))
        {
            let wall_grain = grain.is_some_and(|g| matches!(&w.surface, crate::physics::walls::Surface::Rough { grains } if grains.contains(&g)));
            if wall_grain || w.v[1].abs() * dt > max_step {
                let accel = w.load_y().abs() / w.mass;
                return format!(
                    "the load on the {} wall: {pa} Pa on a wall of {:.3e} kg accelerates it by {accel:.3e} m/s^2 (it moves at {:.3e} m/s now). Raise walls.{}.mass or lower walls.{}.control.pressure",
                    w.name, w.mass, w.v[1], w.name, w.name
                );
            }
        }
        // Gravity: a grain falling freely (along gravity, as fast as a free fall since the
        // start) with nothing to stop it.
        if let Some(g) = grain.filter(|&g| g < p.n_free) {
            let falling = D::dot(p.v[g], gravity) > 0.0 && D::norm(p.v[g]) >= 0.5 * D::norm(gravity) * time;
            if D::flat(std::slice::from_ref(&gravity)).iter().any(|&g| g != 0.0) && falling && D::norm(p.v[g]) > 2.0 * self.start_speed {
                return format!(
                    "gravity: grain {g} has fallen freely to {:.3e} m/s ({:?} m/s^2 for {time:.3e} s), and nothing stops it. Add a wall across its path, or shorten the duration",
                    D::norm(p.v[g]),
                    D::flat(std::slice::from_ref(&gravity))
                );
            }
        }
        let ratio = dt / self.stability_limit;
        if self.allow_unstable && ratio > 1.0 {
            return format!(
                "the time step {dt:.3e} s is {ratio:.2} times the stability limit {:.3e} s (time_step.allow_unstable is set). Use more steps per contact",
                self.stability_limit
            );
        }
        // Grains far faster than the time step was chosen for: their contacts are shorter
        // than it assumed.
        let fastest = (0..p.n_free).map(|i| D::norm(p.v[i])).filter(|v| v.is_finite()).fold(0.0, f64::max);
        if fastest > 10.0 * self.characteristic_speed {
            return format!(
                "grains move at up to {fastest:.3e} m/s, {:.0} times the {} m/s the time step was chosen for: their contacts last far fewer steps than {:.1}. Find what accelerates them (a load, a wall, a material far softer or lighter than intended), or choose the time step for that speed (time_step.characteristic_speed, or the rule's impact_speed)",
                fastest / self.characteristic_speed,
                self.characteristic_speed,
                self.contact_time / dt
            );
        }
        format!(
            "the contact forces grew faster than the time step {dt:.3e} s ({:.1} steps per contact, {ratio:.2} of the stability limit) resolves them. Use a smaller time step (more steps per contact); if it persists, look for grains set up overlapping, a load too large for the wall's mass, or a wall too fast",
            self.contact_time / dt
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::dim::Vec2;

    fn two_grains() -> Particles {
        let mut p = Particles::default();
        for x in [-1e-3, 1e-3] {
            p.push(Vec2::new(x, 0.0), Vec2::zeros(), 0.0, 1e-3, 1e-5, 4e-12, 0);
        }
        p.n_free = 2;
        p
    }

    #[test]
    fn a_grain_outside_or_one_that_jumped_is_found_and_named() {
        let mut p = two_grains();
        let b = Boundary::open();
        // Margin 1 cm: the region is x in [-1e-3 - 1.4e-2, 1e-3 + 1.4e-2] (four radii more).
        let d = Domain::new(&p, &[], &b, 0.01, 5e-5);
        let at = p.x.clone();
        assert_eq!(d.check(&p, &[], &at, &b, 2e-4), None);
        // Just inside, then just outside, in x and in y.
        p.x[1].x = 1e-3 + 0.014 - 1e-9;
        assert_eq!(d.check(&p, &[], &[], &b, 2e-4), None);
        p.x[1].x = 1e-3 + 0.014 + 1e-9;
        assert_eq!(d.check(&p, &[], &[], &b, 2e-4), Some(Fault::Left { grain: 1, at: vec![p.x[1].x, p.x[1].y] }));
        p.x[1] = Vec2::new(1e-3, -0.02);
        assert!(matches!(d.check(&p, &[], &[], &b, 2e-4), Some(Fault::Left { grain: 1, .. })));
        // A NaN position is outside everything.
        p.x[1] = Vec2::new(f64::NAN, 0.0);
        assert!(matches!(d.check(&p, &[], &[], &b, 2e-4), Some(Fault::Left { grain: 1, .. })));
        // Moved half the skin plus a little less, then a little more, than one step's most.
        let mut q = two_grains();
        q.x[0].x += 2e-4 + 4.9e-5;
        assert_eq!(d.check(&q, &[], &at, &b, 2e-4), None);
        q.x[0].x += 2e-6;
        match d.check(&q, &[], &at, &b, 2e-4) {
            Some(Fault::Jumped { grain: 0, moved }) => assert!((moved - 5.1e-5).abs() < 1e-12, "{moved}"),
            other => panic!("{other:?}"),
        }
    }
}
