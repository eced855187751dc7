//! A material table: the plugin name and its constants.

use crate::{Result, SceneError};
use serde::{Deserialize, Serialize};
use squeal_core::{ParamValue, Params};
use std::collections::BTreeMap;

/// A material: plugin name plus its constants.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MaterialSpec {
    /// Material plugin name (`isotropic`, `transversely_isotropic`, ...).
    pub kind: String,
    /// Constants passed to the plugin (names with units, e.g. `youngs_modulus_pa`).
    #[serde(flatten)]
    pub constants: BTreeMap<String, toml::Value>,
}

impl MaterialSpec {
    /// Converts the constants to plugin [`Params`]; `field` names the table for errors.
    pub fn params(&self, file: &str, field: &str) -> Result<Params> {
        let mut p = Params::new();
        for (k, v) in &self.constants {
            let value = match v {
                toml::Value::Float(x) => ParamValue::Num(*x),
                toml::Value::Integer(i) => ParamValue::Num(*i as f64),
                toml::Value::Boolean(b) => ParamValue::Bool(*b),
                toml::Value::String(s) => ParamValue::Str(s.clone()),
                toml::Value::Array(a) => ParamValue::List(
                    a.iter()
                        .map(|x| x.as_float().or_else(|| x.as_integer().map(|i| i as f64)))
                        .collect::<Option<Vec<f64>>>()
                        .ok_or_else(|| SceneError::Field {
                            file: file.into(),
                            field: format!("{field}.{k}"),
                            message: "expected a list of numbers".into(),
                        })?,
                ),
                other => {
                    return Err(SceneError::Field {
                        file: file.into(),
                        field: format!("{field}.{k}"),
                        message: format!("expected a number, string or list, got {other}"),
                    })
                }
            };
            p.0.insert(k.clone(), value);
        }
        Ok(p)
    }
}
