//! Reading streams (issue 27, point 3): a header is read without the
//! samples, a check keeps no sample, what is read never passes the file's
//! size, and a name that is not a regular file is refused before it is read.

use super::*;
use std::fs;
use std::path::Path;

/// Writes a one-channel recording of `n` frames, sample i = i.
fn write1(dir: &Path, name: &str, n: usize) {
    let meta = RecordingMeta::new(1000.0, vec![Channel::new("force", "N")]);
    let mut w = RecordingWriter::create(&dir.join(name), meta).unwrap();
    for i in 0..n {
        w.write_frame(&[i as f64]).unwrap();
    }
    w.finish().unwrap();
}

#[test]
fn samples_across_read_chunks_decode_exactly_and_a_scan_keeps_none() {
    // 20 000 frames of 8 bytes: three 64 KiB reads.
    let dir = tempfile::tempdir().unwrap();
    write1(dir.path(), "long", 20_000);
    let p = dir.path().join("long.wav");
    let rec = Recording::open(&p).unwrap();
    let want: Vec<f64> = (0..20_000).map(f64::from).collect();
    assert_eq!(rec.channel("force").unwrap(), &want[..]);

    let scan = Recording::scan_channels(&p, &["force"]).unwrap();
    assert_eq!(scan.frames(), 20_000);
    assert_eq!(scan.loaded().count(), 0, "a scan keeps no channel");
    assert!(scan.channel("force").is_none());

    // A scan checks every sample: a NaN in the third read is found, at its frame.
    let mut bytes = fs::read(&p).unwrap();
    let at = 58 + 17_345 * 8;
    bytes[at..at + 8].copy_from_slice(&f64::NAN.to_le_bytes());
    fs::write(&p, bytes).unwrap();
    let e = Recording::scan_channels(&p, &["force"]).unwrap_err().to_string();
    assert!(e.ends_with("long.wav: channel `force` frame 17345 is NaN"), "{e}");
    // Nothing asked for: the samples are not read at all.
    assert!(Recording::open_channels(&p, &[] as &[&str]).is_ok());
}

#[test]
fn a_header_claiming_more_than_the_file_holds_reads_what_is_there() {
    // The data chunk's size says 4 GiB; 100 frames are in the file.
    let dir = tempfile::tempdir().unwrap();
    write1(dir.path(), "big", 100);
    let p = dir.path().join("big.wav");
    let mut bytes = fs::read(&p).unwrap();
    bytes[54..58].copy_from_slice(&u32::MAX.to_le_bytes());
    fs::write(&p, bytes).unwrap();
    let rec = Recording::open(&p).unwrap();
    assert_eq!(rec.frames(), 100);
    assert_eq!(rec.shortfall().map(|s| s.present), Some(100));
    assert!(rec.shortfall().unwrap().claimed > 500_000_000);
}

#[cfg(unix)]
#[test]
fn names_that_are_not_regular_files_are_refused_before_they_are_read() {
    let dir = tempfile::tempdir().unwrap();
    write1(dir.path(), "r", 10);
    let wav = dir.path().join("r.wav");
    let json = dir.path().join("r.json");

    // A WAV that is a link to /dev/zero (which never ends).
    fs::remove_file(&wav).unwrap();
    std::os::unix::fs::symlink("/dev/zero", &wav).unwrap();
    let e = Recording::open(&wav).unwrap_err().to_string();
    assert!(e.contains("r.wav: is a device, FIFO or socket, not a regular file"), "{e}");
    assert!(Recording::scan_channels(&wav, &["force"]).is_err());

    // A folder of the WAV's name.
    fs::remove_file(&wav).unwrap();
    fs::create_dir(&wav).unwrap();
    let e = Recording::open(&wav).unwrap_err().to_string();
    assert!(e.contains("r.wav: is a folder, not a regular file"), "{e}");
    fs::remove_dir(&wav).unwrap();

    // A FIFO (opening it would wait for a writer forever).
    let made = std::process::Command::new("mkfifo").arg(&wav).status().map(|s| s.success()).unwrap_or(false);
    if made {
        let e = Recording::open(&wav).unwrap_err().to_string();
        assert!(e.contains("r.wav: is a device, FIFO or socket"), "{e}");
        fs::remove_file(&wav).unwrap();
    }

    // A sidecar that is a link to /dev/zero, or too large to be a sidecar.
    write1(dir.path(), "s", 10);
    let sjson = dir.path().join("s.json");
    let text = fs::read_to_string(&sjson).unwrap();
    fs::remove_file(&sjson).unwrap();
    std::os::unix::fs::symlink("/dev/zero", &sjson).unwrap();
    let e = Recording::open(&sjson).unwrap_err().to_string();
    assert!(e.contains("s.json: is a device, FIFO or socket"), "{e}");
    fs::remove_file(&sjson).unwrap();
    let padded = text.replacen('{', &format!("{{\"pad\": \"{}\",", "x".repeat(2 << 20)), 1);
    fs::write(&sjson, padded).unwrap();
    let e = Recording::open(&sjson).unwrap_err().to_string();
    assert!(e.contains("s.json: ") && e.contains("a sidecar holds at most 1048576 bytes"), "{e}");

    // A link to a regular file is followed.
    fs::remove_file(&json).unwrap();
    write1(dir.path(), "t", 10);
    std::os::unix::fs::symlink(dir.path().join("t.json"), &json).unwrap();
    fs::remove_dir_all(dir.path().join("r.wav")).ok();
    std::os::unix::fs::symlink(dir.path().join("t.wav"), &wav).unwrap();
    assert_eq!(Recording::open(&wav).unwrap().frames(), 10);
}
