//! Nothing lost or hidden: quitting while work runs, a broken limits file on
//! disk, saved outputs found again at start-up, a choice that stays with its
//! trial. Driven through `update` and [`SyncRunner`]; nothing sleeps.

use super::{key, keys, terminal, Fixture};
use crate::acm::Variant;
use crate::ui::app::{update, Msg, Overlay};
use crate::ui::headless::buffer_text;
use crate::ui::jobs::{read_limits_on_disk, SyncRunner};
use crate::ui::msg::Screen;
use ratatui::crossterm::event::{KeyCode, KeyEvent, KeyModifiers};

fn ctrl_c() -> Msg {
    Msg::Key(KeyEvent::new(KeyCode::Char('c'), KeyModifiers::CONTROL))
}

#[test]
fn quitting_while_a_correction_runs_asks_and_says_what_runs() {
    let fx = Fixture::new();
    let mut app = fx.app();
    app.select_file("fb.csv.gz");
    // `r` starts a job; its effects are not carried out, so it still runs.
    let jobs = update(&mut app, Msg::Key(KeyEvent::from(KeyCode::Char('r'))));
    assert_eq!(jobs.len(), 1);
    assert!(app.unsaved());
    update(&mut app, Msg::Key(KeyEvent::from(KeyCode::Char('q'))));
    assert_eq!(app.overlay, Some(Overlay::QuitConfirm));
    assert!(!app.quit);
    let text = buffer_text(terminal(&app, 80, 24).backend().buffer());
    assert!(text.contains("fb.csv.gz correcting, 0%"), "{text}");
    update(&mut app, Msg::Key(KeyEvent::from(KeyCode::Char('n'))));
    // Ctrl-C asks the same, also while the filter takes characters.
    keys(&mut app, "/");
    assert!(app.filter_editing);
    update(&mut app, ctrl_c());
    assert_eq!(app.overlay, Some(Overlay::QuitConfirm));
    assert_eq!(app.filter, "", "Ctrl-C is not typed into the filter");
    update(&mut app, Msg::Key(KeyEvent::from(KeyCode::Char('y'))));
    assert!(app.quit);
}

#[test]
fn ctrl_c_quits_at_once_when_nothing_would_be_lost() {
    let fx = Fixture::new();
    let mut app = fx.app();
    SyncRunner::send(&mut app, ctrl_c());
    assert!(app.quit);
}

#[test]
fn a_save_under_way_shows_saving_and_quitting_asks() {
    let fx = Fixture::new();
    let mut app = fx.app();
    app.select_file("fb.csv.gz");
    key(&mut app, KeyCode::Enter);
    keys(&mut app, "rc");
    // `w` without carrying out the save: it is under way.
    let save = update(&mut app, Msg::Key(KeyEvent::from(KeyCode::Char('w'))));
    assert_eq!(save.len(), 1);
    let e = app.open_entry().unwrap();
    let v = e.chosen.unwrap();
    assert_eq!(e.variant_status(v), "saving");
    assert!(app.message.as_ref().unwrap().0.contains("saving"));
    update(&mut app, Msg::Key(KeyEvent::from(KeyCode::Char('q'))));
    assert_eq!(app.overlay, Some(Overlay::QuitConfirm));
    let text = buffer_text(terminal(&app, 80, 24).backend().buffer());
    assert!(
        text.contains(&format!("fb.csv.gz {v} being saved")),
        "{text}"
    );
    update(&mut app, Msg::Key(KeyEvent::from(KeyCode::Char('n'))));
    SyncRunner::run(&mut app, save);
    assert_eq!(app.open_entry().unwrap().variant_status(v), "saved");
    assert!(!app.unsaved());
}

#[test]
fn a_broken_limits_file_on_disk_shows_its_located_error_and_keeps_the_table() {
    let fx = Fixture::new();
    let mut app = fx.app();
    // Save the built-in limits so that the folder has them, then break a row.
    keys(&mut app, "L");
    keys(&mut app, "w");
    let dir = app.limits.dir.clone();
    let name = app.limits.table_name.clone();
    let good = app.limits.table.clone();
    let path = dir.join(&name);
    let text = std::fs::read_to_string(&path).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let row = lines.iter().position(|l| l.starts_with("hip,")).unwrap();
    let mut cells: Vec<&str> = lines[row].split(',').collect();
    cells[4] = "abc";
    lines[row] = cells.join(",");
    std::fs::write(&path, lines.join("\n") + "\n").unwrap();
    let msg = read_limits_on_disk(&dir, &name).expect("the folder has limits");
    let Msg::LimitsInvalid(why) = &msg else {
        panic!("{msg:?}")
    };
    // file:line:column of the bad cell.
    let at = format!("{}:{}:", name, row + 1);
    assert!(why.contains(&at), "{why} should locate {at}");
    SyncRunner::send(&mut app, msg);
    assert_eq!(app.limits.table, good, "the last good table stays in use");
    let (m, is_error) = app.message.clone().unwrap();
    assert!(is_error && m.contains(&at), "{m}");
    let text = buffer_text(terminal(&app, 80, 24).backend().buffer());
    assert!(text.contains("limits!"), "{text}");
    assert!(text.contains("! on disk:"), "{text}");
    // Mended on disk: the error goes.
    std::fs::write(&path, good.to_csv()).unwrap();
    let msg = read_limits_on_disk(&dir, &name).unwrap();
    SyncRunner::send(&mut app, msg);
    assert_eq!(app.limits.disk_error, None);
}

#[test]
fn saved_outputs_are_found_again_after_a_restart() {
    let fx = Fixture::new();
    let mut app = fx.app();
    app.select_file("fb.csv.gz");
    key(&mut app, KeyCode::Enter);
    keys(&mut app, "rc");
    key(&mut app, KeyCode::Char(' '));
    keys(&mut app, "w");
    let v = app.open_entry().unwrap().chosen.unwrap();
    // A new session over the same folder: `saved` before anything runs.
    let mut again = fx.app();
    let e = again.entry("fb.csv.gz").unwrap();
    assert!(e.results.is_empty());
    assert_eq!(e.variant_status(v), "saved");
    let others = Variant::ALL.iter().filter(|&&o| o != v);
    assert!(others.clone().all(|&o| e.variant_status(o) == "-"));
    // After a run with the same settings and table it is still saved.
    again.select_file("fb.csv.gz");
    keys(&mut again, "r");
    let e = again.entry("fb.csv.gz").unwrap();
    assert_eq!(
        e.results[&v].saved.as_deref(),
        Some(&*format!("corrected/fb.{v}.csv.gz"))
    );
    assert!(others.clone().all(|&o| e.variant_status(o) == "done"));
    // An output whose sidecar records another input is not this trial's.
    let side = fx
        .root()
        .join(format!("trials/corrected/fb.{v}.csv.gz.acmw.json"));
    let json = std::fs::read_to_string(&side).unwrap();
    let hash = crate::sidecar::Sidecar::load(&side).unwrap().input.sha256;
    std::fs::write(&side, json.replace(&hash, &"0".repeat(hash.len()))).unwrap();
    let third = fx.app();
    assert_eq!(third.entry("fb.csv.gz").unwrap().variant_status(v), "-");
}

/// `w` over an output of another correction of the trial (its sidecar
/// records another limit table) asks; `n` keeps the file, `y` writes. A save
/// of the very correction on disk asks nothing.
#[test]
fn saving_over_another_corrections_output_asks() {
    let fx = Fixture::new();
    let mut app = fx.app();
    app.select_file("fb.csv.gz");
    key(&mut app, KeyCode::Enter);
    keys(&mut app, "rc");
    key(&mut app, KeyCode::Char(' '));
    keys(&mut app, "w");
    let v = app.open_entry().unwrap().chosen.unwrap();
    let out = fx.root().join(format!("trials/corrected/fb.{v}.csv.gz"));
    let side = crate::sidecar::sidecar_path(&out);
    let json = std::fs::read_to_string(&side).unwrap();
    let hash = crate::sidecar::Sidecar::load(&side).unwrap().limits.sha256;
    let other = "1".repeat(hash.len());
    std::fs::write(&side, json.replace(&hash, &other)).unwrap();
    let written = std::fs::read(&out).unwrap();
    let mut again = fx.app();
    again.select_file("fb.csv.gz");
    key(&mut again, KeyCode::Enter);
    keys(&mut again, "rc");
    for _ in Variant::ALL {
        key(&mut again, KeyCode::Left);
    }
    while Variant::ALL[again.compare_col] != v {
        key(&mut again, KeyCode::Right);
    }
    key(&mut again, KeyCode::Char(' '));
    assert_eq!(again.open_entry().unwrap().variant_status(v), "chosen");
    let asks = update(&mut again, Msg::Key(KeyEvent::from(KeyCode::Char('w'))));
    assert!(asks.is_empty(), "nothing written before the answer");
    assert_eq!(again.open_entry().unwrap().overwrite, Some(v));
    let text = buffer_text(terminal(&again, 80, 24).backend().buffer());
    assert!(text.contains("Overwrite?"), "{text}");
    assert!(
        text.contains(&format!("corrected/fb.{v}.csv.gz exists")),
        "{text}"
    );
    keys(&mut again, "n");
    assert_eq!(again.open_entry().unwrap().overwrite, None);
    assert_eq!(std::fs::read(&out).unwrap(), written);
    assert!(std::fs::read_to_string(&side).unwrap().contains(&other));
    keys(&mut again, "w");
    keys(&mut again, "y");
    let e = again.open_entry().unwrap();
    assert_eq!(e.overwrite, None);
    assert_eq!(e.variant_status(v), "saved");
    let now = crate::sidecar::Sidecar::load(&side).unwrap().limits.sha256;
    assert_eq!(now, hash, "written with the table in use");
    // The same correction again: nothing to ask.
    keys(&mut again, "w");
    assert_eq!(again.open_entry().unwrap().overwrite, None);
    assert_eq!(again.open_entry().unwrap().variant_status(v), "saved");
}

#[test]
fn choosing_a_variant_keeps_to_its_trial() {
    let fx = Fixture::new();
    let mut app = fx.app();
    app.select_file("fb.csv.gz");
    key(&mut app, KeyCode::Enter);
    keys(&mut app, "rc");
    let shown = app.variant;
    key(&mut app, KeyCode::Right);
    key(&mut app, KeyCode::Char(' '));
    let chosen = app.open_entry().unwrap().chosen.unwrap();
    assert_ne!(chosen, shown);
    assert_eq!(app.variant, shown, "the variant shown stays");
    assert!(app
        .trials
        .iter()
        .filter(|t| t.file != "fb.csv.gz")
        .all(|t| t.chosen.is_none()));
    assert_eq!(app.screen, Screen::Compare);
}

#[test]
fn what_a_variant_skipped_or_fell_back_to_is_said() {
    let fx = Fixture::new();
    let mut app = fx.app();
    for f in ["knee.csv", "fb.csv.gz"] {
        app.select_file(f);
        keys(&mut app, "r");
    }
    let knee = app.entry("knee.csv").unwrap();
    let fb = app.entry("fb.csv.gz").unwrap();
    // IK needs the base IMU, which the two-IMU knee trial lacks.
    let ik = knee.variant_note(Variant::Ik).unwrap();
    assert_eq!(
        ik,
        "nothing corrected: the base IMU 'base' is not in the trial"
    );
    assert_eq!(fb.variant_note(Variant::Ik), None);
    // A baseline corrects only its own joint kind; the rest get drift-centroid.
    let others = fb.loaded().unwrap().before.len() - 2;
    let rivest = fb.variant_note(Variant::Rivest).unwrap();
    assert!(
        rivest.starts_with(&format!("{others} joint(s) by drift-centroid")),
        "{rivest}"
    );
    // ACM variants do all they were asked.
    assert!(Variant::ALL
        .iter()
        .filter(|v| !matches!(v, Variant::Rivest | Variant::Mueller | Variant::Ik))
        .all(|&v| fb.variant_note(v).is_none() && knee.variant_note(v).is_none()));
    // The trial screen's footer says so, the status line says what.
    app.select_file("knee.csv");
    key(&mut app, KeyCode::Enter);
    while app.variant != Variant::Ik {
        keys(&mut app, "v");
    }
    keys(&mut app, "r");
    let text = buffer_text(terminal(&app, 80, 24).backend().buffer());
    assert!(text.contains("ik: nothing done!"), "{text}");
    assert!(
        text.contains("knee.csv ik: nothing corrected: the base IMU"),
        "{text}"
    );
}

/// The workbench saves a six-decimal trial's correction at six decimals.
#[test]
fn a_save_keeps_the_inputs_decimals() {
    use crate::trial::precision::{decimals_of, Precision};
    use crate::trial::{read_trial, write_trial_hashed, TrialFormat};
    let fx = Fixture::new();
    let trials = fx.root().join("trials");
    let fb = read_trial(&trials.join("fb.csv.gz"), &crate::model::Model::infant13()).unwrap();
    let six = trials.join("six.csv");
    write_trial_hashed(&fb, &six, TrialFormat::QuatCsv, Precision::Decimals(6)).unwrap();
    let mut app = fx.app();
    app.select_file("six.csv");
    key(&mut app, KeyCode::Enter);
    keys(&mut app, "rc");
    key(&mut app, KeyCode::Char(' '));
    keys(&mut app, "w");
    let v = app.open_entry().unwrap().chosen.unwrap();
    let out = std::fs::read_to_string(trials.join(format!("corrected/six.{v}.csv"))).unwrap();
    let most = out
        .lines()
        .skip(1)
        .flat_map(|l| l.split(',').skip(1).map(decimals_of).collect::<Vec<_>>())
        .max();
    assert_eq!(most, Some(6));
}
