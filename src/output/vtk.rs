//! ParaView snapshots: one `.vtp` (VTK XML PolyData) per frame and a `.pvd` collection
//! that lists them with their times. Load `grains.pvd` in ParaView and use a Glyph filter
//! (sphere, scale by `radius_m`) to see the grains.
//!
//! With the scene's `output.contacts`, each frame after the first also has the step's
//! contacts: `frames/contacts_NNNNN.vtp`, one line per touching pair (grain centre to
//! the partner's centre, its periodic image next to the grain, or to the contact point
//! on a flat wall), listed in `contacts.pvd`; colour by `normal_force_n` or give a Tube
//! filter its radius from it to see the force chains. The same contacts, one row each,
//! are in `frames/contacts_NNNNN.csv`. Those frames' grains carry their number of
//! contacts and their stress times volume ([`grain_stress_volumes`]). The first frame
//! (step 0) has no contacts: they are those a step's force stage computed.
//!
//! The arrays are appended raw (binary, little endian, 64-bit sizes), which ParaView and
//! the `vtk` library read; a frame is about a third of its ASCII size and exact.
//!
//! A run in space writes the same grains' frames ([`VtkSeries::frame_of`]), its spins
//! and torques as 3-vectors (in the plane their one component about z); its contacts
//! are not recorded yet (issue 30).

use std::fmt::Write as _;

use crate::engine::world::View;
use crate::error::Error;
use crate::observe::packing::{grain_contacts, grain_stress_volumes};
use crate::output::folder::OutFolder;
use crate::physics::contact::Partner;
use crate::physics::dim::Dim;

/// The frames of a run, in the `frames` sub-folder of its output folder.
pub struct VtkSeries {
    frames: Vec<(f64, String)>,
    /// The frames that have contacts: time, s, and the contacts' `.vtp`.
    contacts: Vec<(f64, String)>,
}

/// One VTK XML PolyData file being built: its XML, and the arrays appended after it
/// (each a 64-bit byte count, then the values).
struct Vtp {
    xml: String,
    data: Vec<u8>,
}

impl Vtp {
    fn new() -> Self {
        let xml = String::from("<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n  <PolyData>\n");
        Vtp { xml, data: Vec::new() }
    }

    fn tag(&mut self, line: &str) {
        self.xml.push_str(line);
        self.xml.push('\n');
    }

    fn array<const B: usize>(&mut self, kind: &str, name: &str, comps: usize, values: impl Iterator<Item = [u8; B]>) {
        let _ = writeln!(self.xml, "        <DataArray type=\"{kind}\" Name=\"{name}\" NumberOfComponents=\"{comps}\" format=\"appended\" offset=\"{}\"/>", self.data.len());
        let at = self.data.len();
        self.data.extend_from_slice(&0u64.to_le_bytes());
        for v in values {
            self.data.extend_from_slice(&v);
        }
        let bytes = (self.data.len() - at - 8) as u64;
        self.data[at..at + 8].copy_from_slice(&bytes.to_le_bytes());
    }

    fn f64s(&mut self, name: &str, comps: usize, values: impl Iterator<Item = f64>) {
        self.array("Float64", name, comps, values.map(f64::to_le_bytes));
    }

    fn i64s(&mut self, name: &str, values: impl Iterator<Item = i64>) {
        self.array("Int64", name, 1, values.map(i64::to_le_bytes));
    }

    /// Cells of `per` points each, numbered in order: `connectivity` and `offsets`.
    fn cells(&mut self, what: &str, n: usize, per: usize) {
        self.tag(&format!("      <{what}>"));
        self.i64s("connectivity", 0..(n * per) as i64);
        self.i64s("offsets", (1..=n as i64).map(|k| k * per as i64));
        self.tag(&format!("      </{what}>"));
    }

    fn bytes(mut self) -> Vec<u8> {
        self.xml.push_str("    </Piece>\n  </PolyData>\n  <AppendedData encoding=\"raw\">\n   _");
        let mut out = self.xml.into_bytes();
        out.extend_from_slice(&self.data);
        out.extend_from_slice(b"\n  </AppendedData>\n</VTKFile>\n");
        out
    }
}

fn xyz(v: &crate::physics::dim::Vec2) -> [f64; 3] {
    [v.x, v.y, 0.0]
}

/// Vectors of the plane or space as VTK's points: three components each (z = 0 in the
/// plane).
fn points<D: Dim>(v: &[D::Vector<f64>]) -> impl Iterator<Item = f64> + '_ {
    D::flat(v).chunks_exact(D::D).flat_map(|c| [c[0], c[1], if D::D == 3 { c[2] } else { 0.0 }])
}

/// The last line of defence (the run checks the state before a frame): no frame holds
/// a number that is not finite.
fn all_finite<D: Dim>(e: &View<D>) -> Result<(), Error> {
    let p = e.particles;
    let vector = |v: &D::Vector<f64>| D::flat(std::slice::from_ref(v)).iter().all(|c| c.is_finite());
    let spin = |w: &D::Spin<f64>| D::spin_flat(std::slice::from_ref(w)).iter().all(|c| c.is_finite());
    match (0..p.len()).find(|&i| !(vector(&p.x[i]) && vector(&p.v[i]) && vector(&p.f[i]) && spin(&p.omega[i]) && spin(&p.torque[i]))) {
        Some(i) => Err(Error::Other(format!("frame at t = {:e} s not written: grain {i}'s state is not finite", e.time))),
        None => Ok(()),
    }
}

fn finite(v: &crate::physics::dim::Vec2) -> bool {
    v.x.is_finite() && v.y.is_finite()
}

/// The contacts' file of a grains frame (`frames/grains_NNNNN.vtp`), `ext` `vtp` or `csv`.
fn contacts_file(frame: &str, ext: &str) -> String {
    frame.replacen("grains_", "contacts_", 1).replace(".vtp", &format!(".{ext}"))
}

impl VtkSeries {
    pub fn new(folder: &mut OutFolder) -> Result<Self, Error> {
        folder.folder("frames")?;
        Ok(VtkSeries { frames: Vec::new(), contacts: Vec::new() })
    }

    /// The files of `frames` (time, file), as a checkpoint recorded them: each grains
    /// frame and the contacts files that may go with it.
    pub fn files_of(frames: &[(f64, String)]) -> Vec<String> {
        frames.iter().flat_map(|(_, f)| [f.clone(), contacts_file(f, "vtp"), contacts_file(f, "csv")]).collect()
    }

    /// Continue a series whose first frames are `frames` (time, file), as a checkpoint
    /// recorded them ([`VtkSeries::frames`]), the contacts of those that have them in the
    /// folder: the `.pvd` indexes are written again with those only (a run stopped after
    /// the checkpoint may have listed more).
    pub fn resume(frames: Vec<(f64, String)>, folder: &mut OutFolder) -> Result<Self, Error> {
        folder.folder("frames")?;
        let listed = |f: &str| folder.manifest().files.iter().any(|m| m.path == f);
        let contacts = frames.iter().map(|(t, f)| (*t, contacts_file(f, "vtp"))).filter(|(_, c)| listed(c)).collect();
        let s = VtkSeries { frames, contacts };
        if !s.frames.is_empty() {
            s.index(folder)?;
        }
        Ok(s)
    }

    /// The frames written so far: time, s, and file.
    pub fn frames(&self) -> &[(f64, String)] {
        &self.frames
    }

    /// Write one frame and rewrite the `.pvd` index (each a whole file, listed in the
    /// folder's manifest); with `contacts` (recorded at this step, [`View::contacts`]),
    /// the contacts' `.vtp` and `.csv` too, and the grains' contacts and stresses.
    pub fn frame(&mut self, e: &View, contacts: bool, folder: &mut OutFolder) -> Result<(), Error> {
        all_finite(e)?;
        if let Some(c) = e.contacts.iter().find(|c| !(finite(&c.point) && finite(&c.branch) && c.normal_force.is_finite() && finite(&c.tangential_force) && c.overlap.is_finite())) {
            return Err(Error::Other(format!("frame at t = {:e} s not written: a contact of grain {}'s is not finite", e.time, c.i)));
        }
        let name = self.grains(e, folder, |g| {
            if contacts {
                g.i64s("contacts", grain_contacts(e).into_iter().map(i64::from));
                // A 3x3 tensor, row a column b: positions along a, forces along b.
                g.f64s("stress_volume_n_m", 9, grain_stress_volumes(e).into_iter().flat_map(|s| [s[0], s[1], 0.0, s[2], s[3], 0.0, 0.0, 0.0, 0.0]));
            }
        })?;
        if contacts {
            let file = contacts_file(&name, "vtp");
            folder.write(&file, &contacts_vtp(e))?;
            folder.write(&contacts_file(&name, "csv"), contacts_csv(e).as_bytes())?;
            self.contacts.push((e.time, file));
        }
        self.frames.push((e.time, name));
        self.index(folder)
    }

    /// Write one frame of grains in the plane or in space (spheres: positions,
    /// velocities, forces as 3-vectors; in space spins and torques too, in the plane
    /// their one component about z) and rewrite the `.pvd` index. Contacts are the
    /// plane's ([`VtkSeries::frame`]).
    pub fn frame_of<D: Dim>(&mut self, e: &View<D>, folder: &mut OutFolder) -> Result<(), Error> {
        all_finite(e)?;
        let name = self.grains(e, folder, |_| ())?;
        self.frames.push((e.time, name));
        self.index(folder)
    }

    /// Write the grains' file of the next frame (checked finite), `extra` adding point
    /// arrays after the grains' own; its name.
    fn grains<D: Dim>(&self, e: &View<D>, folder: &mut OutFolder, extra: impl FnOnce(&mut Vtp)) -> Result<String, Error> {
        let p = e.particles;
        let n = p.len();
        let mut g = Vtp::new();
        g.tag(&format!("    <Piece NumberOfPoints=\"{n}\" NumberOfVerts=\"{n}\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">"));
        g.tag("      <Points>");
        g.f64s("position_m", 3, points::<D>(&p.x));
        g.tag("      </Points>");
        g.tag("      <PointData Scalars=\"radius_m\">");
        g.i64s("id", 0..n as i64);
        g.f64s("radius_m", 1, p.r.iter().cloned());
        g.f64s("velocity_m_s", 3, points::<D>(&p.v));
        g.f64s("spin_rad_s", D::SPIN, D::spin_flat(&p.omega).iter().cloned());
        g.f64s("force_n", 3, points::<D>(&p.f));
        g.f64s("torque_n_m", D::SPIN, D::spin_flat(&p.torque).iter().cloned());
        g.f64s("material", 1, p.material.iter().map(|&m| m as f64));
        g.f64s("wall_grain", 1, (0..n).map(|i| if i < p.n_free { 0.0 } else { 1.0 }));
        extra(&mut g);
        g.tag("      </PointData>");
        g.cells("Verts", n, 1);
        let name = format!("frames/grains_{:05}.vtp", self.frames.len());
        folder.write(&name, &g.bytes())?;
        Ok(name)
    }

    /// Write the `.pvd` indexes of the frames.
    fn index(&self, folder: &mut OutFolder) -> Result<(), Error> {
        folder.write("grains.pvd", pvd(&self.frames).as_bytes())?;
        if self.contacts.is_empty() { Ok(()) } else { folder.write("contacts.pvd", pvd(&self.contacts).as_bytes()) }
    }
}

fn pvd(frames: &[(f64, String)]) -> String {
    let mut pvd = String::from("<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n  <Collection>\n");
    for (t, f) in frames {
        let _ = writeln!(pvd, "    <DataSet timestep=\"{t:e}\" part=\"0\" file=\"{f}\"/>");
    }
    pvd.push_str("  </Collection>\n</VTKFile>\n");
    pvd
}

/// A contact's partner as a number: the grain's id, or -1 (bottom) / -2 (top) for a
/// flat wall.
fn partner_id(p: Partner) -> i64 {
    match p {
        Partner::Grain(j) => j as i64,
        Partner::Wall(k) => -(k as i64) - 1,
    }
}

/// The contacts of `e` as lines, two points each (grain i's centre, then its partner's
/// centre next to it, or the contact point on a flat wall).
fn contacts_vtp(e: &View) -> Vec<u8> {
    let (p, cs) = (e.particles, e.contacts);
    let m = cs.len();
    let mut v = Vtp::new();
    v.tag(&format!("    <Piece NumberOfPoints=\"{}\" NumberOfVerts=\"0\" NumberOfLines=\"{m}\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">", 2 * m));
    v.tag("      <Points>");
    v.f64s("position_m", 3, cs.iter().flat_map(|c| {
        let x = p.x[c.i as usize];
        let [a, b] = [xyz(&x), xyz(&(x - c.branch))];
        [a[0], a[1], a[2], b[0], b[1], b[2]]
    }));
    v.tag("      </Points>");
    // On the points too, for a Tube filter's radius.
    v.tag("      <PointData Scalars=\"normal_force_n\">");
    v.f64s("normal_force_n", 1, cs.iter().flat_map(|c| [c.normal_force; 2]));
    v.tag("      </PointData>");
    v.tag("      <CellData Scalars=\"normal_force_n\">");
    v.i64s("grain", cs.iter().map(|c| c.i as i64));
    v.i64s("partner", cs.iter().map(|c| partner_id(c.partner)));
    v.f64s("normal_force_n", 1, cs.iter().map(|c| c.normal_force));
    v.f64s("tangential_force_n", 3, cs.iter().flat_map(|c| xyz(&c.tangential_force)));
    v.f64s("force_n", 3, cs.iter().flat_map(|c| xyz(&c.force())));
    v.f64s("normal", 3, cs.iter().flat_map(|c| xyz(&c.normal)));
    v.f64s("overlap_m", 1, cs.iter().map(|c| c.overlap));
    v.f64s("contact_point_m", 3, cs.iter().flat_map(|c| xyz(&c.point)));
    v.i64s("sliding", cs.iter().map(|c| c.sliding as i64));
    v.tag("      </CellData>");
    v.cells("Lines", m, 2);
    v.bytes()
}

/// The contacts of `e`, one CSV row each: the force is the one grain i felt.
fn contacts_csv(e: &View) -> String {
    let mut s = String::from("grain,partner,point_x_m,point_y_m,normal_x,normal_y,overlap_m,normal_force_n,tangential_force_x_n,tangential_force_y_n,sliding\n");
    for c in e.contacts {
        let _ = writeln!(
            s,
            "{},{},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{}",
            c.i,
            partner_id(c.partner),
            c.point.x,
            c.point.y,
            c.normal.x,
            c.normal.y,
            c.overlap,
            c.normal_force,
            c.tangential_force.x,
            c.tangential_force.y,
            c.sliding as u8
        );
    }
    s
}
