//! CSV time series. Headers come from the row types' field names, which carry the unit
//! (`time_s`, `work_walls_j`, ...). Rows are flushed as written, so a run that stops
//! keeps everything it computed.

use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

use serde::Serialize;

use crate::error::Error;

pub struct CsvSeries {
    w: ::csv::Writer<BufWriter<File>>,
    path: String,
}

impl CsvSeries {
    pub fn create(path: &Path) -> Result<Self, Error> {
        let f = File::create(path).map_err(|e| Error::io(path.display(), e))?;
        Ok(CsvSeries { w: ::csv::Writer::from_writer(BufWriter::new(f)), path: path.display().to_string() })
    }
    /// Write a row; a row with a number that is not finite is refused (the run's checks
    /// stop a run before that, so this is the last line of defence: no output holds NaN).
    pub fn row<T: Serialize>(&mut self, row: &T) -> Result<(), Error> {
        if let Some(column) = crate::finite::non_finite_column(row) {
            return Err(Error::Other(format!("{}: a row whose {column} is not finite was not written", self.path)));
        }
        self.w.serialize(row).map_err(|e| Error::Other(format!("{}: {e}", self.path)))?;
        self.w.flush().map_err(|e| Error::io(&self.path, e))
    }
}
