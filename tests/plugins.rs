//! Every crate under `plugins/` is registered: its one dependency line in the root
//! `Cargo.toml` is all the build script needs, and each plugin kind it provides shows in
//! `squeal::registry()`.

use std::path::Path;

#[test]
fn every_plugin_crate_is_registered() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut found = Vec::new();
    for entry in std::fs::read_dir(root.join("plugins")).unwrap() {
        let manifest = entry.unwrap().path().join("Cargo.toml");
        let Ok(text) = std::fs::read_to_string(&manifest) else {
            continue;
        };
        let doc: toml::Table = text.parse().unwrap();
        let name = doc["package"]["name"].as_str().unwrap().to_string();
        assert!(
            squeal::PLUGIN_CRATES.contains(&name.as_str()),
            "{name} ({}) is not registered: add `{name} = {{ path = \"plugins/...\" }}` to the \
             root [dependencies]",
            manifest.display()
        );
        found.push(name);
    }
    assert_eq!(found.len(), squeal::PLUGIN_CRATES.len(), "{found:?}");
    let reg = squeal::registry();
    for (kind, names) in [
        ("basis", reg.bases.names()),
        ("eigen", reg.eigen.names()),
        ("equilibrium", reg.equilibrium.names()),
        ("material", reg.materials.names()),
        ("contact law", reg.contact_laws.names()),
    ] {
        assert!(!names.is_empty(), "no {kind} plugin registered");
    }
}

#[test]
fn the_default_registry_has_every_basis_pod_included() {
    use squeal::core::Params;
    let reg = squeal::registry();
    let bases: Vec<(String, String)> = reg.bases.describe();
    for name in ["modes", "enriched", "residue", "cms", "pod"] {
        let (_, d) = bases
            .iter()
            .find(|(n, _)| n == name)
            .unwrap_or_else(|| panic!("`{name}` not registered: {bases:?}"));
        assert!(!d.is_empty(), "{name}");
    }
    let pod = reg.bases.create("pod", &Params::new()).unwrap();
    assert!(!pod.depends_on_mu());
    let (k, v) = Params::parse_kv("snapshots=0,0.4,0.8").unwrap();
    assert!(reg.bases.create("pod", &Params::new().with(&k, v)).is_ok());
    let e = reg
        .bases
        .create("pod", &Params::new().with_num("snapshot", 0.4))
        .err()
        .expect("a typo is refused")
        .to_string();
    assert!(e.contains("snapshot") && e.contains("snapshots"), "{e}");
}
