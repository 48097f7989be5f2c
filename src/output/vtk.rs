//! ParaView snapshots: one `.vtp` (VTK XML PolyData, ASCII) per frame, and a `.pvd`
//! collection that lists them with their times. Load the `.pvd` in ParaView and use a
//! Glyph filter (sphere, scale by `radius_m`) to see the grains.

use std::fmt::Write as _;

use crate::engine::world::View;
use crate::error::Error;
use crate::output::folder::OutFolder;

/// The frames of a run, in the `frames` sub-folder of its output folder.
pub struct VtkSeries {
    frames: Vec<(f64, String)>,
}

fn data_array(out: &mut String, name: &str, comps: usize, values: impl Iterator<Item = f64>) {
    let _ = write!(out, "        <DataArray type=\"Float64\" Name=\"{name}\" NumberOfComponents=\"{comps}\" format=\"ascii\">\n          ");
    for v in values {
        let _ = write!(out, "{v:e} ");
    }
    out.push_str("\n        </DataArray>\n");
}

impl VtkSeries {
    pub fn new(folder: &mut OutFolder) -> Result<Self, Error> {
        folder.folder("frames")?;
        Ok(VtkSeries { frames: Vec::new() })
    }

    /// Continue a series whose first frames are `frames` (time, file), as a checkpoint
    /// recorded them ([`VtkSeries::frames`]): the `.pvd` index is written again with
    /// those only (a run stopped after the checkpoint may have listed more).
    pub fn resume(frames: Vec<(f64, String)>, folder: &mut OutFolder) -> Result<Self, Error> {
        folder.folder("frames")?;
        let s = VtkSeries { frames };
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
    /// folder's manifest).
    pub fn frame(&mut self, e: &View, folder: &mut OutFolder) -> Result<(), Error> {
        let p = e.particles;
        let n = p.len();
        // The last line of defence (the run checks the state before a frame): no frame
        // holds a number that is not finite.
        let finite = |v: &crate::physics::dim::Vec2| v.x.is_finite() && v.y.is_finite();
        if let Some(i) = (0..n).find(|&i| !(finite(&p.x[i]) && finite(&p.v[i]) && finite(&p.f[i]) && p.omega[i].is_finite())) {
            return Err(Error::Other(format!("frame at t = {:e} s not written: grain {i}'s state is not finite", e.time)));
        }
        let mut s = String::with_capacity(200 * n + 1000);
        s.push_str("<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <PolyData>\n");
        let _ = writeln!(s, "    <Piece NumberOfPoints=\"{n}\" NumberOfVerts=\"{n}\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">");
        s.push_str("      <Points>\n");
        data_array(&mut s, "position_m", 3, p.x.iter().flat_map(|x| [x.x, x.y, 0.0]));
        s.push_str("      </Points>\n      <PointData Scalars=\"radius_m\">\n");
        data_array(&mut s, "radius_m", 1, p.r.iter().cloned());
        data_array(&mut s, "velocity_m_s", 3, p.v.iter().flat_map(|v| [v.x, v.y, 0.0]));
        data_array(&mut s, "spin_rad_s", 1, p.omega.iter().cloned());
        data_array(&mut s, "force_n", 3, p.f.iter().flat_map(|f| [f.x, f.y, 0.0]));
        data_array(&mut s, "material", 1, p.material.iter().map(|&m| m as f64));
        data_array(&mut s, "wall_grain", 1, (0..n).map(|i| if i < p.n_free { 0.0 } else { 1.0 }));
        s.push_str("      </PointData>\n      <Verts>\n");
        s.push_str("        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n          ");
        for i in 0..n {
            let _ = write!(s, "{i} ");
        }
        s.push_str("\n        </DataArray>\n        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n          ");
        for i in 0..n {
            let _ = write!(s, "{} ", i + 1);
        }
        s.push_str("\n        </DataArray>\n      </Verts>\n    </Piece>\n  </PolyData>\n</VTKFile>\n");
        let name = format!("frames/grains_{:05}.vtp", self.frames.len());
        folder.write(&name, s.as_bytes())?;
        self.frames.push((e.time, name));
        self.index(folder)
    }

    /// Write the `.pvd` index of the frames.
    fn index(&self, folder: &mut OutFolder) -> Result<(), Error> {
        let mut pvd = String::from("<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n  <Collection>\n");
        for (t, f) in &self.frames {
            let _ = writeln!(pvd, "    <DataSet timestep=\"{t:e}\" part=\"0\" file=\"{f}\"/>");
        }
        pvd.push_str("  </Collection>\n</VTKFile>\n");
        folder.write("grains.pvd", pvd.as_bytes())
    }
}
