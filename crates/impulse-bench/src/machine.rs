//! The machine a benchmark ran on: logical CPUs, CPU model, date.

use std::fmt;
use std::time::{SystemTime, UNIX_EPOCH};

/// What a benchmark result needs to say about where it was measured.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MachineInfo {
    /// Logical CPUs available to this process (what `nproc` prints).
    pub logical_cpus: usize,
    /// The first `model name` of /proc/cpuinfo, or "unknown".
    pub cpu_model: String,
    /// UTC date of the run, `YYYY-MM-DD`.
    pub date: String,
    /// The 1-, 5- and 15-minute load averages of /proc/loadavg when read (other work on the
    /// machine slows a benchmark down), or "unknown".
    pub load_average: String,
}

impl MachineInfo {
    /// Reads the machine now.
    pub fn current() -> Self {
        let logical_cpus = std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1);
        let cpu_model = std::fs::read_to_string("/proc/cpuinfo")
            .ok()
            .and_then(|text| cpu_model_of(&text))
            .unwrap_or_else(|| "unknown".to_string());
        let seconds = SystemTime::now()
            .duration_since(UNIX_EPOCH)
            .map(|d| d.as_secs())
            .unwrap_or(0);
        let load_average = std::fs::read_to_string("/proc/loadavg")
            .ok()
            .map(|text| {
                text.split_whitespace()
                    .take(3)
                    .collect::<Vec<_>>()
                    .join(" ")
            })
            .filter(|s| !s.is_empty())
            .unwrap_or_else(|| "unknown".to_string());
        Self {
            logical_cpus,
            cpu_model,
            date: utc_date(seconds),
            load_average,
        }
    }
}

impl fmt::Display for MachineInfo {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "machine: {} logical CPUs (nproc), CPU model \"{}\", date {} (UTC), load average {}",
            self.logical_cpus, self.cpu_model, self.date, self.load_average
        )
    }
}

/// The value of the first `model name` line of a /proc/cpuinfo text.
pub fn cpu_model_of(cpuinfo: &str) -> Option<String> {
    cpuinfo.lines().find_map(|line| {
        let (key, value) = line.split_once(':')?;
        (key.trim() == "model name").then(|| value.trim().to_string())
    })
}

/// `YYYY-MM-DD` of a Unix time in seconds (UTC, proleptic Gregorian calendar).
pub fn utc_date(unix_seconds: u64) -> String {
    let mut days = unix_seconds / 86_400;
    let mut year = 1970u64;
    loop {
        let length = if is_leap(year) { 366 } else { 365 };
        if days < length {
            break;
        }
        days -= length;
        year += 1;
    }
    let february = if is_leap(year) { 29 } else { 28 };
    let months = [31, february, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31];
    let mut month = 1;
    for length in months {
        if days < length {
            break;
        }
        days -= length;
        month += 1;
    }
    format!("{year:04}-{month:02}-{:02}", days + 1)
}

fn is_leap(year: u64) -> bool {
    (year.is_multiple_of(4) && !year.is_multiple_of(100)) || year.is_multiple_of(400)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dates() {
        assert_eq!(utc_date(0), "1970-01-01");
        assert_eq!(utc_date(951_782_400), "2000-02-29");
        assert_eq!(utc_date(1_709_251_199), "2024-02-29");
        assert_eq!(utc_date(1_735_689_600), "2025-01-01");
    }

    #[test]
    fn cpu_model_line() {
        let text = "processor\t: 0\nmodel name\t: AMD EPYC 7B13\nflags\t: fpu\n";
        assert_eq!(cpu_model_of(text).as_deref(), Some("AMD EPYC 7B13"));
        assert_eq!(cpu_model_of("processor : 0\n"), None);
    }
}
