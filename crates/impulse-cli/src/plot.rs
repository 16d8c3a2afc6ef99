//! `impulse plot`: the columns of a `--stats` CSV over the run, one panel per column, as SVG
//! or PNG (after the output file's extension).
//!
//! Drawn with plotters' SVG and bitmap backends; text uses the font compiled into the binary
//! (see [`crate::plot_output`]), so no system fonts are needed.

use std::path::Path;

use anyhow::{Context, Result, anyhow, bail};
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::plot_output::{self, FONT};

/// The columns plotted when none are asked for.
pub const DEFAULT_COLUMNS: [&str; 5] = [
    "contacts",
    "iterations",
    "natural_map_residual",
    "kinetic_energy",
    "max_depth",
];

/// Width of the plot and height of one panel (pixels).
const WIDTH: u32 = 900;
const PANEL_HEIGHT: u32 = 180;
const LINE: RGBColor = RGBColor(31, 100, 200);

/// A CSV table of numbers with a header row.
#[derive(Debug)]
pub struct Table {
    /// Column names, from the first line.
    pub header: Vec<String>,
    /// Row-major values; a cell that is not a number is NaN.
    pub rows: Vec<Vec<f64>>,
}

impl Table {
    /// Reads a comma-separated file whose first line names the columns.
    pub fn read(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("cannot read {}", path.display()))?;
        let mut lines = text.lines().filter(|l| !l.trim().is_empty());
        let header: Vec<String> = lines
            .next()
            .ok_or_else(|| anyhow!("{} is empty", path.display()))?
            .split(',')
            .map(|c| c.trim().to_string())
            .collect();
        let rows: Vec<Vec<f64>> = lines
            .map(|line| {
                line.split(',')
                    .map(|c| c.trim().parse().unwrap_or(f64::NAN))
                    .collect()
            })
            .collect();
        if let Some(k) = rows.iter().position(|r| r.len() != header.len()) {
            bail!(
                "{}: row {} has {} cells, the header {}",
                path.display(),
                k + 2,
                rows[k].len(),
                header.len()
            );
        }
        Ok(Self { header, rows })
    }

    /// The index of column `name`, or an error listing the columns.
    pub fn column(&self, name: &str) -> Result<usize> {
        self.header.iter().position(|h| h == name).ok_or_else(|| {
            anyhow!(
                "no column '{name}'; the columns are {}",
                self.header.join(", ")
            )
        })
    }
}

/// Plots `columns` of the CSV at `input` against its `time` column (else its first) into the
/// file `out`, SVG or PNG after its extension.
pub fn plot(input: &Path, out: &Path, columns: &[String]) -> Result<()> {
    plot_output::Format::of(out)?;
    let table = Table::read(input)?;
    let x_column = table.column("time").unwrap_or(0);
    let columns: Vec<String> = if columns.is_empty() {
        DEFAULT_COLUMNS
            .iter()
            .filter(|c| table.column(c).is_ok())
            .map(|c| c.to_string())
            .collect()
    } else {
        columns.to_vec()
    };
    if columns.is_empty() {
        bail!(
            "{}: none of the default columns ({}); choose some with --columns",
            input.display(),
            DEFAULT_COLUMNS.join(", ")
        );
    }
    let indices = columns
        .iter()
        .map(|c| table.column(c))
        .collect::<Result<Vec<_>>>()?;
    let height = PANEL_HEIGHT * columns.len() as u32;
    let panels = Panels {
        table: &table,
        x_column,
        columns: &columns,
        indices: &indices,
    };
    plot_output::write(
        out,
        (WIDTH, height),
        |root| panels.draw(root),
        |root| panels.draw(root),
    )
}

/// What [`plot`] draws: one panel per column.
struct Panels<'a> {
    table: &'a Table,
    x_column: usize,
    columns: &'a [String],
    indices: &'a [usize],
}

impl Panels<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()> {
        let draw_error = |e: &dyn std::fmt::Display| anyhow!("{e}");
        let table = self.table;
        root.fill(&WHITE).map_err(|e| draw_error(&e))?;
        let panels = root.split_evenly((self.columns.len(), 1));
        let x_name = &table.header[self.x_column];
        for ((panel, name), &k) in panels.iter().zip(self.columns).zip(self.indices) {
            let points: Vec<(f64, f64)> = table
                .rows
                .iter()
                .map(|r| (r[self.x_column], r[k]))
                .filter(|(x, y)| x.is_finite() && y.is_finite())
                .collect();
            let (x0, x1) = range(points.iter().map(|p| p.0));
            let (y0, y1) = range(points.iter().map(|p| p.1));
            let mut chart = ChartBuilder::on(panel)
                .caption(name, (FONT, 16))
                .margin(8)
                .x_label_area_size(30)
                .y_label_area_size(80)
                .build_cartesian_2d(x0..x1, y0..y1)
                .map_err(|e| draw_error(&e))?;
            chart
                .configure_mesh()
                .x_desc(x_name.as_str())
                .label_style((FONT, 12))
                .y_label_formatter(&|v| tick(*v))
                .draw()
                .map_err(|e| draw_error(&e))?;
            chart
                .draw_series(LineSeries::new(points, LINE.stroke_width(2)))
                .map_err(|e| draw_error(&e))?;
        }
        Ok(())
    }
}

/// A tick label: plain with up to four decimals between 0.01 and 10⁶, else in scientific
/// notation.
fn tick(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    if (1e-2..1e6).contains(&v.abs()) {
        let text = format!("{v:.4}");
        text.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{v:.2e}")
    }
}

/// The smallest and largest of `values`, widened to a non-empty range.
fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    });
    if lo > hi {
        (0.0, 1.0)
    } else if hi - lo <= 1e-12 * hi.abs().max(1e-300) {
        let pad = if hi == 0.0 { 1.0 } else { 0.1 * hi.abs() };
        (lo - pad, hi + pad)
    } else {
        (lo, hi)
    }
}
