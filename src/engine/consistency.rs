//! Geometry and consistency of a scene's grains, walls and time step, checked by the
//! build before the engine is allocated: where grains sit against the walls and against
//! each other, how far one moves in a step, whether the load is one the grains can carry
//! and the wall can follow, whether an impact can happen at all. Each refusal names the
//! field (its JSON path), the value and what would be allowed.

use crate::error::{Error, Shown, shown_joined};
use crate::physics::boundary::Boundary;
use crate::physics::dim::Dim;
use crate::physics::material::{Material, PairMaterial};
use crate::physics::particles::Particles;
use crate::physics::walls::{Control, Surface, Wall};
use crate::scene::{Analysis, ControlSpec, Grains, Scene};

/// Largest overlap at the start, as a fraction of the smaller radius, that a scene's
/// grains may have: the watchdog's bound (the run would stop at its first step).
pub const MAX_START_OVERLAP: f64 = 0.1;

pub use crate::scene::limits::MAX_PACKING_OVERLAP;

/// Largest distance a grain, a grain's surface (spin) or a wall may move in one step, as
/// a fraction of the smallest free grain's radius: two grains meeting at this speed
/// overlap by at most 0.1 of a radius after their first step in contact, the watchdog's
/// bound. Physical time steps move grains by 1e-3 of a radius or less (50 m/s impacts at
/// 50 steps per contact).
pub const MAX_STEP_MOVE: f64 = 0.05;

/// Largest overlap, as a fraction of a mean radius, that the load on a wall may press
/// into its contacts (estimated from Hertz: a contact per grain diameter along the wall).
/// The shear cell's 100 kPa on glass gives 5e-4.
pub const MAX_LOAD_OVERLAP: f64 = 0.05;

/// How to name grain i of a built scene in a message.
pub enum GrainNames {
    /// `grains.list[i]`.
    List,
    /// The grain file's path, and the line of each grain.
    File(String, Vec<u32>),
    /// Grains of a packing (stored along a Z curve, so by their storage index).
    Pack,
}

impl GrainNames {
    pub fn of(scene: &Scene) -> Self {
        match &scene.grains {
            Grains::List(_) => GrainNames::List,
            Grains::File { path, .. } => GrainNames::File(path.clone(), Vec::new()),
            Grains::Pack(_) => GrainNames::Pack,
        }
    }
    /// The name of grain `i` (free grains first, then the rough walls' grains).
    pub fn name<D: Dim>(&self, i: usize, p: &Particles<D>, walls: &[Wall<D>]) -> String {
        if i >= p.n_free {
            let wall = walls.iter().find(|w| matches!(&w.surface, Surface::Rough { grains } if grains.contains(&i)));
            return match wall {
                Some(w) => format!("a grain of the {} wall (walls.{}.y)", w.name, w.name),
                None => format!("grain {i}"),
            };
        }
        match self {
            GrainNames::List => format!("grains.list[{i}]"),
            GrainNames::File(path, lines) => match lines.get(i) {
                Some(l) => format!("the grain on line {l} of {path}"),
                None => format!("grain {i} of {path}"),
            },
            GrainNames::Pack => format!("packed grain {i}"),
        }
    }
    /// The JSON path of a free grain's field (`v`, `omega`), for refusals.
    fn field(&self, i: usize, field: &str) -> String {
        match self {
            GrainNames::List => format!("grains.list[{i}].{field}"),
            _ => format!("grains[{i}].{field}"),
        }
    }
}

fn refuse(field: impl Into<String>, value: impl std::fmt::Display, allowed: impl Into<String>) -> Error {
    Error::Invalid { field: field.into(), value: value.to_string(), allowed: allowed.into() }
}

/// Every coordinate within [`crate::scene::limits::MAX_COORDINATE_RADII`] largest radii of the
/// origin.
pub fn coordinates<D: Dim>(scene: &Scene, p: &Particles<D>, names: &GrainNames, walls: &[Wall<D>]) -> Result<(), Error> {
    let r_max = p.r.iter().cloned().fold(0.0, f64::max);
    let bound = crate::scene::limits::MAX_COORDINATE_RADII * r_max;
    let allowed = || format!("within {bound:e} m of the origin ({:e} largest radii: further out, rounding reaches the overlaps the contact law resolves)", crate::scene::limits::MAX_COORDINATE_RADII);
    if let Some(i) = (0..p.len()).find(|&i| !(0..D::D).all(|k| p.x[i][k].abs() <= bound)) {
        return Err(refuse(names.name(i, p, walls), format!("at ({}) m", point::<D>(p.x[i])), allowed()));
    }
    if let Some([a, b]) = scene.domain.periodic_x
        && !(a.abs() <= bound && b.abs() <= bound)
    {
        return Err(refuse("domain.periodic_x", format!("[{}, {}]", a.shown(), b.shown()), allowed()));
    }
    for w in walls {
        if w.y.abs() > bound {
            return Err(refuse(format!("walls.{}.y", w.name), w.y.shown(), allowed()));
        }
    }
    Ok(())
}

/// Grains given by the scene (listed, or read from a file), as (centre, radius), within
/// [`crate::scene::limits::MAX_COORDINATE_RADII`] largest radii of the origin: checked before
/// anything is sized from where they lie (the rough walls span their extent).
pub fn given_coordinates<'a>(grains: impl Iterator<Item = (&'a [f64], f64)> + Clone, name: impl Fn(usize) -> String) -> Result<(), Error> {
    let r_max = grains.clone().map(|g| g.1).fold(0.0, f64::max);
    let bound = crate::scene::limits::MAX_COORDINATE_RADII * r_max;
    match grains.enumerate().find(|(_, (x, _))| !x.iter().all(|c| c.abs() <= bound)) {
        Some((k, (x, _))) => Err(refuse(
            name(k),
            format!("at ({}) m", shown_joined(x)),
            format!("within {bound:e} m of the origin ({:e} largest radii: further out, rounding reaches the overlaps the contact law resolves)", crate::scene::limits::MAX_COORDINATE_RADII),
        )),
        None => Ok(()),
    }
}

/// Masses and moments of inertia finite and positive (a radius or density at the edge of
/// the floating-point range gives 0 or infinity).
pub fn masses<D: Dim>(p: &Particles<D>, names: &GrainNames, walls: &[Wall<D>], mats: &[Material]) -> Result<(), Error> {
    match (0..p.len()).find(|&i| !(p.m[i].is_finite() && p.m[i] > 0.0 && p.inertia[i].is_finite() && p.inertia[i] > 0.0)) {
        Some(i) => Err(refuse(
            names.name(i, p, walls),
            format!("radius {} m, density {} kg/m^3: mass {} kg", p.r[i], mats[p.material[i] as usize].density, p.m[i]),
            "a radius and density whose mass and moment of inertia are finite and > 0",
        )),
        None => Ok(()),
    }
}

/// The periodic cell must be at least two grain diameters long: below, a grain could
/// touch another through two of its images, which the minimum image cannot see.
pub fn periodic_cell<D: Dim>(boundary: &Boundary<D>, p: &Particles<D>) -> Result<(), Error> {
    let r_max = p.r.iter().cloned().fold(0.0, f64::max);
    if boundary.is_periodic() && boundary.period < 4.0 * r_max {
        let (a, b) = (boundary.x_min, boundary.x_min + boundary.period);
        return Err(refuse("domain.periodic_x", format!("[{a}, {b}]"), format!("a cell at least 4 r_max = {} m long (two diameters of the largest grain)", 4.0 * r_max)));
    }
    if boundary.is_periodic()
        && let Some(i) = (0..p.n_free).find(|&i| !(p.x[i][0] >= boundary.x_min && p.x[i][0] <= boundary.x_min + boundary.period))
    {
        return Err(refuse(
            "domain.periodic_x",
            format!("[{}, {}]", boundary.x_min, boundary.x_min + boundary.period),
            format!("a periodic cell that holds every grain (grain {i} is at x = {} m)", p.x[i][0]),
        ));
    }
    // Along z in space, alike.
    if boundary.is_periodic_z() {
        let (a, b) = (boundary.z_min, boundary.z_min + boundary.z_period);
        if boundary.z_period < 4.0 * r_max {
            return Err(refuse("domain.periodic_z", format!("[{a}, {b}]"), format!("a cell at least 4 r_max = {} m long (two diameters of the largest grain)", 4.0 * r_max)));
        }
        if let Some(i) = (0..p.n_free).find(|&i| !(p.x[i][D::D - 1] >= a && p.x[i][D::D - 1] <= b)) {
            return Err(refuse("domain.periodic_z", format!("[{a}, {b}]"), format!("a periodic cell that holds every grain (grain {i} is at z = {} m)", p.x[i][D::D - 1])));
        }
    }
    Ok(())
}

/// Grains on the right side of each wall (a flat wall's plane, a rough wall's line of
/// glued grains) and not overlapping a flat wall, nor each other (nor a rough wall's
/// grains), by more than `bound` of the smaller radius. A packing that keeps more is
/// refused by its packing fraction, with the fix. Returns the largest overlap there is
/// (grains i, j and the fraction), for the diagnosis of a run that goes wrong.
pub fn start_overlaps<D: Dim>(p: &Particles<D>, walls: &[Wall<D>], boundary: &Boundary<D>, names: &GrainNames, bound: f64, scene: &Scene) -> Result<Option<(usize, usize, f64)>, Error> {
    for w in walls {
        for i in 0..p.n_free {
            let gap = w.side * (p.x[i][1] - w.y);
            let side = if w.side > 0.0 { "below" } else { "above" };
            if gap < 0.0 {
                let what = if w.is_flat() { "plane" } else { "glued grains' centres" };
                return Err(refuse(format!("walls.{}.y", w.name), w.y.shown(), format!("a wall whose {what} lie {side} every grain's centre ({} is at y = {} m)", names.name(i, p, walls), p.x[i][1].shown())));
            }
            let ratio = (p.r[i] - gap) / p.r[i];
            if w.is_flat() && ratio > bound {
                return Err(refuse(
                    format!("walls.{}.y", w.name),
                    w.y.shown(),
                    format!("a wall that {} overlaps by at most {bound} of its radius at the start (it overlaps it by {ratio:.3})", names.name(i, p, walls)),
                ));
            }
        }
    }
    let worst = crate::kernels::cells::largest_overlap(&p.x, &p.r, p.n_free, boundary, bound);
    if let Some((i, j, ratio)) = worst
        && ratio > bound
    {
        if let (GrainNames::Pack, Grains::Pack(spec)) = (names, &scene.grains)
            && i < p.n_free
            && j < p.n_free
        {
            return Err(refuse(
                "grains.pack.packing_fraction",
                spec.packing_fraction,
                format!(
                    "a packing the relaxation frees of overlaps: after its sweeps (at most {}) two grains still overlap by {ratio:.2e} of the smaller radius, more than {bound}. Use a lower packing_fraction (0.7 relaxes fully), or a narrower radius distribution",
                    crate::scene::pack::MAX_SWEEPS
                ),
            ));
        }
        return Err(refuse(
            names.name(i, p, walls),
            format!("at ({}) m", point::<D>(p.x[i])),
            format!("grains that overlap by at most {bound} of the smaller radius at the start ({} overlaps it by {ratio:.3})", names.name(j, p, walls)),
        ));
    }
    Ok(worst)
}

/// The most anything may move in one step of `dt`: [`MAX_STEP_MOVE`] of the smallest
/// free grain's radius.
struct StepBound {
    most: f64,
    dt: f64,
}

impl StepBound {
    fn of<D: Dim>(p: &Particles<D>, dt: f64) -> StepBound {
        let r_min = p.r[..p.n_free].iter().cloned().fold(f64::INFINITY, f64::min);
        StepBound { most: MAX_STEP_MOVE * r_min, dt }
    }

    /// `Err` (field `field`, value `value`) when `what` moves `step` m in a step, more
    /// than the bound.
    fn check(&self, field: impl Into<String>, value: String, what: &str, step: f64) -> Result<(), Error> {
        let (most, dt) = (self.most, self.dt);
        if step <= most {
            return Ok(());
        }
        Err(refuse(
            field,
            value,
            format!(
                "{what} of at most {most:.3e} m per step ({MAX_STEP_MOVE} of the smallest radius) at dt = {dt:.3e} s; it moves {step:.3e} m: the contact could not be resolved. Use a smaller time step (more steps per contact) or a lower speed"
            ),
        ))
    }

    /// A wall at velocity `v`, set at `field` (its x velocity's path; the value names the
    /// y velocity too when the wall has one).
    fn wall<D: Dim>(&self, field: String, v: D::Vector<f64>) -> Result<(), Error> {
        let value = if (1..D::D).all(|k| v[k] == 0.0) { v[0].shown().to_string() } else { format!("[{}] m/s", point::<D>(v)) };
        self.check(field, value, "a wall speed", D::norm(v) * self.dt)
    }

    /// Gravity `g`, set at `field`: what it adds to a grain's move in one step.
    fn gravity<D: Dim>(&self, field: String, g: D::Vector<f64>) -> Result<(), Error> {
        self.check(field, format!("[{}] m/s^2", point::<D>(g)), "a gravity that adds", D::norm(g) * self.dt * self.dt)
    }
}

/// No grain, grain surface or wall moving more than [`MAX_STEP_MOVE`] of the smallest
/// radius in one step of `dt`, nor gravity adding that much to a move in one step.
pub fn motion<D: Dim>(p: &Particles<D>, walls: &[Wall<D>], gravity: D::Vector<f64>, names: &GrainNames, dt: f64) -> Result<(), Error> {
    let bound = StepBound::of(p, dt);
    for i in 0..p.n_free {
        bound.check(names.field(i, "v"), format!("[{}] m/s", point::<D>(p.v[i])), "a speed", D::norm(p.v[i]) * dt)?;
        let w = D::spin_components(&p.omega[i]);
        let spin = if w.len() == 1 { format!("{} rad/s", w[0].shown()) } else { format!("[{}] rad/s", shown_joined(w)) };
        bound.check(names.field(i, "omega"), spin, "a spin whose surface moves", D::spin_dot(p.omega[i], p.omega[i]).sqrt() * p.r[i] * dt)?;
    }
    for w in walls {
        bound.wall::<D>(format!("walls.{}.velocity_x", w.name), w.v)?;
    }
    bound.gravity::<D>("gravity".into(), gravity)
}

/// A point's (or a vector's) coordinates as a message shows them: `x, y` or `x, y, z`.
fn point<D: Dim>(v: D::Vector<f64>) -> String {
    shown_joined(D::flat(std::slice::from_ref(&v)))
}

/// DMT cohesion that the contacts can hold: for every pair of materials that can touch
/// with a work of adhesion, the attraction 2 pi w R* of the largest free grain (R* = r,
/// as on a flat wall: the largest attraction) must not press it past the watchdog's
/// overlap, [`MAX_START_OVERLAP`] of the smallest radius: the normal law's force there
/// (at the reduced mass of a twin pair, the softer for the derived spring) must exceed
/// the pull-off force. Above, the attraction alone would crush the contacts (and a large
/// enough w would make the forces infinite).
pub fn cohesion<D: Dim>(scene: &Scene, p: &Particles<D>, walls: &[Wall<D>]) -> Result<(), Error> {
    let mats = &scene.materials;
    if scene.adhesive_material().is_none() || p.n_free == 0 {
        return Ok(());
    }
    let r_min = p.r[..p.n_free].iter().cloned().fold(f64::INFINITY, f64::min);
    let r_max = p.r[..p.n_free].iter().cloned().fold(0.0, f64::max);
    let dn = MAX_START_OVERLAP * r_min;
    for (a, b) in crate::engine::effects::meeting_pairs(p, walls) {
        let pm = PairMaterial::mix(&mats[a], &mats[b]);
        if pm.pulloff == 0.0 {
            continue;
        }
        let m_star = 0.5 * scene.grain_shape.mass(r_max, mats[a].density);
        let holds = scene.model.normal.stiffness(&pm, r_max, m_star, dn).kn * dn;
        if !(pm.pulloff * r_max <= holds) {
            let k = if mats[a].work_of_adhesion > 0.0 { a } else { b };
            let w_max = holds / (2.0 * std::f64::consts::PI * r_max);
            return Err(refuse(
                format!("materials[{k}].work_of_adhesion"),
                mats[k].work_of_adhesion,
                format!(
                    "a pair work of adhesion sqrt(w_a w_b) of at most {w_max:.4e} J/m^2 between materials[{a}] and materials[{b}] (theirs: {:.4e}): above it the attraction 2 pi w R* on a grain of radius {r_max:e} m presses it more than {MAX_START_OVERLAP} of the smallest radius into its partner, past the watchdog's limit",
                    pm.work_of_adhesion()
                ),
            ));
        }
    }
    Ok(())
}

/// The time step must be stable for every pair of materials the scene's grains and walls
/// use, not only for the smallest grain's own material (which sets dt): each pair of
/// free grains' materials at the smallest radius, each free grain against a rough wall's
/// glued grain, and against each flat wall, every grain of its own material's mass.
/// Without `time_step.allow_unstable`, dt above the stiffest pair's limit is refused.
/// `friction`: a tangential force can arise ([`crate::engine::effects::Effects::friction`]).
pub fn stable_for_every_pair<D: Dim>(scene: &Scene, p: &Particles<D>, walls: &[Wall<D>], info: &crate::engine::timestep::TimeStepInfo, friction: bool) -> Result<(), Error> {
    use crate::engine::timestep::RefContact;
    if scene.time_step.allow_unstable {
        return Ok(());
    }
    let mats = &scene.materials;
    let used = |grains: std::ops::Range<usize>| {
        let mut m: Vec<usize> = p.material[grains].iter().map(|&m| m as usize).collect();
        m.sort_unstable();
        m.dedup();
        m
    };
    let (free, glued) = (used(0..p.n_free), used(p.n_free..p.len()));
    let r = p.r[..p.n_free].iter().cloned().fold(f64::INFINITY, f64::min);
    let shape = scene.grain_shape;
    // A grain of radius `r` and material `k`: (radius, mass, moment of inertia).
    let grain = |r: f64, k: usize| {
        let m = shape.mass(r, mats[k].density);
        (r, m, shape.inertia(r, m))
    };
    let rule = scene.model.beta_rule();
    let mut refs = Vec::new();
    let mut names = Vec::new();
    for (ia, &a) in free.iter().enumerate() {
        let ga = grain(r, a);
        for &b in &free[ia..] {
            let pair = PairMaterial::mix_with(&mats[a], &mats[b], rule);
            refs.push(if a == b { RefContact::twin(r, ga.1, ga.2, pair) } else { RefContact::grains(ga, grain(r, b), pair) });
            names.push(format!("materials[{a}] against materials[{b}]"));
        }
        for w in walls {
            match &w.surface {
                Surface::Flat => {
                    refs.push(RefContact::wall(r, ga.1, ga.2, PairMaterial::mix_with(&mats[a], &mats[w.material], rule)));
                    names.push(format!("materials[{a}] against the {} wall", w.name));
                }
                Surface::Rough { .. } if glued.contains(&w.material) => {
                    refs.push(RefContact::grains(ga, grain(w.glued_radius, w.material), PairMaterial::mix_with(&mats[a], &mats[w.material], rule)));
                    names.push(format!("materials[{a}] against the {} wall's grains", w.name));
                }
                Surface::Rough { .. } => {}
            }
        }
    }
    let v = info.characteristic_speed_m_s;
    let limit = |c: &RefContact| crate::engine::timestep::stability_limit(&scene.model, std::slice::from_ref(c), v, friction);
    let Some(k) = (0..refs.len()).min_by(|&x, &y| limit(&refs[x]).total_cmp(&limit(&refs[y]))) else { return Ok(()) };
    let worst = limit(&refs[k]);
    if !(info.dt_s <= worst) {
        return Err(refuse(
            "time_step",
            format!("dt = {:.4e} s", info.dt_s),
            format!(
                "<= {worst:.4e} s, the stability limit of the stiffest contact the scene has ({}, at the smallest radius and {v} m/s), not only of the smallest grain's own material: use more steps per contact, or set time_step.allow_unstable",
                names[k]
            ),
        ));
    }
    Ok(())
}

/// The general damping's drag `F = -c m v` is explicit: its relaxation time 1/c must be
/// longer than the time step (c dt <= 1; beyond, each step overshoots, and from c dt = 2
/// the drag itself is unstable).
pub fn drag(scene: &Scene, dt: f64) -> Result<(), Error> {
    if let Some(c) = scene.model.general_damping
        && !(c * dt <= 1.0)
    {
        return Err(refuse(
            "model.general_damping",
            format!("{} 1/s", c.shown()),
            format!("<= {:.4e} 1/s at dt = {dt:.4e} s: a drag whose relaxation time 1/c is at least a time step (c dt <= 1; the explicit drag overshoots beyond and is unstable from 2)", 1.0 / dt),
        ));
    }
    Ok(())
}

/// A loaded wall's load must be one the grains can carry (the overlap it presses into
/// the contacts, from Hertz) and one the wall can follow at this time step (the wall on
/// its contacts, a mass on springs, within the velocity-Verlet stability limit).
pub fn load<D: Dim>(scene: &Scene, p: &Particles<D>, walls: &[Wall<D>], length: f64, depth: f64, dt: f64) -> Result<(), Error> {
    let Some(ws) = &scene.walls else { return Ok(()) };
    let ControlSpec::Pressure(pressure) = ws.top.control else { return Ok(()) };
    let Some(wall) = walls.iter().find(|w| matches!(w.control, Control::Load { .. })) else { return Ok(()) };
    load_on(scene, p, walls, wall, pressure, "walls.top", length, depth, dt)
}

/// Each stage of a protocol as [`motion`] and [`load`] check the scene's start: the walls'
/// speeds, gravity, and each load a stage puts on the top wall.
pub fn stages<D: Dim>(scene: &Scene, p: &Particles<D>, walls: &[Wall<D>], length: f64, depth: f64, dt: f64) -> Result<(), Error> {
    let bound = StepBound::of(p, dt);
    let velocities = scene.wall_velocities();
    for (k, st) in scene.stages.iter().enumerate() {
        for (w, wall) in walls.iter().enumerate() {
            let at = format!("stages[{k}].walls.{}", wall.name);
            let mut v = D::zero::<f64>();
            (v[0], v[1]) = (velocities[k + 1][w][0], velocities[k + 1][w][1]);
            bound.wall::<D>(format!("{at}.velocity_x"), v)?;
            let change = if w == 0 { &st.walls.bottom } else { &st.walls.top };
            if let Some(ControlSpec::Pressure(pa)) = change.control {
                load_on(scene, p, walls, wall, pa, &at, length, depth, dt)?;
            }
        }
        if let Some(g) = st.gravity {
            bound.gravity::<D>(format!("stages[{k}].gravity"), g.lift::<D>())?;
        }
    }
    Ok(())
}

/// [`load`] for a pressure (Pa) on `wall`, set at `at` (a JSON path).
#[allow(clippy::too_many_arguments)]
fn load_on<D: Dim>(scene: &Scene, p: &Particles<D>, walls: &[Wall<D>], wall: &Wall<D>, pressure: f64, at: &str, length: f64, depth: f64, dt: f64) -> Result<(), Error> {
    let n_free = p.n_free;
    let r_mean = p.r[..n_free].iter().sum::<f64>() / n_free as f64;
    // The softest pair of materials the grains and walls use.
    let mut used: Vec<usize> = p.material.iter().map(|&m| m as usize).chain(walls.iter().map(|w| w.material)).collect();
    used.sort_unstable();
    used.dedup();
    let mats = &scene.materials;
    let soft = used.iter().flat_map(|&a| used.iter().map(move |&b| PairMaterial::mix(&mats[a], &mats[b]))).min_by(|x, y| x.e_star.total_cmp(&y.e_star));
    let Some(soft) = soft else { return Ok(()) };
    let e_star = soft.e_star;
    // One contact per grain diameter along the wall (in space per grain diameter
    // squared of its area), each carrying the load on a diameter of the wall's area:
    // F = p (2 r) t (in space p (2 r)^2), between two mean grains (R* = r/2, m* = m/2).
    // Hertz: F = 4/3 E* sqrt(R*) dn^1.5; the linear spring: F = kn dn.
    let r_star = 0.5 * r_mean;
    let m_star = 0.5 * p.m[..n_free].iter().sum::<f64>() / n_free as f64;
    // The wall's area each contact carries, m^2.
    let share = if D::D == 2 { 2.0 * r_mean * depth } else { 4.0 * r_mean * r_mean };
    let force = if D::D == 2 { pressure * 2.0 * r_mean * depth } else { pressure * share };
    let law = scene.model.normal;
    let spring = law.hooke().map(|_| law.stiffness(&soft, r_star, m_star, 0.0).kn);
    let dn = match spring {
        None => (0.75 * force / (e_star * r_star.sqrt())).powf(2.0 / 3.0),
        Some(kn) => force / kn,
    };
    let most = MAX_LOAD_OVERLAP * r_mean;
    if !(dn <= most) {
        let (p_max, what) = match spring {
            None => (4.0 / 3.0 * e_star * r_star.sqrt() * most.powf(1.5) / share, format!("E* = {e_star:.3e} Pa")),
            Some(kn) => (kn * most / share, format!("kn = {kn:.3e} N/m")),
        };
        return Err(refuse(
            format!("{at}.control.pressure"),
            format!("{pressure} Pa"),
            format!(
                "at most {p_max:.3e} Pa for these grains ({what}): the load would press each contact in by about {:.3} of a radius (the contact law is meant for under {MAX_LOAD_OVERLAP}; the watchdog stops at {MAX_START_OVERLAP})",
                dn / r_mean
            ),
        ));
    }
    // The wall on its contacts: stiffness dF/ddn (Hertz 2 E* sqrt(R* dn), the spring kn)
    // each, one per grain diameter; stable while dt <= 2 / omega, omega^2 = n k / M.
    let k = spring.unwrap_or_else(|| 2.0 * e_star * (r_star * dn).sqrt());
    let contacts = if D::D == 2 { (length / (2.0 * r_mean)).max(1.0) } else { (length / (2.0 * r_mean)).max(1.0) * (depth / (2.0 * r_mean)).max(1.0) };
    let omega = (contacts * k / wall.mass).sqrt();
    if !(dt * omega <= 2.0) {
        let m_min = contacts * k * dt * dt / 4.0;
        return Err(refuse(
            "walls.top.mass",
            format!("{} kg", wall.mass),
            format!(
                ">= {m_min:.3e} kg: on its ~{contacts:.0} contacts under the load the wall oscillates at {omega:.3e} rad/s, which velocity Verlet at dt = {dt:.3e} s cannot follow (it needs dt <= 2/omega)"
            ),
        ));
    }
    Ok(())
}

/// An impact analysis needs grain 0 and grain 1, or grain 0 and a flat wall, and the two
/// must meet within the run (moving straight, or pulled together by gravity).
pub fn impact<D: Dim>(scene: &Scene, p: &Particles<D>, walls: &[Wall<D>], boundary: &Boundary<D>, duration: f64) -> Result<(), Error> {
    if scene.analysis != Analysis::Impact {
        return Ok(());
    }
    let n = p.n_free;
    let never = |why: String| refuse("analysis", "impact", format!("a scene whose impact can happen: {why}"));
    let gravity = scene.gravity.lift::<D>();
    match n {
        2 => {
            // Gravity moves both alike: only their relative motion decides.
            let d = boundary.image(p.x[0] - p.x[1]);
            let u = p.v[0] - p.v[1];
            let reach = p.r[0] + p.r[1];
            let u2 = D::norm_squared(u);
            let t = if u2 > 0.0 { -D::dot(d, u) / u2 } else { f64::INFINITY };
            if !(t > 0.0 && t.is_finite()) {
                return Err(never("grains 0 and 1 are not approaching each other".into()));
            }
            let miss = D::norm(d + u * t);
            if miss >= reach {
                return Err(never(format!("grains 0 and 1 pass each other {miss:.3e} m apart, more than the sum of their radii ({reach:.3e} m)")));
            }
            let meet = t - (reach * reach - miss * miss).sqrt() / u2.sqrt();
            if meet > duration {
                return Err(never(format!("grains 0 and 1 meet at t = {meet:.3e} s, after the run's duration {duration:.3e} s")));
            }
            Ok(())
        }
        1 => {
            let Some(w) = walls.iter().find(|w| w.is_flat()) else {
                return Err(never("one grain needs a flat wall to hit (or give two grains)".into()));
            };
            // Towards the wall: -side along y.
            let gap = w.side * (p.x[0][1] - w.y) - p.r[0];
            let (speed, pull) = (-w.side * (p.v[0][1] - w.v[1]), -w.side * gravity[1]);
            // Distance covered towards the wall by time t: speed t + pull t^2 / 2.
            let reach = |t: f64| speed * t + 0.5 * pull * t * t;
            let ever = speed > 0.0 || pull > 0.0;
            if !ever {
                return Err(never(format!("grain 0 is not moving towards the {} wall (the first flat wall), and nothing pulls it there", w.name)));
            }
            if reach(duration) < gap {
                return Err(never(format!("grain 0 does not reach the {} wall ({gap:.3e} m away) within the run's duration {duration:.3e} s", w.name)));
            }
            Ok(())
        }
        _ => Err(never(format!("two grains, or one grain and a flat wall; this scene has {n} grains"))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_impact_must_be_able_to_happen() {
        let head_on = crate::scene::builtin::builtin("collision").unwrap();
        let built = crate::engine::build::build(&head_on).unwrap();
        let (p, b) = (built.engine.particles(), built.engine.boundary());
        assert!(impact(&head_on, p, &[], &b, head_on.duration).is_ok());
        // Too short a run: they meet after 10.5 steps, i.e. a bit later than 10 steps.
        let dt = built.time_step.dt_s;
        let e = impact(&head_on, p, &[], &b, 10.0 * dt).unwrap_err().to_string();
        assert!(e.contains("after the run's duration"), "{e}");
        assert!(impact(&head_on, p, &[], &b, 11.0 * dt).is_ok());
        // Moving apart.
        let mut apart = p.clone();
        apart.v.swap(0, 1);
        let e = impact(&head_on, &apart, &[], &b, 1.0).unwrap_err().to_string();
        assert!(e.contains("not approaching"), "{e}");
        // Passing each other: grain 1 lifted by three radii.
        let mut miss = p.clone();
        miss.x[1].y += 3e-3;
        let e = impact(&head_on, &miss, &[], &b, 1.0).unwrap_err().to_string();
        assert!(e.contains("pass each other"), "{e}");
        // Lifted by 1.9 radii, they still graze.
        let mut graze = p.clone();
        graze.x[1].y += 1.9e-3;
        assert!(impact(&head_on, &graze, &[], &b, 1.0).is_ok());
    }
}
