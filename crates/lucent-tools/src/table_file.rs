//! What the committed tables' generators share: their command line
//! (`EXAMPLE [OUT.csv] [--flag ...]`, the table's own path by default) and
//! their output, a CSV whose `# ` lines say how it was made, written
//! whole under its name or not at all.

use std::fmt::Write as _;
use std::time::Instant;

/// A generator's command line and the moment it started.
pub struct TableCommand {
    out: String,
    flags: Vec<String>,
    start: Instant,
}

impl TableCommand {
    /// The process's arguments: the first one not starting with `--` is
    /// the output path (`default_out` without one), the others are flags.
    pub fn from_args(default_out: &str) -> TableCommand {
        let args: Vec<String> = std::env::args().skip(1).collect();
        let (flags, paths): (Vec<String>, Vec<String>) =
            args.into_iter().partition(|a| a.starts_with("--"));
        TableCommand {
            out: paths
                .into_iter()
                .next()
                .unwrap_or_else(|| default_out.into()),
            flags,
            start: Instant::now(),
        }
    }

    /// Whether `flag` (with its `--`) was given.
    pub fn has(&self, flag: &str) -> bool {
        self.flags.iter().any(|f| f == flag)
    }

    /// Seconds since the command started.
    pub fn seconds(&self) -> f64 {
        self.start.elapsed().as_secs_f64()
    }

    /// Prints a generator's progress message with the seconds so far.
    pub fn progress(&self, message: &str) {
        eprintln!("{message} ({:.0} s)", self.seconds());
    }

    /// Writes the table: `header` as `# ` lines, then `columns`, then
    /// `rows`, through a temporary file renamed over the output, so a
    /// failed run leaves the committed table as it was. Exits with 1 on a
    /// failure to write.
    pub fn write(&self, header: &[String], columns: &str, rows: &str) {
        let mut csv = String::new();
        for line in header {
            writeln!(csv, "# {line}").unwrap();
        }
        writeln!(csv, "{columns}").unwrap();
        csv.push_str(rows);
        let tmp = format!("{}.tmp", self.out);
        let written = std::fs::write(&tmp, csv).and_then(|()| std::fs::rename(&tmp, &self.out));
        if let Err(e) = written {
            let _ = std::fs::remove_file(&tmp);
            eprintln!("error: cannot write {}: {e}", self.out);
            std::process::exit(1);
        }
        eprintln!("wrote {} in {:.0} s", self.out, self.seconds());
    }
}
