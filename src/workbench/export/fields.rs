//! What every scene field becomes in each reference code's deck: the one table the
//! exporter and its test go by.
//!
//! Each leaf of the scene schema (a JSON path; list elements written `[]`, every enum
//! variant's fields included, a unit variant's choice at the enum's own path) has one
//! [`Decision`] per code:
//! - **written**: the value goes into the deck, `grains.data` or `export.json` (the text
//!   says where);
//! - **refused**: values the code cannot express are refused by name, as
//!   `export to CODE: PATH = VALUE cannot be expressed: WHY` ([`refuse`]);
//! - **differs**: the deck knowingly computes something else for some values, and says so
//!   in a line `# Differs: PATH = VALUE: WHAT` ([`differs_line`]);
//! - **outside**: not part of the physics a deck computes (the text says why it is fine
//!   to leave out); changing it leaves the exported files as they are;
//! - **one value**: scene validation admits a single value, which the deck expresses.
//!
//! A field may be written for some values and refused for others, or written with a
//! Differs note. `tests/export_fields.rs` derives the scene's JSON schema (schemars),
//! requires a decision here for every leaf and no entry without a leaf, and checks each
//! decision on scenes with that field changed: a scene field added without a decision,
//! or a decision the exporter does not keep, fails it. `grainlab export CODE
//! --explain-fields` prints the table of one code.

use std::fmt::Write as _;

use super::common::Code;
use crate::error::Error;

/// What one scene field becomes in one code's deck (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Decision {
    /// Where the value goes.
    pub written: Option<&'static str>,
    /// Which values are refused, and why.
    pub refused: Option<&'static str>,
    /// For which values the deck computes something else, and what (a `# Differs:` line).
    pub differs: Option<(&'static str, &'static str)>,
    /// Why the field may be left out.
    pub outside: Option<&'static str>,
    /// The one value validation admits, and what the deck does with it.
    pub one_value: Option<&'static str>,
}

/// Why no code's deck can express `model.tangential = "mindlin_deresiewicz"`.
const MICROSLIP_REFUSED: &str = "\"mindlin_deresiewicz\": no reference code has micro-slip (LIGGGHTS', LAMMPS' and YADE's Mindlin laws are no-slip springs, and YADE's Law2_ScGeom_MindlinPhys_MindlinDeresiewitz computes no shear force); the nearest law's oblique impacts differ several-fold at small angles";

const NONE: Decision = Decision { written: None, refused: None, differs: None, outside: None, one_value: None };

const fn written(to: &'static str) -> Decision {
    Decision { written: Some(to), ..NONE }
}
const fn refused(why: &'static str) -> Decision {
    Decision { refused: Some(why), ..NONE }
}
const fn differs(when: &'static str, what: &'static str) -> Decision {
    Decision { differs: Some((when, what)), ..NONE }
}
const fn outside(why: &'static str) -> Decision {
    Decision { outside: Some(why), ..NONE }
}
const fn one_value(what: &'static str) -> Decision {
    Decision { one_value: Some(what), ..NONE }
}

impl Decision {
    /// Also refuse some values.
    const fn or_refused(self, why: &'static str) -> Decision {
        Decision { refused: Some(why), ..self }
    }
    /// Also note a difference for some values.
    const fn or_differs(self, when: &'static str, what: &'static str) -> Decision {
        Decision { differs: Some((when, what)), ..self }
    }
}

/// One scene field and what it becomes in each code.
#[derive(Clone, Copy, Debug)]
pub struct Field {
    /// JSON path, list elements as `[]`.
    pub path: &'static str,
    pub liggghts: Decision,
    pub yade: Decision,
    pub lammps: Decision,
}

impl Field {
    pub fn decision(&self, code: Code) -> &Decision {
        match code {
            Code::Liggghts => &self.liggghts,
            Code::Yade => &self.yade,
            Code::Lammps => &self.lammps,
        }
    }
    /// LAMMPS' decision where it is not LIGGGHTS' (the two read one input language, and
    /// the LAMMPS deck shares the LIGGGHTS deck's commands for grains, rows and records).
    const fn in_lammps(self, d: Decision) -> Field {
        Field { lammps: d, ..self }
    }
}

const fn both(path: &'static str, d: Decision) -> Field {
    Field { path, liggghts: d, yade: d, lammps: d }
}
/// LIGGGHTS' and YADE's decisions; LAMMPS takes LIGGGHTS' unless [`Field::in_lammps`]
/// says otherwise.
const fn each(path: &'static str, liggghts: Decision, yade: Decision) -> Field {
    Field { path, liggghts, yade, lammps: liggghts }
}

const NAME_L: &str = "the comments of in.liggghts, the title line of grains.data, export.json `scene`; escaped to printable ASCII on one line (`\\`, quotes, control and non-ASCII characters as Rust escapes, `&` as `\\u{26}`): no line break starts a command and no comment ends in `&`, which would continue it onto the next line";
const NAME_Y: &str = "the comments of yade.py, the title line of grains.data, export.json `scene`; escaped to printable ASCII on one line (`\\`, quotes, control and non-ASCII characters as Rust escapes): no line break starts a Python statement";
const PACKED: &str = "grains.data: grainlab generates the packing once, so both codes start from the same grains";
const RULE_L: &str = "resolved into dt: `timestep DT` and `run N` (N = ceil(duration / dt)), export.json time_step_s";
const RULE_Y: &str = "resolved into dt: `O.dt = DT` and STEPS (N = ceil(duration / dt)), export.json time_step_s";
const Y_L: &str = "flat: `fix wall/gran ... primitive yplane Y`; rough: the row's atoms in grains.data";
const Y_Y: &str = "flat: `wall(Y, axis=1)`; rough: the row's spheres in grains.data";
const VX_L: &str = "flat: `shear x V` on the wall/gran fix; rough: the row's velocities in grains.data, kept by `setforce 0.0 ...` and nve";
const VX_Y: &str = "flat: the wall body's state.vel; rough: the row's velocities in grains.data, kept by blockedDOFs (the loaded row as a clump)";
const VY_L: &str = "rough: the row's velocities in grains.data, kept by `setforce 0.0 0.0 0.0` and nve";
const VY_Y: &str = "rough: the row's velocities in grains.data, kept by blockedDOFs 'xyzXYZ'";
const VY_FLAT: &str = "a flat wall moving in y: the decks' planes do not move in y (refused as walls.NAME.velocity_y)";
const SURFACE_L: &str = "flat: a primitive `wall/gran` plane (R* = r, m* = m, as grainlab); rough: a row of atoms in grains.data moved as one (setforce + nve)";
const SURFACE_Y: &str = "flat: a `wall` body with Ig2_Wall_Sphere_ScGeom(hertzian=True); rough: the row's spheres from grains.data, blocked at their velocity (`xyzXYZ`), the loaded top row one clump";
const FLAT_IN_SHEAR: &str = "a flat wall in a shear scene: the shear decks measure the forces on the rows of rough walls";
const FLAT_Y: &str = "YADE's hertzian wall has a large finite radius, so R* and the ratcheting factor differ from a plane's by O(r / R_wall) (2e-9 relative on the oblique impacts)";
const ROUGH_R: &str = "grains.data: the row's atoms (their number and diameter)";
const MATERIAL_L: &str = "flat: the wall/gran fix's atom type (material + 1); rough: the row's atom type in grains.data";
const MATERIAL_Y: &str = "flat: the wall body's material mats[k]; rough: the row's atom type in grains.data";
const BOTTOM_CONTROL: &str = "\"fixed\": only the top wall carries a load (scene validation refuses a pressure on the bottom wall); the decks hold the bottom wall (a fixed plane, or a row at constant velocity)";
const BOTTOM_MASS: &str = "the bottom wall is always held in y (only the top wall carries a load), so its mass has no effect, in grainlab either";
const THICKNESS: &str = "export.json depth_m (wall forces to stresses), and the load p L_x t on a loaded top wall";
const LIST_X: &str = "grains.data Atoms: x y (z = 0 in 2D; a 3D scene's x y z)";
const LIST_V: &str = "grains.data Velocities: vx vy (vz = 0 in 2D; a 3D scene's vx vy vz)";
const LIST_R: &str = "grains.data Atoms: diameter 2 r";
const ATOM_TYPE: &str = "grains.data atom type (material + 1)";
const NAME_M: &str = "the comments of in.lammps, the title line of grains.data, export.json `scene`; escaped to printable ASCII on one line (`\\`, quotes, control and non-ASCII characters as Rust escapes, `&` as `\\u{26}`): no line break starts a command and no comment ends in `&`, which LAMMPS too reads as a line continued by the next";
const Y_M: &str = "flat: `fix wall/gran granular ... yplane Y NULL` (bottom: grains above) or `yplane NULL Y` (top); rough: the row's atoms in grains.data";
const SURFACE_M: &str = "flat: `fix wall/gran granular` planes (R* = r, m* = m, as grainlab), one per material of the free grains, each with that pair's coefficients; rough: a row of atoms in grains.data moved as one (setforce + nve)";
const MATERIAL_M: &str = "flat: the wall/gran fixes take the coefficients of the pair (wall material, grain material); rough: the row's atom type in grains.data";
const MODULI_M: &str = "each pair of atom types' `pair_coeff I J hertz KN ...` with KN = 4/3 E* and `tangential mindlin KT ...` with KT = 8 G*, mixed by grainlab (LAMMPS' hertz/material would take a given pair as one material, and mixes the pairs not given its own way); the derived spring's kn from E*";
const SPRING_REFUSED_M: &str = "the derived spring where a pair of atom types, or a flat wall and a material of the free grains, meets at more than one kn (grains of several sizes or masses): LAMMPS' `hooke` takes one kn per pair of types and per wall fix";
const SPRING_M: &str = "`hooke KN` and `tangential linear_history KT` in every pair_coeff and wall/gran fix; `damping tsuji` damps each contact with its own sqrt(m* kn), so grains of every size and mass are exact";
const TANGENTIAL_M: &str = "LAMMPS' total-displacement history (grainlab's total_force_cap) caps the total tangential force (elastic and damping) and, on slip, keeps the displacement that gives the cap with the damping; between grains it rescales the history to its length when the contact frame turns. grainlab's total_displacement caps the elastic force alone and projects the history: frictional contacts with damping (e < 1), and frictional grain pairs, differ (head-on and frictionless impacts, and a grain on a flat wall at e = 1, agree); incremental_force is YADE's law, which differs more";
const NORMAL_Y: &str = "hertz: FrictMat and Ip2_FrictMat_FrictMat_MindlinPhys; hooke, hooke_stiffness: ViscElMat(kn, ks, cn, cs) per material and per flat wall (KN, KS, CN, CS, WALL_*), which Ip2_ViscElMat_ViscElMat_ViscElPhys puts in series per contact, solved by grainlab from its pairs' kn, kt, 2 |beta| sqrt(m* k), and Law2_ScGeom_ViscElPhys_Basic";
const SPRING_REFUSED_Y: &str = "a pair of materials (or a flat wall and a material) whose contacts meet at more than one stiffness or damping rate (the derived spring, or damping, of grains of several sizes or masses), or whose values no per-material values in series give: YADE's ViscElMat gives each body one spring and one dashpot, and a contact the two in series";
const SPRING_Y: &str = "the KN, KS (and CN, CS) lists of ViscElMat: twice the pair's value for a material's own grains, the series partner for a flat wall (grainlab's kn, kt per pair, as derived or given)";
const SPRING_L: &str = "`fix m5 kn`, `fix m6 kt` per pair of atom types, and the damping rates gamman, gammat = -2 beta(e) sqrt(k / m*) (LIGGGHTS multiplies them by m*)";
const SPRING_REFUSED_L: &str = "a pair of materials that meets at more than one reduced mass (grains of two sizes, or a grain and a flat wall): hooke/stiffness takes one damping rate per pair of atom types, times m*";
const SPIN_NO_ROTATION: &str = "a non-zero spin with model.rotation = false (and friction): grainlab's grain-grain contacts then leave the spin out of the contact velocity, LIGGGHTS and LAMMPS (`nve`) and YADE (blocked rotation) keep the spin, which never changes, in it";
const SPACE_L: &str = "2: spheres at z = 0 in a 3D box, which nothing moves out of the plane (`boundary X f f`, z bounds +-2 r_max); 3: spheres in space, no 2D constraint (no `enforce2d`, no `dimension 2`): `boundary X f Z` (p along a periodic x or z, else bounds that hold the grains for the run), each grain's z, vz and spin (wx, wy, wz) in grains.data, the rough walls' lattices of atoms (L_x by L_z) moved as one, series.txt and walls.txt with the z components (export.json dimension and columns)";
const SPACE_Y: &str = "2: spheres with blockedDOFs 'zXY' (the sphere-in-plane model); 3: free spheres (no blocked DOF; 'XYZ' without rotation) with each grain's z, vz and spin (wx, wy, wz) from grains.data, the periodic cell periodic in z too where the scene is (else 10x the packing along z, as along y), the rough walls' lattices of spheres (L_x by L_z) blocked or clumped, series.txt and walls.txt with the z components (export.json dimension and columns)";
const NOT_PHYSICS_OUTPUT: &str = "grainlab's own output";

/// Every leaf of the scene schema and its decision for each code.
pub const FIELDS: &[Field] = &[
    each("name", written(NAME_L), written(NAME_Y)).in_lammps(written(NAME_M)),
    both("description", outside("free text: no physics, not written (the decks name the scene by its name)")),
    each(
        "grain_shape",
        refused("\"disk\": not exported yet; the deck writes spheres at z = 0 (sphere_in_plane: mass 4/3 pi r^3 rho, inertia 2/5 m r^2), and LIGGGHTS' `dimension 2` disks (pi r^2 rho per metre, m r^2 / 2) would need a deck of their own (enforce2d, density times thickness), not written nor checked against LIGGGHTS"),
        refused("\"disk\": YADE's spheres with blockedDOFs 'zXY' are the sphere_in_plane model (mass 4/3 pi r^3 rho, inertia 2/5 m r^2); this contact law has no disk of a stated thickness there"),
    )
    .in_lammps(refused("\"disk\": not exported yet; the deck writes spheres at z = 0 (sphere_in_plane: mass 4/3 pi r^3 rho, inertia 2/5 m r^2), and LAMMPS' disks (`dimension 2`, `set ... density/disc`, `fix enforce2d`) would need a deck of their own, not written nor checked against LAMMPS")),
    each(
        "grain_shape.disk.thickness",
        refused("disks are not exported yet (see grain_shape)"),
        refused("disks cannot be expressed (see grain_shape)"),
    ),
    each("dimension", written(SPACE_L), written(SPACE_Y)),
    both("materials[].name", outside("a label: the decks refer to materials by position (LIGGGHTS atom type k + 1, YADE mats[k])")),
    each("materials[].youngs_modulus", written("`fix m1 ... youngsModulus peratomtype`"), written("E[k], FrictMat(young)")).in_lammps(written(MODULI_M)),
    each(
        "materials[].poisson_ratio",
        written("`fix m2 ... poissonsRatio peratomtype` (LIGGGHTS mixes E* and G* as grainlab)"),
        written("NU[k], FrictMat(poisson) (YADE 2023.02 mixes E* and G* as grainlab)"),
    )
    .in_lammps(written(MODULI_M)),
    each(
        "materials[].density",
        written("grains.data density column (atom mass 4/3 pi r^3 rho)"),
        written("RHO[k], FrictMat(density): sphere mass 4/3 pi r^3 rho"),
    ),
    each(
        "materials[].restitution",
        written("`fix m3 ... coefficientRestitution peratomtypepair`, each pair the smaller e (grainlab's rule)")
            .or_refused("e <= 0.05 under `model hertz` and `model hooke`: LIGGGHTS 3.8 requires 0.05 < coefficientRestitution <= 1 (global_properties.cpp; `hooke/stiffness` damps with the written gammas and takes any)"),
        written("BETA = sqrt(5/6) |beta(e)| as Ip2_FrictMat_FrictMat_MindlinPhys(betan = betas = BETA), never `en` (a different damping fit)")
            .or_refused("materials of different restitution: YADE's Ip2_FrictMat_FrictMat_MindlinPhys takes one betan for every pair"),
    )
    .in_lammps(written("each pair of types' damping, the pair's smaller e: `damping tsuji` with the input c whose LAMMPS polynomial 1.2728 - 4.2783 c + 11.087 c^2 - 22.348 c^3 + 27.467 c^4 - 18.022 c^5 + 4.8218 c^6 equals sqrt(5) |beta(e)| (Hertz) or 2 |beta(e)| (linear spring), solved by bisection (c < 0 for e below about 0.11, c > 1 above 0.9995: LAMMPS does not clip it); `damping viscoelastic` with 0 at e = 1; the tangential damping x_gt = sqrt(kt / Sn), the tangential-to-normal ratio of grainlab's")),
    each(
        "materials[].friction",
        written("`fix m4 ... coefficientFriction peratomtypepair`, each pair the smaller mu (0 when frictionless)"),
        written("MU[k], FrictMat(frictionAngle = atan(mu)): YADE takes the pair's smaller angle (0 when frictionless)"),
    )
    .in_lammps(written("each pair of types' `tangential ... MU`, the pair's smaller mu (0 when frictionless)")),
    each(
        "materials[].work_of_adhesion",
        refused("above 0 (DMT cohesion; 0, no cohesion, is what the deck computes): LIGGGHTS 3.8's cohesion models (sjkr, sjkr2) are other laws"),
        refused("above 0 (DMT cohesion; 0, no cohesion, is what the deck computes): YADE 2023's Mindlin law has no DMT attraction"),
    )
    .in_lammps(
        written("each pair of types' normal model: above 0 `dmt 2E* D 0 GAMMA` with GAMMA = w/2 (LAMMPS' 4 pi GAMMA R* is grainlab's 2 pi w R*, w the pair's geometric mean; Poisson 0 makes LAMMPS' 4/3 E/(2(1 - nu^2)) between grains and 4/3 E/(2(1 - nu)) on a wall both 4/3 E*); head-on and frictionless contacts agree to rounding")
            .or_refused("above 0 with model.normal = hooke or hooke_stiffness: LAMMPS' dmt is Hertzian")
            .or_differs("above 0 with friction", "LAMMPS 20220106's DMT friction cap mu |Fne + 2 F_pulloff| takes F_pulloff = 4 pi coh R* from a variable its DMT branch never sets (only JKR's does): measured on one grain sliding on a wall/gran plane and on a pair, the cap is mu |Fne + 8 pi 1e-6 R*| whatever the input cohesion, instead of grainlab's (and later LAMMPS releases') mu |Fn + 2 F0|; frictional DMT contacts differ"),
    ),
    each(
        "materials[].rolling_friction",
        written("`fix m9 ... coefficientRollingFriction peratomtypepair`, each pair the smaller mu_r (with model.rolling cdt or epsd2)"),
        outside("read only with model.rolling other than none, which the YADE export refuses"),
    )
    .in_lammps(written("each pair of types' `rolling sds K G MU_R`, MU_R the pair's smaller mu_r (with model.rolling sds)")),
    each(
        "domain.periodic_x",
        written("`boundary p f f` and the box's x bounds in grains.data"),
        written("a periodic cell of length L from x_min (y and z 10x the packing: YADE cells are periodic in every direction)")
            .or_refused("an impact scene, or a scene without two rough walls: YADE's periodic script is the shear cell's (rough rows, the top one loaded or held); or a cell shorter than 4 r_max + 2 r_min: YADE's periodic collider stops on a body whose bounds (its diameter and twice the Verlet distance, by default half the smallest radius) span over half the cell"),
    ),
    each(
        "domain.periodic_z",
        written("3D: `boundary X f p` and the box's z bounds in grains.data"),
        written("3D: the periodic cell's z length LZ from Z0 (the shear cell's script)")
            .or_refused("without domain.periodic_x (YADE's periodic script is the shear cell's; the open script has no periodic cell), or a cell shorter along z than 4 r_max + 2 r_min (YADE's periodic collider, as along x)"),
    ),
    both("grains.list[].x", written(LIST_X)),
    both("grains.list[].v", written(LIST_V)),
    both("grains.list[].omega", written("grains.data Velocities: wz (wx = wy = 0 in 2D; a 3D scene's wx wy wz)").or_refused(SPIN_NO_ROTATION)),
    both("grains.list[].r", written(LIST_R)),
    both("grains.list[].material", written(ATOM_TYPE)),
    both("grains.file.path", written("grains.data: grainlab reads the file and writes its grains (the decks never read the path)")),
    both("grains.file.columns", outside("the grain file's format: the grains grainlab reads with it are written to grains.data (see grains.file.path); the same file read with other columns is refused, so a change of it alone never reaches a deck")),
    both("grains.file.material", written(ATOM_TYPE)),
    both("grains.pack.count", written(PACKED)),
    both("grains.pack.radius.fixed.radius", written(PACKED)),
    both("grains.pack.radius.uniform.min", written(PACKED)),
    both("grains.pack.radius.uniform.max", written(PACKED)),
    both("grains.pack.radius.normal.mean", written(PACKED)),
    both("grains.pack.radius.normal.std", written(PACKED)),
    both("grains.pack.radius.normal.min", written(PACKED)),
    both("grains.pack.radius.normal.max", written(PACKED)),
    both("grains.pack.radius.lognormal.median", written(PACKED)),
    both("grains.pack.radius.lognormal.sigma", written(PACKED)),
    both("grains.pack.radius.lognormal.min", written(PACKED)),
    both("grains.pack.radius.lognormal.max", written(PACKED)),
    both("grains.pack.seed", written(PACKED)),
    both("grains.pack.material", written(ATOM_TYPE)),
    both("grains.pack.x", written(PACKED)),
    both("grains.pack.y_min", written(PACKED)),
    both("grains.pack.z", written(PACKED)),
    both("grains.pack.packing_fraction", written(PACKED)),
    each("walls.bottom.y", written(Y_L), written(Y_Y)).in_lammps(written(Y_M)),
    each("walls.bottom.velocity_x", written(VX_L), written(VX_Y)),
    each("walls.bottom.velocity_y", written(VY_L).or_refused(VY_FLAT), written(VY_Y).or_refused(VY_FLAT)),
    each(
        "walls.bottom.surface",
        written(SURFACE_L).or_refused(FLAT_IN_SHEAR),
        written(SURFACE_Y).or_refused(FLAT_IN_SHEAR).or_differs("flat", FLAT_Y),
    )
    .in_lammps(written(SURFACE_M).or_refused(FLAT_IN_SHEAR)),
    both("walls.bottom.surface.rough.radius", written(ROUGH_R)),
    both("walls.bottom.control", one_value(BOTTOM_CONTROL)),
    both("walls.bottom.control.pressure", one_value(BOTTOM_CONTROL)),
    both("walls.bottom.mass", outside(BOTTOM_MASS)),
    each("walls.bottom.material", written(MATERIAL_L), written(MATERIAL_Y)).in_lammps(written(MATERIAL_M)),
    each("walls.top.y", written(Y_L), written(Y_Y)).in_lammps(written(Y_M)),
    each("walls.top.velocity_x", written(VX_L), written(VX_Y)),
    each("walls.top.velocity_y", written(VY_L).or_refused(VY_FLAT), written(VY_Y).or_refused(VY_FLAT)),
    each(
        "walls.top.surface",
        written(SURFACE_L).or_refused(FLAT_IN_SHEAR),
        written(SURFACE_Y).or_refused(FLAT_IN_SHEAR).or_differs("flat", FLAT_Y),
    )
    .in_lammps(written(SURFACE_M).or_refused(FLAT_IN_SHEAR)),
    both("walls.top.surface.rough.radius", written(ROUGH_R)),
    each(
        "walls.top.control",
        written("\"fixed\": a fixed plane, or `setforce 0.0 0.0 0.0` on the row").or_refused("a load on a flat wall (see walls.top.control.pressure)"),
        written("\"fixed\": a fixed wall body, or the row blocked at its velocity").or_refused("a load on a flat wall, or without a periodic x (see walls.top.control.pressure)"),
    ),
    each(
        "walls.top.control.pressure",
        written("the load p L_x t (3D: p L_x L_z) on the rough row (3D: lattice): `setforce 0.0 NULL 0.0`, `aveforce NULL -F/n NULL` (per atom) and nve move it as one body of its atoms' mass")
            .or_refused("on a flat wall: a primitive wall/gran plane cannot carry a load; use a rough wall"),
        written("LOAD = p L_x t (3D: p L_x L_z), a permanent force on the top row's clump (blockedDOFs 'xzXYZ')")
            .or_refused("on a flat wall (a wall body cannot carry a load; use a rough wall), or without a periodic x (the script moves a loaded row in the periodic cell only, and holds rough rows elsewhere)")
            .or_differs("any", "YADE's leapfrog takes the initial velocities as v(-1/2), grainlab's velocity Verlet as v(0): bodies under a force at t = 0 (the loaded wall, touching grains) start O(a dt^2) apart, which a flow forgets"),
    )
    .in_lammps(
        written("the load p L_x t (3D: p L_x L_z) on the rough row (3D: lattice): `setforce 0.0 NULL 0.0`, `aveforce NULL -F/n NULL` (per atom) and nve move it as one body of its atoms' mass")
            .or_refused("on a flat wall: a wall/gran plane cannot carry a load; use a rough wall"),
    ),
    each(
        "walls.top.mass",
        refused("a loaded top wall whose mass differs from its row's atoms' total beyond rounding (1e-12): LIGGGHTS moves the row as its atoms (nve, aveforce), and another atom density would change the contact damping (m*); a fixed wall's mass has no effect, in grainlab either"),
        written("a loaded top row: the clump's state.mass (NewtonIntegrator accelerates a clump by F / state.mass; its spheres keep their own masses in the contact damping, as grainlab's glued grains); a fixed wall's mass has no effect, in grainlab either"),
    )
    .in_lammps(refused("a loaded top wall whose mass differs from its row's atoms' total beyond rounding (1e-12): LAMMPS moves the row as its atoms (nve, aveforce), and another atom density would change the contact damping (m*); a fixed wall's mass has no effect, in grainlab either")),
    each("walls.top.material", written(MATERIAL_L), written(MATERIAL_Y)).in_lammps(written(MATERIAL_M)),
    both("walls.thickness", written(THICKNESS)),
    each(
        "gravity",
        refused("not exported yet: grainlab pulls the free grains only, and a `fix gravity` on the free group has not been checked against it"),
        refused("not exported yet: NewtonIntegrator's gravity would also pull the loaded wall's clump, which grainlab's gravity does not"),
    ),
    each(
        "model.normal",
        written("`pair_style gran model hertz` (hertz), `model hooke` (hooke), `model hooke/stiffness` (hooke_stiffness), in the pair style and the wall/gran fixes")
            .or_refused(SPRING_REFUSED_L),
        written(NORMAL_Y).or_refused(SPRING_REFUSED_Y),
    )
    .in_lammps(written("`hertz` (hertz) or `hooke` (hooke, hooke_stiffness) in every pair_coeff and wall/gran fix").or_refused(SPRING_REFUSED_M)),
    each(
        "model.normal.hooke.characteristic_velocity",
        written("`fix m5 all property/global characteristicVelocity scalar VC` (LIGGGHTS derives kn = kt from it per contact, as grainlab does)"),
        written(SPRING_Y),
    )
    .in_lammps(written("kn = kt of each pair of types and each wall fix, derived by grainlab from VC, E*, R* and m* (LIGGGHTS' formula): `hooke KN` and `tangential linear_history KT`").or_refused(SPRING_REFUSED_M)),
    each(
        "model.normal.hooke_stiffness.kn",
        written(SPRING_L).or_refused(SPRING_REFUSED_L),
        written(SPRING_Y),
    )
    .in_lammps(written(SPRING_M)),
    each(
        "model.normal.hooke_stiffness.kt",
        written(SPRING_L).or_refused(SPRING_REFUSED_L),
        written(SPRING_Y),
    )
    .in_lammps(written(SPRING_M)),
    each(
        "model.damping",
        written("\"clamped_restitution\": coefficientRestitution of each pair the e' whose beta(e') is the pair's clamped beta (LIGGGHTS turns it back to rounding)")
            .or_refused("\"tsuji\" and \"tsuji_sqrt2\": LIGGGHTS 3.8's `model hertz` and `model hooke` damp with beta(e) only; it has no Tsuji fit; \"clamped_restitution\" under `model hertz` or `model hooke` with a pair's e below 0.214, whose e' is at or below 0.05 (LIGGGHTS requires 0.05 < coefficientRestitution there)"),
        written("\"clamped_restitution\": betan = betas = sqrt(5/6) |beta| of the clamped beta (Hertz), the spring's cn, cs from it (YADE always clamps)")
            .or_refused("\"tsuji\" and \"tsuji_sqrt2\": YADE's Mindlin law damps with betan, betas only; it has no Tsuji fit"),
    )
    .in_lammps(written("\"restitution\" and \"clamped_restitution\": `damping tsuji` with the input that gives grainlab's damping of each pair (materials[].restitution and its beta); \"tsuji\": `damping tsuji` with each pair's restitution as its input, LAMMPS' own fit, and X = sqrt(kt / kn); \"tsuji_sqrt2\": `damping tsuji` with the input c whose fit equals sqrt(2) alpha(e), solved by bisection as above, and X = sqrt(kt / kn)")),
    each(
        "model.tangential",
        written("total_displacement: `pair_style gran model hertz tangential history`; frictionless: coefficientFriction 0 (Ft = 0) and `nve`")
            .or_differs("incremental_force, total_force_cap, total_force_cap_spring_kept", "LIGGGHTS has only the total-displacement history, which caps the elastic force alone; head-on impacts agree, oblique ones differ (incremental_force: rebound spin up to 2x; total_force_cap, total_force_cap_spring_kept: frictional contacts with damping)")
            .or_refused(MICROSLIP_REFUSED),
        written("incremental_force: Law2_ScGeom_MindlinPhys_Mindlin; frictionless: frictionAngle 0 (Ft = 0)")
            .or_differs("total_displacement, total_force_cap, total_force_cap_spring_kept", "YADE's Mindlin law adds force increments; head-on impacts agree, oblique ones differ (rebound spin up to 2x)")
            .or_refused(MICROSLIP_REFUSED),
    )
    .in_lammps(
        written("total_force_cap (LAMMPS' own law) and total_displacement: `tangential mindlin` (Hertz) or `tangential linear_history` (linear spring), a total tangential displacement; frictionless: MU 0 (Ft = 0) and `nve`")
            .or_differs("total_displacement, total_force_cap_spring_kept, incremental_force", TANGENTIAL_M)
            .or_refused(MICROSLIP_REFUSED),
    ),
    each(
        "model.limit_force",
        written("`limitForce on` in the pair style and the wall/gran fixes"),
        differs("false", "YADE always clamps Fn >= 0 (the realised restitution is higher, most for small e)"),
    )
    .in_lammps(written("`limit_damping` in every pair_coeff and wall/gran fix: the total normal force clamped at 0, as grainlab's clamp")),
    each(
        "model.lever_arm",
        differs("radius, yade, contact_point, lammps", "LIGGGHTS' arm is r - dn/2, in the torque and in the contact velocity (lever_arm radius_minus_half_overlap); torques and tangential velocities differ by O(dn/r)"),
        differs("radius, radius_minus_half_overlap, contact_point (Hertz), yade (linear spring), lammps", "YADE's Mindlin law (Hertz) has the ScGeom kinematics of lever_arm yade (full radii for the spins in the contact velocity, its translational part scaled by (r1 + r2) / (r1 + r2 - dn), torque arm r - dn/2, r - dn on a wall); its ViscElPhys law (the linear spring) the contact point's, lever_arm contact_point (r - dn/2 between grains, r - dn on a wall, in the velocity and the torque); torques and tangential velocities differ by O(dn/r)"),
    )
    .in_lammps(written("lammps: LAMMPS' own arms (r in the contact velocity and r - dn/2 in the torque between grains, r in both on a wall/gran plane); radius is the same for a grain on a flat wall").or_differs("radius (grain pairs), radius_minus_half_overlap, yade, contact_point", "LAMMPS' arms are lever_arm lammps; torques and tangential velocities of frictional grain pairs differ by O(dn/r)")),
    each(
        "model.rolling",
        written("cdt, epsd2: `rolling_friction cdt` or `rolling_friction epsd2` in the pair style and the wall/gran fixes (LIGGGHTS scales a grain's spin on a wall by (r - dn/2)/(r - dn) for EPSD2, which grainlab does with lever_arm radius_minus_half_overlap)")
            .or_refused("sds: LIGGGHTS 3.8 has cdt, epsd, epsd2 and epsd3, no spring-dashpot-slider on a rolling displacement"),
        written("none: no rolling torque, as YADE's Mindlin law").or_refused("cdt, epsd2, sds: YADE 2023's Mindlin law has no rolling resistance (its rolling moments belong to CohFrictMat's law)"),
    )
    .in_lammps(written("sds: `rolling sds K G MU_R` in every pair_coeff and wall/gran fix (a grain on a wall: R* = r, as grainlab)").or_refused("cdt, epsd2: LAMMPS 20220106's pair granular has rolling sds only")),
    each(
        "model.rolling.sds.stiffness",
        outside("read only with model.rolling = sds, which the LIGGGHTS export refuses"),
        outside("read only with model.rolling = sds, which the YADE export refuses"),
    )
    .in_lammps(written("`rolling sds K ...`: K, N/m")),
    each(
        "model.rolling.sds.damping",
        outside("read only with model.rolling = sds, which the LIGGGHTS export refuses"),
        outside("read only with model.rolling = sds, which the YADE export refuses"),
    )
    .in_lammps(written("`rolling sds K G ...`: G, kg/s (LAMMPS' gamma_roll, not scaled by the normal damping)")),
    each(
        "model.rotation",
        written("false: `fix nve` for the free grains instead of `nve/sphere`"),
        written("false: blockedDOFs 'zXYZ' for the free grains instead of 'zXY' (3D: 'XYZ' instead of none)"),
    ),
    each(
        "model.general_damping",
        refused("grainlab's drag is F = -c m v and M = -c I w on each free grain; LIGGGHTS' `fix viscous` applies -gamma v with one gamma per atom type and no torque"),
        refused("grainlab's drag is F = -c m v and M = -c I w on each free grain; NewtonIntegrator's damping is Cundall's non-viscous damping (the force scaled by 1 - d sign(F v)), LinearDragEngine a Stokes drag 6 pi nu r v without torque"),
    )
    .in_lammps(refused("grainlab's drag is F = -c m v and M = -c I w on each free grain; LAMMPS' `fix viscous` applies -gamma v with one gamma per atom type and no torque")),
    each("time_step.rule.fixed.dt", written(RULE_L), written(RULE_Y)),
    each("time_step.rule.steps_per_contact.steps", written(RULE_L), written(RULE_Y)),
    each("time_step.rule.steps_per_contact.impact_speed", written(RULE_L), written(RULE_Y)),
    each("time_step.rule.rayleigh_fraction.fraction", written(RULE_L), written(RULE_Y)),
    each("time_step.rule.seed_rule.factor", written(RULE_L), written(RULE_Y)),
    each("time_step.rule.seed_rule.reference_overlap", written(RULE_L), written(RULE_Y)),
    each("time_step.rule.accuracy.quantity", written(RULE_L), written(RULE_Y)),
    each("time_step.rule.accuracy.tolerance", written(RULE_L), written(RULE_Y)),
    each("time_step.rule.accuracy.impact_speed", written(RULE_L), written(RULE_Y)),
    both(
        "time_step.characteristic_speed",
        outside("sets grainlab's stability check and the reported steps per contact only; the deck takes the resolved dt"),
    ),
    both("time_step.allow_unstable", outside("grainlab's guard against a dt above the stability limit; the deck takes the same dt either way")),
    each(
        "duration",
        written("`run N` (N = ceil(duration / dt)), export.json steps, and the box's margins in grains.data"),
        written("STEPS (N = ceil(duration / dt)), export.json steps, and the margins in grains.data"),
    ),
    each(
        "neighbor.skin",
        written("`neighbor SKIN bin`, SKIN = skin x the smallest free grain's diameter"),
        outside("a neighbour-list setting: the contacts found do not depend on it, and YADE sizes its own Verlet distance"),
    ),
    each(
        "output.samples",
        written("steps per walls.txt row (shear decks: `fix ave/time` and `fix print`), export.json sample_every; impact decks record every step"),
        written("steps per walls.txt row (shear scripts: SAMPLE), export.json sample_every; impact scripts record every step"),
    ),
    both("output.frames", outside(NOT_PHYSICS_OUTPUT)),
    both("output.contacts", outside("grainlab's own record of the contacts (packing.csv), read from the forces the step computes without changing them")),
    both("output.energy", outside("grainlab's energy ledger, a compile-time switch that leaves the forces as they are; the decks record states and forces")),
    both(
        "analysis",
        written("what the deck records: impact, series.txt at every step; shear, walls.txt; none, nothing (a deck to time or to watch); export.json analysis and columns (an impact without two grains, or a grain and a flat wall, is refused by the scene's own checks)"),
    ),
    each("stages[].name", written("a `# stage K: NAME` comment before the stage's run; export.json stages"), written("the STAGES list; export.json stages")),
    each(
        "stages[].duration",
        written("the stage's `run N` (N = ceil(duration / dt); `pre no` where only velocities change, so that LIGGGHTS keeps the last step's forces for the first half kick as grainlab does); export.json stages").or_refused(STAGES_FLAT),
        written("the stage's steps and first step in STAGES (its changes made at that step, one `O.run` for the protocol); export.json stages").or_refused(STAGES_OPEN),
    )
    .in_lammps(written("the stage's `run N` (N = ceil(duration / dt); `pre no` where only velocities change, so that LAMMPS keeps the last step's forces for the first half kick as grainlab does); export.json stages").or_refused(STAGES_FLAT)),
    each(
        "stages[].walls.bottom.velocity_x",
        written("`velocity bottom set VX ...` on the row before the stage's run (the held row keeps it)"),
        written("the bottom row's state.vel in STAGES, set at the stage's first step after its forces are recorded, before NewtonIntegrator"),
    ),
    each(
        "stages[].walls.bottom.velocity_y",
        written("`velocity bottom set ... VY ...` on the row before the stage's run"),
        written("the bottom row's state.vel in STAGES, set at the stage's first step after its forces are recorded, before NewtonIntegrator"),
    ),
    both("stages[].walls.bottom.control", one_value(BOTTOM_CONTROL)),
    both("stages[].walls.bottom.control.pressure", one_value(BOTTOM_CONTROL)),
    each(
        "stages[].walls.top.velocity_x",
        written("`velocity top set VX ...` on the row before the stage's run"),
        written("the top clump's state.vel in STAGES, set at the stage's first step after its forces are recorded, before NewtonIntegrator"),
    ),
    each(
        "stages[].walls.top.velocity_y",
        written("`velocity top set ... VY ...` on the held row before the stage's run"),
        written("the top clump's state.vel in STAGES (held: blockedDOFs 'xyzXYZ')"),
    ),
    each(
        "stages[].walls.top.control",
        written("\"fixed\": the row's `aveforce` removed and `setforce 0.0 0.0 0.0`, its y velocity set; a pressure: `setforce 0.0 NULL 0.0` and `aveforce`")
            .or_differs("a change of control after the first stage", "the fixes are replaced, so the stage's run needs LIGGGHTS' setup, which recomputes the forces at the step-end velocities (the stage's new wall velocities included) and rebuilds the neighbour list: the stage's first half kick differs from grainlab's (which uses the last step's forces), an O(dt) difference of one step"),
        written("\"fixed\": the clump blocked in y (`xyzXYZ`) at its velocity, no load; a pressure: free in y (`xzXYZ`) under setPermF"),
    )
    .in_lammps(
        written("\"fixed\": the row's `aveforce` removed and `setforce 0.0 0.0 0.0`, its y velocity set; a pressure: `setforce 0.0 NULL 0.0` and `aveforce`")
            .or_differs("a change of control after the first stage", "the fixes are replaced, so the stage's run needs LAMMPS' setup, which recomputes the forces at the step-end velocities (the stage's new wall velocities included) and rebuilds the neighbour list: the stage's first half kick differs from grainlab's (which uses the last step's forces), an O(dt) difference of one step"),
    ),
    each(
        "stages[].walls.top.control.pressure",
        written("the load p L_x t (3D: p L_x L_z) on the row: `aveforce NULL -F/n NULL` (per atom), replaced at the stage's start (a given walls.top.mass other than the row's atoms' is refused there)"),
        written("LOAD = p L_x t (3D: p L_x L_z) in STAGES: setPermF on the top clump, free in y"),
    ),
    each("stages[].gravity", refused(STAGE_GRAVITY), refused(STAGE_GRAVITY)),
    each(
        "stages[].samples",
        written("export.json stages[].sample_every (steps / samples): the deck prints every step of a protocol, and the digest averages those rows into the stage's"),
        written("export.json stages[].sample_every (steps / samples): the script records every step of a protocol, and the digest averages those rows into the stage's"),
    ),
    both("stages[].frames", outside(NOT_PHYSICS_OUTPUT)),
    both("stages[].average", written("export.json stages[].average: the digest averages the last averaged stage's rows, as grainlab's summary")),
    both("statistics.average_from", written("export.json statistics: the digest averages the code's rows from the same fraction on, as grainlab's summary")),
    both("statistics.blocks", written("export.json statistics: the digest cuts the code's rows into blocks by the same rule, as grainlab's summary")),
];

const STAGES_FLAT: &str = "a protocol with a flat wall: a flat wall's motion and contact histories live in the deck's wall fix or body, not checked across a stage change (refused as stages[0].duration)";
const STAGES_OPEN: &str = "a protocol without domain.periodic_x, or with a flat wall: the script runs a protocol in the periodic shear cell between rough rows only (refused as stages[0].duration)";
const STAGE_GRAVITY: &str = "a non-zero gravity, as the scene's own `gravity`: not exported yet";

/// The normalised path of a concrete one: list indices `[k]` become `[]`.
pub fn normalise(path: &str) -> String {
    let mut out = String::with_capacity(path.len());
    let mut in_index = false;
    for c in path.chars() {
        match c {
            '[' => {
                in_index = true;
                out.push('[');
            }
            ']' => {
                in_index = false;
                out.push(']');
            }
            _ if in_index => {}
            _ => out.push(c),
        }
    }
    out
}

/// The table's entry for a (concrete or normalised) path.
pub fn field(path: &str) -> Option<&'static Field> {
    let p = normalise(path);
    FIELDS.iter().find(|f| f.path == p)
}

fn entry(path: &str) -> &'static Field {
    field(path).unwrap_or_else(|| panic!("src/export/fields.rs has no entry for `{path}`"))
}

/// The refusal of `path = value` for `code`, with the table's reason and what this scene
/// adds (`detail`, may be empty).
pub fn refuse(code: Code, path: &str, value: impl std::fmt::Display, detail: &str) -> Error {
    let why = entry(path).decision(code).refused.unwrap_or_else(|| panic!("src/export/fields.rs: {path} is refused for {} without a reason", code.name()));
    let detail = if detail.is_empty() { String::new() } else { format!(" ({detail})") };
    Error::Export(format!("export to {}: {path} = {value} cannot be expressed: {why}{detail}", code.name()))
}

/// The table's note of what `code` does differently for `path`.
pub fn note(code: Code, path: &str) -> &'static str {
    entry(path).decision(code).differs.unwrap_or_else(|| panic!("src/export/fields.rs: {path} differs for {} without a note", code.name())).1
}

/// The deck comment `# Differs: path = value: what` with the table's text (the caller
/// writes it for the values that differ).
pub fn differs_line(code: Code, path: &str, value: impl std::fmt::Display) -> String {
    format!("# Differs: {path} = {value}: {}", note(code, path))
}

/// The table of one code, grouped: what it cannot express first.
pub fn explain(code: Code) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "export to {}: what each scene field becomes (src/export/fields.rs)", code.name());
    // Each group's title and its (values, text) of a decision.
    type Pick = fn(&Decision) -> Option<(&'static str, &'static str)>;
    let groups: [(&str, Pick); 5] = [
        ("cannot be expressed (refused, naming the field)", |d| d.refused.map(|t| ("", t))),
        ("expressed approximately (a `# Differs:` line in the deck)", |d| d.differs),
        ("written", |d| d.written.map(|t| ("", t))),
        ("not part of the physics the deck computes", |d| d.outside.map(|t| ("", t))),
        ("one valid value", |d| d.one_value.map(|t| ("", t))),
    ];
    for (title, pick) in groups {
        let _ = writeln!(s, "\n{title}:");
        for f in FIELDS {
            if let Some((when, text)) = pick(f.decision(code)) {
                let when = if when.is_empty() { String::new() } else { format!(" = {when}") };
                let _ = writeln!(s, "  {}{when}: {text}", f.path);
            }
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_are_unique_and_every_decision_says_something() {
        for (k, f) in FIELDS.iter().enumerate() {
            assert!(FIELDS[..k].iter().all(|g| g.path != f.path), "{} twice", f.path);
            for code in [Code::Liggghts, Code::Yade, Code::Lammps] {
                let d = f.decision(code);
                // A field is written, refused, outside or of one value; a Differs note
                // alone is a decision too (the code does it its own way).
                assert!(d.written.is_some() || d.refused.is_some() || d.outside.is_some() || d.one_value.is_some() || d.differs.is_some(), "{} {:?}", f.path, code);
                // Outside and one-value fields are neither written nor refused.
                if d.outside.is_some() || d.one_value.is_some() {
                    assert!(d.written.is_none() && d.refused.is_none() && d.differs.is_none(), "{} {:?}", f.path, code);
                }
            }
        }
    }

    #[test]
    fn indices_are_normalised() {
        assert_eq!(normalise("materials[12].restitution"), "materials[].restitution");
        assert_eq!(normalise("grains.list[0].x"), "grains.list[].x");
        assert_eq!(field("walls.top.mass").map(|f| f.path), Some("walls.top.mass"));
    }

    #[test]
    fn a_refusal_names_code_path_value_and_reason() {
        let e = refuse(Code::Liggghts, "model.general_damping", 0.1, "").to_string();
        assert!(e.contains("export to liggghts: model.general_damping = 0.1 cannot be expressed: ") && e.contains("fix viscous"), "{e}");
    }
}
