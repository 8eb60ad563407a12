//! Histograms as the thesis' Figures 3-3 to 3-6: per axis of one joint (or
//! pooled group), the samples in 1-degree bins, the limits (near-black lines),
//! the mean (grey) and the interval holding 90% of the samples (red). Angles
//! in degrees on the horizontal axis, sample counts on the vertical.

use super::{colours, draw_err, Figure, PlotError, FONT};
use crate::analysis::histogram::{AxisHistogram, JointHistogram};
use crate::limits::axis_name;
use plotters::coord::Shift;
use plotters::prelude::*;

/// What a histogram figure shows.
#[derive(Debug, Clone)]
pub struct Histograms<'a> {
    /// Title line (joint, trials, span).
    pub title: String,
    pub hist: &'a JointHistogram,
}

impl Figure for Histograms<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        if self.hist.axes.iter().all(Option::is_none) {
            return Err(PlotError::Empty(format!(
                "no samples of {}",
                self.hist.name
            )));
        }
        let root = root.titled(&self.title, (FONT, 20)).map_err(draw_err)?;
        let panels = root.split_evenly((1, 3));
        for (axis, panel) in panels.iter().enumerate() {
            if let Some(h) = &self.hist.axes[axis] {
                let range = self.hist.limits.map(|l| l.range_deg[axis]);
                panel_of(panel, axis, h, range)?;
            }
        }
        Ok(())
    }
}

/// One axis: bars, then the limit, mean and interval lines over them.
fn panel_of<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    axis: usize,
    h: &AxisHistogram,
    range: Option<[f64; 2]>,
) -> Result<(), PlotError> {
    let last_edge = h.first_edge_deg + h.counts.len() as f64 * h.bin_deg;
    let (mut x0, mut x1) = (h.first_edge_deg, last_edge);
    if let Some([l, u]) = range {
        x0 = x0.min(l);
        x1 = x1.max(u);
    }
    let pad = ((x1 - x0) * 0.03).max(1.0);
    let top = f64::from(h.peak()) * 1.1;
    let [lo90, hi90] = h.interval_deg;
    let caption = format!(
        "{}  mean {:.1}  90% [{:.1}, {:.1}]",
        axis_name(axis),
        h.mean_deg,
        lo90,
        hi90
    );
    let mut chart = ChartBuilder::on(area)
        .caption(caption, (FONT, 13))
        .margin(8)
        .x_label_area_size(34)
        .y_label_area_size(52)
        .build_cartesian_2d((x0 - pad)..(x1 + pad), 0.0..top.max(1.0))
        .map_err(draw_err)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc("deg")
        .y_desc("samples")
        .label_style((FONT, 11))
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| format!("{v:.0}"))
        .draw()
        .map_err(draw_err)?;
    let bars = h
        .counts
        .iter()
        .enumerate()
        .filter(|(_, &c)| c > 0)
        .map(|(k, &c)| {
            let left = h.first_edge_deg + k as f64 * h.bin_deg;
            Rectangle::new(
                [(left, 0.0), (left + h.bin_deg, f64::from(c))],
                colours::RAW.filled(),
            )
        });
    chart.draw_series(bars).map_err(draw_err)?;
    let vline = |x: f64| vec![(x, 0.0), (x, top)];
    let mut lines: Vec<(f64, RGBColor)> = vec![];
    if let Some([l, u]) = range {
        lines.extend([(l, colours::LIMIT), (u, colours::LIMIT)]);
    }
    lines.push((h.mean_deg, colours::MEAN));
    lines.extend([(lo90, colours::INTERVAL), (hi90, colours::INTERVAL)]);
    for (x, c) in lines {
        chart
            .draw_series(LineSeries::new(vline(x), c.stroke_width(2)))
            .map_err(draw_err)?;
    }
    Ok(())
}
