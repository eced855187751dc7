//! ParaView output: the mesh and mode shapes as VTK XML unstructured grids (`.vtu`, ASCII)
//! gathered in a `.pvd` collection.
//!
//! Each mode is one `.vtu` file with the point vector `displacement` (m, mass-normalized
//! shape), the point scalar `magnitude` and the cell scalar `body`; its frequency (Hz) is
//! the collection's `timestep` and a `frequency_hz` field. Hexahedra are VTK cell type 12,
//! whose node order (bottom face counter-clockwise, then top) is squeal's.

use squeal_fe::Mesh;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// VTK cell type of the 8-node hexahedron.
pub const VTK_HEXAHEDRON: u8 = 12;

/// One vector field on the mesh nodes: `values[3 n + a]`.
pub struct NodalField<'a> {
    /// Array name.
    pub name: &'a str,
    /// Three components per mesh node.
    pub values: &'a [f64],
}

/// Writes one `.vtu` file: the mesh, its body ids and optional nodal vector fields plus
/// field data (name, value).
pub fn write_vtu(
    path: &Path,
    mesh: &Mesh,
    fields: &[NodalField<'_>],
    field_data: &[(&str, f64)],
) -> std::io::Result<()> {
    let n = mesh.n_nodes();
    for f in fields {
        if f.values.len() != 3 * n {
            return Err(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                format!(
                    "{}: field `{}` has {} values, expected 3 x {n} nodes",
                    path.display(),
                    f.name,
                    f.values.len()
                ),
            ));
        }
    }
    let mut s = String::with_capacity(64 * n + 80 * mesh.hexes.len());
    s.push_str("<?xml version=\"1.0\"?>\n");
    s.push_str(
        "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n<UnstructuredGrid>\n",
    );
    if !field_data.is_empty() {
        s.push_str("<FieldData>\n");
        for (name, v) in field_data {
            let _ = writeln!(
                s,
                "<DataArray type=\"Float64\" Name=\"{name}\" NumberOfTuples=\"1\" format=\"ascii\">{v:e}</DataArray>"
            );
        }
        s.push_str("</FieldData>\n");
    }
    let _ = writeln!(
        s,
        "<Piece NumberOfPoints=\"{n}\" NumberOfCells=\"{}\">",
        mesh.hexes.len()
    );
    if let Some(first) = fields.first() {
        let _ = writeln!(
            s,
            "<PointData Vectors=\"{}\" Scalars=\"magnitude\">",
            first.name
        );
        for f in fields {
            let _ = writeln!(
                s,
                "<DataArray type=\"Float64\" Name=\"{}\" NumberOfComponents=\"3\" format=\"ascii\">",
                f.name
            );
            for c in f.values.chunks(3) {
                let _ = writeln!(s, "{:e} {:e} {:e}", c[0], c[1], c[2]);
            }
            s.push_str("</DataArray>\n");
        }
        s.push_str("<DataArray type=\"Float64\" Name=\"magnitude\" format=\"ascii\">\n");
        for c in first.values.chunks(3) {
            let _ = writeln!(s, "{:e}", (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt());
        }
        s.push_str("</DataArray>\n</PointData>\n");
    }
    s.push_str(
        "<CellData Scalars=\"body\">\n<DataArray type=\"Int32\" Name=\"body\" format=\"ascii\">\n",
    );
    for b in &mesh.hex_body {
        let _ = writeln!(s, "{b}");
    }
    s.push_str("</DataArray>\n</CellData>\n<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n");
    for p in &mesh.nodes {
        let _ = writeln!(s, "{:e} {:e} {:e}", p[0], p[1], p[2]);
    }
    s.push_str("</DataArray>\n</Points>\n<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
    for h in &mesh.hexes {
        let _ = writeln!(
            s,
            "{} {} {} {} {} {} {} {}",
            h[0], h[1], h[2], h[3], h[4], h[5], h[6], h[7]
        );
    }
    s.push_str("</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
    for e in 1..=mesh.hexes.len() {
        let _ = writeln!(s, "{}", 8 * e);
    }
    s.push_str("</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
    for _ in &mesh.hexes {
        let _ = writeln!(s, "{VTK_HEXAHEDRON}");
    }
    s.push_str("</DataArray>\n</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
    std::fs::write(path, s)
}

/// Writes `mesh.vtu`, one `mode_NNN.vtu` per shape and `modes.pvd` into `dir`; `shapes`
/// are (frequency in Hz, three values per mesh node). Returns the written paths.
pub fn write_modes(
    dir: &Path,
    mesh: &Mesh,
    shapes: &[(f64, Vec<f64>)],
) -> std::io::Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir)?;
    let mut written = vec![dir.join("mesh.vtu")];
    write_vtu(&written[0], mesh, &[], &[])?;
    let mut pvd = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n<Collection>\n",
    );
    for (i, (f, u)) in shapes.iter().enumerate() {
        let name = format!("mode_{:03}.vtu", i + 1);
        let path = dir.join(&name);
        write_vtu(
            &path,
            mesh,
            &[NodalField {
                name: "displacement",
                values: u,
            }],
            &[("frequency_hz", *f), ("mode", (i + 1) as f64)],
        )?;
        let _ = writeln!(
            pvd,
            "<DataSet timestep=\"{f}\" group=\"\" part=\"0\" file=\"{name}\"/>"
        );
        written.push(path);
    }
    pvd.push_str("</Collection>\n</VTKFile>\n");
    let p = dir.join("modes.pvd");
    std::fs::write(&p, pvd)?;
    written.push(p);
    Ok(written)
}

/// Expands a vector on the free DOFs to three values per mesh node (zeros on fixed DOFs).
pub fn nodal(free_of_full: &[Option<usize>], u_free: &[f64]) -> Vec<f64> {
    free_of_full
        .iter()
        .map(|f| f.map_or(0.0, |i| u_free[i]))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn arrays(text: &str, name: &str) -> Vec<f64> {
        let start = text
            .find(&format!("Name=\"{name}\""))
            .unwrap_or_else(|| panic!("no array {name}"));
        let open = start + text[start..].find('>').unwrap() + 1;
        let close = open + text[open..].find("</DataArray>").unwrap();
        text[open..close]
            .split_whitespace()
            .map(|t| t.parse::<f64>().unwrap())
            .collect()
    }

    #[test]
    fn vtu_structure_and_sizes() {
        let mesh = Mesh::block(&[0.0, 1.0, 2.0], &[0.0, 1.0], &[0.0, 0.5, 1.0]);
        let n = mesh.n_nodes();
        let u: Vec<f64> = (0..3 * n).map(|i| i as f64 * 0.1).collect();
        let dir = std::env::temp_dir().join(format!("squeal-vtu-{}", std::process::id()));
        let files = write_modes(&dir, &mesh, &[(123.5, u.clone()), (456.0, u.clone())]).unwrap();
        assert_eq!(files.len(), 4);
        let text = std::fs::read_to_string(dir.join("mode_002.vtu")).unwrap();
        // balanced tags
        for tag in [
            "VTKFile",
            "UnstructuredGrid",
            "Piece",
            "PointData",
            "CellData",
            "Points",
            "Cells",
        ] {
            assert_eq!(
                text.matches(&format!("<{tag}")).count(),
                text.matches(&format!("</{tag}>")).count(),
                "{tag}"
            );
        }
        assert_eq!(
            text.matches("<DataArray").count(),
            text.matches("</DataArray>").count()
        );
        assert!(text.contains(&format!(
            "NumberOfPoints=\"{n}\" NumberOfCells=\"{}\"",
            mesh.hexes.len()
        )));
        assert_eq!(arrays(&text, "displacement"), u);
        assert_eq!(arrays(&text, "magnitude").len(), n);
        let conn = arrays(&text, "connectivity");
        assert_eq!(conn.len(), 8 * mesh.hexes.len());
        assert!(conn.iter().all(|&c| c >= 0.0 && (c as usize) < n));
        assert_eq!(
            arrays(&text, "offsets").last().copied(),
            Some(8.0 * mesh.hexes.len() as f64)
        );
        assert!(arrays(&text, "types").iter().all(|&t| t == 12.0));
        assert_eq!(arrays(&text, "frequency_hz"), vec![456.0]);
        let pvd = std::fs::read_to_string(dir.join("modes.pvd")).unwrap();
        assert_eq!(pvd.matches("<DataSet").count(), 2);
        assert!(pvd.contains("file=\"mode_001.vtu\"") && pvd.contains("timestep=\"123.5\""));
        // VTK's hexahedron has a positive volume with squeal's node order
        let x = mesh.hex_coords(0);
        assert!(squeal_fe::mesh::hex_volume(&x) > 0.0);
        // wrong field size is an error naming the file
        let e = write_vtu(
            &dir.join("bad.vtu"),
            &mesh,
            &[NodalField {
                name: "d",
                values: &[0.0],
            }],
            &[],
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("bad.vtu") && e.contains("`d`"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
