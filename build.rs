//! Registers every plugin crate: the `[dependencies]` of this package whose path lies
//! under `plugins/` (directly, or through `[workspace.dependencies]`) each get a
//! `<crate>::register(&mut registry)` call in `squeal::registry()`. Adding a method is
//! therefore one crate under `plugins/` plus its one dependency line in `Cargo.toml`.

use std::path::Path;

fn main() {
    println!("cargo:rerun-if-changed=Cargo.toml");
    let dir = std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR");
    let text = std::fs::read_to_string(Path::new(&dir).join("Cargo.toml"))
        .expect("the root Cargo.toml is readable");
    let doc: toml::Table = text.parse().expect("the root Cargo.toml is valid TOML");
    let workspace = doc
        .get("workspace")
        .and_then(|w| w.get("dependencies"))
        .and_then(|d| d.as_table())
        .cloned()
        .unwrap_or_default();
    let deps = doc
        .get("dependencies")
        .and_then(|d| d.as_table())
        .cloned()
        .unwrap_or_default();
    let mut plugins = Vec::new();
    for (name, spec) in &deps {
        let path = match spec.get("path").and_then(|p| p.as_str()) {
            Some(p) => Some(p.to_string()),
            None if spec.get("workspace").and_then(|w| w.as_bool()) == Some(true) => workspace
                .get(name)
                .and_then(|w| w.get("path"))
                .and_then(|p| p.as_str())
                .map(str::to_string),
            None => None,
        };
        if path.is_some_and(|p| p.starts_with("plugins/")) {
            plugins.push(name.clone());
        }
    }
    let calls: String = plugins
        .iter()
        .map(|p| format!("    {}::register(reg);\n", p.replace('-', "_")))
        .collect();
    let names: String = plugins.iter().map(|p| format!("\"{p}\", ")).collect();
    let code = format!(
        "/// Registers every plugin crate of `plugins/` this package depends on.\n\
         fn register_plugins(reg: &mut Registry) {{\n{calls}}}\n\n\
         /// The plugin crates registered by [`registry`], by package name.\n\
         pub const PLUGIN_CRATES: &[&str] = &[{names}];\n"
    );
    let out = std::env::var("OUT_DIR").expect("cargo sets OUT_DIR");
    std::fs::write(Path::new(&out).join("plugins.rs"), code).expect("OUT_DIR is writable");
}
