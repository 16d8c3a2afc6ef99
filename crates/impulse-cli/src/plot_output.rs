//! Where the plots go: an SVG or a PNG file, chosen by the file's extension, with text drawn in
//! the DejaVu Sans font compiled into the binary (`assets/fonts/`, Bitstream Vera licence), so
//! neither format needs system fonts.

use std::path::Path;

use anyhow::{Context, Result, anyhow, bail};
use plotters::coord::Shift;
use plotters::prelude::*;

/// The family name the plots ask for; it is the compiled-in font.
pub const FONT: &str = "sans-serif";

/// Registers the compiled-in font under [`FONT`] (once per process; impulse-bench compiles it
/// in, since its front plots need it too and impulse-cli depends on it).
pub fn register_font() -> Result<()> {
    impulse_bench::register_plot_font()
}

/// The image format of a plot file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Svg,
    Png,
}

impl Format {
    /// The format named by `out`'s extension (`.svg` or `.png`, any case), else an error.
    pub fn of(out: &Path) -> Result<Self> {
        match out
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("svg") => Ok(Self::Svg),
            Some("png") => Ok(Self::Png),
            _ => bail!(
                "{}: a plot is written as SVG or PNG; give a file ending in .svg or .png",
                out.display()
            ),
        }
    }
}

/// Draws a `size` plot and writes it to `out`, as SVG or PNG after its extension: `draw` draws
/// it on the SVG backend, `draw_png` on the bitmap one (the same generic drawing function, in
/// practice: a closure cannot be generic over the backend).
pub fn write(
    out: &Path,
    size: (u32, u32),
    draw: impl FnOnce(&DrawingArea<SVGBackend<'_>, Shift>) -> Result<()>,
    draw_png: impl FnOnce(&DrawingArea<BitMapBackend<'_>, Shift>) -> Result<()>,
) -> Result<()> {
    register_font()?;
    let format = Format::of(out)?;
    match format {
        Format::Svg => {
            let mut text = String::new();
            {
                let root = SVGBackend::with_string(&mut text, size).into_drawing_area();
                draw(&root).with_context(|| format!("cannot draw {}", out.display()))?;
                root.present()
                    .map_err(|e| anyhow!("cannot draw {}: {e}", out.display()))?;
            }
            std::fs::write(out, text).with_context(|| format!("cannot write {}", out.display()))
        }
        Format::Png => {
            let (w, h) = size;
            let mut pixels = vec![255u8; w as usize * h as usize * 3];
            {
                let root = BitMapBackend::with_buffer(&mut pixels, size).into_drawing_area();
                draw_png(&root).with_context(|| format!("cannot draw {}", out.display()))?;
                root.present()
                    .map_err(|e| anyhow!("cannot draw {}: {e}", out.display()))?;
            }
            let image = image::RgbImage::from_raw(w, h, pixels)
                .ok_or_else(|| anyhow!("cannot draw {}: bad pixel buffer", out.display()))?;
            image
                .save_with_format(out, image::ImageFormat::Png)
                .with_context(|| format!("cannot write {}", out.display()))
        }
    }
}
