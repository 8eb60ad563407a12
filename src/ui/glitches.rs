//! Orientation glitches on the trial screen: which belong to the selected
//! joint, where the next one is (key `G`), and their markers on the charts.

use super::workbench::Loaded;
use crate::trial::glitch::Glitch;

/// Glitches of the joint's two IMUs (proximal and distal), by time.
pub fn of_joint<'a>(l: &'a Loaded, joint: &str) -> Vec<&'a Glitch> {
    let Some(j) = l.model.joint(joint) else {
        return Vec::new();
    };
    l.glitches
        .iter()
        .filter(|g| g.imu == j.proximal || g.imu == j.distal)
        .collect()
}

/// The time (seconds from the first sample) of the first glitch after
/// `cursor_s`, wrapping to the first one; `None` without glitches.
pub fn next_after(glitches: &[&Glitch], cursor_s: f64) -> Option<f64> {
    // A glitch within a microsecond of the cursor is the one it is on.
    glitches
        .iter()
        .map(|g| g.time_s)
        .find(|&t| t > cursor_s + 1e-6)
        .or_else(|| glitches.first().map(|g| g.time_s))
}

/// Chart points `(time, angle)` marking the glitches in `[s0, s1]` on the
/// trace `angles` (axis `axis`), at the sample after each jump.
pub fn markers(
    glitches: &[&Glitch],
    angles: &[[f64; 3]],
    axis: usize,
    span: (f64, f64),
) -> Vec<(f64, f64)> {
    glitches
        .iter()
        .filter(|g| g.time_s >= span.0 && g.time_s <= span.1)
        .filter_map(|g| angles.get(g.index).map(|a| (g.time_s, a[axis])))
        .collect()
}

/// The footer's note: `glitch k/N (G next)`, k the one at the cursor if any.
pub fn footer(glitches: &[&Glitch], cursor_s: f64) -> Option<String> {
    if glitches.is_empty() {
        return None;
    }
    let at = glitches
        .iter()
        .position(|g| (g.time_s - cursor_s).abs() < 1e-6)
        .map_or("-".to_string(), |k| (k + 1).to_string());
    Some(format!("glitch {at}/{} (G next)  ", glitches.len()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rotation::quat_axis_angle_deg;
    use crate::simulate::{preset, simulate};
    use crate::trial::{write_trial, TrialFormat};
    use crate::ui::app::{Msg, Screen};
    use crate::ui::headless::{load_app, show, Show};
    use crate::ui::jobs::SyncRunner;
    use crate::ui::render::render;
    use crate::ui::tests::SIZES;
    use crate::ui::theme::Theme;
    use ratatui::crossterm::event::{KeyCode, KeyEvent};

    /// The knee trial (20 s at 50 Hz) with one corrupted calf sample at 6.00 s
    /// (sample 300, turned 120 deg about X): the trial screen marks it and `G`
    /// puts the cursor on it.
    #[test]
    fn trial_screen_marks_a_glitch_and_g_moves_there() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().join("trials");
        std::fs::create_dir_all(&dir).unwrap();
        let mut cfg = preset("knee_calf_z15").unwrap();
        cfg.duration_s = 20.0;
        let mut trial = simulate(&cfg).unwrap().trial;
        let calf = trial.imu_mut("l_calf").unwrap();
        calf.orientation[300] *= quat_axis_angle_deg([1.0, 0.0, 0.0], 120.0);
        write_trial(&trial, &dir.join("glitch.csv"), TrialFormat::QuatCsv).unwrap();
        let mut app = load_app("trials", &dir, &tmp.path().join("joint_limits")).unwrap();
        show(
            &mut app,
            &Show {
                screen: "trial".into(),
                trial: Some("glitch.csv".into()),
                ..Show::default()
            },
        )
        .unwrap();
        let l = app.open_entry().unwrap().loaded().unwrap().clone();
        assert_eq!(l.glitches.len(), 1, "{:?}", l.glitches);
        assert_eq!((l.glitches[0].index, l.glitches[0].spike), (300, true));
        SyncRunner::send(&mut app, Msg::Key(KeyEvent::from(KeyCode::Char('G'))));
        assert_eq!(app.screen, Screen::Trial);
        assert!(
            (app.view.cursor_s - 6.0).abs() < 1e-9,
            "{}",
            app.view.cursor_s
        );
        // The only glitch: G again stays on it.
        SyncRunner::send(&mut app, Msg::Key(KeyEvent::from(KeyCode::Char('G'))));
        assert!((app.view.cursor_s - 6.0).abs() < 1e-9);
        for (w, h) in SIZES {
            let mut t = ratatui::Terminal::new(ratatui::backend::TestBackend::new(w, h)).unwrap();
            t.draw(|f| render(&app, &Theme::default(), f)).unwrap();
            let text = format!("{:?}", t.backend());
            assert!(text.contains("glitch 1/1 (G next)"), "{text}");
            assert!(text.contains('×'), "no glitch marker at {w}x{h}");
            insta::assert_snapshot!(format!("trial_glitch_{w}x{h}"), t.backend());
        }
    }

    fn g(imu: &str, index: usize, time_s: f64) -> Glitch {
        Glitch {
            imu: imu.into(),
            index,
            time_s,
            jump_deg: 90.0,
            spike: true,
        }
    }

    #[test]
    fn next_wraps_and_footer_counts() {
        let all = [g("a", 10, 0.1), g("b", 50, 0.5)];
        let refs: Vec<&Glitch> = all.iter().collect();
        assert_eq!(next_after(&refs, 0.0), Some(0.1));
        assert_eq!(next_after(&refs, 0.1), Some(0.5));
        assert_eq!(next_after(&refs, 0.7), Some(0.1));
        assert_eq!(next_after(&[], 0.7), None);
        assert_eq!(footer(&refs, 0.5).unwrap(), "glitch 2/2 (G next)  ");
        assert_eq!(footer(&refs, 0.3).unwrap(), "glitch -/2 (G next)  ");
        let angles = vec![[1.0, 2.0, 3.0]; 60];
        assert_eq!(markers(&refs, &angles, 1, (0.0, 0.3)), [(0.1, 2.0)]);
    }
}
