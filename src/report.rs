//! A trial's figures before and after each correction variant, as a data
//! structure (for JSON and screens) and as aligned text tables (for terminals).

use crate::acm::hinge::HingeRecord;
use crate::acm::window::{borrow_notes, layout};
use crate::acm::{Correction, ImuHeading, SkippedJoint, Variant};
use crate::ik::IkSummary;
use crate::limits::{LimitTable, Settings};
use crate::metrics::{trial_figures, JointFigures};
use crate::model::Model;
use crate::pose::PoseRecord;
use crate::trial::glitch::{glitch_note, glitches, Glitch, DEFAULT_GLITCH_DEG};
use crate::trial::timing::{timing, Timing};
use crate::trial::Trial;
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;

/// The figures of one variant.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct VariantReport {
    pub variant: Variant,
    pub joints: Vec<JointFigures>,
    pub skipped: Vec<SkippedJoint>,
    /// Estimated heading drift per IMU (heading-drift variants only).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub headings: Vec<ImuHeading>,
    /// The `ik` variant's solver figures.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ik: Option<IkSummary>,
    /// The hinge axes per hinge joint (`hinge` variant only).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub hinges: Vec<(String, HingeRecord)>,
}

/// A trial's figures, uncorrected and per variant.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrialReport {
    pub trial: String,
    pub samples: usize,
    pub duration_s: f64,
    pub rate_hz: f64,
    pub imus: Vec<String>,
    pub model: String,
    pub limits_source: String,
    pub limits_sha256: String,
    /// The limit table's model when it is not the Euler box
    /// (`swing-twist`); absent for Euler tables.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub limits_model: Option<String>,
    pub settings: Settings,
    /// Whether a ground truth was compared against.
    pub truth: bool,
    pub uncorrected: Vec<JointFigures>,
    pub variants: Vec<VariantReport>,
    pub warnings: Vec<String>,
    /// The pose calibration the trial went through before correction.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pose_calibration: Option<PoseRecord>,
    /// Spacing of the sample times: irregular intervals and gaps.
    #[serde(default)]
    pub timing: Timing,
    /// Windows of the windowed variants that borrowed their neighbours' samples.
    #[serde(default)]
    pub borrowed_windows: Vec<String>,
    /// Threshold of the glitch search, degrees between neighbouring samples.
    #[serde(default)]
    pub glitch_deg: f64,
    /// Orientation jumps over `glitch_deg` (reported, not smoothed).
    #[serde(default)]
    pub glitches: Vec<Glitch>,
    /// Scores against an optical reference (`report --reference`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reference: Option<crate::reference::ReferenceReport>,
}

impl TrialReport {
    /// Searches `trial` (the one reported on) for glitches over `deg` instead of
    /// the default threshold.
    pub fn set_glitch_threshold(&mut self, trial: &Trial, deg: f64) {
        self.glitch_deg = deg;
        self.glitches = glitches(trial, deg);
    }
}

/// Inputs of a report.
pub struct ReportInput<'a> {
    pub trial: &'a Trial,
    pub model: &'a Model,
    pub limits: &'a LimitTable,
    pub limits_source: &'a str,
    pub settings: &'a Settings,
    /// True segment orientations, when known.
    pub truth: Option<&'a Trial>,
}

impl ReportInput<'_> {
    /// Figures of the uncorrected trial and of already computed corrections.
    pub fn report<'c>(&self, corrections: impl IntoIterator<Item = &'c Correction>) -> TrialReport {
        let corrections: Vec<&Correction> = corrections.into_iter().collect();
        let t = self.trial;
        TrialReport {
            trial: t.name.clone(),
            samples: t.len(),
            duration_s: t.duration_s(),
            rate_hz: t.rate_hz(),
            imus: t.imus.iter().map(|i| i.name.clone()).collect(),
            model: self.model.name.clone(),
            limits_source: self.limits_source.to_string(),
            limits_sha256: self.limits.hash(),
            limits_model: self
                .limits
                .swing_twist
                .as_ref()
                .map(|_| self.limits.model_name().to_string()),
            settings: *self.settings,
            truth: self.truth.is_some(),
            uncorrected: trial_figures(t, None, self.truth, self.model, self.limits),
            variants: corrections
                .iter()
                .map(|c| VariantReport {
                    variant: c.variant,
                    joints: trial_figures(
                        &c.corrected,
                        Some(t),
                        self.truth,
                        self.model,
                        self.limits,
                    ),
                    skipped: c.skipped.clone(),
                    headings: c.headings.clone(),
                    ik: c.ik.as_ref().map(|r| r.summary()),
                    hinges: (c.joints.iter())
                        .filter_map(|j| j.hinge.clone().map(|h| (j.joint.clone(), h)))
                        .collect(),
                })
                .collect(),
            warnings: t.warnings.clone(),
            pose_calibration: None,
            timing: timing(&t.time_s),
            borrowed_windows: if corrections.iter().any(|c| c.variant.windowed()) {
                borrow_notes(&layout(
                    &t.time_s,
                    self.settings.window_s,
                    self.settings.hop_s,
                ))
            } else {
                Vec::new()
            },
            glitch_deg: DEFAULT_GLITCH_DEG,
            glitches: glitches(t, DEFAULT_GLITCH_DEG),
            reference: None,
        }
    }
}

fn xyz(v: [f64; 3], decimals: usize) -> String {
    format!("{:.d$} {:.d$} {:.d$}", v[0], v[1], v[2], d = decimals)
}

fn table(
    out: &mut String,
    title: &str,
    r: &TrialReport,
    cell: &dyn Fn(&JointFigures) -> Option<String>,
) {
    let mut cols: Vec<(String, &Vec<JointFigures>)> = vec![("uncorrected".into(), &r.uncorrected)];
    for v in &r.variants {
        cols.push((v.variant.name().into(), &v.joints));
    }
    let rows: Vec<(String, Vec<String>)> = r
        .uncorrected
        .iter()
        .map(|j| {
            let cells = cols
                .iter()
                .map(|(_, figs)| {
                    figs.iter()
                        .find(|f| f.joint == j.joint)
                        .and_then(cell)
                        .unwrap_or_else(|| "-".into())
                })
                .collect();
            (j.joint.clone(), cells)
        })
        .collect();
    let jw = rows.iter().map(|(j, _)| j.len()).max().unwrap_or(5).max(5);
    let widths: Vec<usize> = (0..cols.len())
        .map(|c| {
            rows.iter()
                .map(|(_, cells)| cells[c].len())
                .max()
                .unwrap_or(0)
                .max(cols[c].0.len())
        })
        .collect();
    let _ = writeln!(out, "\n{title}");
    let _ = write!(out, "{:<jw$}", "joint");
    for (c, (name, _)) in cols.iter().enumerate() {
        let _ = write!(out, "  {:>w$}", name, w = widths[c]);
    }
    out.push('\n');
    for (joint, cells) in rows {
        let _ = write!(out, "{joint:<jw$}");
        for (c, cell) in cells.iter().enumerate() {
            let _ = write!(out, "  {:>w$}", cell, w = widths[c]);
        }
        out.push('\n');
    }
}

/// An IMU's heading counts as drift above this, degrees.
const HEADING_SHOWN_DEG: f64 = 0.05;

/// The estimated heading drift of a heading-drift variant: per window centre
/// (rows) and drifting IMU (columns) the heading in degrees and its rate since
/// the previous centre in degrees per second.
fn heading_table(out: &mut String, v: &VariantReport) {
    let shown: Vec<&ImuHeading> = v
        .headings
        .iter()
        .filter(|h| h.max_abs_heading_deg() > HEADING_SHOWN_DEG)
        .collect();
    let vertical = v.headings.first().map_or("z-up", |h| h.vertical.name());
    let _ = writeln!(
        out,
        "\nEstimated heading drift, {}: deg about the vertical ({vertical}) | deg/s since the previous window",
        v.variant
    );
    if shown.is_empty() {
        let _ = writeln!(out, "no IMU drifted by more than {HEADING_SHOWN_DEG} deg");
        return;
    }
    let _ = write!(out, "{:>8}", "time s");
    for h in &shown {
        let _ = write!(out, "  {:>18}", h.imu);
    }
    out.push('\n');
    for (k, w) in shown[0].windows.iter().enumerate() {
        let _ = write!(out, "{:>8.1}", w.centre_s);
        for h in &shown {
            let hw = &h.windows[k];
            let rate = hw
                .rate_deg_s
                .map_or("-".to_string(), |r| format!("{r:+.4}"));
            let _ = write!(out, "  {:>8.2} | {rate:>7}", hw.heading_deg);
        }
        out.push('\n');
    }
    let _ = write!(out, "{:>8}", "mean/s");
    for h in &shown {
        let _ = write!(out, "  {:>18}", format!("{:+.4}", h.mean_rate_deg_s()));
    }
    out.push('\n');
    let still: Vec<&str> = v
        .headings
        .iter()
        .filter(|h| h.max_abs_heading_deg() <= HEADING_SHOWN_DEG)
        .map(|h| h.imu.as_str())
        .collect();
    if !still.is_empty() {
        let _ = writeln!(out, "no heading drift found: {}", still.join(", "));
    }
}

/// The report as aligned text tables for a terminal.
pub fn format_text(r: &TrialReport) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{}: {} samples, {:.1} s at {:.1} Hz, {} IMUs; model {}; limits {}{} (sha256 {})",
        r.trial,
        r.samples,
        r.duration_s,
        r.rate_hz,
        r.imus.len(),
        r.model,
        r.limits_source,
        r.limits_model
            .as_ref()
            .map(|m| format!(" ({m})"))
            .unwrap_or_default(),
        &r.limits_sha256[..12]
    );
    let _ = writeln!(
        out,
        "lambda1 {}, window {} s, hop {} s",
        r.settings.lambda1, r.settings.window_s, r.settings.hop_s
    );
    for w in &r.warnings {
        let _ = writeln!(out, "warning: {w}");
    }
    if let Some(p) = &r.pose_calibration {
        let _ = writeln!(
            out,
            "pose calibration at {} s ({} samples): heading corrected by {:.2} deg; \"uncorrected\" is the calibrated trial",
            p.calibration.at, p.samples, p.heading_deg
        );
    }
    for n in r.timing.notes().iter().chain(&r.borrowed_windows) {
        let _ = writeln!(out, "time: {n}");
    }
    if let Some(g) = glitch_note(&r.glitches, r.glitch_deg) {
        let _ = writeln!(out, "glitches: {g}");
    }
    if let Some(v) = r.variants.first().filter(|v| !v.skipped.is_empty()) {
        let list: Vec<String> = v
            .skipped
            .iter()
            .map(|s| format!("{} ({})", s.joint, s.reason))
            .collect();
        let _ = writeln!(out, "skipped joints: {}", list.join("; "));
    }
    table(
        &mut out,
        "Joint mean excursion, deg per sample (Figure 4-20)",
        r,
        &|f| Some(format!("{:.3}", f.excursion.joint_mean_excursion_deg)),
    );
    table(
        &mut out,
        "Samples outside the limits, % per axis X Y Z (Table 4-1)",
        r,
        &|f| Some(xyz(f.excursion.pct_outside, 1)),
    );
    table(
        &mut out,
        "Mean excursion, deg per sample per axis X Y Z (Table 4-2)",
        r,
        &|f| Some(xyz(f.excursion.mean_excursion_deg, 2)),
    );
    if !r.variants.is_empty() {
        table(
            &mut out,
            "Mean shift of the angles X Y Z | mean correction angle, deg (Table 4-3)",
            r,
            &|f| {
                f.shift.map(|s| {
                    format!(
                        "{} | {:.2}",
                        xyz(s.mean_shift_deg, 2),
                        s.mean_correction_angle_deg
                    )
                })
            },
        );
    }
    if r.truth {
        table(
            &mut out,
            "RMS error against truth, deg per axis X Y Z",
            r,
            &|f| f.truth.map(|t| xyz(t.rms_error_deg, 2)),
        );
        table(
            &mut out,
            "Angle between applied and true correction, deg (mean)",
            r,
            &|f| {
                f.truth
                    .map(|t| format!("{:.2}", t.mean_correction_error_deg))
            },
        );
    }
    for v in r.variants.iter().filter(|v| v.variant.fits_headings()) {
        heading_table(&mut out, v);
    }
    for v in r.variants.iter().filter(|v| !v.hinges.is_empty()) {
        hinge_text(&mut out, v);
    }
    for v in &r.variants {
        if let Some(ik) = &v.ik {
            ik_text(&mut out, ik);
        }
    }
    out
}

/// Per hinge joint: in how many windows each axis was used, how far the
/// sensors sat off the hinge, and why a window fell back.
fn hinge_text(out: &mut String, v: &VariantReport) {
    let _ = writeln!(
        out,
        "\nHinge axes, {}: windows using the proximal | distal axis; mean tilt of each from the IMU's own axis, deg",
        v.variant
    );
    for (joint, h) in &v.hinges {
        let (p, d) = h.windows_used();
        let mean = |f: &dyn Fn(&crate::acm::hinge::HingeWindow) -> Option<f64>| {
            let xs: Vec<f64> = h.windows.iter().filter_map(f).collect();
            if xs.is_empty() {
                "-".to_string()
            } else {
                format!("{:.2}", xs.iter().sum::<f64>() / xs.len() as f64)
            }
        };
        let n = h.windows.len();
        let pooled = h.windows.iter().filter(|w| w.pooled).count();
        let _ = writeln!(
            out,
            "{joint:<14} hinge {:<4} {p}/{n} | {d}/{n} windows; tilt {} | {}{}{}",
            h.hinge,
            mean(&|w| w.proximal_tilt_deg),
            mean(&|w| w.distal_tilt_deg),
            if pooled > 0 {
                format!("; {pooled} windows took axes pooled with their neighbours")
            } else {
                String::new()
            },
            if h.proximal_turned_by_axis {
                "; proximal IMU turned by the axis alone (no joint above corrects it)"
            } else {
                ""
            }
        );
        for w in &h.windows {
            if let Some(why) = &w.fallback {
                let _ = writeln!(
                    out,
                    "{:14} window at {:.1} s, axis not used (drift-centroid there): {why}",
                    "", w.centre_s
                );
            }
        }
    }
}

fn ik_text(out: &mut String, s: &IkSummary) {
    let _ = writeln!(
        out,
        "\nInverse kinematics (ik): {} frames, {} coordinates; RMS orientation error per frame {:.3} deg mean, {:.3} max; {:.2} steps per frame (max {})",
        s.frames,
        s.coordinates.len(),
        s.mean_rms_error_deg,
        s.max_rms_error_deg,
        s.mean_iterations,
        s.max_iterations
    );
    if !s.pct_at_limit.is_empty() {
        let list: Vec<String> = s
            .pct_at_limit
            .iter()
            .map(|(c, p)| format!("{c} {p:.1}%"))
            .collect();
        let _ = writeln!(out, "frames on a hard limit: {}", list.join(", "));
    }
}
