//! The 3-D scatter as a figure (thesis appendix B): a joint's Z-Y-X angles
//! (degrees) as three projections, X-Y, X-Z and Y-Z, uncorrected in the left
//! column and corrected in the right, the limits as rectangles, points
//! coloured by limit class (blue within, purple within 10 deg, red beyond) or
//! by time. Samples are reduced to one point per pixel of the plotting area
//! (keeping the worst class, or the latest time, of the pixel; see
//! [`crate::analysis::scatter::Raster`]), so a 30-minute trial makes a small
//! file that looks the same as plotting every sample.

use super::{draw_err, Figure, PlotError, FONT};
use crate::analysis::scatter::{
    axis_bounds, scatter_rasters, ClassCounts, Colouring, LimitClass, PROJECTIONS,
};
use crate::limits::axis_name;
use plotters::coord::Shift;
use plotters::prelude::*;

/// Point colours of the limit classes (the thesis' blue, purple, red).
pub const CLASS_RGB: [RGBColor; 3] = [
    RGBColor(0x1f, 0x4e, 0xd8),
    RGBColor(0x9b, 0x30, 0xc8),
    RGBColor(0xe0, 0x1b, 0x1b),
];
/// Point colours of the time bands, earliest first.
pub const TIME_RGB: [RGBColor; 6] = [
    RGBColor(0x1f, 0x4e, 0xd8),
    RGBColor(0x17, 0xa2, 0xb8),
    RGBColor(0x2c, 0xa0, 0x2c),
    RGBColor(0xd8, 0xb0, 0x00),
    RGBColor(0xf0, 0x6a, 0x1a),
    RGBColor(0xc0, 0x1f, 0x8f),
];
/// The limits (the thesis' yellow band), drawn a little darker on white.
pub const LIMIT_RGB: RGBColor = RGBColor(0xe6, 0xb8, 0x00);
/// Radius of a point, pixels.
pub const POINT_PX: i32 = 2;

/// The colours of `colouring`'s keys.
pub fn key_colours(c: Colouring) -> &'static [RGBColor] {
    match c {
        Colouring::Limits => &CLASS_RGB,
        Colouring::Time => &TIME_RGB,
    }
}

/// What a scatter figure shows.
#[derive(Debug, Clone)]
pub struct Scatter<'a> {
    /// Title line (trial and joint).
    pub title: String,
    /// Uncorrected Z-Y-X angles `[x, y, z]`, degrees.
    pub raw: &'a [[f64; 3]],
    /// Corrected angles and their label (the variant), if any.
    pub corrected: Option<(String, &'a [[f64; 3]])>,
    /// The joint's limits `[lower, upper]` per axis, degrees.
    pub range_deg: Option<[[f64; 2]; 3]>,
    pub colouring: Colouring,
}

/// A legend caption: the share of samples per class, or the time bands.
pub fn caption(
    label: &str,
    angles: &[[f64; 3]],
    range: Option<&[[f64; 2]; 3]>,
    c: Colouring,
) -> String {
    match (c, range) {
        (Colouring::Limits, Some(r)) => {
            let n = ClassCounts::of(angles, r);
            format!(
                "{label}: within {:.1}%, <=10 deg out {:.1}%, >10 deg out {:.1}%",
                n.pct(LimitClass::Within),
                n.pct(LimitClass::Near),
                n.pct(LimitClass::Beyond)
            )
        }
        (Colouring::Limits, None) => format!("{label}: no limits"),
        (Colouring::Time, _) => format!("{label}: coloured by time, blue (start) to magenta (end)"),
    }
}

impl Figure for Scatter<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        if self.raw.is_empty() {
            return Err(PlotError::Empty("no samples of the joint".into()));
        }
        let root = root.titled(&self.title, (FONT, 20)).map_err(draw_err)?;
        let mut sets: Vec<&[[f64; 3]]> = vec![self.raw];
        sets.extend(self.corrected.as_ref().map(|c| c.1));
        let bounds = axis_bounds(&sets, self.range_deg.as_ref());
        let columns = root.split_evenly((1, sets.len()));
        let labels = std::iter::once("uncorrected".to_string())
            .chain(self.corrected.as_ref().map(|c| c.0.clone()));
        for ((column, angles), label) in columns.iter().zip(&sets).zip(labels) {
            let title = caption(&label, angles, self.range_deg.as_ref(), self.colouring);
            let column = column.titled(&title, (FONT, 14)).map_err(draw_err)?;
            for (p, panel) in column.split_evenly((3, 1)).iter().enumerate() {
                self.panel(panel, angles, &bounds, p)?;
            }
        }
        Ok(())
    }
}

impl Scatter<'_> {
    fn panel<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        angles: &[[f64; 3]],
        bounds: &[[f64; 2]; 3],
        p: usize,
    ) -> Result<(), PlotError> {
        let (hx, vy) = PROJECTIONS[p];
        let (bx, by) = (bounds[hx], bounds[vy]);
        let mut chart = ChartBuilder::on(area)
            .margin(6)
            .x_label_area_size(30)
            .y_label_area_size(44)
            .build_cartesian_2d(bx[0]..bx[1], by[0]..by[1])
            .map_err(draw_err)?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc(format!("{} (deg)", axis_name(hx)))
            .y_desc(format!("{} (deg)", axis_name(vy)))
            .label_style((FONT, 12))
            .draw()
            .map_err(draw_err)?;
        if let Some(r) = &self.range_deg {
            chart
                .draw_series(std::iter::once(Rectangle::new(
                    [(r[hx][0], r[vy][0]), (r[hx][1], r[vy][1])],
                    LIMIT_RGB.stroke_width(2),
                )))
                .map_err(draw_err)?;
        }
        // One point per pixel of the plotting area.
        let (w, h) = chart.plotting_area().dim_in_pixel();
        let range = self.range_deg.unwrap_or([[-180.0, 180.0]; 3]);
        let rasters = scatter_rasters(
            angles,
            &range,
            bounds,
            self.colouring,
            w as usize,
            h as usize,
        );
        let raster = &rasters[p];
        let colours = key_colours(self.colouring);
        // Lower keys first, so that a beyond point is drawn over a within one.
        for key in 0..colours.len() as u8 {
            let points = raster
                .dots()
                .filter(|d| d.2 == key)
                .map(|(c, r, _)| raster.centre(c, r, bx, by))
                .map(|xy| Circle::new(xy, POINT_PX, colours[key as usize].filled()));
            chart.draw_series(points).map_err(draw_err)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plot::to_svg;

    const KNEE: [[f64; 2]; 3] = [[-5.0, 5.0], [0.0, 130.0], [-5.0, 5.0]];

    fn fill(c: RGBColor) -> String {
        format!("fill=\"#{:02X}{:02X}{:02X}\"", c.0, c.1, c.2)
    }

    #[test]
    fn svg_has_axes_limits_and_one_point_per_sample() {
        // Samples far apart (distinct pixels in every projection): 4 within,
        // 3 near, 5 beyond, uncorrected; the corrected all within.
        let mut raw = vec![];
        for k in 0..4 {
            raw.push([
                -4.0 + 2.0 * k as f64,
                10.0 + 30.0 * k as f64,
                4.0 - 2.5 * k as f64,
            ]);
        }
        for k in 0..3 {
            raw.push([
                8.0 + 2.0 * k as f64,
                20.0 + 25.0 * k as f64,
                0.0 - 1.5 * k as f64,
            ]);
        }
        for k in 0..5 {
            raw.push([
                20.0 + 4.0 * k as f64,
                150.0 - 30.0 * k as f64,
                30.0 - 9.0 * k as f64,
            ]);
        }
        let cor: Vec<[f64; 3]> = (0..raw.len())
            .map(|k| {
                [
                    -4.5 + 0.8 * k as f64,
                    5.0 + 10.0 * k as f64,
                    4.5 - 0.8 * k as f64,
                ]
            })
            .collect();
        let fig = Scatter {
            title: "knee test".into(),
            raw: &raw,
            corrected: Some(("drift".into(), &cor)),
            range_deg: Some(KNEE),
            colouring: Colouring::Limits,
        };
        let svg = to_svg(&fig, (1200, 1500)).unwrap();
        // Axes: six panels, each with its two axis names.
        for name in ["X (deg)", "Y (deg)", "Z (deg)"] {
            assert_eq!(
                svg.matches(&format!(">\n{name}\n</text>")).count(),
                4,
                "{name}"
            );
        }
        // Limits: one rectangle per panel in the limit colour.
        let stroke = format!(
            "stroke=\"#{:02X}{:02X}{:02X}\"",
            LIMIT_RGB.0, LIMIT_RGB.1, LIMIT_RGB.2
        );
        assert_eq!(svg.matches(&stroke).count(), 6);
        // Points: every sample once per projection, in its class colour.
        assert_eq!(svg.matches("<circle").count(), 6 * raw.len());
        assert_eq!(
            svg.matches(&fill(CLASS_RGB[0])).count(),
            3 * 4 + 3 * raw.len()
        );
        assert_eq!(svg.matches(&fill(CLASS_RGB[1])).count(), 3 * 3);
        assert_eq!(svg.matches(&fill(CLASS_RGB[2])).count(), 3 * 5);
        assert!(svg.contains("uncorrected: within 33.3%,"));
        assert!(svg.contains("drift: within 100.0%,"));
        // A long trial stays small: at most one point per pixel.
        let many: Vec<[f64; 3]> = (0..20_000)
            .map(|i| {
                let t = i as f64 * 0.01;
                [3.0 * t.sin(), 65.0 + 60.0 * (0.3 * t).sin(), 2.0 * t.cos()]
            })
            .collect();
        let fig = Scatter {
            title: "long".into(),
            raw: &many,
            corrected: None,
            range_deg: Some(KNEE),
            colouring: Colouring::Time,
        };
        let svg = to_svg(&fig, (600, 900)).unwrap();
        let n = svg.matches("<circle").count();
        assert!(n > 100 && n < 3 * 600 * 300 / 4, "{n}");
        assert!(svg.contains(&fill(TIME_RGB[5])));
    }
}
