//! A corpus of hostile and edge-case inputs, generated here, across every
//! format `acmw correct` reads: trials (quaternion and Euler CSV, `.sto`,
//! gzip, Xsens exports with their mapping), limit tables, settings, models,
//! calibration files and sidecars. Each runs the real binary in its own
//! folder, under an address-space limit and a wall-clock limit, and must end
//! in a correct result (exit 0, an output that reads back) or an error that
//! names the file and, for malformed content, the line and column (exit 3);
//! refusals that concern the file as a whole (a FIFO, a cap) say why. Never a
//! panic, an abort, a signal or a hang.

use acm_workbench::model::Model;
use acm_workbench::rotation::{euler_zyx_deg, quat_from_euler_zyx_deg, Quat};
use acm_workbench::trial::read_trial;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::fmt::Write as _;
use std::io::Write as _;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Address space each run may use, bytes.
const MEMORY_LIMIT: u64 = 3 << 30;
/// Wall-clock limit of one run (generous for a loaded 2-core machine; every
/// input here is tiny, a run takes well under a second).
const TIME_LIMIT: Duration = Duration::from_secs(60);
/// The input cap the runs get, MB (small, so that the cap is tested cheaply).
const INPUT_CAP_MB: &str = "16";

#[derive(Debug, Clone, Copy, PartialEq)]
enum Expect {
    /// Exit 0 and an output that reads back.
    Ok,
    /// Exit 3 and `file:line:column:` (or `file:line:` for a whole line)
    /// with a line and column >= 1 for the named file.
    Located(&'static str),
    /// Exit 1 or 3 and a message containing this text.
    Refused(&'static str),
    /// Either of `Ok` or a located error in the named file (random mutations).
    OkOrLocated(&'static str),
    /// Exit 3 and exactly this line on stderr (the place and the words).
    Exact(&'static str),
}

struct Case {
    name: String,
    /// Files to create: (relative path, bytes).
    files: Vec<(String, Vec<u8>)>,
    args: Vec<String>,
    expect: Expect,
}

fn case(
    name: impl Into<String>,
    files: Vec<(&str, Vec<u8>)>,
    args: &[&str],
    expect: Expect,
) -> Case {
    Case {
        name: name.into(),
        files: files.into_iter().map(|(p, b)| (p.to_string(), b)).collect(),
        args: args.iter().map(|s| s.to_string()).collect(),
        expect,
    }
}

fn orientations(n: usize, seed: u64) -> Vec<Quat> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            quat_from_euler_zyx_deg([
                rng.random_range(-179.0..179.0),
                rng.random_range(-80.0..80.0),
                rng.random_range(-179.0..179.0),
            ])
        })
        .collect()
}

/// A valid two-IMU trial of the infant model (`base`, `upper_back`) at 100 Hz.
fn quat_csv(times: &[f64]) -> String {
    let a = orientations(times.len(), 1);
    let b = orientations(times.len(), 2);
    let mut out = String::from("time,base_qw,base_qx,base_qy,base_qz,upper_back_qw,upper_back_qx,upper_back_qy,upper_back_qz\n");
    for (i, t) in times.iter().enumerate() {
        let (p, q) = (&a[i], &b[i]);
        let _ = writeln!(
            out,
            "{t},{},{},{},{},{},{},{},{}",
            p.w, p.i, p.j, p.k, q.w, q.i, q.j, q.k
        );
    }
    out
}

fn euler_csv(n: usize) -> String {
    let a = orientations(n, 3);
    let b = orientations(n, 4);
    let mut out = String::from(
        "time,base_roll,base_pitch,base_yaw,upper_back_roll,upper_back_pitch,upper_back_yaw\n",
    );
    for i in 0..n {
        let [r, p, y] = euler_zyx_deg(&a[i]);
        let [r2, p2, y2] = euler_zyx_deg(&b[i]);
        let _ = writeln!(out, "{},{r},{p},{y},{r2},{p2},{y2}", i as f64 / 100.0);
    }
    out
}

fn sto(n: usize) -> String {
    let a = orientations(n, 5);
    let b = orientations(n, 6);
    let mut out = String::from("\nDataRate=100.000000\nDataType=Quaternion\nversion=3\nOpenSimVersion=4.1\nendheader\ntime\tbase\tupper_back\n");
    for i in 0..n {
        let (p, q) = (&a[i], &b[i]);
        let _ = writeln!(
            out,
            "{}\t{},{},{},{}\t{},{},{},{}",
            i as f64 / 100.0,
            p.w,
            p.i,
            p.j,
            p.k,
            q.w,
            q.i,
            q.j,
            q.k
        );
    }
    out
}

fn times(n: usize) -> Vec<f64> {
    (0..n).map(|i| i as f64 / 100.0).collect()
}

fn gz(bytes: &[u8]) -> Vec<u8> {
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    e.write_all(bytes).unwrap();
    e.finish().unwrap()
}

/// Replaces line `k` (0-based) of `text`.
fn with_line(text: &str, k: usize, line: &str) -> String {
    let mut lines: Vec<&str> = text.lines().collect();
    lines[k] = line;
    lines.join("\n") + "\n"
}

/// Replaces the first cell `old` on line `k` by `new` (CSV).
fn with_cell(text: &str, k: usize, col: usize, new: &str) -> String {
    let line = text.lines().nth(k).unwrap();
    let mut cells: Vec<&str> = line.split(',').collect();
    cells[col] = new;
    with_line(text, k, &cells.join(","))
}

const CORRECT: &[&str] = &[
    "correct", "t.csv", "-o", "out.csv", "--quiet", "--model", "infant13",
];

fn trial_cases() -> Vec<Case> {
    let base = quat_csv(&times(200));
    let mut v = vec![case(
        "valid quat csv",
        vec![("t.csv", base.clone().into_bytes())],
        CORRECT,
        Expect::Ok,
    )];
    let cell_cases: [(&str, usize, usize, &str); 12] = [
        ("NaN cell", 5, 2, "NaN"),
        ("inf cell", 5, 2, "inf"),
        ("-inf time", 5, 0, "-inf"),
        ("empty cell", 7, 3, ""),
        ("text cell", 9, 4, "abc"),
        ("zero quaternion w", 3, 1, "0"),
        ("norm 2 quaternion", 3, 1, "2"),
        ("huge number", 4, 1, "1e308"),
        ("repeated time", 6, 0, "0.04"),
        ("time going back", 6, 0, "0.01"),
        ("time jump to 1e15 s", 100, 0, "1e15"),
        ("hex cell", 8, 2, "0x1p3"),
    ];
    for (name, k, col, new) in cell_cases {
        v.push(case(
            name,
            vec![("t.csv", with_cell(&base, k, col, new).into_bytes())],
            CORRECT,
            Expect::Located("t.csv"),
        ));
    }
    // The time axis: absurd but finite spans and rates.
    let mut t = times(200);
    t[199] = 1e300;
    v.push(case(
        "span 1e300 s",
        vec![("t.csv", quat_csv(&t).into_bytes())],
        CORRECT,
        Expect::Located("t.csv"),
    ));
    let t: Vec<f64> = (0..200).map(|i| i as f64 * 1e-9).collect();
    v.push(case(
        "1 GHz rate",
        vec![("t.csv", quat_csv(&t).into_bytes())],
        CORRECT,
        Expect::Located("t.csv"),
    ));
    let t: Vec<f64> = (0..200).map(|i| i as f64 * 7200.0).collect();
    v.push(case(
        "one sample per 2 h",
        vec![("t.csv", quat_csv(&t).into_bytes())],
        CORRECT,
        Expect::Located("t.csv"),
    ));
    let t: Vec<f64> = (0..400)
        .map(|i| i as f64 / 100.0 + if i >= 200 { 1e6 } else { 0.0 })
        .collect();
    v.push(case(
        "1e6-s pause in 4 s of data",
        vec![("t.csv", quat_csv(&t).into_bytes())],
        CORRECT,
        Expect::Ok,
    ));
    let t: Vec<f64> = (0..200).map(|i| 1.7e9 + i as f64 / 100.0).collect();
    v.push(case(
        "unix-epoch times",
        vec![("t.csv", quat_csv(&t).into_bytes())],
        CORRECT,
        Expect::Ok,
    ));
    let t: Vec<f64> = (0..200).map(|i| 1e12 + i as f64 / 100.0).collect();
    v.push(case(
        "times beyond 1e10 s",
        vec![("t.csv", quat_csv(&t).into_bytes())],
        CORRECT,
        Expect::Located("t.csv"),
    ));
    // Structure.
    let lines: Vec<&str> = base.lines().collect();
    v.push(case(
        "short row",
        vec![("t.csv", with_line(&base, 10, "0.09,1,0,0").into_bytes())],
        CORRECT,
        Expect::Located("t.csv"),
    ));
    v.push(case(
        "long row",
        vec![(
            "t.csv",
            with_line(&base, 10, &format!("{},1", lines[10])).into_bytes(),
        )],
        CORRECT,
        Expect::Located("t.csv"),
    ));
    v.push(case(
        "header only",
        vec![("t.csv", format!("{}\n", lines[0]).into_bytes())],
        CORRECT,
        Expect::Located("t.csv"),
    ));
    v.push(case(
        "empty file",
        vec![("t.csv", Vec::new())],
        CORRECT,
        Expect::Located("t.csv"),
    ));
    v.push(case(
        "blank lines only",
        vec![("t.csv", b"\n\n  \n".to_vec())],
        CORRECT,
        Expect::Located("t.csv"),
    ));
    v.push(case(
        "no time column",
        vec![("t.csv", base.replacen("time", "tiem", 1).into_bytes())],
        CORRECT,
        Expect::Located("t.csv"),
    ));
    v.push(case(
        "one sample",
        vec![("t.csv", lines[..2].join("\n").into_bytes())],
        CORRECT,
        Expect::OkOrLocated("t.csv"),
    ));
    v.push(case(
        "two samples",
        vec![("t.csv", lines[..3].join("\n").into_bytes())],
        CORRECT,
        Expect::OkOrLocated("t.csv"),
    ));
    let mut bom = vec![0xef, 0xbb, 0xbf];
    bom.extend(base.as_bytes());
    v.push(case("BOM", vec![("t.csv", bom)], CORRECT, Expect::Ok));
    v.push(case(
        "CRLF",
        vec![("t.csv", base.replace('\n', "\r\n").into_bytes())],
        CORRECT,
        Expect::Ok,
    ));
    let mut bad = base.clone().into_bytes();
    bad[300] = 0xff;
    v.push(case(
        "invalid UTF-8",
        vec![("t.csv", bad)],
        CORRECT,
        Expect::Located("t.csv"),
    ));
    v.push(case(
        "NUL bytes",
        vec![("t.csv", base.replacen(',', "\0,", 20).into_bytes())],
        CORRECT,
        Expect::Located("t.csv"),
    ));
    v.push(case(
        "1 MB cell",
        vec![(
            "t.csv",
            with_cell(&base, 4, 1, &"9".repeat(1 << 20)).into_bytes(),
        )],
        CORRECT,
        Expect::Located("t.csv"),
    ));
    v.push(case(
        "unknown IMUs only",
        vec![(
            "t.csv",
            base.replace("base_", "foo_")
                .replace("upper_back_", "bar_")
                .into_bytes(),
        )],
        CORRECT,
        Expect::OkOrLocated("t.csv"),
    ));
    v.push(case(
        "duplicate IMU columns",
        vec![(
            "t.csv",
            base.replacen("upper_back_", "base_", 4).into_bytes(),
        )],
        CORRECT,
        Expect::Located("t.csv"),
    ));
    // Euler CSV.
    let e = euler_csv(200);
    v.push(case(
        "valid euler csv",
        vec![("t.csv", e.clone().into_bytes())],
        CORRECT,
        Expect::Ok,
    ));
    v.push(case(
        "euler NaN",
        vec![("t.csv", with_cell(&e, 5, 1, "nan").into_bytes())],
        CORRECT,
        Expect::Located("t.csv"),
    ));
    v.push(case(
        "euler 1e300 deg",
        vec![("t.csv", with_cell(&e, 5, 2, "1e300").into_bytes())],
        CORRECT,
        Expect::OkOrLocated("t.csv"),
    ));
    v.push(case(
        "euler ragged",
        vec![("t.csv", with_line(&e, 5, "0.04,1,2").into_bytes())],
        CORRECT,
        Expect::Located("t.csv"),
    ));
    v.push(case(
        "euler missing yaw",
        vec![(
            "t.csv",
            e.replacen(",upper_back_yaw", ",upper_back_yyy", 1)
                .into_bytes(),
        )],
        CORRECT,
        Expect::OkOrLocated("t.csv"),
    ));
    // .sto.
    let s = sto(200);
    let sto_args: &[&str] = &[
        "correct", "t.sto", "-o", "out.sto", "--quiet", "--model", "infant13",
    ];
    v.push(case(
        "valid sto",
        vec![("t.sto", s.clone().into_bytes())],
        sto_args,
        Expect::Ok,
    ));
    v.push(case(
        "sto without endheader",
        vec![("t.sto", s.replace("endheader", "endhead").into_bytes())],
        sto_args,
        Expect::Located("t.sto"),
    ));
    v.push(case(
        "sto three parts",
        vec![(
            "t.sto",
            with_line(&s, 10, "0.03\t1,0,0\t1,0,0,0").into_bytes(),
        )],
        sto_args,
        Expect::Located("t.sto"),
    ));
    v.push(case(
        "sto NaN part",
        vec![(
            "t.sto",
            with_line(&s, 10, "0.03\t1,0,NaN,0\t1,0,0,0").into_bytes(),
        )],
        sto_args,
        Expect::Located("t.sto"),
    ));
    v.push(case(
        "sto ragged",
        vec![("t.sto", with_line(&s, 10, "0.03\t1,0,0,0").into_bytes())],
        sto_args,
        Expect::Located("t.sto"),
    ));
    v.push(case(
        "sto header only",
        vec![(
            "t.sto",
            s.lines()
                .take(7)
                .collect::<Vec<_>>()
                .join("\n")
                .into_bytes(),
        )],
        sto_args,
        Expect::Located("t.sto"),
    ));
    // gzip.
    let gz_args: &[&str] = &[
        "correct", "t.csv.gz", "-o", "out.csv", "--quiet", "--model", "infant13",
    ];
    v.push(case(
        "valid gzip",
        vec![("t.csv.gz", gz(base.as_bytes()))],
        gz_args,
        Expect::Ok,
    ));
    let g = gz(base.as_bytes());
    v.push(case(
        "truncated gzip",
        vec![("t.csv.gz", g[..g.len() / 2].to_vec())],
        gz_args,
        Expect::Refused("gzip"),
    ));
    v.push(case(
        "not gzip",
        vec![("t.csv.gz", base.clone().into_bytes())],
        gz_args,
        Expect::Refused("gzip"),
    ));
    v.push(case(
        "gzip not named .gz",
        vec![("t.csv", g.clone())],
        CORRECT,
        Expect::Located("t.csv"),
    ));
    v.push(case(
        "gzip bomb",
        vec![("t.csv.gz", gz(&vec![b'0'; 64 << 20]))],
        gz_args,
        Expect::Refused("decompressed data is more than 16 MB"),
    ));
    v.push(case(
        "raw size cap",
        vec![("t.csv", {
            let mut big = base.clone().into_bytes();
            big.resize(17 << 20, b'\n');
            big
        })],
        CORRECT,
        Expect::Refused("file is more than 16 MB"),
    ));
    v
}

/// Seeded random damage to a valid file: flipped bytes, lines deleted,
/// doubled or swapped, digits changed, garbage inserted.
fn mutate(text: &str, rng: &mut ChaCha8Rng) -> Vec<u8> {
    let mut lines: Vec<Vec<u8>> = text.lines().map(|l| l.as_bytes().to_vec()).collect();
    for _ in 0..rng.random_range(1..4) {
        let k = rng.random_range(0..lines.len());
        match rng.random_range(0..7) {
            0 => {
                lines.remove(k);
            }
            1 => {
                let l = lines[k].clone();
                lines.insert(k, l);
            }
            2 => {
                let j = rng.random_range(0..lines.len());
                lines.swap(k, j);
            }
            3 if !lines[k].is_empty() => {
                let i = rng.random_range(0..lines[k].len());
                lines[k][i] = rng.random();
            }
            4 if !lines[k].is_empty() => {
                let i = rng.random_range(0..lines[k].len());
                lines[k][i] = b"0123456789.-e,\t"[rng.random_range(0..15)];
            }
            5 => {
                let junk = [
                    "nan", "1e999", ",,,", "\"", "-0", "\u{feff}", "1e-320", "\t\t",
                ];
                lines[k].extend(junk[rng.random_range(0..junk.len())].as_bytes());
            }
            _ => {
                let cut = rng.random_range(0..=lines[k].len());
                lines[k].truncate(cut);
            }
        }
    }
    lines
        .join(&b'\n')
        .into_iter()
        .chain(std::iter::once(b'\n'))
        .collect()
}

fn mutation_cases() -> Vec<Case> {
    let mut rng = ChaCha8Rng::seed_from_u64(17);
    let base = quat_csv(&times(120));
    let s = sto(120);
    let e = euler_csv(120);
    let mut v = Vec::new();
    for k in 0..30 {
        v.push(case(
            format!("quat csv mutation {k}"),
            vec![("t.csv", mutate(&base, &mut rng))],
            CORRECT,
            Expect::OkOrLocated("t.csv"),
        ));
    }
    for k in 0..10 {
        v.push(case(
            format!("euler csv mutation {k}"),
            vec![("t.csv", mutate(&e, &mut rng))],
            CORRECT,
            Expect::OkOrLocated("t.csv"),
        ));
    }
    let sto_args: &[&str] = &[
        "correct", "t.sto", "-o", "out.sto", "--quiet", "--model", "infant13",
    ];
    for k in 0..10 {
        v.push(case(
            format!("sto mutation {k}"),
            vec![("t.sto", mutate(&s, &mut rng))],
            sto_args,
            Expect::OkOrLocated("t.sto"),
        ));
    }
    let settings = acm_workbench::limits::BUILTIN_SETTINGS;
    for k in 0..10 {
        v.push(case(
            format!("settings mutation {k}"),
            vec![
                ("t.csv", base.clone().into_bytes()),
                ("joint_limits/settings.toml", mutate(settings, &mut rng)),
            ],
            CORRECT,
            Expect::OkOrLocated("settings.toml"),
        ));
    }
    v
}

fn settings_cases() -> Vec<Case> {
    let base = quat_csv(&times(200)).into_bytes();
    let s = acm_workbench::limits::BUILTIN_SETTINGS;
    let with = |name: &str, text: String, expect| {
        case(
            name,
            vec![
                ("t.csv", base.clone()),
                ("joint_limits/settings.toml", text.into_bytes()),
            ],
            CORRECT,
            expect,
        )
    };
    let set = |key: &str, value: &str| {
        s.lines()
            .map(|l| {
                if l.starts_with(&format!("{key} =")) {
                    format!("{key} = {value}")
                } else {
                    l.to_string()
                }
            })
            .collect::<Vec<_>>()
            .join("\n")
    };
    let mut v = vec![
        with("valid settings", s.to_string(), Expect::Ok),
        with(
            "unknown key lambda_1",
            format!("{s}lambda_1 = 5\n"),
            Expect::Located("settings.toml"),
        ),
        with(
            "hop 0",
            set("hop_s", "0"),
            Expect::Exact("acmw: joint_limits/settings.toml:7:1: hop_s: expected a number of seconds between window_s / 1000 (0.06) and window_s (60), found 0"),
        ),
        with(
            "negative hop",
            set("hop_s", "-3"),
            Expect::Located("settings.toml"),
        ),
        with(
            "window 0",
            set("window_s", "0"),
            Expect::Located("settings.toml"),
        ),
        with(
            "window 1e300",
            set("window_s", "1e300"),
            Expect::Located("settings.toml"),
        ),
        with(
            "lambda1 -5",
            set("lambda1", "-5"),
            Expect::Exact("acmw: joint_limits/settings.toml:4:1: lambda1: expected a finite weight per degree in [0, 1000000], found -5"),
        ),
        with(
            "lambda1 nan",
            set("lambda1", "nan"),
            Expect::Located("settings.toml"),
        ),
        with(
            "glitch 500",
            format!("{s}  glitch_deg = 500\n").replace("glitch_deg = 30\n", ""),
            Expect::Exact("acmw: joint_limits/settings.toml:13:3: glitch_deg: expected a number of degrees in (0, 180], found 500"),
        ),
        with(
            "precision 18",
            set("precision", "18"),
            Expect::Located("settings.toml"),
        ),
        with(
            "precision word",
            set("precision", "\"most\""),
            Expect::Located("settings.toml"),
        ),
        with(
            "table missing",
            set("table", "\"nope.csv\""),
            Expect::Exact("acmw: joint_limits/settings.toml:2:1: expected a limit table in joint_limits or a built-in one, found no 'nope.csv'"),
        ),
        with(
            "syntax error",
            format!("{s}[[[\n"),
            Expect::Located("settings.toml"),
        ),
        with(
            "vertical sideways",
            set("vertical", "\"sideways\""),
            Expect::Located("settings.toml"),
        ),
        with(
            "string for a number",
            set("lambda1", "\"five\""),
            Expect::Located("settings.toml"),
        ),
    ];
    let tiny = set("window_s", "1e-6").replace("hop_s = 30.0", "hop_s = 1e-6");
    v.push(with(
        "window = hop = 1e-6",
        tiny,
        Expect::Refused("fewer than 4 samples"),
    ));
    let flags = |name: &str, extra: &[&str], expect| {
        let mut args = CORRECT.to_vec();
        args.extend_from_slice(extra);
        case(name, vec![("t.csv", base.clone())], &args, expect)
    };
    // A value from a flag is blamed on the flag, with what was expected.
    v.push(flags(
        "--hop 0",
        &["--hop", "0"],
        Expect::Exact("acmw: --hop: expected a number of seconds between window_s / 1000 (0.06) and window_s (60), found 0"),
    ));
    v.push(flags(
        "--window -1",
        &["--window=-1"],
        Expect::Exact(
            "acmw: --window: expected a positive number of seconds, at most 1e7, found -1",
        ),
    ));
    v.push(flags(
        "--lambda1 inf",
        &["--lambda1", "inf"],
        Expect::Exact(
            "acmw: --lambda1: expected a finite weight per degree in [0, 1000000], found inf",
        ),
    ));
    v.push(flags(
        "--window 0.5 --hop 1e-6",
        &["--window", "0.5", "--hop", "1e-6"],
        Expect::Exact("acmw: --hop: expected a number of seconds between window_s / 1000 (0.0005) and window_s (0.5), found 0.000001"),
    ));
    v.push(flags(
        "--window 0.5 with the settings' hop",
        &["--window", "0.5"],
        Expect::Exact("acmw: --window: the settings' hop_s does not suit it: expected a number of seconds between window_s / 1000 (0.0005) and window_s (0.5), found 30; give --hop too"),
    ));
    v.push(flags(
        "--window 0.02 on 100 Hz",
        &["--window", "0.02", "--hop", "0.02"],
        Expect::Refused("fewer than 4 samples"),
    ));
    v
}

fn table_model_calibration_cases() -> Vec<Case> {
    let base = quat_csv(&times(200)).into_bytes();
    let table = acm_workbench::limits::BUILTIN_TABLES[0].1;
    let lim = |name: &str, text: String, expect| {
        let mut args = CORRECT.to_vec();
        args.extend_from_slice(&["--limits", "l.csv"]);
        case(
            name,
            vec![("t.csv", base.clone()), ("l.csv", text.into_bytes())],
            &args,
            expect,
        )
    };
    let header = "joint,axis,movement,lower_deg,upper_deg,centroid_deg,lambda2";
    let mut v = vec![
        lim("valid table", table.to_string(), Expect::Ok),
        lim(
            "bad table header",
            table.replacen(header, "joint,axis,lower", 1),
            Expect::Located("l.csv"),
        ),
        lim(
            "bad axis",
            format!("{table}back,W,x,0,1,,0\n"),
            Expect::Located("l.csv"),
        ),
        lim(
            "limit 1000 deg",
            format!("{table}hip,X,x,0,1000,,0\n"),
            Expect::Located("l.csv"),
        ),
        lim(
            "duplicate row",
            format!(
                "{table}{}\n",
                table
                    .lines()
                    .find(|l| l.starts_with("back,X"))
                    .unwrap_or("back,X,x,0,1,,0")
            ),
            Expect::Located("l.csv"),
        ),
        lim(
            "quoted joint with comma",
            format!("{table}\"a,b\",X,x,0,1,,0\n\"a,b\",Y,y,0,1,,0\n\"a,b\",Z,z,0,1,,0\n"),
            Expect::Ok,
        ),
        lim(
            "ragged table row",
            format!("{table}back,X\n"),
            Expect::Located("l.csv"),
        ),
        lim("empty table", String::new(), Expect::Located("l.csv")),
    ];
    let model = acm_workbench::model::BUILTIN_MODELS[0].1;
    let m = |name: &str, text: String, expect| {
        let args = [
            "correct", "t.csv", "-o", "out.csv", "--quiet", "--model", "m.toml",
        ];
        case(
            name,
            vec![("t.csv", base.clone()), ("m.toml", text.into_bytes())],
            &args,
            expect,
        )
    };
    v.push(m("valid model file", model.to_string(), Expect::Ok));
    v.push(m(
        "model unknown key",
        model.replacen("base = ", "basis = \"x\"\nbase = ", 1),
        Expect::Located("m.toml"),
    ));
    v.push(m(
        "model joint unknown key",
        model.replacen("kind = \"back\"", "kind = \"back\"\nkinds = 3", 1),
        Expect::Located("m.toml"),
    ));
    v.push(m(
        "model syntax error",
        format!("{model}\n[[joint\n"),
        Expect::Located("m.toml"),
    ));
    let cycle = model.replacen(
        "proximal = \"base\"\ndistal = \"upper_back\"",
        "proximal = \"upper_back\"\ndistal = \"base\"",
        1,
    );
    let at = line_of(&cycle, "proximal = \"upper_back\"");
    v.push(m(
        "model cycle",
        cycle,
        exact(format!("acmw: m.toml:{at}:1: joint 'back': proximal IMU 'upper_back' must be the base or the distal IMU of an earlier joint (correction order)")),
    ));
    let nobody = model.replacen("base = \"base\"", "base = \"nobody\"", 1);
    let at = line_of(&nobody, "base = \"nobody\"");
    v.push(m(
        "model base not an imu",
        nobody,
        exact(format!(
            "acmw: m.toml:{at}:1: base IMU 'nobody' is not in `imus`"
        )),
    ));
    // `imus` lists base first: a second "base" in the list.
    let twice = model.replacen("imus = [", "imus = [\"base\", ", 1);
    let at = line_of(&twice, "imus = [");
    v.push(m(
        "model IMU listed twice",
        twice,
        exact(format!(
            "acmw: m.toml:{at}:17: IMU 'base' is listed twice in `imus`"
        )),
    ));
    // Coverage: a table without the knee's Y row points at the knee's rows.
    let no_knee_y: String = table
        .lines()
        .filter(|l| !l.starts_with("knee,Y,"))
        .map(|l| format!("{l}\n"))
        .collect();
    let at = line_of(&no_knee_y, "knee,");
    v.push(lim(
        "table without knee Y",
        no_knee_y,
        exact(format!("acmw: l.csv:{at}:2: no row for joint 'l_knee' (kind 'knee') axis Y of model 'infant13': expected a row `knee,Y,...`")),
    ));
    let cal = |name: &str, text: &str, expect| {
        let mut args = CORRECT.to_vec();
        args.extend_from_slice(&["--calibration", "c.toml"]);
        case(
            name,
            vec![
                ("t.csv", base.clone()),
                ("c.toml", text.as_bytes().to_vec()),
            ],
            &args,
            expect,
        )
    };
    v.push(cal(
        "calibration garbage",
        "this is not toml\n",
        Expect::Located("c.toml"),
    ));
    v.push(cal(
        "calibration unknown key",
        "program = \"acmw\"\nversion = \"0\"\nfoo = 1\n",
        Expect::Located("c.toml"),
    ));
    v.push(cal("calibration empty", "", Expect::Located("c.toml")));
    v
}

#[cfg(unix)]
fn special_file_cases() -> Vec<Case> {
    // Created by the runner (FIFO, device link, folder); see `make_special`.
    vec![
        case("FIFO named t.csv", vec![], CORRECT, Expect::Refused("FIFO")),
        case(
            "symlink to /dev/zero",
            vec![],
            CORRECT,
            Expect::Refused("a device"),
        ),
        case(
            "folder named l.csv",
            vec![("t.csv", quat_csv(&times(100)).into_bytes())],
            &[CORRECT, &["--limits", "l.csv"]].concat(),
            Expect::Refused("folder"),
        ),
    ]
}

#[cfg(unix)]
fn make_special(name: &str, dir: &Path) {
    match name {
        "FIFO named t.csv" => {
            let c = std::ffi::CString::new(dir.join("t.csv").to_str().unwrap()).unwrap();
            // SAFETY: a valid NUL-terminated path.
            assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        }
        "symlink to /dev/zero" => {
            std::os::unix::fs::symlink("/dev/zero", dir.join("t.csv")).unwrap()
        }
        "folder named l.csv" => std::fs::create_dir(dir.join("l.csv")).unwrap(),
        _ => {}
    }
}

/// An MT Manager export of `counters` with this rate comment.
fn export(counters: &[u64], rate: &str, seed: u64) -> String {
    let mut out = format!(
        "// Start Time: Unknown\n// Update Rate: {rate}\n// Filter Profile: human (46.1)\n"
    );
    out.push_str("PacketCounter\tSampleTimeFine\tQuat_q0\tQuat_q1\tQuat_q2\tQuat_q3\n");
    for (c, q) in counters.iter().zip(orientations(counters.len(), seed)) {
        let _ = writeln!(
            out,
            "{:05}\t\t{}\t{}\t{}\t{}",
            c % 65536,
            q.w,
            q.i,
            q.j,
            q.k
        );
    }
    out
}

fn mapping(prefix: &str) -> String {
    let mut out = format!("<?xml version=\"1.0\" encoding=\"UTF-8\" ?>\n<OpenSimDocument Version=\"40000\">\n\t<XsensDataReaderSettings>\n\t\t<trial_prefix>{prefix}</trial_prefix>\n\t\t<ExperimentalSensors>\n");
    for (serial, name) in [("00B1", "base"), ("00B2", "upper_back")] {
        let _ = write!(out, "\t\t\t<ExperimentalSensor name=\"_{serial}\">\n\t\t\t\t<name_in_model>{name}</name_in_model>\n\t\t\t</ExperimentalSensor>\n");
    }
    out.push_str("\t\t</ExperimentalSensors>\n\t</XsensDataReaderSettings>\n</OpenSimDocument>\n");
    out
}

fn xsens_cases() -> Vec<Case> {
    let args: &[&str] = &[
        "correct", "m.xml", "-o", "out.sto", "--quiet", "--model", "infant13",
    ];
    let rec = |name: &str, rate: &str, a: Vec<u64>, b: Vec<u64>, prefix: &str, expect| {
        case(
            name,
            vec![
                ("m.xml", mapping(prefix).into_bytes()),
                ("MT_01_00B1.txt", export(&a, rate, 1).into_bytes()),
                ("MT_01_00B2.txt", export(&b, rate, 2).into_bytes()),
            ],
            args,
            expect,
        )
    };
    let c: Vec<u64> = (100..300).collect();
    vec![
        rec(
            "valid xsens",
            "100.0Hz",
            c.clone(),
            c.clone(),
            "MT_01",
            Expect::Ok,
        ),
        rec(
            "update rate 1e-300 Hz",
            "1e-300Hz",
            c.clone(),
            c.clone(),
            "MT_01",
            Expect::Exact("acmw: ./MT_01_00B1.txt:2:17: update rate 1e-300 Hz: expected a finite rate from one sample an hour to 100000 Hz (a sample interval between 0.00001 s and 3600 s)"),
        ),
        rec(
            "update rate inf Hz",
            "infHz",
            c.clone(),
            c.clone(),
            "MT_01",
            Expect::Exact("acmw: ./MT_01_00B1.txt:2:17: update rate 'infHz' is invalid: expected a finite positive rate in Hz, found inf"),
        ),
        rec(
            "update rate 0 Hz",
            "0Hz",
            c.clone(),
            c.clone(),
            "MT_01",
            Expect::Exact("acmw: ./MT_01_00B1.txt:2:17: update rate '0Hz' is invalid: expected a finite positive rate in Hz, found 0"),
        ),
        rec(
            "update rate NaN",
            "NaNHz",
            c.clone(),
            c.clone(),
            "MT_01",
            Expect::Exact("acmw: ./MT_01_00B1.txt:2:17: update rate 'NaNHz' is invalid: expected a finite positive rate in Hz, found NaN"),
        ),
        rec(
            "update rate -100 Hz",
            "-100 Hz",
            c.clone(),
            c.clone(),
            "MT_01",
            Expect::Exact("acmw: ./MT_01_00B1.txt:2:17: update rate '-100 Hz' is invalid: expected a finite positive rate in Hz, found -100"),
        ),
        rec(
            "update rate not a number",
            "fast",
            c.clone(),
            c.clone(),
            "MT_01",
            Expect::Exact("acmw: ./MT_01_00B1.txt:2:17: update rate 'fast' is invalid: expected a rate in Hz such as 100.0Hz"),
        ),
        rec(
            "no common packet",
            "100Hz",
            (100..200).collect(),
            (200..300).collect(),
            "MT_01",
            Expect::Refused("share no packet"),
        ),
        rec(
            "interleaved packets only",
            "100Hz",
            (100..300).step_by(2).collect(),
            (101..300).step_by(2).collect(),
            "MT_01",
            Expect::Refused("share no packet"),
        ),
        rec(
            "trial_prefix ../",
            "100Hz",
            c.clone(),
            c.clone(),
            "../MT_01",
            Expect::Located("m.xml"),
        ),
        rec(
            "trial_prefix absolute",
            "100Hz",
            c.clone(),
            c,
            "/etc/MT_01",
            Expect::Located("m.xml"),
        ),
    ]
}

/// 1-based line of the first line of `text` that starts with `start`.
fn line_of(text: &str, start: &str) -> usize {
    1 + text
        .lines()
        .position(|l| l.trim_start().starts_with(start))
        .unwrap_or_else(|| panic!("no line starting {start:?}"))
}

/// [`Expect::Exact`] of a message built at run time.
fn exact(line: String) -> Expect {
    Expect::Exact(Box::leak(line.into_boxed_str()))
}

/// Runs one case in a fresh folder; `None` when it behaved, else what went wrong.
fn run(c: &Case) -> Option<String> {
    let dir = tempfile::tempdir().unwrap();
    for (p, bytes) in &c.files {
        let path = dir.path().join(p);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, bytes).unwrap();
    }
    #[cfg(unix)]
    make_special(&c.name, dir.path());
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_acmw"));
    cmd.current_dir(dir.path())
        .args(&c.args)
        .env("ACMW_MAX_INPUT_MB", INPUT_CAP_MB)
        .env("RUST_BACKTRACE", "0")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    #[cfg(unix)]
    {
        use std::os::unix::process::CommandExt;
        // SAFETY: setrlimit is async-signal-safe.
        unsafe {
            cmd.pre_exec(|| {
                let lim = libc::rlimit {
                    rlim_cur: MEMORY_LIMIT,
                    rlim_max: MEMORY_LIMIT,
                };
                libc::setrlimit(libc::RLIMIT_AS, &lim);
                Ok(())
            });
        }
    }
    let start = Instant::now();
    let mut child = cmd.spawn().unwrap();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if start.elapsed() > TIME_LIMIT {
            let _ = child.kill();
            let _ = child.wait();
            return Some(format!("still running after {TIME_LIMIT:?}"));
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    let Some(code) = status.code() else {
        return Some(format!("killed by a signal ({status:?}): {stderr}"));
    };
    // `file:line:column: ...`, or `file:line: ...` when the whole line is meant.
    let located = |file: &str| -> bool {
        stderr.lines().any(|l| {
            let Some(i) = l.find(file) else { return false };
            let mut parts = l[i + file.len()..].splitn(4, ':');
            parts.next() == Some("")
                && parts
                    .next()
                    .and_then(|n| n.parse::<u64>().ok())
                    .is_some_and(|n| n >= 1)
                && parts
                    .next()
                    .is_some_and(|n| n.parse::<u64>().is_ok_and(|c| c >= 1) || n.starts_with(' '))
        })
    };
    let output_reads_back = || {
        let out = ["out.csv", "out.sto"]
            .iter()
            .map(|n| dir.path().join(n))
            .find(|p| p.exists());
        let Some(out) = out else { return false };
        read_trial(&out, &Model::infant13()).is_ok()
            && acm_workbench::sidecar::sidecar_path(&out).exists()
    };
    let ok = match c.expect {
        Expect::Ok => code == 0 && output_reads_back(),
        Expect::Located(f) => code == 3 && located(f),
        Expect::Refused(s) => (code == 1 || code == 3) && stderr.contains(s),
        Expect::OkOrLocated(f) => (code == 0 && output_reads_back()) || (code == 3 && located(f)),
        Expect::Exact(line) => code == 3 && stderr.lines().any(|l| l == line),
    };
    (!ok).then(|| format!("exit {code}, expected {:?}: {stderr}", c.expect))
}

fn all_cases() -> Vec<Case> {
    let mut v = trial_cases();
    v.extend(settings_cases());
    v.extend(table_model_calibration_cases());
    v.extend(xsens_cases());
    #[cfg(unix)]
    v.extend(special_file_cases());
    v.extend(mutation_cases());
    v
}

#[test]
fn hostile_corpus_ends_in_results_or_located_errors() {
    let cases = all_cases();
    assert!(cases.len() >= 100, "only {} cases", cases.len());
    let failures: Vec<String> = cases
        .iter()
        .filter_map(|c| run(c).map(|why| format!("{}: {why}", c.name)))
        .collect();
    assert!(
        failures.is_empty(),
        "{} of {} cases misbehaved:\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n")
    );
}

/// `--from-sidecar` with an edited sidecar: the error names the sidecar and
/// the line and column of the key at fault in it (exit 3).
#[test]
fn sidecar_errors_point_at_the_key() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("t.csv"), quat_csv(&times(200))).unwrap();
    let acmw = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_acmw"))
            .current_dir(dir.path())
            .args(args)
            .output()
            .unwrap()
    };
    let out = acmw(CORRECT);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(dir.path().join("out.csv.acmw.json")).unwrap();
    let json: serde_json::Value = serde_json::from_str(&text).unwrap();
    let hash = json["limits"]["sha256"].as_str().unwrap();
    let hash_key = format!("\"sha256\": \"{hash}\"");
    let edited_hash = format!("\"sha256\": \"0{}\"", &hash[1..]);
    let cases = [
        (
            "\"hop_s\": 30.0",
            "\"hop_s\": 0.0",
            "settings.hop_s: expected a number of seconds between window_s / 1000 (0.06) and window_s (60), found 0",
        ),
        (
            "\"lambda1\": 0.05",
            "\"lambda1\": -5.0",
            "settings.lambda1: expected a finite weight per degree in [0, 1000000], found -5",
        ),
        (
            "\"base\": \"base\"",
            "\"base\": \"nobody\"",
            "model: base IMU 'nobody' is not in `imus`",
        ),
        (
            "\"proximal\": \"base\"",
            "\"proximal\": \"head\"",
            "model: joint 'back': proximal IMU 'head' must be the base or the distal IMU of an earlier joint (correction order)",
        ),
        (
            &hash_key,
            &edited_hash,
            "limits.csv does not match limits.sha256 (the sidecar was edited?)",
        ),
    ];
    for (from, to, message) in cases {
        let edited = text.replacen(from, to, 1);
        assert_ne!(edited, text, "{from} not in the sidecar");
        std::fs::write(dir.path().join("s.json"), &edited).unwrap();
        let at = edited.find(to).unwrap();
        let line = edited[..at].matches('\n').count() + 1;
        let column = at - edited[..at].rfind('\n').map_or(0, |i| i + 1) + 1;
        let out = acmw(&[
            "correct",
            "t.csv",
            "--from-sidecar",
            "s.json",
            "-o",
            "again.csv",
            "--quiet",
        ]);
        assert_eq!(
            (
                out.status.code(),
                String::from_utf8_lossy(&out.stderr).into_owned()
            ),
            (
                Some(3),
                format!("acmw: s.json:{line}:{column}: {message}\n")
            ),
            "{from} -> {to}"
        );
    }
}
