//! Drawing a [`Figure`] with plotters, as PNG and SVG from the same code: the paper's layout
//! (curves with shaded bands, standard errors for `plot`'s learning curves and bootstrap
//! intervals for `report`'s figures, and a red dash-dot optimal line) with large, readable
//! text.

use super::error::PlotError;
use super::figure::{Figure, Rgb};
use super::font::{self, FAMILY};
use super::legend;
use super::summary::format_return;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

/// Figure size in pixels (PNG) and user units (SVG).
pub const SIZE: (u32, u32) = (1200, 800);

const TITLE_PX: u32 = 30;
const AXIS_DESC_PX: u32 = 24;
const TICK_PX: u32 = 19;
const LEGEND_PX: u32 = 19;
const CAPTION_PX: u32 = 16;
/// The legend's margin around its text and keys, and the width of its key column.
const LEGEND_MARGIN_PX: u32 = 16;
const LEGEND_KEY_PX: u32 = 36;
const OPTIMAL_RED: RGBColor = RGBColor(214, 39, 40);

/// Draw `fig` into `png` and `svg`, each written atomically: the pair every figure is
/// published as.
pub fn render_files(fig: &Figure, png: &Path, svg: &Path) -> Result<(), PlotError> {
    render_png(fig, png)?;
    let svg_text = render_svg(fig, svg)?;
    crate::files::atomic::write_atomic(svg, svg_text.as_bytes()).map_err(|source| {
        PlotError::Write {
            path: svg.to_path_buf(),
            source,
        }
    })
}

/// Draw `fig` into a PNG file at `path`.
pub fn render_png(fig: &Figure, path: &Path) -> Result<(), PlotError> {
    font::register()?;
    let err = |message: String| PlotError::Draw {
        path: path.to_path_buf(),
        message,
    };
    let (w, h) = SIZE;
    let mut rgb = vec![0u8; w as usize * h as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, SIZE).into_drawing_area();
        draw(&root, fig).map_err(err)?;
        root.present().map_err(|e| err(e.to_string()))?;
    }
    // Encoded into the one atomic writer: a reader never sees a torn PNG, and the file is
    // written only onto a regular file or a new name.
    crate::files::atomic::write_atomic_with(path, |out| {
        let mut png = png::Encoder::new(out, w, h);
        png.set_color(png::ColorType::Rgb);
        png.set_depth(png::BitDepth::Eight);
        png.write_header()
            .and_then(|mut writer| writer.write_image_data(&rgb))
            .map_err(std::io::Error::other)
    })
    .map_err(|e| err(e.to_string()))
}

/// Draw `fig` as SVG text; `path` is only used in error messages.
pub fn render_svg(fig: &Figure, path: &Path) -> Result<String, PlotError> {
    font::register()?;
    let err = |message: String| PlotError::Draw {
        path: path.to_path_buf(),
        message,
    };
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        draw(&root, fig).map_err(err)?;
        root.present().map_err(|e| err(e.to_string()))?;
    }
    Ok(svg)
}

fn rgb((r, g, b): Rgb) -> RGBColor {
    RGBColor(r, g, b)
}

/// The data ranges shown: every curve's band and the optimal line, padded by 6% so nothing touches
/// the frame, and x from 0 when the figure asks. Never empty, even for a single point.
/// Returns beyond +-[`MAX_AXIS`] are drawn clipped at the frame: the axis must stay finite and
/// wide enough for f64 steps, or the tick search never ends.
fn ranges(fig: &Figure) -> (std::ops::Range<f64>, std::ops::Range<f64>) {
    let points = fig.series.iter().flat_map(|s| &s.points);
    let (mut x0, mut x1) = (f64::INFINITY, f64::NEG_INFINITY);
    let (mut y0, mut y1) = (f64::INFINITY, f64::NEG_INFINITY);
    let mut see_y = |v: f64| {
        if v.is_finite() {
            let v = v.clamp(-MAX_AXIS, MAX_AXIS);
            y0 = y0.min(v);
            y1 = y1.max(v);
        }
    };
    for p in points {
        x0 = x0.min(p.x);
        x1 = x1.max(p.x);
        // An infinite band (one huge return makes the SE overflow) still shows its line.
        see_y(p.y);
        see_y(p.low);
        see_y(p.high);
    }
    if let Some(opt) = fig.optimal {
        see_y(opt);
    }
    if !x0.is_finite() {
        (x0, x1) = (0.0, 1.0);
    }
    if !y0.is_finite() {
        (y0, y1) = (0.0, 1.0);
    }
    if fig.x_from_zero {
        x0 = x0.min(0.0);
    }
    if x1 <= x0 {
        x1 = x0 + 1.0;
    }
    let pad = if y1 > y0 {
        0.06 * (y1 - y0)
    } else {
        (0.06 * y0.abs()).max(1.0)
    };
    (x0..x1, (y0 - pad)..(y1 + pad))
}

/// Largest magnitude shown on the return axis.
const MAX_AXIS: f64 = 1e12;

/// The on-segments of a dash-dot pattern along [x0, x1], in data units, given data units per
/// pixel: a 16 px dash, 6 px gap, 3 px dot, 6 px gap, repeated.
fn dash_dot_segments(x0: f64, x1: f64, units_per_px: f64) -> Vec<(f64, f64)> {
    let pattern = [(16.0, 6.0), (3.0, 6.0)];
    let mut segs = Vec::new();
    let mut x = x0;
    'outer: loop {
        for (on, off) in pattern {
            if x >= x1 {
                break 'outer;
            }
            let end = (x + on * units_per_px).min(x1);
            segs.push((x, end));
            x = end + off * units_per_px;
        }
    }
    segs
}

/// Greedily break `text` at spaces into lines no wider than `max_px` as `width` measures them
/// (a single word wider than that gets a line of its own).
fn wrap_words(text: &str, max_px: u32, width: impl Fn(&str) -> u32) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    let mut line = String::new();
    for word in text.split_whitespace() {
        let candidate = if line.is_empty() {
            word.to_string()
        } else {
            format!("{line} {word}")
        };
        if line.is_empty() || width(&candidate) <= max_px {
            line = candidate;
        } else {
            lines.push(std::mem::replace(&mut line, word.to_string()));
        }
    }
    if !line.is_empty() {
        lines.push(line);
    }
    lines
}

fn draw<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, fig: &Figure) -> Result<(), String> {
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    root.fill(&WHITE).map_err(e)?;
    let (w, h) = root.dim_in_pixel();
    let caption_style = TextStyle::from((FAMILY, CAPTION_PX).into_font())
        .color(&RGBColor(80, 80, 80))
        .pos(Pos::new(HPos::Center, VPos::Center));
    // A caption with provenance notes runs wider than the figure: break it into lines.
    let caption_lines = wrap_words(&fig.caption, w.saturating_sub(40), |line| {
        root.estimate_text_size(line, &caption_style)
            .map_or(u32::MAX, |(width, _)| width)
    });
    let line_px = CAPTION_PX + 6;
    let bottom_px = 20 + line_px * caption_lines.len().max(1) as u32;
    let (top, rest) = root.split_vertically(76);
    let (main, bottom) = rest.split_vertically(h.saturating_sub(76 + bottom_px));

    let title_style =
        TextStyle::from((FAMILY, TITLE_PX).into_font()).pos(Pos::new(HPos::Center, VPos::Center));
    top.draw_text(&fig.title, &title_style, (w as i32 / 2, 28))
        .map_err(e)?;
    if let Some(partial) = &fig.partial {
        let style = TextStyle::from((FAMILY, LEGEND_PX).into_font())
            .color(&RGBColor(170, 20, 20))
            .pos(Pos::new(HPos::Center, VPos::Center));
        top.draw_text(partial, &style, (w as i32 / 2, 62))
            .map_err(e)?;
    }
    for (i, line) in caption_lines.iter().enumerate() {
        let y = 20 + (line_px as usize * i) as i32;
        bottom
            .draw_text(line, &caption_style, (w as i32 / 2, y))
            .map_err(e)?;
    }

    let (xr, yr) = ranges(fig);
    let build = |yr: std::ops::Range<f64>| {
        ChartBuilder::on(&main)
            .margin_left(16)
            .margin_right(36)
            .margin_top(8)
            .x_label_area_size(64)
            .y_label_area_size(90)
            .build_cartesian_2d(xr.clone(), yr)
    };
    let legend_size = legend_size(fig).map_err(|e| e.to_string())?;
    let mut chart = build(yr.clone()).map_err(e)?;
    let (mut legend_at, covered) = occupancy(&chart, fig).best_place(legend_size);
    if covered > 0 {
        // Nowhere is free: make room above the data.
        let area_h = chart.plotting_area().get_pixel_range().1.len() as i32;
        let top = yr.end + legend::headroom(yr.clone(), area_h, legend_size.1);
        chart = build(yr.start..top).map_err(e)?;
        legend_at = occupancy(&chart, fig).best_place(legend_size).0;
    }
    let (x_lo, x_hi) = (xr.start, xr.end);
    chart
        .configure_mesh()
        .x_desc(fig.x_label.as_str())
        .y_desc(fig.y_label.as_str())
        .axis_desc_style((FAMILY, AXIS_DESC_PX))
        .label_style((FAMILY, TICK_PX))
        .x_labels(8)
        .y_labels(8)
        .x_label_formatter(&|x| trim_number(*x))
        .y_label_formatter(&|y| trim_number(*y))
        .bold_line_style(BLACK.mix(0.10))
        .light_line_style(BLACK.mix(0.03))
        .axis_style(BLACK.mix(0.6))
        .draw()
        .map_err(e)?;

    // Values far off the axes are drawn at a frame's height beyond them: the drawing area clips
    // them the same, and plotters' pixel arithmetic (i32) cannot overflow on a huge return.
    let y_span = chart.y_range().end - chart.y_range().start;
    let (y_lo, y_hi) = (chart.y_range().start - y_span, chart.y_range().end + y_span);
    let on_axes = |y: f64| if y.is_nan() { y } else { y.clamp(y_lo, y_hi) };
    // Bands first, so every line is drawn on top of every band.
    for s in &fig.series {
        let upper = s.points.iter().map(|p| (p.x, on_axes(p.high)));
        let lower = s.points.iter().rev().map(|p| (p.x, on_axes(p.low)));
        let outline: Vec<(f64, f64)> = upper.chain(lower).collect();
        chart
            .draw_series(std::iter::once(Polygon::new(
                outline,
                rgb(s.colour).mix(0.22).filled(),
            )))
            .map_err(e)?;
    }
    for s in &fig.series {
        let colour = rgb(s.colour);
        let line: Vec<(f64, f64)> = s.points.iter().map(|p| (p.x, on_axes(p.y))).collect();
        let single = line.len() < 2;
        chart
            .draw_series(LineSeries::new(line.clone(), colour.stroke_width(3)))
            .map_err(e)?
            .label(&s.label)
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 28, y)], colour.stroke_width(4))
            });
        if single {
            chart
                .draw_series(line.iter().map(|&p| Circle::new(p, 5, colour.filled())))
                .map_err(e)?;
        }
    }
    if let Some(opt) = fig.optimal {
        let px_width = chart.plotting_area().get_pixel_range().0.len().max(1) as f64;
        let units_per_px = (x_hi - x_lo) / px_width;
        let style = OPTIMAL_RED.stroke_width(3);
        let segs = dash_dot_segments(x_lo, x_hi, units_per_px);
        chart
            .draw_series(
                segs.into_iter()
                    .map(|(a, b)| PathElement::new(vec![(a, opt), (b, opt)], style)),
            )
            .map_err(e)?
            .label(optimal_label(opt))
            .legend(move |(x, y)| {
                EmptyElement::at((x, y))
                    + PathElement::new(vec![(0, 0), (12, 0)], style)
                    + PathElement::new(vec![(16, 0), (18, 0)], style)
                    + PathElement::new(vec![(22, 0), (28, 0)], style)
            });
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::Coordinate(legend_at.0, legend_at.1))
        .margin(LEGEND_MARGIN_PX)
        .legend_area_size(LEGEND_KEY_PX)
        .label_font((FAMILY, LEGEND_PX))
        .background_style(WHITE.mix(0.88))
        .border_style(BLACK.mix(0.35))
        .draw()
        .map_err(e)?;
    Ok(())
}

/// The legend's size in pixels as plotters lays it out: the labels' text block, the key's
/// width and the margin around both.
fn legend_size(fig: &Figure) -> Result<(i32, i32), String> {
    let font = TextStyle::from((FAMILY, LEGEND_PX).into_font());
    let mut text = MultiLineText::<_, &str>::new((0, 0), &font);
    for s in &fig.series {
        text.push_line(s.label.as_str());
    }
    let optimal = fig.optimal.map(optimal_label);
    if let Some(label) = &optimal {
        text.push_line(label.as_str());
    }
    let (w, h) = text.estimate_dimension().map_err(|e| format!("{e:?}"))?;
    let margin = LEGEND_MARGIN_PX as i32;
    Ok((w + LEGEND_KEY_PX as i32 + 2 * margin, h + 2 * margin))
}

/// The legend text of the optimal line.
fn optimal_label(opt: f64) -> String {
    format!("optimal return {}", format_return(opt))
}

/// The plotting area's pixels that curves, bands and the optimal line are drawn on.
fn occupancy<DB: DrawingBackend>(
    chart: &ChartContext<DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    fig: &Figure,
) -> legend::Occupancy {
    let (xs, ys) = chart.plotting_area().get_pixel_range();
    let mut occupied = legend::Occupancy::new(xs.len() as i32, ys.len() as i32);
    let (y_lo, y_hi) = (ys.start, ys.end);
    let px = |x: f64, y: f64| {
        let y = y.clamp(-MAX_AXIS, MAX_AXIS);
        let (px, py) = chart.backend_coord(&(x, y));
        (px - xs.start, py.clamp(y_lo - 1, y_hi) - ys.start)
    };
    for s in &fig.series {
        let band: Vec<(i32, i32, i32, i32)> = s
            .points
            .iter()
            .map(|p| {
                let (x_px, line) = px(p.x, p.y);
                let top = px(p.x, p.high).1;
                let bottom = px(p.x, p.low).1;
                (x_px, line, top, bottom)
            })
            .collect();
        occupied.mark_band(&band);
    }
    if let Some(opt) = fig.optimal {
        occupied.mark_row(px(xs.start as f64, opt).1);
    }
    occupied
}

/// Tick labels without trailing zeros: 80, 2.5, -10.
fn trim_number(v: f64) -> String {
    let s = format!("{v:.2}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.into()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn captions_wrap_at_spaces_within_the_width() {
        let chars = |l: &str| l.len() as u32;
        assert_eq!(wrap_words("aa bb cc dd", 5, chars), ["aa bb", "cc dd"]);
        assert_eq!(
            wrap_words("a verylongword b", 4, chars),
            ["a", "verylongword", "b"]
        );
        assert_eq!(wrap_words("  one  ", 80, chars), ["one"]);
        assert!(wrap_words("", 80, chars).is_empty());
    }
    use crate::plot::stats::CurvePoint;

    #[test]
    fn dash_dot_alternates_long_dash_and_dot_and_stays_in_range() {
        // 1 unit per pixel: dash [0, 16], gap to 22, dot [22, 25], gap to 31, dash [31, 47] ...
        let segs = dash_dot_segments(0.0, 40.0, 1.0);
        assert_eq!(segs, vec![(0.0, 16.0), (22.0, 25.0), (31.0, 40.0)]);
    }

    #[test]
    fn y_range_covers_bands_and_the_optimal_line_with_padding() {
        let fig = Figure {
            title: "t".into(),
            series: vec![crate::plot::figure::Series {
                label: "a".into(),
                colour: (0, 0, 0),
                points: vec![
                    CurvePoint {
                        episode: 0,
                        mean: -10.0,
                        se: 2.0,
                        n: 2,
                    }
                    .into(),
                    CurvePoint {
                        episode: 100,
                        mean: 40.0,
                        se: 5.0,
                        n: 2,
                    }
                    .into(),
                ],
            }],
            optimal: Some(80.0),
            partial: None,
            caption: String::new(),
            x_label: "training episodes".into(),
            x_from_zero: true,
            y_label: "discounted return".into(),
        };
        let (x, y) = ranges(&fig);
        assert_eq!(x, 0.0..100.0);
        // data span -12 .. 80 = 92, padded by 6% = 5.52 each side
        assert!((y.start - (-12.0 - 5.52)).abs() < 1e-9);
        assert!((y.end - (80.0 + 5.52)).abs() < 1e-9);
    }

    #[test]
    fn the_x_axis_starts_at_zero_only_when_the_figure_asks() {
        let mut fig = figure_of(vec![
            CurvePoint {
                episode: 100,
                mean: 1.0,
                se: 0.0,
                n: 1,
            },
            CurvePoint {
                episode: 200,
                mean: 2.0,
                se: 0.0,
                n: 1,
            },
        ]);
        assert_eq!(ranges(&fig).0, 0.0..200.0);
        fig.x_from_zero = false;
        assert_eq!(ranges(&fig).0, 100.0..200.0);
    }

    #[test]
    fn tick_labels_drop_trailing_zeros() {
        assert_eq!(trim_number(80.0), "80");
        assert_eq!(trim_number(2.5), "2.5");
        assert_eq!(trim_number(-0.001), "0");
    }

    fn figure_of(points: Vec<CurvePoint>) -> Figure {
        Figure {
            title: "t".into(),
            series: vec![crate::plot::figure::Series {
                label: "a".into(),
                colour: (0, 0, 0),
                points: points.into_iter().map(Into::into).collect(),
            }],
            optimal: Some(80.0),
            partial: None,
            caption: String::new(),
            x_label: "training episodes".into(),
            x_from_zero: true,
            y_label: "discounted return".into(),
        }
    }

    #[test]
    fn huge_and_infinite_values_give_finite_axes_and_render_at_once() {
        let cases = [
            (1e200, f64::INFINITY),
            (1e200, 0.0),
            (-1e300, 1e300),
            (f64::NAN, f64::NAN),
            (5e15, 1.0),
        ];
        for (mean, se) in cases {
            let fig = figure_of(vec![
                CurvePoint {
                    episode: 0,
                    mean: 1.0,
                    se: 0.0,
                    n: 2,
                },
                CurvePoint {
                    episode: 10,
                    mean,
                    se,
                    n: 2,
                },
            ]);
            let (x, y) = ranges(&fig);
            assert!(x.start.is_finite() && x.end.is_finite() && x.start < x.end);
            assert!(
                y.start.is_finite() && y.end.is_finite() && y.start < y.end,
                "{y:?}"
            );
            assert!(
                y.end - y.start > y.end.abs() * 1e-6,
                "{y:?}: too narrow for f64 steps"
            );
            // Rendering must finish: run it on a thread and give it a generous deadline.
            let (tx, rx) = std::sync::mpsc::channel();
            let dir = tempfile::tempdir().unwrap();
            let path = dir.path().join("f.svg");
            std::thread::spawn(move || {
                let _ = tx.send(render_svg(&fig, &path).is_ok());
            });
            let done = rx.recv_timeout(std::time::Duration::from_secs(60));
            assert_eq!(done, Ok(true), "mean {mean}, se {se}");
        }
    }

    #[test]
    fn the_legend_goes_where_no_curve_is() {
        // Two flat curves along the top and the bottom of the axes: the lower right (the usual
        // place) holds the low one, the middle right is free.
        let flat = |label: &str, mean: f64| crate::plot::figure::Series {
            label: label.into(),
            colour: (0, 0, 0),
            points: (0..50)
                .map(|i| {
                    CurvePoint {
                        episode: i * 100,
                        mean,
                        se: 1.0,
                        n: 2,
                    }
                    .into()
                })
                .collect(),
        };
        let mut fig = figure_of(Vec::new());
        fig.series = vec![flat("flat low", 0.0), flat("flat high", 100.0)];
        fig.optimal = None;
        let svg = render_svg(&fig, Path::new("t.svg")).unwrap();
        let at = svg
            .find(">\nflat low\n<")
            .expect("the legend names the curve");
        let tag = &svg[svg[..at].rfind("<text").unwrap()..at];
        let y: f64 = tag
            .split("y=\"")
            .nth(1)
            .and_then(|rest| rest.split('"').next())
            .and_then(|v| v.parse().ok())
            .unwrap_or_else(|| panic!("no y in {tag}"));
        assert!((250.0..450.0).contains(&y), "legend text at y = {y}");
    }
}
