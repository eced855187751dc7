//! Gmsh MSH 4.1 reader and writer: round trips, a hand-written file, and one test per
//! malformed case checking that the message names the file and what was expected.

use squeal_fe::mesh::{hex_volume, linspace};
use squeal_fe::Mesh;
use squeal_io::{read_msh, read_msh_bytes, write_msh, IoError};
use std::path::{Path, PathBuf};

/// A fresh directory for one test.
fn tmp(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("squeal-io-gmsh")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// One hexahedron (unit cube scaled by 2 along x) with sparse, unordered node tags, a
/// named contact face on z = 1, an unnamed physical volume, a physical point, an unused
/// node (tag 90, parametric) and a
/// section squeal does not read.
const ONE_HEX: &str = r#"$MeshFormat
4.1 0 8
$EndMeshFormat
$PhysicalNames
2
2 3 "contact face"
0 9 "corner"
$EndPhysicalNames
$Comments
anything $Nodes here is skipped
$EndComments
$Entities
1 0 1 1
5 0 0 0 1 9
11 0 0 1 2 1 1 1 3 0
21 0 0 0 2 1 1 1 7 0
$EndEntities
$Nodes
3 9 10 90
0 5 0 1
10
0 0 0
3 21 0 7
80
20
30
40
50
60
70
0 1 1
2 0 0
2 1 0
0 1 0
0 0 1
2 0 1
2 1 1
2 11 1 1
90
1 1 1 0.5 0.5
$EndNodes
$Elements
3 3 1 3
0 5 15 1
1 10
2 11 3 1
2 50 60 70 80
3 21 5 1
3 10 20 30 40 50 60 70 80
$EndElements
$Periodic
0
$EndPeriodic
"#;

#[test]
fn hand_written_hex_is_read() {
    let m = read_msh_bytes(ONE_HEX.as_bytes(), Path::new("one.msh")).unwrap();
    // node 90 is used by no hexahedron: dropped; the rest numbered by tag
    assert_eq!(m.nodes.len(), 8);
    assert_eq!(m.nodes[0], [0.0, 0.0, 0.0]); // tag 10
    assert_eq!(m.nodes[1], [2.0, 0.0, 0.0]); // tag 20
    assert_eq!(m.nodes[7], [0.0, 1.0, 1.0]); // tag 80
    assert_eq!(m.hexes.len(), 1);
    assert_eq!(m.hex_body, vec![0]);
    assert_eq!(m.hexes[0], [0, 1, 2, 3, 4, 5, 6, 7]);
    approx::assert_relative_eq!(hex_volume(&m.hex_coords(0)), 2.0, max_relative = 1e-14);
    assert_eq!(m.node_set("contact face").unwrap(), &[4, 5, 6, 7]);
    assert_eq!(m.node_set("corner").unwrap(), &[0]);
    // the physical volume selects nothing and is no node set
    assert!(m.node_set("physical_7").is_err());
    assert_eq!(m.node_sets.len(), 2);
}

#[test]
fn mirrored_hexahedra_are_flipped() {
    // the same cube with its bottom and top faces traversed clockwise: negative volume
    let text = ONE_HEX.replace("3 10 20 30 40 50 60 70 80", "3 10 40 30 20 50 80 70 60");
    let m = read_msh_bytes(text.as_bytes(), Path::new("mirror.msh")).unwrap();
    approx::assert_relative_eq!(hex_volume(&m.hex_coords(0)), 2.0, max_relative = 1e-14);
    assert_eq!(m.hexes[0], [0, 1, 2, 3, 4, 5, 6, 7]);
}

#[test]
fn block_and_annulus_round_trip() {
    let d = tmp("round_trip");
    let block = Mesh::block(
        &[0.0, 0.1, 0.25, 0.3],
        &linspace(-0.02, 0.02, 3),
        &linspace(0.0, 0.015, 2),
    );
    let annulus = Mesh::annulus(&linspace(0.05, 0.15, 3), 24, &linspace(-0.01, 0.0, 2));
    for (name, mesh, groups) in [
        ("block", &block, vec!["xmin", "zmax", "ymin"]),
        ("annulus", &annulus, vec!["inner", "zmax"]),
    ] {
        let path = d.join(format!("{name}.msh"));
        write_msh(mesh, &path, &groups).unwrap();
        let back = read_msh(&path).unwrap();
        assert_eq!(
            back.nodes, mesh.nodes,
            "{name}: coordinates are bit-identical"
        );
        assert_eq!(back.hexes, mesh.hexes, "{name}");
        assert_eq!(back.hex_body, mesh.hex_body, "{name}");
        assert_eq!(back.node_sets.len(), groups.len());
        for g in groups {
            assert_eq!(
                back.node_set(g).unwrap(),
                mesh.node_set(g).unwrap(),
                "{name}.{g}"
            );
        }
    }
}

#[test]
fn writer_rejects_unknown_groups_and_non_faces() {
    let d = tmp("writer");
    let mut m = Mesh::block(&[0.0, 1.0, 2.0], &[0.0, 1.0], &[0.0, 1.0]);
    let e = write_msh(&m, &d.join("a.msh"), &["nope"])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("a.msh") && e.contains("nope") && e.contains("xmin"),
        "{e}"
    );
    m.node_sets.insert("lonely".into(), vec![0, 1]);
    let e = write_msh(&m, &d.join("b.msh"), &["lonely"])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("b.msh") && e.contains("unions of hexahedron faces"),
        "{e}"
    );
}

/// Reads `text` as `name`, expecting an error whose message contains every one of `want`.
fn fails(name: &str, text: &str, want: &[&str]) -> String {
    let e = read_msh_bytes(text.as_bytes(), Path::new(name)).unwrap_err();
    assert!(matches!(e, IoError::Msh { .. }), "{e:?}");
    let e = e.to_string();
    assert!(e.contains(name), "names the file: {e}");
    assert!(e.contains("expected"), "says what was expected: {e}");
    assert!(!e.contains("expected expected"), "{e}");
    for w in want {
        assert!(e.contains(w), "`{w}` in: {e}");
    }
    e
}

#[test]
fn binary_and_old_versions_are_rejected() {
    let bin = ONE_HEX.replace("4.1 0 8", "4.1 1 8");
    fails(
        "bin.msh",
        &bin,
        &["bin.msh:2:", "binary", "expected MSH 4.1 ASCII"],
    );
    let v22 = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n1\n1 0 0 0\n$EndNodes\n";
    fails(
        "old.msh",
        v22,
        &["old.msh:2:", "2.2", "expected MSH 4.1 ASCII"],
    );
    fails("empty.msh", "", &["empty", "expected MSH 4.1 ASCII"]);
    fails(
        "vtk.msh",
        "# vtk DataFile Version 3.0\n",
        &["vtk.msh:1:", "$MeshFormat", "expected MSH 4.1 ASCII"],
    );
    // a real binary file (non-UTF-8 bytes) read from disk
    let d = tmp("binary");
    let mut bytes = b"$MeshFormat\n4.1 1 8\n".to_vec();
    bytes.extend([1u8, 0, 0, 0, 0xff, 0xfe]);
    bytes.extend(b"\n$EndMeshFormat\n");
    let path = d.join("real-binary.msh");
    std::fs::write(&path, bytes).unwrap();
    let e = read_msh(&path).unwrap_err().to_string();
    assert!(
        e.contains("real-binary.msh") && e.contains("expected MSH 4.1 ASCII"),
        "{e}"
    );
}

#[test]
fn non_hexahedral_elements_are_rejected() {
    let tet = ONE_HEX.replace(
        "3 21 5 1\n3 10 20 30 40 50 60 70 80",
        "3 21 4 1\n3 10 40 30 20",
    );
    fails(
        "tet.msh",
        &tet,
        &[
            "tet.msh:48:",
            "element type 4 (4-node tetrahedron)",
            "expected 8-node hexahedra (type 5)",
        ],
    );
    let hex20 = ONE_HEX.replace("3 21 5 1", "3 21 17 1");
    fails(
        "hex20.msh",
        &hex20,
        &[
            "element type 17 (20-node hexahedron)",
            "expected 8-node hexahedra (type 5)",
        ],
    );
    let unknown = ONE_HEX.replace("3 21 5 1", "3 21 99 1");
    fails("t99.msh", &unknown, &["unknown element type 99", "type 5"]);
    // only the quadrangle face: no volume at all
    let faces_only = ONE_HEX
        .replace("3 3 1 3", "2 2 1 2")
        .replace("3 21 5 1\n3 10 20 30 40 50 60 70 80\n", "");
    fails(
        "faces.msh",
        &faces_only,
        &["no hexahedron", "physical volume"],
    );
}

#[test]
fn truncated_and_malformed_files_are_rejected() {
    // cut in the middle of the node coordinates
    let cut = &ONE_HEX[..ONE_HEX.find("2 0 1\n").unwrap()];
    fails(
        "cut.msh",
        cut,
        &["cut.msh:", "ends early", "node coordinates"],
    );
    // missing $EndNodes
    let no_end = ONE_HEX.replace("$EndNodes\n", "");
    fails("noend.msh", &no_end, &["found `$Elements`", "`$EndNodes`"]);
    // a bad number
    let bad = ONE_HEX.replace("2 1 1\n", "2 1 x\n");
    fails(
        "bad.msh",
        &bad,
        &["bad.msh:37:", "`x` is not a finite number"],
    );
    // an element with a missing node tag
    let short = ONE_HEX.replace("3 10 20 30 40 50 60 70 80", "3 10 40 30 20 50 60 70");
    fails(
        "short.msh",
        &short,
        &["short.msh:49:", "fewer than 8 node tags"],
    );
    // an unclosed unknown section
    let open = ONE_HEX.replace("$EndPeriodic\n", "");
    fails(
        "open.msh",
        &open,
        &["`$Periodic` is not closed", "`$EndPeriodic`"],
    );
    // no $Elements section
    let no_el = &ONE_HEX[..ONE_HEX.find("$Elements").unwrap()];
    fails("noel.msh", no_el, &["no $Elements section"]);
    // a degenerate (flat) hexahedron
    let flat = ONE_HEX.replace("3 10 20 30 40 50 60 70 80", "3 10 40 30 20 10 40 30 20");
    fails(
        "flat.msh",
        &flat,
        &["flat.msh:49:", "hexahedron 3 is degenerate"],
    );
    // a repeated node: the element keeps a volume but a corner collapses
    let wedge = ONE_HEX.replace("3 10 20 30 40 50 60 70 80", "3 10 20 30 40 50 60 70 50");
    fails(
        "wedge.msh",
        &wedge,
        &["wedge.msh:49:", "hexahedron 3 has a repeated node"],
    );
}

#[test]
fn undefined_node_tags_are_rejected() {
    let undefined = ONE_HEX.replace("3 10 20 30 40 50 60 70 80", "3 10 40 30 20 50 60 70 81");
    fails(
        "undef.msh",
        &undefined,
        &[
            "undef.msh:49:",
            "element 3 references node tag 81",
            "node tags defined in $Nodes",
        ],
    );
    // in a face element too
    let face = ONE_HEX.replace("2 50 60 70 80", "2 50 60 70 99");
    fails(
        "face.msh",
        &face,
        &["face.msh:47:", "element 2 references node tag 99"],
    );
    // a node tag defined twice
    let twice = ONE_HEX.replace("80\n20\n", "20\n20\n");
    fails("twice.msh", &twice, &["node tag 20 is defined twice"]);
}

#[test]
fn missing_file_names_it() {
    let e = read_msh(Path::new("/nonexistent/dir/disc.msh"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("/nonexistent/dir/disc.msh") && e.contains("cannot read"),
        "{e}"
    );
}
