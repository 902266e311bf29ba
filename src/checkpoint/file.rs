//! The checkpoint file format: a fixed header, then the checkpoint as MessagePack.
//!
//! ```text
//! bytes  0..12  magic "POLYDEM-CKPT"
//!       12..16  format version, u32 little endian (FORMAT_VERSION)
//!       16..24  payload length in bytes, u64 little endian
//!       24..32  FNV-1a 64 hash of the payload, u64 little endian
//!       32..    payload: the Checkpoint, MessagePack with named fields (rmp-serde)
//! ```
//!
//! The header lets a reader refuse what it cannot read before decoding anything, with a message
//! that says why: not a checkpoint, a format of a newer polydem, a truncated or damaged file.
//! MessagePack keeps every f64 bit for bit; named fields let a later version add a field with a
//! default and still read this one.

use super::Checkpoint;
use crate::io::atomic::write_atomic_file;
use serde::Serialize;
use std::fs::File;
use std::io::{self, BufReader, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

const MAGIC: &[u8; 12] = b"POLYDEM-CKPT";
const HEADER: usize = 32;

/// The format this polydem writes and reads. Raise it when a change makes older files unreadable
/// (a field removed or changed in meaning), and say so in `docs/checkpoints.md`.
pub const FORMAT_VERSION: u32 = 1;

/// Why a checkpoint could not be written or read.
#[derive(Debug, thiserror::Error)]
pub enum CheckpointError {
    #[error("cannot write checkpoint '{path}': {source}")]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("cannot read checkpoint '{path}': {source}")]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("'{path}' is not a polydem checkpoint (it does not start with {MAGIC:?})", MAGIC = std::str::from_utf8(MAGIC).unwrap_or_default())]
    NotACheckpoint { path: PathBuf },
    #[error(
        "checkpoint '{path}' has format version {found}, but this polydem reads version \
         {FORMAT_VERSION}: {advice}"
    )]
    Version {
        path: PathBuf,
        found: u32,
        advice: &'static str,
    },
    #[error(
        "checkpoint '{path}' is truncated: its header promises {expected} bytes of data, the file \
         holds {found} (the run was probably stopped while writing it; the previous checkpoint \
         in the same folder is complete)"
    )]
    Truncated {
        path: PathBuf,
        expected: u64,
        found: u64,
    },
    #[error("checkpoint '{path}' is damaged: its data do not match the checksum in its header")]
    Damaged { path: PathBuf },
    #[error("checkpoint '{path}' cannot be decoded: {message}")]
    Decode { path: PathBuf, message: String },
    #[error("cannot encode the checkpoint: {0}")]
    Encode(String),
}

/// Writes `checkpoint` to `path` atomically (a complete file or none, see `io::atomic`).
///
/// The payload is encoded straight into the file, hashed and counted on its way, and the header's
/// length and checksum are filled in at the end: the file is never held in memory (at 65,000
/// spheres it is 120 MB, which a buffer grown by doubling and a second copy with the header had
/// made 2.5 times that at the run's peak).
pub fn write<W: Serialize>(path: &Path, checkpoint: &Checkpoint<W>) -> Result<(), CheckpointError> {
    let mut encode_error = None;
    let written = write_atomic_file(path, |file| {
        file.write_all(&header(0, 0))?;
        let mut payload = Hashing::new(&mut *file);
        if let Err(e) = rmp_serde::encode::write_named(&mut payload, checkpoint) {
            let message = e.to_string();
            encode_error = Some(e);
            return Err(io::Error::other(message));
        }
        let (length, hash) = (payload.length, payload.hash);
        file.seek(SeekFrom::Start(LENGTH_AT))?;
        file.write_all(&length.to_le_bytes())?;
        file.write_all(&hash.to_le_bytes())
    });
    written.map_err(|source| match encode_error {
        // An error of the file itself (a full disk) comes through the encoder too.
        Some(rmp_serde::encode::Error::InvalidValueWrite(_)) | None => CheckpointError::Write {
            path: path.to_path_buf(),
            source,
        },
        Some(e) => CheckpointError::Encode(e.to_string()),
    })
}

/// The header of a payload of `length` bytes hashing to `hash`.
fn header(length: u64, hash: u64) -> [u8; HEADER] {
    let mut bytes = [0; HEADER];
    bytes[..12].copy_from_slice(MAGIC);
    bytes[12..16].copy_from_slice(&FORMAT_VERSION.to_le_bytes());
    bytes[16..24].copy_from_slice(&length.to_le_bytes());
    bytes[24..32].copy_from_slice(&hash.to_le_bytes());
    bytes
}

/// Where the header's length is (its checksum follows).
const LENGTH_AT: u64 = 16;

/// Reads the checkpoint at `path`, refusing files of another format version, truncated or damaged
/// ones with a message that says which. The payload is decoded as it is read, not read whole
/// first; its checksum is checked before the checkpoint is returned.
pub fn read(path: &Path) -> Result<Checkpoint, CheckpointError> {
    let reading = |source| CheckpointError::Read {
        path: path.to_path_buf(),
        source,
    };
    let file = File::open(path).map_err(reading)?;
    let size = file.metadata().map_err(reading)?.len();
    decode(path, BufReader::with_capacity(1 << 16, file), size)
}

/// Decodes a checkpoint file of `size` bytes from `file`.
fn decode(path: &Path, mut file: impl Read, size: u64) -> Result<Checkpoint, CheckpointError> {
    let path = path.to_path_buf();
    let mut bytes = Vec::with_capacity(HEADER);
    (&mut file)
        .take(HEADER as u64)
        .read_to_end(&mut bytes)
        .map_err(|source| CheckpointError::Read {
            path: path.clone(),
            source,
        })?;
    if bytes.len() < MAGIC.len() || &bytes[..MAGIC.len()] != MAGIC {
        return Err(CheckpointError::NotACheckpoint { path });
    }
    let word = |range: std::ops::Range<usize>| {
        bytes
            .get(range)
            .map(|b| b.iter().rev().fold(0u64, |v, &x| (v << 8) | x as u64))
    };
    let Some(version) = word(12..16) else {
        return Err(CheckpointError::Truncated {
            path,
            expected: HEADER as u64,
            found: bytes.len() as u64,
        });
    };
    let version = version as u32;
    if version != FORMAT_VERSION {
        let advice = if version > FORMAT_VERSION {
            "it was written by a newer polydem; resume it with that version"
        } else {
            "it was written by an older polydem; resume it with that version, or start the run \
             again"
        };
        return Err(CheckpointError::Version {
            path,
            found: version,
            advice,
        });
    }
    let (Some(length), Some(hash)) = (word(16..24), word(24..32)) else {
        return Err(CheckpointError::Truncated {
            path,
            expected: HEADER as u64,
            found: bytes.len() as u64,
        });
    };
    let found = size.saturating_sub(HEADER as u64);
    if found < length {
        return Err(CheckpointError::Truncated {
            path,
            expected: length,
            found,
        });
    }
    let mut payload = Hashing::new(file.take(length));
    let decoded: Result<Checkpoint, _> = rmp_serde::from_read(&mut payload);
    // The rest of the payload, if the decoder stopped early (damaged data), still counts.
    if let Err(source) = io::copy(&mut payload, &mut io::sink()) {
        return Err(CheckpointError::Read { path, source });
    }
    if payload.hash != hash || payload.length != length {
        return Err(CheckpointError::Damaged { path });
    }
    decoded.map_err(|e| CheckpointError::Decode {
        path,
        message: e.to_string(),
    })
}

/// A reader or writer that hashes ([`fnv1a`]) and counts the bytes passing through it.
struct Hashing<T> {
    inner: T,
    hash: u64,
    length: u64,
}

impl<T> Hashing<T> {
    fn new(inner: T) -> Self {
        Hashing {
            inner,
            hash: FNV_OFFSET,
            length: 0,
        }
    }

    fn pass(&mut self, bytes: &[u8]) {
        self.hash = fnv1a_more(self.hash, bytes);
        self.length += bytes.len() as u64;
    }
}

impl<T: Write> Write for Hashing<T> {
    fn write(&mut self, bytes: &[u8]) -> io::Result<usize> {
        let n = self.inner.write(bytes)?;
        self.pass(&bytes[..n]);
        Ok(n)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.inner.flush()
    }
}

impl<T: Read> Read for Hashing<T> {
    fn read(&mut self, bytes: &mut [u8]) -> io::Result<usize> {
        let n = self.inner.read(bytes)?;
        self.pass(&bytes[..n]);
        Ok(n)
    }
}

const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;

/// FNV-1a, 64 bits (Fowler, Noll, Vo): enough to tell a damaged file or a changed scene, which is
/// all it is used for (not a defence against deliberate tampering).
pub fn fnv1a(bytes: &[u8]) -> u64 {
    fnv1a_more(FNV_OFFSET, bytes)
}

/// [`fnv1a`] of the bytes hashed to `hash` so far followed by `bytes`.
fn fnv1a_more(mut hash: u64, bytes: &[u8]) -> u64 {
    for &b in bytes {
        hash ^= b as u64;
        hash = hash.wrapping_mul(0x0000_0100_0000_01b3);
    }
    hash
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fnv1a_matches_the_reference_values() {
        // From the FNV reference test suite.
        assert_eq!(fnv1a(b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a(b"a"), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(fnv1a(b"foobar"), 0x8594_4171_f739_67e8);
    }

    fn decode_slice(path: &Path, bytes: &[u8]) -> Result<Checkpoint, CheckpointError> {
        decode(path, bytes, bytes.len() as u64)
    }

    fn error(r: Result<Checkpoint, CheckpointError>) -> CheckpointError {
        match r {
            Err(e) => e,
            Ok(_) => panic!("decoded"),
        }
    }

    #[test]
    fn a_file_that_is_not_a_checkpoint_is_named_as_such() {
        let e = error(decode_slice(Path::new("x.vtp"), b"<?xml version"));
        assert!(matches!(e, CheckpointError::NotACheckpoint { .. }), "{e}");
        assert!(e.to_string().contains("x.vtp"));
    }

    fn header(version: u32, length: u64, hash: u64) -> Vec<u8> {
        let mut b = MAGIC.to_vec();
        b.extend_from_slice(&version.to_le_bytes());
        b.extend_from_slice(&length.to_le_bytes());
        b.extend_from_slice(&hash.to_le_bytes());
        b
    }

    #[test]
    fn a_future_version_is_refused_before_decoding() {
        let e = error(decode_slice(
            Path::new("c"),
            &header(FORMAT_VERSION + 1, 0, 0),
        ));
        assert!(e.to_string().contains("newer polydem"), "{e}");
    }

    #[test]
    fn truncated_and_damaged_payloads_are_told_apart() {
        let payload = b"0123456789";
        let mut whole = header(FORMAT_VERSION, 10, fnv1a(payload));
        whole.extend_from_slice(payload);
        let e = error(decode_slice(Path::new("c"), &whole[..whole.len() - 3]));
        assert!(
            matches!(
                e,
                CheckpointError::Truncated {
                    expected: 10,
                    found: 7,
                    ..
                }
            ),
            "{e}"
        );
        let e = error(decode_slice(Path::new("c"), &whole[..20]));
        assert!(matches!(e, CheckpointError::Truncated { .. }), "{e}");
        let mut damaged = whole.clone();
        *damaged.last_mut().unwrap() ^= 1;
        let e = error(decode_slice(Path::new("c"), &damaged));
        assert!(matches!(e, CheckpointError::Damaged { .. }), "{e}");
        // Intact but not a checkpoint's data: a decoding error, not a panic.
        let e = error(decode_slice(Path::new("c"), &whole));
        assert!(matches!(e, CheckpointError::Decode { .. }), "{e}");
    }
}
