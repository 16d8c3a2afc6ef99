//! Trajectory writers: CSV (`frame,time,body,x,y,z,qx,qy,qz,qw`) or JSON lines (one object per
//! frame). Each frame is flushed whole, so a run that stops keeps every frame already written.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

use anyhow::{Context, Result, bail};
use parry3d::math::Pose;

/// Output format, chosen from the file extension.
enum Format {
    Csv,
    JsonLines,
}

/// Writes frames of body poses to a file.
pub struct TrajectoryWriter {
    out: BufWriter<File>,
    format: Format,
    /// The file's path, for error messages.
    path: std::path::PathBuf,
}

impl TrajectoryWriter {
    /// Creates the file; `.csv` writes CSV, `.jsonl` JSON lines; any other extension is an error.
    pub fn create(path: &Path) -> Result<Self> {
        let format = match path.extension().and_then(|e| e.to_str()) {
            Some("csv") => Format::Csv,
            Some("jsonl") => Format::JsonLines,
            _ => bail!(
                "{}: trajectory file must end in .csv or .jsonl",
                path.display()
            ),
        };
        let file =
            File::create(path).with_context(|| format!("cannot create {}", path.display()))?;
        let mut out = BufWriter::new(file);
        if let Format::Csv = format {
            writeln!(out, "frame,time,body,x,y,z,qx,qy,qz,qw")
                .with_context(|| format!("cannot write {}", path.display()))?;
        }
        Ok(Self {
            out,
            format,
            path: path.to_path_buf(),
        })
    }

    /// Appends one frame (the pose of every body, scene order) and flushes it. Errors name the
    /// file.
    pub fn write_frame(&mut self, frame: u64, time: f64, poses: &[Pose]) -> Result<()> {
        self.write_and_flush(frame, time, poses)
            .with_context(|| format!("cannot write {}", self.path.display()))
    }

    fn write_and_flush(&mut self, frame: u64, time: f64, poses: &[Pose]) -> std::io::Result<()> {
        match self.format {
            Format::Csv => {
                for (i, pose) in poses.iter().enumerate() {
                    let t = pose.translation;
                    let q = pose.rotation;
                    writeln!(
                        self.out,
                        "{frame},{time},{i},{},{},{},{},{},{},{}",
                        t.x, t.y, t.z, q.x, q.y, q.z, q.w
                    )?;
                }
            }
            Format::JsonLines => {
                let poses: Vec<[f32; 7]> = poses
                    .iter()
                    .map(|p| {
                        let (t, q) = (p.translation, p.rotation);
                        [t.x, t.y, t.z, q.x, q.y, q.z, q.w]
                    })
                    .collect();
                let line = serde_json::json!({
                    "frame": frame,
                    "time": time,
                    "fields": ["x", "y", "z", "qx", "qy", "qz", "qw"],
                    "bodies": poses,
                });
                writeln!(self.out, "{line}")?;
            }
        }
        self.out.flush()?;
        Ok(())
    }
}
