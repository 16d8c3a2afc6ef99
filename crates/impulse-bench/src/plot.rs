//! SVG plots of the quality/speed fronts (`impulse-bench front`).
//!
//! plotters' SVG backend writes text as SVG `<text>` elements and leaves the glyphs to the
//! viewer. The workspace builds plotters with `ab_glyph` (for impulse-cli's PNG plots), which
//! measures text with a registered font: [`register_plot_font`] registers DejaVu Sans, compiled
//! in, so no font files, font-kit or fontconfig are needed to write a plot.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, anyhow};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::front::{
    BARS, BOX3D, FrontPoint, IMPULSE, JOLT, PLOT_E_FLOOR_MM, RAPIER, SceneFront, display_name,
    pareto_front, plot_path,
};

/// DejaVu Sans 2.37 (Bitstream Vera licence, `crates/impulse-cli/assets/fonts/`).
static DEJAVU_SANS: &[u8] = include_bytes!("../../impulse-cli/assets/fonts/DejaVuSans.ttf");

/// Registers the compiled-in DejaVu Sans as plotters' `sans-serif` (once per process); every
/// plot of the workspace draws its text with it.
pub fn register_plot_font() -> Result<()> {
    static REGISTERED: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| {
        plotters::style::register_font(FONT, FontStyle::Normal, DEJAVU_SANS).is_ok()
    });
    if ok {
        Ok(())
    } else {
        Err(anyhow!("the compiled-in plot font could not be read"))
    }
}

/// Plot size in SVG pixels.
const SIZE: (u32, u32) = (960, 640);
const FONT: &str = "sans-serif";
/// impulse's colour (blue) and the peers': Rapier orange, Box3D green, Jolt purple.
const IMPULSE_COLOUR: RGBColor = RGBColor(31, 100, 200);
const RAPIER_COLOUR: RGBColor = RGBColor(230, 110, 0);
const BOX3D_COLOUR: RGBColor = RGBColor(30, 150, 60);
const JOLT_COLOUR: RGBColor = RGBColor(150, 60, 170);
const BAR_COLOUR: RGBColor = RGBColor(110, 110, 110);

/// Font size of the names of front points (SVG pixels).
const LABEL_SIZE: u32 = 11;

/// A box in backend pixels: top left and bottom right corners.
type PixelBox = ((i32, i32), (i32, i32));

/// True when two boxes share some area.
fn overlap(a: &PixelBox, b: &PixelBox) -> bool {
    a.0.0 < b.1.0 && b.0.0 < a.1.0 && a.0.1 < b.1.1 && b.0.1 < a.1.1
}

/// E as plotted: clamped below at [`PLOT_E_FLOOR_MM`].
fn plotted_e(p: &FrontPoint) -> f64 {
    p.e_mm.max(PLOT_E_FLOOR_MM)
}

/// A tick label: the value with at most three decimals, trailing zeros dropped.
fn tick(v: f64) -> String {
    let text = if v.abs() >= 100.0 {
        format!("{v:.0}")
    } else {
        format!("{v:.3}")
    };
    if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        text
    }
}

/// Tick values on a log axis from `lo` to `hi`: 1, 2, 5 × 10^k, or only the powers of ten
/// when those are many, or 1…9 × 10^k when they are few. (plotters' own log ticks leave the
/// stretch below the first power of ten unlabelled.)
fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let ticks = |mantissas: &[f64]| -> Vec<f64> {
        let mut out = Vec::new();
        for k in lo.log10().floor() as i32..=hi.log10().ceil() as i32 {
            for m in mantissas {
                let v = m * 10f64.powi(k);
                if (lo..=hi).contains(&v) {
                    out.push(v);
                }
            }
        }
        out
    };
    let ticks_125 = ticks(&[1.0, 2.0, 5.0]);
    if ticks_125.len() > 15 {
        ticks(&[1.0])
    } else if ticks_125.len() < 3 {
        ticks(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0])
    } else {
        ticks_125
    }
}

/// The staircase of a front sorted by time: from each point right to the next point's time,
/// then down to its E (the best E reachable at a given time per step).
fn staircase(front: &[&FrontPoint]) -> Vec<(f64, f64)> {
    let mut line = Vec::with_capacity(2 * front.len());
    for (k, p) in front.iter().enumerate() {
        line.push((p.ms_per_step, plotted_e(p)));
        if let Some(next) = front.get(k + 1) {
            line.push((next.ms_per_step, plotted_e(p)));
        }
    }
    line
}

/// Writes the plot of one scene's points to `path`: x = ms/step (log), y = E in mm (log,
/// clamped below at [`PLOT_E_FLOOR_MM`]), every point of each engine as a marker, each
/// engine's Pareto front as a staircase, the bars as dashed lines.
pub(crate) fn write_front_svg(front: &SceneFront, path: &Path) -> Result<()> {
    draw(front, path).map_err(|e| anyhow!("{e}"))
}

fn draw(front: &SceneFront, path: &Path) -> Result<(), Box<dyn std::error::Error>> {
    let points: Vec<&FrontPoint> = front
        .points
        .iter()
        .filter(|p| p.counts() && p.ms_per_step > 0.0)
        .collect();
    let (mut x_lo, mut x_hi) = points.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), p| {
        (lo.min(p.ms_per_step), hi.max(p.ms_per_step))
    });
    if points.is_empty() {
        (x_lo, x_hi) = (0.1, 10.0);
    }
    (x_lo, x_hi) = (x_lo / 2.0, x_hi * 1.4);
    let y_lo = points
        .iter()
        .map(|p| plotted_e(p))
        .fold(BARS[2].1, f64::min)
        / 2.0;
    let y_hi = points
        .iter()
        .map(|p| plotted_e(p))
        .fold(BARS[0].1, f64::max)
        * 3.0;

    register_plot_font()?;
    let root = SVGBackend::new(path, SIZE).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            format!(
                "{}: error against time per step, {} steps ({} bodies)",
                front.scene, front.steps, front.bodies
            ),
            (FONT, 24),
        )
        .margin(16)
        .x_label_area_size(50)
        .y_label_area_size(70)
        .build_cartesian_2d(
            (x_lo..x_hi)
                .log_scale()
                .with_key_points(log_ticks(x_lo, x_hi)),
            (y_lo..y_hi)
                .log_scale()
                .with_key_points(log_ticks(y_lo, y_hi)),
        )?;
    chart
        .configure_mesh()
        .x_desc("time per step (ms, log scale)")
        .y_desc(if front.points.iter().any(|p| p.end_overlap_mm.is_some()) {
            "E = max(end overlap, overlap during the run / 30) in mm (log scale; below 0.01 at \
             0.01)"
        } else {
            "E = max(|sink|, overlap, drift) in mm (log scale; below 0.01 at 0.01)"
        })
        .x_label_formatter(&|v| tick(*v))
        .y_label_formatter(&|v| tick(*v))
        .label_style((FONT, 15))
        .axis_desc_style((FONT, 17))
        .light_line_style(WHITE.mix(0.0))
        .draw()?;

    for (name, bar_mm) in BARS {
        chart.draw_series(DashedLineSeries::new(
            [(x_lo, bar_mm), (x_hi, bar_mm)],
            8,
            5,
            BAR_COLOUR.stroke_width(1),
        ))?;
        let style = TextStyle::from((FONT, 15).into_font())
            .color(&BAR_COLOUR)
            .pos(Pos::new(HPos::Left, VPos::Bottom));
        chart.draw_series(std::iter::once(Text::new(
            format!("{name} ({bar_mm} mm)"),
            (x_lo * 1.03, bar_mm * 1.06),
            style,
        )))?;
    }

    // Boxes of the names written so far (backend pixels: top left, bottom right).
    let mut labels: Vec<PixelBox> = Vec::new();
    let engines = [
        (IMPULSE, IMPULSE_COLOUR),
        (RAPIER, RAPIER_COLOUR),
        (BOX3D, BOX3D_COLOUR),
        (JOLT, JOLT_COLOUR),
    ];
    for (engine, colour) in engines {
        let name = display_name(engine);
        let all: Vec<&FrontPoint> = points
            .iter()
            .copied()
            .filter(|p| p.engine == engine)
            .collect();
        if all.is_empty() {
            continue;
        }
        let markers = all.iter().map(|p| (p.ms_per_step, plotted_e(p)));
        if engine == IMPULSE {
            chart
                .draw_series(markers.map(|c| Circle::new(c, 3, colour.mix(0.55).filled())))?
                .label(format!("{name}: every setting"))
                .legend(move |(x, y)| Circle::new((x + 10, y), 3, colour.mix(0.55).filled()));
        } else {
            chart
                .draw_series(markers.map(|c| TriangleMarker::new(c, 4, colour.mix(0.55).filled())))?
                .label(format!("{name}: every setting"))
                .legend(move |(x, y)| {
                    TriangleMarker::new((x + 10, y), 4, colour.mix(0.55).filled())
                });
        }
        let best = pareto_front(&front.points, engine);
        chart
            .draw_series(LineSeries::new(staircase(&best), colour.stroke_width(2)))?
            .label(format!("{name}: Pareto front"))
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
            });
        let on_front = best.iter().map(|p| (p.ms_per_step, plotted_e(p)));
        if engine == IMPULSE {
            chart.draw_series(on_front.map(|c| Circle::new(c, 4, colour.filled())))?;
        } else {
            chart.draw_series(on_front.map(|c| TriangleMarker::new(c, 6, colour.filled())))?;
        }
        // The front's settings by name, small, below left of their points, where the
        // staircase (down onto each point, then right) does not pass; a name that would
        // overlap one already written is left out (the tables list them all).
        let style = TextStyle::from((FONT, LABEL_SIZE).into_font())
            .color(&colour)
            .pos(Pos::new(HPos::Right, VPos::Top));
        let mut names = Vec::new();
        for p in &best {
            let at = (p.ms_per_step / 1.02, plotted_e(p) / 1.08);
            let (x, y) = chart.backend_coord(&at);
            let width = (LABEL_SIZE as f64 * 0.62 * p.setting.chars().count() as f64) as i32;
            let label = ((x - width, y), (x, y + LABEL_SIZE as i32));
            if labels.iter().any(|other| overlap(&label, other)) {
                continue;
            }
            labels.push(label);
            names.push(Text::new(p.setting.clone(), at, style.clone()));
        }
        chart.draw_series(names)?;
    }

    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .label_font((FONT, 15))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK.mix(0.4))
        .draw()?;
    root.present()?;
    Ok(())
}

/// Writes one plot per scene to `dir` ([`plot_path`]), creating `dir`; returns the paths.
pub fn write_plots(fronts: &[SceneFront], dir: &Path) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    fronts
        .iter()
        .map(|front| {
            let path = plot_path(dir, &front.scene);
            write_front_svg(front, &path)
                .with_context(|| format!("plotting {}", path.display()))?;
            Ok(path)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_ticks_cover_the_range() {
        assert_eq!(log_ticks(0.015, 0.36), [0.02, 0.05, 0.1, 0.2]);
        assert_eq!(log_ticks(0.5, 20.0), [0.5, 1.0, 2.0, 5.0, 10.0, 20.0]);
        assert_eq!(
            log_ticks(0.005, 1e4),
            [0.01, 0.1, 1.0, 10.0, 100.0, 1e3, 1e4]
        );
        assert_eq!(log_ticks(1.5, 4.5), [2.0, 3.0, 4.0]);
    }

    #[test]
    fn boxes_overlap_only_when_they_share_area() {
        let a = ((0, 0), (10, 10));
        assert!(overlap(&a, &((5, 5), (15, 15))));
        assert!(!overlap(&a, &((10, 0), (20, 10))));
        assert!(!overlap(&a, &((0, 11), (10, 20))));
    }

    #[test]
    fn ticks_drop_trailing_zeros() {
        assert_eq!(tick(0.01), "0.01");
        assert_eq!(tick(1.0), "1");
        assert_eq!(tick(2.5), "2.5");
        assert_eq!(tick(500.0), "500");
    }
}
