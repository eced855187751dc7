//! Setting scene values by dotted path (`thin_plate.thickness_m`,
//! `pin.material.shear_modulus_axial_pa`): what model updating and parameter studies
//! change. The scene goes through its TOML form, so a path is exactly a field of the
//! scene file (`docs/scenes.md`), an unknown field is refused by the same rules as a file,
//! and the edited scene is validated like a file.

use crate::{Result, Scene, SceneError};

impl Scene {
    /// The number at `path`, `None` when the scene has no value there (an optional field
    /// left to its default, or a body the scene lacks).
    pub fn value_at(&self, path: &str) -> Option<f64> {
        let value = toml::Value::try_from(self).ok()?;
        let mut node = &value;
        for key in path.split('.') {
            node = node.as_table()?.get(key)?;
        }
        node.as_float()
            .or_else(|| node.as_integer().map(|i| i as f64))
    }

    /// A copy of the scene with the numbers `values` set at their dotted paths, validated;
    /// `file` names the edited scene in errors. A path must lead through tables the scene
    /// has to a numeric field of the scene format (it may be absent, for an optional
    /// field); the error names the path and what is wrong.
    pub fn with_values(&self, values: &[(&str, f64)], file: &str) -> Result<Scene> {
        let mut doc = toml::Value::try_from(self).map_err(|e| SceneError::Parse {
            file: file.into(),
            message: format!("cannot write the scene as TOML: {e}"),
        })?;
        for &(path, v) in values {
            set_path(&mut doc, path, v).map_err(|message| SceneError::Field {
                file: file.into(),
                field: path.into(),
                message,
            })?;
        }
        let mut scene: Scene = doc.try_into().map_err(|e: toml::de::Error| {
            let paths: Vec<&str> = values.iter().map(|(p, _)| *p).collect();
            SceneError::Parse {
                file: file.into(),
                message: format!("setting {}: {}", paths.join(", "), e.message().trim_end()),
            }
        })?;
        // imported meshes are read once, not written to TOML: carry them over
        for (to, from) in [
            (
                scene.disc.as_mut().and_then(|d| d.mesh.as_mut()),
                self.disc.as_ref().and_then(|d| d.mesh.as_ref()),
            ),
            (
                scene.pin.as_mut().and_then(|p| p.mesh.as_mut()),
                self.pin.as_ref().and_then(|p| p.mesh.as_ref()),
            ),
        ] {
            if let (Some(to), Some(from)) = (to, from) {
                to.loaded = from.loaded.clone();
            }
        }
        scene.validate(file)?;
        Ok(scene)
    }
}

fn set_path(doc: &mut toml::Value, path: &str, v: f64) -> std::result::Result<(), String> {
    if !v.is_finite() {
        return Err(format!("expected a finite number, got {v}"));
    }
    let keys: Vec<&str> = path.split('.').collect();
    if keys.iter().any(|k| k.is_empty()) {
        return Err("expected a dotted path of field names, e.g. `thin_plate.thickness_m`".into());
    }
    let (leaf, tables) = keys.split_last().expect("split gives one key at least");
    let mut node = doc;
    let mut walked = String::new();
    for key in tables {
        let here = if walked.is_empty() {
            "the scene".to_string()
        } else {
            format!("`{walked}`")
        };
        let table = node
            .as_table_mut()
            .ok_or_else(|| format!("{here} is not a table"))?;
        node = table
            .get_mut(*key)
            .ok_or_else(|| format!("{here} has no table `{key}` (add it to the scene first)"))?;
        if !walked.is_empty() {
            walked.push('.');
        }
        walked.push_str(key);
    }
    let table = node
        .as_table_mut()
        .ok_or_else(|| format!("`{walked}` is not a table"))?;
    match table.get(*leaf) {
        Some(toml::Value::Integer(_)) => {
            if v.fract() != 0.0 || v.abs() > 9.0e15 {
                return Err(format!("expected a whole number, got {v}"));
            }
            table.insert(leaf.to_string(), toml::Value::Integer(v as i64));
            Ok(())
        }
        Some(toml::Value::Float(_)) | None => {
            table.insert(leaf.to_string(), toml::Value::Float(v));
            Ok(())
        }
        Some(other) => Err(format!("is a {}, not a number", other.type_str())),
    }
}

#[cfg(test)]
mod tests {
    use crate::Scene;

    #[test]
    fn a_value_set_by_path_is_read_back_and_validated() {
        let s = Scene::builtin("pin-on-disc-coarse").unwrap();
        let t = s
            .with_values(&[("thin_plate.thickness_m", 0.004)], "edit")
            .unwrap();
        assert_eq!(t.thin_plate.as_ref().unwrap().thickness_m, 0.004);
        assert_eq!(t.value_at("thin_plate.thickness_m"), Some(0.004));
        // an optional field absent from the scene may be set
        let g = s
            .with_values(&[("pin.material.shear_modulus_axial_pa", 2e9)], "edit")
            .unwrap();
        assert_eq!(g.value_at("pin.material.shear_modulus_axial_pa"), Some(2e9));
        // the scene's own validation still applies
        let e = s
            .with_values(&[("thin_plate.thickness_m", -1.0)], "edit")
            .unwrap_err()
            .to_string();
        assert!(e.contains("thin_plate.thickness_m"), "{e}");
    }

    #[test]
    fn a_wrong_path_is_named() {
        let s = Scene::builtin("pin-on-disc-coarse").unwrap();
        let e = s
            .with_values(&[("thin_plate.thicknes_m", 0.004)], "edit")
            .unwrap_err()
            .to_string();
        assert!(e.contains("thicknes_m"), "{e}");
        let e = s
            .with_values(&[("plate.thickness_m", 0.004)], "edit")
            .unwrap_err()
            .to_string();
        assert!(e.contains("no table `plate`"), "{e}");
        let e = s
            .with_values(&[("pin.material.kind", 1.0)], "edit")
            .unwrap_err()
            .to_string();
        assert!(e.contains("not a number"), "{e}");
        assert_eq!(s.value_at("thin_plate.nothing"), None);
        // whole-number fields take whole numbers only
        let e = s
            .with_values(&[("mesh.min_layers", 2.5)], "edit")
            .unwrap_err()
            .to_string();
        assert!(e.contains("whole number"), "{e}");
        let r = s.with_values(&[("mesh.min_layers", 3.0)], "edit").unwrap();
        assert_eq!(r.mesh.min_layers, 3);
    }
}
