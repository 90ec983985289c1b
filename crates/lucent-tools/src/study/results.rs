//! `results.csv`: one row per (configuration, sample count), the study's
//! durable state. Rows are appended and flushed to disk one at a time, so an
//! interrupted study loses at most the row being rendered; on restart the
//! file is read back, a torn last line is dropped (the valid rows are
//! rewritten atomically first) and only missing rows are rendered.

use std::fs::{File, OpenOptions};
use std::io::Write;
use std::path::{Path, PathBuf};

use lucent::film::atomic_write;

/// The longest time a row may record (a year): beyond it the row is not
/// one a study wrote.
pub const MAX_SECONDS: f64 = 3.2e7;

pub const HEADER: &str =
    "config,axis,value,backend,integrator,spp,seconds,rmse,relmse,bias,bias_stderr,fireflies,denoise_seconds";

/// Why a results file cannot be read, written or appended to.
#[derive(Debug, thiserror::Error)]
pub enum ResultsError {
    /// The file exists but cannot be read.
    #[error("cannot read {}: {source}", path.display())]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    /// The file starts with another header: not ours to overwrite.
    #[error(
        "{}: unexpected header \"{header}\"; not a results file of this version of lucent study \
         (move it away or choose another output directory)",
        path.display()
    )]
    Header { path: PathBuf, header: String },
    /// The valid rows could not be rewritten (`cannot write PATH: …`).
    #[error(transparent)]
    Write(#[from] lucent::Error),
    /// The rewritten file cannot be opened for appending.
    #[error("cannot open {}: {source}", path.display())]
    Open {
        path: PathBuf,
        source: std::io::Error,
    },
    /// A text field of a row would break the CSV.
    #[error("results: field \"{field}\" contains a separator")]
    Separator { field: String },
    /// A row could not be appended and flushed.
    #[error("cannot append to {}: {source}", path.display())]
    Append {
        path: PathBuf,
        source: std::io::Error,
    },
}

#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    pub config: String,
    pub axis: String,
    pub value: String,
    pub backend: String,
    pub integrator: String,
    pub spp: u32,
    /// Wall-clock time of the image: the render of all samples up to this
    /// count, plus its denoise when the configuration denoises.
    pub seconds: f64,
    pub rmse: f64,
    pub rel_mse: f64,
    pub bias: f64,
    pub bias_stderr: f64,
    pub fireflies: u64,
    /// The share of `seconds` spent denoising this rung's image (0 when
    /// the configuration does not denoise).
    pub denoise_seconds: f64,
}

impl Row {
    fn to_line(&self) -> String {
        // `{}` prints the shortest decimal that reads back to the same f64.
        format!(
            "{},{},{},{},{},{},{},{},{},{},{},{},{}",
            self.config,
            self.axis,
            self.value,
            self.backend,
            self.integrator,
            self.spp,
            self.seconds,
            self.rmse,
            self.rel_mse,
            self.bias,
            self.bias_stderr,
            self.fireflies,
            self.denoise_seconds
        )
    }

    fn parse(line: &str) -> Option<Row> {
        let f: Vec<&str> = line.split(',').collect();
        if f.len() != 13 {
            return None;
        }
        let row = Row {
            config: f[0].into(),
            axis: f[1].into(),
            value: f[2].into(),
            backend: f[3].into(),
            integrator: f[4].into(),
            spp: f[5].parse().ok()?,
            seconds: f[6].parse().ok()?,
            rmse: f[7].parse().ok()?,
            rel_mse: f[8].parse().ok()?,
            bias: f[9].parse().ok()?,
            bias_stderr: f[10].parse().ok()?,
            fireflies: f[11].parse().ok()?,
            denoise_seconds: f[12].parse().ok()?,
        };
        // a row no run writes (seconds of 1e308, a NaN error) is dropped
        // like a torn one, so no plot is asked to span it
        let measures = [
            row.seconds,
            row.rmse,
            row.rel_mse,
            row.bias,
            row.bias_stderr,
            row.denoise_seconds,
        ];
        (measures.iter().all(|v| v.is_finite())
            && (0.0..=MAX_SECONDS).contains(&row.seconds)
            && (0.0..=row.seconds).contains(&row.denoise_seconds))
        .then_some(row)
    }
}

/// The results file of a study directory, open for appending.
#[derive(Debug)]
pub(crate) struct Results {
    path: PathBuf,
    rows: Vec<Row>,
    file: File,
}

impl Results {
    /// Opens `path`, reading the rows already there. A file with another
    /// header is an error (it is not ours to overwrite); unparseable lines
    /// (a row torn by an interruption) are dropped.
    pub fn open(path: &Path) -> Result<Results, ResultsError> {
        let rows = Self::read(path)?;
        // Rewrite what was valid, so appends start after a complete line.
        let mut text = format!("{HEADER}\n");
        for r in &rows {
            text.push_str(&r.to_line());
            text.push('\n');
        }
        atomic_write(path, |tmp| {
            std::io::Write::write_all(tmp, text.as_bytes()).map_err(|e| e.to_string())
        })?;
        let file = OpenOptions::new()
            .append(true)
            .open(path)
            .map_err(|source| ResultsError::Open {
                path: path.to_path_buf(),
                source,
            })?;
        Ok(Results {
            path: path.to_path_buf(),
            rows,
            file,
        })
    }

    /// The rows of the results file at `path` (none if there is no file),
    /// or why it cannot be resumed; reads only, so a study can refuse a
    /// directory before it writes anything in it.
    pub fn read(path: &Path) -> Result<Vec<Row>, ResultsError> {
        let mut rows = Vec::new();
        let text = super::input_file::read_text(path).map_err(|source| ResultsError::Read {
            path: path.to_path_buf(),
            source,
        })?;
        if let Some(text) = text {
            let mut lines = text.lines();
            match lines.next() {
                Some(h) if h.trim_end() == HEADER => {}
                None => {}
                Some(h) => {
                    return Err(ResultsError::Header {
                        path: path.to_path_buf(),
                        header: h.to_string(),
                    })
                }
            }
            rows.extend(lines.filter_map(Row::parse));
        }
        Ok(rows)
    }

    pub fn rows(&self) -> &[Row] {
        &self.rows
    }

    pub fn get(&self, config: &str, spp: u32) -> Option<&Row> {
        self.rows
            .iter()
            .find(|r| r.config == config && r.spp == spp)
    }

    /// Appends one row and flushes it to disk before returning.
    pub(crate) fn append(&mut self, row: Row) -> Result<(), ResultsError> {
        for s in [
            &row.config,
            &row.axis,
            &row.value,
            &row.backend,
            &row.integrator,
        ] {
            if s.contains(',') || s.contains('\n') {
                return Err(ResultsError::Separator { field: s.clone() });
            }
        }
        let line = format!("{}\n", row.to_line());
        self.file
            .write_all(line.as_bytes())
            .and_then(|()| self.file.sync_data())
            .map_err(|source| ResultsError::Append {
                path: self.path.clone(),
                source,
            })?;
        self.rows.push(row);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::fs;

    fn row(config: &str, spp: u32) -> Row {
        Row {
            config: config.into(),
            axis: "radius".into(),
            value: "table:16".into(),
            backend: "bvh".into(),
            integrator: "diffusion".into(),
            spp,
            seconds: 0.1 + spp as f64 / 3.0,
            rmse: 1.0 / 3.0,
            rel_mse: 1e-7,
            bias: -0.000123456789,
            bias_stderr: 2.5e-5,
            fireflies: 7,
            denoise_seconds: 0.05,
        }
    }

    #[test]
    fn rows_round_trip_and_torn_lines_are_dropped() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("results.csv");
        {
            let mut r = Results::open(&p).unwrap();
            r.append(row("radius=table:16", 1)).unwrap();
            r.append(row("radius=table:16", 2)).unwrap();
            assert!(r.append(row("a,b", 4)).is_err());
        }
        // simulate an interruption in the middle of a row
        let mut f = OpenOptions::new().append(true).open(&p).unwrap();
        f.write_all(b"radius=table:16,radius,table:16,bvh,diff")
            .unwrap();
        drop(f);
        let mut r = Results::open(&p).unwrap();
        assert_eq!(
            r.rows(),
            &[row("radius=table:16", 1), row("radius=table:16", 2)]
        );
        assert!(r.get("radius=table:16", 2).is_some() && r.get("radius=table:16", 4).is_none());
        r.append(row("x", 4)).unwrap();
        let text = fs::read_to_string(&p).unwrap();
        assert_eq!(text.lines().count(), 4);
        assert!(text.ends_with('\n'));
        fs::write(&p, "something,else\n").unwrap();
        assert!(Results::open(&p)
            .unwrap_err()
            .to_string()
            .contains("unexpected header"));
    }
}
