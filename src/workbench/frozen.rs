//! Frozen-state cross-checks of what the packing observers read: a shear cell is run for
//! a number of steps, its contacts are recorded at the last one
//! ([`crate::engine::world::Probe`]), and the state those contacts were computed from
//! (every grain's position, velocity and spin, the walls' planes and velocities, each
//! contact's elastic tangential force after the step) is written as text files that
//! LIGGGHTS (`scripts/frozen/liggghts.py`: `read_data`, a restart patched with the
//! histories, one `run 0`) and YADE (`scripts/frozen/yade.py`: interactions made, their
//! `shearElastic` set, one step of 1e-200 s) load and evaluate without moving. Each code
//! writes its contacts in the same table as [`contacts_table`], with its own stress,
//! coordination and fabric; `tests/frozen.rs` holds the engine's to them
//! (`reference/frozen/<case>/`).
//!
//! Files (SI units, numbers with every digit):
//! - `scene.txt`: `key value` lines: E, nu, e, mu, rho (the one material), L (the
//!   periodic length; x from 0), y_bottom, y_top (the flat walls' planes), vx_bottom,
//!   vx_top, limitForce (0 or 1), dt;
//! - `grains.txt`: `id x y r vx vy omega` (ids from 1, the grains' order);
//! - `history.txt`: `i j ft_x ft_y sliding`: the elastic tangential force on grain i of
//!   its contact with j (a grain id, or `bottom` / `top`), and 1 if it slid this step;
//! - `contacts.txt` ([`contacts_table`]): the engine's evaluation.

use std::fmt::Write as _;

use crate::error::Error;
use crate::observe::packing::{PackingRow, packing_row};
use crate::physics::contact::{ContactRecord, Partner};
use crate::physics::dim::GrainShape;
use crate::scene::Scene;

/// A frozen state and the engine's contacts at it.
pub struct Frozen {
    pub scene_txt: String,
    pub grains_txt: String,
    pub history_txt: String,
    pub contacts_txt: String,
    /// The contacts as recorded.
    pub contacts: Vec<ContactRecord>,
    /// What the packing observer makes of them ([`packing_row`]), and the volume its
    /// stress is over, m^3 (L_x t H).
    pub packing: Option<PackingRow>,
    pub volume_m3: f64,
}

fn refuse(field: &str, why: &str) -> Error {
    Error::Scene(format!("frozen-state export: {field}: {why}"))
}

/// A contact's partner in the files: a grain id (from 1) or the wall's name.
fn partner(p: Partner) -> String {
    match p {
        Partner::Grain(j) => (j + 1).to_string(),
        Partner::Wall(0) => "bottom".into(),
        Partner::Wall(_) => "top".into(),
    }
}

/// The contacts, one line each: `i j cx cy nx ny dn Fnx Fny Ftx Fty` with the normal
/// from i to j (towards the wall for a wall), the contact point (between grains on the
/// line of centres in the middle of the overlap, r_i - dn/2 from i's centre; on a
/// wall, on its plane, r_i - dn from the centre: [`ContactRecord::point`]), and the
/// normal and tangential forces on i; grain pairs first, by i then j, then the walls.
pub fn contacts_table(contacts: &[ContactRecord]) -> String {
    let mut rows: Vec<(bool, u32, u32, String)> = Vec::new();
    for c in contacts {
        // Seen from the grain of the lower id.
        let c = match c.partner {
            Partner::Grain(j) if j < c.i => ContactRecord {
                i: j,
                partner: Partner::Grain(c.i),
                normal: -c.normal,
                branch: -c.branch,
                tangential_force: -c.tangential_force,
                tangential_elastic: -c.tangential_elastic,
                ..*c
            },
            _ => *c,
        };
        let (n, fn_, ft) = (-c.normal, c.normal * c.normal_force, c.tangential_force);
        let (wall, j) = match c.partner {
            Partner::Grain(j) => (false, j),
            Partner::Wall(k) => (true, k),
        };
        let line = format!("{} {} {:e} {:e} {:e} {:e} {:e} {:e} {:e} {:e} {:e}", c.i + 1, partner(c.partner), c.point.x, c.point.y, n.x, n.y, c.overlap, fn_.x, fn_.y, ft.x, ft.y);
        rows.push((wall, c.i, j, line));
    }
    rows.sort_by_key(|r| (r.0, r.1, r.2));
    let mut s = String::from("# i j cx cy nx ny dn Fnx Fny Ftx Fty (n from i to j or towards the wall; forces on i)\n");
    for r in rows {
        s.push_str(&r.3);
        s.push('\n');
    }
    s
}

/// Run `scene` for `steps` steps, record the contacts of the last, and write the state
/// they were computed from. Refused (by field) where the reference decks could not load
/// the same state: rough walls, a wall not held in y, several materials, disks, a
/// periodic range not from 0.
pub fn freeze(scene: &Scene, steps: u64) -> Result<Frozen, Error> {
    let walls = scene.walls.as_ref().ok_or_else(|| refuse("walls", "a shear cell with two walls is needed"))?;
    for (name, w) in [("bottom", &walls.bottom), ("top", &walls.top)] {
        if !matches!(w.surface, crate::scene::SurfaceSpec::Flat) {
            return Err(refuse(&format!("walls.{name}.surface"), "flat walls only (LIGGGHTS' primitive planes)"));
        }
        if w.velocity_y != 0.0 || !matches!(w.control, crate::scene::ControlSpec::Fixed) {
            return Err(refuse(&format!("walls.{name}"), "walls held in y (fixed, velocity_y 0): a primitive wall moves in x only"));
        }
    }
    if scene.materials.len() != 1 {
        return Err(refuse("materials", "one material"));
    }
    if scene.grain_shape != GrainShape::SphereInPlane {
        return Err(refuse("grain_shape", "sphere_in_plane (the reference codes' spheres)"));
    }
    let Some([x0, x1]) = scene.domain.periodic_x else { return Err(refuse("domain.periodic_x", "a periodic cell")) };
    if x0 != 0.0 {
        return Err(refuse("domain.periodic_x", "a range from 0"));
    }
    let mut scene = scene.clone();
    scene.output.contacts = true;
    let mut built = crate::study::accuracy::build(&scene)?;
    let e = built.engine.as_mut();
    for k in 1..=steps {
        if k == steps {
            e.want_contacts();
        }
        e.step()?;
    }
    let probe = e.probe();
    let p = e.particles();
    if probe.step != steps || probe.walls.len() != 2 {
        return Err(Error::Other("frozen-state export: no contacts recorded at the last step".into()));
    }
    let m = &scene.materials[0];
    let mut s = String::new();
    for (k, v) in [
        ("E", m.youngs_modulus),
        ("nu", m.poisson_ratio),
        ("e", m.restitution),
        ("mu", m.friction),
        ("rho", m.density),
        ("L", x1 - x0),
        ("y_bottom", probe.walls[0].0),
        ("y_top", probe.walls[1].0),
        ("vx_bottom", probe.walls[0].1.x),
        ("vx_top", probe.walls[1].1.x),
        ("limitForce", if scene.model.limit_force { 1.0 } else { 0.0 }),
        ("dt", built.time_step.dt_s),
    ] {
        let _ = writeln!(s, "{k} {v:e}");
    }
    let mut g = String::from("# id x y r vx vy omega\n");
    for i in 0..p.n_free {
        let _ = writeln!(g, "{} {:e} {:e} {:e} {:e} {:e} {:e}", i + 1, probe.x[i].x, probe.x[i].y, p.r[i], probe.v[i].x, probe.v[i].y, probe.omega[i]);
    }
    let mut h = String::from("# i j ft_x ft_y sliding (elastic tangential force on i after the step, N)\n");
    for c in &probe.contacts {
        let _ = writeln!(h, "{} {} {:e} {:e} {}", c.i + 1, partner(c.partner), c.tangential_elastic.x, c.tangential_elastic.y, c.sliding as u8);
    }
    let contacts_txt = contacts_table(&probe.contacts);
    let packing = packing_row(&e.view(), built.length, built.depth);
    let volume_m3 = packing.map_or(0.0, |r| built.length * built.depth * r.height_m);
    Ok(Frozen { scene_txt: s, grains_txt: g, history_txt: h, contacts_txt, contacts: probe.contacts.clone(), packing, volume_m3 })
}
