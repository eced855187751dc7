//! Name/value parameters from which plugins are constructed.
//!
//! Scene files and the command line (`--basis-opt k=v`) both end up as [`Params`]; a plugin
//! reads them through the typed getters, which produce errors naming the key. The getters
//! also note every key asked for, present or not: the [`Registry`](crate::Registry)
//! refuses a key its plugin never asked for (a typo must not fall back to a default
//! silently), with no list of known keys to keep by hand.

use crate::{Error, Result};
use std::collections::{BTreeMap, BTreeSet};
use std::sync::{Arc, Mutex};

/// One parameter value.
#[derive(Debug, Clone, PartialEq)]
pub enum ParamValue {
    /// A number (integers are stored as numbers too).
    Num(f64),
    /// A string.
    Str(String),
    /// A flag.
    Bool(bool),
    /// A list of numbers (an axis, a rectangle, ...).
    List(Vec<f64>),
}

impl std::fmt::Display for ParamValue {
    /// The value as a user writes it: `0.3`, `abc`, `true`, `0.1,0.2`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ParamValue::Num(x) => write!(f, "{x}"),
            ParamValue::Str(s) => write!(f, "`{s}`"),
            ParamValue::Bool(b) => write!(f, "{b}"),
            ParamValue::List(l) => {
                let parts: Vec<String> = l.iter().map(|x| x.to_string()).collect();
                write!(f, "{}", parts.join(","))
            }
        }
    }
}

/// An ordered map of named parameters, and the keys read from it so far when it is
/// tracked ([`Params::tracked`]).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Params(pub BTreeMap<String, ParamValue>, ReadLog);

impl std::fmt::Display for Params {
    /// The parameters as a user writes them, in key order: `k=v, k=v` (empty when none).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        for (i, (k, v)) in self.0.iter().enumerate() {
            if i > 0 {
                write!(f, ", ")?;
            }
            write!(f, "{k}={v}")?;
        }
        Ok(())
    }
}

/// The keys asked of a tracked [`Params`] (shared by its clones); equal to any other log,
/// so that parameters compare by their values only.
#[derive(Debug, Clone, Default)]
pub struct ReadLog(Option<Arc<Mutex<BTreeSet<String>>>>);

impl PartialEq for ReadLog {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl Params {
    /// Empty parameters: every plugin falls back to its defaults.
    pub fn new() -> Self {
        Self::default()
    }

    /// A copy of the values that notes every key its getters are asked for
    /// ([`unread`](Self::unread), [`read_keys`](Self::read_keys)); the copy of a tracked
    /// `Params` notes into the same log.
    pub fn tracked(&self) -> Self {
        match &self.1 .0 {
            Some(_) => self.clone(),
            None => Self(self.0.clone(), ReadLog(Some(Arc::default()))),
        }
    }

    fn note(&self, key: &str) {
        if let Some(log) = &self.1 .0 {
            log.lock()
                .unwrap_or_else(|p| p.into_inner())
                .insert(key.to_string());
        }
    }

    /// The keys asked for so far (empty when not tracked), sorted.
    pub fn read_keys(&self) -> Vec<String> {
        match &self.1 .0 {
            Some(log) => log
                .lock()
                .unwrap_or_else(|p| p.into_inner())
                .iter()
                .cloned()
                .collect(),
            None => Vec::new(),
        }
    }

    /// The keys present that no getter was asked for, sorted; empty when not tracked.
    pub fn unread(&self) -> Vec<String> {
        if self.1 .0.is_none() {
            return Vec::new();
        }
        let read = self.read_keys();
        self.0
            .keys()
            .filter(|k| !read.contains(k))
            .cloned()
            .collect()
    }

    /// The value of `key`, if present (noted as asked for).
    pub fn get(&self, key: &str) -> Option<&ParamValue> {
        self.note(key);
        self.0.get(key)
    }

    /// Whether `key` is present (noted as asked for).
    pub fn contains(&self, key: &str) -> bool {
        self.get(key).is_some()
    }

    /// Builder-style insertion.
    pub fn with(mut self, key: &str, value: ParamValue) -> Self {
        self.0.insert(key.to_string(), value);
        self
    }

    /// Builder-style insertion of a number.
    pub fn with_num(self, key: &str, value: f64) -> Self {
        self.with(key, ParamValue::Num(value))
    }

    /// Parses `key=value`; the value is a number, `true`/`false`, a comma separated
    /// list of numbers, or else a string.
    pub fn parse_kv(text: &str) -> Result<(String, ParamValue)> {
        let (k, v) = text
            .split_once('=')
            .ok_or_else(|| Error::param(text, "expected `key=value`"))?;
        let (k, v) = (k.trim(), v.trim());
        let value = if let Ok(x) = v.parse::<f64>() {
            ParamValue::Num(x)
        } else if v == "true" || v == "false" {
            ParamValue::Bool(v == "true")
        } else if v.contains(',') {
            let list: std::result::Result<Vec<f64>, _> =
                v.split(',').map(|s| s.trim().parse::<f64>()).collect();
            match list {
                Ok(l) => ParamValue::List(l),
                Err(_) => ParamValue::Str(v.to_string()),
            }
        } else {
            ParamValue::Str(v.to_string())
        };
        Ok((k.to_string(), value))
    }

    /// A number, or `default` when absent. Errors when present with another type or
    /// not finite.
    pub fn num_or(&self, key: &str, default: f64) -> Result<f64> {
        match self.get(key) {
            None => Ok(default),
            Some(ParamValue::Num(x)) if x.is_finite() => Ok(*x),
            Some(other) => Err(Error::param(
                key,
                format!("expected a finite number, got {other}"),
            )),
        }
    }

    /// A required number.
    pub fn num(&self, key: &str) -> Result<f64> {
        if !self.contains(key) {
            return Err(Error::param(key, "required number is missing"));
        }
        self.num_or(key, f64::NAN)
    }

    /// An optional number: `None` when absent.
    pub fn num_opt(&self, key: &str) -> Result<Option<f64>> {
        if self.contains(key) {
            self.num(key).map(Some)
        } else {
            Ok(None)
        }
    }

    /// A non-negative integer, or `default` when absent.
    pub fn usize_or(&self, key: &str, default: usize) -> Result<usize> {
        let x = self.num_or(key, default as f64)?;
        if x < 0.0 || x.fract() != 0.0 {
            return Err(Error::param(
                key,
                format!("expected a non-negative integer, got {x}"),
            ));
        }
        Ok(x as usize)
    }

    /// A string, or `default` when absent.
    pub fn str_or<'a>(&'a self, key: &str, default: &'a str) -> Result<&'a str> {
        match self.get(key) {
            None => Ok(default),
            Some(ParamValue::Str(s)) => Ok(s),
            Some(other) => Err(Error::param(key, format!("expected a string, got {other}"))),
        }
    }

    /// A list of numbers, or `default` when absent.
    pub fn list_or(&self, key: &str, default: &[f64]) -> Result<Vec<f64>> {
        match self.get(key) {
            None => Ok(default.to_vec()),
            Some(ParamValue::List(l)) => Ok(l.clone()),
            Some(other) => Err(Error::param(
                key,
                format!("expected a list of numbers, got {other}"),
            )),
        }
    }

    /// Errors on the first key of a tracked copy that no getter asked for, naming what
    /// `plugin` (of kind `kind`) does read.
    pub fn refuse_unread(&self, kind: &str, plugin: &str) -> Result<()> {
        match self.unread().first() {
            None => Ok(()),
            Some(k) => {
                let read = self.read_keys();
                Err(Error::param(
                    k.clone(),
                    format!(
                        "unknown parameter for {kind} `{plugin}`; {}",
                        if read.is_empty() {
                            "it takes none".to_string()
                        } else {
                            format!("it takes: {}", read.join(", "))
                        }
                    ),
                ))
            }
        }
    }
}

/// `value` of the parameter `name` when it is a finite number above 0, else the error
/// every plugin gives for it ("must be a positive number, got ...").
pub fn positive(name: &str, value: f64) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(Error::param(
            name,
            format!("must be a positive number, got {value}"),
        ))
    }
}

/// `value` of the parameter `name` when `0 < value < 1` (a relative tolerance or cut),
/// else the error every plugin gives for it ("must be in (0, 1), got ...").
pub fn fraction(name: &str, value: f64) -> Result<f64> {
    if value > 0.0 && value < 1.0 {
        Ok(value)
    } else {
        Err(Error::param(
            name,
            format!("must be in (0, 1), got {value}"),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parse_and_get() {
        let (k, v) = Params::parse_kv("tol = 1e-6").unwrap();
        assert_eq!(k, "tol");
        assert_eq!(v, ParamValue::Num(1e-6));
        let p = Params::new().with("tol", v).with_num("n", 3.0);
        assert_eq!(p.num_or("tol", 1.0).unwrap(), 1e-6);
        assert_eq!(p.usize_or("n", 1).unwrap(), 3);
        assert!(p.usize_or("tol", 1).is_err());
        assert_eq!(p.num_or("absent", 2.5).unwrap(), 2.5);
        let (_, l) = Params::parse_kv("axis=0,0,1").unwrap();
        assert_eq!(l, ParamValue::List(vec![0.0, 0.0, 1.0]));
    }

    #[test]
    fn keys_no_getter_asked_for_are_refused_with_what_is_read() {
        let p = Params::new()
            .with_num("tolerance", 1.0)
            .with_num("tol", 2.0)
            .tracked();
        assert_eq!(p.num_or("tol", 1.0).unwrap(), 2.0);
        assert_eq!(p.num_or("absent", 3.0).unwrap(), 3.0);
        assert_eq!(p.unread(), vec!["tolerance".to_string()]);
        let e = p.refuse_unread("basis", "x").unwrap_err().to_string();
        assert!(
            e.contains("`tolerance`") && e.contains("absent, tol") && e.contains("basis `x`"),
            "{e}"
        );
        // a key read through a clone counts too; an untracked copy refuses nothing
        let q = p.clone();
        assert!(q.contains("tolerance"));
        assert!(p.refuse_unread("basis", "x").is_ok());
        let plain = Params::new().with_num("tolerance", 1.0);
        assert!(plain.unread().is_empty() && plain.refuse_unread("basis", "x").is_ok());
        assert_eq!(plain, Params::new().with_num("tolerance", 1.0).tracked());
    }

    #[test]
    fn range_checks_name_the_parameter_and_the_value() {
        assert_eq!(positive("cutoff_factor", 1.5).unwrap(), 1.5);
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let e = positive("cutoff_factor", bad).unwrap_err().to_string();
            assert!(e.contains("cutoff_factor") && e.contains("positive"), "{e}");
        }
        assert_eq!(fraction("rank_tol", 1e-10).unwrap(), 1e-10);
        for bad in [0.0, 1.0, -0.5, f64::NAN] {
            let e = fraction("rank_tol", bad).unwrap_err().to_string();
            assert!(e.contains("rank_tol") && e.contains("(0, 1)"), "{e}");
        }
    }
}
