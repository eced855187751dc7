//! Writes `scenes/imported-disc.msh`, the Gmsh MSH 4.1 mesh of the example scene
//! `scenes/imported-disc.toml`: a coarse steel disc (60 to 300 mm diameter, 12 mm thick)
//! meshed as a structured annulus, coordinates in millimetres (the scene reads it with
//! `scale = 0.001`), physical surfaces `bore` (the clamped inner cylinder) and
//! `friction` (the top face z = 0).
//!
//! `cargo run -p squeal-scene --example write_imported_disc [OUT]`

use squeal_fe::mesh::linspace;
use squeal_fe::Mesh;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args().nth(1).unwrap_or_else(|| {
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../scenes/imported-disc.msh"
        )
        .into()
    });
    let mut disc = Mesh::annulus(&linspace(30.0, 150.0, 8), 64, &linspace(-12.0, 0.0, 2));
    let bore = disc
        .node_sets
        .remove("inner")
        .expect("annulus has an inner face");
    let friction = disc
        .node_sets
        .remove("zmax")
        .expect("annulus has a top face");
    disc.node_sets.clear();
    disc.node_sets.insert("bore".into(), bore);
    disc.node_sets.insert("friction".into(), friction);
    squeal_io::write_msh(&disc, std::path::Path::new(&out), &["bore", "friction"])?;
    println!(
        "{out}: {} nodes, {} hexahedra, groups bore and friction (mm)",
        disc.nodes.len(),
        disc.hexes.len()
    );
    Ok(())
}
