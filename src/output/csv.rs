//! CSV time series. Headers come from the row types' field names, which carry the unit
//! (`time_s`, `work_walls_j`, ...). Rows are flushed as written, so a run that stops
//! keeps everything it computed.

use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::error::Error;

/// The end of a streamed series' name while the command goes.
pub const PART_SUFFIX: &str = ".part";

/// `path` with `suffix` appended to its file name.
pub fn with_suffix(path: &Path, suffix: &str) -> PathBuf {
    let mut s = path.as_os_str().to_owned();
    s.push(suffix);
    PathBuf::from(s)
}

/// A writer that counts and checksums what goes through it (the manifest's size and
/// CRC-32, without reading the file again).
struct Counted {
    file: File,
    bytes: u64,
    crc: crc32fast::Hasher,
}

impl Write for Counted {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let n = self.file.write(buf)?;
        self.bytes += n as u64;
        self.crc.update(&buf[..n]);
        Ok(n)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.file.flush()
    }
}

pub struct CsvSeries {
    out: Counted,
    /// Where the rows go now.
    path: PathBuf,
    /// The name the file takes at [`CsvSeries::finish`], if not `path`.
    final_path: Option<PathBuf>,
    /// The header has been written.
    header: bool,
}

fn csv_error(path: &Path, e: ::csv::Error) -> Error {
    if e.is_io_error() {
        match e.into_kind() {
            ::csv::ErrorKind::Io(io) => Error::io(path.display(), io),
            _ => unreachable!("an I/O error"),
        }
    } else {
        Error::Other(format!("{}: {e}", path.display()))
    }
}

impl CsvSeries {
    /// Write into `path` directly.
    pub fn create(path: &Path) -> Result<Self, Error> {
        Self::open(path, None)
    }

    /// Write into `path.part`, renamed to `path` by [`CsvSeries::finish`]: `path` appears
    /// only complete, and a process that dies leaves its rows under the `.part` name.
    pub fn staged(path: &Path) -> Result<Self, Error> {
        Self::open(&with_suffix(path, PART_SUFFIX), Some(path.to_path_buf()))
    }

    fn open(path: &Path, final_path: Option<PathBuf>) -> Result<Self, Error> {
        let file = File::create(path).map_err(|e| Error::io(path.display(), e))?;
        let out = Counted { file, bytes: 0, crc: crc32fast::Hasher::new() };
        Ok(CsvSeries { out, path: path.to_path_buf(), final_path, header: false })
    }

    /// Write a row; a row with a number that is not finite is refused (the run's checks
    /// stop a run before that, so this is the last line of defence: no output holds NaN).
    pub fn row<T: Serialize>(&mut self, row: &T) -> Result<(), Error> {
        self.row_in("", row)
    }

    /// Write a row of a protocol's stage `stage`, named in a first column `stage` (none
    /// when `stage` is empty: a run without stages). Stage names need no quoting (scene
    /// validation admits letters, digits, spaces and `-_.`).
    pub fn row_in<T: Serialize>(&mut self, stage: &str, row: &T) -> Result<(), Error> {
        if let Some(column) = crate::finite::non_finite_column(row) {
            return Err(Error::Other(format!("{}: a row whose {column} is not finite was not written", self.path.display())));
        }
        let mut w = ::csv::WriterBuilder::new().has_headers(!self.header).from_writer(Vec::new());
        w.serialize(row).map_err(|e| csv_error(&self.path, e))?;
        let mut bytes = w.into_inner().map_err(|e| Error::io(self.path.display(), e.into_error()))?;
        if !stage.is_empty() {
            let text = String::from_utf8(bytes).expect("CSV of numbers is UTF-8");
            let mut out = String::with_capacity(text.len() + 2 * stage.len());
            for (k, line) in text.split_inclusive('\n').enumerate() {
                out.push_str(if k == 0 && !self.header { "stage," } else { stage });
                if k > 0 || self.header {
                    out.push(',');
                }
                out.push_str(line);
            }
            bytes = out.into_bytes();
        }
        self.header = true;
        self.out.write_all(&bytes).and_then(|()| self.out.flush()).map_err(|e| Error::io(self.path.display(), e))
    }

    /// Continue the staged series `path` (its `path.part`, or `path` itself if a run that
    /// ended renamed it: renamed back) from its first `bytes` bytes, what a checkpoint
    /// recorded; what follows them (rows written after the checkpoint) is cut off. An
    /// error if the file is missing or shorter.
    pub fn resume(path: &Path, bytes: u64) -> Result<Self, Error> {
        let part = with_suffix(path, PART_SUFFIX);
        if !part.exists() && path.exists() {
            std::fs::rename(path, &part).map_err(|e| Error::io(part.display(), e))?;
        }
        let mut file = std::fs::OpenOptions::new().read(true).write(true).open(&part).map_err(|e| Error::io(part.display(), e))?;
        let len = file.metadata().map_err(|e| Error::io(part.display(), e))?.len();
        if len < bytes {
            return Err(Error::Checkpoint { file: part.display().to_string(), why: format!("holds {len} bytes, the checkpoint needs its first {bytes}: it was cut after the checkpoint was written") });
        }
        file.set_len(bytes).map_err(|e| Error::io(part.display(), e))?;
        // The checksum of what is kept, read a piece at a time (a series may be large);
        // the reads leave the file at its end, where the rows go on.
        let mut crc = crc32fast::Hasher::new();
        let mut piece = vec![0u8; 1 << 16];
        loop {
            match std::io::Read::read(&mut file, &mut piece) {
                Ok(0) => break,
                Ok(n) => crc.update(&piece[..n]),
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => return Err(Error::io(part.display(), e)),
            }
        }
        let out = Counted { file, bytes, crc };
        Ok(CsvSeries { out, path: part, final_path: Some(path.to_path_buf()), header: bytes > 0 })
    }

    /// Bytes written so far, on disk (rows are flushed as written); with `sync`, after
    /// asking the system to put them on the disk itself (a checkpoint refers to them).
    pub fn written(&mut self, sync: bool) -> Result<u64, Error> {
        self.out.flush().map_err(|e| Error::io(self.path.display(), e))?;
        if sync {
            self.out.file.sync_data().map_err(|e| Error::io(self.path.display(), e))?;
        }
        Ok(self.out.bytes)
    }

    /// Flush, rename a staged series to its name, and return its size and CRC-32.
    pub fn finish(mut self) -> Result<(u64, u32), Error> {
        self.out.flush().map_err(|e| Error::io(self.path.display(), e))?;
        if let Some(to) = &self.final_path {
            std::fs::rename(&self.path, to).map_err(|e| Error::io(to.display(), e))?;
        }
        Ok((self.out.bytes, self.out.crc.finalize()))
    }
}
