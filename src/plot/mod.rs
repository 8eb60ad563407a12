//! Figures for papers: `acmw plot` draws with the plotters crate and writes
//! SVG or PNG (chosen by the output's extension). One module per kind of
//! figure; each builds a [`Figure`] from library data, so the same figure
//! goes to either format.
//!
//! Text is drawn with the DejaVu Sans font shipped in `assets/fonts` (the
//! PNG never depends on the system's fonts; an SVG names `sans-serif` and the
//! viewer's font draws it).

pub mod envelope;
pub mod globe;
pub mod histogram;
pub mod scatter;
pub mod traces;

use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// The kinds of figure `acmw plot` draws.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlotKind {
    /// A joint's X, Y and Z angles over time, uncorrected and corrected, with
    /// the limit and centroid lines ([`traces`]).
    Traces,
    /// Histograms of a joint's angles over trials with the limits, the mean
    /// and the 90% interval, as the thesis' Figures 3-3 to 3-6 ([`histogram`]).
    Histogram,
    /// A joint's Z-Y-X angles as three projections, points coloured by limit
    /// class or time, uncorrected beside corrected ([`scatter`]).
    Scatter,
    /// The distal segment's direction on a sphere around the joint with the
    /// limit band, as the thesis' Figure 4-5 ([`globe`]).
    Globe,
}

/// Output format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    Svg,
    Png,
}

impl Format {
    /// The format a path's extension asks for (`.svg` or `.png`, any case).
    pub fn from_path(path: &Path) -> Result<Format, PlotError> {
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("svg") => Ok(Format::Svg),
            Some("png") => Ok(Format::Png),
            _ => Err(PlotError::Format(path.display().to_string())),
        }
    }
}

/// Why a figure could not be made.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    #[error("{0}: expected an output file ending in .svg or .png")]
    Format(String),
    #[error("cannot draw the figure: {0}")]
    Draw(String),
    #[error("{path}: cannot write: {source}")]
    Io {
        path: String,
        source: std::io::Error,
    },
    #[error("nothing to plot: {0}")]
    Empty(String),
}

/// A figure that draws itself on any plotters backend.
pub trait Figure {
    /// Draws on `root` (already filled white).
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError>;
}

/// The font family every figure uses.
pub const FONT: &str = "sans-serif";

static FONT_BYTES: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

fn register_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        // The shipped font parses; a failure here would be a broken build.
        let _ = plotters::style::register_font(FONT, FontStyle::Normal, FONT_BYTES);
    });
}

/// A plotters error as text.
pub fn draw_err<E: std::fmt::Debug>(e: E) -> PlotError {
    PlotError::Draw(format!("{e:?}"))
}

/// The figure as SVG text, `size` in pixels (width, height).
pub fn to_svg(fig: &impl Figure, size: (u32, u32)) -> Result<String, PlotError> {
    register_font();
    let mut out = String::new();
    {
        let root = SVGBackend::with_string(&mut out, size).into_drawing_area();
        root.fill(&WHITE).map_err(draw_err)?;
        fig.draw(&root)?;
        root.present().map_err(draw_err)?;
    }
    Ok(out)
}

/// The figure as PNG bytes (8-bit RGB), `size` in pixels.
pub fn to_png(fig: &impl Figure, size: (u32, u32)) -> Result<Vec<u8>, PlotError> {
    register_font();
    let mut rgb = vec![0u8; size.0 as usize * size.1 as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, size).into_drawing_area();
        root.fill(&WHITE).map_err(draw_err)?;
        fig.draw(&root)?;
        root.present().map_err(draw_err)?;
    }
    let mut png_bytes = vec![];
    {
        let mut enc = png::Encoder::new(&mut png_bytes, size.0, size.1);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        let mut w = enc.write_header().map_err(draw_err)?;
        w.write_image_data(&rgb).map_err(draw_err)?;
    }
    Ok(png_bytes)
}

/// Draws `fig` and writes it to `path` (format from the extension) atomically.
pub fn write(fig: &impl Figure, path: &Path, size: (u32, u32)) -> Result<(), PlotError> {
    let bytes = match Format::from_path(path)? {
        Format::Svg => to_svg(fig, size)?.into_bytes(),
        Format::Png => to_png(fig, size)?,
    };
    crate::save::atomic_write(path, &bytes).map_err(|source| PlotError::Io {
        path: path.display().to_string(),
        source,
    })
}

/// Colours shared by the figures (the thesis' convention where it has one).
pub mod colours {
    use plotters::style::RGBColor;
    /// Uncorrected angles and histogram bars.
    pub const RAW: RGBColor = RGBColor(0x1f, 0x77, 0xb4);
    /// Corrected angles.
    pub const CORRECTED: RGBColor = RGBColor(0xd6, 0x27, 0x28);
    /// Limit lines (the thesis' black dashed lines).
    pub const LIMIT: RGBColor = RGBColor(0x20, 0x20, 0x20);
    /// Centroid lines.
    pub const CENTROID: RGBColor = RGBColor(0x2c, 0xa0, 0x2c);
    /// The mean (the thesis' grey line).
    pub const MEAN: RGBColor = RGBColor(0x80, 0x80, 0x80);
    /// The 90% interval (the thesis' red lines).
    pub const INTERVAL: RGBColor = RGBColor(0xff, 0x00, 0x00);
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Box1;
    impl Figure for Box1 {
        fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
            root.draw(&Text::new("hi", (5, 5), (FONT, 12)))
                .map_err(draw_err)?;
            root.draw(&Rectangle::new([(10, 10), (20, 20)], colours::RAW.filled()))
                .map_err(draw_err)
        }
    }

    #[test]
    fn formats_come_from_the_extension_and_both_write() {
        assert_eq!(Format::from_path(Path::new("a.SVG")).unwrap(), Format::Svg);
        assert_eq!(Format::from_path(Path::new("a.png")).unwrap(), Format::Png);
        let e = Format::from_path(Path::new("a.pdf")).unwrap_err();
        assert!(e.to_string().contains("a.pdf: expected"), "{e}");
        let svg = to_svg(&Box1, (40, 30)).unwrap();
        assert!(
            svg.starts_with("<svg") && svg.contains(">\nhi\n</text>"),
            "{svg}"
        );
        let png = to_png(&Box1, (40, 30)).unwrap();
        assert_eq!(&png[1..4], b"PNG");
        // The text was rasterised with the shipped font: left of the box,
        // where only the text can be, some pixel is not white.
        let mut dec = png::Decoder::new(std::io::Cursor::new(&png))
            .read_info()
            .unwrap();
        let mut rgb = vec![0; dec.output_buffer_size()];
        dec.next_frame(&mut rgb).unwrap();
        let px = |x: usize, y: usize| &rgb[(y * 40 + x) * 3..(y * 40 + x) * 3 + 3];
        assert!((5..10).any(|x| (4..20).any(|y| px(x, y) != [255, 255, 255])));
        assert_eq!(px(15, 15), [0x1f, 0x77, 0xb4]);
        let dir = tempfile::tempdir().unwrap();
        write(&Box1, &dir.path().join("f.png"), (40, 30)).unwrap();
        assert!(dir.path().join("f.png").exists());
    }
}
