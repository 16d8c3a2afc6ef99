//! `impulse run --stats FILE`: per-step diagnostics as CSV, one row per step.
//!
//! Columns: `step`, `time` (s, at the end of the step), `contacts`, `rows`, `iterations`,
//! `natural_map_residual` (the LCP's mixed units, see [`impulse::StepDiagnostics`]),
//! `kinetic_energy` (J), `max_depth` (largest overlap among the step's contact points before
//! the solve, m), then the wall time of each stage of the step in ms
//! ([`impulse::report::StepProfile::stages`], `kinematic_ms`, `broad_phase_ms` …) and `total_ms`, then
//! the CPU time of each phase of the solve stage summed over islands in ms
//! ([`impulse::report::SolvePhaseProfile::phases`], `phase_prepare_ms` … `phase_record_ms`).

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use impulse::StepDiagnostics;
use impulse::report::StepProfile;

/// Writes one CSV row per step.
pub struct StatsWriter {
    path: PathBuf,
    out: BufWriter<File>,
}

impl StatsWriter {
    /// Creates `path` and writes the header.
    pub fn create(path: &Path) -> Result<Self> {
        let file =
            File::create(path).with_context(|| format!("cannot create {}", path.display()))?;
        let mut writer = Self {
            path: path.to_path_buf(),
            out: BufWriter::new(file),
        };
        let mut header = String::from(
            "step,time,contacts,rows,iterations,natural_map_residual,kinetic_energy,max_depth",
        );
        for (name, _) in StepProfile::default().stages() {
            header.push_str(&format!(",{name}_ms"));
        }
        header.push_str(",total_ms");
        for (name, _) in StepProfile::default().solve_phases.phases() {
            header.push_str(&format!(",phase_{name}_ms"));
        }
        writeln!(writer.out, "{header}").with_context(|| writer.error())?;
        Ok(writer)
    }

    fn error(&self) -> String {
        format!("cannot write {}", self.path.display())
    }

    /// Writes the row of the step just taken.
    pub fn write_step(
        &mut self,
        time: f64,
        diagnostics: &StepDiagnostics,
        profile: &StepProfile,
    ) -> Result<()> {
        let mut row = format!(
            "{},{},{},{},{},{},{},{}",
            diagnostics.step,
            time,
            diagnostics.contacts,
            diagnostics.rows,
            diagnostics.iterations,
            diagnostics.natural_map_residual,
            diagnostics.kinetic_energy,
            diagnostics.max_depth,
        );
        for (_, ms) in profile.stages() {
            row.push_str(&format!(",{ms}"));
        }
        row.push_str(&format!(",{}", profile.total));
        for (_, ms) in profile.solve_phases.phases() {
            row.push_str(&format!(",{ms}"));
        }
        writeln!(self.out, "{row}").with_context(|| self.error())
    }

    /// Flushes the file.
    pub fn finish(&mut self) -> Result<()> {
        self.out.flush().with_context(|| self.error())
    }
}
