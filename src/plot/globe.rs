//! The globographic plot as a figure (thesis Figure 4-5, appendix C): the
//! distal segment's direction on a sphere around the joint, seen from the
//! middle of the limits (flexion up, ab/adduction right), the flexion and
//! ab/adduction limits as a yellow band, points coloured by limit class over
//! all three axes (rotation shows only in the colour), uncorrected beside
//! corrected. The mapping is [`crate::analysis::globe`]; points are reduced to
//! one per pixel as in [`super::scatter`].

use super::scatter::{caption, key_colours, POINT_PX};
use super::{draw_err, Figure, PlotError, FONT};
use crate::analysis::globe::{
    band_outline, band_points, extent, globe_raster, grid_lines, rect_outline, swing_outline,
    GlobeView, JointAxes,
};
use crate::analysis::scatter::{Colouring, Grid};
use crate::limits::axis_name;
use plotters::coord::Shift;
use plotters::prelude::*;

/// The band's fill (the thesis' yellow).
pub const BAND_RGB: RGBColor = RGBColor(0xff, 0xe0, 0x40);
/// Grid lines and the sphere's outline.
pub const GRID_RGB: RGBColor = RGBColor(0xc8, 0xc8, 0xc8);
/// The edge of a swing-twist region.
pub const SWING_RGB: RGBColor = RGBColor(0xd0, 0x60, 0x00);

/// What a globographic figure shows.
#[derive(Debug, Clone)]
pub struct Globe<'a> {
    /// Title line (trial and joint).
    pub title: String,
    /// The distal segment's name (the point's meaning).
    pub distal: String,
    /// Uncorrected Z-Y-X angles `[x, y, z]`, degrees.
    pub raw: &'a [[f64; 3]],
    /// Corrected angles and their label (the variant), if any.
    pub corrected: Option<(String, &'a [[f64; 3]])>,
    /// The joint's limits `[lower, upper]` per axis, degrees.
    pub range_deg: [[f64; 2]; 3],
    pub axes: JointAxes,
    pub colouring: Colouring,
    /// The joint's swing-twist region, drawn as its edge over the band, when
    /// the limit table is of that model.
    pub swing: Option<crate::limits::swing_twist::SwingTwistLimits>,
}

/// Visible runs of a polyline on the view's screen.
fn runs(view: &GlobeView, line: &[[f64; 3]]) -> Vec<Vec<(f64, f64)>> {
    let mut out = vec![vec![]];
    for d in line {
        match view.visible(*d) {
            Some(p) => out.last_mut().expect("non-empty").push(p),
            None => out.push(vec![]),
        }
    }
    out.retain(|r| r.len() > 1);
    out
}

impl Globe<'_> {
    /// The view and the square screen bounds holding the band and the samples.
    pub fn frame(&self) -> (GlobeView, [f64; 2], [f64; 2]) {
        let view = GlobeView::for_limits(&self.range_deg, self.axes);
        let mut outlines = vec![band_outline(&self.range_deg, self.axes, 32)];
        for a in std::iter::once(self.raw).chain(self.corrected.as_ref().map(|c| c.1)) {
            if let Some([f, b]) = extent(a, self.axes) {
                outlines.push(rect_outline(f, b, self.axes, 32));
            }
        }
        let (bx, by) = view.fit(&outlines, 0.06);
        // Square, about the centre of the fitted rectangle.
        let r = 0.5 * (bx[1] - bx[0]).max(by[1] - by[0]);
        let (cx, cy) = (0.5 * (bx[0] + bx[1]), 0.5 * (by[0] + by[1]));
        (view, [cx - r, cx + r], [cy - r, cy + r])
    }
}

impl Figure for Globe<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        if self.raw.is_empty() {
            return Err(PlotError::Empty("no samples of the joint".into()));
        }
        let root = root.titled(&self.title, (FONT, 20)).map_err(draw_err)?;
        let mut sets: Vec<(String, &[[f64; 3]])> = vec![("uncorrected".into(), self.raw)];
        sets.extend(self.corrected.as_ref().map(|(l, a)| (l.clone(), *a)));
        let columns = root.split_evenly((1, sets.len()));
        let frame = self.frame();
        for (column, (label, angles)) in columns.iter().zip(&sets) {
            let label = format!("{label}, {} direction", self.distal);
            let title = caption(&label, angles, Some(&self.range_deg), self.colouring);
            let column = column.titled(&title, (FONT, 14)).map_err(draw_err)?;
            self.panel(&column, angles, &frame)?;
        }
        Ok(())
    }
}

impl Globe<'_> {
    fn panel<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        angles: &[[f64; 3]],
        (view, bx, by): &(GlobeView, [f64; 2], [f64; 2]),
    ) -> Result<(), PlotError> {
        let (w, h) = area.dim_in_pixel();
        let side = w.min(h.saturating_sub(40)).max(10);
        // A square plotting area, centred.
        let area = area.margin(
            (h.saturating_sub(side) / 2) as i32,
            (h.saturating_sub(side) / 2) as i32,
            (w.saturating_sub(side) / 2) as i32,
            (w.saturating_sub(side) / 2) as i32,
        );
        let a = self.axes;
        let mut chart = ChartBuilder::on(&area)
            .margin(4)
            .x_label_area_size(24)
            .y_label_area_size(24)
            .build_cartesian_2d(bx[0]..bx[1], by[0]..by[1])
            .map_err(draw_err)?;
        chart
            .configure_mesh()
            .disable_mesh()
            .disable_x_axis()
            .disable_y_axis()
            .x_desc(format!(
                "{} ({}) ->",
                if self.swing.is_some() {
                    "swing_2"
                } else {
                    "ab/adduction"
                },
                axis_name(a.abduction)
            ))
            .y_desc(format!(
                "{} ({}) ->",
                if self.swing.is_some() {
                    "swing_1"
                } else {
                    "flexion"
                },
                axis_name(a.flexion)
            ))
            .label_style((FONT, 12))
            .draw()
            .map_err(draw_err)?;
        // The sphere's outline and grid lines every 30 degrees.
        let circle = (0..=360).map(|k| {
            let t = (k as f64).to_radians();
            (t.cos(), t.sin())
        });
        chart
            .draw_series(std::iter::once(PathElement::new(
                circle.collect::<Vec<_>>(),
                GRID_RGB,
            )))
            .map_err(draw_err)?;
        for line in grid_lines(a, 30.0, 121) {
            for run in runs(view, &line) {
                chart
                    .draw_series(std::iter::once(PathElement::new(run, GRID_RGB)))
                    .map_err(draw_err)?;
            }
        }
        // The band: a filled polygon when it lies on the visible side, else points.
        let outline = band_outline(&self.range_deg, a, 64);
        let poly: Option<Vec<(f64, f64)>> = outline.iter().map(|d| view.visible(*d)).collect();
        match poly {
            Some(p) => chart
                .draw_series(std::iter::once(Polygon::new(p, BAND_RGB.filled())))
                .map_err(draw_err)?,
            None => chart
                .draw_series(
                    band_points(&self.range_deg, a, 0.5)
                        .into_iter()
                        .filter_map(|d| view.visible(d))
                        .map(|xy| Circle::new(xy, 1, BAND_RGB.filled())),
                )
                .map_err(draw_err)?,
        };
        // A swing-twist table's region: its edge, over the band (its box).
        if let Some(st) = &self.swing {
            for run in runs(view, &swing_outline(st, 256)) {
                chart
                    .draw_series(std::iter::once(PathElement::new(
                        run,
                        SWING_RGB.stroke_width(2),
                    )))
                    .map_err(draw_err)?;
            }
        }
        // The samples, one point per pixel, lower keys first.
        let (pw, ph) = chart.plotting_area().dim_in_pixel();
        let grid = Grid {
            w: pw as usize,
            h: ph as usize,
            bx: *bx,
            by: *by,
        };
        let raster = globe_raster(angles, &self.range_deg, a, view, self.colouring, grid);
        let colours = key_colours(self.colouring);
        for key in 0..colours.len() as u8 {
            let points = raster
                .dots()
                .filter(|d| d.2 == key)
                .map(|(c, r, _)| raster.centre(c, r, *bx, *by))
                .map(|xy| Circle::new(xy, POINT_PX, colours[key as usize].filled()));
            chart.draw_series(points).map_err(draw_err)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plot::scatter::CLASS_RGB;
    use crate::plot::to_svg;

    #[test]
    fn svg_has_the_band_the_outline_and_class_coloured_points() {
        let knee = [[-5.0, 5.0], [0.0, 130.0], [-5.0, 5.0]];
        // Well apart on the sphere: 3 within, 2 near (rotation only: inside
        // the band, purple), 2 beyond.
        let raw = [
            [0.0, 20.0, 0.0],
            [0.0, 65.0, 3.0],
            [0.0, 110.0, -3.0],
            [12.0, 40.0, 0.0],
            [-9.0, 90.0, 0.0],
            [0.0, 50.0, 30.0],
            [0.0, 80.0, -25.0],
        ];
        let fig = Globe {
            title: "l_knee".into(),
            distal: "l_calf".into(),
            raw: &raw,
            corrected: None,
            range_deg: knee,
            axes: JointAxes::default(),
            colouring: Colouring::Limits,
            swing: None,
        };
        let svg = to_svg(&fig, (900, 900)).unwrap();
        let fill = |c: RGBColor| format!("fill=\"#{:02X}{:02X}{:02X}\"", c.0, c.1, c.2);
        assert_eq!(svg.matches("<polygon").count(), 1, "one band");
        assert!(svg.contains(&fill(BAND_RGB)));
        assert_eq!(svg.matches("<circle").count(), 7);
        assert_eq!(svg.matches(&fill(CLASS_RGB[0])).count(), 3);
        assert_eq!(svg.matches(&fill(CLASS_RGB[1])).count(), 2);
        assert_eq!(svg.matches(&fill(CLASS_RGB[2])).count(), 2);
        assert!(svg.contains("ab/adduction (Z) -&gt;") || svg.contains("ab/adduction (Z) ->"));
        assert!(svg.contains("flexion (Y)"));
        assert!(svg.contains("<polyline"), "outline and grid");
    }
}
