//! The output folder is grainlab's: nothing in it mixes two runs.
//!
//! [`OutFolder::claim`] takes `--out DIR` for a run (or an export):
//! - a missing or empty DIR is used (created);
//! - a DIR with a `manifest.json` from an earlier grainlab command, and nothing else, is
//!   refused, or with `--overwrite` cleared of exactly the files that manifest lists
//!   (and of its folders, once empty) before anything new is written;
//! - a DIR that holds anything grainlab did not write (no manifest, a file the manifest
//!   does not list, or a listed file changed since grainlab wrote it) is refused, whatever
//!   the flag, naming a few of those files. Nothing is written or deleted then.
//!
//! The manifest lists every file grainlab writes in DIR before the file exists (so a
//! process killed at any point leaves no file its manifest does not list), with its size
//! and CRC-32 once it is complete, and the command's status: `running` while it goes, then
//! the run's ending. Whole files (summary.json, frames, the `.pvd` index, the manifest) are
//! written under a temporary name ending in [`TEMP_SUFFIX`] and renamed: a reader never sees
//! half a file. Streamed series are written as `NAME.part` (flushed row by row, so a
//! killed run keeps what it computed) and renamed to `NAME` when the command ends. The
//! renames protect against the process dying, not the machine: nothing is fsynced.

use std::io::Write as _;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::error::Error;
pub use crate::output::csv::{PART_SUFFIX, with_suffix};
use crate::output::csv::CsvSeries;

/// The manifest's file name in the output folder.
pub const MANIFEST: &str = "manifest.json";
/// What the manifest's `format` field says.
pub const FORMAT: &str = "grainlab-output-folder/1";
/// The end of a whole file's name while it is written ([`write_atomic`]).
pub const TEMP_SUFFIX: &str = ".grainlab-tmp";
/// How many foreign files a refusal names.
const NAMED: usize = 5;
/// The most a manifest may weigh, bytes: a million files listed.
const MAX_MANIFEST_BYTES: u64 = 128 << 20;

/// `manifest.json`: what grainlab wrote in its output folder.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Manifest {
    /// [`FORMAT`].
    pub format: String,
    /// The grainlab version that wrote the folder.
    pub grainlab: String,
    /// The command, e.g. `run shear` or `export liggghts oblique`.
    pub command: String,
    /// `running` while the command goes; then `completed`, `stopped` (a diagnosis or an
    /// I/O failure: summary.json says which) or `interrupted`.
    pub status: String,
    /// Sub-folders grainlab made (`frames`).
    pub folders: Vec<String>,
    /// Every file grainlab wrote, relative to the folder, `/`-separated.
    pub files: Vec<FileEntry>,
}

/// A file of the manifest.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FileEntry {
    pub path: String,
    /// Size in bytes; null while the file is being written.
    pub bytes: Option<u64>,
    /// CRC-32 (IEEE, as zlib and `crc32` compute it), 8 hex digits; null while the file is
    /// being written.
    pub crc32: Option<String>,
}

/// An output folder grainlab has claimed ([`OutFolder::claim`]).
#[derive(Debug)]
pub struct OutFolder {
    dir: PathBuf,
    manifest: Manifest,
}

/// Write `bytes` to `path` under a temporary name in the same folder, then rename it:
/// `path` holds either its old content or all of the new one.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), Error> {
    write_whole(path, bytes, false)
}

/// [`write_atomic`], with the content on the disk itself before the rename (`sync`): a
/// machine that stops too leaves the old content or all of the new.
fn write_whole(path: &Path, bytes: &[u8], sync: bool) -> Result<(), Error> {
    let tmp = with_suffix(path, TEMP_SUFFIX);
    let written = std::fs::File::create(&tmp)
        .and_then(|mut f| f.write_all(bytes).and_then(|()| if sync { f.sync_all() } else { Ok(()) }))
        .and_then(|()| std::fs::rename(&tmp, path));
    written.map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        Error::io(path.display(), e)
    })
}

/// CRC-32 as the manifest writes it.
pub fn crc_hex(crc: u32) -> String {
    format!("{crc:08x}")
}

/// Every entry under `dir` (relative, `/`-separated; whether it is a folder), sorted. Links
/// are entries, not followed.
fn walk(dir: &Path) -> Result<Vec<(String, bool)>, Error> {
    fn go(root: &Path, d: &Path, out: &mut Vec<(String, bool)>) -> Result<(), Error> {
        for e in std::fs::read_dir(d).map_err(|e| Error::io(d.display(), e))? {
            let e = e.map_err(|e| Error::io(d.display(), e))?;
            let path = e.path();
            let rel = path.strip_prefix(root).expect("under the root").components().map(|c| c.as_os_str().to_string_lossy()).collect::<Vec<_>>().join("/");
            let is_dir = e.file_type().map_err(|e| Error::io(path.display(), e))?.is_dir();
            out.push((rel, is_dir));
            if is_dir {
                go(root, &path, out)?;
            }
        }
        Ok(())
    }
    let mut out = Vec::new();
    go(dir, dir, &mut out)?;
    out.sort();
    Ok(out)
}

/// "a, b, c and 4 more".
fn name_some(names: &[String]) -> String {
    let mut s = names.iter().take(NAMED).cloned().collect::<Vec<_>>().join(", ");
    if names.len() > NAMED {
        s += &format!(" and {} more", names.len() - NAMED);
    }
    s
}

/// The manifest of grainlab's in `dir`, if there is one: read only if a regular file of
/// sane size (a pipe named like it would never end), and of this [`FORMAT`].
fn read_manifest(dir: &Path) -> Option<Manifest> {
    crate::scene::limits::read_bounded(&dir.join(MANIFEST), MAX_MANIFEST_BYTES, MANIFEST).ok().and_then(|t| serde_json::from_str(&t).ok()).filter(|m: &Manifest| m.format == FORMAT)
}

/// Delete the file `path`; one that is not there is no error.
fn remove_if_there(path: &Path) -> Result<(), Error> {
    match std::fs::remove_file(path) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(Error::io(path.display(), e)),
        _ => Ok(()),
    }
}

/// What claiming a folder will delete: files, then folders (deepest first).
struct Clearing {
    files: Vec<String>,
    folders: Vec<String>,
}

/// Decide whether `dir` may be used, without writing anything.
fn inspect(dir: &Path, overwrite: bool) -> Result<Clearing, Error> {
    let refuse = |why: String| Err(Error::Folder { dir: dir.display().to_string(), why });
    let nothing = Clearing { files: Vec::new(), folders: Vec::new() };
    match std::fs::metadata(dir) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(nothing),
        Err(e) => return Err(Error::io(dir.display(), e)),
        Ok(m) if !m.is_dir() => return refuse("is not a folder".into()),
        Ok(_) => {}
    }
    let entries = walk(dir)?;
    if entries.is_empty() {
        return Ok(nothing);
    }
    let Some(manifest) = read_manifest(dir) else {
        let names: Vec<String> = entries.iter().map(|e| e.0.clone()).collect();
        return refuse(format!(
            "it holds files grainlab did not write ({}): grainlab writes only into a new or empty folder, or one it wrote itself (its {MANIFEST} lists what it wrote)",
            name_some(&names)
        ));
    };
    let listed = |rel: &str| manifest.files.iter().any(|f| f.path == rel);
    let ours = |rel: &str, is_dir: bool| {
        if is_dir {
            return manifest.folders.iter().any(|f| f == rel);
        }
        // A whole file's temporary, left by a process that died between writing and
        // renaming it: its target was listed before it was written.
        let target = rel.strip_suffix(TEMP_SUFFIX).unwrap_or(rel);
        target == MANIFEST || listed(target)
    };
    let foreign: Vec<String> = entries.iter().filter(|(rel, is_dir)| !ours(rel, *is_dir)).map(|e| e.0.clone()).collect();
    if !foreign.is_empty() {
        return refuse(format!(
            "it holds the output of an earlier `grainlab {}` and files grainlab did not write ({}): move them away or choose another folder; --overwrite deletes only what grainlab wrote",
            manifest.command,
            name_some(&foreign)
        ));
    }
    if !overwrite {
        return refuse(format!(
            "it holds the output of an earlier `grainlab {}` ({}, {} files): add --overwrite to delete exactly those files first, or choose another folder",
            manifest.command,
            manifest.status,
            manifest.files.len()
        ));
    }
    // A listed file that is not as grainlab left it was changed by someone: not deleted.
    // (While a command runs its manifest is not rewritten after every file it completes,
    // so a `running` manifest's sizes are not checked.)
    let mut changed = Vec::new();
    if manifest.status != "running" {
        for f in &manifest.files {
            let (Some(bytes), Some(crc)) = (f.bytes, f.crc32.as_deref()) else { continue };
            if !entries.iter().any(|e| e.0 == f.path && !e.1) {
                continue;
            }
            let path = dir.join(&f.path);
            // The size first: a file of another size (or no regular file) has changed,
            // without reading it.
            let meta = std::fs::metadata(&path).map_err(|e| Error::io(path.display(), e))?;
            if !meta.is_file() || meta.len() != bytes {
                changed.push(f.path.clone());
                continue;
            }
            let data = std::fs::read(&path).map_err(|e| Error::io(path.display(), e))?;
            if crc_hex(crc32fast::hash(&data)) != crc {
                changed.push(f.path.clone());
            }
        }
    }
    if !changed.is_empty() {
        return refuse(format!(
            "files grainlab wrote there have been changed since ({}): --overwrite does not delete them; move them away or choose another folder",
            name_some(&changed)
        ));
    }
    // Only what the walk found, so nothing outside the folder, whatever the manifest says.
    let files = entries.iter().filter(|e| !e.1).map(|e| e.0.clone()).collect();
    let mut folders: Vec<String> = entries.iter().filter(|e| e.1).map(|e| e.0.clone()).collect();
    folders.sort_by_key(|f| std::cmp::Reverse(f.matches('/').count()));
    Ok(Clearing { files, folders })
}

impl OutFolder {
    /// Check that `dir` may be used without writing anything (see the module's rules):
    /// the same refusals as [`OutFolder::claim`], before a long build.
    pub fn check(dir: &Path, overwrite: bool) -> Result<(), Error> {
        inspect(dir, overwrite).map(|_| ())
    }

    /// Take `dir` for `command` (see the module's rules): create it, or clear an earlier
    /// command's files with `overwrite`, and write a manifest with status `running`.
    pub fn claim(dir: &Path, overwrite: bool, command: &str) -> Result<Self, Error> {
        let clearing = inspect(dir, overwrite)?;
        std::fs::create_dir_all(dir).map_err(|e| Error::io(dir.display(), e))?;
        // The old manifest goes last (replaced by the new one), so that a process that
        // dies while clearing leaves a folder whose manifest lists what is left.
        for f in clearing.files.iter().filter(|f| *f != MANIFEST) {
            remove_if_there(&dir.join(f))?;
        }
        for f in &clearing.folders {
            let path = dir.join(f);
            std::fs::remove_dir(&path).map_err(|e| Error::io(path.display(), e))?;
        }
        let manifest = Manifest { format: FORMAT.into(), grainlab: env!("CARGO_PKG_VERSION").into(), command: command.into(), status: "running".into(), folders: Vec::new(), files: Vec::new() };
        let folder = OutFolder { dir: dir.to_path_buf(), manifest };
        folder.save()?;
        Ok(folder)
    }

    /// Take back the folder of a run that did not complete, to resume it: its manifest
    /// must be grainlab's and its status not `completed`. The status goes back to
    /// `running`, and the files a resumed run writes again at its end (`summary.json`,
    /// `force_overlap.csv`, `profiles.csv`) and the frames past the first `frames` of `frames_kept` are
    /// deleted and unlisted, so that nothing in the folder mixes the two runs.
    pub fn reopen(dir: &Path, frames_kept: &[String]) -> Result<Self, Error> {
        let refuse = |why: String| Err(Error::Folder { dir: dir.display().to_string(), why });
        let Some(mut manifest) = read_manifest(dir) else {
            return refuse(format!("has no {MANIFEST} of grainlab's: it is not a run's output folder"));
        };
        if manifest.status == "completed" {
            return refuse(format!("holds a completed `grainlab {}`: nothing to resume", manifest.command));
        }
        let gone = |p: &str| ["summary.json", "force_overlap.csv", "force_overlap.csv.part", "profiles.csv", "profiles.csv.part"].contains(&p) || (p.starts_with("frames/") && !frames_kept.iter().any(|f| f == p));
        for f in manifest.files.iter().filter(|f| gone(&f.path)) {
            remove_if_there(&dir.join(&f.path))?;
        }
        manifest.files.retain(|f| !gone(&f.path));
        manifest.status = "running".into();
        let folder = OutFolder { dir: dir.to_path_buf(), manifest };
        folder.save()?;
        Ok(folder)
    }

    /// Continue the series `rel` from its first `bytes` bytes ([`CsvSeries::resume`]),
    /// listed as `rel.part` until [`OutFolder::close_series`].
    pub fn resume_series(&mut self, rel: &str, bytes: u64) -> Result<CsvSeries, Error> {
        self.announce(&format!("{rel}{PART_SUFFIX}"))?;
        let s = CsvSeries::resume(&self.dir.join(rel), bytes)?;
        self.manifest.files.retain(|f| f.path != rel);
        self.save()?;
        Ok(s)
    }

    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The manifest as it stands.
    pub fn manifest(&self) -> &Manifest {
        &self.manifest
    }

    fn save(&self) -> Result<(), Error> {
        write_atomic(&self.dir.join(MANIFEST), (serde_json::to_string_pretty(&self.manifest).expect("serialisable") + "\n").as_bytes())
    }

    /// List `rel` (a file about to be written) in the manifest on disk; its path.
    pub fn announce(&mut self, rel: &str) -> Result<PathBuf, Error> {
        if !self.manifest.files.iter().any(|f| f.path == rel) {
            self.manifest.files.push(FileEntry { path: rel.into(), bytes: None, crc32: None });
            self.save()?;
        }
        Ok(self.dir.join(rel))
    }

    /// Make the sub-folder `rel`, listed.
    pub fn folder(&mut self, rel: &str) -> Result<PathBuf, Error> {
        if !self.manifest.folders.iter().any(|f| f == rel) {
            self.manifest.folders.push(rel.into());
            self.save()?;
        }
        let path = self.dir.join(rel);
        std::fs::create_dir_all(&path).map_err(|e| Error::io(path.display(), e))?;
        Ok(path)
    }

    /// Note `rel`'s final size and checksum (saved with the manifest's next write).
    fn record(&mut self, rel: &str, bytes: u64, crc: u32) {
        if let Some(f) = self.manifest.files.iter_mut().find(|f| f.path == rel) {
            f.bytes = Some(bytes);
            f.crc32 = Some(crc_hex(crc));
        }
    }

    /// Write the whole file `rel` atomically, listed first.
    pub fn write(&mut self, rel: &str, bytes: &[u8]) -> Result<(), Error> {
        self.write_with(rel, bytes, false)
    }

    /// [`OutFolder::write`], synced to the disk before the rename (a checkpoint).
    pub fn write_synced(&mut self, rel: &str, bytes: &[u8]) -> Result<(), Error> {
        self.write_with(rel, bytes, true)
    }

    fn write_with(&mut self, rel: &str, bytes: &[u8], sync: bool) -> Result<(), Error> {
        let path = self.announce(rel)?;
        write_whole(&path, bytes, sync)?;
        self.record(rel, bytes.len() as u64, crc32fast::hash(bytes));
        Ok(())
    }

    /// A CSV series `rel`, written as `rel.part` until [`OutFolder::close_series`].
    pub fn series(&mut self, rel: &str) -> Result<CsvSeries, Error> {
        self.announce(&format!("{rel}{PART_SUFFIX}"))?;
        CsvSeries::staged(&self.dir.join(rel))
    }

    /// Finish the series `rel`: rename `rel.part` to `rel` (both listed meanwhile).
    pub fn close_series(&mut self, series: CsvSeries, rel: &str) -> Result<(), Error> {
        self.announce(rel)?;
        let (bytes, crc) = series.finish()?;
        let part = format!("{rel}{PART_SUFFIX}");
        self.manifest.files.retain(|f| f.path != part);
        self.record(rel, bytes, crc);
        Ok(())
    }

    /// A series of `rows` written as a whole (`rel.part`, then renamed).
    pub fn write_series<T: Serialize>(&mut self, rel: &str, rows: &[T]) -> Result<(), Error> {
        let mut w = self.series(rel)?;
        for r in rows {
            w.row(r)?;
        }
        self.close_series(w, rel)
    }

    /// Delete the file `rel`, if there, and unlist it.
    pub fn remove(&mut self, rel: &str) -> Result<(), Error> {
        remove_if_there(&self.dir.join(rel))?;
        self.manifest.files.retain(|f| f.path != rel);
        Ok(())
    }

    /// Write the final manifest with `status` (files that were announced and never
    /// written are left out).
    pub fn finish(&mut self, status: &str) -> Result<(), Error> {
        self.manifest.status = status.into();
        let dir = self.dir.clone();
        self.manifest.files.retain(|f| dir.join(&f.path).exists());
        self.save()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(dir: &Path) -> Vec<String> {
        walk(dir).unwrap().into_iter().map(|e| e.0).collect()
    }

    #[test]
    fn claims_an_empty_or_missing_folder_and_lists_what_it_writes() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().join("new");
        let mut f = OutFolder::claim(&dir, false, "run test").unwrap();
        f.write("summary.json", b"123456789").unwrap();
        f.folder("frames").unwrap();
        f.write("frames/a.vtp", b"frame").unwrap();
        let mut s = f.series("energy.csv").unwrap();
        s.row(&(1.0, 2.0)).unwrap();
        assert!(dir.join("energy.csv.part").exists());
        f.close_series(s, "energy.csv").unwrap();
        f.finish("completed").unwrap();
        assert_eq!(names(&dir), ["energy.csv", "frames", "frames/a.vtp", "manifest.json", "summary.json"]);
        let m: Manifest = serde_json::from_str(&std::fs::read_to_string(dir.join(MANIFEST)).unwrap()).unwrap();
        assert_eq!(m.status, "completed");
        assert_eq!(m.folders, ["frames"]);
        let paths: Vec<&str> = m.files.iter().map(|f| f.path.as_str()).collect();
        assert_eq!(paths, ["summary.json", "frames/a.vtp", "energy.csv"]);
        // The check value of CRC-32/ISO-HDLC (zlib's crc32).
        assert_eq!(m.files[0].crc32.as_deref(), Some("cbf43926"));
        assert_eq!(m.files[2].bytes, Some(std::fs::metadata(dir.join("energy.csv")).unwrap().len()));
        // Reused: refused without --overwrite, cleared with it.
        assert!(matches!(OutFolder::claim(&dir, false, "run test"), Err(Error::Folder { .. })));
        std::fs::write(dir.join("summary.json.grainlab-tmp"), "half").unwrap();
        let f = OutFolder::claim(&dir, true, "run again").unwrap();
        assert_eq!(names(&dir), ["manifest.json"]);
        assert_eq!(f.manifest().status, "running");
    }

    #[test]
    fn refuses_files_it_did_not_write_and_deletes_nothing() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path();
        std::fs::write(dir.join("notes.txt"), "mine").unwrap();
        for overwrite in [false, true] {
            let e = OutFolder::claim(dir, overwrite, "run test").unwrap_err().to_string();
            assert!(e.contains("notes.txt") && e.contains("did not write"), "{e}");
        }
        assert_eq!(names(dir), ["notes.txt"]);
        let file = dir.join("notes.txt");
        assert!(OutFolder::claim(&file, true, "run test").unwrap_err().to_string().contains("is not a folder"));
    }
}
