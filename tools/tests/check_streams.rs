//! `evflow check` streams through a recording instead of loading it (issue
//! 27, point 3): a 600 MB recording is checked in a process that may not
//! map 400 MB, and a WAV, a mesh or a graph file that is a link to
//! `/dev/zero` is refused at once.

#![cfg(unix)]

use evflow_nodes::recording::format::{Channel, RecordingMeta, RecordingWriter};
use std::path::Path;
use std::process::{Command, Output};

/// A one-channel recording of `frames` zero samples at 1 kHz, written
/// sparse (a header and a length, no data blocks).
fn sparse_recording(dir: &Path, name: &str, frames: u64) {
    let meta = RecordingMeta::new(1000.0, vec![Channel::new("force", "N")]);
    let mut w = RecordingWriter::create(&dir.join(name), meta).unwrap();
    w.write_frame(&[0.0]).unwrap();
    w.finish().unwrap();
    let wav = dir.join(format!("{name}.wav"));
    let data = frames * 8;
    let f = std::fs::OpenOptions::new().write(true).open(&wav).unwrap();
    f.set_len(58 + data).unwrap();
    use std::os::unix::fs::FileExt;
    f.write_all_at(&((data + 50) as u32).to_le_bytes(), 4).unwrap();
    f.write_all_at(&(frames as u32).to_le_bytes(), 46).unwrap();
    f.write_all_at(&(data as u32).to_le_bytes(), 54).unwrap();
    let json = dir.join(format!("{name}.json"));
    let text = std::fs::read_to_string(&json).unwrap().replace("\"frames\": 1", &format!("\"frames\": {frames}"));
    std::fs::write(&json, text).unwrap();
}

fn graph(dir: &Path, recording: &str) -> std::path::PathBuf {
    let path = dir.join("g.toml");
    std::fs::write(
        &path,
        format!(
            "[graph]\nformat = 1\nname = \"g\"\nrate = 1000.0\nconnections = [\"rec.force -> st.in\"]\n\
             [nodes.rec]\ntype = \"recording.in\"\npath = \"{recording}\"\nchannels = [\"force\"]\n\
             [nodes.st]\ntype = \"stats\"\n"
        ),
    )
    .unwrap();
    path
}

/// `evflow check FILE` in a shell whose address space is cut to `kib` KiB.
fn check_limited(file: &Path, kib: u64) -> Output {
    Command::new("sh")
        .arg("-c")
        .arg(format!("ulimit -v {kib} && exec \"$0\" check \"$1\""))
        .arg(env!("CARGO_BIN_EXE_evflow"))
        .arg(file)
        .output()
        .expect("sh runs")
}

#[test]
fn checking_a_large_recording_takes_no_memory_of_its_size() {
    let dir = tempfile::tempdir().unwrap();
    sparse_recording(dir.path(), "big", 75_000_000); // 600 MB
    let g = graph(dir.path(), "big");
    let o = check_limited(&g, 400 * 1024);
    let (out, err) = (String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    assert!(o.status.success(), "check failed within 400 MiB:\n{out}\n{err}");
    assert!(out.contains("built:"), "{out}");
}

#[test]
fn a_recording_linked_to_dev_zero_is_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    sparse_recording(dir.path(), "z", 10);
    std::fs::remove_file(dir.path().join("z.wav")).unwrap();
    std::os::unix::fs::symlink("/dev/zero", dir.path().join("z.wav")).unwrap();
    let g = graph(dir.path(), "z");
    let o = check_limited(&g, 400 * 1024);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("z.wav") && err.contains("not a regular file"), "{err}");
}

#[test]
fn a_mesh_or_a_graph_file_linked_to_a_device_is_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    std::os::unix::fs::symlink("/dev/zero", dir.path().join("scene.obj")).unwrap();
    let g = dir.path().join("mesh.toml");
    std::fs::write(
        &g,
        "[graph]\nformat = 1\nname = \"m\"\nrate = 1000\nconnections = [\"p.x -> s.x\", \"p.y -> s.y\", \"s.z -> k.in\"]\n\
         [nodes.p]\ntype = \"mesh.path\"\n[nodes.s]\ntype = \"mesh.gradient\"\nfile = \"scene.obj\"\n\
         [nodes.k]\ntype = \"stats\"\n",
    )
    .unwrap();
    let o = check_limited(&g, 400 * 1024);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("scene.obj") && err.contains("not a regular file"), "{err}");
    // The graph file itself.
    let z = dir.path().join("zero.toml");
    std::os::unix::fs::symlink("/dev/zero", &z).unwrap();
    let o = check_limited(&z, 400 * 1024);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("zero.toml") && err.contains("not a regular file"), "{err}");
}
