//! Reading YAML configuration files with errors that name the file (and the line, when the
//! parser knows it).

use std::path::Path;

use serde::de::DeserializeOwned;
use thiserror::Error;

/// A configuration file that could not be read or parsed.
#[derive(Debug, Error)]
pub enum YamlError {
    /// The file could not be read.
    #[error("{file}: cannot read: {source}")]
    Io {
        /// The file, as given by the caller.
        file: String,
        /// The underlying I/O error.
        source: std::io::Error,
    },
    /// The text is not valid YAML or does not match the expected structure.
    #[error("{file}{}: {message}", position(.line, .column))]
    Parse {
        /// The file (or source name) the text came from.
        file: String,
        /// 1-based line of the problem, when known.
        line: Option<u64>,
        /// 1-based column of the problem, when known.
        column: Option<u64>,
        /// The parser's message.
        message: String,
    },
}

fn position(line: &Option<u64>, column: &Option<u64>) -> String {
    match (line, column) {
        (Some(l), Some(c)) => format!(":{l}:{c}"),
        (Some(l), None) => format!(":{l}"),
        _ => String::new(),
    }
}

/// Strips the parser's own `error: line L column C: ` prefix (the position is reported apart).
fn strip_position(message: &str) -> &str {
    let m = message.trim().trim_start_matches("error:").trim_start();
    if m.starts_with("line ") {
        if let Some((head, rest)) = m.split_once(": ") {
            if head.split_whitespace().all(|w| w == "line" || w == "column" || w.parse::<u64>().is_ok()) {
                return rest;
            }
        }
    }
    m
}

impl YamlError {
    /// The file (or source name) the error is about.
    pub fn file(&self) -> &str {
        match self {
            YamlError::Io { file, .. } | YamlError::Parse { file, .. } => file,
        }
    }
}

/// Reads the file at `path`; returns its text and its name as errors should show it.
pub fn read_text(path: &Path) -> Result<(String, String), YamlError> {
    let file = path.display().to_string();
    match std::fs::read_to_string(path) {
        Ok(text) => Ok((text, file)),
        Err(source) => Err(YamlError::Io { file, source }),
    }
}

/// Parses `text` as `T`; `source` names the file in errors.
pub fn parse_str<T: DeserializeOwned>(text: &str, source: &str) -> Result<T, YamlError> {
    serde_saphyr::from_str::<T>(text).map_err(|e| {
        let location = e.location().filter(|l| l.line() > 0);
        let line = location.map(|l| l.line());
        let column = location.map(|l| l.column()).filter(|&c| c > 0);
        // The rendered message may carry a multi-line source snippet: keep the first line.
        let rendered = e.to_string();
        let message = strip_position(rendered.lines().next().unwrap_or("invalid YAML")).to_string();
        YamlError::Parse { file: source.to_string(), line, column, message }
    })
}
