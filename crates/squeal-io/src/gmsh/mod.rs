//! Gmsh MSH 4.1 ASCII meshes of 8-node hexahedra: [`read_msh`] and [`write_msh`].
//!
//! **What is read.** `$MeshFormat` must be `4.1 0 <size>` (ASCII). `$PhysicalNames`,
//! `$Entities`, `$Nodes` and `$Elements` are read; every other section (`$Periodic`,
//! `$NodeData`, `$PartitionedEntities`, ...) is skipped. Node tags may be sparse and
//! need not be sorted; parametric node blocks are accepted (the parametric coordinates
//! are ignored). Element types: 5 (8-node hexahedron) makes the mesh; 3 (4-node
//! quadrangle), 1 (2-node line) and 15 (point) only carry physical groups. Any other
//! type is an error naming it (a tetrahedron, prism, pyramid or second-order element
//! cannot be analysed by squeal's trilinear hexahedra).
//!
//! **Node order.** Gmsh numbers a hexahedron's nodes like VTK and like squeal
//! ([`squeal_fe::mesh`]): nodes 0-3 on the bottom face counter-clockwise seen from the
//! top, nodes 4-7 above them. No reordering is needed. An element whose volume
//! ([`squeal_fe::mesh::hex_volume`]) is negative (a mirrored node order, as some
//! exporters write) is flipped to `[0, 3, 2, 1, 4, 7, 6, 5]`; a degenerate one (zero
//! volume to `1e-12` of its largest edge cubed) is an error naming its element tag.
//!
//! **Output.** A [`Mesh`] with every hexahedron in body 0 and the nodes used by them
//! (others are dropped), numbered in increasing node tag order. Every physical group of
//! dimension 0 to 2 becomes a node set named after its physical name (`physical_<tag>`
//! when unnamed) holding the sorted nodes of its elements; groups of different
//! dimensions with one name are merged. Physical volumes (which Gmsh needs to save the
//! hexahedra at all) select nothing: every hexahedron of the file is read. Coordinates are returned as written (the caller scales them).
//!
//! Every error ([`IoError::Msh`]) names the file, the 1-based line where one applies and
//! what was expected; malformed input never panics.

mod parse;
mod write;

use crate::IoError;
use parse::{tokenize, Block, Parser};
use squeal_fe::mesh::hex_volume;
use squeal_fe::Mesh;
use std::collections::{BTreeMap, BTreeSet, HashMap, HashSet};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
pub use write::{msh_string, write_msh, VOLUME_GROUP};

/// The expected format, quoted in errors.
const EXPECTED_FORMAT: &str = "MSH 4.1 ASCII (`$MeshFormat` then `4.1 0 8`; \
                               export with `gmsh -format msh41` and Mesh.Binary = 0)";

/// What a hexahedral mesh file must contain, quoted in element-type errors.
const EXPECTED_HEX: &str = "8-node hexahedra (type 5), with 4-node quadrangles (3), \
                            lines (1) or points (15) for physical groups";

/// Name and node count of a Gmsh element type.
fn element_type(t: i64) -> Option<(&'static str, usize, usize)> {
    // (name, nodes, dimension)
    Some(match t {
        1 => ("2-node line", 2, 1),
        2 => ("3-node triangle", 3, 2),
        3 => ("4-node quadrangle", 4, 2),
        4 => ("4-node tetrahedron", 4, 3),
        5 => ("8-node hexahedron", 8, 3),
        6 => ("6-node prism", 6, 3),
        7 => ("5-node pyramid", 5, 3),
        8 => ("3-node line", 3, 1),
        9 => ("6-node triangle", 6, 2),
        10 => ("9-node quadrangle", 9, 2),
        11 => ("10-node tetrahedron", 10, 3),
        12 => ("27-node hexahedron", 27, 3),
        13 => ("18-node prism", 18, 3),
        14 => ("14-node pyramid", 14, 3),
        15 => ("1-node point", 1, 0),
        16 => ("8-node quadrangle", 8, 2),
        17 => ("20-node hexahedron", 20, 3),
        18 => ("15-node prism", 15, 3),
        19 => ("13-node pyramid", 13, 3),
        _ => return None,
    })
}

/// Reads a Gmsh MSH 4.1 ASCII file of 8-node hexahedra (see the [module docs](self)).
pub fn read_msh(path: &Path) -> Result<Mesh, IoError> {
    let bytes = std::fs::read(path).map_err(|source| IoError::Io {
        file: path.to_path_buf(),
        action: "read",
        source,
    })?;
    read_msh_bytes(&bytes, path)
}

/// Reads MSH 4.1 ASCII content; `file` names it in errors.
pub fn read_msh_bytes(bytes: &[u8], file: &Path) -> Result<Mesh, IoError> {
    let text = String::from_utf8_lossy(bytes);
    let toks = tokenize(&text);
    let last_line = toks.last().map_or(1, |t| t.1);
    let mut p = Parser {
        toks,
        pos: 0,
        file,
        last_line,
    };
    p.mesh_format()?;
    let mut names: HashMap<(usize, i64), String> = HashMap::new();
    let mut entity_phys: HashMap<(usize, i64), Vec<i64>> = HashMap::new();
    let mut nodes: HashMap<u64, [f64; 3]> = HashMap::new();
    let mut blocks: Vec<Block> = Vec::new();
    let (mut seen_nodes, mut seen_elements) = (false, false);
    while let Some((sec, line)) = p.peek() {
        p.pos += 1;
        match sec {
            "$PhysicalNames" => p.physical_names(&mut names)?,
            "$Entities" => p.entities(&mut entity_phys)?,
            "$Nodes" => {
                seen_nodes = true;
                p.nodes(&mut nodes)?;
            }
            "$Elements" => {
                seen_elements = true;
                p.elements(&mut blocks)?;
            }
            s if s.starts_with('$') && !s.starts_with("$End") => p.skip_section(s, line)?,
            other => {
                return Err(p.err(
                    Some(line),
                    format!("found `{other}` between sections"),
                    "a section such as `$Nodes` ... `$EndNodes`",
                ))
            }
        }
    }
    if !seen_nodes || !seen_elements {
        return Err(p.err(
            None,
            format!(
                "no {} section",
                if seen_nodes { "$Elements" } else { "$Nodes" }
            ),
            "`$Nodes` and `$Elements` sections",
        ));
    }
    let (mut mesh, index) = hex_mesh(&p, &nodes, &blocks)?;
    node_sets(&p, &mut mesh, &index, &nodes, &blocks, &names, &entity_phys)?;
    Ok(mesh)
}

/// The mesh of the hexahedra of `blocks`: the nodes they use, in increasing tag order
/// (`index`: node tag to mesh node), each element checked and turned to a positive volume.
fn hex_mesh(
    p: &Parser<'_>,
    nodes: &HashMap<u64, [f64; 3]>,
    blocks: &[Block],
) -> Result<(Mesh, HashMap<u64, usize>), IoError> {
    let mut used = BTreeSet::new();
    for b in blocks.iter().filter(|b| b.hex) {
        for (etag, line, v) in &b.elements {
            for &t in v {
                if !nodes.contains_key(&t) {
                    return Err(undefined_node(p, *etag, *line, t));
                }
                used.insert(t);
            }
        }
    }
    if used.is_empty() {
        return Err(p.err(
            None,
            "the file holds no hexahedron".into(),
            "8-node hexahedra (type 5); when physical groups are defined, Gmsh saves only \
             their elements: add a physical volume or set Mesh.SaveAll = 1",
        ));
    }
    let index: HashMap<u64, usize> = used.iter().enumerate().map(|(i, &t)| (t, i)).collect();
    let mut mesh = Mesh {
        nodes: used.iter().map(|t| nodes[t]).collect(),
        ..Mesh::default()
    };
    for b in blocks.iter().filter(|b| b.hex) {
        for (etag, line, v) in &b.elements {
            let mut h = [0usize; 8];
            for (slot, t) in h.iter_mut().zip(v) {
                *slot = index[t];
            }
            let x = h.map(|n| mesh.nodes[n]);
            let vol = hex_volume(&x);
            let edge = squeal_fe::hex8::edge_lengths(&x)
                .into_iter()
                .fold(0.0, f64::max);
            if vol.is_nan() || vol.abs() <= 1e-12 * edge.powi(3) {
                return Err(p.err(
                    Some(*line),
                    format!("hexahedron {etag} is degenerate (volume {vol:e})"),
                    "hexahedra of non-zero volume",
                ));
            }
            if vol < 0.0 {
                h = [h[0], h[3], h[2], h[1], h[4], h[7], h[6], h[5]];
            }
            // a repeated node (an edge of zero length) or an inverted corner leaves the
            // volume non-zero but the element unusable
            let q = squeal_fe::hex8::scaled_jacobian(&h.map(|n| mesh.nodes[n]));
            if q <= 0.0 {
                return Err(p.err(
                    Some(*line),
                    format!(
                        "hexahedron {etag} has a repeated node or an inverted corner \
                         (scaled Jacobian {q:.3})"
                    ),
                    "hexahedra whose eight corners are distinct and convex",
                ));
            }
            mesh.hexes.push(h);
        }
    }
    mesh.hex_body = vec![0; mesh.hexes.len()];
    Ok((mesh, index))
}

/// An element that references a node `$Nodes` does not define.
fn undefined_node(p: &Parser<'_>, etag: u64, line: usize, t: u64) -> IoError {
    p.err(
        Some(line),
        format!("element {etag} references node tag {t}, which $Nodes does not define"),
        "node tags defined in $Nodes",
    )
}

/// The physical groups of dimension 0 to 2 as node sets of `mesh` (named by
/// `$PhysicalNames`, else `physical_TAG`).
fn node_sets(
    p: &Parser<'_>,
    mesh: &mut Mesh,
    index: &HashMap<u64, usize>,
    nodes: &HashMap<u64, [f64; 3]>,
    blocks: &[Block],
    names: &HashMap<(usize, i64), String>,
    entity_phys: &HashMap<(usize, i64), Vec<i64>>,
) -> Result<(), IoError> {
    let mut groups: BTreeMap<(usize, i64), BTreeSet<usize>> = BTreeMap::new();
    for ((dim, _), phys) in entity_phys.iter().filter(|((d, _), _)| *d < 3) {
        for &ph in phys {
            groups.entry((*dim, ph)).or_default();
        }
    }
    for b in blocks.iter().filter(|b| b.dim < 3) {
        let Some(phys) = entity_phys.get(&(b.dim, b.tag)) else {
            continue;
        };
        for &ph in phys {
            let set = groups.entry((b.dim, ph)).or_default();
            for (etag, line, v) in &b.elements {
                for t in v {
                    if !nodes.contains_key(t) {
                        return Err(undefined_node(p, *etag, *line, *t));
                    }
                    if let Some(&i) = index.get(t) {
                        set.insert(i);
                    }
                }
            }
        }
    }
    for ((dim, ph), set) in groups {
        let name = names
            .get(&(dim, ph))
            .cloned()
            .unwrap_or_else(|| format!("physical_{ph}"));
        let entry = mesh.node_sets.entry(name).or_default();
        entry.extend(set);
        entry.sort_unstable();
        entry.dedup();
    }
    Ok(())
}
