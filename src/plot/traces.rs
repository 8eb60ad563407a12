//! Traces: one joint's X, Y and Z angles (degrees) over time (seconds from the
//! first sample), uncorrected and corrected, with the limit lines and the
//! centroid, one panel per axis. Long trials are reduced to a min/max
//! envelope per pixel column, so spikes stay visible and files stay small.

use super::envelope::envelope;
use super::{colours, draw_err, Figure, PlotError, FONT};
use crate::limits::{axis_name, JointLimits};
use plotters::coord::Shift;
use plotters::prelude::*;

/// What a traces figure shows.
#[derive(Debug, Clone)]
pub struct Traces<'a> {
    /// Title line (trial and joint).
    pub title: String,
    /// Sample times as recorded, seconds, ascending.
    pub time_s: &'a [f64],
    /// Uncorrected Z-Y-X angles `[x, y, z]`, degrees, one per sample.
    pub raw: &'a [[f64; 3]],
    /// Corrected angles and their label (the variant), if any.
    pub corrected: Option<(String, &'a [[f64; 3]])>,
    /// The joint's limits and centroid, degrees.
    pub limits: Option<JointLimits>,
    /// Span shown, seconds from the first sample.
    pub span_s: (f64, f64),
}

impl Figure for Traces<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        if self.raw.is_empty() || self.time_s.len() != self.raw.len() {
            return Err(PlotError::Empty("no samples of the joint".into()));
        }
        let root = root.titled(&self.title, (FONT, 20)).map_err(draw_err)?;
        let panels = root.split_evenly((3, 1));
        for (axis, panel) in panels.iter().enumerate() {
            self.panel(panel, axis)?;
        }
        Ok(())
    }
}

impl Traces<'_> {
    fn panel<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        axis: usize,
    ) -> Result<(), PlotError> {
        let (t0, t1) = self.span_s;
        let origin = self.time_s[0];
        let range = self.limits.map(|l| l.range_deg[axis]);
        let centroid = self.limits.and_then(|l| l.centroid_deg).map(|c| c[axis]);
        // Bounds from the samples in view and the limits.
        let (a, b) = (
            self.time_s.partition_point(|&t| t - origin < t0),
            self.time_s.partition_point(|&t| t - origin <= t1),
        );
        let series = std::iter::once(self.raw).chain(self.corrected.as_ref().map(|c| c.1));
        let (mut lo, mut hi) = series
            .flat_map(|s| s[a..b.max(a)].iter().map(move |v| v[axis]))
            .chain(range.into_iter().flatten())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(v), hi.max(v))
            });
        if !(lo.is_finite() && hi.is_finite()) {
            (lo, hi) = (-1.0, 1.0);
        }
        let pad = ((hi - lo) * 0.05).max(0.5);
        let mut caption = axis_name(axis).to_string();
        if let Some([l, h]) = range {
            caption.push_str(&format!("  limits [{l}, {h}]"));
        }
        if let Some(c) = centroid {
            caption.push_str(&format!("  centroid {c}"));
        }
        let mut chart = ChartBuilder::on(area)
            .caption(caption, (FONT, 14))
            .margin(6)
            .x_label_area_size(if axis == 2 { 34 } else { 20 })
            .y_label_area_size(48)
            .build_cartesian_2d(t0..t1, (lo - pad)..(hi + pad))
            .map_err(draw_err)?;
        let mut mesh = chart.configure_mesh();
        mesh.disable_mesh()
            .y_desc("deg")
            .label_style((FONT, 11))
            .x_label_formatter(&|v| format!("{v:.0}"))
            .y_label_formatter(&|v| format!("{v:.0}"));
        if axis == 2 {
            mesh.x_desc("time (s)");
        }
        mesh.draw().map_err(draw_err)?;
        let line = |y: f64| vec![(t0, y), (t1, y)];
        if let Some([l, h]) = range {
            for y in [l, h] {
                chart
                    .draw_series(LineSeries::new(line(y), colours::LIMIT.stroke_width(1)))
                    .map_err(draw_err)?;
            }
        }
        if let Some(c) = centroid {
            chart
                .draw_series(LineSeries::new(line(c), colours::CENTROID.stroke_width(1)))
                .map_err(draw_err)?;
        }
        let columns = area.dim_in_pixel().0 as usize;
        let raw = envelope(self.time_s, origin, |i| self.raw[i][axis], t0, t1, columns);
        let s = chart
            .draw_series(LineSeries::new(raw, colours::RAW.stroke_width(1)))
            .map_err(draw_err)?;
        if axis == 0 {
            s.label("uncorrected")
                .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], colours::RAW));
        }
        if let Some((label, cor)) = &self.corrected {
            let pts = envelope(self.time_s, origin, |i| cor[i][axis], t0, t1, columns);
            let s = chart
                .draw_series(LineSeries::new(pts, colours::CORRECTED.stroke_width(1)))
                .map_err(draw_err)?;
            if axis == 0 {
                s.label(label.as_str()).legend(|(x, y)| {
                    PathElement::new(vec![(x, y), (x + 16, y)], colours::CORRECTED)
                });
            }
        }
        if axis == 0 {
            chart
                .configure_series_labels()
                .position(SeriesLabelPosition::UpperRight)
                .background_style(WHITE.mix(0.8))
                .border_style(BLACK)
                .label_font((FONT, 11))
                .draw()
                .map_err(draw_err)?;
        }
        Ok(())
    }
}
