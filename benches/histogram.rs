//! Histogram screen benchmarks: a frame of the histogram screen of a
//! 30-minute, 13-IMU trial at 200x60, over the first 30 s (the default) and
//! over the whole trial, and the work of choosing a span (pooling the angles
//! and binning them) for both.
//!
//! Run with `cargo bench --bench histogram`.

use acm_workbench::analysis::TimeSpan;
use acm_workbench::simulate::{simulate, SimConfig};
use acm_workbench::trial::{write_trial, TrialFormat};
use acm_workbench::ui::app::Msg;
use acm_workbench::ui::headless::{load_app, show, Show};
use acm_workbench::ui::histogram::compute_job;
use acm_workbench::ui::render::render;
use acm_workbench::ui::theme::Theme;
use criterion::{criterion_group, criterion_main, Criterion};
use ratatui::backend::TestBackend;
use ratatui::Terminal;
use std::path::Path;

fn benches(c: &mut Criterion) {
    let theme = Theme::builtin("dark", false).unwrap();
    let limits_dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("joint_limits");
    let dir = tempfile::tempdir().unwrap();
    let mut cfg = SimConfig::full_body(3);
    cfg.duration_s = 1800.0;
    let trial = simulate(&cfg).unwrap().trial;
    write_trial(&trial, &dir.path().join("long.csv"), TrialFormat::QuatCsv).unwrap();
    let mut app = load_app("bench", dir.path(), &limits_dir).unwrap();
    let s = Show {
        screen: "histogram".into(),
        trial: Some("long.csv".into()),
        joint: Some("l_hip".into()),
        variant: None,
    };
    show(&mut app, &s).unwrap();
    let trials = vec![app.entry("long.csv").unwrap().loaded().unwrap().clone()];
    let table = app.limits.table.clone();
    let compute = |span| match compute_job(&trials, span, &table) {
        Msg::Histograms(h) => h,
        _ => unreachable!(),
    };
    let mut term = Terminal::new(TestBackend::new(200, 60)).unwrap();
    c.bench_function(
        "draw histogram screen, 30 min trial, first 30 s, 200x60",
        |b| b.iter(|| term.draw(|f| render(&app, &theme, f)).map(|_| ()).unwrap()),
    );
    c.bench_function(
        "histograms and centroids of a 30 min trial, first 30 s",
        |b| b.iter(|| compute(TimeSpan::FIRST_30_S)),
    );
    c.bench_function(
        "histograms and centroids of a 30 min trial, whole trial",
        |b| b.iter(|| compute(TimeSpan::WHOLE)),
    );
    let whole = compute(TimeSpan::WHOLE);
    if let Some(st) = app.histogram.as_mut() {
        st.span = TimeSpan::WHOLE;
        st.hists = whole.joints;
    }
    c.bench_function(
        "draw histogram screen, 30 min trial, whole trial, 200x60",
        |b| b.iter(|| term.draw(|f| render(&app, &theme, f)).map(|_| ()).unwrap()),
    );
}

criterion_group!(histogram, benches);
criterion_main!(histogram);
