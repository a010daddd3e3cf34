//! Line charts drawn to PNG (feature `plot`): plotters' pure-Rust bitmap backend draws them, with the
//! bundled DejaVu Sans (Bitstream Vera licence), and `png` encodes them: no system library is needed.
//! The tour's figures and the work–precision charts use them.
//!
//! ```
//! use dirac_runtime::plot::{Series, line_chart};
//! let parabola = Series {
//!     label: "x²".into(),
//!     points: (0..=10).map(|i| (i as f64, (i * i) as f64)).collect(),
//! };
//! let path = std::env::temp_dir().join("dirac_plot_example.png");
//! line_chart(&path, "a parabola", ("x", "x²"), &[parabola])?;
//! assert!(std::fs::metadata(&path)?.len() > 1000);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::path::Path;
use std::sync::Once;

use plotters::prelude::*;

use crate::base::error::DiracError;

/// One labelled curve.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// The legend's label.
    pub label: String,
    /// The points, in drawing order (non-finite ones are left out).
    pub points: Vec<(f64, f64)>,
}

impl Series {
    /// One series per label, in order of first appearance, each series' points sorted by `x`.
    ///
    /// ```
    /// use dirac_runtime::plot::Series;
    /// let lines = Series::by_label([("a", (2.0, 1.0)), ("b", (0.0, 0.0)), ("a", (1.0, 3.0))]);
    /// assert_eq!(lines[0].label, "a");
    /// assert_eq!(lines[0].points, vec![(1.0, 3.0), (2.0, 1.0)]);
    /// assert_eq!(lines[1].points, vec![(0.0, 0.0)]);
    /// ```
    pub fn by_label<L: AsRef<str>>(
        points: impl IntoIterator<Item = (L, (f64, f64))>,
    ) -> Vec<Series> {
        let mut series: Vec<Series> = Vec::new();
        for (label, point) in points {
            let label = label.as_ref();
            match series.iter_mut().find(|s| s.label == label) {
                Some(line) => line.points.push(point),
                None => series.push(Series {
                    label: label.to_string(),
                    points: vec![point],
                }),
            }
        }
        for line in &mut series {
            line.points.sort_by(|a, b| a.0.total_cmp(&b.0));
        }
        series
    }
}

/// Makes the bundled font available as "sans-serif" (once per process).
fn register_font() -> Result<(), DiracError> {
    static REGISTER: Once = Once::new();
    let mut result = Ok(());
    REGISTER.call_once(|| {
        let bytes: &'static [u8] = include_bytes!("../../assets/DejaVuSans.ttf");
        if plotters::style::register_font("sans-serif", FontStyle::Normal, bytes).is_err() {
            result = Err(DiracError::Io("the bundled font could not be read".into()));
        }
    });
    result
}

/// The size of a chart, in pixels.
const SIZE: (u32, u32) = (900, 600);

/// Draws `series` as lines on one chart, 900×600, with a legend, to the PNG file `path` (its
/// directory created if needed). An error when `path` does not end in `.png`, nothing is finite
/// or the file cannot be written.
pub fn line_chart(
    path: impl AsRef<Path>,
    title: &str,
    (x_label, y_label): (&str, &str),
    series: &[Series],
) -> Result<(), DiracError> {
    let path = path.as_ref();
    let png = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if !png {
        return Err(DiracError::Io(format!(
            "{}: charts are written as PNG; name the file *.png",
            path.display()
        )));
    }
    register_font()?;
    let written = draw(title, (x_label, y_label), series).and_then(|pixels| {
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)?;
        }
        write_png(path, SIZE, &pixels)
    });
    written.map_err(|e| DiracError::Io(format!("{}: {e}", path.display())))
}

/// The chart's pixels: 8-bit RGB, row by row.
fn draw(
    title: &str,
    (x_label, y_label): (&str, &str),
    series: &[Series],
) -> Result<Vec<u8>, Box<dyn std::error::Error>> {
    let points = series
        .iter()
        .flat_map(|s| s.points.iter())
        .filter(|(x, y)| x.is_finite() && y.is_finite());
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for &(x, y) in points {
        (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
    }
    if x0 >= x1 || !x0.is_finite() {
        return Err("nothing to draw".into());
    }
    let pad = 0.05 * (y1 - y0).max(1e-12);
    let mut pixels = vec![0u8; 3 * SIZE.0 as usize * SIZE.1 as usize];
    let root = BitMapBackend::with_buffer(&mut pixels, SIZE).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 24))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(x0..x1, (y0 - pad)..(y1 + pad))?;
    chart
        .configure_mesh()
        .x_desc(x_label)
        .y_desc(y_label)
        .label_style(("sans-serif", 15))
        .draw()?;
    for (k, s) in series.iter().enumerate() {
        let color = Palette99::pick(k).to_rgba();
        let finite = s
            .points
            .iter()
            .cloned()
            .filter(|(x, y)| x.is_finite() && y.is_finite());
        chart
            .draw_series(LineSeries::new(finite, color.stroke_width(2)))?
            .label(s.label.clone())
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
            });
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .label_font(("sans-serif", 15))
        .draw()?;
    root.present()?;
    drop(chart);
    drop(root);
    Ok(pixels)
}

/// Writes 8-bit RGB `pixels`, row by row, to the PNG file `path`.
fn write_png(
    path: &Path,
    (width, height): (u32, u32),
    pixels: &[u8],
) -> Result<(), Box<dyn std::error::Error>> {
    let file = std::io::BufWriter::new(std::fs::File::create(path)?);
    let mut encoder = png::Encoder::new(file, width, height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    // A filter chosen row by row: charts of flat colour then compress about four times better.
    encoder.set_adaptive_filter(png::AdaptiveFilterType::Adaptive);
    let mut writer = encoder.write_header()?;
    writer.write_image_data(pixels)?;
    writer.finish()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line() -> Series {
        Series {
            label: "line".into(),
            points: vec![(0.0, 0.0), (1.0, 1.0)],
        }
    }

    /// The file decodes to the pixels drawn, and those hold the curve: its colour in the lower
    /// left quarter, away from the legend (upper right).
    #[test]
    fn the_chart_is_a_png_of_the_drawn_pixels() {
        register_font().unwrap();
        let drawn = draw("a line", ("x", "y"), &[line()]).unwrap();
        let path = std::env::temp_dir().join(format!("dirac_plot_{}.png", std::process::id()));
        line_chart(&path, "a line", ("x", "y"), &[line()]).unwrap();
        let file = std::fs::File::open(&path).unwrap();
        let mut reader = png::Decoder::new(std::io::BufReader::new(file))
            .read_info()
            .unwrap();
        let mut pixels = vec![0; reader.output_buffer_size()];
        let frame = reader.next_frame(&mut pixels).unwrap();
        std::fs::remove_file(&path).unwrap();
        assert_eq!((frame.width, frame.height), SIZE);
        assert_eq!(frame.color_type, png::ColorType::Rgb);
        assert_eq!(pixels, drawn);
        let colour = Palette99::pick(0).to_rgba();
        let (width, height) = (SIZE.0 as usize, SIZE.1 as usize);
        let curve_in_lower_left = (height / 2..height).any(|row| {
            (0..width / 2).any(|column| {
                let at = 3 * (row * width + column);
                pixels[at..at + 3] == [colour.0, colour.1, colour.2]
            })
        });
        assert!(curve_in_lower_left);
        assert_eq!(&pixels[..3], &[255, 255, 255]);
    }

    /// Another format is refused before anything is drawn or written.
    #[test]
    fn only_png_files_are_written() {
        let path = std::env::temp_dir().join(format!("dirac_plot_{}.jpg", std::process::id()));
        let refused = line_chart(&path, "a line", ("x", "y"), &[line()]).unwrap_err();
        assert!(refused.to_string().contains("*.png"), "{refused}");
        assert!(!path.exists());
    }
}
