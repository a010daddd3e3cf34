//! Charts drawn to PNG (feature `plot`): lines in the plane ([`line_chart`]), curves in space
//! ([`space_chart`]) and a field over space and time ([`space_time_chart`]). Plotters' pure-Rust bitmap backend draws them with the bundled DejaVu Sans
//! (Bitstream Vera licence) and `png` encodes them: no system library is needed. The tour's
//! figures and the work–precision charts use them.
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

use plotters::chart::SeriesLabelStyle;
use plotters::coord::{CoordTranslate, Shift};
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

/// One labelled curve in space.
#[derive(Debug, Clone, PartialEq)]
pub struct SpaceSeries {
    /// The legend's label.
    pub label: String,
    /// The points `[x, y, z]`, in drawing order (non-finite ones are left out).
    pub points: Vec<[f64; 3]>,
}

/// The size of a chart, in pixels.
const SIZE: (u32, u32) = (900, 600);

/// An error, for the chart's file.
type Failure = Box<dyn std::error::Error>;

/// Draws `series` as lines on one chart, 900×600, with a legend, to the PNG file `path` (its
/// directory created if needed). An error when `path` does not end in `.png`, nothing is finite
/// or the file cannot be written.
pub fn line_chart(
    path: impl AsRef<Path>,
    title: &str,
    (x_label, y_label): (&str, &str),
    series: &[Series],
) -> Result<(), DiracError> {
    save(path.as_ref(), || draw(title, (x_label, y_label), series))
}

/// Draws `series` as curves in space, seen in perspective from above and aside with `z` up, in
/// a cube of equal scales (lengths and angles as they are), 900×600 with a legend, to the PNG
/// file `path`: the motion of a mechanism or a body's axis. Errors as [`line_chart`]'s.
///
/// ```
/// use dirac_runtime::plot::{SpaceSeries, space_chart};
/// let helix = SpaceSeries {
///     label: "helix".into(),
///     points: (0..=200).map(|i| {
///         let t = 0.1 * i as f64;
///         [t.cos(), t.sin(), 0.05 * t]
///     }).collect(),
/// };
/// let path = std::env::temp_dir().join("dirac_space_chart_example.png");
/// space_chart(&path, "a helix", &[helix])?;
/// assert!(std::fs::metadata(&path)?.len() > 1000);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn space_chart(
    path: impl AsRef<Path>,
    title: &str,
    series: &[SpaceSeries],
) -> Result<(), DiracError> {
    save(path.as_ref(), || draw_in_space(title, series))
}

/// Draws a field over space and time as a map, 900×600, to the PNG file `path`: `x` along the
/// horizontal axis, time up, the field's value `snapshots[k].1[j]` at `(x[j], snapshots[k].0)`
/// in colour from blue (its least value) through white to red (its largest), the range in the
/// title; where the values take both signs, white is zero and the range is symmetric about it.
/// A field over a plane is drawn the same way, its rows `(y, values)` as the snapshots. At most 600 columns and 400 rows are drawn (evenly picked). An error where a snapshot
/// does not have one value per position, where the positions or the times are not finite or do
/// not increase, where there are fewer than two positions or snapshots, and as
/// [`line_chart`]'s.
///
/// ```
/// use dirac_runtime::plot::space_time_chart;
/// let x: Vec<f64> = (0..=50).map(|j| 0.02 * j as f64).collect();
/// let wave = |t: f64| x.iter().map(|x| (6.0 * (x - t)).sin()).collect::<Vec<_>>();
/// let snapshots: Vec<(f64, Vec<f64>)> = (0..=20).map(|k| (0.05 * k as f64, wave(0.05 * k as f64))).collect();
/// let path = std::env::temp_dir().join("dirac_space_time_example.png");
/// space_time_chart(&path, "a travelling wave", ("x", "t"), &x, &snapshots)?;
/// assert!(std::fs::metadata(&path)?.len() > 1000);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn space_time_chart(
    path: impl AsRef<Path>,
    title: &str,
    labels: (&str, &str),
    x: &[f64],
    snapshots: &[(f64, Vec<f64>)],
) -> Result<(), DiracError> {
    if let Some((t, values)) = snapshots.iter().find(|(_, v)| v.len() != x.len()) {
        return Err(DiracError::Dimension(format!(
            "the snapshot at t = {t} has {} values for {} positions",
            values.len(),
            x.len()
        )));
    }
    let times: Vec<f64> = snapshots.iter().map(|(t, _)| *t).collect();
    for (what, axis) in [("position", x), ("snapshot time", &times[..])] {
        if let Some((k, &bad)) = axis.iter().enumerate().find(|(_, a)| !a.is_finite()) {
            return Err(DiracError::NonFinite {
                what: format!("{what} {k} of a space-time chart"),
                value: bad,
            });
        }
        if let Some(k) = axis.windows(2).position(|w| w[1] <= w[0]) {
            return Err(DiracError::Dimension(format!(
                "the {what}s of a space-time chart must increase: {} then {}",
                axis[k],
                axis[k + 1]
            )));
        }
    }
    save(path.as_ref(), || {
        draw_space_time(title, labels, x, snapshots)
    })
}

/// Checks that `path` names a PNG file, draws, and writes the pixels there.
fn save(path: &Path, pixels: impl FnOnce() -> Result<Vec<u8>, Failure>) -> Result<(), DiracError> {
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
    let written = pixels().and_then(|pixels| {
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)?;
        }
        write_png(path, SIZE, &pixels)
    });
    written.map_err(|e| DiracError::Io(format!("{}: {e}", path.display())))
}

/// The pixels (8-bit RGB, row by row) of a white chart on which `draw` draws.
fn canvas(
    draw: impl FnOnce(&DrawingArea<BitMapBackend<'_>, Shift>) -> Result<(), Failure>,
) -> Result<Vec<u8>, Failure> {
    let mut pixels = vec![0u8; 3 * SIZE.0 as usize * SIZE.1 as usize];
    let root = BitMapBackend::with_buffer(&mut pixels, SIZE).into_drawing_area();
    root.fill(&WHITE)?;
    draw(&root)?;
    root.present()?;
    drop(root);
    Ok(pixels)
}

/// The smallest and largest finite value of each of `values`' coordinates; `None` where no point
/// is finite or every point is the same.
fn bounds<const D: usize>(values: impl Iterator<Item = [f64; D]>) -> Option<[(f64, f64); D]> {
    let mut bounds = [(f64::INFINITY, f64::NEG_INFINITY); D];
    for point in values.filter(|p| p.iter().all(|x| x.is_finite())) {
        for (b, x) in bounds.iter_mut().zip(point) {
            *b = (b.0.min(x), b.1.max(x));
        }
    }
    let spread = bounds.iter().map(|b| b.1 - b.0).fold(0.0, f64::max);
    (spread > 0.0).then_some(bounds)
}

/// The 2-D chart's pixels.
fn draw(
    title: &str,
    (x_label, y_label): (&str, &str),
    series: &[Series],
) -> Result<Vec<u8>, Failure> {
    let points = series
        .iter()
        .flat_map(|s| s.points.iter().map(|&(x, y)| [x, y]));
    let [(x0, x1), (y0, y1)] = bounds(points).ok_or("nothing to draw")?;
    if x0 >= x1 {
        return Err("nothing to draw".into());
    }
    let pad = 0.05 * (y1 - y0).max(1e-12);
    canvas(|root| {
        let mut chart = ChartBuilder::on(root)
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
            let finite = s
                .points
                .iter()
                .filter(|(x, y)| x.is_finite() && y.is_finite());
            curve(&mut chart, k, &s.label, finite.copied())?;
        }
        legend(&mut chart.configure_series_labels())
    })
}

/// The 3-D chart's pixels. plotters' second axis is the vertical one: `z` is drawn along it.
fn draw_in_space(title: &str, series: &[SpaceSeries]) -> Result<Vec<u8>, Failure> {
    let points = series.iter().flat_map(|s| s.points.iter().copied());
    let [(x0, x1), (y0, y1), (z0, z1)] = bounds(points).ok_or("nothing to draw")?;
    // A cube about the points' centre, so that every axis has the same scale.
    let half = 0.55 * (x1 - x0).max(y1 - y0).max(z1 - z0);
    let range = |(a, b): (f64, f64)| (0.5 * (a + b) - half)..(0.5 * (a + b) + half);
    let finite = |p: &&[f64; 3]| p.iter().all(|x| x.is_finite());
    canvas(|root| {
        let mut chart = ChartBuilder::on(root)
            .caption(title, ("sans-serif", 24))
            .margin(15)
            .build_cartesian_3d(range((x0, x1)), range((z0, z1)), range((y0, y1)))?;
        chart.with_projection(|mut view| {
            view.yaw = 0.6;
            view.pitch = 0.35;
            view.scale = 0.85;
            view.into_matrix()
        });
        chart
            .configure_axes()
            .label_style(("sans-serif", 13))
            .draw()?;
        for (k, s) in series.iter().enumerate() {
            let points = s.points.iter().filter(finite).map(|p| (p[0], p[2], p[1]));
            curve(&mut chart, k, &s.label, points)?;
        }
        legend(&mut chart.configure_series_labels())
    })
}

/// The space–time map's pixels: a rectangle per picked position and snapshot.
fn draw_space_time(
    title: &str,
    (x_label, t_label): (&str, &str),
    x: &[f64],
    snapshots: &[(f64, Vec<f64>)],
) -> Result<Vec<u8>, Failure> {
    if x.len() < 2 || snapshots.len() < 2 {
        return Err("a space-time chart needs two positions and two snapshots".into());
    }
    let values = snapshots.iter().flat_map(|(_, v)| v.iter().map(|&u| [u]));
    let [(low, high)] = bounds(values).unwrap_or([(-1.0, 1.0)]);
    // Values of both signs: white at zero, the range symmetric about it.
    let (low, high) = match low < 0.0 && high > 0.0 {
        true => (-high.max(-low), high.max(-low)),
        false => (low, high),
    };
    let picked = |count: usize, most: usize| -> Vec<usize> {
        let step = count.div_ceil(most).max(1);
        (0..count).step_by(step).collect()
    };
    let (columns, rows) = (picked(x.len(), 600), picked(snapshots.len(), 400));
    // Each picked column spans to the next one's position (the last as wide as the one before).
    let span = |picked: &[usize], at: &dyn Fn(usize) -> f64, i: usize| {
        let start = at(picked[i]);
        let end = match picked.get(i + 1) {
            Some(&next) => at(next),
            None => start + (start - at(picked[i - 1])),
        };
        (start, end)
    };
    let position = |j: usize| x[j];
    let time = |k: usize| snapshots[k].0;
    let (x0, x1) = (
        span(&columns, &position, 0).0,
        span(&columns, &position, columns.len() - 1).1,
    );
    let (t0, t1) = (
        span(&rows, &time, 0).0,
        span(&rows, &time, rows.len() - 1).1,
    );
    let caption = format!("{title} (blue {low:.3} to red {high:.3})");
    canvas(|root| {
        let mut chart = ChartBuilder::on(root)
            .caption(caption, ("sans-serif", 22))
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d(x0..x1, t0..t1)?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc(x_label)
            .y_desc(t_label)
            .label_style(("sans-serif", 15))
            .draw()?;
        let cells = rows.iter().enumerate().flat_map(|(r, &k)| {
            let (t_start, t_end) = span(&rows, &time, r);
            let columns = &columns;
            columns.iter().enumerate().map(move |(c, &j)| {
                let (x_start, x_end) = span(columns, &position, c);
                let colour = diverging((snapshots[k].1[j] - low) / (high - low));
                Rectangle::new([(x_start, t_start), (x_end, t_end)], colour.filled())
            })
        });
        chart.draw_series(cells)?;
        Ok(())
    })
}

/// Blue at 0, white at ½, red at 1 (grey where `s` is not finite).
fn diverging(s: f64) -> RGBColor {
    if !s.is_finite() {
        return RGBColor(128, 128, 128);
    }
    let s = s.clamp(0.0, 1.0);
    let mix = |a: f64, b: f64, w: f64| (a + (b - a) * w).round() as u8;
    let (blue, white, red) = (
        (40.0, 70.0, 170.0),
        (255.0, 255.0, 255.0),
        (180.0, 30.0, 40.0),
    );
    let (from, to, w) = match s < 0.5 {
        true => (blue, white, 2.0 * s),
        false => (white, red, 2.0 * s - 1.0),
    };
    RGBColor(
        mix(from.0, to.0, w),
        mix(from.1, to.1, w),
        mix(from.2, to.2, w),
    )
}

/// Draws `points` as a line in the `k`-th colour of the palette, with its entry in the legend.
fn curve<'a, 'p: 'a, CT: CoordTranslate>(
    chart: &mut ChartContext<'a, BitMapBackend<'p>, CT>,
    k: usize,
    label: &str,
    points: impl Iterator<Item = CT::From>,
) -> Result<(), Failure>
where
    CT::From: Clone + 'static,
{
    let color = Palette99::pick(k).to_rgba();
    chart
        .draw_series(LineSeries::new(points, color.stroke_width(2)))?
        .label(label)
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2)));
    Ok(())
}

/// Draws a chart's legend, in the style of every chart.
fn legend<'a, 'p: 'a, CT: CoordTranslate>(
    labels: &mut SeriesLabelStyle<'a, '_, BitMapBackend<'p>, CT>,
) -> Result<(), Failure> {
    labels
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .label_font(("sans-serif", 15))
        .draw()?;
    Ok(())
}

/// Writes 8-bit RGB `pixels`, row by row, to the PNG file `path`.
fn write_png(path: &Path, (width, height): (u32, u32), pixels: &[u8]) -> Result<(), Failure> {
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

    /// The columns and rows, left of the legend, of the pixels in series `k`'s colour.
    fn spans(pixels: &[u8], k: usize) -> ((usize, usize), (usize, usize)) {
        let colour = Palette99::pick(k).to_rgba();
        let width = SIZE.0 as usize;
        let (mut columns, mut rows) = ((usize::MAX, 0), (usize::MAX, 0));
        for (at, pixel) in pixels.chunks(3).enumerate() {
            let (row, column) = (at / width, at % width);
            if column < 600 && pixel == [colour.0, colour.1, colour.2] {
                columns = (columns.0.min(column), columns.1.max(column));
                rows = (rows.0.min(row), rows.1.max(row));
            }
        }
        (columns, rows)
    }

    /// `z` is up: a vertical segment is drawn upright, a horizontal one across.
    #[test]
    fn space_charts_stand_z_upright() {
        register_font().unwrap();
        let segment = |end: [f64; 3]| SpaceSeries {
            label: "segment".into(),
            points: vec![[0.0; 3], end],
        };
        let upright = draw_in_space("z", &[segment([0.0, 0.0, 1.0])]).unwrap();
        let ((left, right), (top, bottom)) = spans(&upright, 0);
        assert!(
            right - left <= 3 && bottom - top > 100,
            "{left}..{right}, {top}..{bottom}"
        );
        let across = draw_in_space("x", &[segment([1.0, 0.0, 0.0])]).unwrap();
        let ((left, right), _) = spans(&across, 0);
        assert!(right - left > 100, "{left}..{right}");
        assert!(draw_in_space("a point", &[segment([0.0; 3])]).is_err());
    }

    /// A field low on the left half and high on the right, later in time on the right still:
    /// the map is blue left of the middle, red right of it, the same at the bottom and the top;
    /// a snapshot of the wrong length, or a single one, is refused.
    #[test]
    fn space_time_charts_put_x_across_and_colour_the_values() {
        register_font().unwrap();
        let x: Vec<f64> = (0..100).map(|j| j as f64).collect();
        let step = |t: f64| {
            (
                t,
                x.iter()
                    .map(|&x| if x < 50.0 { -1.0 } else { 1.0 })
                    .collect(),
            )
        };
        let snapshots: Vec<(f64, Vec<f64>)> = (0..10).map(|k| step(k as f64)).collect();
        let pixels = draw_space_time("a step", ("x", "t"), &x, &snapshots).unwrap();
        let width = SIZE.0 as usize;
        let pixel = |row: usize, column: usize| {
            let at = 3 * (row * width + column);
            [pixels[at], pixels[at + 1], pixels[at + 2]]
        };
        for row in [150, 300, 450] {
            let (left, right) = (pixel(row, 250), pixel(row, 750));
            assert!(left[2] > 150 && left[0] < 100, "row {row}: left {left:?}");
            assert!(
                right[0] > 150 && right[2] < 100,
                "row {row}: right {right:?}"
            );
        }
        let path =
            std::env::temp_dir().join(format!("dirac_space_time_{}.png", std::process::id()));
        let mut short = snapshots.clone();
        short[3].1.pop();
        let refused = space_time_chart(&path, "short", ("x", "t"), &x, &short);
        assert!(
            matches!(refused, Err(DiracError::Dimension(_))),
            "{refused:?}"
        );
        assert!(space_time_chart(&path, "one", ("x", "t"), &x, &snapshots[..1]).is_err());
        let mut late = snapshots.clone();
        late[4].0 = f64::NAN;
        let refused = space_time_chart(&path, "NaN", ("x", "t"), &x, &late);
        assert!(
            matches!(refused, Err(DiracError::NonFinite { .. })),
            "{refused:?}"
        );
        let mut back = x.clone();
        back[7] = back[6];
        let refused = space_time_chart(&path, "back", ("x", "t"), &back, &snapshots);
        assert!(
            matches!(refused, Err(DiracError::Dimension(_))),
            "{refused:?}"
        );
        assert!(!path.exists());
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
