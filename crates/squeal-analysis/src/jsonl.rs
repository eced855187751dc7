//! JSON lines: the one append/load pair of checkpoints and study results. Every record is
//! one line, appended and synced before the call returns, so a killed run loses at most
//! the line being written; a torn last line is ignored on load.

use serde::de::DeserializeOwned;
use serde::Serialize;
use std::io::Write;
use std::path::Path;

/// The records of `path` (none if the file does not exist). Lines that do not parse as
/// `T` (a torn last line after a crash) are skipped.
pub fn load<T: DeserializeOwned>(path: &Path) -> std::io::Result<Vec<T>> {
    match std::fs::read_to_string(path) {
        Ok(text) => Ok(text
            .lines()
            .filter_map(|l| serde_json::from_str::<T>(l).ok())
            .collect()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(Vec::new()),
        Err(e) => Err(e),
    }
}

/// Appends one record as a line to `path` (created if needed), synced before returning.
/// A torn last line (no final newline) is closed first so the new record starts a line.
pub fn append<T: Serialize>(path: &Path, record: &T) -> std::io::Result<()> {
    let line = serde_json::to_string(record).map_err(std::io::Error::other)?;
    let mut f = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .read(true)
        .open(path)?;
    let len = f.metadata()?.len();
    let mut text = String::with_capacity(line.len() + 2);
    if len > 0 {
        use std::io::{Read, Seek, SeekFrom};
        let mut last = [0u8; 1];
        f.seek(SeekFrom::Start(len - 1))?;
        f.read_exact(&mut last)?;
        if last[0] != b'\n' {
            text.push('\n');
        }
    }
    text.push_str(&line);
    text.push('\n');
    f.write_all(text.as_bytes())?;
    f.sync_data()
}

/// Writes `records` as JSON lines to `path` at once (through a temporary file and a
/// rename, so a reader never sees half a file).
pub fn write_all<T: Serialize>(path: &Path, records: &[T]) -> std::io::Result<()> {
    let mut text = String::new();
    for r in records {
        text.push_str(&serde_json::to_string(r).map_err(std::io::Error::other)?);
        text.push('\n');
    }
    write_atomic(path, text.as_bytes())
}

/// Writes `bytes` to `path` through `path.tmp` and a rename.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".tmp");
    let tmp = std::path::PathBuf::from(tmp);
    {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_data()?;
    }
    std::fs::rename(&tmp, path)
}

/// Where two JSON values first differ: a dotted path and both values (shortened).
pub fn first_difference(a: &serde_json::Value, b: &serde_json::Value) -> String {
    fn short(v: &serde_json::Value) -> String {
        let t = v.to_string();
        match t.char_indices().nth(60) {
            Some((i, _)) => format!("{}...", &t[..i]),
            None => t,
        }
    }
    fn go(a: &serde_json::Value, b: &serde_json::Value, path: &str) -> String {
        let join = |k: &str| {
            if path.is_empty() {
                k.to_string()
            } else {
                format!("{path}.{k}")
            }
        };
        match (a, b) {
            (serde_json::Value::Object(x), serde_json::Value::Object(y)) => x
                .iter()
                .find(|(k, v)| y.get(*k) != Some(*v))
                .map(|(k, v)| match y.get(k) {
                    Some(w) => go(v, w, &join(k)),
                    None => format!("{} (only in one)", join(k)),
                })
                .or_else(|| {
                    y.keys()
                        .find(|k| !x.contains_key(*k))
                        .map(|k| format!("{} (only in one)", join(k)))
                })
                .unwrap_or_default(),
            _ => format!("{path}: {} vs {}", short(a), short(b)),
        }
    }
    go(a, b, "")
}

/// NaN: the serde default of a number that older records do not have (a quantity that
/// was not computed).
pub fn nan() -> f64 {
    f64::NAN
}

/// JSON writes NaN (a quantity not computed, an error not measured) as `null`; reads it
/// back as NaN.
pub fn null_as_nan<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    use serde::Deserialize;
    Option::<f64>::deserialize(d).map(|v| v.unwrap_or(f64::NAN))
}
