//! The residual-against-iteration plots of `impulse lcp convergence` and `impulse lcp
//! engine-convergence`, as SVG or PNG (after the output file's extension, text in the font
//! compiled into the binary): log10 of each series' residual against sweeps or pivots, one
//! line per solver (dashed where asked), an optional marker per series, and a legend.

use std::path::Path;

use anyhow::{Result, anyhow};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::plot_output::{self, FONT};

/// One solver's run as plotted: `(x, residual)` with x the sweep or pivot count (0 = start).
pub(crate) struct Series {
    pub(crate) label: String,
    pub(crate) colour: &'static str,
    pub(crate) dashed: bool,
    pub(crate) points: Vec<(f64, f64)>,
    /// Lemke's final (polished) residual, drawn as a marker at its pivot count.
    pub(crate) marker: Option<(f64, f64)>,
}

/// Plot size (pixels).
const SIZE: (u32, u32) = (820, 600);

/// Writes the plot to `out`, SVG or PNG after its extension (see [`draw`]).
pub fn write_plot(
    out: &Path,
    title: &str,
    subtitle: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    floor: f64,
) -> Result<()> {
    plot_output::write(
        out,
        SIZE,
        |root| draw(root, title, subtitle, x_label, y_label, series, floor),
        |root| draw(root, title, subtitle, x_label, y_label, series, floor),
    )
}

/// Draws the plot on `root`. Residuals are drawn as log10(max(r, `floor`)), so an exact 0
/// stays on the plot. The x axis spans the series without markers (the iterative solvers'
/// sweeps); a marker beyond it (a longer Lemke path) is drawn on its right edge with its
/// pivot count. NaN points are left out.
pub fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    subtitle: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    floor: f64,
) -> Result<()> {
    let log = |r: f64| r.max(floor).log10();
    let sweeps = series
        .iter()
        .filter(|s| s.marker.is_none())
        .flat_map(|s| s.points.iter())
        .fold(0.0_f64, |m, &(x, _)| m.max(x));
    let x_max = if sweeps > 0.0 {
        sweeps
    } else {
        series
            .iter()
            .flat_map(|s| s.points.iter().chain(s.marker.iter()))
            .fold(1.0_f64, |m, &(x, _)| m.max(x))
    };
    let visible = || {
        series
            .iter()
            .flat_map(|s| s.points.iter().filter(move |&&(x, _)| x <= x_max))
            .chain(series.iter().filter_map(|s| s.marker.as_ref()))
            .filter(|(_, r)| !r.is_nan())
            .map(|&(_, r)| log(r))
    };
    let mut y_min = visible().fold(f64::INFINITY, f64::min).floor();
    let mut y_max = visible().fold(f64::NEG_INFINITY, f64::max).ceil();
    if !(y_min.is_finite() && y_max.is_finite()) {
        (y_min, y_max) = (-1.0, 0.0);
    }
    if y_max - y_min < 1.0 {
        y_max = y_min + 1.0;
    }

    {
        let error = |e: &dyn std::fmt::Display| anyhow!("{e}");
        root.fill(&WHITE).map_err(|e| error(&e))?;
        let centre =
            |size| TextStyle::from((FONT, size).into_font()).pos(Pos::new(HPos::Center, VPos::Top));
        root.draw_text(title, &centre(16), (SIZE.0 as i32 / 2, 10))
            .map_err(|e| error(&e))?;
        root.draw_text(
            subtitle,
            &centre(12).color(&RGBColor(85, 85, 85)),
            (SIZE.0 as i32 / 2, 34),
        )
        .map_err(|e| error(&e))?;
        let (_, body) = root.split_vertically(56);
        let mut chart = ChartBuilder::on(&body)
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(70)
            .build_cartesian_2d(0.0..x_max, y_min..y_max)
            .map_err(|e| error(&e))?;
        let decades = (y_max - y_min).round() as usize;
        chart
            .configure_mesh()
            .x_desc(x_label)
            .y_desc(y_label)
            .y_labels(decades.min(12) + 1)
            .x_label_formatter(&|v| format!("{v}"))
            .y_label_formatter(&|v| format!("1e{}", v.round() as i64))
            .label_style((FONT, 12))
            .draw()
            .map_err(|e| error(&e))?;
        for s in series {
            let colour = hex_colour(s.colour);
            let points: Vec<(f64, f64)> = s
                .points
                .iter()
                .filter(|&&(x, r)| !r.is_nan() && x <= x_max)
                .map(|&(x, r)| (x, log(r)))
                .collect();
            let style = colour.stroke_width(2);
            let drawn = if s.dashed {
                chart.draw_series(DashedLineSeries::new(points, 6, 4, style))
            } else {
                chart.draw_series(LineSeries::new(points, style))
            };
            drawn
                .map_err(|e| error(&e))?
                .label(s.label.as_str())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], style));
            if let Some((x, r)) = s.marker {
                let at = (x.min(x_max), log(r));
                chart
                    .draw_series(std::iter::once(Circle::new(at, 5, colour.filled())))
                    .map_err(|e| error(&e))?;
                if x > x_max {
                    chart
                        .draw_series(std::iter::once(
                            EmptyElement::at(at)
                                + Text::new(
                                    format!("after {x} pivots"),
                                    (-8, -8),
                                    TextStyle::from((FONT, 12).into_font())
                                        .color(&colour)
                                        .pos(Pos::new(HPos::Right, VPos::Bottom)),
                                ),
                        ))
                        .map_err(|e| error(&e))?;
                }
            }
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.85))
            .border_style(RGBColor(150, 150, 150))
            .label_font((FONT, 12))
            .draw()
            .map_err(|e| error(&e))?;
    }
    Ok(())
}

/// `#rrggbb` as a colour (black if malformed).
fn hex_colour(text: &str) -> RGBColor {
    let channel = |k: usize| {
        text.get(1 + 2 * k..3 + 2 * k)
            .and_then(|h| u8::from_str_radix(h, 16).ok())
            .unwrap_or(0)
    };
    RGBColor(channel(0), channel(1), channel(2))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_plot_names_its_series_and_marks_a_long_lemke_path() {
        let series = [
            Series {
                label: "PGS".into(),
                colour: "#1f77b4",
                dashed: false,
                points: (0..=20).map(|k| (k as f64, 10f64.powi(-k / 4))).collect(),
                marker: None,
            },
            Series {
                label: "Lemke".into(),
                colour: "#2ca02c",
                dashed: true,
                points: vec![(0.0, 1.0), (40.0, 1e-3)],
                marker: Some((40.0, 1e-12)),
            },
        ];
        plot_output::register_font().unwrap();
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
            draw(&root, "t", "s", "iteration", "residual", &series, 1e-17).unwrap();
            root.present().unwrap();
        }
        assert!(svg.starts_with("<svg"));
        for text in ["PGS", "Lemke", "after 40 pivots", "1e-12", "iteration"] {
            assert!(svg.contains(text), "{text} missing");
        }
        assert_eq!(hex_colour("#2ca02c"), RGBColor(0x2c, 0xa0, 0x2c));
    }
}
