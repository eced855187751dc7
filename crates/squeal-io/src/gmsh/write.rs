//! The MSH 4.1 ASCII writer.

use super::*;

/// Name of the physical volume [`write_msh`] puts every hexahedron in.
pub const VOLUME_GROUP: &str = "volume";

/// The six faces of a hexahedron, nodes ordered for an outward normal.
const HEX_FACES: [[usize; 4]; 6] = [
    [0, 3, 2, 1],
    [4, 5, 6, 7],
    [0, 1, 5, 4],
    [1, 2, 6, 5],
    [2, 3, 7, 6],
    [3, 0, 4, 7],
];

/// The MSH 4.1 ASCII text of `mesh`: every hexahedron in volume entity 1 (physical
/// volume [`VOLUME_GROUP`]), and for each
/// node set named in `groups` a surface entity and a physical surface of that name
/// holding the hexahedron faces whose four nodes all lie in the set. `file` names the
/// destination in errors: an unknown group, or a set that is not a union of faces.
pub fn msh_string(mesh: &Mesh, groups: &[&str], file: &Path) -> Result<String, IoError> {
    let err = |problem: String, expected: &str| IoError::Msh {
        file: file.to_path_buf(),
        line: None,
        problem,
        expected: expected.into(),
    };
    if mesh.hexes.is_empty() {
        return Err(err(
            "the mesh has no hexahedron".into(),
            "a hexahedral mesh",
        ));
    }
    for (n, p) in mesh.nodes.iter().enumerate() {
        if p.iter().any(|v| !v.is_finite()) {
            return Err(err(format!("node {n} is at {p:?}"), "finite coordinates"));
        }
    }
    // faces of each group
    let mut faces: Vec<Vec<[usize; 4]>> = Vec::new();
    for &g in groups {
        let set = mesh
            .node_set(g)
            .map_err(|m| err(m, "node sets of the mesh"))?;
        let inside: HashSet<usize> = set.iter().copied().collect();
        let mut seen = HashSet::new();
        let mut fs = Vec::new();
        let mut covered = HashSet::new();
        for h in &mesh.hexes {
            for f in HEX_FACES {
                let q = f.map(|a| h[a]);
                if q.iter().all(|n| inside.contains(n)) {
                    let mut key = q;
                    key.sort_unstable();
                    if seen.insert(key) {
                        fs.push(q);
                        covered.extend(q);
                    }
                }
            }
        }
        if covered.len() != inside.len() {
            return Err(err(
                format!(
                    "node set `{g}` has {} nodes on no hexahedron face inside the set",
                    inside.len() - covered.len()
                ),
                "node sets that are unions of hexahedron faces",
            ));
        }
        faces.push(fs);
    }
    let bbox = |ns: &mut dyn Iterator<Item = usize>| {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for n in ns {
            for k in 0..3 {
                lo[k] = lo[k].min(mesh.nodes[n][k]);
                hi[k] = hi[k].max(mesh.nodes[n][k]);
            }
        }
        format!(
            "{:e} {:e} {:e} {:e} {:e} {:e}",
            lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]
        )
    };
    let mut s = String::new();
    let w = &mut s;
    let _ = writeln!(w, "$MeshFormat\n4.1 0 8\n$EndMeshFormat");
    // a physical volume too: Gmsh re-saves only physical elements, and meshio needs
    // every element block of a file with physical groups to have one
    let _ = writeln!(w, "$PhysicalNames\n{}", groups.len() + 1);
    for (i, g) in groups.iter().enumerate() {
        let _ = writeln!(w, "2 {} \"{g}\"", i + 1);
    }
    let _ = writeln!(w, "3 {} \"{VOLUME_GROUP}\"", groups.len() + 1);
    let _ = writeln!(w, "$EndPhysicalNames");
    let _ = writeln!(w, "$Entities\n0 0 {} 1", groups.len());
    for (i, fs) in faces.iter().enumerate() {
        let _ = writeln!(
            w,
            "{} {} 1 {} 0",
            i + 1,
            bbox(&mut fs.iter().flatten().copied()),
            i + 1
        );
    }
    let _ = writeln!(
        w,
        "1 {} 1 {} 0",
        bbox(&mut (0..mesh.nodes.len())),
        groups.len() + 1
    );
    let _ = writeln!(w, "$EndEntities");
    let n = mesh.nodes.len();
    let _ = writeln!(w, "$Nodes\n1 {n} 1 {n}\n3 1 0 {n}");
    for t in 1..=n {
        let _ = writeln!(w, "{t}");
    }
    for p in &mesh.nodes {
        let _ = writeln!(w, "{:e} {:e} {:e}", p[0], p[1], p[2]);
    }
    let _ = writeln!(w, "$EndNodes");
    let n_el = mesh.hexes.len() + faces.iter().map(Vec::len).sum::<usize>();
    let _ = writeln!(w, "$Elements\n{} {n_el} 1 {n_el}", groups.len() + 1);
    let mut tag = 0;
    for (i, fs) in faces.iter().enumerate() {
        let _ = writeln!(w, "2 {} 3 {}", i + 1, fs.len());
        for q in fs {
            tag += 1;
            let _ = writeln!(
                w,
                "{tag} {} {} {} {}",
                q[0] + 1,
                q[1] + 1,
                q[2] + 1,
                q[3] + 1
            );
        }
    }
    let _ = writeln!(w, "3 1 5 {}", mesh.hexes.len());
    for h in &mesh.hexes {
        tag += 1;
        let _ = write!(w, "{tag}");
        for &v in h {
            let _ = write!(w, " {}", v + 1);
        }
        let _ = writeln!(w);
    }
    let _ = writeln!(w, "$EndElements");
    Ok(s)
}

/// Writes `mesh` as a Gmsh MSH 4.1 ASCII file (see [`msh_string`]): nodes tagged 1..n in
/// mesh order, hexahedra in squeal's (= Gmsh's) node order, and one physical surface of
/// quadrangles per node set named in `groups`. Node sets not named are not written.
pub fn write_msh(mesh: &Mesh, path: &Path, groups: &[&str]) -> Result<(), IoError> {
    let text = msh_string(mesh, groups, path)?;
    std::fs::write(path, text).map_err(|source| IoError::Io {
        file: PathBuf::from(path),
        action: "write",
        source,
    })
}
