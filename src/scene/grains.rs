//! Where a scene's grains come from: a grain file read in its declared columns (within
//! the budget's file size), and the smallest grain a scene will have (the one its time
//! step is for), known before anything is built.

use crate::error::Error;
use crate::scene::limits::Limits;
use crate::scene::{GrainColumns, Grains, Scene};

/// A grain file's grains (centre `[x, y, z]` with z = 0 for `"x y r"`, radius) and the
/// line of each.
type FileGrains = (Vec<([f64; 3], f64)>, Vec<u32>);

/// The grains of a particle file: one per line in the declared `columns`, `#` starts a
/// comment; with the line of each grain, for messages. The file is read up to the
/// budget's file size ([`Limits::file_bytes`]). A plane scene takes x and y of each
/// centre, a 3D scene all three (it refuses `"x y r"`: [`Scene::validate`]).

pub fn read_grain_file(path: &str, columns: GrainColumns, limits: &Limits) -> Result<FileGrains, Error> {
    let text = crate::scene::limits::read_bounded(std::path::Path::new(path), limits.file_bytes(), "grains.file.path")?;
    let mut out = Vec::new();
    let mut lines = Vec::new();
    for (k, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let bad = |why: &str| Error::Scene(format!("{path}:{}: {why}: `{line}` (grains.file.columns = \"{}\", in m)", k + 1, columns.name()));
        let v: Vec<f64> = line.split_whitespace().map(str::parse).collect::<Result<_, _>>().map_err(|_| bad("not a number"))?;
        if v.len() != columns.count() {
            return Err(bad(&format!("{} numbers where the columns are {}", v.len(), columns.count())));
        }
        let r = v[columns.count() - 1];
        let x = match columns {
            GrainColumns::XYR => [v[0], v[1], 0.0],
            GrainColumns::XYZR => [v[0], v[1], v[2]],
        };
        if !(r.is_finite() && r > 0.0) {
            return Err(bad("the radius must be > 0"));
        }
        // z is checked here too: a plane scene ignores it, but a number that is not one
        // is a broken file.
        if !x.iter().all(|c| c.is_finite()) {
            return Err(bad("the position must be finite"));
        }
        out.push((x, r));
        lines.push((k + 1) as u32);
    }
    if out.is_empty() {
        return Err(Error::Invalid { field: "grains.file.path".into(), value: path.into(), allowed: "a file with at least one grain".into() });
    }
    Ok((out, lines))
}

impl Scene {
    /// The radius (m) and material index of the smallest free grain the scene will have:
    /// a listed one, one read from its file, or the smallest its packing draws (the same
    /// radii, from the same seed, as the build's); the first of equal ones.
    pub fn smallest_grain(&self, limits: &Limits) -> Result<(f64, usize), Error> {
        let first_min = |it: &mut dyn Iterator<Item = (f64, usize)>| it.fold(None, |best: Option<(f64, usize)>, g| match best {
            Some(b) if b.0.total_cmp(&g.0).is_le() => Some(b),
            _ => Some(g),
        });
        let found = match &self.grains {
            Grains::List(list) => first_min(&mut list.iter().map(|g| (g.r, g.material))),
            Grains::File { path, columns, material } => {
                let (grains, _) = read_grain_file(path, *columns, limits)?;
                first_min(&mut grains.iter().map(|g| (g.1, *material)))
            }
            Grains::Pack(p) => first_min(&mut p.radius.sample(p.count, p.seed).into_iter().map(|r| (r, p.material))),
        };
        found.ok_or_else(|| Error::Scene("no grains".into()))
    }
}
