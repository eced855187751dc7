//! Parsing of the study inputs: number lists, zone axes, shards, regions.

use super::{input, Result};
use serde::{Deserialize, Serialize};

/// Parses a list of numbers: comma-separated values and inclusive ranges
/// `FROM:TO:STEP` (e.g. `0.004:0.02:0.002,0.025`), in the given order; `option` names the
/// option in errors.
pub fn parse_list(option: &str, text: &str) -> Result<Vec<f64>> {
    let num = |s: &str| -> Result<f64> {
        let v = s
            .trim()
            .parse::<f64>()
            .map_err(|_| input(option, format!("`{s}` in `{text}` is not a number")))?;
        if v.is_finite() {
            Ok(v)
        } else {
            Err(input(option, format!("`{s}` in `{text}` is not finite")))
        }
    };
    let mut out = Vec::new();
    for item in text.split(',').map(str::trim) {
        if item.is_empty() {
            return Err(input(
                option,
                format!("empty item in `{text}`: expected values or FROM:TO:STEP ranges, comma separated"),
            ));
        }
        let parts: Vec<&str> = item.split(':').collect();
        match parts.as_slice() {
            [v] => out.push(num(v)?),
            [a, b, c] => {
                let (a, b, c) = (num(a)?, num(b)?, num(c)?);
                if !(c > 0.0 && b >= a) {
                    return Err(input(
                        option,
                        format!(
                            "range `{item}`: expected FROM:TO:STEP with FROM <= TO and STEP > 0"
                        ),
                    ));
                }
                let n = ((b - a) / c + 1e-9).floor() as usize;
                if n > 100_000 {
                    return Err(input(
                        option,
                        format!("range `{item}` has {} values (at most 100001)", n + 1),
                    ));
                }
                out.extend((0..=n).map(|k| ((a + k as f64 * c) * 1e12).round() / 1e12));
            }
            _ => {
                return Err(input(
                    option,
                    format!("`{item}`: expected a value or FROM:TO:STEP"),
                ))
            }
        }
    }
    Ok(out)
}

/// Where zones start along one axis: centred on the pin face, or at given offsets from
/// the face corner (m).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Axis {
    /// The zone's centre on the face centre: `x0 = (size - a) / 2`.
    Centred,
    /// Offsets from the face corner (m).
    Values(Vec<f64>),
}

impl Axis {
    /// `centred` (or `centered`, `center`) or a list as in [`parse_list`], offsets >= 0.
    pub fn parse(option: &str, text: &str) -> Result<Self> {
        if matches!(text.trim(), "centred" | "centered" | "center" | "centre") {
            return Ok(Axis::Centred);
        }
        let v = parse_list(option, text)?;
        if let Some(x) = v.iter().find(|x| **x < 0.0) {
            return Err(input(
                option,
                format!("expected offsets >= 0 m from the pin face corner (or `centred`), got {x}"),
            ));
        }
        Ok(Axis::Values(v))
    }

    pub(super) fn offsets(&self, size: f64, len: f64) -> Vec<f64> {
        match self {
            Axis::Centred => vec![((size - len) / 2.0 * 1e12).round() / 1e12],
            Axis::Values(v) => v.clone(),
        }
    }
}

/// Part `K` of `N` of a study: the cases whose index (in id order) is `K - 1` modulo `N`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// 1-based part.
    pub k: usize,
    /// Number of parts.
    pub n: usize,
}

impl Shard {
    /// Parses `K/N` with `1 <= K <= N`.
    pub fn parse(text: &str) -> Result<Self> {
        let bad = || {
            input(
                "options.shard",
                format!(
                    "`{text}`: expected K/N with 1 <= K <= N (e.g. 2/8: the second of 8 parts)"
                ),
            )
        };
        let (k, n) = text.split_once('/').ok_or_else(bad)?;
        let (k, n) = (
            k.trim().parse::<usize>().map_err(|_| bad())?,
            n.trim().parse::<usize>().map_err(|_| bad())?,
        );
        if k == 0 || n == 0 || k > n {
            return Err(bad());
        }
        Ok(Self { k, n })
    }

    /// Whether case `index` belongs to this shard.
    pub fn holds(&self, index: usize) -> bool {
        index % self.n == self.k - 1
    }
}

/// Parses a region `x0,y0,a,b` (m from the pin face corner).
pub fn parse_region(option: &str, text: &str) -> Result<[f64; 4]> {
    let v = parse_list(option, text)?;
    match v.as_slice() {
        [x0, y0, a, b] if *x0 >= 0.0 && *y0 >= 0.0 && *a > 0.0 && *b > 0.0 => Ok([*x0, *y0, *a, *b]),
        _ => Err(input(
            option,
            format!("`{text}`: expected x0,y0,a,b in m (x0, y0 >= 0 from the pin face corner, a, b > 0)"),
        )),
    }
}
