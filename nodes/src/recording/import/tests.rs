//! Tests of `evflow import`'s library: `.npy` and CSV round trips through
//! the recording format, rate inference, refusals, and that a failed
//! import leaves nothing behind.

use super::*;
use crate::recording::format::Recording;
use std::fs;

/// An `.npy` file as `np.save` writes it: magic, version, header length,
/// the header dict padded with spaces to a multiple of 64 bytes and ended
/// by a newline, then `data`.
fn npy_bytes(major: u8, descr: &str, fortran: bool, shape: &str, data: &[u8]) -> Vec<u8> {
    let py = if fortran { "True" } else { "False" };
    let mut h = format!("{{'descr': '{descr}', 'fortran_order': {py}, 'shape': {shape}, }}");
    let len_bytes = if major == 1 { 2 } else { 4 };
    while (8 + len_bytes + h.len() + 1) % 64 != 0 {
        h.push(' ');
    }
    h.push('\n');
    let mut b = b"\x93NUMPY".to_vec();
    b.extend([major, 0]);
    if major == 1 {
        b.extend((h.len() as u16).to_le_bytes());
    } else {
        b.extend((h.len() as u32).to_le_bytes());
    }
    b.extend(h.as_bytes());
    b.extend(data);
    b
}

/// `values` as the bytes of dtype `kind` (`f8`, `i2`, …), big- or
/// little-endian.
fn encode(values: &[f64], kind: &str, big: bool) -> Vec<u8> {
    macro_rules! enc {
        ($t:ty) => {
            values
                .iter()
                .flat_map(|&x| if big { (x as $t).to_be_bytes().to_vec() } else { (x as $t).to_le_bytes().to_vec() })
                .collect()
        };
    }
    match kind {
        "f8" => enc!(f64),
        "f4" => enc!(f32),
        "i1" => enc!(i8),
        "u1" => enc!(u8),
        "i2" => enc!(i16),
        "u2" => enc!(u16),
        "i4" => enc!(i32),
        "u4" => enc!(u32),
        "i8" => enc!(i64),
        "u8" => enc!(u64),
        k => panic!("no such test dtype {k}"),
    }
}

/// Values every test dtype holds exactly, including each type's extremes
/// where it matters.
fn values_for(kind: &str, frames: usize, channels: usize) -> Vec<Vec<f64>> {
    let pool: Vec<f64> = match kind {
        "f8" => vec![1.0 / 3.0, -0.0, 5e-324, f64::MAX, -2.5e-7, 123456.789],
        "f4" => vec![0.25, -1.5, 3.0e-8f32 as f64, f32::MAX as f64, -65504.0, 0.1f32 as f64],
        "i1" => vec![-128.0, 127.0, 0.0, -1.0, 5.0, 42.0],
        "u1" => vec![0.0, 255.0, 1.0, 128.0, 7.0, 99.0],
        "i2" => vec![-32768.0, 32767.0, 0.0, -1.0, 1234.0, -999.0],
        "u2" => vec![0.0, 65535.0, 1.0, 32768.0, 4095.0, 2048.0],
        "i4" => vec![i32::MIN as f64, i32::MAX as f64, 0.0, -1.0, 70000.0, -3.0],
        "u4" => vec![0.0, u32::MAX as f64, 1.0, 2.0e9, 65536.0, 3.0],
        "i8" => vec![-(1i64 << 53) as f64, (1i64 << 53) as f64, 0.0, -1.0, 1e15, -7.0],
        "u8" => vec![0.0, (1u64 << 53) as f64, 1.0, 1e15, 4.0, 12.0],
        k => panic!("no such test dtype {k}"),
    };
    (0..channels).map(|c| (0..frames).map(|i| pool[(i * 5 + c * 3) % pool.len()]).collect()).collect()
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

fn files_in(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> =
        fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    v.sort();
    v
}

fn with_rate(rate: f64) -> ImportOptions {
    ImportOptions { rate: Some(rate), ..ImportOptions::default() }
}

#[test]
fn npy_round_trips_every_dtype_byte_order_layout_and_version() {
    let dir = tempfile::tempdir().unwrap();
    let kinds = ["f8", "f4", "i1", "u1", "i2", "u2", "i4", "u4", "i8", "u8"];
    let mut cases = 0;
    for kind in kinds {
        for big in [false, true] {
            let mark = if kind.ends_with('1') {
                '|'
            } else if big {
                '>'
            } else {
                '<'
            };
            if kind.ends_with('1') && big {
                continue;
            }
            for (major, channels, fortran) in [(1, 1, false), (1, 3, false), (2, 3, true), (3, 2, false), (3, 2, true)]
            {
                let frames = 7;
                let cols = values_for(kind, frames, channels);
                let logical: Vec<f64> = if fortran {
                    cols.iter().flatten().copied().collect() // column after column
                } else {
                    (0..frames).flat_map(|i| cols.iter().map(move |c| c[i])).collect()
                };
                let shape = if channels == 1 { format!("({frames},)") } else { format!("({frames}, {channels})") };
                let descr = format!("{mark}{kind}");
                let src = dir.path().join(format!("a-{kind}-{big}-{major}-{channels}-{fortran}.npy"));
                fs::write(&src, npy_bytes(major, &descr, fortran, &shape, &encode(&logical, kind, big))).unwrap();
                let dest = dir.path().join(format!("out-{cases}"));
                let w = import_file(&src, &dest, &with_rate(10_000.0)).unwrap();
                assert_eq!((w.frames, w.channels, w.rate), (frames as u64, channels, 10_000.0));
                let rec = Recording::open(&dest).unwrap();
                for (c, want) in cols.iter().enumerate() {
                    assert_eq!(
                        bits(rec.channel(&format!("ch{c}")).unwrap()),
                        bits(want),
                        "{descr} v{major} {shape} fortran={fortran} ch{c}"
                    );
                }
                let order = if channels == 1 {
                    ""
                } else if fortran {
                    ", Fortran order"
                } else {
                    ", C order"
                };
                assert_eq!(
                    rec.meta().source,
                    format!("evflow import of {} (NumPy {major}.0, {descr}, shape {shape}{order})", src.display())
                );
                cases += 1;
            }
        }
    }
    assert_eq!(cases, 90);
}

/// Bytes written by NumPy 2.4 itself: `np.save` of `[[1.5, -2], [3, 4]]`
/// (version 1.0, `<f8`) and `write_array(…, version=(3, 0))` of a Fortran
/// `>i2` array `[[1, 2], [3, 4]]`.
#[test]
fn npy_files_written_by_numpy_itself() {
    let mut f8 = b"\x93NUMPY\x01\x00v\x00{'descr': '<f8', 'fortran_order': False, 'shape': (2, 2), }".to_vec();
    f8.extend(std::iter::repeat_n(b' ', 58));
    f8.push(b'\n');
    for x in [1.5f64, -2.0, 3.0, 4.0] {
        f8.extend(x.to_le_bytes());
    }
    assert_eq!(f8.len(), 128 + 32);
    let a = npy::parse(&f8, Path::new("a.npy")).unwrap();
    assert_eq!((a.frames, a.channels, a.samples), (2, 2, vec![1.5, -2.0, 3.0, 4.0]));

    let mut i2 = b"\x93NUMPY\x03\x00t\x00\x00\x00{'descr': '>i2', 'fortran_order': True, 'shape': (2, 2), }".to_vec();
    i2.extend(std::iter::repeat_n(b' ', 57));
    i2.extend(b"\n\x00\x01\x00\x03\x00\x02\x00\x04");
    let a = npy::parse(&i2, Path::new("b.npy")).unwrap();
    assert_eq!(a.samples, [1.0, 2.0, 3.0, 4.0]);
    assert_eq!(a.description, "NumPy 3.0, >i2, shape (2, 2), Fortran order");

    // Python 2's long integers, a v3 header in UTF-8 and double quotes.
    let old = npy_bytes(1, "<f8", false, "(2L, 1L)", &encode(&[1.0, 2.0], "f8", false));
    assert_eq!(npy::parse(&old, Path::new("c.npy")).unwrap().samples, [1.0, 2.0]);
    let mut v3 = b"\x93NUMPY\x03\x00".to_vec();
    let h = "{\"descr\": \"<f4\", \"shape\": (2,), \"fortran_order\": False}  \n";
    v3.extend((h.len() as u32).to_le_bytes());
    v3.extend(h.as_bytes());
    v3.extend(encode(&[0.5, -0.5], "f4", false));
    assert_eq!(npy::parse(&v3, Path::new("d.npy")).unwrap().samples, [0.5, -0.5]);
}

fn npy_err(bytes: &[u8]) -> String {
    npy::parse(bytes, Path::new("x.npy")).unwrap_err().to_string()
}

#[test]
fn npy_refusals_say_what_is_wrong() {
    let f8 = |shape: &str, n: usize| npy_bytes(1, "<f8", false, shape, &encode(&vec![1.0; n], "f8", false));
    let cases: Vec<(Vec<u8>, &str)> = vec![
        (vec![], "the file is empty"),
        (b"time,force\n0,1\n".to_vec(), "does not start with the .npy magic"),
        (b"\x93NUMPY\x04\x00\x10\x00".to_vec(), "format version 4.0 is not one this evflow reads (1.0, 2.0 and 3.0)"),
        (b"\x93NUMPY\x01\x00".to_vec(), "the file ends inside the header length"),
        (b"\x93NUMPY\x02\x00\xff\xff\xff\xff".to_vec(), "the header claims 4294967295 bytes; headers longer than"),
        (
            b"\x93NUMPY\x01\x00\x40\x00{'descr'".to_vec(),
            "the header claims 64 bytes but the file ends after 8 (cut short?)",
        ),
        (npy_bytes(1, "|O", false, "(3,)", &[0; 24]), "dtype '|O' is an object array"),
        (npy_bytes(1, "<c16", false, "(3,)", &[0; 48]), "dtype '<c16' is complex"),
        (npy_bytes(1, "<U5", false, "(3,)", &[0; 60]), "dtype '<U5' holds text"),
        (npy_bytes(1, "<f2", false, "(3,)", &[0; 6]), "dtype '<f2' is float16"),
        (npy_bytes(1, "|b1", false, "(3,)", &[0; 3]), "dtype '|b1' is boolean"),
        (npy_bytes(1, "<M8[s]", false, "(3,)", &[0; 24]), "holds dates or time spans"),
        (npy_bytes(1, "f8", false, "(3,)", &[0; 24]), "dtype 'f8' has no byte-order mark"),
        (npy_bytes(1, "|f8", false, "(3,)", &[0; 24]), "dtype '|f8' is a multi-byte type marked `|`"),
        (
            f8("(2, 3, 4)", 24),
            "shape (2, 3, 4) has 3 dimensions; a recording is 1-D (frames,) or 2-D (frames, channels)",
        ),
        (f8("()", 1), "shape () is a single number"),
        (f8("(0,)", 0), "shape (0,) holds no samples"),
        (f8("(5, 0)", 0), "shape (5, 0) holds no samples"),
        (
            f8("(2, 100)", 200),
            "shape (2, 100) reads as 100 channels of 2 frames; a recording is (frames, channels): save the transpose",
        ),
        (f8("(10, 2)", 19), "truncated: shape (10, 2) of <f8 needs 160 bytes of data but the file holds 152"),
        (f8("(10, 2)", 21), "8 bytes follow the 160 bytes of data that shape (10, 2) of <f8 describes"),
        (f8("(4611686018427387904, 4611686018427387904)", 2), "claims more bytes than any file can hold"),
        (f8("(99999999999999999999999,)", 1), "holds the number 99999999999999999999999, too large"),
        (f8("(-3,)", 1), "holds the negative number -3"),
        (f8("(1000000000000, 2)", 4), "truncated: shape (1000000000000, 2) of <f8 needs 16000000000000 bytes"),
        (npy_bytes(1, "<f8", false, "[3]", &[0; 24]), "`shape` is a list, not a tuple"),
        (npy_bytes(1, "<f8", false, "(3.5,)", &[0; 24]), "misses a `,` or `)`"),
    ];
    for (bytes, want) in cases {
        let e = npy_err(&bytes);
        assert!(e.starts_with("x.npy: not an importable .npy file: "), "{e}");
        assert!(e.contains(want), "expected `{want}` in: {e}");
    }
    // Header dicts that lie or are not dicts.
    let header = |h: &str| {
        let mut b = b"\x93NUMPY\x01\x00".to_vec();
        b.extend((h.len() as u16).to_le_bytes());
        b.extend(h.as_bytes());
        b.extend([0u8; 8]);
        npy_err(&b)
    };
    for (h, want) in [
        ("{'descr': '<f8', 'shape': (1,)}", "header has no `fortran_order`"),
        ("{'descr': '<f8', 'fortran_order': 0, 'shape': (1,)}", "`fortran_order` is the number 0, not True or False"),
        ("{'descr': '<f8', 'fortran_order': False}", "header has no `shape`"),
        ("{'fortran_order': False, 'shape': (1,)}", "header has no `descr`"),
        ("{'descr': '<f8', 'descr': '<f8', 'fortran_order': False, 'shape': (1,)}", "header lists `descr` twice"),
        ("{'descr': '<f8', 'fortran_order': False, 'shape': (1,), 'extra': 1}", "unexpected key `extra`"),
        ("{'descr': [('a', '<f8')], 'fortran_order': False, 'shape': (1,)}", "structured array"),
        ("{'descr': '<f8', 'fortran_order': False, 'shape': (1,)} trailing", "has text after its closing `}`"),
        ("['descr', '<f8']", "header is a list, not a dict"),
        ("{'descr': '<f8', 'fortran_order': False, 'shape': (1,)", "misses a `,` or `}`"),
        ("{'descr': '<f8 ", "ends inside a string"),
        ("{'descr': '\\x3cf8', 'fortran_order': False, 'shape': (1,)}", "escape sequence"),
        ("((((((((((((((((((((1))))))))))))))))))))", "nests deeper than 8 levels"),
        ("{'descr': '<f8', 'fortran_order': Maybe, 'shape': (1,)}", "unexpected word `Maybe`"),
        ("\u{e9}", "non-ASCII"),
    ] {
        let e = header(h);
        assert!(e.contains(want), "header {h:?}: expected `{want}` in: {e}");
    }
    // Non-finite samples name the column and frame.
    let nan = npy_bytes(1, "<f8", false, "(3, 2)", &encode(&[0.0, 1.0, 2.0, f64::NAN, 4.0, 5.0], "f8", false));
    assert_eq!(npy_err(&nan), "x.npy: column 1 (from 0) frame 1 is NaN; a recording holds finite samples");
    let inf = npy_bytes(1, ">f4", true, "(2, 2)", &encode(&[0.0, f64::NEG_INFINITY, 2.0, 3.0], "f4", true));
    assert_eq!(npy_err(&inf), "x.npy: column 0 (from 0) frame 1 is -Inf; a recording holds finite samples");
}

/// A CSV in every form a lab writes; each must give the same recording.
#[test]
fn csv_variants_round_trip_with_rate_from_the_time_column() {
    let dir = tempfile::tempdir().unwrap();
    let rows: Vec<(f64, f64, f64)> =
        (0..200).map(|i| (i as f64 / 1000.0, (i as f64 * 0.37).sin(), (i % 7) as f64 / 7.0)).collect();
    let text = |sep: &str, head: &str, fmt: &dyn Fn(f64) -> String| {
        let mut s = String::from(head);
        for (t, f, u) in &rows {
            s += &format!("{}{sep}{}{sep}{}\n", fmt(*t), fmt(*f), fmt(*u));
        }
        s
    };
    let exact = |x: f64| format!("{x:?}");
    let comma = |x: f64| format!("{x:?}").replace('.', ",");
    let variants = [
        ("a.csv", text(",", "time [s],force [N],u\n", &exact)),
        ("b.csv", text(";", "# lab 3, rig A\n\ntime [s];force [N];u\n", &comma)),
        ("c.tsv", text("\t", "\"time [s]\"\t\"force [N]\"\t\"u\"\n", &exact)),
        ("d.txt", text(" ", "time [s] force [N] u\n", &exact).replace("time [s] force [N]", "time force")),
        ("e.csv", {
            // Times in milliseconds, CRLF line ends.
            let mut s = String::from("t (ms),force [N],u\r\n");
            for (t, f, u) in &rows {
                s += &format!("{:?},{f:?},{u:?}\r\n", t * 1000.0);
            }
            s
        }),
    ];
    for (name, body) in &variants {
        let src = dir.path().join(name);
        fs::write(&src, body).unwrap();
        let got = read(&src, &ImportOptions::default()).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(got.meta.rate, 1000.0, "{name}");
        assert_eq!(got.frames, 200);
        let names: Vec<&str> = got.meta.channels.iter().map(|c| c.name.as_str()).collect();
        assert_eq!(names, ["force", "u"], "{name}");
        if *name != "d.txt" {
            assert_eq!(got.meta.channels[0].unit, "N", "{name}");
        }
        let force: Vec<f64> = rows.iter().map(|r| r.1).collect();
        assert_eq!(bits(&got.channel("force").unwrap()), bits(&force), "{name}");
        assert!(got.notes.iter().any(|n| n.contains("rate 1000 Hz from time column")), "{name}: {:?}", got.notes);
    }

    // Written and read back, with the condition and the source.
    let mut opts = ImportOptions { keep_time: true, ..ImportOptions::default() };
    opts.condition.load_g = Some(85.0);
    opts.condition.velocity_cm_s = Some(4.0);
    opts.condition.material = Some("felt".into());
    opts.condition.gain = Some(1.0);
    opts.add_condition("trial=3").unwrap();
    opts.add_condition("operator=jk").unwrap();
    opts.add_condition("lowpassed=true").unwrap();
    let src = dir.path().join("a.csv");
    let w = import_file(&src, &dir.path().join("rec"), &opts).unwrap();
    assert_eq!((w.frames, w.channels, w.rate), (200, 3, 1000.0));
    let rec = Recording::open(&dir.path().join("rec")).unwrap();
    let ch: Vec<(String, String)> = rec.meta().channels.iter().map(|c| (c.name.clone(), c.unit.clone())).collect();
    assert_eq!(ch, [("time".into(), "s".into()), ("force".into(), "N".into()), ("u".into(), String::new())]);
    let c = &rec.meta().condition;
    assert_eq!(
        (c.load_g, c.velocity_cm_s, c.material.as_deref(), c.gain),
        (Some(85.0), Some(4.0), Some("felt"), Some(1.0))
    );
    assert_eq!(c.extra["trial"], serde_json::json!(3));
    assert_eq!(c.extra["operator"], serde_json::json!("jk"));
    assert_eq!(c.extra["lowpassed"], serde_json::json!(true));
    assert_eq!(
        rec.meta().source,
        format!("evflow import of {} (200 rows, comma delimiter, header row)", src.display())
    );
}

#[test]
fn names_units_and_rate_from_the_options() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("raw.csv");
    fs::write(&src, "1,2,3\n4,5,6\n").unwrap();
    // No header: ch0…, and a rate must be given.
    let e = read(&src, &ImportOptions::default()).unwrap_err().to_string();
    assert_eq!(
        e,
        format!(
            "{}: no sample rate: give --rate HZ, or a time column in the header (`time [s]`, `t`, or named with --channels)",
            src.display()
        )
    );
    let got = read(&src, &with_rate(500.0)).unwrap();
    assert_eq!(got.meta.channels.iter().map(|c| c.name.as_str()).collect::<Vec<_>>(), ["ch0", "ch1", "ch2"]);
    assert_eq!(got.duration(), 2.0 / 500.0);
    // --channels naming a time column: the rate comes from it.
    let opts = ImportOptions {
        channels: Some(vec!["t".into(), "force".into(), "u".into()]),
        units: Some(vec!["ms".into(), "N".into(), "".into()]),
        ..ImportOptions::default()
    };
    let got = read(&src, &opts).unwrap();
    assert!((got.meta.rate - 1000.0 / 3.0).abs() < 1e-9, "{}", got.meta.rate);
    assert_eq!(got.meta.channels, [Channel::new("force", "N"), Channel::new("u", "")]);
    assert_eq!(got.samples(), [2.0, 3.0, 5.0, 6.0]);
    // Header names made into port names; unnamed columns.
    fs::write(&src, "Time,Force X (N),,µ\n0,1,2,3\n0.5,1,2,3\n").unwrap();
    let got = read(&src, &ImportOptions::default()).unwrap();
    assert_eq!(got.meta.rate, 2.0);
    let names: Vec<&str> = got.meta.channels.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["Force_X", "ch2", "ch3"]);
    assert!(got.notes.contains(&"header name `Force X` written as channel `Force_X`".to_string()), "{:?}", got.notes);

    let err = |opts: &ImportOptions| read(&src, opts).unwrap_err().to_string();
    let p = src.display();
    assert_eq!(
        err(&ImportOptions { channels: Some(vec!["a".into()]), ..with_rate(1.0) }),
        format!("{p}: --channels lists 1 name(s) but the file has 4 column(s)")
    );
    assert_eq!(
        err(&ImportOptions { units: Some(vec!["N".into(); 3]), ..with_rate(1.0) }),
        format!("{p}: --units lists 3 unit(s) but the file has 4 column(s)")
    );
    assert_eq!(
        err(&ImportOptions { channels: Some(["a", "b c", "d", "e"].map(String::from).to_vec()), ..with_rate(1.0) }),
        "--channels: `b c` is not a valid channel name (letters, digits, `_`, `-`)"
    );
    assert_eq!(
        err(&ImportOptions { channels: Some(["a", "b", "a", "e"].map(String::from).to_vec()), ..with_rate(1.0) }),
        format!("{p}: columns 1 and 3 are both named `a`; name them with --channels")
    );
    assert_eq!(
        err(&ImportOptions { channels: Some(["time", "b", "T", "e"].map(String::from).to_vec()), ..with_rate(1.0) }),
        format!(
            "{p}: columns 1, 3 are all time columns (named time or t); keep one, or rename the others with --channels"
        )
    );
    assert_eq!(err(&with_rate(-3.0)), "--rate -3: not a positive number of Hz");
    // A rate `recording.in` would refuse is refused here, given or inferred.
    for (r, shown) in [(1e308, "1e308"), (2e7, "20000000"), (1e-4, "0.0001")] {
        assert_eq!(
            err(&with_rate(r)),
            format!(
                "--rate {shown}: outside the 0.001 … 10000000 Hz a recording may have for `recording.in` to play it"
            )
        );
    }
    let tiny = src.with_file_name("tiny-steps.csv");
    fs::write(&tiny, "t,force\n0,1\n1e-300,2\n2e-300,3\n").unwrap();
    let e = read(&tiny, &ImportOptions::default()).unwrap_err().to_string();
    assert!(
        e.contains("time column `t` steps by 1e-300 s: 9.999999999999999e299 Hz is outside")
            && e.contains("outside the 0.001 … 10000000 Hz"),
        "{e}"
    );
    assert_eq!(
        err(&ImportOptions { time_tolerance: -0.1, ..ImportOptions::default() }),
        "--time-tolerance -0.1: a fraction of the time step, at least 0 and below 1 (e.g. 0.01)"
    );
    assert_eq!(
        err(&with_rate(2.1)),
        format!("{p}: --rate 2.1 Hz disagrees with the 2 Hz of time column `Time` (more than 1 % apart)")
    );
    assert!(read(&src, &with_rate(2.01)).is_ok());
    let mut bad = ImportOptions::default();
    bad.condition.load_g = Some(-5.0);
    assert_eq!(err(&bad), "--load-g -5: a normal load is a positive number of grams");
    bad.condition.load_g = Some(f64::NAN);
    assert_eq!(err(&bad), "--load-g NaN: not a finite number");

    fs::write(&src, "time [h],force\n0,1\n1,2\n").unwrap();
    assert_eq!(
        err(&ImportOptions::default()),
        format!("{p}: time column `time` has unit `h`; give its times in s, ms, us or ns")
    );
    fs::write(&src, "time\n0\n1\n").unwrap();
    assert_eq!(
        err(&ImportOptions::default()),
        format!("{p}: the only column is the time column `time`; there is nothing else to record")
    );
    fs::write(&src, "time,force\n0,1\n").unwrap();
    assert_eq!(
        err(&ImportOptions::default()),
        format!("{p}: no sample rate: the time column has a single row; give --rate HZ")
    );
}

#[test]
fn condition_entries_are_typed_and_not_given_twice() {
    let mut o = ImportOptions::default();
    o.add_condition("load_g=85").unwrap();
    o.add_condition(" material = felt ").unwrap();
    assert_eq!((o.condition.load_g, o.condition.material.as_deref()), (Some(85.0), Some("felt")));
    assert_eq!(o.add_condition("load_g=60").unwrap_err().to_string(), "--condition load_g=60: `load_g` is given twice");
    assert_eq!(o.add_condition("gain=high").unwrap_err().to_string(), "--condition gain=high: `high` is not a number");
    assert_eq!(
        o.add_condition("trial").unwrap_err().to_string(),
        "--condition trial: expected KEY=VALUE, e.g. trial=3"
    );
    assert_eq!(o.add_condition("=3").unwrap_err().to_string(), "--condition =3: expected KEY=VALUE with neither empty");
    assert_eq!(o.add_condition("x=inf").unwrap_err().to_string(), "--condition x=inf: `inf` is not a finite number");
}

#[test]
fn an_irregular_time_column_names_its_first_irregular_row() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("gap.csv");
    // 10 kHz with one sample missing after t = 0.0004 (line 7).
    let mut s = String::from("# logger v2\ntime [s],force [N]\n");
    for i in (0..20).filter(|&i| i != 5) {
        s += &format!("{:.4},{}\n", i as f64 * 1e-4, i);
    }
    fs::write(&src, &s).unwrap();
    let e = read(&src, &ImportOptions::default()).unwrap_err();
    let ImportError::IrregularTime { line, previous, step, .. } = &e else { panic!("{e}") };
    assert_eq!((*line, *previous), (8, 7));
    assert!((step - 2e-4).abs() < 1e-12);
    assert!(e.to_string().starts_with(&format!("{}:8: time column `time` steps by 0.000", src.display())), "{e}");
    // Time stamps that jitter by 0.5 % of a step pass; a decreasing time fails.
    let mut s = String::from("t,force\n");
    for i in 0..100 {
        s += &format!("{},{}\n", i as f64 * 1e-3 + if i % 2 == 1 { 5e-6 } else { 0.0 }, i);
    }
    fs::write(&src, &s).unwrap();
    let rate = read(&src, &ImportOptions::default()).unwrap().meta.rate;
    assert!((rate - 1000.0).abs() < 1e-2, "{rate}");
    fs::write(&src, "t,force\n0,1\n-1,2\n-2,3\n").unwrap();
    assert!(matches!(read(&src, &ImportOptions::default()), Err(ImportError::IrregularTime { line: 3, .. })));
    // An .npy time column (named with --channels) names the frame.
    let src = dir.path().join("t.npy");
    fs::write(
        &src,
        npy_bytes(1, "<f8", false, "(4, 2)", &encode(&[0.0, 1.0, 0.1, 1.0, 0.2, 1.0, 0.35, 1.0], "f8", false)),
    )
    .unwrap();
    let opts = ImportOptions { channels: Some(vec!["time".into(), "force".into()]), ..ImportOptions::default() };
    assert!(matches!(read(&src, &opts), Err(ImportError::IrregularTime { line: 4, previous: 3, .. })));
}

#[test]
fn unsupported_files_are_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let e = |name: &str| {
        let p = dir.path().join(name);
        fs::write(&p, b"x").unwrap();
        read(&p, &ImportOptions::default()).unwrap_err().to_string()
    };
    assert!(e("a.mat").contains("MATLAB .mat files are not read (docs/rig.md says why)"));
    assert!(e("a.npz").contains(".npz archives are not read; save the array with np.save"));
    assert!(e("a.xlsx").ends_with(
        "cannot import a .xlsx file; evflow import reads .npy (NumPy) and .csv, .tsv or .txt (delimited text)"
    ));
    assert!(e("noext").contains("cannot import a file without an extension"));
    let missing = dir.path().join("missing.csv");
    let m = read(&missing, &ImportOptions::default()).unwrap_err().to_string();
    assert!(m.starts_with(&format!("{}: ", missing.display())), "{m}");
    // Hostile text: header only, empty, binary junk read as Latin-1.
    let p = dir.path().join("h.csv");
    fs::write(&p, "time [s],force [N]\n").unwrap();
    assert!(read(&p, &ImportOptions::default())
        .unwrap_err()
        .to_string()
        .ends_with("holds no samples: a header row and no data rows"));
    fs::write(&p, "").unwrap();
    assert!(read(&p, &ImportOptions::default()).unwrap_err().to_string().contains("holds no samples"));
    fs::write(&p, [0xfe, 0x00, 0x31, b'\n', 0x80]).unwrap();
    assert!(matches!(read(&p, &ImportOptions::default()), Err(ImportError::Cell { line: 2, .. })));
    // UTF-16 with a byte-order mark, as Excel's "Unicode text" saves.
    for le in [true, false] {
        let text = "time\tforce [N]\r\n0\t1,5\r\n0,5\t2\r\n";
        let mut b = if le { vec![0xff, 0xfe] } else { vec![0xfe, 0xff] };
        for u in text.encode_utf16() {
            b.extend(if le { u.to_le_bytes() } else { u.to_be_bytes() });
        }
        fs::write(&p, b).unwrap();
        let got = read(&p, &ImportOptions::default()).unwrap();
        assert_eq!((got.meta.rate, got.samples()), (2.0, &[1.5, 2.0][..]));
        assert!(got.notes[0].starts_with("the file is UTF-16"), "{:?}", got.notes);
    }
}

#[test]
fn an_existing_recording_is_kept_unless_forced() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("a.csv");
    fs::write(&src, "t,force\n0,1\n0.001,2\n").unwrap();
    let dest = dir.path().join("a");
    import_file(&src, &dest, &ImportOptions::default()).unwrap();
    fs::write(&src, "t,force\n0,7\n0.001,8\n0.002,9\n").unwrap();
    let e = import_file(&src, &dest, &ImportOptions::default()).unwrap_err().to_string();
    assert_eq!(
        e,
        format!("{}: already exists; give --force to replace it, or another --out", dir.path().join("a.wav").display())
    );
    assert_eq!(Recording::open(&dest).unwrap().channel("force").unwrap(), [1.0, 2.0]);
    import_file(&src, &dest, &ImportOptions { force: true, ..ImportOptions::default() }).unwrap();
    assert_eq!(Recording::open(&dest).unwrap().channel("force").unwrap(), [7.0, 8.0, 9.0]);
    assert_eq!(files_in(dir.path()), ["a.csv", "a.json", "a.wav"]);
}

#[test]
fn a_failed_import_leaves_nothing_at_the_destination() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("bad.csv");
    let mut s = String::from("time,force\n");
    for i in 0..50_000 {
        s += &format!("{},{}\n", i as f64 / 1000.0, if i == 49_999 { "oops".to_string() } else { i.to_string() });
    }
    fs::write(&src, s).unwrap();
    let out = dir.path().join("new").join("deeper");
    let e = import_file(&src, &out.join("rec"), &ImportOptions::default()).unwrap_err().to_string();
    assert!(e.contains(":50001: column 2 (`force`): `oops` is not a number"), "{e}");
    assert!(!dir.path().join("new").exists(), "a folder was created for a failed import");

    // A failure while writing (the sidecar cannot be renamed into place:
    // a folder stands there) removes the WAV that landed and the folders
    // the import created, and keeps what was there before.
    let good = dir.path().join("good.csv");
    fs::write(&good, "time,force\n0,1\n0.001,2\n").unwrap();
    let dest = dir.path().join("w").join("rec");
    fs::create_dir_all(dest.with_extension("json").join("blocker")).unwrap();
    let e = import_file(&good, &dest, &ImportOptions { force: true, ..ImportOptions::default() }).unwrap_err();
    assert!(matches!(e, ImportError::Write(_)), "{e}");
    assert_eq!(files_in(&dir.path().join("w")), ["rec.json"]);
    // Folders created for the destination go again.
    let dest = dir.path().join("x").join("y").join("rec");
    fs::create_dir_all(dir.path().join("x")).unwrap();
    fs::write(dir.path().join("x").join("y"), "a file where the folder should be").unwrap();
    assert!(matches!(import_file(&good, &dest, &ImportOptions::default()), Err(ImportError::Io { .. })));
    assert_eq!(files_in(&dir.path().join("x")), ["y"]);
}

#[test]
fn destination_beside_the_source_or_in_a_folder() {
    let dir = tempfile::tempdir().unwrap();
    let src = Path::new("runs/felt-85g.csv");
    assert_eq!(destination(src, None), Path::new("runs/felt-85g"));
    assert_eq!(destination(src, Some(dir.path())), dir.path().join("felt-85g"));
    assert_eq!(destination(src, Some(Path::new("out/"))), Path::new("out/felt-85g"));
    assert_eq!(destination(src, Some(Path::new("out/x.wav"))), Path::new("out/x.wav"));
    // import_file into a folder.
    let csv = dir.path().join("in.csv");
    fs::write(&csv, "t,f\n0,1\n1,2\n").unwrap();
    let sub = dir.path().join("recs");
    fs::create_dir(&sub).unwrap();
    let w = import_file(&csv, &sub, &ImportOptions::default()).unwrap();
    assert_eq!(w.paths.wav, sub.join("in.wav"));
}

mod hostile {
    use super::super::{csv, npy};
    use proptest::prelude::*;
    use std::path::Path;

    proptest! {
        #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]

        /// Any bytes after a valid start give a value or an error, never a panic.
        #[test]
        fn npy_parser_never_panics(tail in proptest::collection::vec(any::<u8>(), 0..300), major in 1u8..4) {
            let mut b = b"\x93NUMPY".to_vec();
            b.extend([major, 0]);
            b.extend(tail);
            let _ = npy::parse(&b, Path::new("p.npy"));
        }

        /// Headers built from the literal alphabet, in a well-formed frame.
        #[test]
        fn npy_header_parser_never_panics(h in "[{}()\\[\\]',: 0-9a-zA-Z<>|=.L-]{0,80}") {
            let mut b = b"\x93NUMPY\x01\x00".to_vec();
            b.extend((h.len() as u16).to_le_bytes());
            b.extend(h.as_bytes());
            b.extend([0u8; 16]);
            let _ = npy::parse(&b, Path::new("p.npy"));
        }

        #[test]
        fn csv_parser_never_panics(text in "[0-9a-z.,;\t \"#\n\r\\[\\]()eE+-]{0,200}") {
            let _ = csv::parse(&text, Path::new("p.csv"), None);
        }
    }
}

#[cfg(unix)]
#[test]
fn a_source_that_is_not_a_regular_file_is_refused_before_it_is_read() {
    let dir = tempfile::tempdir().unwrap();
    // A .csv link to /dev/zero would otherwise be read until memory runs out.
    let zero = dir.path().join("zero.csv");
    std::os::unix::fs::symlink("/dev/zero", &zero).unwrap();
    let e = read(&zero, &ImportOptions::default()).unwrap_err().to_string();
    assert!(e.contains("zero.csv") && e.contains("not a regular file"), "{e}");
    let folder = dir.path().join("folder.csv");
    fs::create_dir(&folder).unwrap();
    let e = read(&folder, &ImportOptions::default()).unwrap_err().to_string();
    assert!(e.contains("cannot import a folder"), "{e}");
    // A link to a regular file is followed.
    let real = dir.path().join("real.csv");
    fs::write(&real, "t,force\n0,1\n0.001,2\n0.002,3\n").unwrap();
    let link = dir.path().join("link.csv");
    std::os::unix::fs::symlink(&real, &link).unwrap();
    assert_eq!(read(&link, &ImportOptions::default()).unwrap().frames, 3);
}
