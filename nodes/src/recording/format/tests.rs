//! Tests of the recording format: round trips, crash behaviour, refusals.

use super::wav;
use super::*;
use evflow_engine::NodeError;
use std::fs;
use std::path::Path;

fn meta2() -> RecordingMeta {
    let mut m = RecordingMeta::new(1000.0, vec![Channel::new("force", "N"), Channel::new("pos", "m")]);
    m.condition.load_g = Some(85.0);
    m.condition.velocity_cm_s = Some(4.0);
    m.condition.material = Some("felt".into());
    m.condition.gain = Some(1.0);
    m.condition.extra.insert("trial".into(), serde_json::json!(3));
    m.source = "unit test".into();
    m
}

/// Awkward values: extremes, subnormals, negative zero, thirds.
fn column(n: usize, seed: f64) -> Vec<f64> {
    let specials = [f64::MAX, -f64::MAX, f64::MIN_POSITIVE, 5e-324, -0.0, 0.0, 1.0 / 3.0];
    (0..n)
        .map(|i| if i < specials.len() { specials[i] * seed.signum() } else { ((i as f64) * seed).sin() * 1e3 })
        .collect()
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

/// Writes a two-channel recording of `n` frames at `dir/name` (committed).
fn write2(dir: &Path, name: &str, n: usize) -> (Vec<f64>, Vec<f64>) {
    let (a, b) = (column(n, 0.01), column(n, -0.7));
    let mut w = RecordingWriter::create(&dir.join(name), meta2()).unwrap();
    w.reserve_frames(100); // small buffer: many write-outs
    let inter: Vec<f64> = a.iter().zip(&b).flat_map(|(x, y)| [*x, *y]).collect();
    for chunk in inter.chunks(2 * 37) {
        w.write_interleaved(chunk).unwrap();
    }
    w.finish().unwrap();
    (a, b)
}

fn msg(r: Result<Recording, RecordingError>) -> String {
    r.unwrap_err().to_string()
}

#[test]
fn round_trip_is_bit_exact_with_all_metadata() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = write2(dir.path(), "rec.wav", 2500);
    let rec = Recording::open(&dir.path().join("rec")).unwrap();
    rec.require_complete().unwrap();
    assert_eq!(rec.frames(), 2500);
    assert_eq!(bits(rec.channel("force").unwrap()), bits(&a));
    assert_eq!(bits(rec.channel("pos").unwrap()), bits(&b));
    assert_eq!(rec.meta(), &meta2());
    assert_eq!(rec.loaded().collect::<Vec<_>>(), ["force", "pos"]);
    // The file is exactly header + samples.
    assert_eq!(fs::metadata(dir.path().join("rec.wav")).unwrap().len(), 58 + 2500 * 16);
    // Only the asked channels are loaded.
    let only = Recording::open_channels(&dir.path().join("rec.json"), &["pos"]).unwrap();
    assert_eq!(only.channel("force"), None);
    assert_eq!(bits(only.channel("pos").unwrap()), bits(&b));
}

#[test]
fn sidecar_text_is_the_documented_shape() {
    let dir = tempfile::tempdir().unwrap();
    write2(dir.path(), "rec", 3);
    let v: serde_json::Value = serde_json::from_str(&fs::read_to_string(dir.path().join("rec.json")).unwrap()).unwrap();
    let want = serde_json::json!({
        "format": "evflow-recording", "version": 1, "rate": 1000.0, "frames": 3,
        "channels": [{"name": "force", "unit": "N"}, {"name": "pos", "unit": "m"}],
        "condition": {"load_g": 85.0, "velocity_cm_s": 4.0, "material": "felt", "gain": 1.0, "trial": 3},
        "source": "unit test"
    });
    assert_eq!(v, want);
}

/// Reference: the bytes scipy 1.17.1 `scipy.io.wavfile.write(f, 1000, x)`
/// writes for the float64 array `x = [[0.5, -2.0], [1e-300, 3.25], [-0.0, 7.0]]`
/// (an independent implementation of the same layout).
#[test]
fn header_matches_scipy_byte_for_byte() {
    let scipy = "524946466200000057415645666d74201200000003000200e8030000803e00001000400000006661637404000000\
                 030000006461746130000000000000000000e03f00000000000000c059f3f8c21f6ea5010000000000000a40000000\
                 00000000800000000000001c40";
    let mut ours = wav::header(2, 1000, 3).to_vec();
    for x in [0.5f64, -2.0, 1e-300, 3.25, -0.0, 7.0] {
        ours.extend_from_slice(&x.to_le_bytes());
    }
    let hex: String = ours.iter().map(|b| format!("{b:02x}")).collect();
    assert_eq!(hex, scipy.replace(' ', ""));
}

#[test]
fn header_rate_is_rounded_and_sidecar_keeps_the_exact_rate() {
    let dir = tempfile::tempdir().unwrap();
    let mut w =
        RecordingWriter::create(&dir.path().join("r"), RecordingMeta::new(999.6, vec![Channel::new("x", "")])).unwrap();
    w.write_frame(&[1.0]).unwrap();
    w.finish().unwrap();
    let bytes = fs::read(dir.path().join("r.wav")).unwrap();
    assert_eq!(u32::from_le_bytes(bytes[24..28].try_into().unwrap()), 1000);
    assert_eq!(Recording::open(&dir.path().join("r")).unwrap().rate(), 999.6);
    assert_eq!(wav::header_rate(0.2), 1, "a rate below 0.5 Hz still gets a valid header");
    assert_eq!(wav::header_rate(1000.5), 1001, "half away from zero, as documented");
    // The frame limit is the largest count whose RIFF size fits in 32 bits.
    for ch in [1usize, 2, 3, 16] {
        let riff = |frames: u64| frames * (ch as u64) * 8 + 50;
        assert!(riff(wav::max_frames(ch)) <= u64::from(u32::MAX));
        assert!(riff(wav::max_frames(ch) + 1) > u64::from(u32::MAX));
    }
}

#[test]
fn committed_writer_uses_temporary_files_until_finish() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("c.wav");
    let mut w = RecordingWriter::create(&p, meta2()).unwrap();
    w.write_frame(&[1.0, 2.0]).unwrap();
    w.flush().unwrap();
    assert!(!dir.path().join("c.wav").exists() && !dir.path().join("c.json").exists());
    assert!(dir.path().join("c.wav.tmp").exists() && dir.path().join("c.json.tmp").exists());
    let done = w.finish().unwrap();
    assert_eq!(done.frames, 1);
    assert!(!dir.path().join("c.wav.tmp").exists() && !dir.path().join("c.json.tmp").exists());
    assert_eq!(Recording::open(&p).unwrap().channel("pos").unwrap(), &[2.0]);
}

#[cfg(unix)]
#[test]
fn links_planted_at_the_temporary_names_are_never_written_through() {
    // Issue 37, point 2: `ln -s /elsewhere/X.wav out/c.wav.tmp` before a run
    // wrote the recording through the link and renamed the link into place.
    let dir = tempfile::tempdir().unwrap();
    let (out, elsewhere) = (dir.path().join("out"), dir.path().join("elsewhere"));
    fs::create_dir_all(&out).unwrap();
    fs::create_dir_all(&elsewhere).unwrap();
    for ext in ["wav", "json"] {
        fs::write(elsewhere.join(ext), "precious").unwrap();
        std::os::unix::fs::symlink(elsewhere.join(ext), out.join(format!("c.{ext}.tmp"))).unwrap();
        // The live writer's sidecar goes through `NAME.json.tmp` too.
        std::os::unix::fs::symlink(elsewhere.join(ext), out.join(format!("l.{ext}.tmp"))).unwrap();
    }
    let mut w = RecordingWriter::create(&out.join("c.wav"), meta2()).unwrap();
    w.write_frame(&[1.0, 2.0]).unwrap();
    w.finish().unwrap();
    let mut l = RecordingWriter::create_live(&out.join("l"), meta2()).unwrap();
    l.write_frame(&[3.0, 4.0]).unwrap();
    l.flush().unwrap();
    l.finish().unwrap();
    for ext in ["wav", "json"] {
        assert_eq!(fs::read_to_string(elsewhere.join(ext)).unwrap(), "precious", "written through the .{ext}.tmp link");
        for name in ["c", "l"] {
            let m = fs::symlink_metadata(out.join(format!("{name}.{ext}"))).unwrap();
            assert!(m.file_type().is_file(), "{name}.{ext} is not a regular file");
        }
    }
    assert_eq!(Recording::open(&out.join("c.wav")).unwrap().channel("pos").unwrap(), &[2.0]);
    assert_eq!(Recording::open(&out.join("l.wav")).unwrap().channel("pos").unwrap(), &[4.0]);
}

#[test]
fn dropped_committed_writer_removes_its_files_and_keeps_the_old_recording() {
    let dir = tempfile::tempdir().unwrap();
    write2(dir.path(), "keep", 10);
    let before = (fs::read(dir.path().join("keep.wav")).unwrap(), fs::read(dir.path().join("keep.json")).unwrap());
    {
        let mut w = RecordingWriter::create(&dir.path().join("keep"), meta2()).unwrap();
        for _ in 0..1000 {
            w.write_frame(&[9.0, 9.0]).unwrap();
        }
        w.flush().unwrap();
    } // dropped without finish
    let mut names: Vec<_> = fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
    names.sort();
    assert_eq!(names, ["keep.json", "keep.wav"]);
    assert_eq!(fs::read(dir.path().join("keep.wav")).unwrap(), before.0);
    assert_eq!(fs::read(dir.path().join("keep.json")).unwrap(), before.1);
}

#[test]
fn live_writer_leaves_a_readable_file_when_killed_after_a_flush() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("live.wav");
    let mut w = RecordingWriter::create_live(&p, meta2()).unwrap();
    // Before any frame: a valid, empty recording.
    assert_eq!(Recording::open(&p).unwrap().frames(), 0);
    for i in 0..500 {
        w.write_frame(&[i as f64, -(i as f64)]).unwrap();
    }
    w.flush().unwrap();
    w.write_frame(&[1e9, 1e9]).unwrap(); // buffered, never flushed
    std::mem::forget(w); // the process dies: no drop, no finish
    let rec = Recording::open(&p).unwrap();
    rec.require_complete().unwrap();
    assert_eq!(rec.frames(), 500);
    assert_eq!(rec.channel("pos").unwrap()[499], -499.0);

    // A kill in the middle of a write-out leaves bytes past the header's
    // claim: they are ignored (half a frame here).
    let mut bytes = fs::read(&p).unwrap();
    bytes.extend_from_slice(&[0xAB; 12]);
    fs::write(&p, &bytes).unwrap();
    let rec = Recording::open(&p).unwrap();
    assert_eq!((rec.frames(), rec.shortfall()), (500, None));

    // Killed between patching the WAV and rewriting the sidecar: the
    // sidecar's count lags; the WAV's frames are all used.
    let json = dir.path().join("live.json");
    let text = fs::read_to_string(&json).unwrap().replace("\"frames\": 500", "\"frames\": 200");
    fs::write(&json, text).unwrap();
    assert_eq!(Recording::open(&p).unwrap().frames(), 500);
}

#[test]
fn live_writer_finishes_in_place_flushes_on_drop_and_never_overwrites() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("s");
    let mut w = RecordingWriter::create_live(&p, meta2()).unwrap();
    w.write_frame(&[1.0, 2.0]).unwrap();
    drop(w); // e.g. the session stopped on an error
    assert_eq!(Recording::open(&p).unwrap().frames(), 1);
    let e = RecordingWriter::create_live(&p, meta2()).unwrap_err();
    assert!(matches!(e, RecordingError::Exists { .. }), "{e}");
    assert!(e.to_string().contains("never overwrites"));

    let q = dir.path().join("t");
    let mut w = RecordingWriter::create_live(&q, meta2()).unwrap();
    w.write_interleaved(&[1.0, 2.0, 3.0, 4.0]).unwrap();
    assert_eq!(w.finish().unwrap().frames, 2);
    let rec = Recording::open(&q).unwrap();
    assert_eq!((rec.frames(), rec.channel("force").unwrap()), (2, &[1.0, 3.0][..]));
    let leftovers =
        fs::read_dir(dir.path()).unwrap().filter(|e| e.as_ref().unwrap().path().to_string_lossy().ends_with(".tmp"));
    assert_eq!(leftovers.count(), 0);
}

#[test]
fn restart_returns_to_zero_frames() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("r");
    let mut w = RecordingWriter::create(&p, meta2()).unwrap();
    w.reserve_frames(10);
    for _ in 0..95 {
        w.write_frame(&[5.0, 5.0]).unwrap();
    }
    w.restart().unwrap();
    w.write_frame(&[1.0, 2.0]).unwrap();
    w.finish().unwrap();
    let rec = Recording::open(&p).unwrap();
    assert_eq!(rec.frames(), 1);
    assert_eq!(fs::metadata(dir.path().join("r.wav")).unwrap().len(), 58 + 16);
}

#[test]
fn truncated_file_is_read_up_to_its_last_whole_frame() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = write2(dir.path(), "cut", 1000);
    let p = dir.path().join("cut.wav");
    let bytes = fs::read(&p).unwrap();
    fs::write(&p, &bytes[..58 + 600 * 16 + 9]).unwrap(); // 600 frames and a half
    let rec = Recording::open(&p).unwrap();
    assert_eq!(rec.frames(), 600);
    assert_eq!(rec.shortfall(), Some(Shortfall { claimed: 1000, present: 600 }));
    assert_eq!(bits(rec.channel("force").unwrap()), bits(&a[..600]));
    assert_eq!(bits(rec.channel("pos").unwrap()), bits(&b[..600]));
    let e = rec.require_complete().unwrap_err().to_string();
    assert!(e.ends_with("cut.wav: truncated: 1000 frames expected but the file holds 600 (400 missing)"), "{e}");

    // The sidecar claims more than the header (a stale rename): also a shortfall.
    fs::write(&p, &bytes).unwrap();
    let json = dir.path().join("cut.json");
    fs::write(&json, fs::read_to_string(&json).unwrap().replace("\"frames\": 1000", "\"frames\": 1200")).unwrap();
    assert_eq!(Recording::open(&p).unwrap().shortfall(), Some(Shortfall { claimed: 1200, present: 1000 }));
    assert_eq!(Recording::open(&p).unwrap().sidecar_frames(), 1200);
    // Claiming fewer is no shortfall (a live writer killed before it rewrote
    // its sidecar), but what the sidecar says is there to see.
    fs::write(&json, fs::read_to_string(&json).unwrap().replace("\"frames\": 1200", "\"frames\": 999")).unwrap();
    let r = Recording::open(&p).unwrap();
    assert_eq!((r.frames(), r.shortfall(), r.sidecar_frames()), (1000, None, 999));

    // Cut inside the header: not a WAV any more.
    fs::write(&p, &bytes[..30]).unwrap();
    let e = msg(Recording::open(&p));
    assert!(e.contains("cut.wav: not a readable WAV file: `fmt ` chunk shorter than 16 bytes"), "{e}");
}

/// Overwrites sample (frame, channel) of a 2-channel recording's WAV.
fn poke(p: &Path, frame: usize, ch: usize, x: f64) {
    let mut bytes = fs::read(p).unwrap();
    let at = 58 + (frame * 2 + ch) * 8;
    bytes[at..at + 8].copy_from_slice(&x.to_le_bytes());
    fs::write(p, bytes).unwrap();
}

#[test]
fn nan_and_inf_samples_are_refused_naming_channel_and_frame() {
    let dir = tempfile::tempdir().unwrap();
    write2(dir.path(), "force", 2000);
    let p = dir.path().join("force.wav");
    poke(&p, 1203, 0, f64::NAN);
    let e = Recording::open(&p).unwrap_err();
    assert!(e.to_string().ends_with("force.wav: channel `force` frame 1203 is NaN"), "{e}");
    assert!(matches!(NodeError::from(e), NodeError::Data(m) if m.contains("frame 1203 is NaN")));
    poke(&p, 1203, 0, 0.0);
    poke(&p, 7, 1, f64::NEG_INFINITY);
    assert!(msg(Recording::open(&p)).ends_with("channel `pos` frame 7 is -Inf"));
    // A channel that is not loaded is not checked.
    assert!(Recording::open_channels(&p, &["force"]).is_ok());
}

#[test]
fn missing_files_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    write2(dir.path(), "r", 5);
    let e = msg(Recording::open(&dir.path().join("nothing.wav")));
    assert!(e.contains("nothing.wav: no such recording (neither it nor") && e.contains("nothing.json"), "{e}");
    fs::remove_file(dir.path().join("r.json")).unwrap();
    let e = msg(Recording::open(&dir.path().join("r.wav")));
    assert!(e.contains("r.json: sidecar missing"), "{e}");
    write2(dir.path(), "s", 5);
    fs::remove_file(dir.path().join("s.wav")).unwrap();
    let e = msg(Recording::open(&dir.path().join("s.json")));
    assert!(e.contains("s.wav: missing, although its sidecar") && e.contains("s.json exists"), "{e}");
    // Converted for nodes: a file error naming the file.
    let e = Recording::open(&dir.path().join("s.json")).unwrap_err();
    match NodeError::from(e) {
        NodeError::File { path, message } => {
            assert!(path.ends_with("s.wav"));
            assert!(message.starts_with("missing, although"), "{message}");
        }
        other => panic!("{other:?}"),
    }
}

/// Replaces the sidecar of `dir/r` and returns the error of opening it.
fn with_sidecar(dir: &Path, text: &str) -> String {
    fs::write(dir.join("r.json"), text).unwrap();
    msg(Recording::open(&dir.join("r")))
}

#[test]
fn bad_sidecars_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    write2(dir.path(), "r", 5);
    let good = fs::read_to_string(dir.path().join("r.json")).unwrap();
    let d = dir.path();

    let e = with_sidecar(d, "{\"format\": \"evflow-recording\", ");
    assert!(e.contains("r.json: sidecar is not valid JSON"), "{e}");
    let e = with_sidecar(d, &good.replace("evflow-recording", "something-else"));
    assert!(e.contains("r.json: `format` is `\"something-else\"`, not \"evflow-recording\""), "{e}");
    let e = with_sidecar(d, "{\"rate\": 1000}");
    assert!(e.contains("`format` is missing"), "{e}");
    let e = with_sidecar(d, &good.replace("\"version\": 1", "\"version\": 2"));
    assert!(
        e.contains("r.json: recording format version 2 is newer than this evflow reads (version 1); update evflow"),
        "{e}"
    );
    let e = with_sidecar(d, &good.replace("\"version\": 1", "\"version\": 0"));
    assert!(e.contains("`version` is `0`"), "{e}");
    let e = with_sidecar(d, &good.replace("\"rate\": 1000.0", "\"rate\": -5.0"));
    assert!(e.contains("r.json: `rate` is -5, not a positive number of Hz"), "{e}");
    let e = with_sidecar(d, &good.replace("\"pos\"", "\"force\""));
    assert!(e.contains("channel `force` is listed twice"), "{e}");
    let e = with_sidecar(d, &good.replace("\"frames\": 5", "\"frames\": -1"));
    assert!(e.contains("r.json: invalid sidecar:"), "{e}");
    let e = with_sidecar(d, "[1, 2]");
    assert!(e.contains("not a JSON object"), "{e}");
}

#[test]
fn wav_and_sidecar_must_agree() {
    let dir = tempfile::tempdir().unwrap();
    write2(dir.path(), "r", 5);
    let good = fs::read_to_string(dir.path().join("r.json")).unwrap();
    let one = good.replace(",\n    {\n      \"name\": \"pos\",\n      \"unit\": \"m\"\n    }", "");
    assert_ne!(one, good, "edit the sidecar's second channel out");
    let e = with_sidecar(dir.path(), &one);
    assert!(e.contains("r.wav: holds 2 channel(s) but its sidecar") && e.contains("r.json lists 1"), "{e}");
    let e = with_sidecar(dir.path(), &good.replace("\"rate\": 1000.0", "\"rate\": 2000.0"));
    assert!(e.contains("r.wav: header rate 1000 Hz disagrees with its sidecar's rate 2000 Hz"), "{e}");
}

/// A WAV with a hand-made `fmt ` body and `frames` zero-filled frames.
fn hand_wav(fmt: &[u8], extra_chunk: bool, data: &[u8]) -> Vec<u8> {
    let mut b = b"RIFF\0\0\0\0WAVE".to_vec();
    b.extend_from_slice(b"fmt ");
    b.extend_from_slice(&(fmt.len() as u32).to_le_bytes());
    b.extend_from_slice(fmt);
    if extra_chunk {
        b.extend_from_slice(b"LIST\x03\0\0\0abc\0"); // odd size, padded
    }
    b.extend_from_slice(b"data");
    b.extend_from_slice(&(data.len() as u32).to_le_bytes());
    b.extend_from_slice(data);
    let riff = (b.len() - 8) as u32;
    b[4..8].copy_from_slice(&riff.to_le_bytes());
    b
}

fn fmt_body(tag: u16, channels: u16, rate: u32, bits: u16) -> Vec<u8> {
    let align = channels * bits / 8;
    let mut f = Vec::new();
    f.extend_from_slice(&tag.to_le_bytes());
    f.extend_from_slice(&channels.to_le_bytes());
    f.extend_from_slice(&rate.to_le_bytes());
    f.extend_from_slice(&(rate * u32::from(align)).to_le_bytes());
    f.extend_from_slice(&align.to_le_bytes());
    f.extend_from_slice(&bits.to_le_bytes());
    f
}

#[test]
fn other_sample_types_are_refused_and_extensible_float64_accepted() {
    let dir = tempfile::tempdir().unwrap();
    write2(dir.path(), "r", 5);
    let wav = dir.path().join("r.wav");
    let open = || msg(Recording::open(&wav));

    fs::write(&wav, hand_wav(&fmt_body(1, 2, 1000, 16), false, &[0; 20])).unwrap();
    let e = open();
    assert!(e.contains("r.wav: samples are 16-bit integers (PCM, format 1); evflow recordings hold 64-bit"), "{e}");
    fs::write(&wav, hand_wav(&fmt_body(3, 2, 1000, 32), false, &[0; 40])).unwrap();
    assert!(open().contains("samples are 32-bit floats (format 3)"));
    fs::write(&wav, b"OggS not a wav at all").unwrap();
    assert!(open().contains("not a readable WAV file: does not start with `RIFF`"));

    // WAVE_FORMAT_EXTENSIBLE with the IEEE-float subformat, and a chunk
    // before `data`: read.
    let mut ext = fmt_body(0xFFFE, 2, 1000, 64);
    ext.extend_from_slice(&22u16.to_le_bytes()); // cbSize
    ext.extend_from_slice(&64u16.to_le_bytes()); // valid bits
    ext.extend_from_slice(&3u32.to_le_bytes()); // channel mask
    ext.extend_from_slice(&[3, 0, 0, 0, 0, 0, 0x10, 0, 0x80, 0, 0, 0xAA, 0, 0x38, 0x9B, 0x71]);
    let mut data = Vec::new();
    for x in [1.5f64, -2.5, 3.5, -4.5] {
        data.extend_from_slice(&x.to_le_bytes());
    }
    fs::write(&wav, hand_wav(&ext, true, &data)).unwrap();
    let json = dir.path().join("r.json");
    fs::write(&json, fs::read_to_string(&json).unwrap().replace("\"frames\": 5", "\"frames\": 2")).unwrap();
    let rec = Recording::open(&wav).unwrap();
    assert_eq!(rec.channel("pos").unwrap(), &[-2.5, -4.5]);
    rec.require_complete().unwrap();
    // The same with the PCM subformat is refused.
    let mut pcm = ext.clone();
    pcm[24] = 1;
    fs::write(&wav, hand_wav(&pcm, false, &data)).unwrap();
    assert!(open().contains("samples are 64-bit integers (PCM, format 1)"), "{}", open());
}

#[test]
fn writer_refuses_bad_samples_and_metadata_without_losing_frames() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("w");
    let mut w = RecordingWriter::create(&p, meta2()).unwrap();
    w.write_interleaved(&[1.0, 2.0, 3.0, 4.0]).unwrap();
    let e = w.write_interleaved(&[5.0, 6.0, 7.0, f64::NAN]).unwrap_err().to_string();
    assert!(e.ends_with("w.wav: channel `pos` frame 3 is NaN"), "{e}");
    let e = w.write_interleaved(&[1.0, 2.0, 3.0]).unwrap_err().to_string();
    assert!(e.contains("3 samples do not make whole frames of 2 channels"), "{e}");
    assert!(w.write_frame(&[1.0]).is_err());
    assert_eq!(w.frames(), 2);
    w.write_frame(&[9.0, 10.0]).unwrap();
    w.finish().unwrap();
    assert_eq!(Recording::open(&p).unwrap().channel("force").unwrap(), &[1.0, 3.0, 9.0]);

    let bad = |m: RecordingMeta| RecordingWriter::create(&dir.path().join("bad"), m).unwrap_err().to_string();
    assert!(bad(RecordingMeta::new(f64::NAN, vec![Channel::new("x", "")])).contains("`rate` is NaN"));
    assert!(bad(RecordingMeta::new(0.0, vec![Channel::new("x", "")])).contains("`rate` is 0"));
    assert!(bad(RecordingMeta::new(1.0, vec![])).contains("`channels` is empty"));
    assert!(bad(RecordingMeta::new(1.0, vec![Channel::new(" ", "")])).contains("channel 0 has an empty name"));
    let mut m = meta2();
    m.condition.gain = Some(f64::INFINITY);
    assert!(bad(m).contains("condition `gain` is inf"));
    assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 2, "a refused writer creates nothing");
}

#[test]
fn paths_name_the_pair() {
    let p = |s: &str| RecordingPaths::new(Path::new(s));
    let pair = |w: &str, j: &str| RecordingPaths { wav: w.into(), json: j.into() };
    assert_eq!(p("a/run.wav"), pair("a/run.wav", "a/run.json"));
    assert_eq!(p("a/run.JSON"), pair("a/run.wav", "a/run.json"));
    assert_eq!(p("run"), pair("run.wav", "run.json"));
    assert_eq!(p("run.v2"), pair("run.v2.wav", "run.v2.json"));
    assert_eq!(p("x.wav").temporary(), pair("x.wav.tmp", "x.json.tmp"));
}
