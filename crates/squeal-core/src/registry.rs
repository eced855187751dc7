//! The plugin registry: names to constructors, one table per plugin kind.
//!
//! A plugin crate exposes `pub fn register(reg: &mut Registry)`; the `squeal` facade
//! calls each of them once in `squeal::registry()`, so adding a method is one crate plus
//! one line there. Out-of-tree code registers into the same object at run time.

use crate::{
    ContactLaw, EigenSolver, EquilibriumSolver, Error, Material, Params, ReductionBasis, Result,
};
use std::collections::BTreeMap;
use std::sync::Arc;

/// A constructor from parameters.
pub type Ctor<T> = Arc<dyn Fn(&Params) -> Result<Box<T>> + Send + Sync>;

/// Constructors of one plugin kind, by name.
pub struct Table<T: ?Sized> {
    kind: &'static str,
    entries: BTreeMap<String, (String, Ctor<T>)>,
}

impl<T: ?Sized> Table<T> {
    fn new(kind: &'static str) -> Self {
        Self {
            kind,
            entries: BTreeMap::new(),
        }
    }

    /// Registers (or replaces) a constructor with a one-line description.
    pub fn register(
        &mut self,
        name: &str,
        description: &str,
        ctor: impl Fn(&Params) -> Result<Box<T>> + Send + Sync + 'static,
    ) {
        self.entries
            .insert(name.to_string(), (description.to_string(), Arc::new(ctor)));
    }

    /// Builds the plugin `name` from `params`; a key the constructor never asked for is
    /// refused ([`Params::refuse_unread`]).
    pub fn create(&self, name: &str, params: &Params) -> Result<Box<T>> {
        match self.entries.get(name) {
            Some((_, ctor)) => {
                let tracked = params.tracked();
                let plugin = ctor(&tracked).map_err(|e| with_unread(e, &tracked.unread()))?;
                tracked.refuse_unread(self.kind, name)?;
                Ok(plugin)
            }
            None => Err(Error::UnknownPlugin {
                kind: self.kind,
                name: name.to_string(),
                available: self.names().join(", "),
            }),
        }
    }

    /// Registered names, sorted.
    pub fn names(&self) -> Vec<String> {
        self.entries.keys().cloned().collect()
    }

    /// `(name, description)` pairs, sorted by name.
    pub fn describe(&self) -> Vec<(String, String)> {
        self.entries
            .iter()
            .map(|(k, (d, _))| (k.clone(), d.clone()))
            .collect()
    }
}

/// A constructor's parameter error, with the keys given that it had not read when it
/// failed (a misspelt key is often why a required one is missing).
fn with_unread(e: Error, unread: &[String]) -> Error {
    match e {
        Error::Param { name, reason } if !unread.is_empty() => {
            let keys: Vec<String> = unread.iter().map(|k| format!("`{k}`")).collect();
            Error::Param {
                name,
                reason: format!(
                    "{reason} (given and not read before this error: {})",
                    keys.join(", ")
                ),
            }
        }
        other => other,
    }
}

/// All plugin tables.
pub struct Registry {
    /// Elastic materials.
    pub materials: Table<dyn Material>,
    /// Contact laws.
    pub contact_laws: Table<dyn ContactLaw>,
    /// Sliding-equilibrium solvers.
    pub equilibrium: Table<dyn EquilibriumSolver>,
    /// Reduction bases.
    pub bases: Table<dyn ReductionBasis>,
    /// Eigen solvers.
    pub eigen: Table<dyn EigenSolver>,
}

impl Default for Registry {
    fn default() -> Self {
        Self {
            materials: Table::new("material"),
            contact_laws: Table::new("contact law"),
            equilibrium: Table::new("equilibrium"),
            bases: Table::new("basis"),
            eigen: Table::new("eigen"),
        }
    }
}

impl Registry {
    /// An empty registry.
    pub fn new() -> Self {
        Self::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Voigt6;

    #[derive(Debug)]
    struct Unit(f64);
    impl Material for Unit {
        fn name(&self) -> &str {
            "unit"
        }
        fn elasticity(&self) -> Voigt6 {
            [[0.0; 6]; 6]
        }
        fn density(&self) -> f64 {
            self.0
        }
    }

    #[test]
    fn create_by_name_and_report_unknown() {
        let mut reg = Registry::new();
        reg.materials.register("unit", "test material", |p| {
            Ok(Box::new(Unit(p.num_or("rho", 1.0)?)))
        });
        let m = reg
            .materials
            .create("unit", &Params::new().with_num("rho", 7.0))
            .unwrap();
        assert_eq!(m.density(), 7.0);
        let e = reg.materials.create("steel", &Params::new()).err().unwrap();
        let msg = e.to_string();
        assert!(msg.contains("steel") && msg.contains("unit"), "{msg}");
        // a key the constructor never reads is refused, naming what it does read
        let e = reg
            .materials
            .create("unit", &Params::new().with_num("rh0", 7.0))
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("rh0") && e.contains("it takes: rho"), "{e}");
    }
}
