//! Limit suggestions and centroids against the generator's truth, and the
//! structure of exported figures.
//!
//! The clean trials are `full_body_swing` simulations (src/simulate/swing.rs):
//! every joint axis swings as one sinusoid over a known range, so the true
//! ranges and means are known exactly.

use acm_workbench::analysis::centroid::centroids;
use acm_workbench::analysis::histogram::{histograms, joint_histogram, DEFAULT_BIN_DEG};
use acm_workbench::analysis::suggest::{suggest_limits, SuggestOptions};
use acm_workbench::analysis::{pool_by_joint, pool_by_table_row, trial_refs, TimeSpan};
use acm_workbench::limits::{LimitTable, BUILTIN_TABLES};
use acm_workbench::metrics::joint_angles;
use acm_workbench::model::Model;
use acm_workbench::plot::{histogram::Histograms, to_svg, traces::Traces};
use acm_workbench::simulate::{preset, simulate, swing};
use acm_workbench::trial::Trial;

/// Clean swing trials of different seeds (different periods and phases, the
/// same true ranges), 30 s each, 0.3 deg sensor noise.
fn clean_trials(seeds: &[u64]) -> Vec<Trial> {
    seeds
        .iter()
        .map(|&seed| {
            let mut cfg = preset("full_body_swing").unwrap();
            cfg.seed = seed;
            cfg.duration_s = 30.0;
            simulate(&cfg).unwrap().trial
        })
        .collect()
}

#[test]
fn suggested_limits_land_within_3_deg_of_the_true_ranges() {
    let model = Model::infant13();
    let trials = clean_trials(&[11, 12, 13, 14]);
    // Start from Table 3-1, as the source did: every row should move.
    let current = LimitTable::parse(BUILTIN_TABLES[1].1, "table_3_1.csv").unwrap();
    let truth_table = LimitTable::default_table();
    let pooled = pool_by_table_row(&trial_refs(&trials, &model), TimeSpan::FIRST_30_S, &current);
    let hists = histograms(&pooled, &current, &model, DEFAULT_BIN_DEG);
    let s = suggest_limits(
        &current,
        &hists,
        TimeSpan::FIRST_30_S,
        SuggestOptions::default(),
    );
    // The tolerance: a sinusoid's 90% interval lies 1.2% of its amplitude
    // (at most 0.8 deg here) inside its extremes, outward rounding adds
    // under 1 deg, noise about 0.5 deg near the Euler singularity.
    let mut worst: f64 = 0.0;
    // Rows of joints infant13 does not have (the 16-segment model's) keep
    // their limits.
    for r in s.rows.iter().filter(|r| r.samples == 0) {
        assert!(!r.changed() && model.joints.iter().all(|j| j.kind != r.joint));
    }
    for r in s.rows.iter().filter(|r| r.samples > 0) {
        let joint = model
            .joints
            .iter()
            .find(|j| j.kind == r.joint || j.name == r.joint)
            .unwrap();
        let truth = swing::range_deg(&truth_table, joint, r.axis);
        for k in 0..2 {
            let err = (r.suggested[k] - truth[k]).abs();
            worst = worst.max(err);
            assert!(
                err <= 3.0,
                "{} axis {}: suggested {:?}, true {truth:?}",
                r.joint,
                r.axis,
                r.suggested
            );
        }
        assert_eq!((r.trials, r.samples % 1500), (4, 0));
    }
    println!("worst suggested limit vs true range: {worst:.2} deg");
    // The suggested table is a valid table with the same rows, comments added.
    let again = LimitTable::parse(&s.table.to_csv(), "suggested.csv").unwrap();
    assert_eq!(again.rows.len(), current.rows.len());
    again.check_covers(&model, "suggested.csv").unwrap();
    assert!(again
        .preamble
        .last()
        .unwrap()
        .contains("4 trial(s), 0-30 s"));
    let diff = s.diff_lines();
    let changed = s.rows.iter().filter(|r| r.changed()).count();
    assert!(changed >= 18, "{diff:#?}");
    let without = usize::from(s.rows.iter().any(|r| r.samples == 0));
    assert_eq!(diff.len(), 1 + changed + 1 + without, "{diff:#?}");
    assert_eq!(s.rows.iter().filter(|r| r.samples > 0).count(), 21);
    assert!(
        diff.iter()
            .any(|l| l.starts_with("knee") && l.contains("130 -> 80")),
        "{diff:#?}"
    );
}

#[test]
fn centroids_lie_within_1_deg_of_the_generator_means() {
    let model = Model::infant13();
    let trials = clean_trials(&[21, 22, 23]);
    let table = LimitTable::default_table();
    let pooled = pool_by_joint(&trial_refs(&trials, &model), TimeSpan::FIRST_30_S);
    let c = centroids(&pooled, TimeSpan::FIRST_30_S);
    assert_eq!(c.rows.len(), 3 * model.joints.len());
    let mut worst: f64 = 0.0;
    for r in &c.rows {
        let joint = model.joint(&r.joint).unwrap();
        let want = swing::centre_deg(&table, joint, r.axis);
        let err = (r.centroid_deg - want).abs();
        worst = worst.max(err);
        // Whole cycles average to the centre exactly; what is left is the
        // noise (0.3 deg per IMU, averaged over 4,500 samples).
        assert!(
            err < 1.0,
            "{} {}: {} vs {want}",
            r.joint,
            r.axis,
            r.centroid_deg
        );
        // A sinusoid's SD is its amplitude / sqrt(2).
        let [lo, hi] = swing::range_deg(&table, joint, r.axis);
        let sd = 0.5 * (hi - lo) / 2f64.sqrt();
        assert!(
            (r.sd_deg - sd).abs() < 0.05 * sd + 0.3,
            "{} {}",
            r.joint,
            r.axis
        );
        assert_eq!((r.samples, r.trials), (4500, 3));
    }
    println!("worst centroid vs generator mean: {worst:.3} deg");
}

/// `(stroke colour, points)` of every polyline in an SVG.
fn polylines(svg: &str) -> Vec<(String, Vec<(f64, f64)>)> {
    svg.lines()
        .filter(|l| l.starts_with("<polyline"))
        .map(|l| {
            let attr = |name: &str| {
                let k = l.find(&format!("{name}=\"")).unwrap() + name.len() + 2;
                l[k..k + l[k..].find('"').unwrap()].to_string()
            };
            let pts = attr("points")
                .split_whitespace()
                .map(|p| {
                    let (x, y) = p.split_once(',').unwrap();
                    (x.parse().unwrap(), y.parse().unwrap())
                })
                .collect();
            (attr("stroke"), pts)
        })
        .collect()
}

fn of<'a>(lines: &'a [(String, Vec<(f64, f64)>)], colour: &str) -> Vec<&'a Vec<(f64, f64)>> {
    lines
        .iter()
        .filter(|l| l.0 == colour)
        .map(|l| &l.1)
        .collect()
}

#[test]
fn histogram_svg_has_axes_limit_lines_and_one_bar_per_bin() {
    let model = Model::infant13();
    let trials = clean_trials(&[31, 32]);
    let table = LimitTable::default_table();
    let pooled = pool_by_table_row(&trial_refs(&trials, &model), TimeSpan::FIRST_30_S, &table);
    let hip = pooled.iter().find(|g| g.name == "hip").unwrap();
    let h = joint_histogram(hip, &table, &model, DEFAULT_BIN_DEG);
    let fig = Histograms {
        title: "hip".into(),
        hist: &h,
    };
    let svg = to_svg(&fig, (1200, 500)).unwrap();
    // Axes: three panels, each with its two axis lines and descriptions.
    assert_eq!(svg.matches(">\ndeg\n</text>").count(), 3);
    assert_eq!(svg.matches(">\nsamples\n</text>").count(), 3);
    let lines = polylines(&svg);
    assert!(of(&lines, "#000000").len() >= 6);
    // Bars: one rectangle per non-empty bin.
    let bins: usize = h
        .axes
        .iter()
        .map(|a| {
            a.as_ref()
                .unwrap()
                .counts
                .iter()
                .filter(|&&c| c > 0)
                .count()
        })
        .sum();
    assert_eq!(svg.matches("fill=\"#1F77B4\"").count(), bins);
    // Vertical lines: 2 limits, 1 mean and 2 interval lines per panel, in
    // the order lower limit < interval < mean < interval < upper limit (the
    // swing ranges lie inside Table 3-2).
    let vertical = |c: &str| -> Vec<f64> {
        let v = of(&lines, c);
        assert!(v.iter().all(|p| p.len() == 2 && p[0].0 == p[1].0), "{c}");
        let mut xs: Vec<f64> = v.iter().map(|p| p[0].0).collect();
        xs.sort_by(f64::total_cmp);
        xs
    };
    let (limit, mean, interval) = (
        vertical("#202020"),
        vertical("#808080"),
        vertical("#FF0000"),
    );
    assert_eq!((limit.len(), mean.len(), interval.len()), (6, 3, 6));
    for p in 0..3 {
        let order = [
            limit[2 * p],
            interval[2 * p],
            mean[p],
            interval[2 * p + 1],
            limit[2 * p + 1],
        ];
        assert!(
            order.windows(2).all(|w| w[0] < w[1]),
            "panel {p}: {order:?}"
        );
    }
}

#[test]
fn traces_svg_has_three_panels_limit_lines_and_bounded_points() {
    let model = Model::infant13();
    let mut cfg = preset("full_body_swing").unwrap();
    cfg.duration_s = 120.0;
    let trial = simulate(&cfg).unwrap().trial;
    let joint = model.joint("l_knee").unwrap();
    let raw = joint_angles(&trial, joint).unwrap();
    let shifted: Vec<[f64; 3]> = raw.iter().map(|a| [a[0] + 1.0, a[1], a[2]]).collect();
    let table = LimitTable::default_table();
    let fig = Traces {
        title: "knee".into(),
        time_s: &trial.time_s,
        raw: &raw,
        corrected: Some(("drift".into(), &shifted)),
        limits: table.joint_limits("l_knee", "knee", true),
        span_s: (0.0, 120.0),
    };
    let width = 800;
    let svg = to_svg(&fig, (width, 600)).unwrap();
    assert_eq!(svg.matches(">\ndeg\n</text>").count(), 3);
    assert_eq!(svg.matches(">\ntime (s)\n</text>").count(), 1);
    let lines = polylines(&svg);
    // 6,000 samples per line, at most two points per pixel column.
    let raw_lines = of(&lines, "#1F77B4");
    let data: Vec<_> = raw_lines.iter().filter(|p| p.len() > 2).collect();
    assert_eq!(data.len(), 3);
    assert!(data.iter().all(|p| p.len() <= 2 * width as usize + 2));
    assert_eq!(
        of(&lines, "#D62728").iter().filter(|p| p.len() > 2).count(),
        3
    );
    // Limit lines: two horizontal ones per panel, the lower below the upper.
    let limits = of(&lines, "#202020");
    assert_eq!(limits.len(), 6);
    assert!(limits.iter().all(|p| p.len() == 2 && p[0].1 == p[1].1));
    let mut ys: Vec<f64> = limits.iter().map(|p| p[0].1).collect();
    ys.sort_by(f64::total_cmp);
    // Panels stack top to bottom; in each, the upper limit is drawn higher
    // (smaller y) than the lower one, and both inside the panel.
    for p in 0..3 {
        assert!(ys[2 * p] < ys[2 * p + 1]);
        assert!(ys[2 * p + 1] < ys.get(2 * p + 2).copied().unwrap_or(f64::MAX));
    }
}
