//! Built-in scenes, runnable by name: `grainlab run shear`. `grainlab scenes NAME` prints
//! one as JSON to start a scene file from.

use crate::physics::contact::LeverArm;
use crate::physics::material::Material;
use crate::scene::*;
use crate::scene::pack::RadiusDist;

/// Names and one-line descriptions.
pub const BUILTIN: &[(&str, &str)] = &[
    ("collision", "two glass beads head-on at 1 m/s, e = 0.5: the seed's 1D model with energy monitoring"),
    ("oblique", "a glass bead hitting a flat glass wall at 45 degrees and 1 m/s, e = 0.9, mu = 0.5"),
    ("shear", "the seed's experiment: ~1000 polydisperse glass beads, periodic x, rough walls at +-0.5 m/s under 100 kPa"),
    ("protocol", "the shear cell as a study runs it, in four stages: compress to 100 kPa, relax, shear at +-0.5 m/s, shear at +-2 m/s"),
    ("shear3d", "the shear box in 3D: 2000 polydisperse glass spheres, periodic x and z, rough walls (glued lattices) at +-0.5 m/s under 100 kPa"),
    ("collision3d", "two glass spheres head-on at 1 m/s along the skew line (2, 1, 2)/3 in 3D, e = 0.5"),
    ("oblique3d", "a glass sphere hitting a flat glass wall at 45 degrees and 1 m/s in 3D, its tangential velocity along (3, 0, 4)/5 (out of the x-y plane), e = 0.9, mu = 0.5"),
];

fn glass(restitution: f64) -> Material {
    Material { restitution, ..Material::default() }
}

/// Two equal grains of radius `r` approaching head-on at relative speed `v`.
///
/// They start 10.5 time steps before contact, so that the contact begins half-way
/// through a step at every speed and time step: the realised restitution depends on
/// that phase at O(dt/t_c), and fixing it makes results depend on dt/t_c alone.
pub fn head_on(material: Material, r: f64, v: f64, steps_per_contact: f64) -> Scene {
    head_on_under(NormalLaw::Hertz, material, r, v, steps_per_contact)
}

/// [`head_on`] under the normal law `law` (its contact time sets the time step and the
/// approach).
pub fn head_on_under(law: NormalLaw, material: Material, r: f64, v: f64, steps_per_contact: f64) -> Scene {
    let m = 4.0 / 3.0 * std::f64::consts::PI * r * r * r * material.density;
    let pm = crate::physics::material::PairMaterial::mix(&material, &material);
    let tc = law.contact_time(&pm, r / 2.0, m / 2.0, v);
    let dt = tc / steps_per_contact;
    let gap = 10.5 * v * dt;
    Scene {
        name: "collision".into(),
        description: BUILTIN[0].1.into(),
        grain_shape: Default::default(),
        dimension: Default::default(),
        materials: vec![material],
        domain: Domain::default(),
        grains: Grains::List(vec![
            GrainSpec { x: [-r - gap / 2.0, 0.0].into(), v: [v / 2.0, 0.0].into(), omega: 0.0.into(), r, material: 0 },
            GrainSpec { x: [r + gap / 2.0, 0.0].into(), v: [-v / 2.0, 0.0].into(), omega: 0.0.into(), r, material: 0 },
        ]),
        walls: None,
        gravity: [0.0, 0.0].into(),
        model: ModelSpec { normal: law, ..ModelSpec::default() },
        time_step: TimeStepSpec {
            rule: TimeStepRule::StepsPerContact { steps: steps_per_contact, impact_speed: v },
            characteristic_speed: None,
            allow_unstable: false,
        },
        // The approach and three contact times (the run stops at separation anyway).
        duration: 2.0 * gap / v + 3.0 * tc,
        neighbor: NeighborSpec::default(),
        output: OutputSpec { samples: 200, frames: 0, energy: true, contacts: false },
        analysis: Analysis::Impact,
        statistics: Default::default(),
        stages: Vec::new(),
    }
}

/// A grain of radius `r` hitting a flat wall at `angle_deg` from the normal at speed `v`.
pub fn oblique(material: Material, r: f64, v: f64, angle_deg: f64, tangential: TangentialSpec, steps_per_contact: f64) -> Scene {
    let a = angle_deg.to_radians();
    let mut s = head_on(material.clone(), r, v, steps_per_contact);
    // 10.5 steps before contact, as for head-on impacts (grain on wall: m* = m, R* = r).
    let m = 4.0 / 3.0 * std::f64::consts::PI * r * r * r * material.density;
    let e_star = crate::physics::material::PairMaterial::mix(&material, &material).e_star;
    let dt = crate::physics::material::hertz_contact_time(m, r, e_star, v).min(crate::physics::material::hertz_contact_time(m / 2.0, r / 2.0, e_star, v)) / steps_per_contact;
    let gap = 10.5 * v * a.cos() * dt;
    s.name = "oblique".into();
    s.description = BUILTIN[1].1.into();
    s.grains = Grains::List(vec![GrainSpec { x: [0.0, r + gap].into(), v: [v * a.sin(), -v * a.cos()].into(), omega: 0.0.into(), r, material: 0 }]);
    s.walls = Some(WallsSpec {
        bottom: WallSpec { y: Some(0.0), velocity_x: 0.0, velocity_y: 0.0, surface: SurfaceSpec::Flat, control: ControlSpec::Fixed, mass: None, material: 0 },
        top: WallSpec { y: Some(1.0), velocity_x: 0.0, velocity_y: 0.0, surface: SurfaceSpec::Flat, control: ControlSpec::Fixed, mass: None, material: 0 },
        thickness: None,
    });
    s.model.tangential = tangential;
    s
}

/// A grain of `shape` and radius `r` about to hit a rigid plane (a flat bottom wall at
/// y = 0) with normal speed `vn` (m/s), tangential velocity `vt` (m/s, along +x) and spin
/// `omega` (rad/s), 10.5 steps of t_c/`steps` before contact, t_c the Hertz contact time of
/// the grain on the plane at vn: the impacts of Chung & Ooi (2011) (tests/chung_ooi.rs,
/// the workbench's `chung-ooi` cases). "Rigid" is a wall material 1e30 Pa stiff (E* and G*
/// are the grain's own to 1e-19) of the grain's restitution and friction 1e3, so that the
/// pair takes the grain's values (the smaller of the two). The top wall is 100 r away.
#[allow(clippy::too_many_arguments)]
pub fn on_rigid_plane(grain: Material, shape: crate::physics::dim::GrainShape, r: f64, vn: f64, vt: f64, omega: f64, steps: f64, tangential: TangentialSpec) -> Scene {
    let mut s = oblique(grain.clone(), r, vn, 0.0, tangential, steps);
    let rigid = Material { name: "rigid".into(), youngs_modulus: 1e30, friction: 1e3, ..grain.clone() };
    let m = shape.mass(r, grain.density);
    let pm = crate::physics::material::PairMaterial::mix(&grain, &rigid);
    let tc = crate::physics::material::hertz_contact_time(m, r, pm.e_star, vn);
    let dt = tc / steps;
    let gap = 10.5 * vn * dt;
    s.name = "plane-impact".into();
    s.description = format!("a grain of radius {r} m on a rigid plane at vn = {vn} m/s, vt = {vt} m/s, spin {omega} rad/s");
    s.materials = vec![grain, rigid];
    s.grain_shape = shape;
    s.grains = Grains::List(vec![GrainSpec { x: [0.0, r + gap].into(), v: [vt, -vn].into(), omega: omega.into(), r, material: 0 }]);
    let w = s.walls.as_mut().expect("oblique has walls");
    w.bottom.material = 1;
    w.top.material = 1;
    w.top.y = Some(100.0 * r);
    s.time_step.rule = TimeStepRule::Fixed { dt };
    s.duration = 2.0 * gap / vn + 3.0 * tc;
    s
}

/// A grain of radius `r` hitting a resting twin at speed `v`, `angle_deg` between its
/// velocity and the line of centres at contact. It starts 10.5 steps before contact.
pub fn oblique_pair(material: Material, r: f64, v: f64, angle_deg: f64, tangential: TangentialSpec, steps_per_contact: f64) -> Scene {
    let a = angle_deg.to_radians();
    let mut s = head_on(material.clone(), r, v, steps_per_contact);
    let m = 4.0 / 3.0 * std::f64::consts::PI * r * r * r * material.density;
    let e_star = crate::physics::material::PairMaterial::mix(&material, &material).e_star;
    let dt = crate::physics::material::hertz_contact_time(m / 2.0, r / 2.0, e_star, v) / steps_per_contact;
    // Moving down (-y) onto a grain at the origin: at contact n = (sin a, cos a).
    let gap = 10.5 * v * dt;
    s.name = "oblique-pair".into();
    s.description = format!("a glass bead hitting a resting one at {angle_deg} degrees and {v} m/s");
    s.grains = Grains::List(vec![
        GrainSpec { x: [2.0 * r * a.sin(), 2.0 * r * a.cos() + gap].into(), v: [0.0, -v].into(), omega: 0.0.into(), r, material: 0 },
        GrainSpec { x: [0.0, 0.0].into(), v: [0.0, 0.0].into(), omega: 0.0.into(), r, material: 0 },
    ]);
    s.model.tangential = tangential;
    s
}

/// The seed's shear cell.
pub fn shear() -> Scene {
    let (l, v, p) = (0.04, 0.5, 1e5);
    Scene {
        name: "shear".into(),
        description: BUILTIN[2].1.into(),
        grain_shape: Default::default(),
        dimension: Default::default(),
        materials: vec![glass(0.5)],
        domain: Domain { periodic_x: Some([0.0, l]), periodic_z: None },
        grains: Grains::Pack(PackSpec {
            count: 1000,
            radius: RadiusDist::Uniform { min: 0.4e-3, max: 0.6e-3 },
            seed: 1,
            material: 0,
            x: [0.0, l],
            z: None,
            y_min: None,
            packing_fraction: 0.75,
        }),
        walls: Some(WallsSpec {
            bottom: WallSpec { y: Some(0.0), velocity_x: -v, velocity_y: 0.0, surface: SurfaceSpec::Rough { radius: 0.5e-3 }, control: ControlSpec::Fixed, mass: None, material: 0 },
            top: WallSpec { y: None, velocity_x: v, velocity_y: 0.0, surface: SurfaceSpec::Rough { radius: 0.5e-3 }, control: ControlSpec::Pressure(p), mass: None, material: 0 },
            thickness: None,
        }),
        gravity: [0.0, 0.0].into(),
        model: ModelSpec { lever_arm: LeverArm::Radius, ..ModelSpec::default() },
        time_step: TimeStepSpec { rule: TimeStepRule::StepsPerContact { steps: 50.0, impact_speed: v }, characteristic_speed: None, allow_unstable: false },
        duration: 0.05,
        neighbor: NeighborSpec::default(),
        output: OutputSpec { samples: 400, frames: 20, energy: true, contacts: false },
        analysis: Analysis::Shear,
        statistics: Default::default(),
        stages: Vec::new(),
    }
}

/// The shear box in space: 2000 glass spheres (radii uniform in 0.4-0.6 mm, volume
/// fraction 0.5 before the load) in a cell periodic in x and z, 10 x 10 mm, between
/// rough walls (square lattices of glued 0.5 mm spheres) at -+0.5 m/s, the top one under
/// 100 kPa on its 10 x 10 mm area; the 2D cell's model and time step.
pub fn shear3d() -> Scene {
    shear_box(2000, 0.01)
}

/// The 3D shear box ([`shear3d`]) with `count` spheres in a square cell `length` m on a
/// side (periodic in x and z): the same height when `count` grows with `length` squared
/// (2000 spheres per 10 x 10 mm), as the workbench's 3D ensembles and
/// `scripts/bench-peers` size it.
pub fn shear_box(count: usize, length: f64) -> Scene {
    let (l, v, p) = (length, 0.5, 1e5);
    let mut s = shear();
    s.name = "shear3d".into();
    s.description = BUILTIN[4].1.into();
    s.dimension = Dimension::Three;
    s.domain = Domain { periodic_x: Some([0.0, l]), periodic_z: Some([0.0, l]) };
    s.grains = Grains::Pack(PackSpec { count, radius: RadiusDist::Uniform { min: 0.4e-3, max: 0.6e-3 }, seed: 1, material: 0, x: [0.0, l], z: Some([0.0, l]), y_min: None, packing_fraction: 0.5 });
    let walls = s.walls.as_mut().expect("the shear cell has walls");
    (walls.bottom.velocity_x, walls.top.velocity_x, walls.top.control) = (-v, v, ControlSpec::Pressure(p));
    s.duration = 0.02;
    s.output.samples = 200;
    s
}

/// [`head_on`] in space: two spheres of radius `r` meeting at relative speed `v` along the
/// unit line `axis` (the plane's head-on impact turned onto it: the same gap, time step
/// and duration).
pub fn head_on_space(material: Material, r: f64, v: f64, steps_per_contact: f64, axis: [f64; 3]) -> Scene {
    let mut s = head_on(material, r, v, steps_per_contact);
    let Grains::List(g) = &mut s.grains else { unreachable!("head_on lists its grains") };
    for q in g.iter_mut() {
        let (x, vx) = (q.x[0], q.v[0]);
        q.x = axis.map(|a| a * x).into();
        q.v = axis.map(|a| a * vx).into();
    }
    s.name = "collision3d".into();
    s.description = BUILTIN[5].1.into();
    s.dimension = Dimension::Three;
    s
}

/// [`oblique`] in space: a sphere hitting the flat bottom wall at `angle_deg` from its
/// normal, its tangential velocity along the unit x-z direction `along` (the plane's
/// `oblique` has it along x).
pub fn oblique_space(material: Material, r: f64, v: f64, angle_deg: f64, tangential: TangentialSpec, steps_per_contact: f64, along: [f64; 2]) -> Scene {
    let mut s = oblique(material, r, v, angle_deg, tangential, steps_per_contact);
    let Grains::List(g) = &mut s.grains else { unreachable!("oblique lists its grain") };
    let (vt, vy, y) = (g[0].v[0], g[0].v[1], g[0].x[1]);
    g[0].x = [0.0, y, 0.0].into();
    g[0].v = [vt * along[0], vy, vt * along[1]].into();
    s.name = "oblique3d".into();
    s.description = BUILTIN[6].1.into();
    s.dimension = Dimension::Three;
    s
}

/// A plane impact `scene` in space, turned by `angle` (rad) about the unit `axis`: its
/// grains' positions, velocities and spins (about z in the plane, about the turned z in
/// space). A scene with walls may be turned only about y (walls are normal to y).
pub fn turned(scene: &Scene, axis: [f64; 3], angle: f64) -> Scene {
    let rot = nalgebra::Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(nalgebra::Vector3::from(axis)), angle);
    let mut s = scene.clone();
    s.dimension = Dimension::Three;
    if let Grains::List(list) = &mut s.grains {
        for g in list.iter_mut() {
            use crate::physics::dim::Space;
            let (x, v, w) = (rot * g.x.lift::<Space>(), rot * g.v.lift::<Space>(), rot * g.omega.lift::<Space>());
            (g.x, g.v, g.omega) = (<[f64; 3]>::from(x).into(), <[f64; 3]>::from(v).into(), SpinSpec::Vector(w.into()));
        }
    }
    s
}

/// The shear cell in a four-stage protocol: the packing is compressed under 100 kPa with
/// the walls at rest, relaxes under the load, is sheared with the walls at +-0.5 m/s and
/// then at +-2 m/s. The time step is set for contacts at 2 m/s, the fastest stage's
/// wall speed; the first two stages are not averaged (no steady shear).
pub fn protocol() -> Scene {
    let mut s = shear();
    s.name = "protocol".into();
    s.description = BUILTIN[3].1.into();
    let walls = s.walls.as_mut().expect("the shear cell has walls");
    walls.bottom.velocity_x = 0.0;
    walls.top.velocity_x = 0.0;
    s.time_step.rule = TimeStepRule::StepsPerContact { steps: 50.0, impact_speed: 2.0 };
    let shear_at = |name: &str, v: f64, duration: f64| StageSpec {
        name: name.into(),
        duration,
        walls: StageWalls { bottom: WallChange { velocity_x: Some(-v), ..WallChange::default() }, top: WallChange { velocity_x: Some(v), ..WallChange::default() } },
        average: true,
        ..StageSpec::default()
    };
    s.stages = vec![
        StageSpec { name: "compress".into(), duration: 0.01, average: false, ..StageSpec::default() },
        StageSpec { name: "relax".into(), duration: 0.005, average: false, ..StageSpec::default() },
        shear_at("shear 0.5", 0.5, 0.03),
        shear_at("shear 2", 2.0, 0.03),
    ];
    s.duration = 0.075;
    s.output.samples = 600;
    s.output.frames = 30;
    s
}

/// The seed's shear cell with `count` grains over a periodic length `length`, m: the
/// same height when `count` grows with `length` (1000 grains per 0.04 m), as the tests
/// and `scripts/bench-peers` size it.
pub fn shear_cell(count: usize, length: f64) -> Scene {
    let mut s = shear();
    if let Grains::Pack(p) = &mut s.grains {
        p.count = count;
        p.x = [0.0, length];
    }
    s.domain.periodic_x = Some([0.0, length]);
    s
}

/// A scene named on the command line: a built-in name, or a scene file (read up to the
/// budget's file size, [`crate::scene::limits::Limits::file_bytes`]). A built-in name wins over
/// a folder of that name in the working directory; a file of that name is ambiguous and
/// refused (write `./NAME` for the file). A grain file's relative path is taken from the
/// scene file's folder.
pub fn load(arg: &str, limits: &crate::scene::limits::Limits) -> Result<Scene, crate::Error> {
    let path = std::path::Path::new(arg);
    if let Some(scene) = builtin(arg) {
        if path.is_file() {
            return Err(crate::Error::Scene(format!("`{arg}` is both a built-in scene and a file in this folder: write `./{arg}` for the file")));
        }
        return Ok(scene);
    }
    if !path.exists() {
        let names: Vec<&str> = BUILTIN.iter().map(|b| b.0).collect();
        return Err(crate::Error::Scene(format!("`{arg}` is neither a scene file nor a built-in scene ({})", names.join(", "))));
    }
    let text = crate::scene::limits::read_bounded(path, limits.file_bytes(), "scene file")?;
    let mut scene = Scene::from_json(&text)?;
    if let Grains::File { path: grains, .. } = &mut scene.grains {
        let p = std::path::Path::new(grains.as_str());
        if p.is_relative() {
            let folder = path.parent().unwrap_or(std::path::Path::new(""));
            *grains = folder.join(p).to_string_lossy().into_owned();
        }
    }
    Ok(scene)
}

/// A built-in scene by name.
pub fn builtin(name: &str) -> Option<Scene> {
    match name {
        "collision" => Some(head_on(glass(0.5), 1e-3, 1.0, 200.0)),
        "oblique" => Some(oblique(glass(0.9), 1e-3, 1.0, 45.0, TangentialSpec::TotalDisplacement, 200.0)),
        "shear" => Some(shear()),
        "protocol" => Some(protocol()),
        "shear3d" => Some(shear3d()),
        "collision3d" => Some(head_on_space(glass(0.5), 1e-3, 1.0, 200.0, [2.0 / 3.0, 1.0 / 3.0, 2.0 / 3.0])),
        "oblique3d" => Some(oblique_space(glass(0.9), 1e-3, 1.0, 45.0, TangentialSpec::TotalDisplacement, 200.0, [0.6, 0.8])),
        _ => None,
    }
}
