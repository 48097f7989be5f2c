//! What a scene may ask of the machine, checked before anything is allocated: memory
//! (estimated from the scene's declared sizes against a budget), steps, materials,
//! the size of the files it reads.
//!
//! Every structure a run keeps is sized from the scene: grains (free and glued to rough
//! walls), the pair table of the materials, the rows of the time series, an impact's
//! force-overlap curve. [`MemoryEstimate`] adds them up with the bytes per item below,
//! and a scene whose estimate exceeds the budget is refused with the estimate and the
//! field that drives it.

use crate::error::Error;

/// Bytes per grain of a running engine, all structures included (grain arrays, the
/// Verlet list with its histories and energy memory, the cell list, a flat wall's
/// history per grain, a frame's text being written). docs/performance.md measures 392
/// bytes per grain from 10^5 to 10^6 grains in the shear cell; 1024 covers the packing
/// relaxation's transient arrays and denser contact networks.
pub const BYTES_PER_GRAIN: u64 = 1024;

/// Bytes per grain (free or glued to a wall) of micro-slip's beds of springs
/// (`model.tangential = "mindlin_deresiewicz"`), on top of [`BYTES_PER_GRAIN`]: each
/// listed pair keeps 66 f64 (528 bytes); measured 1080 bytes per grain more than the total
/// displacement's in the shear cell at 20000 grains and 2160 at 5000 (the pair lists'
/// capacity doubles as they grow), and 6144 covers denser networks (the margin of
/// [`BYTES_PER_GRAIN`] over its measured 392).
pub const BYTES_PER_GRAIN_MICROSLIP: u64 = 6144;

/// Bytes per entry of the materials' pair table (one `PairMaterial`, 7 f64).
pub const BYTES_PER_MATERIAL_PAIR: u64 = 56;

/// Bytes per row kept in memory for the summary (a wall row, 9 f64) or per point of an
/// impact's force-overlap curve (3 f64), rounded up.
pub const BYTES_PER_ROW: u64 = 96;

/// Bytes per grain of the packing observers (`output.contacts`), on top of
/// [`BYTES_PER_GRAIN`]: a step's contact records (88 bytes each, about 1.5 contacts per
/// grain in a dense packing, up to 3 in 2D), the copies of the state they were computed
/// from (40), and a frame's contact lines and CSV being written (about 380 bytes per
/// contact).
pub const BYTES_PER_GRAIN_CONTACTS: u64 = 1536;

/// Most layers of a profile across the gap ([`crate::observe::profiles`]): a gap of more
/// than this many mean diameters gets thicker layers.
pub const MAX_PROFILE_LAYERS: usize = 1000;

/// Bytes per sample the packing observers keep for the summary: a packing row and a
/// profile sample of at most [`MAX_PROFILE_LAYERS`] layers of 8 numbers.
pub const BYTES_PER_PACKING_SAMPLE: u64 = 256 + 64 * MAX_PROFILE_LAYERS as u64;

/// Most materials a scene may list: the pair table has one entry per ordered pair, and
/// the LIGGGHTS export writes n x n matrices on one line.
pub const MAX_MATERIALS: usize = 256;

/// Most steps a run may take (duration / dt): about a day of steps for a few grains on
/// one core, far beyond any study here; more comes from a dt that came out absurdly small.
pub const MAX_STEPS: f64 = 1e12;

/// Most ParaView frames a run writes: each rewrites the `.pvd` index and the output
/// folder's manifest, whose sizes grow with the frames.
pub const MAX_FRAMES: u64 = 10_000;

/// Most stages a protocol may have: each is a row of the summary and a block of the
/// exported decks.
pub const MAX_STAGES: usize = 1000;

/// The most points an impact's force-overlap curve keeps: a million steps in contact (an
/// impact at 200 steps per contact time takes about 200).
pub const MAX_CURVE_POINTS: usize = 1_000_000;

/// How far from the origin, in largest grain radii, a coordinate (grain, wall, periodic
/// cell, packing region) may lie: beyond, the rounding of positions (2.2e-16 of the
/// coordinate) approaches the overlaps the contact law resolves, and products of
/// coordinates stop being safely finite.
pub const MAX_COORDINATE_RADII: f64 = 1e6;

/// The machine's share a run may take: by default half the memory the machine has
/// (`MemTotal` in /proc/meminfo; 8 GiB where it cannot be read); `--memory-budget`
/// overrides it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Limits {
    /// Memory budget, bytes.
    pub memory_bytes: u64,
}

impl Default for Limits {
    fn default() -> Self {
        Limits::machine()
    }
}

impl Limits {
    /// Half the machine's memory (read once).
    pub fn machine() -> Self {
        static MACHINE: std::sync::OnceLock<Limits> = std::sync::OnceLock::new();
        *MACHINE.get_or_init(|| {
            let total = std::fs::read_to_string("/proc/meminfo").ok().and_then(|s| {
                let line = s.lines().find(|l| l.starts_with("MemTotal:"))?;
                let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
                Some(kib.saturating_mul(1024))
            });
            Limits { memory_bytes: total.unwrap_or(16 << 30) / 2 }
        })
    }

    /// A budget of `bytes`.
    pub fn with_memory(bytes: u64) -> Self {
        Limits { memory_bytes: bytes }
    }

    /// The most bytes a scene may make grainlab read from one file (a scene file, a grain
    /// file): an eighth of the budget (the parsed data take several times the text).
    pub fn file_bytes(&self) -> u64 {
        self.memory_bytes / 8
    }

    /// Refuse `estimate` when it exceeds the budget; the message names the field that
    /// drives it (`driver`) and its value.
    pub fn check(&self, estimate: &MemoryEstimate) -> Result<(), Error> {
        if estimate.bytes() <= self.memory_bytes {
            return Ok(());
        }
        let (field, value) = estimate.driver();
        Err(Error::Invalid {
            field,
            value,
            allowed: format!(
                "a scene that fits the memory budget of {} (estimated {}: {}); raise the budget with --memory-budget",
                human_bytes(self.memory_bytes),
                human_bytes(estimate.bytes()),
                estimate.parts()
            ),
        })
    }
}

/// What a scene will keep in memory, by part.
#[derive(Clone, Debug, Default)]
pub struct MemoryEstimate {
    /// Free grains, and the JSON path and value of the field that sets their number.
    pub grains: (u64, String, String),
    /// Grains glued to rough walls, and the field that sets their number.
    pub wall_grains: (u64, String, String),
    /// Materials.
    pub materials: u64,
    /// Rows kept for the summary (wall rows, impact curve points), and the field that
    /// sets them.
    pub rows: (u64, String, String),
    /// With the packing observers (`output.contacts`): the grains whose contacts are
    /// recorded and the samples kept.
    pub inside: (u64, u64),
    /// Micro-slip's beds of springs (`model.tangential = "mindlin_deresiewicz"`).
    pub microslip: bool,
}

impl MemoryEstimate {
    fn terms(&self) -> [(u64, &str); 6] {
        [
            (self.grains.0.saturating_mul(BYTES_PER_GRAIN), "grains"),
            (self.wall_grains.0.saturating_mul(BYTES_PER_GRAIN), "wall grains"),
            (self.materials.saturating_mul(self.materials).saturating_mul(BYTES_PER_MATERIAL_PAIR), "material pairs"),
            (self.rows.0.saturating_mul(BYTES_PER_ROW), "rows"),
            (self.inside.0.saturating_mul(BYTES_PER_GRAIN_CONTACTS).saturating_add(self.inside.1.saturating_mul(BYTES_PER_PACKING_SAMPLE)), "the packing observers (output.contacts)"),
            (if self.microslip { self.grains.0.saturating_add(self.wall_grains.0).saturating_mul(BYTES_PER_GRAIN_MICROSLIP) } else { 0 }, "micro-slip's springs (model.tangential)"),
        ]
    }
    /// The total, bytes.
    pub fn bytes(&self) -> u64 {
        self.terms().iter().fold(0u64, |a, t| a.saturating_add(t.0))
    }
    /// The parts in words.
    fn parts(&self) -> String {
        self.terms().iter().filter(|t| t.0 > 0).map(|(b, what)| format!("{} for {what}", human_bytes(*b))).collect::<Vec<_>>().join(", ")
    }
    /// The field behind the largest part.
    fn driver(&self) -> (String, String) {
        let t = self.terms();
        let k = (0..t.len()).max_by_key(|&k| t[k].0).unwrap_or(0);
        match k {
            0 => (self.grains.1.clone(), self.grains.2.clone()),
            1 => (self.wall_grains.1.clone(), self.wall_grains.2.clone()),
            2 => ("materials".into(), format!("{} materials", self.materials)),
            3 => (self.rows.1.clone(), self.rows.2.clone()),
            4 => ("output.contacts".into(), format!("true ({} grains, {} samples)", self.inside.0, self.inside.1)),
            // Micro-slip's springs: as many as the grains.
            _ => (self.grains.1.clone(), self.grains.2.clone()),
        }
    }
}

/// Bytes in binary units, for messages: `1.5 GiB`.
pub fn human_bytes(b: u64) -> String {
    let units = ["B", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"];
    let mut v = b as f64;
    let mut k = 0;
    while v >= 1024.0 && k + 1 < units.len() {
        v /= 1024.0;
        k += 1;
    }
    if k == 0 { format!("{b} B") } else { format!("{v:.1} {}", units[k]) }
}

/// Parse a size such as `512M`, `4G`, `4GiB` or `1000000` (bytes) for `--memory-budget`.
pub fn parse_bytes(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let split = t.find(|c: char| !(c.is_ascii_digit() || c == '.')).unwrap_or(t.len());
    let (num, unit) = t.split_at(split);
    let v: f64 = num.parse().map_err(|_| format!("`{s}` is not a size (e.g. 512M, 4G)"))?;
    let scale = match unit.trim().to_ascii_lowercase().trim_end_matches("ib").trim_end_matches('b') {
        "" => 1.0,
        "k" => 1024.0,
        "m" => 1024.0 * 1024.0,
        "g" => 1024.0 * 1024.0 * 1024.0,
        "t" => 1024.0 * 1024.0 * 1024.0 * 1024.0,
        _ => return Err(format!("`{s}`: unknown unit (use K, M, G or T)")),
    };
    let bytes = v * scale;
    if !(bytes.is_finite() && (1.0..1.8e19).contains(&bytes)) {
        return Err(format!("`{s}` is not a size between 1 B and 16 EiB"));
    }
    Ok(bytes as u64)
}

/// Read a file of at most `limit` bytes as text. Only regular files are read (a device
/// such as /dev/zero or a pipe never ends); `field` names the scene field or argument
/// that gave the path, for the messages.
pub fn read_bounded(path: &std::path::Path, limit: u64, field: &str) -> Result<String, Error> {
    use std::io::Read;
    let shown = path.display();
    let meta = std::fs::metadata(path).map_err(|e| Error::io(format!("{field} = {shown}"), e))?;
    if !meta.is_file() {
        return Err(Error::Invalid { field: field.into(), value: shown.to_string(), allowed: "a regular file (not a folder, device or pipe)".into() });
    }
    let too_big = |n: u64| Error::Invalid {
        field: field.into(),
        value: format!("{shown} ({})", human_bytes(n)),
        allowed: format!("a file of at most {} (an eighth of the memory budget; raise it with --memory-budget)", human_bytes(limit)),
    };
    if meta.len() > limit {
        return Err(too_big(meta.len()));
    }
    let f = std::fs::File::open(path).map_err(|e| Error::io(format!("{field} = {shown}"), e))?;
    let mut bytes = Vec::new();
    // The file may grow after the size was read: never take more than the limit.
    f.take(limit + 1).read_to_end(&mut bytes).map_err(|e| Error::io(format!("{field} = {shown}"), e))?;
    if bytes.len() as u64 > limit {
        return Err(too_big(bytes.len() as u64));
    }
    String::from_utf8(bytes).map_err(|_| Error::Invalid { field: field.into(), value: shown.to_string(), allowed: "a UTF-8 text file".into() })
}

/// Largest overlap a seeded packing may keep after its relaxation, as a fraction of the
/// smaller radius of the pair: 2e-2. The elastic energy of an overlap dn, released, throws
/// the two grains apart at about sqrt(E*/rho) (dn/r)^(5/4): 27 m/s for glass at 2e-2,
/// fifty times the shear cell's wall speed; beyond, a run starts with an explosion, not
/// a packing. Measured (uniform radii 0.4-0.6 mm, 200 to 5000 grains, seeds 1-3): the
/// relaxation ([`crate::scene::pack`]) reaches its 1e-4 of the smallest radius at packing fractions up to 0.7 and
/// leaves up to 2e-3 at 0.75 (the built-in shear cell: 1.3e-3), once 8e-2 in a cell of
/// 200 grains; radii from 0.1 to 1 mm at 0.75 leave 1.25e-2 (tests/hard_cases.rs shears
/// that stably); at 0.8, and for wide lognormal radii from 0.75 on, 1e-2 to 0.5.
pub const MAX_PACKING_OVERLAP: f64 = 2e-2;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_with_binary_units_and_refuse_nonsense() {
        assert_eq!(parse_bytes("512M"), Ok(512 << 20));
        assert_eq!(parse_bytes("4GiB"), Ok(4 << 30));
        assert_eq!(parse_bytes("1.5k"), Ok(1536));
        assert_eq!(parse_bytes("1000"), Ok(1000));
        assert!(parse_bytes("-1G").is_err() && parse_bytes("4X").is_err() && parse_bytes("1e30").is_err() && parse_bytes("0").is_err());
    }

    #[test]
    fn an_estimate_over_budget_names_its_largest_part() {
        let e = MemoryEstimate {
            grains: (1 << 20, "grains.pack.count".into(), "1048576".into()),
            wall_grains: (10, "walls.bottom.surface.rough.radius".into(), "0.001".into()),
            materials: 1,
            rows: (400, "output.samples".into(), "400".into()),
            inside: (0, 0),
            microslip: false,
        };
        assert_eq!(e.bytes(), (1 << 20) * BYTES_PER_GRAIN + 10 * BYTES_PER_GRAIN + BYTES_PER_MATERIAL_PAIR + 400 * BYTES_PER_ROW);
        assert!(Limits::with_memory(2 << 30).check(&e).is_ok());
        let msg = Limits::with_memory(64 << 20).check(&e).unwrap_err().to_string();
        assert!(msg.contains("grains.pack.count = 1048576") && msg.contains("64.0 MiB") && msg.contains("1.0 GiB for grains"), "{msg}");
        // Micro-slip's springs: on top, per grain (free and glued), named by the grains'
        // field whose number they follow.
        let m = MemoryEstimate { microslip: true, ..e };
        assert_eq!(m.bytes(), (1 << 20) * (BYTES_PER_GRAIN + BYTES_PER_GRAIN_MICROSLIP) + 10 * (BYTES_PER_GRAIN + BYTES_PER_GRAIN_MICROSLIP) + BYTES_PER_MATERIAL_PAIR + 400 * BYTES_PER_ROW);
        let msg = Limits::with_memory(2 << 30).check(&m).unwrap_err().to_string();
        assert!(msg.contains("grains.pack.count = 1048576") && msg.contains("6.0 GiB for micro-slip's springs"), "{msg}");
    }
}
