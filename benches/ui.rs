//! Workbench benchmarks (issues 4 and 7): drawing the trial screen and the
//! analysis views of a 30-minute, 13-IMU trial at 200x60, and the first frame on a folder of 100 trials
//! (file names only: trials load in the background after it).
//!
//! Run with `cargo bench --bench ui`.

use acm_workbench::simulate::{simulate, SimConfig};
use acm_workbench::trial::{write_trial, TrialFormat};
use acm_workbench::ui::app::App;
use acm_workbench::ui::headless::{draw, load_app, show, Show};
use acm_workbench::ui::jobs::{list_trials, load_limits};
use acm_workbench::ui::render::render;
use acm_workbench::ui::theme::Theme;
use criterion::{criterion_group, criterion_main, Criterion};
use ratatui::backend::TestBackend;
use ratatui::Terminal;
use std::path::Path;

fn benches(c: &mut Criterion) {
    let theme = Theme::builtin("dark", false).unwrap();
    let limits_dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("joint_limits");

    // A 30-minute trial, corrected with every variant, on the trial screen.
    let dir = tempfile::tempdir().unwrap();
    let mut cfg = SimConfig::full_body(3);
    cfg.duration_s = 1800.0;
    let trial = simulate(&cfg).unwrap().trial;
    write_trial(&trial, &dir.path().join("long.csv"), TrialFormat::QuatCsv).unwrap();
    let mut app = load_app("bench", dir.path(), &limits_dir).unwrap();
    let s = Show {
        screen: "trial".into(),
        trial: Some("long.csv".into()),
        joint: Some("l_knee".into()),
        variant: None,
    };
    show(&mut app, &s).unwrap();
    // A frame as the runtime draws it: one terminal kept across frames.
    let mut term = Terminal::new(TestBackend::new(200, 60)).unwrap();
    c.bench_function("draw trial screen, 30 min trial, 200x60", |b| {
        b.iter(|| term.draw(|f| render(&app, &theme, f)).map(|_| ()).unwrap())
    });
    // The same through `acmw render`'s path (a new terminal and buffer each time).
    c.bench_function("render trial screen to a new buffer, 200x60", |b| {
        b.iter(|| draw(&app, &theme, 200, 60))
    });

    // The analysis views of the same trial, each drawn as the
    // runtime draws it; the globe also on a shoulder (a wide limit band).
    for (view, joint) in [
        ("scatter", "l_knee"),
        ("globe", "l_knee"),
        ("globe", "l_shoulder"),
        ("applied", "l_knee"),
        ("stick", "l_knee"),
    ] {
        let mut v = app.clone();
        let s = Show {
            screen: view.into(),
            trial: Some("long.csv".into()),
            joint: Some(joint.into()),
            variant: None,
        };
        show(&mut v, &s).unwrap();
        v.views.time_s = 900.0;
        // The first frame fills the angle caches, as the first frame on screen does.
        term.draw(|f| render(&v, &theme, f)).unwrap();
        c.bench_function(
            &format!("draw {view} view ({joint}), 30 min trial, 200x60"),
            |b| b.iter(|| term.draw(|f| render(&v, &theme, f)).map(|_| ()).unwrap()),
        );
    }

    // A folder of 100 trials: list, build the state, draw the first frame.
    let many = tempfile::tempdir().unwrap();
    let mut short = SimConfig::full_body(4);
    short.duration_s = 5.0;
    let small = simulate(&short).unwrap().trial;
    for k in 0..100 {
        write_trial(
            &small,
            &many.path().join(format!("t{k:03}.csv")),
            TrialFormat::QuatCsv,
        )
        .unwrap();
    }
    c.bench_function("first frame, folder of 100 trials", |b| {
        b.iter(|| {
            let files = list_trials(many.path()).unwrap();
            let limits = load_limits(&limits_dir).unwrap();
            let app = App::new("many".into(), many.path().to_path_buf(), files, limits);
            draw(&app, &theme, 120, 40)
        })
    });
}

criterion_group!(ui, benches);
criterion_main!(ui);
