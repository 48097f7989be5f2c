//! The checkpoint file: what `grainlab resume DIR` continues a run from, bit for bit.
//!
//! `checkpoint.bin` in the run's output folder, replaced whole at every checkpoint
//! (written under a temporary name, synced to disk, then renamed: a crash at any moment
//! leaves the last good one). Its layout:
//!
//! | bytes | what |
//! | --- | --- |
//! | 8 | [`MAGIC`]: `GLCKPT` in ASCII and two 0 bytes |
//! | 4 | format version, little-endian ([`FORMAT_VERSION`]) |
//! | 8 | payload length in bytes, little-endian |
//! | 4 | CRC-32 (IEEE) of the payload, little-endian |
//! | rest | the payload: [`Checkpoint`] in postcard |
//!
//! A file that is not one, of another format version, shorter or longer than it says, or
//! whose checksum does not match, is refused with what is wrong; so is a payload that
//! does not decode. The engine's and the run loop's states inside are opaque here
//! ([`crate::engine::snapshot`], [`crate::study::run`]).

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::Error;

/// The checkpoint's file name in an output folder.
pub const CHECKPOINT: &str = "checkpoint.bin";
/// The first bytes of a checkpoint.
pub const MAGIC: [u8; 8] = *b"GLCKPT\0\0";
/// The layout of the payload; a change to it (or to a state inside) raises it.
pub const FORMAT_VERSION: u32 = 1;
const HEADER: usize = 8 + 4 + 8 + 4;

/// What a checkpoint holds.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Checkpoint {
    /// The grainlab version and commit that wrote it: a run resumes bit for bit only on
    /// the build that started it.
    pub grainlab: String,
    pub commit: String,
    /// The scene the run was built from (JSON, every default filled in, before a
    /// `--duration` cut: the time step may depend on stages the cut left out).
    pub scene: String,
    /// The run's `--duration`, if it was given, s.
    pub duration: Option<f64>,
    /// Threads the run used (a resumed run may use others: the bits do not depend on it).
    pub threads: usize,
    /// Simulated time between checkpoints (`--checkpoint-every`), s; none when only a
    /// stop request wrote this one.
    pub every_s: Option<f64>,
    /// The step the state is at, and its time, s.
    pub step: u64,
    pub time_s: f64,
    /// The engine's state ([`crate::engine::simulation::Engine::save`]).
    pub engine: Vec<u8>,
    /// The run loop's state: observers, outputs written so far.
    pub run: Vec<u8>,
}

impl Checkpoint {
    /// The file's bytes.
    pub fn encode(&self) -> Vec<u8> {
        let payload = postcard::to_stdvec(self).expect("a checkpoint encodes");
        let mut out = Vec::with_capacity(HEADER + payload.len());
        out.extend_from_slice(&MAGIC);
        out.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
        out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
        out.extend_from_slice(&crc32fast::hash(&payload).to_le_bytes());
        out.extend_from_slice(&payload);
        out
    }

    /// Read a checkpoint's bytes (`file` names it in errors).
    pub fn decode(bytes: &[u8], file: &str) -> Result<Checkpoint, Error> {
        let refuse = |why: String| Err(Error::Checkpoint { file: file.into(), why });
        if bytes.len() < MAGIC.len() || bytes[..MAGIC.len()] != MAGIC {
            return refuse("is not a grainlab checkpoint (its first bytes are not GLCKPT)".into());
        }
        if bytes.len() < HEADER {
            return refuse(format!("is truncated: {} bytes, shorter than its {HEADER}-byte header", bytes.len()));
        }
        let word = |at: usize, n: usize| bytes[at..at + n].iter().rev().fold(0u64, |a, &b| a << 8 | b as u64);
        let version = word(8, 4);
        if version != FORMAT_VERSION as u64 {
            return refuse(format!("has format version {version}; this grainlab reads version {FORMAT_VERSION} (resume it with the grainlab that wrote it)"));
        }
        let (len, crc) = (word(12, 8), word(20, 4) as u32);
        let payload = &bytes[HEADER..];
        if payload.len() as u64 != len {
            let what = if (payload.len() as u64) < len { "is truncated" } else { "has bytes past its end" };
            return refuse(format!("{what}: its payload is {} bytes, its header says {len}", payload.len()));
        }
        if crc32fast::hash(payload) != crc {
            return refuse("is corrupt: its checksum does not match its content".into());
        }
        postcard::from_bytes(payload).or_else(|e| refuse(format!("does not decode ({e})")))
    }

    /// Read the checkpoint at `path`, refused if it is larger than `max_bytes`.
    pub fn read(path: &Path, max_bytes: u64) -> Result<Checkpoint, Error> {
        let shown = path.display().to_string();
        let meta = match std::fs::metadata(path) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                return Err(Error::Checkpoint {
                    file: shown,
                    why: "is missing: a run writes one every --checkpoint-every and on a stop request (SIGINT, SIGTERM), and deletes it when it completes".into(),
                });
            }
            m => m.map_err(|e| Error::io(&shown, e))?,
        };
        if !meta.is_file() {
            return Err(Error::Checkpoint { file: shown, why: "is not a regular file".into() });
        }
        if meta.len() > max_bytes {
            return Err(Error::Checkpoint { file: shown, why: format!("is {} bytes, more than the memory budget allows ({max_bytes})", meta.len()) });
        }
        let bytes = std::fs::read(path).map_err(|e| Error::io(&shown, e))?;
        Checkpoint::decode(&bytes, &shown)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Checkpoint {
        Checkpoint { grainlab: "0.1.0".into(), commit: "abc".into(), scene: "{}".into(), duration: Some(1.0), threads: 2, every_s: Some(0.5), step: 7, time_s: 7e-6, engine: vec![1, 2, 3], run: vec![4, 5] }
    }

    #[test]
    fn round_trips_and_refuses_every_kind_of_damage() {
        let bytes = sample().encode();
        let back = Checkpoint::decode(&bytes, "c").unwrap();
        assert_eq!((back.step, back.engine.as_slice(), back.run.as_slice(), back.every_s), (7, &[1u8, 2, 3][..], &[4u8, 5][..], Some(0.5)));
        let why = |b: &[u8]| Checkpoint::decode(b, "c").unwrap_err().to_string();
        assert!(why(b"{\"json\": 1}").contains("not a grainlab checkpoint"));
        assert!(why(&bytes[..10]).contains("truncated"));
        assert!(why(&bytes[..bytes.len() - 1]).contains("truncated"));
        let mut longer = bytes.clone();
        longer.push(0);
        assert!(why(&longer).contains("past its end"));
        let mut flipped = bytes.clone();
        *flipped.last_mut().unwrap() ^= 1;
        assert!(why(&flipped).contains("corrupt"));
        let mut version = bytes.clone();
        version[8] = 9;
        assert!(why(&version).contains("format version 9"));
    }
}
