//! SVG figures with plotters (SVG backend only: text is written as SVG text
//! elements, so no system font is needed to draw or to build).

use meshless_impact::{Error, Result};
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::prelude::*;
use plotters::style::colors::colormaps::ViridisRGB;
use std::path::Path;

const SIZE: (u32, u32) = (720, 480);

/// One line (or set of markers) of a plot.
#[derive(Debug, Clone)]
pub struct Series {
    /// Legend label.
    pub label: String,
    /// (x, y) points; non-finite points (and non-positive ones on log axes) are skipped.
    pub points: Vec<(f64, f64)>,
    /// Draw markers only, no line.
    pub markers_only: bool,
}

impl Series {
    /// A line with markers.
    pub fn line(label: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Series {
            label: label.into(),
            points,
            markers_only: false,
        }
    }

    /// Markers only.
    pub fn markers(label: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Series {
            label: label.into(),
            points,
            markers_only: true,
        }
    }
}

/// Axes of a line plot.
#[derive(Debug, Clone, Copy)]
pub struct Axes<'a> {
    /// Plot title.
    pub title: &'a str,
    /// X-axis label.
    pub x: &'a str,
    /// Y-axis label.
    pub y: &'a str,
    /// Logarithmic x axis.
    pub log_x: bool,
    /// Logarithmic y axis.
    pub log_y: bool,
    /// Add the diagonal y = x (parity plots).
    pub diagonal: bool,
}

impl<'a> Axes<'a> {
    /// Linear axes.
    pub fn linear(title: &'a str, x: &'a str, y: &'a str) -> Self {
        Axes {
            title,
            x,
            y,
            log_x: false,
            log_y: false,
            diagonal: false,
        }
    }

    /// Logarithmic axes.
    pub fn log_log(title: &'a str, x: &'a str, y: &'a str) -> Self {
        Axes {
            log_x: true,
            log_y: true,
            ..Axes::linear(title, x, y)
        }
    }
}

fn plot_err(path: &Path, e: impl std::fmt::Display) -> Error {
    Error::io(path, e)
}

fn palette(k: usize) -> RGBColor {
    let (r, g, b) = Palette99::pick(k).to_rgba().rgb();
    RGBColor(r, g, b)
}

fn bounds(values: impl Iterator<Item = f64>, log: bool) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && (!log || *v > 0.0))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if !lo.is_finite() {
        return if log { (0.1, 10.0) } else { (0.0, 1.0) };
    }
    if log {
        let (lo, hi) = if hi / lo < 1.5 {
            (lo / 1.5, hi * 1.5)
        } else {
            (lo, hi)
        };
        (lo / 1.2, hi * 1.2)
    } else {
        let pad = if hi > lo {
            0.05 * (hi - lo)
        } else {
            0.05 * hi.abs().max(1.0)
        };
        (lo - pad, hi + pad)
    }
}

fn usable(p: &(f64, f64), ax: &Axes) -> bool {
    p.0.is_finite() && p.1.is_finite() && (!ax.log_x || p.0 > 0.0) && (!ax.log_y || p.1 > 0.0)
}

/// Draws `series` on the given axes into an SVG file.
pub fn lines(path: &Path, ax: Axes, series: &[Series]) -> Result<()> {
    panels(path, &[(ax, series)])
}

/// Draws charts side by side into one SVG file: each its axes and series.
pub fn panels(path: &Path, charts: &[(Axes, &[Series])]) -> Result<()> {
    let n = charts.len().max(1);
    svg_file(path, (SIZE.0 * n as u32, SIZE.1), |root| {
        root.fill(&WHITE).map_err(|e| plot_err(path, e))?;
        for (area, (ax, series)) in root.split_evenly((1, n)).iter().zip(charts) {
            chart(path, area, *ax, series)?;
        }
        root.present().map_err(|e| plot_err(path, e))
    })
}

/// Draws an SVG picture of `size` pixels with `draw` and writes it to
/// `path` whole ([`meshless_impact::files::write_whole`]).
fn svg_file(path: &Path, size: (u32, u32), draw: impl FnOnce(&Area) -> Result<()>) -> Result<()> {
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, size).into_drawing_area();
        draw(&root)?;
    }
    meshless_impact::files::write_whole_bytes(path, text.as_bytes())
}

/// The drawing area of one chart.
type Area<'a> = DrawingArea<SVGBackend<'a>, plotters::coord::Shift>;

/// Draws one chart into `area` (of the file `path`, for the messages).
fn chart(path: &Path, area: &Area, ax: Axes, series: &[Series]) -> Result<()> {
    let pts = || {
        series
            .iter()
            .flat_map(|s| s.points.iter().filter(|p| usable(p, &ax)))
    };
    let (mut x0, mut x1) = bounds(pts().map(|p| p.0), ax.log_x);
    let (mut y0, mut y1) = bounds(pts().map(|p| p.1), ax.log_y);
    if ax.diagonal {
        let (lo, hi) = (x0.min(y0), x1.max(y1));
        (x0, x1, y0, y1) = (lo, hi, lo, hi);
    }
    match (ax.log_x, ax.log_y) {
        (false, false) => draw(path, area, ax, series, x0..x1, y0..y1),
        (true, false) => draw(path, area, ax, series, (x0..x1).log_scale(), y0..y1),
        (false, true) => draw(path, area, ax, series, x0..x1, (y0..y1).log_scale()),
        (true, true) => draw(
            path,
            area,
            ax,
            series,
            (x0..x1).log_scale(),
            (y0..y1).log_scale(),
        ),
    }
}

fn draw<X, Y>(path: &Path, area: &Area, ax: Axes, series: &[Series], xs: X, ys: Y) -> Result<()>
where
    X: AsRangedCoord<Value = f64>,
    Y: AsRangedCoord<Value = f64>,
    X::CoordDescType: ValueFormatter<f64>,
    Y::CoordDescType: ValueFormatter<f64>,
{
    let mut chart = ChartBuilder::on(area)
        .caption(ax.title, ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(xs, ys)
        .map_err(|e| plot_err(path, e))?;
    let fmt = |v: &f64| super::sig(*v, 3);
    chart
        .configure_mesh()
        .x_desc(ax.x)
        .y_desc(ax.y)
        .x_label_formatter(&fmt)
        .y_label_formatter(&fmt)
        .draw()
        .map_err(|e| plot_err(path, e))?;
    if ax.diagonal {
        let (a, b) = (chart.x_range(), chart.y_range());
        let (lo, hi) = (a.start.max(b.start), a.end.min(b.end));
        chart
            .draw_series(LineSeries::new([(lo, lo), (hi, hi)], BLACK.mix(0.4)))
            .map_err(|e| plot_err(path, e))?
            .label("y = x")
            .legend(|(x, y)| PathElement::new([(x, y), (x + 16, y)], BLACK.mix(0.4)));
    }
    for (k, s) in series.iter().enumerate() {
        let color = palette(k);
        let pts: Vec<(f64, f64)> = s
            .points
            .iter()
            .copied()
            .filter(|p| usable(p, &ax))
            .collect();
        if !s.markers_only {
            chart
                .draw_series(LineSeries::new(pts.clone(), color.stroke_width(2)))
                .map_err(|e| plot_err(path, e))?;
        }
        let few = pts.len() <= 40 || s.markers_only;
        chart
            .draw_series(
                pts.iter()
                    .filter(|_| few)
                    .map(|&p| Circle::new(p, 3, color.filled())),
            )
            .map_err(|e| plot_err(path, e))?
            .label(s.label.as_str())
            .legend(move |(x, y)| Circle::new((x + 8, y), 4, color.filled()));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK.mix(0.3))
        .position(if ax.diagonal {
            SeriesLabelPosition::UpperLeft
        } else {
            SeriesLabelPosition::UpperRight
        })
        .draw()
        .map_err(|e| plot_err(path, e))
}

/// Particles in the R-Z plane (the first two coordinates of axisymmetric
/// [`crate::Snapshot::positions`]) coloured by `values` (viridis), with a
/// colour bar. Lengths are plotted in millimetres.
pub fn map(path: &Path, title: &str, positions: &[[f64; 3]], values: &[f64]) -> Result<()> {
    let (v0, v1) = values
        .iter()
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let rmax = positions.iter().map(|p| p[0]).fold(0.0, f64::max) * 1e3;
    let zmax = positions.iter().map(|p| p[1]).fold(0.0, f64::max) * 1e3;
    let points: Vec<(f64, f64)> = positions.iter().map(|p| (p[0] * 1e3, p[1] * 1e3)).collect();
    plane(
        path,
        &Plane {
            title,
            x: "R (mm)",
            y: "Z (mm)",
            xs: (0.0, rmax * 1.05),
            ys: (0.0, zmax * 1.02),
            values: (v0, v1),
        },
        &points,
        values,
        &[],
    )
}

/// The frame of a [`plane`] map: titles and ranges.
#[derive(Debug, Clone, Copy)]
pub struct Plane<'a> {
    /// Plot title.
    pub title: &'a str,
    /// Horizontal axis label.
    pub x: &'a str,
    /// Vertical axis label.
    pub y: &'a str,
    /// Horizontal range.
    pub xs: (f64, f64),
    /// Vertical range.
    pub ys: (f64, f64),
    /// Range of the colour scale.
    pub values: (f64, f64),
}

/// Points in a plane coloured by `values` (viridis, over `frame.values`),
/// with a colour bar, equal scales on both axes, and the `grey` points
/// drawn grey underneath (a body without the coloured field).
pub fn plane(
    path: &Path,
    frame: &Plane,
    points: &[(f64, f64)],
    values: &[f64],
    grey: &[(f64, f64)],
) -> Result<()> {
    let (v0, v1) = frame.values;
    let v1 = if v1 > v0 { v1 } else { v0 + 1.0 };
    let (x0, x1) = frame.xs;
    let (y0, y1) = frame.ys;
    // Equal scales on both axes: the plot's height follows the aspect.
    let width = 420u32;
    let height =
        ((width as f64 - 90.0) * (y1 - y0) / (x1 - x0).max(1e-9) + 80.0).clamp(300.0, 900.0) as u32;
    svg_file(path, (width + 110, height), |root| {
        root.fill(&WHITE).map_err(|e| plot_err(path, e))?;
        let (left, right) = root.split_horizontally(width);
        let mut chart = ChartBuilder::on(&left)
            .caption(frame.title, ("sans-serif", 16))
            .margin(10)
            .x_label_area_size(35)
            .y_label_area_size(45)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(|e| plot_err(path, e))?;
        chart
            .configure_mesh()
            .disable_x_mesh()
            .disable_y_mesh()
            .x_desc(frame.x)
            .y_desc(frame.y)
            .draw()
            .map_err(|e| plot_err(path, e))?;
        let inside = |p: &(f64, f64)| p.0 >= x0 && p.0 <= x1 && p.1 >= y0 && p.1 <= y1;
        chart
            .draw_series(
                grey.iter()
                    .filter(|p| inside(p))
                    .map(|p| Circle::new(*p, 2, RGBColor(170, 170, 170).filled())),
            )
            .map_err(|e| plot_err(path, e))?;
        let c = |v: f64| ViridisRGB::get_color_normalized(v, v0, v1);
        chart
            .draw_series(
                points
                    .iter()
                    .zip(values)
                    .filter(|(p, _)| inside(p))
                    .map(|(p, &v)| Circle::new(*p, 2, c(v).filled())),
            )
            .map_err(|e| plot_err(path, e))?;
        // Colour bar.
        let mut bar = ChartBuilder::on(&right)
            .margin_top(40)
            .margin_bottom(45)
            .margin_right(50)
            .y_label_area_size(0)
            .right_y_label_area_size(45)
            .build_cartesian_2d(0.0..1.0, v0..v1)
            .map_err(|e| plot_err(path, e))?;
        let fmt = |v: &f64| super::sig(*v, 3);
        bar.configure_mesh()
            .disable_x_mesh()
            .disable_y_mesh()
            .disable_x_axis()
            .y_labels(8)
            .y_label_style(("sans-serif", 12))
            .y_label_formatter(&fmt)
            .draw()
            .map_err(|e| plot_err(path, e))?;
        let n = 64;
        bar.draw_series((0..n).map(|k| {
            let a = v0 + (v1 - v0) * k as f64 / n as f64;
            let b = v0 + (v1 - v0) * (k + 1) as f64 / n as f64;
            Rectangle::new([(0.0, a), (1.0, b)], c(0.5 * (a + b)).filled())
        }))
        .map_err(|e| plot_err(path, e))?;
        root.present().map_err(|e| plot_err(path, e))
    })
}
