//! A trial another program appends to, opened in the workbench: the rows
//! land in fragments (lines cut anywhere), the follow job is stepped by
//! hand and its messages go through `update`, so nothing sleeps: a solve
//! is awaited on its channel.

use crate::acm::Variant;
use crate::correct::pipeline::{self, Preparation, Setup};
use crate::limits::LimitTable;
use crate::trial::{read_trial_from_str, trial_to_string, TrialFormat};
use crate::ui::app::{act, update, App, Effect, Msg};
use crate::ui::headless::{buffer_text, draw, load_app};
use crate::ui::jobs::live::LiveJob;
use crate::ui::jobs::SyncRunner;
use crate::ui::keymap::Action;
use crate::ui::msg::Screen;
use crate::ui::theme::Theme;
use rand::{Rng, SeedableRng};
use std::io::Write;
use std::path::Path;
use std::time::Duration;

/// Byte offset of data row `k` (0-based) of a trial file's text.
fn row_at(text: &str, k: usize) -> usize {
    text.split_inclusive('\n').take(k + 1).map(str::len).sum()
}

/// Duration of the open trial as read so far, seconds.
fn l_duration(app: &App) -> f64 {
    app.open_entry()
        .unwrap()
        .loaded()
        .unwrap()
        .trial
        .duration_s()
}

/// Feeds a follow job's messages to the workbench (they cause no effects
/// while the trial grows).
fn feed(app: &mut App, msgs: Vec<Msg>) {
    for m in msgs {
        let fx = update(app, m);
        assert!(fx.is_empty(), "{fx:?}");
    }
}

/// Waits for every solve asked for (on the solver's channel).
fn settle(app: &mut App, live: &mut LiveJob) {
    while live.solving() {
        let msgs = live.wait_solved(Duration::from_secs(300));
        feed(app, msgs);
    }
}

/// Appends `text` to `path` in random fragments (cut anywhere, lines
/// included), stepping the follow after each.
fn append_in_fragments(
    path: &Path,
    text: &str,
    rng: &mut rand_chacha::ChaCha8Rng,
    app: &mut App,
    live: &mut LiveJob,
) {
    let mut f = std::fs::OpenOptions::new().append(true).open(path).unwrap();
    let bytes = text.as_bytes();
    let mut at = 0;
    while at < bytes.len() {
        let n = rng.random_range(1..4000).min(bytes.len() - at);
        f.write_all(&bytes[at..at + n]).unwrap();
        f.flush().unwrap();
        at += n;
        let msgs = live.step().unwrap();
        feed(app, msgs);
    }
}

/// The corrected orientations of the first `n` rows of `text`, as
/// `acmw correct` corrects a trial of those rows.
fn offline(text: &str, n: usize, app: &App) -> crate::trial::Trial {
    let model = crate::model::Model::infant13();
    let lines: Vec<&str> = text.split_inclusive('\n').collect();
    let prefix = lines[..n + 1].concat();
    let trial = read_trial_from_str(&prefix, "live.csv", TrialFormat::QuatCsv, &model).unwrap();
    let table: &LimitTable = &app.limits.table;
    let setup = Setup {
        model: &model,
        limits: table,
        limits_source: &app.limits.source,
        settings: &app.settings,
    };
    let p = pipeline::prepare(trial, setup, &Preparation::default()).unwrap();
    pipeline::correct(&p.trial, setup, Variant::Drift, &Default::default())
        .unwrap()
        .corrected
}

#[test]
fn a_growing_trial_scrolls_and_its_solved_part_grows() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("trials");
    std::fs::create_dir_all(&dir).unwrap();
    let mut cfg = crate::simulate::preset("knee_calf_z15").unwrap();
    cfg.duration_s = 80.0;
    let sim = crate::simulate::simulate(&cfg).unwrap();
    let text = trial_to_string(&sim.trial, TrialFormat::QuatCsv);
    // The recorder has created the file (empty) when the workbench starts.
    let path = dir.join("live.csv");
    std::fs::write(&path, "").unwrap();
    let mut app = load_app("trials", &dir, &tmp.path().join("joint_limits")).unwrap();
    assert_eq!(app.variant, Variant::Drift);
    // The folder watcher reports the change: the trial is followed.
    let fx = update(&mut app, Msg::FileChanged("live.csv".into(), path.clone()));
    let [Effect::Follow(job)] = fx.as_slice() else {
        panic!("{fx:?}")
    };
    let mut live = LiveJob::new((**job).clone());
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(21);
    // 25 s of rows (1250, trial length n dt) and half a line.
    let cut = row_at(&text, 1250) + 3;
    append_in_fragments(&path, &text[..cut], &mut rng, &mut app, &mut live);
    let e = app.entry("live.csv").unwrap();
    let l = e.loaded().expect("the rows so far are shown");
    // The half line is not read: the last row is the one before it.
    assert!(
        (l.trial.duration_s() - 25.0).abs() < 1e-6,
        "{}",
        l.trial.duration_s()
    );
    assert_eq!(l.trial.len(), 1250);
    assert_eq!(e.variant_status(Variant::Drift), "live");
    act(&mut app, Action::Enter);
    assert_eq!(app.screen, Screen::Trial);
    // Opened at its newest sample.
    assert_eq!(app.view.cursor_s, l_duration(&app));
    settle(&mut app, &mut live);
    let v = app.entry("live.csv").unwrap().live.clone().unwrap();
    // Solved on the rows before 20 s (the newest warm-up point reached).
    assert_eq!(v.solved, 1000);
    assert!(!v.solving);
    // The solved part is the offline correction of those rows, bit for bit.
    let want = offline(&text, 1000, &app);
    for (got, want) in v.corrected.imus.iter().zip(&want.imus) {
        assert_eq!(got.orientation[..1000], want.orientation[..]);
    }
    let theme = Theme::builtin("dark", true).unwrap();
    let count = |text: &str, c: char| text.matches(c).count();
    let mut first = String::new();
    for (w, h) in crate::ui::tests::SIZES {
        let t = buffer_text(&draw(&app, &theme, w, h));
        // Solved and extrapolated are told apart without colour, and named.
        assert!(
            count(&t, '░') > 0 && (count(&t, '▄') + count(&t, '▀')) > 0,
            "{t}"
        );
        assert!(t.contains("ext") && t.contains("LIVE 1250"), "{t}");
        if w >= 120 {
            assert!(t.contains("solved 0-20.0 s, extrapolated after"), "{t}");
        }
        insta::assert_snapshot!(format!("live_trial_{w}x{h}"), t);
        if w == 120 {
            first = t;
        }
    }
    assert!(first.contains("t 0.0-25.0 s"), "{first}");
    // Keys act at once while the trial grows: zoom in (about the cursor,
    // at the end), and the view stays on the newest rows as they land.
    act(&mut app, Action::ZoomIn);
    let cut2 = row_at(&text, 3500);
    append_in_fragments(&path, &text[cut..cut2], &mut rng, &mut app, &mut live);
    let d = app
        .open_entry()
        .unwrap()
        .loaded()
        .unwrap()
        .trial
        .duration_s();
    assert!((d - 70.0).abs() < 1e-6, "{d}");
    let (s0, s1) = app.view.span(d);
    assert!(
        (s1 - d).abs() < 1e-9 && (s0 - d / 2.0).abs() < 1e-9,
        "{s0} {s1}"
    );
    assert_eq!(app.view.cursor_s, d);
    settle(&mut app, &mut live);
    let v2 = app.entry("live.csv").unwrap().live.clone().unwrap();
    // The first window is complete: solved on the rows before 60 s.
    assert_eq!(v2.solved, 3000);
    let want = offline(&text, 3000, &app);
    for (got, want) in v2.corrected.imus.iter().zip(&want.imus) {
        assert_eq!(got.orientation[..3000], want.orientation[..]);
    }
    let second = buffer_text(&draw(&app, &theme, 120, 40));
    assert!(second.contains("t 35.0-70.0 s"), "{second}");
    assert!(second.contains("solved 0-60.0 s"), "{second}");
    // Panned away from the end, the view stays where it was put.
    act(&mut app, Action::Left);
    let before = app.view.span(d);
    append_in_fragments(&path, &text[cut2..], &mut rng, &mut app, &mut live);
    let d = app
        .open_entry()
        .unwrap()
        .loaded()
        .unwrap()
        .trial
        .duration_s();
    assert!((d - 80.0).abs() < 0.03, "{d}");
    assert_eq!(app.view.span(d).0, before.0);
    settle(&mut app, &mut live);
    // The writer stops: the trial is read whole and every variant corrected.
    let fx = update(&mut app, live.finish(Ok(())));
    assert!(matches!(fx.as_slice(), [Effect::Load { .. }]), "{fx:?}");
    SyncRunner::run(&mut app, fx);
    let e = app.entry("live.csv").unwrap();
    assert!(e.live.is_none() && e.following.is_none());
    assert_eq!(e.results.len(), Variant::ALL.len());
    let n = e.loaded().unwrap().trial.len();
    assert_eq!(n, sim.trial.len());
    let want = offline(&text, n, &app);
    assert_eq!(
        e.results[&Variant::Drift].correction.corrected.imus,
        want.imus
    );
}

/// A file rewritten from its start while followed is read again from its
/// start, and the workbench says so.
#[test]
fn a_truncated_growing_trial_starts_over() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("trials");
    std::fs::create_dir_all(&dir).unwrap();
    let mut cfg = crate::simulate::preset("knee_calf_z15").unwrap();
    cfg.duration_s = 8.0;
    let sim = crate::simulate::simulate(&cfg).unwrap();
    let text = trial_to_string(&sim.trial, TrialFormat::QuatCsv);
    let path = dir.join("live.csv");
    std::fs::write(&path, &text).unwrap();
    let mut app = load_app("trials", &dir, &tmp.path().join("joint_limits")).unwrap();
    let fx = update(&mut app, Msg::FileChanged("live.csv".into(), path.clone()));
    let [Effect::Follow(job)] = fx.as_slice() else {
        panic!("{fx:?}")
    };
    let mut live = LiveJob::new((**job).clone());
    feed(&mut app, live.step().unwrap());
    assert_eq!(
        app.entry("live.csv").unwrap().loaded().unwrap().trial.len(),
        400
    );
    let short = row_at(&text, 101);
    std::fs::write(&path, &text[..short]).unwrap();
    feed(&mut app, live.step().unwrap());
    let (msg, is_error) = app.message.clone().unwrap();
    assert!(is_error && msg.contains("was truncated"), "{msg}");
    feed(&mut app, live.step().unwrap());
    assert_eq!(
        app.entry("live.csv").unwrap().loaded().unwrap().trial.len(),
        101
    );
    // Another follow of the same trial (a new variant) makes this one's news stale.
    act(&mut app, Action::Variant);
    let stale = live.finish(Ok(()));
    assert!(update(&mut app, stale).is_empty());
    assert!(app.entry("live.csv").unwrap().following.is_some());
}

/// `w` while the trial grows is refused with a status message (a half trial
/// saved under the final output's name would pass for the whole one); once
/// the writer stopped and the trial was corrected whole, `w` saves, and the
/// sidecar records the file's SHA-256, so that a new session finds the
/// output saved. The live trial's source carries the hash of the bytes read.
#[test]
fn a_save_waits_for_the_final_correction_and_records_the_file_hash() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("trials");
    std::fs::create_dir_all(&dir).unwrap();
    let limits = tmp.path().join("joint_limits");
    let mut cfg = crate::simulate::preset("knee_calf_z15").unwrap();
    cfg.duration_s = 30.0;
    let sim = crate::simulate::simulate(&cfg).unwrap();
    let text = trial_to_string(&sim.trial, TrialFormat::QuatCsv);
    let path = dir.join("live.csv");
    std::fs::write(&path, "").unwrap();
    let mut app = load_app("trials", &dir, &limits).unwrap();
    let fx = update(&mut app, Msg::FileChanged("live.csv".into(), path.clone()));
    let [Effect::Follow(job)] = fx.as_slice() else {
        panic!("{fx:?}")
    };
    let mut live = LiveJob::new((**job).clone());
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(16);
    // 14 s of rows and part of the next line.
    let cut = row_at(&text, 700) + 5;
    append_in_fragments(&path, &text[..cut], &mut rng, &mut app, &mut live);
    settle(&mut app, &mut live);
    let hash_of_file = || crate::input::sha256_hex(&std::fs::read(&path).unwrap());
    let l = app.entry("live.csv").unwrap().loaded().unwrap().clone();
    assert_eq!(l.trial.len(), 700);
    // Every byte written so far was read (the half line too): its hash.
    assert_eq!(l.source.sha256, hash_of_file());
    act(&mut app, Action::Enter);
    assert_eq!(app.screen, Screen::Trial);
    // On the trial screen and on the compare screen, `w` waits.
    assert!(act(&mut app, Action::Save).is_empty());
    let (msg, is_error) = app.message.clone().unwrap();
    assert!(
        is_error && msg.contains("waits for the final correction"),
        "{msg}"
    );
    app.message = None;
    act(&mut app, Action::Compare);
    assert_eq!(app.screen, Screen::Compare);
    assert!(act(&mut app, Action::Save).is_empty());
    let (msg, is_error) = app.message.clone().unwrap();
    assert!(
        is_error && msg.contains("live.csv is still growing") && msg.contains("final correction"),
        "{msg}"
    );
    assert!(!dir.join("corrected").exists(), "nothing was saved");
    // The writer writes the rest and stops.
    append_in_fragments(&path, &text[cut..], &mut rng, &mut app, &mut live);
    settle(&mut app, &mut live);
    let l = app.entry("live.csv").unwrap().loaded().unwrap().clone();
    assert_eq!(l.trial.len(), sim.trial.len());
    assert_eq!(l.source.sha256, hash_of_file());
    let fx = update(&mut app, live.finish(Ok(())));
    SyncRunner::run(&mut app, fx);
    let e = app.entry("live.csv").unwrap();
    assert!(e.live.is_none() && e.following.is_none());
    assert_eq!(e.results.len(), Variant::ALL.len());
    // Final: `w` saves the variant of the compare column.
    let v = Variant::ALL[app.compare_col];
    let fx = act(&mut app, Action::Save);
    assert!(
        matches!(fx.as_slice(), [Effect::SaveVariant { .. }]),
        "{fx:?}"
    );
    SyncRunner::run(&mut app, fx);
    let out = dir.join(format!("corrected/live.{v}.csv"));
    assert!(out.is_file(), "{:?}", app.message);
    let sc = crate::sidecar::Sidecar::load(&crate::sidecar::sidecar_path(&out)).unwrap();
    assert_eq!(sc.variant, v);
    assert_eq!(sc.input.sha256, hash_of_file());
    // A new session over the folder finds it saved.
    let again = load_app("trials", &dir, &limits).unwrap();
    assert_eq!(again.entry("live.csv").unwrap().variant_status(v), "saved");
}

/// The text of one MT Manager export of `imu` (tab-separated, packet
/// counter and quaternion; no mapping: the file name's serial is the IMU).
fn export_text(trial: &crate::trial::Trial, imu: usize) -> String {
    use std::fmt::Write as _;
    let s = &trial.imus[imu];
    let mut text =
        String::from("// Update Rate: 50.0Hz\nPacketCounter\tQuat_q0\tQuat_q1\tQuat_q2\tQuat_q3\n");
    for (c, q) in s.orientation.iter().enumerate() {
        let _ = writeln!(text, "{c:05}\t{}\t{}\t{}\t{}", q.w, q.i, q.j, q.k);
    }
    text
}

/// A folder of Xsens exports that MT Manager appends to, one export per
/// sensor, is followed like a growing CSV: rows shown as every sensor
/// writes them, solved in the background, and once the writer stops the
/// folder is read whole and corrected as `acmw correct FOLDER` corrects it.
#[test]
fn a_growing_export_folder_is_followed() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("trials");
    let folder = dir.join("session");
    std::fs::create_dir_all(&folder).unwrap();
    let mut cfg = crate::simulate::preset("knee_calf_z15").unwrap();
    cfg.duration_s = 30.0;
    let sim = crate::simulate::simulate(&cfg).unwrap();
    let texts: Vec<(std::path::PathBuf, String)> = (0..sim.trial.imus.len())
        .map(|k| {
            let name = format!("session_{}.txt", sim.trial.imus[k].name.replace('_', "-"));
            (folder.join(name), export_text(&sim.trial, k))
        })
        .collect();
    // The lab's mapping of serials to IMUs, as OpenSense reads it.
    let sensors: String = (sim.trial.imus.iter())
        .map(|s| {
            format!(
                "<ExperimentalSensor name=\"_{}\"><name_in_model>{}</name_in_model></ExperimentalSensor>",
                s.name.replace('_', "-"),
                s.name
            )
        })
        .collect();
    let mapping = format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\" ?>\n<OpenSimDocument Version=\"40000\"><XsensDataReaderSettings><trial_prefix>session</trial_prefix><ExperimentalSensors>{sensors}</ExperimentalSensors></XsensDataReaderSettings></OpenSimDocument>\n"
    );
    std::fs::write(folder.join("myIMUMappings.xml"), mapping).unwrap();
    // MT Manager has created the exports (headers only) when the workbench starts.
    for (path, text) in &texts {
        std::fs::write(path, &text[..row_at(text, 1)]).unwrap();
    }
    let mut app = load_app("trials", &dir, &tmp.path().join("joint_limits")).unwrap();
    assert!(app.entry("session").is_some(), "the folder is a trial");
    let fx = update(&mut app, Msg::FileChanged("session".into(), folder.clone()));
    let [Effect::Follow(job)] = fx.as_slice() else {
        panic!("{fx:?}")
    };
    let mut live = LiveJob::new((**job).clone());
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    // Each export grows in its own random fragments, sensors taking turns.
    let mut at: Vec<usize> = texts.iter().map(|(_, t)| row_at(t, 1)).collect();
    let upto = |k: usize, rows: usize| row_at(&texts[k].1, rows + 1);
    let mut grow_to = |rows: usize, app: &mut App, live: &mut LiveJob| loop {
        let k = rng.random_range(0..texts.len());
        let end = upto(k, rows);
        if at.iter().enumerate().all(|(j, &a)| a >= upto(j, rows)) {
            break;
        }
        let n = rng.random_range(1..3000).min(end - at[k]);
        let mut f = std::fs::OpenOptions::new()
            .append(true)
            .open(&texts[k].0)
            .unwrap();
        f.write_all(&texts[k].1.as_bytes()[at[k]..at[k] + n])
            .unwrap();
        at[k] += n;
        feed(app, live.step().unwrap());
    };
    grow_to(600, &mut app, &mut live);
    settle(&mut app, &mut live);
    let e = app.entry("session").unwrap();
    let l = e.loaded().expect("the rows every sensor wrote are shown");
    assert_eq!(l.trial.len(), 600);
    assert_eq!(e.variant_status(Variant::Drift), "live");
    let v = e.live.clone().unwrap();
    assert!(v.solved > 0 && v.solved <= 600, "{}", v.solved);
    act(&mut app, Action::Enter);
    let theme = Theme::builtin("dark", true).unwrap();
    let t = buffer_text(&draw(&app, &theme, 120, 40));
    assert!(t.contains("LIVE 600"), "{t}");
    grow_to(sim.trial.len(), &mut app, &mut live);
    settle(&mut app, &mut live);
    // The writer stops: the folder is read whole and every variant corrected.
    let fx = update(&mut app, live.finish(Ok(())));
    assert!(matches!(fx.as_slice(), [Effect::Load { .. }]), "{fx:?}");
    SyncRunner::run(&mut app, fx);
    let e = app.entry("session").unwrap();
    assert!(e.live.is_none() && e.following.is_none());
    assert_eq!(e.results.len(), Variant::ALL.len());
    let file = pipeline::read(&folder).unwrap();
    let model = crate::trial::detect_model(&folder);
    let trial = file.trial(&model).unwrap();
    assert_eq!(e.loaded().unwrap().trial.len(), trial.len());
    let setup = Setup {
        model: &model,
        limits: &app.limits.table,
        limits_source: &app.limits.source,
        settings: &app.settings,
    };
    let p = pipeline::prepare(trial, setup, &Preparation::default()).unwrap();
    let want = pipeline::correct(&p.trial, setup, Variant::Drift, &Default::default()).unwrap();
    assert_eq!(
        e.results[&Variant::Drift].correction.corrected.imus,
        want.corrected.imus
    );
}
