//! SVG charts with plotters: multi-series line charts and 2-D surfaces drawn as heat maps with a
//! colour scale. Used by `hrm fis surface` and by the paper's figures.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::colors::colormaps::ViridisRGB;
use std::ops::Range;
use std::path::Path;

/// Chart size in pixels.
const SIZE: (u32, u32) = (800, 600);
/// Width of the heat map's part of the picture; the rest holds the colour scale.
const HEATMAP_WIDTH: u32 = 660;
/// Chart titles.
const TITLE_FONT: (&str, u32) = ("sans-serif", 22);
/// Tick labels and legend entries.
const TICK_FONT: (&str, u32) = ("sans-serif", 14);
/// Axis descriptions.
const AXIS_FONT: (&str, u32) = ("sans-serif", 16);

/// The title and axis labels of a chart.
pub struct Labels<'a> {
    /// The caption above the chart.
    pub title: &'a str,
    /// The horizontal axis.
    pub x: &'a str,
    /// The vertical axis.
    pub y: &'a str,
}

/// One named curve of a line chart.
pub struct Series {
    /// The legend entry.
    pub label: String,
    /// The points, in drawing order.
    pub points: Vec<(f64, f64)>,
}

/// Values on a rectangular grid: `z[iy * x.len() + ix]` at `(x[ix], y[iy])`, both axes ascending.
pub struct Grid {
    /// The horizontal sample positions.
    pub x: Vec<f64>,
    /// The vertical sample positions.
    pub y: Vec<f64>,
    /// The values, row by row (one row per `y`).
    pub z: Vec<f64>,
}

/// Writes a line chart of `series` (with a legend) to the SVG file `path`. The vertical axis
/// spans `y_range`, or the data with a 5% margin when it is `None`.
pub fn line_chart(
    path: &Path,
    labels: &Labels<'_>,
    series: &[Series],
    y_range: Option<Range<f64>>,
) -> Result<(), String> {
    let panel = Panel {
        y: labels.y,
        series,
        y_range,
    };
    let layout = panel_ranges(path, std::slice::from_ref(&panel))?;
    let root = SVGBackend::new(path, SIZE).into_drawing_area();
    let draw = || -> Result<(), Box<dyn std::error::Error>> {
        root.fill(&WHITE)?;
        let area = root.titled(labels.title, TITLE_FONT)?;
        draw_panel(&area, labels.x, &panel, &layout[0])?;
        root.present()?;
        Ok(())
    };
    draw().map_err(|e| format!("{}: {e}", path.display()))
}

/// One panel of [`stacked_line_charts`]: its vertical axis label, curves and optional range.
pub struct Panel<'a> {
    /// The vertical axis.
    pub y: &'a str,
    /// The curves.
    pub series: &'a [Series],
    /// The vertical range, or the data with a 5% margin when `None`.
    pub y_range: Option<Range<f64>>,
}

/// Writes `panels` stacked top to bottom, sharing the horizontal axis `x_label` (as in the
/// paper's Figure 9: one panel per modal coordinate), under one `title`, to the SVG file `path`.
pub fn stacked_line_charts(
    path: &Path,
    title: &str,
    x_label: &str,
    panels: &[Panel<'_>],
) -> Result<(), String> {
    if panels.is_empty() {
        return Err(format!("{}: no panels to draw", path.display()));
    }
    let ranges = panel_ranges(path, panels)?;
    let height = (SIZE.1 / 2 + 30) * panels.len() as u32 + 40;
    let root = SVGBackend::new(path, (SIZE.0, height)).into_drawing_area();
    let draw = || -> Result<(), Box<dyn std::error::Error>> {
        root.fill(&WHITE)?;
        let area = root.titled(title, TITLE_FONT)?;
        let rows = area.split_evenly((panels.len(), 1));
        for ((row, panel), range) in rows.iter().zip(panels).zip(&ranges) {
            draw_panel(row, x_label, panel, range)?;
        }
        root.present()?;
        Ok(())
    };
    draw().map_err(|e| format!("{}: {e}", path.display()))
}

/// The horizontal and vertical ranges of each panel; every panel shares the horizontal range
/// of all the data.
fn panel_ranges(path: &Path, panels: &[Panel<'_>]) -> Result<Vec<[Range<f64>; 2]>, String> {
    let context = |e: String| format!("{}: {e}", path.display());
    let all = panels
        .iter()
        .flat_map(|p| p.series.iter().flat_map(|s| s.points.iter()));
    let x_range = span(all.map(|p| p.0), "x").map_err(context)?;
    panels
        .iter()
        .map(|panel| {
            let y_range = match &panel.y_range {
                Some(range) if range.start < range.end => range.clone(),
                Some(range) => return Err(context(format!("empty y range {range:?}"))),
                None => {
                    let points = panel.series.iter().flat_map(|s| s.points.iter());
                    let data = span(points.map(|p| p.1), "y").map_err(context)?;
                    let margin = 0.05 * (data.end - data.start);
                    data.start - margin..data.end + margin
                }
            };
            Ok([x_range.clone(), y_range])
        })
        .collect()
}

/// Width of the legend column right of a chart (pixels): legends never cover the curves.
const LEGEND_WIDTH: u32 = 170;

/// Draws one line chart into `area`, its legend in a column to the right of the plotted area.
fn draw_panel(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    x_label: &str,
    panel: &Panel<'_>,
    [x_range, y_range]: &[Range<f64>; 2],
) -> Result<(), Box<dyn std::error::Error>> {
    let (x_ticks, y_ticks) = (tick_format(x_range), tick_format(y_range));
    let width = area.dim_in_pixel().0;
    let (plot_area, legend_area) = area.split_horizontally(width.saturating_sub(LEGEND_WIDTH));
    let mut chart = ChartBuilder::on(&plot_area)
        .margin(15)
        .x_label_area_size(50)
        .y_label_area_size(75)
        .build_cartesian_2d(x_range.clone(), y_range.clone())?;
    chart
        .configure_mesh()
        .x_desc(x_label)
        .y_desc(panel.y)
        .label_style(TICK_FONT)
        .axis_desc_style(AXIS_FONT)
        .x_label_formatter(&x_ticks)
        .y_label_formatter(&y_ticks)
        .draw()?;
    let mut entries = Vec::with_capacity(panel.series.len());
    for (k, s) in panel.series.iter().enumerate() {
        let colour = Palette99::pick(k).to_rgba();
        chart.draw_series(LineSeries::new(
            s.points.iter().copied(),
            colour.stroke_width(2),
        ))?;
        entries.push((s.label.as_str(), colour.stroke_width(2)));
    }
    legend(&legend_area, &entries)?;
    Ok(())
}

/// Draws legend `entries` (label, line style) one a line from the top of `area`.
fn legend(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    entries: &[(&str, ShapeStyle)],
) -> Result<(), Box<dyn std::error::Error>> {
    for (k, (label, style)) in entries.iter().filter(|(l, _)| !l.is_empty()).enumerate() {
        let y = 40 + 24 * k as i32;
        area.draw(&PathElement::new(vec![(4, y), (28, y)], *style))?;
        area.draw(&Text::new(
            label.to_string(),
            (34, y - 8),
            TICK_FONT.into_font().color(&BLACK),
        ))?;
    }
    Ok(())
}

/// How a curve of an [`xy_chart`] is drawn.
#[derive(Debug, Clone, Copy)]
pub struct Style {
    /// Stroke colour (red, green, blue).
    pub colour: (u8, u8, u8),
    /// Stroke width in pixels.
    pub width: u32,
    /// Whether every point gets a dot (e.g. the joints of an arm).
    pub dots: bool,
}

/// Writes `curves` in the plane with equal scales on both axes (a metre is as long across as
/// up) to the SVG file `path`; curves with an empty label get no legend entry.
pub fn xy_chart(
    path: &Path,
    labels: &Labels<'_>,
    curves: &[(Series, Style)],
) -> Result<(), String> {
    let data = xy_span(path, curves)?;
    let root = SVGBackend::new(path, SIZE).into_drawing_area();
    let draw = || -> Result<(), Box<dyn std::error::Error>> {
        root.fill(&WHITE)?;
        let titled = root.titled(labels.title, TITLE_FONT)?;
        let (area, legend_area) =
            titled.split_horizontally(titled.dim_in_pixel().0.saturating_sub(LEGEND_WIDTH));
        let entries = draw_xy(&area, labels, curves, &data)?;
        legend(&legend_area, &entries)?;
        root.present()?;
        Ok(())
    };
    draw().map_err(|e| format!("{}: {e}", path.display()))
}

/// Writes several views of one scene side by side under one `title` to the SVG file `path`,
/// each with equal scales on its two axes (as [`xy_chart`]) and its own `Labels::title` above
/// it; the legend, of the first view's curves, is on the right.
pub fn xy_views(
    path: &Path,
    title: &str,
    views: &[(Labels<'_>, Vec<(Series, Style)>)],
) -> Result<(), String> {
    if views.is_empty() {
        return Err(format!("{}: no views to draw", path.display()));
    }
    let spans = views
        .iter()
        .map(|(_, curves)| xy_span(path, curves))
        .collect::<Result<Vec<_>, _>>()?;
    let width = (SIZE.0 - LEGEND_WIDTH) * views.len() as u32 / 2 + LEGEND_WIDTH;
    let root = SVGBackend::new(path, (width, SIZE.1 * 3 / 4)).into_drawing_area();
    let draw = || -> Result<(), Box<dyn std::error::Error>> {
        root.fill(&WHITE)?;
        let titled = root.titled(title, TITLE_FONT)?;
        let (area, legend_area) =
            titled.split_horizontally(titled.dim_in_pixel().0.saturating_sub(LEGEND_WIDTH));
        let mut entries = Vec::new();
        for (k, (cell, ((labels, curves), data))) in area
            .split_evenly((1, views.len()))
            .iter()
            .zip(views.iter().zip(&spans))
            .enumerate()
        {
            let cell = cell.titled(labels.title, AXIS_FONT)?;
            let drawn = draw_xy(&cell, labels, curves, data)?;
            if k == 0 {
                entries = drawn;
            }
        }
        legend(&legend_area, &entries)?;
        root.present()?;
        Ok(())
    };
    draw().map_err(|e| format!("{}: {e}", path.display()))
}

/// The horizontal and vertical spans of `curves`' points.
fn xy_span(path: &Path, curves: &[(Series, Style)]) -> Result<[Range<f64>; 2], String> {
    let context = |e: String| format!("{}: {e}", path.display());
    let points = || curves.iter().flat_map(|(s, _)| s.points.iter());
    Ok([
        span(points().map(|p| p.0), "x").map_err(context)?,
        span(points().map(|p| p.1), "y").map_err(context)?,
    ])
}

/// Draws `curves` spanning `data` on `area` with equal scales on both axes; returns the legend
/// entries.
fn draw_xy<'c>(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    labels: &Labels<'_>,
    curves: &'c [(Series, Style)],
    data: &[Range<f64>; 2],
) -> Result<Vec<(&'c str, ShapeStyle)>, Box<dyn std::error::Error>> {
    const MARGIN: u32 = 15;
    const X_LABELS: u32 = 50;
    const Y_LABELS: u32 = 75;
    let (w, h) = area.dim_in_pixel();
    let pixels = (
        w.saturating_sub(2 * MARGIN + Y_LABELS).max(1),
        h.saturating_sub(2 * MARGIN + X_LABELS).max(1),
    );
    let [x_range, y_range] = equal_aspect(data, pixels, 0.05);
    let (x_ticks, y_ticks) = (tick_format(&x_range), tick_format(&y_range));
    let mut chart = ChartBuilder::on(area)
        .margin(MARGIN)
        .x_label_area_size(X_LABELS)
        .y_label_area_size(Y_LABELS)
        .build_cartesian_2d(x_range.clone(), y_range.clone())?;
    // At most a label every 50 pixels across and 30 down, so that a narrow view's labels
    // ("-0.25") do not run together.
    chart
        .configure_mesh()
        .x_desc(labels.x)
        .y_desc(labels.y)
        .x_labels((pixels.0 / 50).clamp(2, 10) as usize)
        .y_labels((pixels.1 / 30).clamp(2, 10) as usize)
        .label_style(TICK_FONT)
        .axis_desc_style(AXIS_FONT)
        .x_label_formatter(&x_ticks)
        .y_label_formatter(&y_ticks)
        .draw()?;
    let mut entries = Vec::new();
    for (series, style) in curves {
        let (r, g, b) = style.colour;
        let colour = RGBColor(r, g, b).stroke_width(style.width);
        chart.draw_series(LineSeries::new(series.points.iter().copied(), colour))?;
        entries.push((series.label.as_str(), colour));
        if style.dots {
            chart.draw_series(
                series
                    .points
                    .iter()
                    .map(|&p| Circle::new(p, style.width + 1, colour.color.filled())),
            )?;
        }
    }
    Ok(entries)
}

/// Ranges around `data` (widened by `margin` of the larger span on every side) whose units per
/// pixel agree on both axes for a plotting area of `pixels` (width, height): the axis with room
/// to spare is widened about its centre.
fn equal_aspect(data: &[Range<f64>; 2], pixels: (u32, u32), margin: f64) -> [Range<f64>; 2] {
    let pad = margin * (data[0].end - data[0].start).max(data[1].end - data[1].start);
    let spans = [
        data[0].end - data[0].start + 2.0 * pad,
        data[1].end - data[1].start + 2.0 * pad,
    ];
    let per_pixel = (spans[0] / f64::from(pixels.0)).max(spans[1] / f64::from(pixels.1));
    let widths = [
        per_pixel * f64::from(pixels.0),
        per_pixel * f64::from(pixels.1),
    ];
    let around = |range: &Range<f64>, width: f64| {
        let centre = 0.5 * (range.start + range.end);
        centre - 0.5 * width..centre + 0.5 * width
    };
    [around(&data[0], widths[0]), around(&data[1], widths[1])]
}

/// Writes `grid` as a heat map with a colour scale labelled `z_label` to the SVG file `path`.
pub fn heatmap(path: &Path, labels: &Labels<'_>, z_label: &str, grid: &Grid) -> Result<(), String> {
    let (nx, ny) = (grid.x.len(), grid.y.len());
    if nx < 2 || ny < 2 || grid.z.len() != nx * ny {
        return Err(format!(
            "{}: a heat map needs at least 2 x 2 samples and one value per grid point ({nx} x {ny} grid, {} values)",
            path.display(),
            grid.z.len()
        ));
    }
    let x_range = span(grid.x.iter().copied(), "x")?;
    let y_range = span(grid.y.iter().copied(), "y")?;
    let z_range = span(grid.z.iter().copied(), "z")?;
    let (x_edges, y_edges) = (cell_edges(&grid.x), cell_edges(&grid.y));
    let (x_ticks, y_ticks, z_ticks) = (
        tick_format(&x_range),
        tick_format(&y_range),
        tick_format(&z_range),
    );
    let colour = |z: f64| ViridisRGB::get_color_normalized(z, z_range.start, z_range.end);
    let root = SVGBackend::new(path, SIZE).into_drawing_area();
    let draw = || -> Result<(), Box<dyn std::error::Error + '_>> {
        root.fill(&WHITE)?;
        let (map_area, scale_area) = root.split_horizontally(HEATMAP_WIDTH);
        let mut chart = ChartBuilder::on(&map_area)
            .caption(labels.title, TITLE_FONT)
            .margin(15)
            .x_label_area_size(50)
            .y_label_area_size(75)
            .build_cartesian_2d(x_range.clone(), y_range.clone())?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc(labels.x)
            .y_desc(labels.y)
            .label_style(TICK_FONT)
            .axis_desc_style(AXIS_FONT)
            .x_label_formatter(&x_ticks)
            .y_label_formatter(&y_ticks)
            .draw()?;
        let cells = (0..ny).flat_map(|iy| (0..nx).map(move |ix| (ix, iy)));
        chart.draw_series(cells.map(|(ix, iy)| {
            let corners = [
                (x_edges[ix], y_edges[iy]),
                (x_edges[ix + 1], y_edges[iy + 1]),
            ];
            Rectangle::new(corners, colour(grid.z[iy * nx + ix]).filled())
        }))?;
        let mut scale = ChartBuilder::on(&scale_area)
            .margin_top(50)
            .margin_bottom(65)
            .margin_right(50)
            .y_label_area_size(0)
            .right_y_label_area_size(60)
            .build_cartesian_2d(0.0..1.0, z_range.clone())?;
        scale
            .configure_mesh()
            .disable_mesh()
            .disable_x_axis()
            .y_desc(z_label)
            .label_style(TICK_FONT)
            .axis_desc_style(AXIS_FONT)
            .y_label_formatter(&z_ticks)
            .draw()?;
        const STEPS: usize = 100;
        let dz = (z_range.end - z_range.start) / STEPS as f64;
        scale.draw_series((0..STEPS).map(|k| {
            let z = z_range.start + k as f64 * dz;
            Rectangle::new([(0.0, z), (1.0, z + dz)], colour(z + 0.5 * dz).filled())
        }))?;
        root.present()?;
        Ok(())
    };
    draw().map_err(|e| format!("{}: {e}", path.display()))
}

/// Tick labels rounded to five significant digits of the axis span, so that no label reads
/// `-0` or `0.30000000000000004`.
fn tick_format(range: &Range<f64>) -> impl Fn(&f64) -> String {
    let exponent = (range.end - range.start).log10().floor() as i32 - 4;
    let step = 10f64.powi(exponent);
    let decimals = (-exponent).max(0) as usize;
    move |v| {
        // Adding 0.0 turns -0 into +0.
        let text = format!("{:.decimals$}", (v / step).round() * step + 0.0);
        if text.contains('.') {
            text.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            text
        }
    }
}

/// The widest span of values a chart scales: under a sixteenth of `f64::MAX`, so that its
/// margins and tick steps stay finite.
const MAX_SPAN: f64 = 1e307;

/// The range spanned by `values`, widened when they are all equal; an error for no or
/// non-finite values, or a span beyond [`MAX_SPAN`].
fn span(values: impl Iterator<Item = f64>, axis: &str) -> Result<Range<f64>, String> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values {
        if !v.is_finite() {
            return Err(format!("cannot plot a non-finite {axis} value ({v})"));
        }
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if lo > hi {
        return Err(format!("nothing to plot: no {axis} values"));
    }
    // A span near double precision's end (values near ±f64::MAX) cannot be scaled to a chart:
    // the axis' margins and tick steps overflow (a span of 1.8e308 drew forever).
    let unplottable = |range: Range<f64>| {
        if range.end - range.start <= MAX_SPAN {
            Ok(range)
        } else {
            Err(format!(
                "cannot plot a non-finite {axis} span: the values run from {lo:e} to {hi:e}, \
                 a span beyond the {MAX_SPAN:e} a chart resolves in double precision"
            ))
        }
    };
    if hi - lo <= 1e-12 * lo.abs().max(hi.abs()).max(1.0) {
        let pad = 0.5 * lo.abs().max(1.0);
        return unplottable(lo - pad..hi + pad);
    }
    unplottable(lo..hi)
}

/// Cell boundaries around ascending samples: the ends, and the midpoints between neighbours.
fn cell_edges(samples: &[f64]) -> Vec<f64> {
    let mut edges = Vec::with_capacity(samples.len() + 1);
    edges.push(samples[0]);
    edges.extend(samples.windows(2).map(|w| 0.5 * (w[0] + w[1])));
    edges.push(samples[samples.len() - 1]);
    edges
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spans_beyond_double_precision_are_refused() {
        let err = span([-1e308, 1e308].into_iter(), "z").unwrap_err();
        assert!(
            err.contains("non-finite z span") && err.contains("1e308"),
            "{err}"
        );
        let err = span([f64::MAX, f64::MAX].into_iter(), "z").unwrap_err();
        assert!(err.contains("non-finite z span"), "{err}");
        // A finite span whose margins and ticks overflow drew forever.
        let err = span([-9.5e307, 9.5e307].into_iter(), "y").unwrap_err();
        assert!(err.contains("non-finite y span"), "{err}");
        assert_eq!(span([1e300, 2e300].into_iter(), "z").unwrap(), 1e300..2e300);
    }

    #[test]
    fn spans_and_cell_edges() {
        assert_eq!(span([1.0, -2.0, 0.5].into_iter(), "x").unwrap(), -2.0..1.0);
        assert_eq!(span([3.0, 3.0].into_iter(), "z").unwrap(), 1.5..4.5);
        assert!(
            span([1.0, f64::NAN].into_iter(), "y")
                .unwrap_err()
                .contains("non-finite y")
        );
        assert!(
            span(std::iter::empty(), "x")
                .unwrap_err()
                .contains("no x values")
        );
        assert_eq!(cell_edges(&[0.0, 1.0, 3.0]), [0.0, 0.5, 2.0, 3.0]);
        let ticks = tick_format(&(-0.3..0.3));
        assert_eq!(
            [
                ticks(&-0.0),
                ticks(&0.1),
                ticks(&(0.1 + 0.2)),
                ticks(&-0.25)
            ],
            ["0", "0.1", "0.3", "-0.25"]
        );
        let ticks = tick_format(&(-100.0..100.0));
        assert_eq!(
            [ticks(&-80.0), ticks(&12.5), ticks(&-1e-9)],
            ["-80", "12.5", "0"]
        );
    }

    #[test]
    fn charts_are_written_as_svg() {
        let dir = std::env::temp_dir().join(format!("hrm-plot-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let labels = Labels {
            title: "t",
            x: "x",
            y: "y",
        };
        let line = dir.join("line.svg");
        let series = [Series {
            label: "sin".into(),
            points: (0..50)
                .map(|k| (k as f64, (k as f64 / 5.0).sin()))
                .collect(),
        }];
        line_chart(&line, &labels, &series, None).unwrap();
        assert!(
            line_chart(&line, &labels, &series, Some(1.0..1.0))
                .unwrap_err()
                .contains("empty y range")
        );
        let text = std::fs::read_to_string(&line).unwrap();
        assert!(text.starts_with("<svg") && text.contains("sin") && text.contains("<polyline"));
        let map = dir.join("map.svg");
        let grid = Grid {
            x: vec![0.0, 1.0, 2.0],
            y: vec![0.0, 1.0],
            z: vec![0.0, 1.0, 2.0, 3.0, 4.0, 5.0],
        };
        heatmap(&map, &labels, "z", &grid).unwrap();
        let text = std::fs::read_to_string(&map).unwrap();
        assert!(text.starts_with("<svg") && text.matches("<rect").count() >= 6 + 100);
        let bad = Grid {
            x: vec![0.0, 1.0],
            y: vec![0.0, 1.0],
            z: vec![0.0; 3],
        };
        assert!(
            heatmap(&map, &labels, "z", &bad)
                .unwrap_err()
                .contains("one value per grid point")
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
