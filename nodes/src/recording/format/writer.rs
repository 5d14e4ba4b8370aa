//! Writing a recording, atomically or live.

use super::reader::non_finite_word;
use super::wav::{self, DATA_SIZE_AT, FACT_FRAMES_AT, HEADER_LEN, RIFF_SIZE_AT, SAMPLE_BYTES};
use super::{sidecar_json, RecordingError, RecordingMeta, RecordingPaths};
use evflow_engine::atomic_file::{create_temporary, write_atomically};
use std::fs::{File, OpenOptions};
use std::io::{Seek, SeekFrom, Write};
use std::path::Path;

/// Frames buffered in memory by default before they are written out.
const DEFAULT_BUFFER_FRAMES: usize = 8192;

/// What a finished writer wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct Written {
    /// The final files.
    pub paths: RecordingPaths,
    /// Frames written.
    pub frames: u64,
    /// Channels per frame.
    pub channels: usize,
    /// Sample rate in Hz.
    pub rate: f64,
}

/// Writes a recording frame by frame.
///
/// Samples collect in a buffer (sized by [`RecordingWriter::reserve_frames`],
/// never grown by a write); whenever the buffer is written out to the WAV —
/// when it is full, and at every [`RecordingWriter::flush`] — the RIFF, `fact`
/// and `data` size fields are patched, so the WAV on disk is always a
/// complete, readable file of the frames written out so far.
///
/// Two modes:
/// * [`RecordingWriter::create`] (offline runs) fills `NAME.wav.tmp` and
///   `NAME.json.tmp` and renames them to the final names only in
///   [`RecordingWriter::finish`]. Dropped without `finish` (an error, an
///   interrupted run) it removes the temporary files: a failed run leaves
///   nothing and never replaces an existing recording.
/// * [`RecordingWriter::create_live`] (session recording) writes the final
///   names directly and also rewrites the sidecar's frame count at every
///   `flush`, so a process killed after a flush leaves a recording that
///   opens with every flushed frame. Dropped without `finish`, it flushes.
#[derive(Debug)]
pub struct RecordingWriter {
    file: Option<File>,
    /// The temporary sidecar, held open from the start (offline only).
    json_file: Option<File>,
    /// Where the bytes go now (temporary or final).
    now: RecordingPaths,
    /// The final names.
    target: RecordingPaths,
    live: bool,
    meta: RecordingMeta,
    header_rate: u32,
    block: usize,
    max_frames: u64,
    /// Frames in the WAV on disk (header patched to this count).
    on_disk: u64,
    /// Frames accepted (on disk + buffered).
    accepted: u64,
    buf: Vec<u8>,
    done: bool,
}

impl RecordingWriter {
    /// Starts an atomically committed recording at `path` (`NAME.wav`,
    /// `NAME.json` or `NAME`): writes to `NAME.wav.tmp` / `NAME.json.tmp`
    /// until [`RecordingWriter::finish`] renames them. Both are new files,
    /// never a file or link already at those names (another name is taken
    /// then: [`evflow_engine::atomic_file::create_temporary`]). A missing
    /// folder on the way is created.
    pub fn create(path: &Path, meta: RecordingMeta) -> Result<Self, RecordingError> {
        Self::start(RecordingPaths::new(path), meta, false)
    }

    /// Starts a live recording at `path`, written directly to the final
    /// names and readable after every [`RecordingWriter::flush`]. Refuses to
    /// overwrite an existing `NAME.wav` or `NAME.json`
    /// ([`RecordingError::Exists`]).
    pub fn create_live(path: &Path, meta: RecordingMeta) -> Result<Self, RecordingError> {
        let target = RecordingPaths::new(path);
        for p in [&target.wav, &target.json] {
            if p.exists() {
                return Err(RecordingError::Exists { path: p.clone() });
            }
        }
        Self::start(target, meta, true)
    }

    fn start(target: RecordingPaths, meta: RecordingMeta, live: bool) -> Result<Self, RecordingError> {
        meta.check().map_err(|message| RecordingError::InvalidMeta { path: target.wav.clone(), message })?;
        let channels = meta.channels.len();
        // A recording may name a folder of its own (`grid/u-felt-60g-3cms`):
        // create it, as a shell's `mkdir -p` would.
        if let Some(dir) = target.wav.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(|e| RecordingError::io(dir, e))?;
        }
        // Live: the final name, refused if taken. Offline: two new
        // temporaries, never a file or a link planted at their names.
        let (file, json_file, now) = if live {
            let file =
                OpenOptions::new().read(true).write(true).create_new(true).open(&target.wav).map_err(|e| {
                    match e.kind() {
                        std::io::ErrorKind::AlreadyExists => RecordingError::Exists { path: target.wav.clone() },
                        _ => RecordingError::io(&target.wav, e),
                    }
                })?;
            (file, None, target.clone())
        } else {
            let (file, wav) = create_temporary(&target.wav).map_err(|e| RecordingError::io(&target.wav, e))?;
            let (json_file, json) = match create_temporary(&target.json) {
                Ok(made) => made,
                Err(e) => {
                    drop(file);
                    let _ = std::fs::remove_file(&wav);
                    return Err(RecordingError::io(&target.json, e));
                }
            };
            (file, Some(json_file), RecordingPaths { wav, json })
        };
        let mut w = RecordingWriter {
            file: Some(file),
            json_file,
            header_rate: wav::header_rate(meta.rate),
            block: channels * SAMPLE_BYTES,
            max_frames: wav::max_frames(channels),
            now,
            target,
            live,
            meta,
            on_disk: 0,
            accepted: 0,
            buf: Vec::new(),
            done: false,
        };
        w.reserve_frames(DEFAULT_BUFFER_FRAMES);
        let header = wav::header(channels as u16, w.header_rate, 0);
        let path = w.now.wav.clone();
        let started = w.file().and_then(|f| f.write_all(&header).map_err(|e| RecordingError::io(&path, e)));
        match started.and_then(|()| w.write_sidecar()) {
            Ok(()) => Ok(w),
            Err(e) => {
                // Remove what was created, in either mode.
                w.discard();
                Err(e)
            }
        }
    }

    /// Makes the buffer hold at least `frames` frames, so writes of up to
    /// that many frames never allocate. Call before a real-time loop.
    pub fn reserve_frames(&mut self, frames: usize) {
        let bytes = frames.max(1).saturating_mul(self.block);
        if self.buf.capacity() < bytes {
            self.buf.reserve_exact(bytes - self.buf.len());
        }
    }

    /// The recording's metadata.
    pub fn meta(&self) -> &RecordingMeta {
        &self.meta
    }

    /// The final files.
    pub fn paths(&self) -> &RecordingPaths {
        &self.target
    }

    /// Frames accepted so far.
    pub fn frames(&self) -> u64 {
        self.accepted
    }

    /// Appends frames given interleaved (`frame0ch0, frame0ch1, …`). Refuses
    /// NaN and infinite samples ([`RecordingError::NonFinite`], naming the
    /// channel and frame), leaving the recording as it was. Allocation-free;
    /// writes the buffer out (blocking I/O) only when it is full.
    pub fn write_interleaved(&mut self, samples: &[f64]) -> Result<(), RecordingError> {
        let ch = self.meta.channels.len();
        let frames = samples.len() / ch;
        if frames * ch != samples.len() {
            return Err(RecordingError::FrameShape {
                path: self.target.wav.clone(),
                samples: samples.len(),
                channels: ch,
            });
        }
        let frames = frames as u64;
        if self.accepted + frames > self.max_frames {
            return Err(RecordingError::TooLong { path: self.target.wav.clone(), max_frames: self.max_frames });
        }
        if let Some(k) = samples.iter().position(|x| !x.is_finite()) {
            let x = samples[k];
            return Err(RecordingError::NonFinite {
                path: self.target.wav.clone(),
                channel: self.meta.channels[k % ch].name.clone(),
                frame: self.accepted + (k / ch) as u64,
                what: non_finite_word(x),
            });
        }
        let per_chunk = (self.buf.capacity() / self.block).max(1) * ch;
        for chunk in samples.chunks(per_chunk) {
            if self.buf.len() + chunk.len() * SAMPLE_BYTES > self.buf.capacity() {
                self.write_out()?;
            }
            for x in chunk {
                self.buf.extend_from_slice(&x.to_le_bytes());
            }
        }
        self.accepted += frames;
        Ok(())
    }

    /// Appends one frame (one sample per channel).
    pub fn write_frame(&mut self, frame: &[f64]) -> Result<(), RecordingError> {
        if frame.len() != self.meta.channels.len() {
            return Err(RecordingError::FrameShape {
                path: self.target.wav.clone(),
                samples: frame.len(),
                channels: self.meta.channels.len(),
            });
        }
        self.write_interleaved(frame)
    }

    /// Writes the buffered frames out and patches the WAV's size fields; a
    /// live writer also rewrites the sidecar with the new frame count. After
    /// it returns, a process killed at any point leaves a live recording
    /// that opens with all the frames written so far.
    pub fn flush(&mut self) -> Result<(), RecordingError> {
        self.write_out()?;
        if self.live {
            self.write_sidecar()?;
        }
        Ok(())
    }

    /// Back to zero frames (a run's reset): the WAV is cut back to its
    /// header and the buffer emptied.
    pub fn restart(&mut self) -> Result<(), RecordingError> {
        self.buf.clear();
        self.accepted = 0;
        self.on_disk = 0;
        let path = self.now.wav.clone();
        self.file()?.set_len(HEADER_LEN).map_err(|e| RecordingError::io(&path, e))?;
        self.patch_sizes()?;
        if self.live {
            self.write_sidecar()?;
        }
        Ok(())
    }

    /// Writes everything out, syncs it to disk, writes the final sidecar
    /// and (for [`RecordingWriter::create`]) renames the temporary files to
    /// the final names: the WAV first, then the sidecar.
    pub fn finish(mut self) -> Result<Written, RecordingError> {
        self.write_out()?;
        let path = self.now.wav.clone();
        self.file()?.sync_all().map_err(|e| RecordingError::io(&path, e))?;
        self.write_sidecar()?;
        self.json_file = None;
        if !self.live {
            for (from, to) in [(&self.now.wav, &self.target.wav), (&self.now.json, &self.target.json)] {
                std::fs::rename(from, to).map_err(|e| RecordingError::io(to, e))?;
            }
        }
        self.done = true;
        self.file = None;
        Ok(Written {
            paths: self.target.clone(),
            frames: self.on_disk,
            channels: self.meta.channels.len(),
            rate: self.meta.rate,
        })
    }

    /// Closes and removes the files being written; the writer is done.
    fn discard(&mut self) {
        self.done = true;
        self.file = None; // close before removing (required on Windows)
        self.json_file = None;
        let _ = std::fs::remove_file(&self.now.wav);
        let _ = std::fs::remove_file(&self.now.json);
    }

    fn file(&mut self) -> Result<&mut File, RecordingError> {
        let path = &self.now.wav;
        self.file.as_mut().ok_or_else(|| RecordingError::io(path, std::io::Error::other("writer already closed")))
    }

    /// Appends the buffer to the WAV and patches the size fields.
    fn write_out(&mut self) -> Result<(), RecordingError> {
        if self.buf.is_empty() {
            return Ok(());
        }
        let end = HEADER_LEN + self.on_disk * self.block as u64;
        let path = self.now.wav.clone();
        let io = |e| RecordingError::io(&path, e);
        let file = self.file.as_mut().ok_or_else(|| io(std::io::Error::other("writer already closed")))?;
        file.seek(SeekFrom::Start(end)).map_err(io)?;
        file.write_all(&self.buf).map_err(io)?;
        self.on_disk += (self.buf.len() / self.block) as u64;
        self.buf.clear();
        self.patch_sizes()
    }

    /// Sets the RIFF, `fact` and `data` fields to the frames on disk.
    fn patch_sizes(&mut self) -> Result<(), RecordingError> {
        let data = self.on_disk * self.block as u64;
        let fields =
            [(RIFF_SIZE_AT, wav::riff_size(data)), (FACT_FRAMES_AT, self.on_disk as u32), (DATA_SIZE_AT, data as u32)];
        let path = self.now.wav.clone();
        let io = |e| RecordingError::io(&path, e);
        let file = self.file.as_mut().ok_or_else(|| io(std::io::Error::other("writer already closed")))?;
        for (at, v) in fields {
            file.seek(SeekFrom::Start(at)).map_err(io)?;
            file.write_all(&v.to_le_bytes()).map_err(io)?;
        }
        file.flush().map_err(io)
    }

    /// Writes the sidecar for the frames on disk: through `NAME.json.tmp`
    /// and a rename when live (so a reader never sees half a sidecar),
    /// into the temporary sidecar created at the start otherwise (rewritten
    /// through its open handle). Either way never through a link at a name.
    fn write_sidecar(&mut self) -> Result<(), RecordingError> {
        let text = sidecar_json(&self.meta, self.on_disk);
        if self.live {
            return write_atomically(&self.target.json, text).map_err(|e| RecordingError::io(&self.target.json, e));
        }
        let path = &self.now.json;
        let io = |e| RecordingError::io(path, e);
        let f = self.json_file.as_mut().ok_or_else(|| io(std::io::Error::other("writer already closed")))?;
        f.set_len(0).map_err(io)?;
        f.seek(SeekFrom::Start(0)).map_err(io)?;
        f.write_all(text.as_bytes()).map_err(io)?;
        f.sync_all().map_err(io)
    }
}

impl Drop for RecordingWriter {
    fn drop(&mut self) {
        if self.done {
            return;
        }
        if self.live {
            // Keep what was recorded: a session cut short is still data.
            let _ = self.flush();
        } else {
            self.discard();
        }
    }
}
