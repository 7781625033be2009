//! Checkpoint files: a whole run saved to a file, so that a run killed
//! (at a cluster's wall-clock limit, by a failed node) goes on from its last
//! checkpoint to the same bits as the run that was never stopped.
//!
//! A checkpoint holds the run's saved state ([`Simulation`]'s, of the
//! state format [`crate::STATE_FORMAT`]) and what its host needs to go on
//! (the program's snapshot times and output files; `null` from Python and
//! the C ABI). The file is three parts:
//!
//! ```text
//! meshless-impact checkpoint 1\n          the magic line and the checkpoint format
//! {"host": ..., "run": {...}}             the body (JSON)
//! \nend crc32=1a2b3c4d bytes=00000000000000012345\n
//! ```
//!
//! The body is JSON, the saved state as [`Simulation::serialize_state`]
//! writes it, so that a state of an older format is brought up to this one
//! as a saved state is. (MessagePack was measured as no faster: the time is
//! serde's work per value, whatever the format; BENCHMARKS.md,
//! "Checkpoints".)
//!
//! The trailer has a fixed width: the CRC-32 of everything before it and
//! that length in bytes. A reader checks the trailer first, so that a file
//! cut short ([`CheckpointFault::Truncated`]) or with any bit changed
//! ([`CheckpointFault::Corrupted`]) is refused before a byte of it is
//! believed; then the formats (newer ones refused:
//! [`CheckpointFault::NewerFormat`]); then the state, which loads as
//! [`Simulation::deserialize_state`] loads one (older state formats
//! brought up to this one, and checked). Files are written whole
//! ([`crate::files::write_whole`]): a kill while one is written leaves the
//! previous checkpoint.

use crate::error::{Error, Result};
use crate::scene::Scene;
use crate::sim::Simulation;
use std::io::Write;
use std::path::Path;

/// The checkpoint format this build writes and the newest it reads.
pub const CHECKPOINT_FORMAT: u32 = 1;

/// The start of every checkpoint file.
const MAGIC: &[u8] = b"meshless-impact checkpoint ";

/// The shape of the trailer (`X`: a lower-case hex digit, `N`: a decimal
/// digit).
const TRAILER: &[u8] = b"\nend crc32=XXXXXXXX bytes=NNNNNNNNNNNNNNNNNNNN\n";

/// What is wrong with a file given as a checkpoint
/// ([`Error::Checkpoint`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CheckpointFault {
    /// It does not start as a checkpoint does.
    NotACheckpoint,
    /// It ends before its trailer: the file was cut short.
    Truncated,
    /// Its checksum or its length disagrees with its content: a byte
    /// changed on the disk or on the way.
    Corrupted,
    /// It was written by a newer build, in a checkpoint or state format
    /// that this build cannot read.
    NewerFormat,
    /// It is a run of another scene than the one asked for.
    OtherScene,
    /// The parameters asked for contradict the checkpoint's.
    Contradicts,
}

impl CheckpointFault {
    /// The fault's name (`"CheckpointTruncated"`): [`Error::name`] of the
    /// error that carries it.
    pub fn name(self) -> &'static str {
        match self {
            CheckpointFault::NotACheckpoint => "NotACheckpoint",
            CheckpointFault::Truncated => "CheckpointTruncated",
            CheckpointFault::Corrupted => "CheckpointCorrupted",
            CheckpointFault::NewerFormat => "CheckpointNewerFormat",
            CheckpointFault::OtherScene => "CheckpointOtherScene",
            CheckpointFault::Contradicts => "CheckpointContradicts",
        }
    }

    /// What the fault is, in words.
    pub fn describe(self) -> &'static str {
        match self {
            CheckpointFault::NotACheckpoint => "not a checkpoint",
            CheckpointFault::Truncated => "truncated",
            CheckpointFault::Corrupted => "corrupted",
            CheckpointFault::NewerFormat => "of a newer format",
            CheckpointFault::OtherScene => "of another scene",
            CheckpointFault::Contradicts => "contradicted by the arguments",
        }
    }
}

impl std::fmt::Display for CheckpointFault {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.describe())
    }
}

/// An [`Error::Checkpoint`] of the file `path`.
pub fn fault(path: &Path, fault: CheckpointFault, detail: impl Into<String>) -> Error {
    Error::Checkpoint {
        path: path.display().to_string(),
        fault,
        detail: detail.into(),
    }
}

/// The body of a checkpoint: the host's part and the run.
#[derive(serde::Serialize)]
struct Body<'a> {
    host: &'a serde_json::Value,
    run: &'a Simulation,
}

/// A writer that counts and checksums what passes through it.
struct Summing<W> {
    inner: W,
    crc: crc32fast::Hasher,
    bytes: u64,
}

impl<W: Write> Write for Summing<W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let n = self.inner.write(buf)?;
        self.crc.update(&buf[..n]);
        self.bytes += n as u64;
        Ok(n)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.inner.flush()
    }
}

/// Writes `sim` and `host` (what its host needs to go on, any JSON value)
/// to the checkpoint file `path`, whole. A run that
/// [`Simulation::check_savable`] refuses is refused with that error.
pub fn save(path: &Path, sim: &Simulation, host: &serde_json::Value) -> Result<()> {
    sim.check_savable()?;
    crate::files::write_whole(path, |out| {
        let mut w = Summing {
            inner: out,
            crc: crc32fast::Hasher::new(),
            bytes: 0,
        };
        writeln!(w, "meshless-impact checkpoint {CHECKPOINT_FORMAT}")?;
        // Buffered above the checksum, so that it sums large blocks.
        let mut body = std::io::BufWriter::with_capacity(1 << 16, &mut w);
        serde_json::to_writer(&mut body, &Body { host, run: sim })?;
        body.flush()?;
        drop(body);
        let (crc, bytes) = (w.crc.finalize(), w.bytes);
        write!(w.inner, "\nend crc32={crc:08x} bytes={bytes:020}\n")
    })
}

/// Reads the checkpoint file `path`: the run, restored and checked as
/// [`Simulation::deserialize_state`] checks one, and its host's value.
pub fn load(path: &Path) -> Result<(Simulation, serde_json::Value)> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    read(path, &bytes)
}

/// [`load`] of the bytes of the file `path`.
pub fn read(path: &Path, bytes: &[u8]) -> Result<(Simulation, serde_json::Value)> {
    let content = check_whole(path, bytes)?;
    let newline = content.iter().position(|&b| b == b'\n').unwrap_or(0);
    let version = std::str::from_utf8(&content[MAGIC.len()..newline])
        .ok()
        .and_then(|v| v.parse::<u32>().ok())
        .ok_or_else(|| {
            fault(
                path,
                CheckpointFault::Corrupted,
                "its first line has no format",
            )
        })?;
    if version > CHECKPOINT_FORMAT {
        return Err(fault(
            path,
            CheckpointFault::NewerFormat,
            format!(
                "it is of checkpoint format {version}, newer than this build's \
                 {CHECKPOINT_FORMAT}: continue it with the build that wrote it, or a newer one"
            ),
        ));
    }
    let mut body: serde_json::Value = serde_json::from_slice(&content[newline + 1..])
        .map_err(|e| fault(path, CheckpointFault::Corrupted, format!("its body: {e}")))?;
    let host = body
        .get_mut("host")
        .map(serde_json::Value::take)
        .unwrap_or_default();
    let run = body
        .get_mut("run")
        .map(serde_json::Value::take)
        .ok_or_else(|| fault(path, CheckpointFault::Corrupted, "it holds no run"))?;
    if let Some(f) = run.get("format").and_then(serde_json::Value::as_u64)
        && f > u64::from(crate::STATE_FORMAT)
    {
        return Err(fault(
            path,
            CheckpointFault::NewerFormat,
            format!(
                "its run is of state format {f}, newer than this build's {}: continue it with \
                 the build that wrote it, or a newer one",
                crate::STATE_FORMAT
            ),
        ));
    }
    let sim = Simulation::from_saved(run)?;
    Ok((sim, host))
}

/// The content of a checkpoint's bytes before its trailer, once the
/// trailer says that they are whole and unchanged.
fn check_whole<'a>(path: &Path, bytes: &'a [u8]) -> Result<&'a [u8]> {
    let first_line = bytes
        .iter()
        .position(|&b| b == b'\n')
        .map_or(bytes, |n| &bytes[..n]);
    let magic_ok =
        first_line.len() > MAGIC.len() && differences(&first_line[..MAGIC.len()], MAGIC) <= 2;
    if !magic_ok {
        return Err(fault(
            path,
            CheckpointFault::NotACheckpoint,
            "it does not start with `meshless-impact checkpoint` (a checkpoint is written by \
             `meshless-impact run --checkpoint FILE`, Python's `Simulation.save` or \
             `mi_sim_checkpoint_save`)",
        ));
    }
    if bytes.len() < MAGIC.len() + TRAILER.len() {
        return Err(fault(
            path,
            CheckpointFault::Truncated,
            format!("it ends after {} bytes, before its trailer", bytes.len()),
        ));
    }
    let (content, tail) = bytes.split_at(bytes.len() - TRAILER.len());
    let shape = tail
        .iter()
        .zip(TRAILER)
        .filter(|&(&b, &t)| match t {
            b'X' => !matches!(b, b'0'..=b'9' | b'a'..=b'f'),
            b'N' => !b.is_ascii_digit(),
            _ => b != t,
        })
        .count();
    // A trailer with a changed byte or two is still one; anything else at
    // the end is the middle of a file cut short.
    if shape > 2 {
        return Err(fault(
            path,
            CheckpointFault::Truncated,
            format!(
                "it ends after {} bytes, without its trailer (a write that did not finish)",
                bytes.len()
            ),
        ));
    }
    let field = |from: &[u8], to: &[u8]| -> Option<&str> {
        let text = std::str::from_utf8(tail).ok()?;
        let at = text.find(std::str::from_utf8(from).ok()?)? + from.len();
        let end = at + text[at..].find(std::str::from_utf8(to).ok()?)?;
        Some(&text[at..end])
    };
    let crc = field(b"crc32=", b" ").and_then(|h| u32::from_str_radix(h, 16).ok());
    let len = field(b"bytes=", b"\n").and_then(|d| d.parse::<u64>().ok());
    let (Some(crc), Some(len)) = (crc, len) else {
        return Err(fault(
            path,
            CheckpointFault::Corrupted,
            "its trailer is damaged",
        ));
    };
    if shape != 0 {
        return Err(fault(
            path,
            CheckpointFault::Corrupted,
            "its trailer is damaged",
        ));
    }
    if len != content.len() as u64 {
        return Err(fault(
            path,
            CheckpointFault::Corrupted,
            format!(
                "it holds {} bytes before its trailer, which says {len}",
                content.len()
            ),
        ));
    }
    let actual = crc32fast::hash(content);
    if actual != crc {
        return Err(fault(
            path,
            CheckpointFault::Corrupted,
            format!("its CRC-32 is {actual:08x}, its trailer says {crc:08x}"),
        ));
    }
    Ok(content)
}

/// The number of positions where `a` and `b` differ.
fn differences(a: &[u8], b: &[u8]) -> usize {
    a.iter().zip(b).filter(|(x, y)| x != y).count()
}

/// The parameters of `asked` that contradict `saved` (a checkpoint's
/// scene), each as `name: VALUE in the checkpoint, VALUE asked`; the
/// scene's name alone when the scenes are not the same scene.
pub fn contradictions(saved: &Scene, asked: &Scene) -> Vec<String> {
    if saved.kind() != asked.kind() {
        return vec![format!(
            "scene: `{}` in the checkpoint, `{}` asked",
            saved.kind(),
            asked.kind()
        )];
    }
    saved
        .param_specs()
        .iter()
        .zip(saved.values().iter().zip(asked.values()))
        .filter(|(_, (a, b))| a.to_bits() != b.to_bits())
        .map(|(s, (a, b))| {
            format!(
                "{}: {} in the checkpoint, {} asked",
                s.name,
                crate::error::number(*a),
                crate::error::number(*b)
            )
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A checkpoint of `noh` after five steps, in a scratch folder of its
    /// own (removed when the test passes), and its bytes.
    fn saved(test: &str) -> (crate::test_dir::TestDir, Vec<u8>) {
        let dir = crate::test_dir::TestDir::new(&format!("ckpt-{test}"));
        let path = dir.join("noh.ckpt");
        let mut scene = Scene::builtin("noh").unwrap();
        scene.set("particles_radial", 10.0).unwrap();
        let mut sim = Simulation::new(scene).unwrap();
        for _ in 0..5 {
            sim.step().unwrap();
        }
        save(&path, &sim, &serde_json::json!({"note": "unit"})).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        (dir, bytes)
    }

    #[test]
    fn every_flipped_bit_of_the_frame_and_a_sample_of_the_body_is_named() {
        let (dir, bytes) = saved("flips");
        let path = dir.join("noh.ckpt");
        let (sim, host) = read(&path, &bytes).unwrap();
        assert_eq!(host["note"], "unit");
        assert_eq!(sim.steps(), 5);
        let n = bytes.len();
        let mut at: Vec<usize> = (0..40).chain(n - 60..n).collect();
        at.extend((0..200).map(|k| 40 + (k * 7919) % (n - 100)));
        for i in at {
            for bit in 0..8 {
                let mut b = bytes.clone();
                b[i] ^= 1 << bit;
                let e = read(&path, &b).unwrap_err();
                let Error::Checkpoint { fault, .. } = &e else {
                    panic!("byte {i} bit {bit}: {e}");
                };
                // The magic word changed in three bits or more is no
                // checkpoint; one bit never does that.
                assert_eq!(
                    *fault,
                    CheckpointFault::Corrupted,
                    "byte {i} bit {bit}: {e}"
                );
            }
        }
    }

    #[test]
    fn every_cut_is_truncated() {
        let (dir, bytes) = saved("cuts");
        let path = dir.join("noh.ckpt");
        let n = bytes.len();
        for len in (MAGIC.len() + 1..n).step_by(97).chain(n - 50..n) {
            let e = read(&path, &bytes[..len]).unwrap_err();
            assert_eq!(e.name(), "CheckpointTruncated", "cut at {len} of {n}: {e}");
            assert!(e.to_string().contains("noh.ckpt"), "{e}");
        }
    }

    #[test]
    fn other_files_and_newer_formats_are_named() {
        let (dir, bytes) = saved("others");
        let path = dir.join("noh.ckpt");
        let state = Simulation::builtin("noh").unwrap().serialize_state();
        assert_eq!(read(&path, &state).unwrap_err().name(), "NotACheckpoint");
        assert_eq!(read(&path, b"").unwrap_err().name(), "NotACheckpoint");
        // Files framed whole around a body of our making.
        let frame = |format: u32, body: &serde_json::Value| {
            let mut b = format!("meshless-impact checkpoint {format}\n").into_bytes();
            serde_json::to_writer(&mut b, body).unwrap();
            let crc = crc32fast::hash(&b);
            let len = b.len();
            b.extend(format!("\nend crc32={crc:08x} bytes={len:020}\n").bytes());
            b
        };
        let (sim, _) = read(&path, &bytes).unwrap();
        let run: serde_json::Value = serde_json::from_slice(&sim.serialize_state()).unwrap();
        let body = serde_json::json!({"host": null, "run": run});
        assert_eq!(read(&path, &frame(1, &body)).unwrap().0.steps(), 5);
        let e = read(&path, &frame(2, &body)).unwrap_err();
        assert_eq!(e.name(), "CheckpointNewerFormat", "{e}");
        assert!(e.to_string().contains("checkpoint format 2"), "{e}");
        let mut newer_state = body.clone();
        newer_state["run"]["format"] = (crate::STATE_FORMAT + 1).into();
        let e = read(&path, &frame(1, &newer_state)).unwrap_err();
        assert_eq!(e.name(), "CheckpointNewerFormat", "{e}");
        let newer = format!("state format {}", crate::STATE_FORMAT + 1);
        assert!(e.to_string().contains(&newer), "{e}");
        // The frame whole around a body that is not a run's state.
        let e = read(&path, &frame(1, &serde_json::json!({"run": {}}))).unwrap_err();
        assert_eq!(e.name(), "InvalidState", "{e}");
    }

    #[test]
    fn contradictions_name_the_parameters() {
        let a = Scene::builtin("taylor").unwrap();
        let mut b = a.clone();
        assert!(contradictions(&a, &b).is_empty());
        b.set("impact_speed", 200.0).unwrap();
        let c = contradictions(&a, &b);
        assert_eq!(c.len(), 1);
        assert!(
            c[0].starts_with("impact_speed: 181 in the checkpoint, 200 asked"),
            "{c:?}"
        );
        let other = Scene::builtin("noh").unwrap();
        assert!(contradictions(&a, &other)[0].starts_with("scene: `taylor`"));
    }
}
