//! The cases: the restitution grid, the oblique impacts and the shear cells grainlab is
//! checked on, each a scene and the codes that compute the same model, written under
//! `reference/cases/<case>/` with each code's deck.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::error::Error;
use crate::physics::contact::LeverArm;
use crate::physics::material::Material;
use crate::scene::{Scene, TangentialSpec, builtin};
use crate::workbench::export::{Code, ExportInfo, export};

/// The restitution grid.
pub const GRID_E: [f64; 6] = [0.1, 0.3, 0.5, 0.7, 0.9, 0.99];
pub const GRID_V: [f64; 4] = [0.01, 0.1, 1.0, 10.0];
pub const GRID_STEPS: [f64; 2] = [50.0, 500.0];
/// Oblique impact angles from the normal, degrees.
pub const ANGLES: [f64; 7] = [5.0, 15.0, 30.0, 45.0, 60.0, 75.0, 85.0];

/// What a case is for, stored as `case.json` beside its scene.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct CaseInfo {
    /// Folder under reference/cases, e.g. `restitution/e0.5-v1-n50-clamp`.
    pub name: String,
    pub description: String,
    /// The codes that compute the same model.
    pub codes: Vec<Code>,
    /// Part of `regen-reference --quick` (and of CI's check that the data are real).
    pub quick: bool,
    /// Keep the force-overlap curve.
    pub curve: bool,
    /// The ensemble this case is a member of (its folder under reference/cases): the
    /// members differ only by their packing's seed and are compared together, the mean
    /// over the members on each side with an interval from the seed-to-seed spread
    /// ([`crate::workbench::compare_ensemble`]), not one by one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ensemble: Option<String>,
}

#[derive(Clone, Debug)]
pub struct Case {
    pub info: CaseInfo,
    pub scene: Scene,
}

impl Case {
    /// The case `name` (its scene named the same with `/` as `-`, its description the
    /// scene's), run by `codes`; `quick` for CI's quick regeneration. No force-overlap
    /// curve, no ensemble.
    fn new(name: String, mut scene: Scene, codes: Vec<Code>, quick: bool) -> Case {
        scene.name = name.replace('/', "-");
        Case { info: CaseInfo { name, description: scene.description.clone(), codes, quick, curve: false, ensemble: None }, scene }
    }
    /// Also compare the force-overlap curve.
    fn with_curve(mut self, curve: bool) -> Case {
        self.info.curve = curve;
        self
    }
    /// A member of the ensemble `group`.
    fn in_ensemble(mut self, group: String) -> Case {
        self.info.ensemble = Some(group);
        self
    }
}

fn glass(restitution: f64) -> Material {
    Material { restitution, ..Material::default() }
}

/// `1`, `0.1`, `10`: a number as it appears in case names.
fn num(v: f64) -> String {
    format!("{v}")
}

/// Every case of the workbench.
pub fn cases() -> Vec<Case> {
    let mut out = Vec::new();
    for &e in &GRID_E {
        for &v in &GRID_V {
            for &n in &GRID_STEPS {
                for clamp in [false, true] {
                    let mut s = builtin::head_on(glass(e), 1e-3, v, n);
                    s.model.limit_force = clamp;
                    s.model.lever_arm = LeverArm::RadiusMinusHalfOverlap;
                    let name = format!("restitution/e{}-v{}-n{}-{}", num(e), num(v), num(n), if clamp { "clamp" } else { "free" });
                    s.description = format!("head-on glass beads r = 1 mm, e = {e}, v = {v} m/s, dt = t_c/{n}, Fn clamp {}", if clamp { "on" } else { "off" });
                    let codes = if clamp { vec![Code::Liggghts, Code::Yade, Code::Lammps] } else { vec![Code::Liggghts, Code::Lammps] };
                    let curve = n == 500.0 && v == 1.0 && [0.1, 0.5, 0.9].contains(&e);
                    out.push(Case::new(name, s, codes, v == 1.0).with_curve(curve));
                }
            }
        }
    }
    for &a in &ANGLES {
        for (target, builder) in [("wall", oblique_wall as fn(f64, TangentialSpec) -> Scene), ("pair", oblique_pair)] {
            for (form, code) in [(TangentialSpec::TotalDisplacement, Code::Liggghts), (TangentialSpec::IncrementalForce, Code::Yade)] {
                let s = builder(a, form);
                let tag = if code == Code::Liggghts { "history" } else { "incremental" };
                let name = format!("oblique-{target}/{tag}-a{}", num(a));
                out.push(Case::new(name, s, vec![code], a == 45.0));
            }
        }
    }
    lammps_cases(&mut out);
    space_cases(&mut out);
    linear_spring_cases(&mut out);
    chung_ooi_cases(&mut out);
    rolling_cases(&mut out);
    let mut s = builtin::shear();
    s.model.lever_arm = LeverArm::RadiusMinusHalfOverlap;
    s.name = "shear-liggghts".into();
    s.description = "the shear cell (built-in `shear`) with LIGGGHTS' lever arm".into();
    s.output.frames = 0;
    out.push(Case { info: CaseInfo { name: "shear/liggghts".into(), description: s.description.clone(), codes: vec![Code::Liggghts], quick: false, curve: false, ensemble: None }, scene: s });
    let mut s = builtin::shear();
    s.name = "shear-lammps".into();
    s.description = "the shear cell (built-in `shear`) as it is (lever arm r): LAMMPS' tangential history caps the total force and its arms differ by O(dn/r), a difference of model the time averages are checked to stay inside".into();
    s.output.frames = 0;
    out.push(Case { info: CaseInfo { name: "shear/lammps".into(), description: s.description.clone(), codes: vec![Code::Lammps], quick: false, curve: false, ensemble: None }, scene: s });
    let mut s = builtin::shear();
    matched(&mut s, TangentialSpec::IncrementalForce);
    s.name = "shear-yade".into();
    s.description = "the shear cell (built-in `shear`) with YADE's incremental tangential force, kinematics and clamp".into();
    s.output.frames = 0;
    out.push(Case { info: CaseInfo { name: "shear/yade".into(), description: s.description.clone(), codes: vec![Code::Yade], quick: false, curve: false, ensemble: None }, scene: s });
    let s = protocol_case();
    out.push(Case { info: CaseInfo { name: "protocol/liggghts".into(), description: s.description.clone(), codes: vec![Code::Liggghts], quick: true, curve: false, ensemble: None }, scene: s });
    let mut s = builtin::protocol();
    s.model.lever_arm = LeverArm::RadiusMinusHalfOverlap;
    s.name = "protocol-builtin-liggghts".into();
    s.description = "the built-in protocol (compress to 100 kPa, relax, shear at +-0.5 m/s, then at +-2 m/s; 1000 grains) with LIGGGHTS' lever arm: its last stage's averages".into();
    s.output.frames = 0;
    out.push(Case { info: CaseInfo { name: "protocol/builtin".into(), description: s.description.clone(), codes: vec![Code::Liggghts], quick: false, curve: false, ensemble: None }, scene: s });
    // The shear cell's ensembles: 200 grains (a fifth of the built-in cell, same height)
    // over ENSEMBLE_SEEDS packings, each code with its own formulation, as the single
    // runs above.
    for (code, tag) in [(Code::Liggghts, "liggghts"), (Code::Yade, "yade")] {
        ensemble(&mut out, &format!("shear-ensemble/{tag}"), code, || builtin::shear_cell(200, 0.008), "the shear cell with 200 grains (0.008 m periodic)");
    }
    space_shear_cases(&mut out);
    out
}

/// The 3D shear box's ensembles (issue 30): 200 spheres in a 5 x 5 mm cell periodic in x
/// and z ([`builtin::shear_box`]: rough lattices at -+0.5 m/s, 100 kPa, 20 ms) over
/// [`ENSEMBLE_SEEDS`] packings, each run natively in 3D by LIGGGHTS (its total
/// displacement projected onto the tangent plane, lever arm r - dn/2) and YADE (its
/// incremental force turned with the contact frame, kinematics and clamp), grainlab each
/// time with the same settings. A single 3D run's time averages move by more than their
/// block interval from one packing to the next, as the plane's do (docs/statistics.md),
/// so the 3D shear box is compared as ensembles only.
fn space_shear_cases(out: &mut Vec<Case>) {
    for (code, tag) in [(Code::Liggghts, "liggghts"), (Code::Yade, "yade")] {
        ensemble(out, &format!("space-shear-ensemble/{tag}"), code, || builtin::shear_box(200, 0.005), "the 3D shear box with 200 spheres (5 x 5 mm, periodic in x and z)");
    }
}

/// An ensemble's members, `group/seed-K`: `scene()` with each of [`ENSEMBLE_SEEDS`] as its
/// packing's seed and `code`'s settings (LIGGGHTS' lever arm; YADE's incremental force,
/// kinematics and clamp), `what` the scene in its description.
fn ensemble(out: &mut Vec<Case>, group: &str, code: Code, scene: impl Fn() -> Scene, what: &str) {
    for seed in ENSEMBLE_SEEDS {
        let mut s = scene();
        if let crate::scene::Grains::Pack(p) = &mut s.grains {
            p.seed = seed;
        }
        if code == Code::Liggghts {
            s.model.lever_arm = LeverArm::RadiusMinusHalfOverlap;
        } else {
            matched(&mut s, TangentialSpec::IncrementalForce);
        }
        s.output.frames = 0;
        s.description = format!("{what}, packing seed {seed}, with {}'s settings: one member of {group}", code.name());
        out.push(Case::new(format!("{group}/seed-{seed}"), s, vec![code], false).in_ensemble(group.to_string()));
    }
}

/// Angles of the oblique impacts in space, degrees from the normal.
pub const SPACE_ANGLES: [f64; 3] = [15.0, 45.0, 75.0];

/// The impacts in space (issue 30), each run natively in 3D by the codes: head-on
/// impacts along the skew line (2, 1, 2)/3 (`space-restitution/`, with the clamp, by
/// LIGGGHTS, YADE and LAMMPS as the plane's clamped grid); a glass bead on a flat wall
/// with its tangential velocity along (3, 0, 4)/5, out of the x-y plane
/// (`space-oblique-wall/`); a bead on a resting one in the plane turned 0.7 rad about
/// (1, 2, 3) (`space-oblique-pair/`); and a bead spinning about two axes (x and z) hitting
/// a wall at 45 degrees along x (`space-spin/`): the tangential formulations each with
/// its code's settings ([`matched`]), LIGGGHTS' history and YADE's incremental force.
fn space_cases(out: &mut Vec<Case>) {
    for e in [0.1, 0.5, 0.9] {
        for v in [0.1, 1.0] {
            let mut s = builtin::head_on_space(glass(e), 1e-3, v, 50.0, [2.0 / 3.0, 1.0 / 3.0, 2.0 / 3.0]);
            s.model.limit_force = true;
            s.model.lever_arm = LeverArm::RadiusMinusHalfOverlap;
            s.description = format!("head-on glass spheres r = 1 mm in space along (2, 1, 2)/3, e = {e}, v = {v} m/s, dt = t_c/50, Fn clamp on");
            let name = format!("space-restitution/e{}-v{}", num(e), num(v));
            out.push(Case::new(name, s, vec![Code::Liggghts, Code::Yade, Code::Lammps], v == 1.0).with_curve(v == 1.0 && e == 0.5));
        }
    }
    let forms = [(TangentialSpec::TotalDisplacement, Code::Liggghts, "history"), (TangentialSpec::IncrementalForce, Code::Yade, "incremental")];
    for &a in &SPACE_ANGLES {
        for (form, code, tag) in forms {
            let mut s = builtin::oblique_space(glass(0.9), 1e-3, 1.0, a, form, 200.0, [0.6, 0.8]);
            matched(&mut s, form);
            s.description = format!("glass sphere on a flat glass wall at 1 m/s, {a} deg from the normal, its tangential velocity along (3, 0, 4)/5, e = 0.9, mu = 0.5, t_c/200");
            out.push(Case::new(format!("space-oblique-wall/{tag}-a{}", num(a)), s, vec![code], a == 45.0));
            let mut s = builtin::turned(&oblique_pair(a, form), [1.0, 2.0, 3.0], 0.7);
            s.description = format!("glass sphere on a resting one at 1 m/s, {a} deg from the line of centres, in the plane turned 0.7 rad about (1, 2, 3), e = 0.9, mu = 0.5, t_c/200");
            out.push(Case::new(format!("space-oblique-pair/{tag}-a{}", num(a)), s, vec![code], a == 45.0));
        }
    }
    for w in [[300.0, -500.0], [-600.0, 200.0]] {
        for (form, code, tag) in forms {
            let mut s = builtin::oblique_space(glass(0.9), 1e-3, 1.0, 45.0, form, 200.0, [1.0, 0.0]);
            if let crate::scene::Grains::List(g) = &mut s.grains {
                g[0].omega = crate::scene::SpinSpec::Vector([w[0], 0.0, w[1]]);
            }
            matched(&mut s, form);
            s.description = format!("glass sphere spinning at ({}, 0, {}) rad/s hitting a flat glass wall at 1 m/s, 45 deg from the normal along x, e = 0.9, mu = 0.5, t_c/200", w[0], w[1]);
            out.push(Case::new(format!("space-spin/{tag}-wx{}-wz{}", num(w[0]), num(w[1])), s, vec![code], w[0] == 300.0));
        }
    }
}

/// The linear spring's stiffnesses in the `hooke-*` cases that give them (LIGGGHTS
/// `model hooke/stiffness`), N/m: for 1 mm glass beads a contact time of about 7 us,
/// near the Hertz one at 1 m/s.
pub const SPRING_KN: f64 = 2.0e5;
pub const SPRING_KT: f64 = 1.5e5;

/// The impacts LAMMPS computes as grainlab does beyond head-on (where the restitution
/// grid has it): a grain on a flat wall at e = 1 with friction (mu = 0.5) and the lever
/// arm r, where LAMMPS' total-displacement history is grainlab's (no damping to cap, no
/// frame to turn), and frictionless oblique pairs (e = 0.9), whose normal force turns with
/// the line of centres. `oblique-wall/lammps-*` and `oblique-pair/lammps-frictionless-*`.
fn lammps_cases(out: &mut Vec<Case>) {
    for &a in &ANGLES {
        let mut s = builtin::oblique(glass(1.0), 1e-3, 1.0, a, TangentialSpec::TotalDisplacement, 200.0);
        s.model.lever_arm = LeverArm::Radius;
        let name = format!("oblique-wall/lammps-a{}", num(a));
        s.description = format!("glass bead on a flat glass wall at 1 m/s, {a} deg from the normal, e = 1, mu = 0.5, lever arm r (LAMMPS' wall/gran), t_c/200");
        out.push(Case::new(name, s, vec![Code::Lammps], a == 45.0));
        let mut s = builtin::oblique_pair(glass(0.9), 1e-3, 1.0, a, TangentialSpec::Frictionless, 200.0);
        s.model.lever_arm = LeverArm::Radius;
        let name = format!("oblique-pair/lammps-frictionless-a{}", num(a));
        s.description = format!("glass bead on a resting one at 1 m/s, {a} deg from the line of centres, e = 0.9, frictionless, t_c/200");
        out.push(Case::new(name, s, vec![Code::Lammps], a == 45.0));
    }
    tsuji_cases(out);
    dmt_cases(out);
    force_cap_cases(out);
    clamped_damping_cases(out);
}

/// The damping that returns e under the clamp (`model.damping = "clamped_restitution"`,
/// `limit_force`): head-on impacts under Hertz (e = 0.05, 0.2, 0.5, 0.8) and the given
/// spring (e = 0.2, 0.8) at 1 m/s, t_c/500, against all three codes (LIGGGHTS' Hertz where
/// its restitution, above 0.05, can carry the clamped beta: e above 0.214). `clamped/...`.
fn clamped_damping_cases(out: &mut Vec<Case>) {
    use crate::scene::{DampingSpec, NormalLaw};
    for (tag, law, es) in [("hertz", NormalLaw::Hertz, &[0.05, 0.2, 0.5, 0.8][..]), ("spring", NormalLaw::HookeStiffness { kn: SPRING_KN, kt: SPRING_KT }, &[0.2, 0.8][..])] {
        for &e in es {
            let mut s = builtin::head_on_under(law, glass(e), 1e-3, 1.0, 500.0);
            s.model.damping = DampingSpec::ClampedRestitution;
            s.model.limit_force = true;
            s.duration *= 10.0;
            // LIGGGHTS' Hertz takes a coefficientRestitution above 0.05 only: e above 0.214
            // here (its hooke/stiffness damps with the written gammas, any e).
            let written = tag == "spring" || crate::physics::restitution::clamped_beta(e).and_then(crate::physics::restitution::restitution_of_beta).is_some_and(|e| e > 0.05);
            let codes = if written { vec![Code::Liggghts, Code::Yade, Code::Lammps] } else { vec![Code::Yade, Code::Lammps] };
            s.description = format!("head-on glass beads r = 1 mm, {tag}, the clamped damping returning e = {e} under the clamp, v = 1 m/s, dt = t_c/500");
            out.push(Case::new(format!("clamped/{tag}-e{}", num(e)), s, codes, e == 0.2));
        }
    }
}

/// LAMMPS' own tangential law (`model.tangential = "total_force_cap"`, lever arm
/// `lammps`), where the other formulations differ from it by design: frictional impacts
/// with damping on a flat wall and on a resting grain (glass, e = 0.9 and 0.5, mu = 0.5,
/// 1 m/s, 5 to 85 degrees), with the clamp at e = 0.5, and the linear spring (given, on
/// the pair). t_c/200. `oblique-wall/forcecap-*`, `oblique-pair/forcecap-*`,
/// `hooke-oblique-pair/forcecap-*`.
fn force_cap_cases(out: &mut Vec<Case>) {
    let cap = |s: &mut Scene, clamp: bool| {
        s.model.tangential = TangentialSpec::TotalForceCap;
        s.model.lever_arm = LeverArm::Lammps;
        s.model.limit_force = clamp;
    };
    for &a in &ANGLES {
        for (e, clamp, tag) in [(0.9, false, ""), (0.5, true, "-clamp-e0.5")] {
            let mut s = builtin::oblique(glass(e), 1e-3, 1.0, a, TangentialSpec::TotalForceCap, 200.0);
            cap(&mut s, clamp);
            let clamped = if clamp { ", Fn >= 0" } else { "" };
            s.description = format!("glass bead on a flat glass wall at 1 m/s, {a} deg from the normal, e = {e}, mu = 0.5{clamped}, LAMMPS' tangential law and arms, t_c/200");
            out.push(Case::new(format!("oblique-wall/forcecap{tag}-a{}", num(a)), s, vec![Code::Lammps], a == 45.0));
            let mut s = builtin::oblique_pair(glass(e), 1e-3, 1.0, a, TangentialSpec::TotalForceCap, 200.0);
            cap(&mut s, clamp);
            s.description = format!("glass bead on a resting one at 1 m/s, {a} deg from the line of centres, e = {e}, mu = 0.5{clamped}, LAMMPS' tangential law and arms, t_c/200");
            out.push(Case::new(format!("oblique-pair/forcecap{tag}-a{}", num(a)), s, vec![Code::Lammps], a == 45.0));
        }
        let mut s = builtin::oblique_pair(glass(0.5), 1e-3, 1.0, a, TangentialSpec::TotalForceCap, 200.0);
        s.model.normal = crate::scene::NormalLaw::HookeStiffness { kn: SPRING_KN, kt: SPRING_KT };
        cap(&mut s, false);
        s.description = format!("glass bead on a resting one at 1 m/s, {a} deg from the line of centres, the given spring (kn = {SPRING_KN} N/m, kt = {SPRING_KT} N/m), e = 0.5, mu = 0.5, LAMMPS' tangential law and arms, t_c/200");
        out.push(Case::new(format!("hooke-oblique-pair/forcecap-a{}", num(a)), s, vec![Code::Lammps], a == 45.0));
    }
}

/// The rolling friction coefficient of the `rolling/*` cases: with mu = 0.5 the rolling
/// torque's cap mu_r R* |Fn| is a fifth of the friction's torque r mu |Fn| on a wall, a
/// tenth on a pair of equal grains.
pub const ROLLING_FRICTION: f64 = 0.1;

/// Rolling resistance against the codes that have it: LIGGGHTS' CDT and EPSD2 on oblique
/// impacts (1 m/s, 30 and 60 degrees, e = 0.9, mu = 0.5, LIGGGHTS' lever arm r - dn/2)
/// on a flat wall and on a resting grain (the incoming grain spinning), and LAMMPS' SDS on a flat wall (e = 1 and
/// lever arm r, where LAMMPS' tangential law is grainlab's: `oblique-wall/lammps`),
/// undamped and damped. t_c/200. `rolling/...`.
fn rolling_cases(out: &mut Vec<Case>) {
    use crate::scene::RollingSpec;
    let resisting = |e: f64| Material { rolling_friction: ROLLING_FRICTION, ..glass(e) };
    type Oblique = fn(Material, f64, f64, f64, TangentialSpec, f64) -> Scene;
    for (law, tag) in [(RollingSpec::Cdt, "cdt"), (RollingSpec::Epsd2, "epsd2")] {
        for (target, builder, what) in [("wall", builtin::oblique as Oblique, "a flat glass wall"), ("pair", builtin::oblique_pair, "a resting one")] {
            for a in [30.0, 60.0] {
                let mut s = builder(resisting(0.9), 1e-3, 1.0, a, TangentialSpec::TotalDisplacement, 200.0);
                // Two equal grains pick up equal spins from their contact, which roll
                // nothing: the incoming one spins at 200 rad/s (w r = 0.2 m/s).
                if let (true, crate::scene::Grains::List(list)) = (target == "pair", &mut s.grains) {
                    list[0].omega = 200.0.into();
                }
                s.model.rolling = law;
                s.model.lever_arm = LeverArm::RadiusMinusHalfOverlap;
                let spin = if target == "pair" { "spinning at 200 rad/s, " } else { "" };
                s.description = format!("glass bead on {what} at 1 m/s, {a} deg, e = 0.9, mu = 0.5, {spin}rolling resistance {tag} (LIGGGHTS), mu_r = {ROLLING_FRICTION}, lever arm r - dn/2, t_c/200");
                out.push(Case::new(format!("rolling/{tag}-{target}-a{}", num(a)), s, vec![Code::Liggghts], a == 30.0));
            }
        }
    }
    for (g, tag) in [(0.0, "sds"), (1e-3, "sds-damped")] {
        for a in [30.0, 60.0] {
            let mut s = builtin::oblique(resisting(1.0), 1e-3, 1.0, a, TangentialSpec::TotalDisplacement, 200.0);
            s.model.rolling = RollingSpec::Sds { stiffness: 1e5, damping: g };
            s.model.lever_arm = LeverArm::Radius;
            s.description = format!("glass bead on a flat glass wall at 1 m/s, {a} deg, e = 1, mu = 0.5, rolling resistance SDS (LAMMPS) k = 1e5 N/m, g = {g} kg/s, mu_r = {ROLLING_FRICTION}, lever arm r, t_c/200");
            out.push(Case::new(format!("rolling/{tag}-wall-a{}", num(a)), s, vec![Code::Lammps], a == 30.0));
        }
    }
    // The shear cell with EPSD2 (LIGGGHTS' lever arm) and with SDS (as shear/lammps: lever
    // arm r, LAMMPS' own tangential history differing by O(dn/r)): time averages within
    // the combined interval.
    for (law, tag, code) in [(RollingSpec::Epsd2, "liggghts", Code::Liggghts), (RollingSpec::Sds { stiffness: 1e5, damping: 0.0 }, "lammps", Code::Lammps)] {
        let mut s = builtin::shear();
        s.model.rolling = law;
        for m in &mut s.materials {
            m.rolling_friction = ROLLING_FRICTION;
        }
        if code == Code::Liggghts {
            s.model.lever_arm = LeverArm::RadiusMinusHalfOverlap;
        }
        s.description = format!("the shear cell (built-in `shear`) with rolling resistance {} (mu_r = {ROLLING_FRICTION}), {}", if code == Code::Liggghts { "EPSD2 and LIGGGHTS' lever arm" } else { "SDS, k = 1e5 N/m, and lever arm r" }, code.name());
        s.output.frames = 0;
        out.push(Case::new(format!("rolling-shear/{tag}"), s, vec![code], false));
    }
}

/// The work of adhesion of the `dmt/*` cases, J/m^2: with 1 mm glass beads a pull-off
/// force 2 pi w R* of 3.1 mN between grains (6.3 mN on a wall), which sticks head-on
/// impacts below about 0.011 m/s at e = 0.5 and 0.0025 m/s at e = 0.9.
pub const DMT_WORK_OF_ADHESION: f64 = 1.0;

/// DMT cohesion against LAMMPS `pair granular dmt` (only LAMMPS has it): head-on impacts
/// from just above the sticking speed (where the attraction takes most of the rebound)
/// to 0.1 m/s at e = 0.5 and 0.9, and frictionless oblique impacts (45 degrees, 0.02
/// m/s, e = 0.5) on a flat wall and on a resting grain. Frictional DMT contacts are not
/// compared: LAMMPS 20220106's DMT friction cap reads a variable its DMT branch never sets
/// (docs/fidelity.md). All at t_c/200 of the impact speed; five times the usual run after
/// contact, since the attraction holds the grains longer. `dmt/...`.
fn dmt_cases(out: &mut Vec<Case>) {
    use crate::scene::NormalLaw;
    let sticky = |e: f64| Material { work_of_adhesion: DMT_WORK_OF_ADHESION, ..glass(e) };
    let mut push = |name: String, mut s: Scene, description: String, quick: bool| {
        s.description = description;
        out.push(Case::new(name, s, vec![Code::Lammps], quick));
    };
    for (e, speeds) in [(0.5, [0.012, 0.02, 0.1]), (0.9, [0.003, 0.01, 0.1])] {
        for v in speeds {
            let mut s = builtin::head_on_under(NormalLaw::Hertz, sticky(e), 1e-3, v, 200.0);
            s.duration *= 5.0;
            let d = format!("head-on glass beads r = 1 mm, e = {e}, work of adhesion {DMT_WORK_OF_ADHESION} J/m^2 (DMT), v = {v} m/s, t_c/200");
            push(format!("dmt/head-on-e{}-v{}", num(e), num(v)), s, d, v == 0.1);
        }
    }
    type Oblique = fn(Material, f64, f64, f64, TangentialSpec, f64) -> Scene;
    for (target, builder, what) in [("wall", builtin::oblique as Oblique, "a flat glass wall"), ("pair", builtin::oblique_pair, "a resting one")] {
        let mut s = builder(sticky(0.5), 1e-3, 0.02, 45.0, TangentialSpec::Frictionless, 200.0);
        s.duration *= 5.0;
        let d = format!("glass bead on {what} at 0.02 m/s, 45 deg, e = 0.5, frictionless, work of adhesion {DMT_WORK_OF_ADHESION} J/m^2 (DMT), t_c/200");
        push(format!("dmt/oblique-{target}-frictionless-a45"), s, d, target == "wall");
    }
}

/// LAMMPS' Tsuji damping (`model.damping = "tsuji"`), which only LAMMPS has: head-on
/// grids under Hertz (e = 0.1 to 1, t_c/50 and t_c/500, clamp on and off) and the given
/// spring (e = 0.1, 0.5, 0.9 at t_c/500), and frictionless oblique impacts at 45 degrees
/// on a flat wall and on a resting grain. `tsuji/...`.
fn tsuji_cases(out: &mut Vec<Case>) {
    use crate::scene::{DampingSpec, NormalLaw};
    for (tag, law, es, ns) in [
        ("hertz", NormalLaw::Hertz, &[0.1, 0.3, 0.5, 0.7, 0.9, 1.0][..], &[50.0, 500.0][..]),
        ("spring", NormalLaw::HookeStiffness { kn: SPRING_KN, kt: SPRING_KT }, &[0.1, 0.5, 0.9][..], &[500.0][..]),
    ] {
        for &e in es {
            for &n in ns {
                for clamp in [false, true] {
                    let mut s = builtin::head_on_under(law, glass(e), 1e-3, 1.0, n);
                    s.model.damping = DampingSpec::Tsuji;
                    s.model.limit_force = clamp;
                    let name = format!("tsuji/{tag}-e{}-n{}-{}", num(e), num(n), if clamp { "clamp" } else { "free" });
                    s.description = format!("head-on glass beads r = 1 mm, {tag}, Tsuji damping (LAMMPS' fit) of e = {e}, v = 1 m/s, dt = t_c/{n}, Fn clamp {}", if clamp { "on" } else { "off" });
                    out.push(Case::new(name, s, vec![Code::Lammps], n == 500.0));
                }
            }
        }
    }
    type Oblique = fn(Material, f64, f64, f64, TangentialSpec, f64) -> Scene;
    for (target, builder, what) in [("wall", builtin::oblique as Oblique, "a flat glass wall"), ("pair", builtin::oblique_pair, "a resting one")] {
        let mut s = builder(glass(0.5), 1e-3, 1.0, 45.0, TangentialSpec::Frictionless, 200.0);
        s.model.damping = DampingSpec::Tsuji;
        let name = format!("tsuji/{target}-frictionless-a45");
        s.description = format!("glass bead on {what} at 1 m/s, 45 deg, frictionless, Tsuji damping of e = 0.5, t_c/200");
        out.push(Case::new(name, s, vec![Code::Lammps], true));
    }
    // LAMMPS' current Tsuji damping (`model.damping = "tsuji_sqrt2"`: the fit times
    // sqrt(2)), run in LAMMPS 20220106 as its `damping tsuji` with the input whose fit
    // gives it: head-on under Hertz (e = 0.2, 0.5, 0.8) and the given spring (e = 0.5) at
    // t_c/500, and an oblique impact on a flat wall with LAMMPS' tangential law.
    for (tag, law, e) in [("hertz", NormalLaw::Hertz, 0.2), ("hertz", NormalLaw::Hertz, 0.5), ("hertz", NormalLaw::Hertz, 0.8), ("spring", NormalLaw::HookeStiffness { kn: SPRING_KN, kt: SPRING_KT }, 0.5)] {
        let mut s = builtin::head_on_under(law, glass(e), 1e-3, 1.0, 500.0);
        s.model.damping = DampingSpec::TsujiSqrt2;
        let name = format!("tsuji/sqrt2-{tag}-e{}-n500-free", num(e));
        s.description = format!("head-on glass beads r = 1 mm, {tag}, LAMMPS' current Tsuji damping (the fit times sqrt(2)) of e = {e}, v = 1 m/s, dt = t_c/500, Fn clamp off");
        out.push(Case::new(name, s, vec![Code::Lammps], true));
    }
    let mut s = builtin::oblique(glass(0.5), 1e-3, 1.0, 45.0, TangentialSpec::TotalForceCap, 200.0);
    s.model.damping = DampingSpec::TsujiSqrt2;
    s.description = "glass bead on a flat glass wall at 1 m/s, 45 deg, LAMMPS' tangential law (total_force_cap), LAMMPS' current Tsuji damping of e = 0.5, t_c/200".to_string();
    out.push(Case::new("tsuji/sqrt2-wall-force-cap-a45".to_string(), s, vec![Code::Lammps], true));
}

/// The linear spring against LIGGGHTS (`model hooke` and `hooke/stiffness`, tangential
/// history, its lever arm), LAMMPS (head-on) and YADE (`ViscElMat`, the incremental
/// force, its kinematics and clamp): a head-on restitution grid for both forms (e = 0.1,
/// 0.5, 0.9; t_c/50 and t_c/500; with and without the clamp, YADE with it), oblique
/// impacts on a flat wall (derived stiffness: the wall contact has R* = r, m* = m) and on
/// a resting grain (given stiffness) in each code's tangential formulation, and the shear
/// cell (derived stiffness, LIGGGHTS).
fn linear_spring_cases(out: &mut Vec<Case>) {
    use crate::scene::NormalLaw;
    let forms = [("derived", NormalLaw::Hooke { characteristic_velocity: 1.0 }), ("given", NormalLaw::HookeStiffness { kn: SPRING_KN, kt: SPRING_KT })];
    for (tag, law) in forms {
        for e in [0.1, 0.5, 0.9] {
            for n in [50.0, 500.0] {
                for clamp in [false, true] {
                    let mut s = builtin::head_on_under(law, glass(e), 1e-3, 1.0, n);
                    s.model.limit_force = clamp;
                    s.model.lever_arm = LeverArm::RadiusMinusHalfOverlap;
                    let name = format!("hooke-restitution/{tag}-e{}-n{}-{}", num(e), num(n), if clamp { "clamp" } else { "free" });
                    s.description = format!("head-on glass beads r = 1 mm on the linear spring ({tag} stiffness), e = {e}, v = 1 m/s, dt = t_c/{n}, Fn clamp {}", if clamp { "on" } else { "off" });
                    let curve = n == 500.0 && e == 0.5 && !clamp;
                    // YADE's ViscElPhys law always clamps.
                    let codes = if clamp { vec![Code::Liggghts, Code::Yade, Code::Lammps] } else { vec![Code::Liggghts, Code::Lammps] };
                    out.push(Case::new(name, s, codes, true).with_curve(curve));
                }
            }
        }
    }
    for &a in &ANGLES {
        for (target, law) in [("wall", forms[0].1), ("pair", forms[1].1)] {
            for (form, code, tag) in [(TangentialSpec::TotalDisplacement, Code::Liggghts, "history"), (TangentialSpec::IncrementalForce, Code::Yade, "incremental")] {
                let mut s = if target == "wall" { oblique_wall(a, form) } else { oblique_pair(a, form) };
                s.model.normal = law;
                matched(&mut s, form);
                let name = format!("hooke-oblique-{target}/{tag}-a{}", num(a));
                s.description = format!("{} on the linear spring ({} stiffness)", s.description, if target == "wall" { "derived" } else { "given" });
                out.push(Case::new(name, s, vec![code], a == 45.0));
            }
        }
    }
    // Two materials against YADE, whose per-material springs and dashpots in series the
    // exporter solves: a second material (E = 200 GPa, nu = 0.3, e = 0.5, mu = 0.3, glass'
    // density) for the resting grain (given spring), and for the flat walls (derived).
    let second = Material { name: "second".into(), youngs_modulus: 200e9, poisson_ratio: 0.3, restitution: 0.5, friction: 0.3, ..glass(0.9) };
    for (target, law) in [("wall", forms[0].1), ("pair", forms[1].1)] {
        let form = TangentialSpec::IncrementalForce;
        let mut s = if target == "wall" { oblique_wall(30.0, form) } else { oblique_pair(30.0, form) };
        s.model.normal = law;
        matched(&mut s, form);
        s.materials.push(second.clone());
        if target == "wall" {
            let w = s.walls.as_mut().expect("flat walls");
            w.bottom.material = 1;
            w.top.material = 1;
        } else if let crate::scene::Grains::List(l) = &mut s.grains {
            l[1].material = 1;
        }
        let name = format!("hooke-oblique-{target}/incremental-2mat-a30");
        s.description = format!("{} on the linear spring ({} stiffness), the {} of a second material (E = 200 GPa, e = 0.5, mu = 0.3)", s.description, if target == "wall" { "derived" } else { "given" }, if target == "wall" { "walls" } else { "resting grain" });
        out.push(Case::new(name, s, vec![Code::Yade], true));
    }
    let mut s = builtin::shear();
    s.model.lever_arm = LeverArm::RadiusMinusHalfOverlap;
    s.model.normal = NormalLaw::Hooke { characteristic_velocity: 1.0 };
    s.name = "hooke-shear-liggghts".into();
    s.description = "the shear cell (built-in `shear`) on the linear spring (LIGGGHTS `model hooke`, vc = 1 m/s) with LIGGGHTS' lever arm".into();
    s.output.frames = 0;
    out.push(Case { info: CaseInfo { name: "hooke-shear/liggghts".into(), description: s.description.clone(), codes: vec![Code::Liggghts], quick: false, curve: false, ensemble: None }, scene: s });
    // YADE puts each material's spring and dashpot in series per contact: the damping
    // 2 |beta| sqrt(m* k) of grains of several masses is not such a series (refused by
    // name), so the cell runs undamped (e = 1: friction alone dissipates) on the given
    // spring.
    let mut s = builtin::shear();
    s.model.normal = NormalLaw::HookeStiffness { kn: SPRING_KN, kt: SPRING_KT };
    matched(&mut s, TangentialSpec::IncrementalForce);
    for m in &mut s.materials {
        m.restitution = 1.0;
    }
    s.name = "hooke-shear-yade".into();
    s.description = "the shear cell (built-in `shear`) on the given linear spring (kn = 2e5, kt = 1.5e5 N/m), undamped (e = 1), with YADE's ViscElPhys law (incremental tangential force, arm to the contact point, clamp)".into();
    s.output.frames = 0;
    out.push(Case { info: CaseInfo { name: "hooke-shear/yade".into(), description: s.description.clone(), codes: vec![Code::Yade], quick: false, curve: false, ensemble: None }, scene: s });
}

/// Chung & Ooi (2011)'s tests 4 and 6 (docs/benchmarks.md) in the reference codes, each
/// formulation with the code that uses it and that code's settings ([`matched`]): test 4,
/// an Al2O3 grain (R = 2.5 mm, e = 0.98, mu = 0.092) on a rigid plane at 3.9 m/s, 5 to 85
/// degrees from the normal; test 6, an Al grain (R = 0.1 m, e = 0.5, mu = 0.4) at
/// vn = 0.2 m/s with spin w0 r / vn from -10 to 10. Sphere in the plane, t_c/500.
fn chung_ooi_cases(out: &mut Vec<Case>) {
    use crate::physics::dim::GrainShape;
    let al2o3 = Material { name: "Al2O3".into(), youngs_modulus: 380e9, poisson_ratio: 0.23, density: 4000.0, restitution: 0.98, friction: 0.092, work_of_adhesion: 0.0, rolling_friction: 0.0 };
    let al = Material { name: "Al".into(), youngs_modulus: 70e9, poisson_ratio: 0.33, density: 2700.0, restitution: 0.5, friction: 0.4, work_of_adhesion: 0.0, rolling_friction: 0.0 };
    for (form, code, tag) in [(TangentialSpec::TotalDisplacement, Code::Liggghts, "history"), (TangentialSpec::IncrementalForce, Code::Yade, "incremental"), (TangentialSpec::TotalForceCap, Code::Lammps, "forcecap")] {
        for a in [5.0f64, 15.0, 25.0, 35.0, 45.0, 55.0, 65.0, 75.0, 85.0] {
            let t = a.to_radians();
            let mut s = builtin::on_rigid_plane(al2o3.clone(), GrainShape::SphereInPlane, 2.5e-3, 3.9 * t.cos(), 3.9 * t.sin(), 0.0, 500.0, form);
            matched(&mut s, form);
            let name = format!("chung-ooi/test4-{tag}-a{}", num(a));
            s.description = format!("Chung & Ooi test 4: Al2O3 grain (R = 2.5 mm, e = 0.98, mu = 0.092) on a rigid plane at 3.9 m/s, {a} deg from the normal, t_c/500");
            out.push(Case::new(name, s, vec![code], a == 45.0));
        }
        for ratio in [-10.0, -4.0, 3.0, 5.0, 10.0] {
            let mut s = builtin::on_rigid_plane(al.clone(), GrainShape::SphereInPlane, 0.1, 0.2, 0.0, ratio * 0.2 / 0.1, 500.0, form);
            matched(&mut s, form);
            let name = format!("chung-ooi/test6-{tag}-w{}", num(ratio));
            s.description = format!("Chung & Ooi test 6: Al grain (R = 0.1 m, e = 0.5, mu = 0.4) on a rigid plane at vn = 0.2 m/s with spin w0 r / vn = {ratio}, t_c/500");
            out.push(Case::new(name, s, vec![code], ratio == 5.0));
        }
    }
}

/// The packing seeds of the workbench's shear ensembles.
pub const ENSEMBLE_SEEDS: std::ops::RangeInclusive<u64> = 1..=8;

/// The workbench's protocol: a 200-grain shear cell, with LIGGGHTS' lever arm, under
/// 100 kPa, packed loosely (area fraction 0.6, so no two grains touch at the start). The
/// top wall falls onto the grains; 54 us in, while it first presses on them, the walls
/// go from +-0.5 m/s ("slow") to +-1 m/s ("fast", 16 us), every step of both recorded;
/// the run goes on at +-1 m/s ("steady", 10 ms, 400 rows, averaged). LIGGGHTS runs the
/// same stages from the exported deck: the two codes' rows of the first two stages agree
/// step for step (tests/workbench.rs, `a_protocol_agrees_step_for_step_...`), the steady
/// stage's time averages as the shear cells' do.
pub fn protocol_case() -> Scene {
    use crate::scene::{Grains, StageSpec, StageWalls, WallChange};
    let mut s = builtin::shear_cell(200, 0.008);
    if let Grains::Pack(p) = &mut s.grains {
        p.packing_fraction = 0.6;
    }
    s.model.lever_arm = LeverArm::RadiusMinusHalfOverlap;
    s.name = "protocol-liggghts".into();
    s.description = "a three-stage protocol (shear at +-0.5 m/s while the top wall lands, then at +-1 m/s, every step recorded; then 10 ms at +-1 m/s, averaged) under 100 kPa in a loose 200-grain shear cell, with LIGGGHTS' lever arm".into();
    s.output.frames = 0;
    s.time_step.rule = crate::scene::TimeStepRule::StepsPerContact { steps: 50.0, impact_speed: 1.0 };
    let vx = |v: f64| WallChange { velocity_x: Some(v), ..WallChange::default() };
    // More samples than steps: a row at every step.
    let every_step = Some(100_000);
    s.stages = vec![
        StageSpec { name: "slow".into(), duration: 54e-6, samples: every_step, average: false, ..StageSpec::default() },
        StageSpec { name: "fast".into(), duration: 16e-6, walls: StageWalls { bottom: vx(-1.0), top: vx(1.0) }, samples: every_step, average: false, ..StageSpec::default() },
        StageSpec { name: "steady".into(), duration: 0.01, samples: Some(400), average: true, ..StageSpec::default() },
    ];
    s.duration = s.stages.iter().map(|st| st.duration).sum();
    s
}

/// Settings matched to the code that uses each tangential formulation: LIGGGHTS' lever
/// arm r - dn/2 and no clamp (its defaults); LAMMPS' arms for its law (total_force_cap),
/// no clamp; YADE's kinematics for the scene's normal law
/// (Mindlin's ratcheting-free ones, ViscElPhys' contact point) and the clamp it always
/// applies.
fn matched(s: &mut Scene, form: TangentialSpec) {
    s.model.tangential = form;
    let yade = form == TangentialSpec::IncrementalForce;
    s.model.limit_force = yade;
    s.model.lever_arm = match form {
        TangentialSpec::IncrementalForce => crate::workbench::export::yade::lever_arm(&s.model.normal),
        TangentialSpec::TotalForceCap => LeverArm::Lammps,
        _ => LeverArm::RadiusMinusHalfOverlap,
    };
}

/// A glass bead (r = 1 mm, e = 0.9, mu = 0.5) hitting a flat glass wall at 1 m/s, `a` degrees from the normal.
pub fn oblique_wall(a: f64, form: TangentialSpec) -> Scene {
    let mut s = builtin::oblique(glass(0.9), 1e-3, 1.0, a, form, 200.0);
    matched(&mut s, form);
    s.description = format!("glass bead on a flat glass wall at 1 m/s, {a} deg from the normal, e = 0.9, mu = 0.5, t_c/200");
    s
}

/// A glass bead hitting a resting one at 1 m/s, `a` degrees between the approach and the
/// line of centres at contact.
pub fn oblique_pair(a: f64, form: TangentialSpec) -> Scene {
    let mut s = builtin::oblique_pair(glass(0.9), 1e-3, 1.0, a, form, 200.0);
    matched(&mut s, form);
    s.description = format!("glass bead on a resting one at 1 m/s, {a} deg from the line of centres, e = 0.9, mu = 0.5, t_c/200");
    s
}

/// Write every case (scene.json, case.json and each code's export) under `root`.
pub fn write_cases(root: &Path, filter: Option<&str>) -> Result<usize, Error> {
    let mut n = 0;
    for c in cases() {
        if filter.is_some_and(|f| !c.info.name.contains(f)) {
            continue;
        }
        write_case(&root.join(&c.info.name), &c)?;
        n += 1;
    }
    Ok(n)
}

pub fn write_case(dir: &Path, c: &Case) -> Result<(), Error> {
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir.display(), e))?;
    let w = |name: &str, text: String| std::fs::write(dir.join(name), text).map_err(|e| Error::io(dir.join(name).display(), e));
    w("scene.json", c.scene.to_json() + "\n")?;
    w("case.json", serde_json::to_string_pretty(&c.info).expect("serialisable") + "\n")?;
    for &code in &c.info.codes {
        export(&c.scene, code, dir)?;
    }
    Ok(())
}

/// A case folder's `case.json` and `export.json`.
pub(crate) fn read_info(case_dir: &Path) -> Result<(CaseInfo, ExportInfo), Error> {
    let read = |name: &str| std::fs::read_to_string(case_dir.join(name)).map_err(|e| Error::io(case_dir.join(name).display(), e));
    let case: CaseInfo = serde_json::from_str(&read("case.json")?).map_err(|e| Error::Other(format!("case.json: {e}")))?;
    let info: ExportInfo = serde_json::from_str(&read("export.json")?).map_err(|e| Error::Other(format!("export.json: {e}")))?;
    Ok((case, info))
}

/// Every case folder (holding a case.json) under `root`, sorted.
pub fn case_dirs(root: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(d) = stack.pop() {
        if d.join("case.json").exists() {
            out.push(d);
            continue;
        }
        if let Ok(rd) = std::fs::read_dir(&d) {
            for e in rd.flatten() {
                if e.path().is_dir() {
                    stack.push(e.path());
                }
            }
        }
    }
    out.sort();
    out
}
